"""A generic semi-smooth Newton method. It knows nothing about rolling.

The caller hands over a :class:`NonlinearSystem` of three functions of the
unknown vector x:

* ``evaluate(x)`` -> a point with ``residual`` (the relative residual that is
  compared with the tolerance) and ``merit`` (what the globalisation
  decreases), plus whatever the other two functions need;
* ``step(x, point)`` -> the Newton point x + dx (the solution of the linearised
  system at x, for a generalised Jacobian chosen by the caller);
* ``describe(x, point)`` -> a dict of extra history columns;
* optionally ``step_columns()`` -> a dict of history columns of the last step
  (for example the linear solver's iterations), added to the row of the
  iterate the step started from.

:func:`newton` iterates from a start, takes every iteration from a shared
:class:`~rolling_cli.solver.budget.Budget` (which also keeps the history), and
globalises the step with a strategy value (:class:`Watchdog`, the default, or
:class:`Armijo`). Whatever the globalisation, the least merit must halve every
``patience`` iterations (its attribute), else Newton stops: a strategy that
does not progress hands over instead of spending the budget. It returns the
converged (x, point) or raises :class:`NewtonFailure` carrying the best iterate
it saw.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .budget import Budget, BudgetExhausted

#: Sufficient decrease (Armijo constant) of the merit.
SUFFICIENT = 1e-4
#: Progress: the least merit must fall by this factor every ``patience`` iterations.
PROGRESS = 0.5


@dataclass(frozen=True)
class NonlinearSystem:
    """The three functions of x that Newton needs (see the module docstring)."""

    evaluate: Callable[[np.ndarray], Any]
    step: Callable[[np.ndarray, Any], np.ndarray]
    describe: Callable[[np.ndarray, Any], dict]
    step_columns: Callable[[], dict] | None = None


class NewtonFailure(Exception):
    """Newton stopped without converging. ``best_x``/``best`` is the iterate of least merit;
    ``reason`` says why ("budget", "stagnation" or a message from the linear solve)."""

    def __init__(self, reason: str, best_x: np.ndarray, best, iterations: int) -> None:
        self.reason = reason
        self.best_x = best_x
        self.best = best
        self.iterations = iterations
        super().__init__(f"{reason} after {iterations} iterations, relative residual {best.residual:.3e}")


@dataclass
class _Track:
    """What a globalisation remembers during one solve: the best iterate and its Newton point."""

    best_x: np.ndarray
    best: Any
    best_target: tuple | None = None
    free: int = 0
    since_progress: int = 0
    reference: float = float("inf")


def _backtrack(system: NonlinearSystem, x, point, target_x, target, backtracks: int):
    """Armijo backtracking along x -> target_x; returns (x, point, alpha, decreased)."""
    m0 = point.merit
    best = (target_x, target, 1.0)
    alpha = 0.5
    for _ in range(backtracks):
        trial_x = x + alpha * (target_x - x)
        trial = system.evaluate(trial_x)
        if trial.merit <= (1.0 - SUFFICIENT * alpha) * m0:
            return trial_x, trial, alpha, True
        if trial.merit < best[1].merit:
            best = (trial_x, trial, alpha)
        alpha *= 0.5
    return (*best, False)


@dataclass(frozen=True)
class Armijo:
    """Monotone globalisation: the full Newton step when it decreases the merit
    sufficiently, else backtracking (halving) along it. When no trial decreases
    the merit the best trial is kept; Newton reports stagnation after
    ``failed`` such steps in a row, or ``patience`` iterations without the least
    merit falling by :data:`PROGRESS`."""

    backtracks: int = 12
    failed: int = 3
    patience: int = 30

    def __call__(self, system, track: _Track, x, point, target_x, target):
        if target.merit <= (1.0 - SUFFICIENT) * point.merit:
            track.free = 0
            return target_x, target, 1.0
        x, point, alpha, decreased = _backtrack(system, x, point, target_x, target, self.backtracks)
        track.free = 0 if decreased else track.free + 1
        if track.free >= self.failed:
            raise _Stagnation
        return x, point, alpha


@dataclass(frozen=True)
class Watchdog:
    """Non-monotone globalisation (Chamberlain et al.'s watchdog technique).

    Full Newton steps are taken while they lower the least merit seen, and up to
    ``free_steps`` in a row that do not: an active-set Newton step that moves a
    stick/slip boundary often raises the merit before the next step lowers it far
    below (a monotone line search then creeps one node per iteration). When the
    free steps are used up, the iteration returns to the best iterate and
    backtracks along its Newton step; if even that gives no sufficient decrease
    the iterate is a numerical fixed point and Newton reports stagnation. So it
    does when the decrease needs a step shorter than ``retrace`` of the Newton
    step: the next full steps from so near the best iterate would retrace the
    free steps just rejected (a cycle until ``patience`` runs out; measured on
    benchmarks/robustness.py: 2 % fewer iterations in all, no new failure, and
    the second point of dissimilar_q04's 21-point load curve 26 -> 12).
    """

    free_steps: int = 6
    backtracks: int = 12
    patience: int = 20
    retrace: float = 1.0 / 16.0

    def __call__(self, system, track: _Track, x, point, target_x, target):
        if target.merit <= (1.0 - SUFFICIENT) * track.best.merit:
            track.free = 0
            return target_x, target, 1.0
        if track.free < self.free_steps:
            track.free += 1
            return target_x, target, 1.0
        track.free = 0
        best_x, best = track.best_x, track.best
        if track.best_target is None:  # no step from the best iterate to go back to
            raise _Stagnation
        best_target_x, best_target = track.best_target
        x, point, alpha, decreased = _backtrack(system, best_x, best, best_target_x, best_target, self.backtracks)
        if not decreased:
            raise _Stagnation
        if alpha < self.retrace:  # the decrease found is kept as the best iterate handed on
            track.best_x, track.best = x, point
            raise _Stagnation
        return x, point, -alpha  # negative: a step taken from the best iterate, not the last one


class _Stagnation(Exception):
    pass


def newton(
    system: NonlinearSystem,
    x0: np.ndarray,
    *,
    tolerance: float,
    budget: Budget,
    globalisation=None,
    first=None,
    label: dict | None = None,
) -> tuple[np.ndarray, Any]:
    """Solve F(x) = 0 from ``x0`` to ``point.residual <= tolerance``.

    ``first`` is the evaluation of x0 if the caller made it with special rules
    (a cold start), else ``system.evaluate(x0)`` is used. ``label`` holds the
    history columns that name this run (strategy, stage). Every Newton point
    costs one iteration of ``budget``. Returns (x, point); raises
    :class:`NewtonFailure` when the budget runs out, the iteration stagnates or
    the linear solve fails, with the best iterate.
    """
    globalisation = globalisation or Watchdog()
    label = label or {}
    x = np.asarray(x0, dtype=float)
    point = first if first is not None else system.evaluate(x)
    track = _Track(x, point)
    alpha = None
    iteration = 0
    while True:
        row = {**label, "iteration": iteration, "residual": point.residual, **system.describe(x, point)}
        budget.record(row)
        if point.residual <= tolerance:
            return x, point
        if iteration == 0 or point.merit < (1.0 - SUFFICIENT) * track.best.merit:
            track.best_x, track.best = x, point
        if point.merit < PROGRESS * track.reference:
            track.reference, track.since_progress = point.merit, 0
        else:
            track.since_progress += 1
            if track.since_progress > globalisation.patience:
                raise NewtonFailure("stagnation", track.best_x, track.best, iteration)
        try:
            budget.take()
            target_x = system.step(x, point)
            if system.step_columns is not None:
                row.update(system.step_columns())
            target = system.evaluate(target_x)
        except BudgetExhausted:
            raise NewtonFailure("budget", track.best_x, track.best, iteration) from None
        except (np.linalg.LinAlgError, FloatingPointError, ArithmeticError) as err:
            raise NewtonFailure(f"linear solve failed ({err})", track.best_x, track.best, iteration) from None
        if x is track.best_x:
            track.best_target = (target_x, target)
        try:
            x, point, alpha = globalisation(system, track, x, point, target_x, target)
        except _Stagnation:
            raise NewtonFailure("stagnation", track.best_x, track.best, iteration + 1) from None
        row["step"] = alpha
        iteration += 1
