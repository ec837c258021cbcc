"""The :class:`~rolling_cli.result.Result` of a solved level: arrays, loads, zones, references,
provenance and convergence record."""

from __future__ import annotations

import dataclasses
import logging
import math
import time

import numpy as np

from .._version import __version__
from ..case import Case
from ..case.given import given
from ..influence.finite import shaft_quantities
from ..model.validity import half_space_check
from ..model.viscoelastic import is_viscoelastic
from ..references import carter, hertz
from ..result import Result, node_states, utc_timestamp
from ..solver.formulation import State
from ..solver.strategies import Solution
from ..solver.system import ContactSystem
from ..stresses import power
from . import effects as effects_mod
from .planning import Level, Plan, _free_creep, build_contact_system, coupling_strength, hertz_applies

log = logging.getLogger(__name__)


def _attach_stresses(case: Case, the_plan: Plan, result: Result) -> Result:
    """The subsurface stresses the case asks for (nothing is imported without a [stresses] table)."""
    if case.stresses is None:
        return result
    from ..stresses import attach

    return attach(case, the_plan, result)


def _surfaces(case: Case, the_plan: Plan, system: ContactSystem, p_n: np.ndarray, p_t: np.ndarray) -> dict:
    """Each deformable body's surface displacements {label: (w, u)} [length] from its own compliance
    (:mod:`rolling_cli.influence.surface`; a BEM body's memoised: the one solved); empty when the
    tractions are empty."""
    if p_n.size == 0:
        return {}
    from ..influence.surface import body_displacements

    return body_displacements(case, the_plan, p_n, p_t, system)


def _linear_solver_attributes(system: ContactSystem, history: list[dict]) -> dict:
    """``linear_solver`` and, matrix-free, this solve's Krylov counts from its Newton history
    (:func:`.solver.matrix_free.result_attributes`)."""
    if not system.matrix_free:
        return {"linear_solver": system.linear_solver}
    from ..solver import matrix_free

    return matrix_free.result_attributes(system, history)


def assemble(level: Level, history: list[dict], timings: dict, converged: bool = True) -> Result:
    """The :class:`Result` of a solved level: arrays, loads, zones, references and provenance."""
    # Over 80 lines for a reason: the one place where a level's arrays become the Result's fields,
    # in the order of the Result's groups; each group's own computation is a helper below.
    case, the_plan, system, solution = level.case, level.plan, level.built, level.solved
    effects = the_plan.effects
    if level.origin:
        effects = effects.with_influence_origin(level.origin)
    strength = coupling_strength(system)
    if strength is not None:
        effects = effects.with_coupling_strength(strength)
    state = solution.state
    stick = solution.stick
    if not effects.tangential and case.friction.mu > 0.0:
        stick = state.p_n < 0.0  # p_t = 0, xi = 0: every contact node adheres
    w = system.weights
    p_n, p_t = state.p_n, state.p_t
    states = node_states(p_n, stick)
    s_t = system.reported_slip(p_n, p_t, state.creep)
    dissipation = power.density(p_t, s_t, states)
    load = system.load(p_n, p_t)  # as normal.load prescribes it: the arc sum, a finite cylinder's shaft load
    q = float(w @ p_t)
    mu = case.friction.mu
    contact = p_n < 0.0
    if contact.any():
        lo, hi = system.extent(contact)
        centre, half_width = 0.5 * (lo + hi), 0.5 * (hi - lo)
    else:
        centre = half_width = math.nan
    overlap = state.overlap if system.definite_normal else math.nan
    a, b = case.bodies.A, case.bodies.B
    if load > 0.0:  # Hertz at the solved load (the reference, and the scales written out)
        ref_a = hertz.half_width(load, the_plan.radius, the_plan.modulus)
        ref_p0 = hertz.peak_pressure(load, ref_a)
    else:
        ref_a = ref_p0 = math.nan
    attrs = {
        "format": "rolling_cli.result",
        "format_version": 1,
        "software_version": __version__,
        "created": utc_timestamp(),
        "title": case.title or "",
        **_convergence_record(level, history, converged),
        "normal_load": load,
        "tangential_load": q,
        "q_over_mu_p": q / (mu * load) if mu > 0.0 and load > 0.0 else math.nan,
        "creep": float(state.creep) if effects.tangential else _free_creep(case),
        "overlap": float(overlap),
        "solved_overlap": float(state.overlap),
        "mu": mu,
        "hertz_a": ref_a,
        "hertz_p0": ref_p0,
        "contact_half_width": half_width,
        "contact_centre": centre,
        "traction_scale": float(np.max(np.abs(p_n))) if p_n.size else 0.0,
        **_model_record(case, the_plan, system, effects, history),
        "coupling_strength": strength or 0.0,
        "message": "",
        "time_influence": timings["influence"],
        "time_solve": timings["solve"],
        "frictional_power_total": power.total(w, dissipation),
    }
    attrs.update(half_space_check(case, half_width))  # a/R against the half-space assumption
    found = _sensitivities(case, system, state, converged, half_width, the_plan, solution)
    attrs.update(_friction_attributes(case, solution if effects.tangential and converged else None, found))
    attrs.update(found)
    attrs.update(shaft_quantities(case, system.x, w, p_n, p_t, centre, half_width))  # finite cylinders (else NaN)
    surfaces = _surfaces(case, the_plan, system, p_n, p_t)  # each body's (w, u): the result and the power balance
    if is_viscoelastic(a) or is_viscoelastic(b):  # rolling resistance, pressure shift, hysteresis (none if elastic)
        from ..model import resistance

        uniform = the_plan.grid.element_edges is None  # F_rr's element rule: one element length
        surface = surfaces.get("A") if resistance.finite_on_flat(case) and uniform else None  # A's (w, u) on its arc
        attrs.update(resistance.attributes(case, system, p_n, p_t, the_plan.radius, surface))
    reference = _closed_forms(case, system.x, the_plan.radius, q, load, ref_a, ref_p0, attrs)
    result = Result(
        x=system.x,
        weights=w,
        p_n=p_n,
        p_t=p_t,
        delta_n=system.gap(p_n, p_t, state.overlap),
        s_t=s_t,
        state=states,
        history=history,
        reference=reference,
        case=case,
        frictional_power=dissipation,
        **{f"surface_{c}_{label}": v for label, wu in surfaces.items() for c, v in zip("wu", wu, strict=True)},
    )
    result.record(**attrs)
    return result


