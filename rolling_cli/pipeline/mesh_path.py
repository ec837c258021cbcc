"""The mesh path: the continuation over mesh levels of one solve (a-estimate levels, coarse grids,
the case's grid, enlarged zones, adaptive refinements), each level warm-started from the previous one;
and the plan measured by it (:func:`measured_plan`, :func:`prepare`)."""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import time
from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from ..adapt import graded
from ..case import Case, case_to_dict
from ..case.given import given
from ..errors import ConvergenceError, ZoneError
from ..influence.build import clear_memo
from ..result import node_states
from ..solver import continuation, control, predictor, strategies
from ..solver.budget import Budget
from ..solver.formulation import State
from ..solver.strategies import Task
from ..solver.system import ContactSystem
from .corner import CORNER_BUDGET, corner_start, corner_zone
from .planning import (
    COARSE_LAW_TOLERANCE,
    LAYER_ELEMENT_FRACTION,
    PRESOLVE_ZONE,
    Level,
    Plan,
    _contact_half_width,
    _sequenced_friction,
    _sequencing_elements,
    _settle_cold,
    _viscoelastic,
    _with_elements,
    build_contact_system,
    build_contact_system_with_origin,
    controls,
    hertz_applies,
    initial_state,
    plan,
    presolve_case,
    repeats_estimate,
)

if TYPE_CHECKING:  # the adaptive levels are imported only with [discretization] tolerance (start-up)
    from ..adapt import levels as adaptive
log = logging.getLogger(__name__)


def measured_plan(case: Case, use_cache: bool = True) -> Plan:
    """The plan with a known contact scale: Hertz, or measured by :func:`estimate_half_width`."""
    the_plan = plan(case)
    if not the_plan.measured:
        the_plan = plan(case, half_width=estimate_half_width(case, use_cache))
    return the_plan


def prepare(case: Case, use_cache: bool = True) -> tuple[Plan, ContactSystem]:
    """The measured plan and its contact system (sweeps share them); a strongly coupled case's on
    the corner's zone (:func:`~rolling_cli.pipeline.corner.corner_zone`, as a solve alone takes it)."""
    the_plan = measured_plan(case, use_cache)
    zoned = corner_zone(case, the_plan)
    if zoned is not case:
        the_plan = plan(zoned, half_width=the_plan.half_width)
    return the_plan, build_contact_system(zoned, the_plan, use_cache)


#: Enlarging the potential zone: factor per step, and the largest zone / a.
ZONE_GROWTH = 1.5
ZONE_LIMIT = 8.0


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
        self.case = corner_zone(case, base)
        if self.case is not case:  # the same contact scale on the larger zone
            zoned = plan(self.case, half_width=base.half_width) if base.measured else plan(self.case)
            if system is None or system.x.shape == zoned.grid.x.shape:  # a given system: built by prepare
                base = zoned
            else:
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
                close = close or repeats_estimate(case, guess, zone, measured)  # the next level skipped
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
        if (
            previous.kind == "coarse grid"
            and level.plan.effects.strategy == "decoupled"
            and hertz_applies(level.case)
            and not _viscoelastic(level.case)
        ):
            # a falling friction law's sequence (decoupled): Hertz's pressure is the normal problem's own
            # start (the coarse one, interpolated, took 4 Newton iterations to settle on 200 elements);
            # the coarse traction and creepage carry the law's stick zone
            guess = initial_state(level.case, level.plan, self._system(level))
            guess.p_t, guess.creep = moved.p_t, moved.creep
            return guess, True, False
        # a viscoelastic body: the coarse pressure, its node states read from it (cold, as _refined_start;
        # SLS roller, 800 elements: 3 normal iterations on the case grid, 9 from Hertz's with E_r, 5 warm)
        return moved, _viscoelastic(level.case), False

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
        if level.kind == "coarse grid" and _sequenced_friction(level.case):
            task = dataclasses.replace(task, tolerance=max(task.tolerance, COARSE_LAW_TOLERANCE))
        if level.plan.grid.uniform or task.formulation == "normal":
            return task
        floor = graded.difference_roundoff(system, task.mu)
        return dataclasses.replace(task, tolerance=max(task.tolerance, floor)) if floor > task.tolerance else task

    def _system(self, level: Level) -> ContactSystem:
        if level.system is None:
            if level.kind == "refined mesh" and level.plan.grid.uniform:
                clear_memo()  # a refined level that came out uniform: keep no earlier level's influence in memory
            t0 = time.perf_counter()
            level.system, level.origin = build_contact_system_with_origin(  # a-estimate: frictionless, normal
                level.case, level.plan, self.use_cache, normal_only=level.kind == "a-estimate"
            )
            self.timings["influence"] += time.perf_counter() - t0
            log.info("%s: contact system of %d nodes, %.3f s", level.kind, level.system.size, time.perf_counter() - t0)
        return level.system

    def solve_at(self, number: float, start) -> tuple[Level, int]:
        """Solve one level from its predicted start on a fresh budget of solver.max_iterations.

        A refined level whose transferred start fails is solved once more from the closed form;
        if that fails too, the level is returned failed (the adaptive loop stops before it)."""
        level = self.levels[number]
        system = self._system(level)
        if start is None:  # the closed form (Carter at a falling law's effective mu on a coarse grid)
            cold = initial_state(level.case, level.plan, system, effective_law=level.kind == "coarse grid")
            start = cold, True, _settle_cold(level.case)
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
        corner = corner_start(level, system)
        budget = Budget(level.case.solver.max_iterations * (CORNER_BUDGET if corner is not None else 1))
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
                corner=corner,
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
