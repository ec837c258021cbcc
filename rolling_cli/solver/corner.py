"""The strongly coupled corner (mu |beta_Dundurs| near 1 and above): a creepage path from xi = 0.

Measured on issue 23's case (mu |beta| = 1.09, benchmarks/RESULTS.md "The strongly coupled corner:
why creepage control failed, and the fix"): the contact moves far from the closed-form start there
(from [-1.08, 0.73] a at xi = 0 to [-1.76, 0.53] a near full slip, against Hertz's [-1, 1] a), and
the generalised Newton from the Hertz/Carter start passes through fragmented node states (contact
with holes, isolated adhesion nodes inside the slip zone) whose Newton points raise the merit up to
ten thousand times; the line searches then stall. From the converged neighbour one creepage step
away the same Newton converges in about six iterations. :func:`creep_path` therefore walks the
creepage from 0 (where the closed-form start converges) to the task's, each step from the last
solution (the boundary-secant predictor of the other paths was measured worse here: 2 of 11 creepages
against 11 of 11 on 104 coarse elements), by the continuation driver that the coupling path uses.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np

from . import continuation, strategies
from .budget import Budget
from .formulation import State
from .task import Solution, StrategyFailed, Task

#: mu |beta_Dundurs| above which a cold start under creepage control walks the creepage path first
#: (and a warm one tries :data:`NEWTON` and :func:`nudged` first). At mu |beta| = 0.6 the usual chain
#: converges alone and cheaper (issue 23's bodies with mu = 1.229, 21 creepages: 751 iterations;
#: 2199 with the path), at 1.09 it does not (15 of 41: benchmarks/RESULTS.md).
STRONG = 1.0


def applies(task: Task) -> bool:
    """Whether :func:`creep_path` is a path for ``task``: a coupled solve under creepage control."""
    kind, value = task.controls.tangential
    return task.formulation == "coupled" and task.friction is None and kind == "creep"


#: Steps of the creepage path: the distance to the task's creepage over this many, at first
#: (the step doubles after an easy point, halves after a failed one).
STEPS = 8


def _at_creep(task: Task, xi: float) -> Task:
    return dataclasses.replace(task, controls=dataclasses.replace(task.controls, tangential=("creep", float(xi))))


def _solver(globalisation_first, globalisation_next):
    """Newton from a start: ``globalisation_first`` first, then ``globalisation_next`` from its best."""
    return strategies.first_success(
        strategies._with(strategies.direct, globalisation_first, "creep path"),
        strategies._with(strategies.direct, globalisation_next, "creep path"),
        name="creep path",
    )


#: Newton with the monotone line search, then the watchdog from its best iterate: the line search
#: brings a far start near, the watchdog lets the last steps of a moving stick/slip boundary raise
#: the merit before they converge (from the converged neighbour 0.002 creepage away on 62 coarse
#: elements: 20 of 20 steps converge, 6.4 iterations each; the monotone search alone 15, the
#: watchdog alone 18).
NEWTON = _solver(strategies.MONOTONE, strategies.WATCHDOG)


def creep_path(task: Task, start: State, budget: Budget, cold: bool = False, origin: State | None = None) -> Solution:
    """Continuation in the creepage from 0 to the task's (creepage control of a coupled task; other
    tasks: :data:`NEWTON` from ``start``), each point solved by :data:`NEWTON` on the shared budget.
    ``origin`` is the closed-form start at xi = 0 (``start`` with no traction when None)."""
    kind, target = task.controls.tangential
    solve = NEWTON
    if kind != "creep" or task.formulation != "coupled":
        return solve(task, start, budget, cold=cold)
    if origin is None:
        origin = start.copy()
        origin.p_t = np.zeros_like(origin.p_t)
    origin = origin.copy()
    origin.creep = 0.0
    try:
        first = solve(_at_creep(task, 0.0), origin, budget, cold=cold)
    except StrategyFailed as err:
        raise StrategyFailed("creep path", "xi = 0", err.reason, err.best, err.residual) from None
    if target == 0.0:
        return first

    def solve_at(xi: float, guess: State) -> tuple[Solution, int]:
        before = budget.taken
        guess = guess.copy()
        guess.creep = xi
        return solve(_at_creep(task, xi), guess, budget), budget.taken - before

    points = [(0.0, first)]
    control = continuation.StepControl(easy=8)
    try:
        continuation.follow(
            _targets(target),
            solve_at,
            lambda points, _s: points[-1][1].state.copy(),
            points,
            failure=StrategyFailed,
            control=control,
            budget=budget,
        )
    except continuation.ContinuationFailed as err:
        best = err.best.state if err.best is not None else None
        raise StrategyFailed("creep path", f"xi = {err.parameter:.4g}", err.reason, best, err.residual) from None
    return points[-1][1]


def _targets(target: float) -> list[float]:
    """The path's first targets: :data:`STEPS` equal steps to ``target``."""
    return [float(v) for v in np.linspace(0.0, target, STEPS + 1)[1:]]