def _model_record(case: Case, the_plan: Plan, system: ContactSystem, effects, history: list[dict]) -> dict:
    """What was simulated and on what: mesh scale, beta (Dundurs' and the seed paper's), penalties,
    node spacing, rolling direction, influence model, elements, effects, linear solver, unit names."""
    a, b = case.bodies.A, case.bodies.B
    return {
        "mesh_half_width": the_plan.half_width,
        "beta_dundurs": 0.5 * the_plan.beta_seed,
        "beta_seed": the_plan.beta_seed,
        "penalty_n": system.penalty_n,
        "penalty_t": system.penalty_t,
        "reference_penalty_n": system.reference_penalty_n,
        "reference_penalty_t": system.reference_penalty_t,
        "node_spacing": system.spacing,
        "direction": case.rolling.direction,
        "influence": the_plan.effects.influence,
        "contact_elements": the_plan.grid.elements,
        "effects": effects.to_json(),
        **(
            {"linear_solver": "dense LU"}  # solver/velocity.py: the slip rows' LU on every system
            if case.friction.law != "constant" and effects.tangential
            else _linear_solver_attributes(system, history)
        ),
        "effects_line": effects.line(),
        "unit_length": case.units.length,
        "unit_stress": case.units.stress,
        "unit_line_force": case.units.line_force,
        "bodies": f"A: {a.kind}, B: {b.kind}",
    }


def _convergence_record(level: Level, history: list[dict], converged: bool) -> dict:
    """Whether and how the level's solve converged: iterations, relative residual, the tolerance
    applied on this level and the strategies that ran (in order, each once)."""
    strategies_run: list[str] = []
    for row in history:
        name = f"{row.get('level', '')}: {row.get('strategy', '')}"
        if name not in strategies_run:
            strategies_run.append(name)
    return {
        "converged": converged,
        "iterations": int(level.iterations),
        "residual": float(level.solved.evaluation.relative_residual),
        "tolerance_applied": max(
            [float(row["tolerance"]) for row in history if row.get("level") == level.kind and "tolerance" in row],
            default=float(level.case.solver.tolerance),
        ),
        "strategies": "; ".join(strategies_run),
    }


