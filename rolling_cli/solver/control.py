"""Solve one task with the default strategy; turn a failure into a clear error.

:func:`solve` runs :func:`rolling_cli.solver.strategies.default` on the shared
budget. A failure becomes a :class:`~rolling_cli.errors.ConvergenceError`
whose message names the strategies tried, the stage that failed, the residual
and what to try, or a :class:`~rolling_cli.errors.GrossSlidingError` when the
prescribed tangential force turns out to reach mu P (overlap control, where P
is only known after the solve).
"""

from __future__ import annotations

import contextlib
import functools

from ..errors import ConvergenceError, GrossSlidingError
from . import corner as corner_path
from . import strategies
from .budget import Budget
from .formulation import State
from .strategies import Solution, StrategyFailed, Task

#: What to try, by the reason a strategy gave.
ADVICE = {
    "budget": "the iteration budget is spent; raise solver.max_iterations",
    "stagnation": "Newton stalls at a non-smooth point of the contact laws; refine the mesh or move the load "
    "further from full slip",
}


def solve(
    task: Task,
    start: State,
    budget: Budget,
    *,
    cold: bool = False,
    settle: bool = False,
    restart: State | None = None,
    restart_settle: bool = False,
    corner: State | None = None,
) -> Solution:
    """Solve ``task`` from ``start`` (``cold``: a closed-form guess, whose first node states are read
    from the pressure; ``settle``: its pressure is only approximate; ``restart``: for a warm start,
    the closed-form start tried next if it fails, ``restart_settle``: with its pressure settled
    first; see :func:`~rolling_cli.solver.strategies.default`; ``corner``: where the coupling is strong
    (mu |beta| above :data:`~rolling_cli.solver.corner.STRONG`), the closed-form start at xi = 0: a
    cold start then walks the creepage path of :func:`~rolling_cli.solver.corner.creep_path` first, a
    warm one tries :data:`~rolling_cli.solver.corner.NEWTON` and :func:`~rolling_cli.solver.corner.nudged`
    first, and matrix-free Newton steps are
    solved exactly, :func:`~rolling_cli.solver.matrix_free.exact_steps`).
    Raises ConvergenceError or GrossSlidingError."""
    strategy = strategies.default(task, settle, restart, restart_settle)
    steps: contextlib.AbstractContextManager = contextlib.nullcontext()
    if corner is not None and cold and corner_path.applies_force(task):
        path = functools.partial(corner_path.force_path, origin=corner)
        strategy = strategies.first_success(path, strategy, name=task.formulation)
    if corner is not None and corner_path.applies(task):
        path = functools.partial(corner_path.creep_path, origin=corner)
        first = [path] if cold else corner_path.warm_chain(start)
        strategy = strategies.first_success(*first, strategy, name=task.formulation)
        if task.system.matrix_free:
            from .matrix_free import exact_steps

            steps = exact_steps()
    try:
        with steps:
            return strategy(task, start, budget, cold=cold)
    except StrategyFailed as err:
        if task.controls.force is not None and err.best is not None:
            check_saturated(task, err.best)
        raise convergence_error(err, budget) from None


def convergence_error(err: StrategyFailed, budget: Budget) -> ConvergenceError:
    """The error for a failed strategy: which ran, where it failed, and what to try."""
    tried = ", ".join(budget.strategies()) or err.strategy
    reasons = [f.reason for f in (err.causes or [err])]
    key = "budget" if budget.exhausted else ("stagnation" if "stagnation" in reasons else "")
    cause = ADVICE.get(key, reasons[-1])
    return ConvergenceError(
        f"Newton did not converge (strategies tried: {tried}; last failed stage: {err.stage})",
        residual=err.residual,
        iterations=budget.taken,
        history=budget.history,
        cause=cause,
        partial=err.best,
    )


def check_saturated(task: Task, state: State) -> None:
    """A tangential target beyond the friction limit at ``state``'s load: gross sliding (raised)."""
    problem = task.problem(task.full_mode)
    load = float(-(task.system.weights @ state.p_n))  # the arc sum: the friction's capacity is mu sum w |p_n|
    target, _ = problem.force_target(state.p_n, state.p_t)
    if load > 0.0 and abs(target) >= task.mu * load * (1.0 - 1e-9):
        raise GrossSlidingError(
            f"gross sliding: the prescribed tangential force |Q| = {abs(target):.6g} reaches "
            f"mu P = {task.mu * load:.6g}; the cylinders slide, they do not roll"
        )