#: The creepages, as factors of the task's, from which :func:`nudged` walks to it, in order: each
#: tried from the start handed on (issue 23's case, 417 elements, the four creepages of 41 that the
#: first two left failing: 0.016 converged from 1.05 and 1.1, 0.029 from 0.97 and 1.1, 0.031 from
#: 1.03, 0.040 from 0.94; benchmarks/RESULTS.md, "the last failures").
NUDGES = (0.97, 1.03, 0.94, 1.06, 0.9, 1.1)


#: Newton iterations a nudged creepage may take before the next is tried: converged ones took 9-38
#: (the four creepages above), failing ones cycle for 15-80 before the stagnation test stops them.
NUDGE_ITERATIONS = 40


def _capped(budget: Budget, most: int) -> Budget:
    """A budget of at most ``most`` more iterations sharing ``budget``'s count and history (the
    caller copies its count back)."""
    return Budget(min(budget.limit, budget.taken + most), budget.taken, budget.history)


def nudged(
    task: Task,
    start: State,
    budget: Budget,
    cold: bool = False,
    origin: State | None = None,
    factors: tuple[float, ...] = NUDGES,
    most: int | None = NUDGE_ITERATIONS,
) -> Solution:
    """:data:`NEWTON` at a creepage a few per cent off the task's (each of ``factors`` in turn, at
    most ``most`` iterations each, None: no cap) from ``origin`` (the level's own start: a failed Newton's
    best iterate, which a chain hands on, has the fragmented node states; ``start`` when None), then
    from that solution the creepage path (the continuation driver, its step halved on a failure) to
    the task's (creepage control of a coupled task).

    For a start transferred from a coarser grid whose Newton cycles at the stick/slip boundary: on
    issue 23's case (417 elements, xi = 0.016) Newton from the 104-element solution alternated
    between adhesion zones of 147 and 150 nodes; from the converged solution at xi = 0.0158 it took
    9 iterations (benchmarks/RESULTS.md). The discrete node states at a neighbouring creepage
    differ, and so does the cycle."""
    target = task.controls.tangential[1]
    if not applies(task) or target == 0.0:
        return NEWTON(task, start, budget, cold=cold)
    failure = None
    start = start if origin is None else origin
    for factor in factors:
        guess = start.copy()
        guess.creep = factor * target
        trial = budget if most is None else _capped(budget, most)
        try:
            near = NEWTON(_at_creep(task, factor * target), guess, trial, cold=cold)
        except StrategyFailed as err:
            failure = err
            continue
        finally:
            budget.taken = trial.taken
        if budget.exhausted:
            break
        try:
            return _walk(task, factor * target, near, budget)
        except StrategyFailed as err:
            failure = err
        if budget.exhausted:
            break
    assert failure is not None
    raise StrategyFailed("nudged", failure.stage, failure.reason, failure.best, failure.residual) from None


def _walk(task: Task, xi: float, near: Solution, budget: Budget) -> Solution:
    """From ``near`` (the solution at creepage ``xi``) to the task's creepage by :data:`NEWTON`,
    halving the step after a failure (:func:`continuation.follow`)."""

    def solve_at(value: float, guess: State) -> tuple[Solution, int]:
        before = budget.taken
        guess = guess.copy()
        guess.creep = value
        return NEWTON(_at_creep(task, value), guess, budget), budget.taken - before

    points = [(xi, near)]
    try:
        continuation.follow(
            [task.controls.tangential[1]],
            solve_at,
            lambda points, _s: points[-1][1].state.copy(),
            points,
            failure=StrategyFailed,
            control=continuation.StepControl(easy=8, min_fraction=1.0 / 8.0),
            budget=budget,
        )
    except continuation.ContinuationFailed as err:
        best = err.best.state if err.best is not None else None
        raise StrategyFailed("nudged", f"xi = {err.parameter:.4g}", err.reason, best, err.residual) from None
    return points[-1][1]


