"""One solve, stage by stage: case -> plan -> influence -> system -> Newton -> result.

:func:`solve` is the public entry point; the stages are plain functions so that
sweeps can reuse the expensive ones: a prebuilt contact system and a warm
start can be passed in, influences are memoised (and BEM ones cached on disk)
by :mod:`rolling_cli.influence.build`, and the pre-solve estimate of a by
:func:`estimate_half_width`.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import time
from dataclasses import dataclass

import numpy as np

from . import __version__, materials
from . import effects as effects_mod
from .case import Case, case_to_dict, case_to_toml, load_case
from .errors import CaseError, ConvergenceError, GrossSlidingError, ZoneError
from .grid import ContactGrid
from .influence.build import pair_compliance
from .references import carter, hertz, thin_layer
from .result import Result, node_states, utc_timestamp
from .solver.control import Controls, solve_rolling
from .solver.initial import carter_ratio_for_creep, cold_start
from .solver.newton import State
from .system import ContactSystem, build_system

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Plan:
    """Derived quantities that fix the discretisation.

    ``modulus`` E* [stress], ``radius`` R* [length], ``beta_seed`` [-],
    ``half_width`` Hertz a [length] (estimated from the overlap when only the
    overlap is given), ``p0`` [stress], ``load`` P or its estimate [force/length],
    ``coupling`` the measured coupling strength once the system is built [-].
    """

    modulus: float
    radius: float
    beta_seed: float
    half_width: float
    p0: float
    load: float
    grid: ContactGrid
    effects: effects_mod.Effects
    coupling: float = 0.0


def plan(case: Case, half_width: float | None = None, use_cache: bool = True, check: bool = True) -> Plan:
    """Materials, contact scale a, contact grid and effects of a case.

    a is the Hertz half-width when the load is prescribed and both bodies are
    half-spaces; otherwise (an imposed overlap, or a layered body) it is
    measured by a coarse frictionless pre-solve (:func:`estimate_half_width`).
    ``half_width`` overrides it. ``check=False`` skips the mesh rules (coarse
    pre-solves only).
    """
    a, b = case.bodies.A, case.bodies.B
    e_star = materials.effective_modulus(a.modulus, a.ratio, b.modulus, b.ratio)
    r_star = materials.effective_radius(a.radius, b.radius)
    beta = materials.beta_seed(a.modulus, a.ratio, b.modulus, b.ratio)
    if half_width is None:
        if case.normal.load is not None and not _layered(case):
            half_width = hertz.half_width(float(case.normal.load), r_star, e_star)
        else:
            half_width = estimate_half_width(case, e_star, r_star, use_cache)
    if case.normal.load is not None:
        load = float(case.normal.load)
    else:
        load = hertz.load_for_half_width(half_width, r_star, e_star)
    p0 = hertz.peak_pressure(load, half_width)
    disc = case.discretization
    order = 2 if disc.element == "quadratic" else 0
    grid = ContactGrid(disc.zone * half_width, disc.contact_elements, order)
    if check:
        _check_layer_elements(case, grid)
    return Plan(e_star, r_star, beta, half_width, p0, load, grid, effects_mod.decide(case))


#: Contact elements on a layer may be at most this fraction of its thickness
#: (nearly singular integration across the layer stays accurate, and the
#: layer's stress gradients, on the scale b, are resolved).
LAYER_ELEMENT_FRACTION = 0.5


def _check_layer_elements(case: Case, grid: ContactGrid) -> None:
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        if body.kind != "layered":
            continue
        limit = LAYER_ELEMENT_FRACTION * float(body.layer_thickness)
        if grid.element_length > limit * (1.0 + 1e-9):
            needed = int(np.ceil(2.0 * grid.half_width / limit))
            raise CaseError(
                f"discretization.contact_elements = {grid.elements}: elements of {grid.element_length:.4g} over "
                f"the potential zone exceed half the layer thickness of bodies.{label} ({limit:.4g}); "
                f"allowed: >= {needed} elements (or a smaller discretization.zone)",
                file=case.source,
                key="discretization.contact_elements",
            )


def _layered(case: Case) -> bool:
    return case.bodies.A.kind == "layered" or case.bodies.B.kind == "layered"


#: Coarse pre-solve: contact elements, and potential zone / first guess of a.
PRESOLVE_ELEMENTS = 16
PRESOLVE_ZONE = 2.5


_estimates: dict[str, float] = {}


def estimate_half_width(case: Case, e_star: float, r_star: float, use_cache: bool = True) -> float:
    """Memoised :func:`measure_half_width` (sweeps vary friction and loads around one model)."""
    data = case_to_dict(case)
    key = json.dumps(
        {k: data.get(k) for k in ("bodies", "normal", "discretization", "solver")}, sort_keys=True, default=str
    )
    if key not in _estimates:
        if len(_estimates) > 64:
            _estimates.clear()
        _estimates[key] = measure_half_width(case, e_star, r_star, use_cache)
    return _estimates[key]


def measure_half_width(case: Case, e_star: float, r_star: float, use_cache: bool = True) -> float:
    """Contact half-width a [length] from coarse frictionless normal solves of the case's own model.

    The first guess is :func:`first_guess`. Coarse solves (the model's geometry
    scaled by the current guess; on a layer, elements of at most
    :data:`PRESOLVE_LAYER_ELEMENT` thicknesses) refine it until it moves by less
    than two coarse node spacings; the zone doubles if the contact reaches its
    edge.
    """
    guess = first_guess(case, e_star, r_star)
    thinnest = min(
        (float(b.layer_thickness) for b in (case.bodies.A, case.bodies.B) if b.kind == "layered"), default=math.inf
    )
    zone = PRESOLVE_ZONE
    coarse = dataclasses.replace(
        case,
        friction=dataclasses.replace(case.friction, mu=0.0),
        tangential=type(case.tangential)(),
        solver=dataclasses.replace(case.solver, penalty="auto"),
    )
    for _ in range(6):
        trial = dataclasses.replace(
            coarse,
            discretization=dataclasses.replace(
                case.discretization,
                contact_elements=_presolve_elements(zone * guess, thinnest),
                zone=zone,
                slip_derivative="fd",
            ),
        )
        the_plan = plan(trial, half_width=guess, check=False)
        system = build_contact_system(trial, the_plan, use_cache)
        start = initial_state(trial, the_plan, system)
        outcome = solve_rolling(
            system, 0.0, _controls(trial, the_plan.effects), start, "normal", 1e-10, trial.solver.max_iterations
        )
        contact = outcome.state.p_n < 0.0
        if contact[0] or contact[-1] or not contact.any():
            zone *= 2.0
            continue
        lo, hi = system.extent(contact)
        measured = 0.5 * (hi - lo)
        if abs(measured - guess) <= 2.0 * system.spacing:
            return float(measured)
        guess, zone = float(measured), 1.6
    return float(guess)


#: In the pre-solve, layer elements may be this many thicknesses long.
PRESOLVE_LAYER_ELEMENT = 2.0


def _presolve_elements(zone_half_width: float, thickness: float) -> int:
    needed = int(np.ceil(2.0 * zone_half_width / (PRESOLVE_LAYER_ELEMENT * thickness))) if thickness < math.inf else 0
    return int(min(max(PRESOLVE_ELEMENTS, needed), 400))


def first_guess(case: Case, e_star: float, r_star: float) -> float:
    """First estimate of a [length] before any solve.

    Half-spaces: Hertz a (load) or the interference half-width sqrt(2 R* d)
    (overlap). A layer: the smaller of Hertz and the thin-layer limits of
    :mod:`rolling_cli.references.thin_layer` for a load (a thin layer is much
    stiffer than a half-space of its material); sqrt(6 R* d) for an overlap on
    a nearly incompressible layer, which bulges beside the contact.
    """
    layers = [b for b in (case.bodies.A, case.bodies.B) if b.kind == "layered"]
    if case.normal.load is not None:
        load = float(case.normal.load)
        guess = hertz.half_width(load, r_star, e_star)
        for body in layers:
            b, young, nu = float(body.layer_thickness), float(body.young), float(body.poisson)
            thin = max(
                thin_layer.compressible_half_width(load, r_star, young, nu, b),
                thin_layer.incompressible_half_width(load, r_star, young, b),
            )
            guess = min(guess, thin)
        return guess
    incompressible = any(float(body.poisson) >= 0.45 for body in layers)
    return thin_layer.half_width_for_overlap(float(case.normal.overlap), r_star, incompressible)


def check_gross_sliding(case: Case) -> None:
    """|Q| >= mu P before any work, when P is known (exit code 2 in the CLI)."""
    kind, value = case.tangential.control()
    mu = case.friction.mu
    load = case.normal.load
    limit = None
    if kind == "q_over_mu_p" and abs(value) >= 1.0:
        limit = f"|Q/(mu P)| = {abs(value):g} >= 1"
    elif kind == "q_over_p" and abs(value) >= mu:
        limit = f"|Q/P| = {abs(value):g} >= mu = {mu:g}"
    elif kind == "load" and value != 0.0 and load is not None and abs(value) >= mu * load:
        limit = f"|Q| = {abs(value):g} >= mu P = {mu * load:g}"
    if limit:
        raise GrossSlidingError(
            f"{case.source + ': ' if case.source else ''}tangential.{kind} = {value:g}: gross sliding, "
            f"{limit}; the cylinders slide, they do not roll; allowed: |Q| < mu P"
        )


def build_contact_system(case: Case, the_plan: Plan, use_cache: bool = True) -> ContactSystem:
    """Influence (BEM or closed form) and the linear rolling system for a planned case."""
    return build_contact_system_with_origin(case, the_plan, use_cache)[0]


def build_contact_system_with_origin(
    case: Case, the_plan: Plan, use_cache: bool = True
) -> tuple[ContactSystem, dict[str, str]]:
    """As :func:`build_contact_system`, plus where each body's influence came from."""
    disc = case.discretization
    compliance, origin = pair_compliance(case, the_plan, use_cache)
    penalty = None if case.solver.penalty == "auto" else float(case.solver.penalty)
    system = build_system(
        compliance,
        the_plan.radius,
        case.rolling.direction,
        the_plan.grid,
        disc.slip_derivative,
        penalty,
    )
    return system, origin


