"""One solve, stage by stage: case -> plan -> influence -> contact system -> solver -> result.

* :func:`plan` (pure, no solves): E*, R*, beta, the contact scale a, the contact
  grid and the effects. a is the Hertz half-width when the load is prescribed
  on two half-spaces; otherwise a first guess from closed forms
  (:func:`first_guess`) that the mesh path measures.
* :func:`build_contact_system`: the influence (closed form or BEM) and the
  linear rolling system of a plan.
* :func:`solve`: walks the **mesh path** with the continuation driver
  (:func:`rolling_cli.solver.continuation.follow`): levels that measure a by
  coarse frictionless solves (overlap control, layers), coarse grids for large
  coupled half-plane grids (grid sequencing), the case's own grid, and larger
  zones while the contact reaches the zone's edge, and with
  ``discretization.tolerance`` the adaptive levels (:mod:`rolling_cli.adapt.levels`:
  refined meshes until the error estimate meets the tolerance or a cap). Each
  level starts from the previous level's solution moved onto its grid (an
  explicit transfer), the first from Hertz and Carter
  (:mod:`rolling_cli.solver.initial`). Each level's solve runs the solver
  strategies (:mod:`rolling_cli.solver.strategies`) on its own iteration
  budget, ``solver.max_iterations``.
* :func:`assemble`: the :class:`~rolling_cli.result.Result`.

Sweeps reuse the expensive stages: :func:`prepare` gives the plan and the
contact system of a case (influences are memoised, BEM ones cached on disk,
measured half-widths memoised), and :func:`solve` accepts a prebuilt system and
a warm start.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._version import __version__
from ..adapt import graded
from ..case import Case, case_to_dict, case_to_toml, load_case
from ..case.given import given
from ..errors import CaseError, ConvergenceError, GrossSlidingError, ZoneError
from ..influence.build import clear_memo, pair_compliance
from ..influence.finite import shaft_quantities
from ..model import materials
from ..model.grid import ContactGrid
from ..model.validity import half_space_check
from ..references import carter, hertz, thin_layer
from ..result import Result, node_states, utc_timestamp
from ..solver import continuation, control, formulation, predictor, strategies
from ..solver.budget import Budget
from ..solver.formulation import State
from ..solver.initial import carter_ratio_for_creep, cold_start
from ..solver.strategies import Controls, Solution, StrategyFailed, Task
from ..solver.system import ContactSystem, abs_max, build_system
from ..stresses import power
from . import effects as effects_mod
from .resources import check_resources

if TYPE_CHECKING:  # the adaptive levels are imported only with [discretization] tolerance (start-up)
    from ..adapt import levels as adaptive

log = logging.getLogger(__name__)


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


def measured_plan(case: Case, use_cache: bool = True) -> Plan:
    """The plan with a known contact scale: Hertz, or measured by :func:`estimate_half_width`."""
    the_plan = plan(case)
    if not the_plan.measured:
        the_plan = plan(case, half_width=estimate_half_width(case, use_cache))
    return the_plan


def prepare(case: Case, use_cache: bool = True) -> tuple[Plan, ContactSystem]:
    """The measured plan and its contact system (sweeps share them)."""
    the_plan = measured_plan(case, use_cache)
    return the_plan, build_contact_system(case, the_plan, use_cache)


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
    return case.bodies.A.kind == "viscoelastic" or case.bodies.B.kind == "viscoelastic"


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
            young, nu = given(body.young, "young"), given(body.poisson, "poisson")
            thin = max(
                thin_layer.compressible_half_width(load, r_star, young, nu, b),
                thin_layer.incompressible_half_width(load, r_star, young, b),
            )
            guess = min(guess, thin)
        return guess
    incompressible = any(given(body.poisson, "poisson") >= 0.45 for body in layers)
    return thin_layer.half_width_for_overlap(given(case.normal.overlap, "normal.overlap"), r_star, incompressible)


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
    if the_plan.grid.uniform or the_plan.effects.influence == "bem":  # the BEM keys a graded grid on its edges
        compliance, origin = pair_compliance(case, the_plan, use_cache)
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


def initial_state(case: Case, the_plan: Plan, system: ContactSystem) -> State:
    """Cold start: Hertz pressure and Carter traction and creepage (see :mod:`rolling_cli.solver.initial`)."""
    kind, value = case.tangential.control()
    ratio = float(np.clip(_initial_ratio(case, the_plan), -1.0, 1.0))
    creep = value if kind == "creep" else None
    return cold_start(system, the_plan.half_width, the_plan.load, case.friction.mu, ratio, creep, case.normal.overlap)


# --- the mesh path --------------------------------------------------------------------------------


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
#: Enlarging the potential zone: factor per step, and the largest zone / a.
ZONE_GROWTH = 1.5
ZONE_LIMIT = 8.0
#: mu |beta_Dundurs| above which the coupling is strong, and |beta_Dundurs| / mu above which the
#: friction is tiny against it (both named in failure messages).
STRONG_COUPLING = 0.6
TINY_FRICTION = 1e3


def presolve_case(case: Case, guess: float, zone: float) -> Case:
    """The coarse frictionless normal case that measures a around the guess ``guess`` [length]."""
    thinnest = min(
        (given(b.layer_thickness, "layer_thickness") for b in (case.bodies.A, case.bodies.B) if b.kind == "layered"),
        default=math.inf,
    )
    needed = int(np.ceil(2.0 * zone * guess / (PRESOLVE_LAYER_ELEMENT * thinnest))) if thinnest < math.inf else 0
    elements = int(min(max(PRESOLVE_ELEMENTS, needed), 400))
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


class MeshPath:
    """The mesh levels of one solve, walked by the continuation driver (module docstring).

    :meth:`targets` is the path: a generator of level numbers that decides the
    next level from the solved ones (``points``): the a-estimate levels while a
    moves by more than two coarse node spacings (the coarse zone doubles when the
    contact reaches its ends), the coarse grid levels, the case's grid, then
    larger zones while the contact reaches the zone's edge, and with a
    ``discretization.tolerance`` the refined meshes of :mod:`rolling_cli.adapt.levels`
    (:meth:`refined_levels`). ``estimates_only`` stops after the a-estimate levels
    (:func:`estimate_half_width`).
    """

    def __init__(
        self,
        case: Case,
        base: Plan,
        system: ContactSystem | None = None,
        start: State | None = None,
        use_cache: bool = True,
        estimates_only: bool = False,
        compare_start: bool = False,
    ) -> None:
        self.case = case
        self.base = base
        self.given = system
        self.start = start
        self.use_cache = use_cache
        self.estimates_only = estimates_only
        self.levels: dict[float, Level] = {}
        self.points: list[tuple[float, Level | None]] = [(0.0, None)]
        self.history: list[dict] = []
        self.timings = {"influence": 0.0, "solve": 0.0}
        self.measured_half_width = base.half_width
        self.warm = False
        self.start_traction = ""
        self.compare_start = compare_start
        self.adaptation: adaptive.Adaptation | None = None

    @property
    def last(self) -> Level:
        """The level solved last (the path asks for the next level only after solving one)."""
        level = self.points[-1][1]
        if level is None:
            raise RuntimeError("no mesh level has been solved yet")
        return level

    def _announce(self, level: Level) -> float:
        number = float(len(self.levels) + 1)
        self.levels[number] = level
        return number

    def targets(self) -> Iterator[float]:
        """The level numbers of the path (see the class docstring)."""
        case, base = self.case, self.base
        if not base.measured and self.given is None:
            guess, zone = base.half_width, PRESOLVE_ZONE
            for _ in range(6):
                coarse = presolve_case(case, guess, zone)
                yield self._announce(Level("a-estimate", coarse, plan(coarse, half_width=guess, check=False)))
                last = self.last
                measured, touches = _contact_half_width(last.solved)
                if touches:
                    zone *= 2.0
                    continue
                close = abs(measured - guess) <= 2.0 * last.built.spacing
                guess, zone = measured, 1.6
                if close:
                    break
            self.measured_half_width = guess
            if self.estimates_only:
                return
            base = plan(case, half_width=guess)
        disc = case.discretization
        if (
            self.given is None
            and base.effects.influence == "half-plane"
            and (base.effects.strategy == "coupled" or _sequenced_friction(case) or _viscoelastic(case))
            and disc.contact_elements >= _sequencing_elements(case)
        ):
            coarse_elements = []
            elements = disc.contact_elements
            while elements >= _sequencing_elements(case):
                elements //= 4
                coarse_elements.append(elements)
            for elements in reversed(coarse_elements):
                coarse = dataclasses.replace(
                    case, discretization=dataclasses.replace(disc, contact_elements=elements), stresses=None
                )
                yield self._announce(Level("coarse grid", coarse, plan(coarse, half_width=base.half_width)))
        yield self._announce(Level("case grid", case, base, self.given))
        while True:
            last = self.last
            if not last.touches_edge:
                break
            zone = last.case.discretization.zone * ZONE_GROWTH
            if zone > ZONE_LIMIT * (1.0 + 1e-9):
                return
            log.warning(
                "the contact reached the edge of the potential zone %.4g a; solving again with %.4g a",
                last.case.discretization.zone,
                zone,
            )
            # the same element length on the larger zone: the resolution the case asked for (and a layer's
            # elements stay at most b/2 long)
            elements = int(math.ceil(case.discretization.contact_elements * zone / case.discretization.zone - 1e-9))
            grown = dataclasses.replace(
                case, discretization=dataclasses.replace(case.discretization, zone=zone, contact_elements=elements)
            )
            yield self._announce(Level("enlarged zone", grown, plan(grown, half_width=last.plan.half_width)))
        if case.discretization.tolerance is not None:
            yield from self.refined_levels()

    def refined_levels(self) -> Iterator[float]:
        """The adaptive levels: while :class:`~rolling_cli.adapt.levels.Adaptation` asks for a
        finer grid, a level on it: the last level's plan on a graded grid (either influence model;
        on a layer no element longer than :data:`LAYER_ELEMENT_FRACTION` of its thickness). A refined
        level that does not converge ends the loop; the result is then the previous level's."""
        disc = self.case.discretization
        last = self.last
        from ..adapt import levels as adaptive

        layers = [
            given(b.layer_thickness, "layer_thickness")
            for b in (self.case.bodies.A, self.case.bodies.B)
            if b.kind == "layered"
        ]
        largest = LAYER_ELEMENT_FRACTION * min(layers) if layers else None
        bem = last.plan.effects.influence == "bem"
        most = adaptive.MAX_BEM_ELEMENTS if bem else adaptive.MAX_ELEMENTS
        self.adaptation = adaptive.Adaptation(
            given(disc.tolerance, "discretization.tolerance"), disc.max_refinements, largest, most, fits=self._fits
        )
        while True:
            last = self.last
            if last.failure is not None:
                previous = self.adaptation.history[-1]
                self.adaptation.note = (
                    f"tolerance {disc.tolerance:g} not met: the refined mesh of {last.plan.grid.elements} contact "
                    f"elements did not converge ({last.failure}); the result is the previous mesh's, estimate "
                    f"{previous['estimate']:.3g} at {previous['elements']} elements"
                )
                return
            grid = self.adaptation.next_grid(self._fields(last))
            if grid is None:
                return
            for number, level in self.levels.items():  # only the last level is still needed
                if level is not last and number > 0:
                    level.system = level.solution = None
            yield self._announce(Level("refined mesh", last.case, dataclasses.replace(last.plan, grid=grid)))

    def _fields(self, level: Level) -> adaptive.LevelFields:
        """The nodal fields of a solved level that the adaptive decision and transfer use."""
        if level.fields is None:
            from ..adapt import levels as adaptive

            state, system, mu = level.solved.state, level.built, level.case.friction.mu
            stick = level.solved.stick
            if not level.plan.effects.tangential and mu > 0.0:
                stick = state.p_n < 0.0  # p_t = 0, xi = 0: every contact node adheres (as assemble)
            level.fields = adaptive.LevelFields(
                level.plan.grid,
                state.p_n,
                state.p_t,
                system.gap(state.p_n, state.p_t, state.overlap),
                node_states(state.p_n, stick),
                float(state.overlap),
                float(state.creep),
                mu,
                level.iterations,
                level.seconds,
            )
        return level.fields

    def _fits(self, elements: int) -> str:
        """Why a level of ``elements`` contact elements cannot be solved here ("" when it can)."""
        from .resources import available_memory, estimate, format_bytes

        needed = estimate(_with_elements(self.case, elements)).bytes
        available = available_memory()
        if available is not None and needed > available:
            return f"about {format_bytes(needed)} of memory, more than the {format_bytes(available)} available"
        return ""

    def predict(self, points: list, number: float) -> tuple[State, bool, bool] | None:
        """The start of a level: (state, cold, settle), or None for the closed-form cold start.

        A given warm start is used; with ``compare_start`` only when its residual
        merit is below that of the closed-form cold start (a neighbour's plain copy
        can be worse than Carter's solution). A level after another starts from its solution moved onto the
        new grid (warm, except after a frictionless a-estimate level, whose
        pressure and overlap then replace those of the cold start).
        """
        previous, level = points[-1][1], self.levels[number]
        if level.kind == "refined mesh":
            return self._refined_start(previous, level)
        if previous is not None and previous.failure is not None:
            previous = None  # after a failed level (a zone too small): a cold start
        if previous is None:
            start, system = self.start, level.system
            if (
                start is not None
                and level.kind == "case grid"
                and system is not None
                and start.p_n.shape == system.x.shape
            ):
                t0 = time.perf_counter()
                try:
                    return self._warm_start(level)
                finally:  # choosing the start is solver work: in the result's time_solve
                    self.timings["solve"] += time.perf_counter() - t0
            return None
        x_to = level.plan.grid.x
        moved = predictor.transfer(previous.solved.state, previous.built.x, x_to, level.case.friction.mu)
        if previous.kind == "a-estimate" and level.kind != "a-estimate":
            guess = initial_state(level.case, level.plan, self._system(level))
            guess.p_n, guess.overlap = moved.p_n, moved.overlap
            return guess, True, True
        if previous.kind == "coarse grid" and level.plan.effects.strategy == "decoupled" and hertz_applies(level.case):
            # a falling friction law's sequence (decoupled): Hertz's pressure is the normal problem's own
            # start (the coarse one, interpolated, took 4 Newton iterations to settle on 200 elements);
            # the coarse traction and creepage carry the law's stick zone
            guess = initial_state(level.case, level.plan, self._system(level))
            guess.p_t, guess.creep = moved.p_t, moved.creep
            return guess, True, False
        return moved, False, False

    def _warm_start(self, level: Level) -> tuple[State, bool, bool] | None:
        """The given warm start, or that start with Carter's closed-form traction and creepage in
        place of its own where this has the smaller residual merit, or (with ``compare_start``)
        None for the cold start where that is better still. The cold start is kept as the
        level's ``restart``: the solver tries it next if the warm start fails.

        The closed-form traction matters where the cold start is nearly exact: on a load
        curve of similar cylinders Carter's traction has the discrete solution's stick and slip
        nodes but for one or two, while the secant of the neighbours misplaces the stick/slip
        boundary near full slip, where it moves like the square root of 1 - Q/(mu P) (carter,
        ``rollc sweep --curve load``, 41 points: 87 Newton iterations all cold, 84 with the
        neighbours' traction alone, 56 with the better of the two, the warm-started cases
        1.07 a case). The pressure and overlap stay the neighbours': along a load curve they
        are the converged ones."""
        case, system, start = level.case, level.built, self.start
        if start is None:
            return None
        task = _task(case, level.plan, system)
        candidates = [start]
        cold = initial_state(case, level.plan, system)
        if case.friction.mu > 0.0:
            candidates.append(predictor.with_traction(start, cold, case.friction.mu))
        if self.compare_start:
            candidates.append(cold)
        merits = [strategies.merit(task, state) for state in candidates] if len(candidates) > 1 else [0.0]
        best = int(np.argmin(merits))  # ties: the first, the neighbours' own start
        if self.compare_start and best == len(candidates) - 1:
            return None
        self.warm = True
        self.start_traction = "closed form" if best == 1 else "neighbours"
        level.restart = cold  # should the warm start fail
        return candidates[best], False, False

    def _refined_start(self, previous: Level, level: Level) -> tuple[State, bool, bool]:
        """A refined level's start: the previous solution transferred onto its grid, or the
        closed-form start where that has the smaller residual merit. Either way the first node
        states are read from the pressure (``cold``): a transferred pressure is not in equilibrium
        with the new grid's gap, whose sign beyond the contact edges would put dozens of the fine
        nodes there in contact, and Newton sheds surplus contact nodes only a few per iteration
        (measured on the dissimilar case at tolerance 1e-4: 41-76 iterations per fine level with
        the projected states, 1-5 with the pressure's)."""
        from ..adapt import levels as adaptive

        warm = adaptive.transferred_state(self._fields(previous), level.plan.grid)
        cold = initial_state(level.case, level.plan, self._system(level))
        task = self._task(level, level.built)
        level.transferred = strategies.merit(task, warm) <= strategies.merit(task, cold)
        return (warm if level.transferred else cold), True, False

    @staticmethod
    def _task(level: Level, system: ContactSystem) -> Task:
        """The solver task of a level; on a graded level its tolerance is at least the rounding floor
        of the slip differences over its smallest elements (:func:`.adapt.graded.difference_roundoff`)."""
        task = _task(level.case, level.plan, system)
        if level.plan.grid.uniform or task.formulation == "normal":
            return task
        floor = graded.difference_roundoff(system, task.mu)
        return dataclasses.replace(task, tolerance=max(task.tolerance, floor)) if floor > task.tolerance else task

    def _system(self, level: Level) -> ContactSystem:
        if level.system is None:
            if level.kind == "refined mesh" and level.plan.grid.uniform:
                clear_memo()  # a refined level that came out uniform: keep no earlier level's influence in memory
            t0 = time.perf_counter()
            level.system, level.origin = build_contact_system_with_origin(level.case, level.plan, self.use_cache)
            self.timings["influence"] += time.perf_counter() - t0
            log.info("%s: contact system of %d nodes, %.3f s", level.kind, level.system.size, time.perf_counter() - t0)
        return level.system

    def solve_at(self, number: float, start) -> tuple[Level, int]:
        """Solve one level from its predicted start on a fresh budget of solver.max_iterations.

        A refined level whose transferred start fails is solved once more from the closed form;
        if that fails too, the level is returned failed (the adaptive loop stops before it)."""
        level = self.levels[number]
        system = self._system(level)
        if start is None:  # the closed form
            start = initial_state(level.case, level.plan, system), True, _settle_cold(level.case)
        taken = self._attempt(level, system, *start)
        if level.failure is not None and level.kind == "refined mesh" and level.transferred:
            level.failure, level.transferred = None, False
            taken += self._attempt(level, system, initial_state(level.case, level.plan, system), True, False)
        level.iterations = taken
        return level, taken

    def _attempt(self, level: Level, system: ContactSystem, state: State, cold: bool, settle: bool) -> int:
        """One solve of ``level`` from ``state``; sets its solution, or its failure when that is a
        re-mesh event (a zone too small) or a refined level; raises :class:`_LevelFailed` otherwise.
        Returns the Newton iterations taken."""
        task = self._task(level, system)
        budget = Budget(level.case.solver.max_iterations)
        t0 = time.perf_counter()
        try:
            restart, level.restart = level.restart, None
            level.solution = control.solve(
                task,
                state,
                budget,
                cold=cold,
                settle=settle,
                restart=restart,
                restart_settle=restart is not None and _settle_cold(level.case),
            )
        except ConvergenceError as err:
            level.failure, level.history = err, budget.history
            remesh_event = level.kind in ("case grid", "enlarged zone") and level.touches_edge
            if not remesh_event and level.kind != "refined mesh":
                raise _LevelFailed(level, err) from None
        finally:
            for row in budget.history:
                row["level"] = level.kind
            self.history.extend(budget.history)
            level.iterations = budget.taken
            level.seconds += time.perf_counter() - t0
            self.timings["solve"] += time.perf_counter() - t0
            if log.isEnabledFor(logging.INFO):  # rollc -v: each level's start, strategies and time
                log.info(
                    "%s (%s start): %d Newton iterations (%s), %.3f s, %s", level.kind, "cold" if cold else "warm",
                    budget.taken, ", ".join(budget.strategies()) or "-", time.perf_counter() - t0,
                    "converged" if level.failure is None else f"failed: {level.failure}",
                )  # fmt: skip
        return budget.taken

    def run(self) -> Level:
        """Walk the path; returns the last level. Raises :class:`_LevelFailed` (via its cause)."""
        try:
            continuation.follow(self.targets(), self.solve_at, self.predict, self.points, failure=_LevelFailed)
        except continuation.ContinuationFailed as err:
            if err.__cause__ is None:
                raise
            raise err.__cause__ from None
        final = self.last
        if final.kind == "refined mesh" and final.failure is not None:  # the last converged level
            final = next(level for _, level in reversed(self.points[1:]) if level is not None and level.failure is None)
        return final


