"""The plan of a solve (pure, no solves): E*, R*, beta, the contact scale a, the contact grid and the
effects; the first guess of a; the contact system of a plan; one mesh level's record (:class:`Level`)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..adapt import graded
from ..case import Case
from ..case.given import given
from ..errors import CaseError, ConvergenceError, GrossSlidingError
from ..influence.build import pair_compliance
from ..model import materials
from ..model.friction import slip_friction
from ..model.grid import ContactGrid
from ..references import carter, hertz, thin_layer
from ..solver.formulation import State
from ..solver.initial import carter_ratio_for_creep, cold_start, effective_friction, effective_hertz
from ..solver.strategies import Controls, Solution
from ..solver.system import ContactSystem, abs_max, build_system
from . import effects as effects_mod

if TYPE_CHECKING:  # the adaptive levels are imported only with [discretization] tolerance (start-up)
    from ..adapt import levels as adaptive


@dataclass(frozen=True)
class Plan:
    """Derived quantities that fix the discretisation.

    ``modulus`` E* [stress], ``radius`` R* [length], ``beta_seed`` [-],
    ``half_width`` the contact scale a [length], ``measured`` whether a is known
    (Hertz, or measured by coarse solves) or only a first guess, ``p0`` [stress],
    ``load`` P or its estimate [force/length], ``coupling`` the measured
    coupling strength once the system is built [-].
    """

    modulus: float
    radius: float
    beta_seed: float
    half_width: float
    p0: float
    load: float
    grid: ContactGrid
    effects: effects_mod.Effects
    measured: bool = True
    coupling: float = 0.0


def plan(case: Case, half_width: float | None = None, check: bool = True) -> Plan:
    """Materials, contact scale a, contact grid and effects of a case. Pure: no solves.

    a is the Hertz half-width when the load is prescribed and both bodies are
    half-spaces; ``half_width`` overrides it (a measured value); otherwise it is
    :func:`first_guess` and the plan says ``measured = False``. The mesh rules
    (layer elements at most b/2) are checked on measured plans unless
    ``check=False`` (coarse pre-solves).
    """
    a, b = case.bodies.A, case.bodies.B
    e_star = materials.effective_modulus(a.modulus, a.ratio, b.modulus, b.ratio)
    r_star = materials.effective_radius(a.radius, b.radius)
    beta = materials.beta_seed(a.modulus, a.ratio, b.modulus, b.ratio)
    measured = True
    if half_width is None:
        if hertz_applies(case):
            half_width = hertz.half_width(given(case.normal.load, "normal.load"), r_star, e_star)
        else:
            half_width, measured = first_guess(case, e_star, r_star), False
    if case.normal.load is not None:
        load = float(case.normal.load)
    else:
        load = hertz.load_for_half_width(half_width, r_star, e_star)
    p0 = hertz.peak_pressure(load, half_width)
    disc = case.discretization
    order = 2 if disc.element == "quadratic" else 0
    grid = ContactGrid(disc.zone * half_width, disc.contact_elements, order)
    _check_arc(case, grid)
    if check and measured:
        _check_layer_elements(case, grid)
    return Plan(e_star, r_star, beta, half_width, p0, load, grid, effects_mod.decide(case), measured)


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


def _check_arc(case: Case, grid: ContactGrid) -> None:
    """A finite cylinder's mesh takes a potential zone of less than half its circumference
    (:func:`rolling_cli.influence.bem.cylinder.annulus_mesh`): beyond, the contact is not a rolling
    contact of cylinders any more."""
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        if body.shape == "cylinder" and not grid.half_width < 0.5 * np.pi * float(body.radius):
            raise CaseError(
                f"bodies.{label}.radius = {float(body.radius):g}: the potential contact zone (half-width "
                f"{grid.half_width:.4g}) reaches half the circumference of the finite cylinder; "
                "allowed: a smaller load or overlap, or a smaller discretization.zone",
                file=case.source,
                key=f"bodies.{label}.radius",
            )


def _layered(case: Case) -> bool:
    return case.bodies.A.kind == "layered" or case.bodies.B.kind == "layered"


def _viscoelastic(case: Case) -> bool:
    """A viscoelastic body: the Hertz start is off (narrower, shifted pressure), so large grids are
    sequenced like coupled ones (measured: rigid roller on an SLS flat, 800 elements, 16 -> 7 Newton
    iterations on the case grid)."""
    from ..model.viscoelastic import is_viscoelastic

    return is_viscoelastic(case.bodies.A) or is_viscoelastic(case.bodies.B)


def hertz_applies(case: Case) -> bool:
    """Hertz gives a and the pressure of the cold start: the load is prescribed on two half-spaces.
    Otherwise (layers, overlap control) the closed-form pressure is only a first approximation."""
    finite = case.bodies.A.shape == "cylinder" or case.bodies.B.shape == "cylinder"  # a is measured: stiffer bodies
    return case.normal.load is not None and not _layered(case) and not finite


def _settle_cold(case: Case) -> bool:
    """A closed-form start with no pre-solve level before it (a sweep's cold case on its prebuilt
    system, the retry of a failed warm start, a level after a failed one) has its pressure
    settled before friction enters on a layer under creepage control: there the Hertz
    pressure is off and Carter's traction for the creepage is full slip, and the coupled Newton
    cycled (tyred_fig11_q41, 21-point creep curve, --no-warm-start: 420 iterations, up to 46 a
    case; settled: 150, up to 8). Measured and not taken: settling every start whose pressure is
    not Hertz's (layers under load control 144 -> 170, paper_fig5_q075's overlap-controlled creep
    curve 83 -> 134)."""
    return _layered(case) and case.tangential.control()[0] == "creep"


def _sequenced_friction(case: Case) -> bool:
    """A velocity-dependent friction law: its solve starts on coarser grids (grid sequencing)."""
    return case.friction.law != "constant"


def _sequencing_elements(case: Case) -> int:
    """The smallest grid that is solved after a coarser one (:data:`SEQUENCING_ELEMENTS`,
    :data:`FRICTION_SEQUENCING_ELEMENTS` with a velocity-dependent friction law)."""
    return FRICTION_SEQUENCING_ELEMENTS if _sequenced_friction(case) else SEQUENCING_ELEMENTS


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
            b = given(body.layer_thickness, "layer_thickness")
            young, nu = body.modulus, given(body.poisson, "poisson")  # a viscoelastic layer's E_r: the widest
            thin = max(
                thin_layer.compressible_half_width(load, r_star, young, nu, b),
                thin_layer.incompressible_half_width(load, r_star, young, b),
            )
            guess = min(guess, thin)
        return guess
    incompressible = any(given(body.poisson, "poisson") >= 0.45 for body in layers)
    return thin_layer.half_width_for_overlap(given(case.normal.overlap, "normal.overlap"), r_star, incompressible)


def check_gross_sliding(case: Case) -> None:
    """|Q| >= mu P before any work, when P is known (exit code 2 in the CLI).

    Not for a finite cylinder: its P is the load on the shaft, while friction carries mu times the
    arc sum of the pressure (0.6-2.5 % away from P at a/R 0.2-0.3), known only once solved; the
    solver's own check (:func:`rolling_cli.solver.control.check_saturated`) uses the arc sum."""
    if case.bodies.A.finite or case.bodies.B.finite:
        return
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
    case: Case, the_plan: Plan, use_cache: bool = True, normal_only: bool = False
) -> tuple[ContactSystem, dict[str, str]]:
    """As :func:`build_contact_system`, plus where each body's influence came from; ``normal_only``
    for a frictionless normal solve (:func:`~rolling_cli.influence.build.pair_compliance`)."""
    disc = case.discretization
    if the_plan.grid.uniform or the_plan.effects.influence == "bem":  # the BEM keys a graded grid on its edges
        compliance, origin = pair_compliance(case, the_plan, use_cache, normal_only)
    else:  # a graded grid (adaptive levels) on the half-plane: outside the influence memo
        compliance, origin = graded.graded_compliance(case, the_plan), {"A": "closed form", "B": "closed form"}
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


