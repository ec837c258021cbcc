"""One Newton run on one stage problem (normal, tangential or coupled), charged to the shared
:class:`~rolling_cli.solver.budget.Budget`: the building block of every strategy
(:mod:`rolling_cli.solver.strategies`) and of the creepage root (:mod:`rolling_cli.solver.creep_root`).
"""

from __future__ import annotations

import numpy as np

from . import formulation, reduced
from .budget import Budget
from .formulation import Problem, State
from .newton import NewtonFailure, NonlinearSystem, Watchdog, newton
from .task import Solution, StrategyFailed


def _nonlinear(problem: Problem, scales: formulation.Scales) -> NonlinearSystem:
    def evaluate(x):
        return formulation.evaluate(problem, State.unpack(x), scales)

    linear: dict = {}

    def step(x, ev):
        linear.clear()
        return reduced.newton_point(problem, State.unpack(x), ev, linear).pack()

    def describe(x, ev):
        return {
            "creep": float(x[-1]),
            "overlap": float(x[-2]),
            "contact": int(ev.contact.sum()),
            "stick": int(ev.stick.sum()),
            "edge": bool(ev.contact[0] or ev.contact[-1]),
            "linear_solver": "dense LU"
            if problem.friction is not None and problem.tangential
            else problem.system.linear_solver,
        }

    return NonlinearSystem(evaluate, step, describe, lambda: dict(linear))


def run_newton(
    problem: Problem,
    start: State,
    tolerance: float,
    budget: Budget,
    strategy: str,
    stage: str,
    cold: bool = False,
    globalisation=None,
) -> Solution:
    """Newton on one stage problem to the tolerance, or to :data:`~rolling_cli.solver.formulation.FLOOR_FACTOR`
    times the round-off floor where that is larger (the history's "tolerance" column says which);
    raises :class:`StrategyFailed` with the best state."""
    scales = formulation.traction_scales(problem, start)
    system = _nonlinear(problem, scales)
    first = formulation.evaluate(problem, start, scales, cold=True) if cold else None
    applied = max(tolerance, formulation.FLOOR_FACTOR * formulation.roundoff_floor(problem, scales))
    label = {"strategy": strategy, "stage": stage, "tolerance": applied}
    try:
        x, ev = newton(
            system,
            start.pack(),
            tolerance=applied,
            budget=budget,
            globalisation=globalisation or Watchdog(),
            first=first,
            label=label,
        )
    except NewtonFailure as err:
        raise StrategyFailed(strategy, stage, err.reason, State.unpack(err.best_x), err.best.residual) from None
    return Solution(State.unpack(x), ev, problem)


def clip_to_friction(state: State, p_t: np.ndarray, mu: float) -> State:
    """``state`` with the tangential traction ``p_t`` [stress] clipped to the friction bound mu |p_n|."""
    out = state.copy()
    out.p_t = np.clip(p_t, mu * state.p_n, -mu * state.p_n)
    return out