def solve(
    case: Case | str | dict,
    *,
    start: State | None = None,
    system: ContactSystem | None = None,
    keep_failed: bool = False,
    use_cache: bool = True,
    compare_start: bool = False,
) -> Result:
    """Solve a case (a :class:`Case`, a case-file path or a TOML dict); return a :class:`Result`.

    ``start`` is a warm start on the case's own grid (a converged or predicted
    neighbour; with ``compare_start`` it is used only when its residual is below
    the cold start's), ``system`` a prebuilt contact system for this case (sweeps
    reuse it). Raises :class:`ConvergenceError`, :class:`ZoneError` or
    :class:`GrossSlidingError`; with ``keep_failed=True`` a failed solve returns
    its best iterate marked ``converged = False`` instead of raising.
    """
    if not isinstance(case, Case):
        case = load_case(case)
    t0 = time.perf_counter()
    check_gross_sliding(case)
    if system is None:
        check_resources(case)  # refuse what will not fit before allocating anything
    base = measured_plan(case, use_cache) if system is not None else plan(case)
    for warning in base.effects.warnings:
        log.warning(warning)
    path = MeshPath(case, base, system, start, use_cache, compare_start=compare_start)
    try:
        final = path.run()
    except _LevelFailed as failed:
        return _failure(failed.level, failed.error, path, keep_failed)
    if final.failure is not None:
        return _failure(final, final.failure, path, keep_failed)
    if final.touches_edge:
        raise _zone_error(final)
    result = assemble(final, path.history, path.timings)
    if final.case.discretization.zone != case.discretization.zone:
        result.attributes["zone_note"] = (
            f"discretization.zone enlarged from {case.discretization.zone:g} to {final.case.discretization.zone:g} "
            f"(contact_elements {case.discretization.contact_elements} to "
            f"{final.case.discretization.contact_elements}, the same element length): the contact reached the "
            "edge of the requested zone"
        )
    if path.adaptation is not None:
        result.attributes.update(path.adaptation.attributes(final.plan.grid))
        disc = dataclasses.replace(final.case.discretization, contact_elements=case.discretization.contact_elements)
        result.case_toml = case_to_toml(dataclasses.replace(final.case, discretization=disc))
        if not path.adaptation.met:
            log.warning("%s", path.adaptation.note)
    result.attributes["time_total_solve"] = time.perf_counter() - t0
    result.attributes["start"] = "warm" if path.warm else "cold"
    if path.warm:
        result.attributes["start_traction"] = path.start_traction
    result.attributes["iterations_total"] = int(sum(level.iterations for level in path.levels.values()))
    if case.solver.branch != "auto" and result.converged:
        from .branches import on_branch

        result = on_branch(case, result, solve, prepare)
    return _attach_stresses(final.case, final.plan, result)