def controls(case: Case, effects: effects_mod.Effects) -> Controls:
    """What the case prescribes, as the solver's :class:`Controls`."""
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


def initial_state(case: Case, the_plan: Plan, system: ContactSystem, effective_law: bool = False) -> State:
    """Cold start: Hertz pressure and Carter traction and creepage (see :mod:`rolling_cli.solver.initial`);
    with a viscoelastic body on half-spaces under a load, the Hertz pressure whose displacement
    fits the rigid profile (:func:`~rolling_cli.solver.initial.effective_hertz`: narrower and
    shifted towards the leading edge). With ``effective_law`` a decoupled case with a
    velocity-dependent friction law starts from Carter at the law's effective mu
    (:func:`~rolling_cli.solver.initial.effective_friction`; the mesh path's coarse grids)."""
    kind, value = case.tangential.control()
    ratio = float(np.clip(_initial_ratio(case, the_plan), -1.0, 1.0))
    creep = value if kind == "creep" else None
    half_width, centre = the_plan.half_width, 0.0
    if _viscoelastic(case) and hertz_applies(case):
        half_width, centre = effective_hertz(system, half_width, the_plan.load)
    mu = case.friction.mu
    friction = slip_friction(case)
    if effective_law and friction is not None and mu > 0.0 and the_plan.effects.strategy == "decoupled":
        # Carter at the law's effective mu (:func:`~rolling_cli.solver.initial.effective_friction`): its stick
        # zone is the law's within a few nodes (Carter's cylinders, 50 elements: 6-22 -> 5-8 Newton
        # iterations). Not with a coupling: on the dissimilar pair of tests/test_friction_laws.py the
        # coupled Newton took more iterations from it (50-200 elements, 12-33 -> 15-61). Only where
        # asked (the coarse grids): a cold start on a sweep's given system with Polach's law under force
        # control (tests/test_law_sensitivities.py) cycled from it as from mu_static's, and the fallbacks'
        # order of events then left the law path too little of the budget
        law, speed = friction.law, friction.speed
        mu_e = effective_friction(lambda s: float(law.mu(speed * s)), mu, half_width, the_plan.radius, ratio, creep)
        if kind == "creep":
            ratio = carter_ratio_for_creep(value, carter.full_slip_creepage(half_width, the_plan.radius, mu_e))
        else:
            ratio = float(np.clip(ratio * mu / mu_e, -1.0, 1.0))
        mu = mu_e
    return cold_start(system, half_width, the_plan.load, mu, ratio, creep, case.normal.overlap, centre)