def _controls(case: Case, effects: effects_mod.Effects) -> Controls:
    kind, value = case.tangential.control()
    if not effects.tangential:
        kind, value = "none", 0.0
    return Controls(case.normal.load, case.normal.overlap, (kind, value))


def _initial_ratio(case: Case, the_plan: Plan) -> float:
    kind, value = case.tangential.control()
    mu = case.friction.mu
    if mu == 0.0:
        return 0.0
    if kind == "q_over_mu_p":
        return value
    if kind == "q_over_p":
        return value / mu
    if kind == "load":
        return value / (mu * the_plan.load)
    return carter_ratio_for_creep(value, carter.full_slip_creepage(the_plan.half_width, the_plan.radius, mu))


def initial_state(case: Case, the_plan: Plan, system: ContactSystem) -> State:
    """Cold start: Hertz pressure and Carter traction and creepage (see :mod:`rolling_cli.solver.initial`)."""
    kind, value = case.tangential.control()
    ratio = float(np.clip(_initial_ratio(case, the_plan), -1.0, 1.0))
    creep = value if kind == "creep" else None
    return cold_start(system, the_plan.half_width, the_plan.load, case.friction.mu, ratio, creep, case.normal.overlap)


#: Grid sequencing: a coupled half-plane solve with at least this many elements
#: starts from the solution on a grid with a quarter of the elements
#: (recursively). Decoupled solves start well from Hertz and Carter already:
#: sequencing them costs more than it saves (benchmarks/RESULTS.md).
SEQUENCING_ELEMENTS = 240