def _with_elements(case: Case, elements: int) -> Case:
    """``case`` on a uniform grid of ``elements`` contact elements."""
    return dataclasses.replace(case, discretization=dataclasses.replace(case.discretization, contact_elements=elements))


def _attach_stresses(case: Case, the_plan: Plan, result: Result) -> Result:
    """The subsurface stresses the case asks for (nothing is imported without a [stresses] table)."""
    if case.stresses is None:
        return result
    from ..stresses import attach

    return attach(case, the_plan, result)


class _LevelFailed(Exception):
    """A mesh level did not converge (carries the level and its ConvergenceError)."""

    def __init__(self, level: Level, error: ConvergenceError) -> None:
        self.level = level
        self.error = error
        self.reason = str(error)
        self.residual = error.residual if error.residual is not None else math.nan
        super().__init__(self.reason)


def _task(case: Case, the_plan: Plan, system: ContactSystem) -> Task:
    from ..model.friction import slip_friction

    return Task(
        system,
        case.friction.mu,
        controls(case, the_plan.effects),
        case.solver.tolerance,
        the_plan.effects.strategy,
        slip_friction(case),
    )


def _zone_error(level: Level) -> ZoneError:
    x, p_n = level.built.x, level.solved.state.p_n
    contact = p_n < 0.0
    return ZoneError(
        "the contact reaches the edge of the potential contact zone, so the answer is wrong",
        residual=level.solved.evaluation.relative_residual,
        iterations=level.iterations,
        cause="discretization.zone is too small for this load; enlarge it "
        f"(contact covers x = {x[contact].min():.4g} .. {x[contact].max():.4g}, zone {x[0]:.4g} .. {x[-1]:.4g})",
    )