@dataclass
class Level:
    """One mesh level of a solve: its case (a coarse frictionless one while a is measured), plan,
    contact system, the kind ("a-estimate", "coarse grid", "case grid", "enlarged zone", "refined
    mesh") and, once solved, its solution and Newton iterations."""

    kind: str
    case: Case
    plan: Plan
    system: ContactSystem | None = None
    origin: dict | None = None
    solution: Solution | None = None
    iterations: int = 0
    seconds: float = 0.0
    failure: ConvergenceError | None = None

    history: list[dict] | None = None
    fields: adaptive.LevelFields | None = None
    transferred: bool = False
    restart: State | None = None  # a warm-started level's closed-form start, tried if the warm one fails

    @property
    def solved(self) -> Solution:
        """The level's solution; RuntimeError before it is solved (or after it was released)."""
        if self.solution is None:
            raise RuntimeError(f"the {self.kind} level has no solution")
        return self.solution

    @property
    def built(self) -> ContactSystem:
        """The level's contact system; RuntimeError before it is built (or after it was released)."""
        if self.system is None:
            raise RuntimeError(f"the {self.kind} level has no contact system")
        return self.system

    @property
    def touches_edge(self) -> bool:
        """The solution presses on an end node of the zone; for a failed level, any iterate did."""
        if self.failure is not None:
            return any(row.get("edge") for row in self.history or [])
        return _contact_half_width(self.solved)[1]


#: Coarse pre-solve that measures a: contact elements, and potential zone / first guess of a.
PRESOLVE_ELEMENTS = 16


PRESOLVE_ZONE = 2.5


#: In the pre-solve, layer elements may be this many thicknesses long.
PRESOLVE_LAYER_ELEMENT = 2.0


#: Grid sequencing: a coupled half-plane solve with at least this many elements
#: starts from the solution on a grid with a quarter of the elements (and so on
#: down). Decoupled solves start well from Hertz and Carter already:
#: sequencing them costs more than it saves (benchmarks/RESULTS.md).
SEQUENCING_ELEMENTS = 240


#: With a falling friction law the stick zone is smaller than any Coulomb start's, and Newton moves
#: its boundary a few nodes an iteration (Carter, 200 elements, xi = -0.002: 15 iterations from
#: Carter's start); from the solution on a quarter of the elements it takes 1 + 4 on the case's grid,
#: plus 13 cheap ones on the coarse grid: the solve 2.5-5.3x -> 1.8-3.2x the Coulomb one
#: (benchmarks/bench_friction.py, benchmarks/RESULTS.md).
FRICTION_SEQUENCING_ELEMENTS = 100