def _sequenced_start(case: Case, the_plan: Plan, system: ContactSystem) -> tuple[State, list[dict]]:
    """Cold start, or for large half-plane grids the interpolated coarse-grid solution.

    Newton's cost on a fine grid is mostly the iterations that move the
    contact and adhesion boundaries; a solution on a grid 4x coarser (cost
    1/64 per factorisation) puts them within a node or two. The overlap and
    creepage carry over unchanged (same zone, same log reference length).
    """
    disc = case.discretization
    if (
        disc.influence != "half-plane"
        or disc.contact_elements < SEQUENCING_ELEMENTS
        or the_plan.effects.strategy != "coupled"
    ):
        return initial_state(case, the_plan, system), []
    coarse_case = dataclasses.replace(
        case, discretization=dataclasses.replace(disc, contact_elements=disc.contact_elements // 4)
    )
    try:
        coarse = solve(coarse_case)
    except (ConvergenceError, ZoneError):
        return initial_state(case, the_plan, system), []
    x = system.x
    p_n = np.minimum(np.interp(x, coarse.x, coarse.p_n, left=0.0, right=0.0), 0.0)
    # Err on the small side at the contact edges: a contact set too large is shed
    # one node per Newton iteration (only the outermost node shows tension), a
    # set too small gains all its missing nodes at once (all of them penetrate).
    in_contact = coarse.x[coarse.p_n < 0.0]
    if in_contact.size:
        p_n[(x < in_contact.min()) | (x > in_contact.max())] = 0.0
    bound = -case.friction.mu * p_n
    p_t = np.clip(np.interp(x, coarse.x, coarse.p_t, left=0.0, right=0.0), -bound, bound)
    overlap = float(coarse.attributes.get("solved_overlap", 0.0))
    label = f"coarse grid, {coarse_case.discretization.contact_elements} elements: "
    history = [{**row, "stage": label + str(row.get("stage", ""))} for row in coarse.history]
    return State(p_n, p_t, overlap, float(coarse.creep)), history


#: mu |beta_Dundurs| above which Newton convergence is not guaranteed (measured:
#: benchmarks/robustness.py; every failure in 2800 random cases lies above it).
STRONG_COUPLING = 0.6

#: Enlarging the potential zone: factor per retry, and the largest zone / a.
ZONE_GROWTH = 1.5
ZONE_LIMIT = 8.0


def solve(
    case: Case | str | dict,
    *,
    start: State | None = None,
    system: ContactSystem | None = None,
    keep_failed: bool = False,
    use_cache: bool = True,
) -> Result:
    """Solve a case (a :class:`Case`, a case-file path or a TOML dict); return a :class:`Result`.

    ``start`` is a warm start (a converged state on the same grid), ``system``
    a prebuilt contact system for this case (sweeps reuse it); ``use_cache``
    allows the on-disk BEM influence cache. When the contact reaches the edge
    of the potential zone (coupling can shift and widen it far beyond Hertz),
    the zone is enlarged by :data:`ZONE_GROWTH` and the case solved again, up
    to :data:`ZONE_LIMIT` a; a warning and the result attribute ``zone_note``
    say so. Raises :class:`ConvergenceError`, :class:`ZoneError` or
    :class:`GrossSlidingError`; with ``keep_failed=True`` a failed solve
    returns its last iterate marked ``converged = False`` instead of raising.
    """
    if not isinstance(case, Case):
        case = load_case(case)
    requested = case.discretization.zone
    while True:
        try:
            result = _solve_once(case, start=start, system=system, keep_failed=keep_failed, use_cache=use_cache)
            break
        except ZoneError:
            zone = case.discretization.zone
            if zone * ZONE_GROWTH > ZONE_LIMIT:
                raise
            case = dataclasses.replace(
                case, discretization=dataclasses.replace(case.discretization, zone=zone * ZONE_GROWTH)
            )
            start = system = None  # a new grid: no warm start, a new contact system
            log.warning(
                "the contact reached the edge of the potential zone %.4g a; solving again with %.4g a",
                zone,
                case.discretization.zone,
            )
    if case.discretization.zone != requested:
        result.attributes["zone_note"] = (
            f"discretization.zone enlarged from {requested:g} to {case.discretization.zone:g}: "
            "the contact reached the edge of the requested zone"
        )
        result.case_toml = case_to_toml(case)
    return result


def _solve_once(
    case: Case,
    *,
    start: State | None = None,
    system: ContactSystem | None = None,
    keep_failed: bool = False,
    use_cache: bool = True,
) -> Result:
    """One solve on the case's own potential zone (see :func:`solve`)."""
    t0 = time.perf_counter()
    check_gross_sliding(case)
    the_plan = plan(case, use_cache=use_cache)
    for warning in the_plan.effects.warnings:
        log.warning(warning)
    if system is None:
        system, origin = build_contact_system_with_origin(case, the_plan, use_cache)
        the_plan = dataclasses.replace(the_plan, effects=the_plan.effects.with_influence_origin(origin))
    strength = coupling_strength(system)
    the_plan = dataclasses.replace(the_plan, coupling=strength or 0.0)
    if strength is not None:
        the_plan = dataclasses.replace(the_plan, effects=the_plan.effects.with_coupling_strength(strength))
    t1 = time.perf_counter()
    coarse_history: list[dict] = []
    warm = start is not None and start.p_n.shape == system.x.shape
    if not warm:
        start, coarse_history = _sequenced_start(case, the_plan, system)
        warm = bool(coarse_history)
    message = ""
    try:
        outcome = solve_rolling(
            system,
            case.friction.mu,
            _controls(case, the_plan.effects),
            start,
            the_plan.effects.strategy,
            case.solver.tolerance,
            case.solver.max_iterations,
            warm=warm,
        )
        state, history, iterations, residual = outcome.state, outcome.history, outcome.iterations, outcome.residual
        stick = outcome.evaluation.stick
        converged = True
    except ConvergenceError as err:
        partial = err.partial
        if partial is not None and (partial.p_n[0] < 0.0 or partial.p_n[-1] < 0.0):
            # The iterate presses on the zone's end nodes (the gauge node among them):
            # the discrete problem is not the intended one, whatever Newton does.
            raise ZoneError(
                "the contact reaches the edge of the potential contact zone during the iteration",
                residual=err.residual,
                iterations=err.iterations,
                cause="discretization.zone is too small for this case; enlarge it",
            ) from err
        strength = abs(0.5 * the_plan.beta_seed) * case.friction.mu
        if strength > STRONG_COUPLING and not err.cause.startswith("strong"):
            err = ConvergenceError(
                "Newton did not converge",
                residual=err.residual,
                iterations=err.iterations,
                history=err.history,
                cause=f"strong normal-tangential coupling with high friction (mu |beta_Dundurs| = {strength:.2f} "
                f"> {STRONG_COUPLING}): convergence is not guaranteed here; try more iterations "
                "(solver.max_iterations), a finer mesh, or a load further from full slip",
                partial=partial,
            )
        if not keep_failed or partial is None:
            raise err
        state, history, iterations, residual = err.partial, err.history, err.iterations or 0, err.residual or math.nan
        stick = np.zeros(system.size, dtype=bool)
        converged = False
        message = str(err)
    t2 = time.perf_counter()
    history = coarse_history + history
    if not the_plan.effects.tangential and case.friction.mu > 0.0:
        stick = state.p_n < 0.0  # p_t = 0, xi = 0: every contact node adheres
    result = _assemble(case, the_plan, system, state, stick, history, iterations, residual, converged)
    result.attributes["message"] = message
    result.attributes["time_influence"] = t1 - t0
    result.attributes["time_solve"] = t2 - t1
    if converged:
        check_zone(result, system)
    return result


def coupling_strength(system: ContactSystem) -> float | None:
    """Measured normal-to-tangential coupling: max|B_tn| / max|B_tt| over the slip rows [-].

    The tangential strain rate per unit nodal pressure against that per unit
    tangential traction; 0 for an exactly decoupled pair, None when the
    coupling blocks are not simulated.
    """
    if system.B_tn is None:
        return None
    rows = np.ones(system.size, dtype=bool)
    rows[system.gauge] = False
    return float(np.abs(system.B_tn[rows]).max() / np.abs(system.B_tt[rows]).max())


def check_zone(result: Result, system: ContactSystem) -> None:
    """The contact must stay inside the potential zone: the end nodes must be separated."""
    contact = result.p_n < 0.0
    if contact[0] or contact[-1]:
        raise ZoneError(
            "the contact reaches the edge of the potential contact zone, so the answer is wrong",
            residual=result.residual,
            iterations=result.iterations,
            cause="discretization.zone is too small for this load; enlarge it "
            f"(contact covers x = {result.x[contact].min():.4g} .. {result.x[contact].max():.4g}, "
            f"zone {result.x[0]:.4g} .. {result.x[-1]:.4g})",
        )


def _assemble(case, the_plan, system, state, stick, history, iterations, residual, converged) -> Result:
    w = system.weights
    p_n, p_t = state.p_n, state.p_t
    states = node_states(p_n, stick)
    load = float(-(w @ p_n))
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
        "converged": converged,
        "iterations": int(iterations),
        "residual": float(residual),
        "normal_load": load,
        "tangential_load": q,
        "q_over_mu_p": q / (mu * load) if mu > 0.0 and load > 0.0 else math.nan,
        "creep": float(state.creep) if the_plan.effects.tangential else _free_creep(case),
        "overlap": float(overlap),
        "solved_overlap": float(state.overlap),
        "mu": mu,
        "hertz_a": ref_a,
        "hertz_p0": ref_p0,
        "mesh_half_width": the_plan.half_width,
        "beta_dundurs": 0.5 * the_plan.beta_seed,
        "beta_seed": the_plan.beta_seed,
        "contact_half_width": half_width,
        "contact_centre": centre,
        "penalty_n": system.penalty_n,
        "penalty_t": system.penalty_t,
        "reference_penalty_n": system.reference_penalty_n,
        "reference_penalty_t": system.reference_penalty_t,
        "traction_scale": float(np.max(np.abs(p_n))) if p_n.size else 0.0,
        "node_spacing": system.spacing,
        "direction": case.rolling.direction,
        "influence": case.discretization.influence,
        "contact_elements": the_plan.grid.elements,
        "effects": the_plan.effects.to_json(),
        "coupling_strength": the_plan.coupling,
        "effects_line": the_plan.effects.line(),
        "unit_length": case.units.length,
        "unit_stress": case.units.stress,
        "unit_line_force": case.units.line_force,
        "bodies": f"A: {a.kind}, B: {b.kind}",
    }
    reference = {}
    similar = (
        effects_mod.cross_compliance(case) == 0.0
        and a.kind != "layered"
        and b.kind != "layered"
        and mu > 0.0
        and load > 0.0
    )
    if similar:
        reference["hertz_pressure"] = hertz.pressure(system.x, ref_a, ref_p0)
        ratio = float(np.clip(q / (mu * load), -1.0, 1.0))
        reference["carter_traction"] = carter.traction(system.x, ratio, ref_a, ref_p0, mu, case.rolling.direction)
        attrs["carter_creep"] = carter.creepage(ratio, ref_a, the_plan.radius, mu)
    return Result(
        x=system.x,
        weights=w,
        p_n=p_n,
        p_t=p_t,
        delta_n=system.gap(p_n, p_t, state.overlap),
        s_t=system.reported_slip(p_n, p_t, state.creep),
        state=states,
        attributes=attrs,
        history=history,
        reference=reference,
        case_toml=case_to_toml(case),
    )


def _free_creep(case: Case) -> float:
    kind, value = case.tangential.control()
    return value if kind == "creep" else 0.0