def _failure(level: Level, err: ConvergenceError, path: MeshPath, keep_failed: bool) -> Result:
    """A failed level: a ZoneError when its best iterate presses on the zone's ends, else the
    ConvergenceError (naming the level, and strong coupling where it applies); or, with
    ``keep_failed``, the best iterate as a result marked not converged."""
    partial = err.partial
    if partial is not None and (partial.p_n[0] < 0.0 or partial.p_n[-1] < 0.0):
        raise ZoneError(
            "the contact reaches the edge of the potential contact zone during the iteration",
            residual=err.residual,
            iterations=err.iterations,
            cause="discretization.zone is too small for this case; enlarge it",
        ) from err
    cause = err.cause
    beta, mu = abs(0.5 * level.plan.beta_seed), level.case.friction.mu
    if beta * mu > STRONG_COUPLING:
        cause += f"; the normal-tangential coupling is strong (mu |beta_Dundurs| = {beta * mu:.2f})"
    elif mu > 0.0 and beta > TINY_FRICTION * mu:
        cause += (
            f"; friction is tiny against the coupling (|beta_Dundurs| / mu = {beta / mu:.3g}): the adhesion zone is "
            "narrower than a node, so Q(xi) is a staircase; refine the mesh or raise solver.max_iterations"
        )
    where = {
        "a-estimate": " in the frictionless pre-solve that measures the contact half-width",
        "coarse grid": " on a coarse grid",
    }.get(level.kind, "")
    message = str(err).split(", relative residual")[0].replace("did not converge", "did not converge" + where, 1)
    err = ConvergenceError(
        message, residual=err.residual, iterations=err.iterations, history=path.history, cause=cause, partial=partial
    )
    if not keep_failed or partial is None or level.kind not in ("case grid", "enlarged zone"):
        raise err
    task = _task(level.case, level.plan, level.built)
    problem = task.problem(task.full_mode)
    prepared = task.prepared(partial)
    ev = formulation.evaluate(problem, prepared, formulation.traction_scales(problem, prepared))
    ev.stick[:] = False
    level.solution = Solution(prepared, ev, problem)
    result = assemble(level, path.history, path.timings, converged=False)
    result.attributes["message"] = str(err)
    return _attach_stresses(level.case, level.plan, result)