def _closed_forms(
    case: Case, x: np.ndarray, radius: float, q: float, load: float, ref_a: float, ref_p0: float, attrs: dict
) -> dict:
    """Hertz's pressure and Carter's traction on the nodes ``x`` [length] where they hold (elastic
    half-spaces, not finite cylinders, exactly decoupled, with friction and a load), at the solved
    load [force/length] and Q; Carter's creepage goes into ``attrs``. Nothing otherwise."""
    a, b = case.bodies.A, case.bodies.B
    mu = case.friction.mu
    similar = (
        effects_mod.cross_compliance(case) == 0.0
        and a.kind not in ("layered", "viscoelastic")
        and b.kind not in ("layered", "viscoelastic")
        and not (a.finite or b.finite)  # a finite cylinder departs from the half-space (README error map)
        and mu > 0.0
        and load > 0.0
    )
    if not similar:
        return {}
    ratio = float(np.clip(q / (mu * load), -1.0, 1.0))
    attrs["carter_creep"] = carter.creepage(ratio, ref_a, radius, mu)
    return {
        "hertz_pressure": hertz.pressure(x, ref_a, ref_p0),
        "carter_traction": carter.traction(x, ratio, ref_a, ref_p0, mu, case.rolling.direction),
    }


def _friction_attributes(case: Case, solution: Solution | None = None, found: dict | None = None) -> dict:
    """The velocity-dependent friction law's record (nothing for Coulomb friction, whose files
    stay as they were): its name, mu_kinetic, the rolling speed and the time unit; for a solved
    tangential problem the slope dQ/dxi of the creep-force curve at the solution (node states
    held: :func:`~rolling_cli.solver.reduced.creep_sensitivity`, d mu/d s_a included) and the
    branch it puts the point on: "rising" (dQ/dxi < 0: Q grows with |xi|, the stable side of the
    curve's peak) or "falling".

    The slope is the sensitivities' ``dQ_dxi`` (``found``, of :func:`_sensitivities`) where those
    differentiate the same held matrix (:func:`_shared_slope`): the velocity system is then
    assembled and solved once for both (it was assembled twice: ~4 ms of a ~50 ms solve at 200
    elements, benchmarks/RESULTS.md)."""
    from ..model.friction import from_case

    law = from_case(case.friction, case.rolling)
    if not law.velocity_dependent:
        return {}
    out = {
        "friction_law": law.name,
        "mu_kinetic": float(law.mu_kinetic),
        "rolling_speed": float(given(case.rolling.speed, "rolling.speed")),
        "unit_time": case.units.time,
    }
    if solution is not None and solution.problem.tangential:
        from ..solver import formulation, reduced

        problem = solution.problem  # with a prescribed force, its bordered matrix gives the held slope
        state = solution.state
        shared = _shared_slope(solution, found)
        if shared is not None:
            return {**out, "creep_slope": shared, "branch": "rising" if shared < 0.0 else "falling"}
        try:
            ev = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
            slope = reduced.creep_sensitivity(problem, state, ev)
        except (np.linalg.LinAlgError, ValueError):  # a singular system: no slope recorded
            return out
        out["creep_slope"] = float(slope)
        out["branch"] = "rising" if slope < 0.0 else "falling"
    return out


def _shared_slope(solution: Solution, found: dict | None) -> float | None:
    """The held slope dQ/dxi [force/length] of a converged law solve from its sensitivities
    (:mod:`rolling_cli.solver.law_sensitivity`), or None where they do not give it.

    Those differentiate the velocity system of the problem with the creepage held, or with the
    force held as Q itself; the slope is A^-1 of the same held matrix A applied to the creepage
    column, whatever row borders it (:func:`rolling_cli.solver.velocity.creep_derivatives`), so
    dQ/dxi under creepage control and 1/(dxi/dQ) under force control are the slope, the same
    numbers up to round-off. Not so where the normal problem is solved with the overlap held (the
    sensitivities hold P instead: another matrix), nor where they are not finite (a singular
    matrix: the slope's own solve then says so)."""
    problem = solution.problem
    if found is None or problem.friction is None or (problem.normal and problem.load is None):
        return None
    slope = found.get("dQ_dxi")
    return float(slope) if slope is not None and math.isfinite(slope) else None


