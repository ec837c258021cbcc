"""Unit tests of the solver layer on small systems (milliseconds each).

The generic Newton and the continuation driver are tested on scalar toy
problems whose answers are known exactly; the formulation, the node-state
rules and the strategies on a 20-node Carter system (half-plane, 7 quadratic
elements), whose converged solution is reached by every strategy.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import case_dict, dissimilar
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.solver import continuation, formulation, predictor, reduced, strategies
from rolling_cli.solver.budget import Budget, BudgetExhausted
from rolling_cli.solver.formulation import State
from rolling_cli.solver.newton import Armijo, NewtonFailure, NonlinearSystem, Watchdog, newton

# --- budget ------------------------------------------------------------------------------------------


def test_budget_counts_records_and_runs_out():
    budget = Budget(2)
    budget.record({"strategy": "a", "iteration": 0})
    budget.take()
    budget.record({"strategy": "b", "iteration": 0})
    budget.take()
    assert budget.taken == 2 and budget.exhausted
    with pytest.raises(BudgetExhausted):
        budget.take()
    assert budget.strategies() == ["a", "b"]


# --- generic Newton on scalar problems -----------------------------------------------------------------


class _Point:
    def __init__(self, f, scale=1.0):
        self.f = f
        self.residual = abs(f) / scale
        self.merit = 0.5 * f * f


def _scalar(f, df):
    return NonlinearSystem(
        evaluate=lambda x: _Point(f(x[0])),
        step=lambda x, p: x - p.f / df(x[0]),
        describe=lambda x, p: {"x": float(x[0])},
    )


def test_newton_converges_quadratically_and_records_its_history():
    system = _scalar(lambda x: x**3 - 2.0, lambda x: 3.0 * x**2)
    budget = Budget(50)
    x, point = newton(system, np.array([1.0]), tolerance=1e-14, budget=budget, label={"strategy": "t"})
    assert x[0] == pytest.approx(2.0 ** (1.0 / 3.0), rel=1e-14)
    residuals = [row["residual"] for row in budget.history]
    # quadratic convergence: each residual about the square of the previous (from the third on)
    for prev, nxt in zip(residuals[2:-1], residuals[3:], strict=False):
        assert nxt <= 10.0 * prev**2 + 1e-15
    assert budget.taken == len(residuals) - 1
    assert all(row["strategy"] == "t" for row in budget.history)


def test_newton_reports_the_best_iterate_when_the_budget_runs_out():
    system = _scalar(lambda x: x**3 - 2.0, lambda x: 3.0 * x**2)
    with pytest.raises(NewtonFailure) as failed:
        newton(system, np.array([10.0]), tolerance=1e-14, budget=Budget(2))
    assert failed.value.reason == "budget"
    assert abs(failed.value.best_x[0] ** 3 - 2.0) < 10.0**3 - 2.0  # better than the start


@pytest.mark.parametrize("globalisation", [Watchdog(free_steps=2, patience=8), Armijo(patience=8)])
def test_newton_without_a_root_stagnates_instead_of_spending_the_budget(globalisation):
    """F(x) = x^2 + 1 has no root; the merit's minimum is at x = 0. Both globalisations stop
    with 'stagnation' well before a budget of 1000, at a best iterate near 0."""
    system = _scalar(lambda x: x * x + 1.0, lambda x: 2.0 * x if x != 0.0 else 1e-300)
    budget = Budget(1000)
    with pytest.raises(NewtonFailure) as failed:
        newton(system, np.array([3.0]), tolerance=1e-12, budget=budget, globalisation=globalisation)
    assert failed.value.reason == "stagnation"
    assert budget.taken < 200
    assert abs(failed.value.best_x[0]) < 3.0


def test_watchdog_takes_a_full_step_that_raises_the_merit_armijo_does_not():
    """A piecewise-linear F, like the projection equations: slope 1 below x = 1 (root 0), slope 0.1
    above. From x = 2 the Newton step of the upper piece lands at -9 (merit 0.6 -> 40.5), from where
    the next step is exact. The watchdog takes it and converges in 2 steps; the monotone line search
    backtracks (step < 1)."""

    def f(x):
        return x if x <= 1.0 else 1.0 + 0.1 * (x - 1.0)

    system = _scalar(f, lambda x: 1.0 if x <= 1.0 else 0.1)
    watch, mono = Budget(100), Budget(100)
    newton(system, np.array([2.0]), tolerance=1e-12, budget=watch, globalisation=Watchdog())
    newton(system, np.array([2.0]), tolerance=1e-12, budget=mono, globalisation=Armijo())
    assert watch.history[0]["step"] == 1.0 and watch.taken == 2
    assert mono.history[0]["step"] < 1.0


def test_watchdog_stops_when_a_backtrack_would_only_retrace_its_free_steps():
    """F has no root: 1 + 0.01 x for x >= -0.1, and 0.999 - (x + 0.1) below. From x = 0 the Newton
    step lands at -100 (merit up 10^4), whose step returns to 0.9, whose step lands near -100 again:
    a cycle. The backtrack from the best iterate (x = 0) finds a decrease only within 1/1000 of the
    step, where the free steps would start the same cycle again: stagnation after one round of free
    steps, instead of cycling until the patience runs out."""

    def f(x):
        return 1.0 + 0.01 * x if x >= -0.1 else 0.999 - (x + 0.1)

    system = _scalar(f, lambda x: 0.01 if x >= -0.1 else -1.0)
    watchdog = Watchdog()
    budget = Budget(1000)
    with pytest.raises(NewtonFailure) as failed:
        newton(system, np.array([0.0]), tolerance=1e-12, budget=budget, globalisation=watchdog)
    assert failed.value.reason == "stagnation"
    assert budget.taken <= watchdog.free_steps + 2 < watchdog.patience
    # the short backtracked step did decrease the merit: it is the best iterate handed on
    assert -0.1 < failed.value.best_x[0] < 0.0 and abs(f(failed.value.best_x[0])) < abs(f(0.0))


# --- node-state rules ------------------------------------------------------------------------------------


def test_node_state_rules():
    p_n = np.array([-1.0, -1.0, 0.0, -0.5])
    gap = np.array([0.0, 2.0, 1.0, 0.1])
    assert formulation.contact_by_projection(p_n, gap, 1.0).tolist() == [True, False, False, True]
    assert formulation.contact_from_pressure(p_n).tolist() == [True, True, False, True]
    assert formulation.nearest_contact(np.zeros(3), np.array([0.3, -0.1, 0.2]), 1.0) == 1
    lam_t = np.array([0.05, 0.2, -0.2, -0.05])
    bound = np.array([0.1, 0.1, 0.1, 0.1])
    assert formulation.adhesion_by_projection(lam_t, bound).tolist() == [True, False, False, True]
    p_t = np.array([0.1, -0.1, -0.1, 0.1])
    assert formulation.reversal_through_adhesion(p_t, lam_t).tolist() == [False, True, False, True]


def test_full_slip_safeguard_adheres_enough_nodes_to_carry_the_force_gap():
    contact = np.array([False, True, True, True, True, False])
    margin = np.array([0.0, 3.0, 1.0, 2.0, 4.0, 0.0])
    bound = np.full(6, 1.0)
    w = np.full(6, 0.5)  # each node's capacity 2 w g = 1
    stick = formulation.full_slip_safeguard(contact, margin, bound, w, force_gap=1.5)
    assert stick.tolist() == [False, False, True, True, False, False]  # the two of smallest margin
    assert not formulation.full_slip_safeguard(np.zeros(6, bool), margin, bound, w, 1.0).any()


# --- the formulation on a 20-node Carter system ---------------------------------------------------------


SMALL = {"discretization.contact_elements": 7}


def _task(data):
    case = load_case(data)
    the_plan, system = pipeline.prepare(case)
    return case, the_plan, system, pipeline._task(case, the_plan, system)


@pytest.fixture(scope="module")
def carter_small():
    case, the_plan, system, task = _task(case_dict(**SMALL))
    solution = strategies.direct(task, pipeline.initial_state(case, the_plan, system), Budget(50), cold=True)
    return case, the_plan, system, task, solution


def test_converged_solution_is_a_fixed_point_of_the_newton_step(carter_small):
    case, the_plan, system, task, solution = carter_small
    assert system.size == 21
    problem = task.problem("tangential")
    state = solution.state
    ev = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
    assert ev.relative_residual <= 1e-10
    again = reduced.newton_point(problem, state, ev)
    scale = case.friction.mu * float(np.max(-state.p_n))
    assert np.max(np.abs(again.p_t - state.p_t)) <= 1e-12 * scale
    assert again.creep == pytest.approx(state.creep, rel=1e-10)


def test_creep_sensitivity_matches_a_difference_quotient_at_fixed_node_states(carter_small):
    case, the_plan, system, task, solution = carter_small
    held = task.problem("tangential", force=False)
    state = solution.state
    ev = formulation.evaluate(held, state, formulation.traction_scales(held, state))
    d_q = reduced.creep_sensitivity(held, state, ev)
    # at fixed node states Q is linear in xi: the Newton point at xi + h gives the exact slope
    h = 1e-3 * abs(state.creep)
    shifted = state.copy()
    shifted.creep += h
    moved = reduced.newton_point(held, shifted, ev)
    slope = float(system.weights @ (moved.p_t - state.p_t)) / h
    assert d_q == pytest.approx(slope, rel=1e-8)
    assert d_q < 0.0  # Q falls as the creepage rises


def test_residual_scales_make_the_force_tolerance_independent_of_mu():
    """The tangential rows are measured against mu s_n: at mu = 1e-6 (the smallest accepted) a
    prescribed Q/(mu P) is still met to the tolerance (a p0 scale would accept a Q error of 1e-4 mu P)."""
    case, the_plan, system, task = _task(case_dict(**SMALL, **{"friction.mu": 1e-6}))
    solution = strategies.direct(task, pipeline.initial_state(case, the_plan, system), Budget(50), cold=True)
    q = float(system.weights @ solution.state.p_t)
    p = float(-(system.weights @ solution.state.p_n))
    assert q / (1e-6 * p) == pytest.approx(0.51, abs=1e-9)


# --- strategies ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["direct", "settled", "coupling_path", "creep_root"])
def test_every_strategy_reaches_the_same_dissimilar_solution(name):
    case, the_plan, system, task = _task(dissimilar(**SMALL))
    start = pipeline.initial_state(case, the_plan, system)
    reference = strategies.direct(task, start, Budget(100), cold=True)
    budget = Budget(200)
    solution = getattr(strategies, name)(task, start, budget, cold=True)
    scale = case.friction.mu * float(np.max(-reference.state.p_n))
    assert np.max(np.abs(solution.state.p_t - reference.state.p_t)) <= 1e-8 * scale
    assert solution.state.creep == pytest.approx(reference.state.creep, rel=1e-8)
    assert budget.strategies() == [name.replace("_", " ")]


def test_first_success_passes_on_the_best_state_and_reports_every_failure():
    case, the_plan, system, task = _task(dissimilar(**SMALL))
    start = pipeline.initial_state(case, the_plan, system)
    seen = []

    def failing(task, start, budget, cold=False):
        seen.append(start)
        better = strategies.direct(task, start, Budget(1), cold=cold) if False else None  # noqa: F841
        raise strategies.StrategyFailed("failing", "stage", "no", start, 1.0)

    def recording(task, start, budget, cold=False):
        seen.append(start)
        return strategies.direct(task, start, budget, cold=cold)

    solution = strategies.first_success(failing, recording)(task, start, Budget(100), cold=True)
    assert seen[0] is start and solution.evaluation.relative_residual <= 1e-10
    with pytest.raises(strategies.StrategyFailed) as failed:
        strategies.first_success(failing, failing, name="both")(task, start, Budget(100))
    assert len(failed.value.causes) == 2 and failed.value.strategy == "both"


def test_a_strategy_that_runs_out_of_budget_raises_with_its_best_state():
    case, the_plan, system, task = _task(dissimilar(**SMALL))
    start = pipeline.initial_state(case, the_plan, system)
    with pytest.raises(strategies.StrategyFailed) as failed:
        strategies.direct(task, start, Budget(1), cold=True)
    assert failed.value.best is not None and failed.value.reason == "budget"


def test_a_failed_warm_start_is_retried_from_the_closed_form_before_the_fallbacks(monkeypatch):
    """strategies.default with a ``restart`` (the closed-form start of a warm-started case): when the
    first strategy fails, the next one is the same Newton from ``restart`` with its node states read
    from the pressure (cold), whatever state the failure handed on; it converges to the solution."""
    case, the_plan, system, task = _task(dissimilar(**SMALL))
    cold = pipeline.initial_state(case, the_plan, system)
    reference = strategies.direct(task, cold, Budget(100), cold=True)
    real_direct = strategies.direct
    calls = []

    def direct(task, start, budget, cold=False, globalisation=None, name="direct"):
        calls.append((name, start, cold))
        if name == "direct":  # the warm attempt fails, handing on its start
            raise strategies.StrategyFailed(name, "coupled", "stagnation", start, 1.0)
        return real_direct(task, start, budget, cold=cold, globalisation=globalisation, name=name)

    monkeypatch.setattr(strategies, "direct", direct)
    warm = reference.state.copy()
    warm.p_t = -warm.p_t[::-1]  # a poor neighbour: stick and slip zones swapped end for end
    solution = strategies.default(task, restart=cold)(task, warm, Budget(100))
    assert [name for name, _, _ in calls] == ["direct", "direct, closed-form start"]
    assert calls[1][1] is cold and calls[1][2] is True
    scale = case.friction.mu * float(np.max(-reference.state.p_n))
    assert np.max(np.abs(solution.state.p_t - reference.state.p_t)) <= 1e-8 * scale
    calls.clear()
    with pytest.raises(strategies.StrategyFailed):  # without a restart: straight to the fallbacks
        strategies.default(task)(task, warm, Budget(3))
    assert "direct, closed-form start" not in [name for name, _, _ in calls]


# --- continuation driver and predictors -------------------------------------------------------------------


class _Fail(Exception):
    def __init__(self):
        self.reason, self.residual = "too far", 1.0


def test_follow_halves_the_step_after_a_failure_and_grows_it_after_easy_successes():
    """solve_at succeeds only within 0.3 of the last point; the driver must insert points."""
    points = [(0.0, 0.0)]
    tried = []

    def solve_at(s, start):
        tried.append(s)
        if abs(s - start) > 0.3:
            raise _Fail
        return s, 1

    continuation.follow(
        [1.0],
        solve_at,
        lambda pts, s: pts[-1][0],
        points,
        failure=_Fail,
        control=continuation.StepControl(min_fraction=1 / 64),
    )
    assert points[-1][0] == 1.0
    assert all(b - a <= 0.3 + 1e-12 for (a, _), (b, _) in zip(points, points[1:], strict=False))
    assert tried[0] == 1.0 and len(points) < 10


def test_follow_gives_up_at_the_smallest_step_with_the_last_solution():
    points = [(0.0, "start")]

    def solve_at(s, start):
        raise _Fail

    with pytest.raises(continuation.ContinuationFailed) as failed:
        continuation.follow(
            [1.0],
            solve_at,
            lambda pts, s: None,
            points,
            failure=_Fail,
            control=continuation.StepControl(min_fraction=1 / 8),
        )
    assert failed.value.best == "start" and failed.value.parameter <= 1 / 8 + 1e-12


def test_secant_moves_a_square_root_kink_to_its_extrapolated_place():
    """Profiles sqrt(max(0, b - x)) with b = 0.2, 0.3: the prediction at s = 2 has its kink at 0.4,
    where a plain secant would keep kinks at 0.2 and 0.3."""
    x = np.linspace(-1.0, 1.0, 401)

    def state(b):
        p_t = 0.1 * np.sqrt(np.clip(b - x, 0.0, None))
        return State(-np.ones_like(x), p_t, 0.0, -b)

    def zones(b):
        # slip (label 2) where x < b with |p_t| = g; adhesion beyond, its margin g - |p_t| = 0.1 sqrt(x - b)
        labels = np.where(x < b, 2, 1).astype(np.int8)
        bound = 0.1 * np.sqrt(np.clip(b - x, 0.0, None)) + 0.1 * np.sqrt(np.clip(x - b, 0.0, None))
        return predictor.zones(x, labels, -np.ones_like(x), state(b).p_t, bound)

    for b in (0.2, 0.3):  # the square-root fit places the boundary to round-off (the margin is exact)
        assert zones(b).boundaries[0] == pytest.approx(b, abs=1e-9)
    predicted = predictor.secant(x, [(0.0, state(0.2), zones(0.2)), (1.0, state(0.3), zones(0.3))], 2.0, mu=1.0)
    exact = state(0.4)
    assert np.max(np.abs(predicted.p_t - exact.p_t)) < 0.2 * np.max(np.abs(state(0.3).p_t - exact.p_t))
    assert predicted.creep == pytest.approx(-0.4)


def test_transfer_keeps_the_contact_set_on_the_small_side():
    x_from = np.linspace(-1.0, 1.0, 11)
    p_n = np.where(np.abs(x_from) < 0.5, -1.0, 0.0)
    moved = predictor.transfer(State(p_n, 0.1 * p_n, 0.2, 0.3), x_from, np.linspace(-2.0, 2.0, 41), mu=0.5)
    x_to = np.linspace(-2.0, 2.0, 41)
    assert np.all(moved.p_n[np.abs(x_to) > 0.41] == 0.0)
    assert np.all(np.abs(moved.p_t) <= 0.5 * np.abs(moved.p_n))
    assert (moved.overlap, moved.creep) == (0.2, 0.3)