_estimates: dict[str, float] = {}


def estimate_half_width(case: Case, use_cache: bool = True) -> float:
    """The contact scale a [length] measured by the a-estimate levels of the mesh path (memoised:
    sweeps vary friction and loads around one model)."""
    data = case_to_dict(case)
    key = json.dumps(
        {k: data.get(k) for k in ("bodies", "normal", "discretization", "solver")}, sort_keys=True, default=str
    )
    if key not in _estimates:
        if len(_estimates) > 64:
            _estimates.clear()
        path = MeshPath(case, plan(case), use_cache=use_cache, estimates_only=True)
        path.run()
        _estimates[key] = float(path.measured_half_width)
    return _estimates[key]


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


def _linear_solver_attributes(system: ContactSystem, history: list[dict]) -> dict:
    """``linear_solver`` and, matrix-free, this solve's Krylov counts from its Newton history
    (:func:`.solver.matrix_free.result_attributes`)."""
    if not system.matrix_free:
        return {"linear_solver": system.linear_solver}
    from ..solver import matrix_free

    return matrix_free.result_attributes(system, history)


def assemble(level: Level, history: list[dict], timings: dict, converged: bool = True) -> Result:
    """The :class:`Result` of a solved level: arrays, loads, zones, references and provenance."""
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
    attrs.update(_friction_attributes(case, solution if effects.tangential and converged else None))
    attrs.update(_sensitivities(case, system, state, converged, half_width))
    attrs.update(shaft_quantities(case, system.x, w, p_n, p_t, centre, half_width))  # finite cylinders (else NaN)
    visco = a.kind == "viscoelastic" or b.kind == "viscoelastic"
    if visco:  # rolling resistance, pressure shift, hysteresis (nothing for an elastic case)
        from ..model import resistance

        attrs.update(resistance.attributes(case, system, p_n, p_t, the_plan.radius))
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
    half-spaces, exactly decoupled, with friction and a load), at the solved load [force/length]
    and Q; Carter's creepage goes into ``attrs``. Nothing otherwise."""
    a, b = case.bodies.A, case.bodies.B
    mu = case.friction.mu
    similar = (
        effects_mod.cross_compliance(case) == 0.0
        and a.kind not in ("layered", "viscoelastic")
        and b.kind not in ("layered", "viscoelastic")
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


def _friction_attributes(case: Case, solution: Solution | None = None) -> dict:
    """The velocity-dependent friction law's record (nothing for Coulomb friction, whose files
    stay as they were): its name, mu_kinetic, the rolling speed and the time unit; for a solved
    tangential problem the slope dQ/dxi of the creep-force curve at the solution (node states
    held: :func:`~rolling_cli.solver.reduced.creep_sensitivity`, d mu/d s_a included) and the
    branch it puts the point on: "rising" (dQ/dxi < 0: Q grows with |xi|, the stable side of the
    curve's peak) or "falling"."""
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

        held = solution.problem.held(force=None)
        state = solution.state
        try:
            ev = formulation.evaluate(held, state, formulation.traction_scales(held, state))
            slope = reduced.creep_sensitivity(held, state, ev)
        except (np.linalg.LinAlgError, ValueError):  # a singular system: no slope recorded
            return out
        out["creep_slope"] = float(slope)
        out["branch"] = "rising" if slope < 0.0 else "falling"
    return out


def _sensitivities(case: Case, system: ContactSystem, state: State, converged: bool, half_width: float) -> dict:
    """The derivatives of a converged solve (:mod:`rolling_cli.solver.sensitivity`) and their time;
    NaN for a failed one (its state is no solution) or a singular final matrix (a warning).

    Not with a velocity-dependent friction law: its slip rows carry the d mu/d s_a term that the
    sensitivity rows do not (NaN, said at debug level). The load homogeneity that gives the
    P-derivatives of half-space pairs does not hold for a viscoelastic body (its time scale
    tau V / a changes with the load), and the fixed-state ones miss the motion of the contact
    edges (3.7 % on dxi/dP of cases/rubber_roller-like SLS case against central differences of
    re-solves): a viscoelastic case records no P-derivatives (NaN)."""
    from ..model import viscoelastic
    from ..model.friction import from_case
    from ..solver import sensitivity

    t0 = time.perf_counter()
    found = sensitivity.UNDEFINED
    if from_case(case.friction, case.rolling).velocity_dependent:
        log.debug("no sensitivities: the friction law depends on the slip speed")
        converged = False
    if converged:
        force = case.tangential.control()[0] != "creep"
        try:
            similar = hertz_applies(case)
            found = sensitivity.sensitivities(system, case.friction.mu, state, force, similar, half_width)
        except np.linalg.LinAlgError as err:
            log.warning("no sensitivities: the final Newton matrix is singular (%s)", err)
    out = found.as_dict()
    if viscoelastic.bodies(case):
        out.update(dict.fromkeys(("dQ_dP", "dxi_dP", "da_dP", "dp0_dP"), math.nan))
    return {**out, "time_sensitivities": time.perf_counter() - t0}


def _free_creep(case: Case) -> float:
    kind, value = case.tangential.control()
    return value if kind == "creep" else 0.0


__all__ = [
    "Plan",
    "plan",
    "prepare",
    "solve",
    "assemble",
    "build_contact_system",
    "check_gross_sliding",
    "estimate_half_width",
    "StrategyFailed",
]