def warm_chain(start: State) -> list:
    """The corner's first strategies for a warm level from ``start`` (a coarser grid's solution):
    :data:`NEWTON`; :func:`nudged` from its best iterate at 0.97 and 1.03 of the creepage, uncapped;
    :func:`nudged` from ``start`` at every one of :data:`NUDGES`, capped. Issue 23's case, 41
    creepages at mu |beta| = 1.09: the first two alone converged 37 of 41 (xi = 0.035 by the second,
    594 iterations); the first and third alone converged the four others but lost 0.035
    (benchmarks/RESULTS.md, "the last failures")."""
    return [NEWTON, functools.partial(nudged, factors=NUDGES[:2], most=None), functools.partial(nudged, origin=start)]


def applies_force(task: Task) -> bool:
    """Whether :func:`force_path` is a path for ``task``: a coupled Coulomb solve under force control."""
    return task.formulation == "coupled" and task.friction is None and task.controls.force is not None


class _Crossed(Exception):
    """The creepage path of :func:`force_path` passed the force between two solutions."""

    def __init__(self, bracket: tuple) -> None:
        self.bracket = bracket
        super().__init__("crossed")


def force_path(task: Task, start: State, budget: Budget, cold: bool = False, origin: State | None = None) -> Solution:
    """Force control of a strongly coupled task by the creepage path: from xi = 0 (``origin``, else
    ``start`` without traction) towards three times ``start``'s creepage (the closed-form estimate for
    the force) in steps of 1/:data:`STEPS` of it, each by :data:`NEWTON` from the last (the step
    halved after a failure), until Q passes the prescribed force; then :data:`NEWTON` under force
    control from the nearer of the two with the creepage interpolated linearly between them."""
    estimate = float(start.creep)
    if not applies_force(task) or estimate == 0.0:
        return NEWTON(task, start, budget, cold=cold)
    guess = (start if origin is None else origin).copy()
    if origin is None:
        guess.p_t = np.zeros_like(guess.p_t)
    guess.creep = 0.0
    weights = task.system.weights
    try:
        first = NEWTON(_at_creep(task, 0.0), guess, budget, cold=cold)
    except StrategyFailed as err:
        raise StrategyFailed("force path", "xi = 0", err.reason, err.best, err.residual) from None
    target = task.problem(task.full_mode).force_target(first.state.p_n, first.state.p_t)[0]
    points = [(0.0, first)]

    def miss(solution: Solution) -> float:
        return float(weights @ solution.state.p_t) - target

    def solve_at(xi: float, guess: State) -> tuple[Solution, int]:
        before = budget.taken
        guess = guess.copy()
        guess.creep = xi
        here = NEWTON(_at_creep(task, xi), guess, budget)
        if miss(here) * miss(points[-1][1]) <= 0.0:
            raise _Crossed((points[-1], (xi, here)))
        return here, budget.taken - before

    targets = [k * estimate / STEPS for k in range(1, 3 * STEPS + 1)]
    try:
        continuation.follow(
            targets,
            solve_at,
            lambda points, _s: points[-1][1].state.copy(),
            points,
            failure=StrategyFailed,
            control=continuation.StepControl(easy=8),
            budget=budget,
        )
    except _Crossed as crossed:
        (xi_0, one), (xi_1, other) = crossed.bracket
        m0, m1 = miss(one), miss(other)
        guess = (other if abs(m1) <= abs(m0) else one).state.copy()
        guess.creep = xi_0 + (xi_1 - xi_0) * m0 / (m0 - m1)
        return NEWTON(task, guess, budget)
    except continuation.ContinuationFailed as err:
        best = err.best.state if err.best is not None else None
        raise StrategyFailed("force path", f"xi = {err.parameter:.4g}", err.reason, best, err.residual) from None
    raise StrategyFailed("force path", f"xi = {points[-1][0]:.4g}", "the force was not reached", None, math.nan)