def _sensitivities(
    case: Case,
    system: ContactSystem,
    state: State,
    converged: bool,
    half_width: float,
    the_plan: Plan,
    solution: Solution | None = None,
) -> dict:
    """The derivatives of a converged solve (:mod:`rolling_cli.solver.sensitivity`) and their time;
    NaN for a failed one (its state is no solution) or a singular final matrix (a warning).

    A velocity-dependent friction law takes them from the velocity Newton's own linearisation
    (:mod:`rolling_cli.solver.law_sensitivity`, with dQ/dV and dxi/dV; the P-derivatives of
    half-space pairs only, by homogeneity; NaN elsewhere). The load homogeneity that gives the
    P-derivatives of half-space pairs does not hold for a viscoelastic body (its time scale
    tau V / a changes with the load), and the fixed-state ones miss the motion of the contact
    edges (3.7 % on dxi/dP of cases/rubber_roller-like SLS case against central differences of
    re-solves): a viscoelastic case records no P-derivatives (NaN), and with a law no dQ/dV
    (the speed enters its influence too, which the law's column does not hold)."""
    from ..model import viscoelastic
    from ..model.friction import from_case
    from ..solver import sensitivity

    t0 = time.perf_counter()
    found = sensitivity.UNDEFINED
    law = from_case(case.friction, case.rolling).velocity_dependent  # no layer derivative with a law (NaN)
    layer = _layer_systems(case, the_plan) if converged and case.output.layer_derivative and not law else None
    if converged and not law:
        force = case.tangential.control()[0] != "creep"
        try:
            similar = hertz_applies(case)
            found = sensitivity.sensitivities(system, case.friction.mu, state, force, similar, half_width, layer)
        except np.linalg.LinAlgError as err:
            log.warning("no sensitivities: the final Newton matrix is singular (%s)", err)
    out = _law_sensitivities(case, state, converged, half_width, solution) if law else found.as_dict()
    if case.output.layer_derivative:  # asked for: NaN where not computed
        out.setdefault("dQ_db", math.nan)
        out.setdefault("dxi_db", math.nan)
    if viscoelastic.bodies(case):
        out.update(dict.fromkeys(("dQ_dP", "dxi_dP", "da_dP", "dp0_dP"), math.nan))
        if law:  # |V| enters the viscoelastic influence too (V tau / a), not only the law's s_a
            out.update(dict.fromkeys(("dQ_dV", "dxi_dV"), math.nan))
    return {**out, "time_sensitivities": time.perf_counter() - t0}


def _law_sensitivities(case: Case, state: State, converged: bool, half_width: float, solution) -> dict:
    """The derivatives with a slip-speed friction law (:mod:`rolling_cli.solver.law_sensitivity`), NaN
    for a failed or normal-only solve or a singular matrix (a warning)."""
    from ..solver import law_sensitivity, sensitivity

    found = sensitivity.UNDEFINED
    if converged and solution is not None and solution.problem.tangential:
        force = case.tangential.control()[0] != "creep"
        try:
            found = law_sensitivity.law_sensitivities(solution.problem, state, force, hertz_applies(case), half_width)
        except np.linalg.LinAlgError as err:
            log.warning("no sensitivities: the final Newton matrix is singular (%s)", err)
    out = found.as_dict()
    out.setdefault("dQ_dV", math.nan)
    out.setdefault("dxi_dV", math.nan)
    return out


#: Relative step of the layer thickness's central difference (:mod:`rolling_cli.solver.sensitivity`).
LAYER_STEP = 1e-4


def _layer_systems(case: Case, the_plan: Plan) -> tuple | None:
    """(the contact system at b + h, at b - h, h) of the case's one layered body on the plan's grid
    (h = :data:`LAYER_STEP` b; built outside the disk cache), or None (a warning) when the case has
    not exactly one layered body."""
    labels = [label for label in ("A", "B") if getattr(case.bodies, label).kind == "layered"]
    if len(labels) != 1:
        log.warning("no dQ/db: output.layer_derivative needs exactly one layered body (the case has %d)", len(labels))
        return None
    body = getattr(case.bodies, labels[0])
    h = LAYER_STEP * float(body.layer_thickness)

    def at(thickness: float) -> ContactSystem:
        bodies = dataclasses.replace(case.bodies, **{labels[0]: dataclasses.replace(body, layer_thickness=thickness)})
        return build_contact_system(dataclasses.replace(case, bodies=bodies), the_plan, use_cache=False)

    return at(float(body.layer_thickness) + h), at(float(body.layer_thickness) - h), h