#: A velocity-dependent law's coarse grids are solved to this relative residual only: their solution is
#: a start, and moved onto the next grid it has a residual of 0.05-0.09 there (Carter's cylinders, 200
#: elements) whatever the last coarse steps did. Measured on bench_friction's cases (200 and 400
#: elements): the same or fewer Newton iterations on the case grid, 1-3 fewer coarse ones, against
#: solving the coarse grid to the case's tolerance.
COARSE_LAW_TOLERANCE = 1e-3


def _presolve_needed(case: Case, guess: float, zone: float) -> int:
    """The pre-solve's elements that keep them :data:`PRESOLVE_LAYER_ELEMENT` layer thicknesses long
    (0 without a layer)."""
    thinnest = min(
        (given(b.layer_thickness, "layer_thickness") for b in (case.bodies.A, case.bodies.B) if b.kind == "layered"),
        default=math.inf,
    )
    return int(np.ceil(2.0 * zone * guess / (PRESOLVE_LAYER_ELEMENT * thinnest))) if thinnest < math.inf else 0


def presolve_set_by_layer(case: Case, guess: float, zone: float) -> bool:
    """Whether the pre-solve of :func:`presolve_case` has its element length set by the layer
    (:data:`PRESOLVE_LAYER_ELEMENT` thicknesses, up to the rounding of the element count), not by
    the guess: then another guess gives the same resolution."""
    return PRESOLVE_ELEMENTS <= _presolve_needed(case, guess, zone) <= PRESOLVE_MAX_ELEMENTS


def repeats_estimate(case: Case, guess: float, zone: float, measured: float) -> bool:
    """Whether the next a-estimate level (guess ``measured``, zone 1.6) can only repeat the width
    ``measured`` [length] of this one (guess ``guess`` [length], ``zone``) within the estimate's
    tolerance of two node spacings: both levels have their element length set by the layer
    (:func:`presolve_set_by_layer`), so the next one has this one's resolution up to the rounding
    of its element count (one element in 16 or more), and the contact lies inside its zone. The
    contact node count then moves by a node or two at most (through that rounding: at one element
    length the zone's size and the grid's parity move none, measured); the next level is skipped
    and this width kept (a thin cover, 60 elements: 12 of 90 ms; benchmarks/scan_estimate_skip.py
    for the answers that move, at the discretisation level)."""
    return presolve_set_by_layer(case, guess, zone) and presolve_set_by_layer(case, measured, 1.6)


#: The pre-solve's largest number of contact elements.
PRESOLVE_MAX_ELEMENTS = 400


def presolve_case(case: Case, guess: float, zone: float) -> Case:
    """The coarse frictionless normal case that measures a around the guess ``guess`` [length]."""
    needed = _presolve_needed(case, guess, zone)
    elements = int(min(max(PRESOLVE_ELEMENTS, needed), PRESOLVE_MAX_ELEMENTS))
    return dataclasses.replace(
        case,
        stresses=None,
        friction=dataclasses.replace(case.friction, mu=0.0),
        tangential=type(case.tangential)(),
        solver=dataclasses.replace(case.solver, penalty="auto"),
        discretization=dataclasses.replace(
            case.discretization, contact_elements=elements, zone=zone, slip_derivative="fd"
        ),
    )


def _contact_half_width(solution: Solution) -> tuple[float, bool]:
    """Measured contact half-width [length] (node cells included) and whether it touches the zone's ends."""
    system, p_n = solution.problem.system, solution.state.p_n
    contact = p_n < 0.0
    if not contact.any():
        return math.nan, True
    lo, hi = system.extent(contact)
    return 0.5 * (hi - lo), bool(contact[0] or contact[-1])


def _with_elements(case: Case, elements: int) -> Case:
    """``case`` on a uniform grid of ``elements`` contact elements."""
    return dataclasses.replace(case, discretization=dataclasses.replace(case.discretization, contact_elements=elements))


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
    return abs_max(system.B_tn, rows) / abs_max(system.B_tt, rows)


def _free_creep(case: Case) -> float:
    kind, value = case.tangential.control()
    return value if kind == "creep" else 0.0
