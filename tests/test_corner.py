"""The strongly coupled corner of issue 23 (mu |beta_Dundurs| = 1.09): creepage control converges cold.

A stiff roller on a soft, compressible flat with high friction. The contact moves to one side as
the creepage grows (past the default zone of 1.5 a), and Newton from the closed-form start passes
through fragmented node states and stalls; the solve now takes a zone of 2.5 a and, from a cold
start, walks the creepage from 0 (rolling_cli/solver/corner.py, benchmarks/RESULTS.md). Checked
against independent references: full sliding (Q = -mu P exactly), force control (a second
formulation that must return the creepage), and the contact laws at every node.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, solve
from rolling_cli.case import load_case
from rolling_cli.pipeline import corner as corner_rules
from rolling_cli.pipeline.planning import plan
from rolling_cli.references.sliding import full_sliding_force

CORNER = {
    "bodies": {
        "A": {"kind": "elastic", "radius": 485.0, "young": 991164.5, "poisson": 0.2730},
        "B": {"kind": "elastic", "radius": math.inf, "young": 396.505, "poisson": 0.02223},
    },
    "friction": {"mu": 2.2376},
    "normal": {"load": 43.863},
    "tangential": {"creep": 0.0},
    "rolling": {"direction": 1},
    # 40 elements on 1.5 a: 67 on the corner's 2.5 a, the same element length (a fast test; the
    # issue's 250 elements are measured in benchmarks/corner_curve.py)
    "discretization": {"influence": "half-plane", "contact_elements": 40},
}


def corner(**dotted) -> dict:
    return case_dict(CORNER, **dotted)


@pytest.fixture(scope="module")
def curve():
    """Creepage-controlled solves, each cold and alone, at a low and a high creepage."""
    return {xi: solve(corner(**{"tangential.creep": xi})) for xi in (0.012, 0.027, 0.03)}


def test_creepage_control_converges_cold_with_the_contact_inside_the_zone(curve):
    for result in curve.values():
        assert_contact_laws(result, result.tolerance_applied)
        contact = result.p_n < 0.0
        assert not (contact[0] or contact[-1])  # the answer is the zone's, not cut by its edge
        assert "coupling is strong" in result.attributes["zone_note"]
    # Q is non-increasing in the creepage (and negative for xi > 0)
    assert curve[0.03].q_over_mu_p < curve[0.012].q_over_mu_p < 0.0


def test_force_control_returns_the_creepage(curve):
    """Force control at the Q/(mu P) of a creepage-controlled solve finds that creepage again: the
    two solves share no path (the force one starts from Carter's creepage estimate). Each meets Q to
    tolerance * mu P (the residual's scale), so the creepages agree to 2 tol mu P / |dQ/dxi|, times 10
    for the rounding of the stick/slip node states."""
    creep = curve[0.03]
    force = solve(corner(**{"tangential.q_over_mu_p": creep.q_over_mu_p}))
    assert_contact_laws(force, force.tolerance_applied)
    tol = max(creep.tolerance_applied, force.tolerance_applied)
    bound = 10.0 * 2.0 * tol * creep.mu * creep.normal_load / abs(creep.attributes["dQ_dxi"])
    assert abs(force.creep - 0.03) <= bound


def test_full_sliding_beyond_the_curve_is_mu_p():
    """Beyond full slip every contact node slips one way: Q = -sgn(xi) sum w mu |p_n| (closed form)."""
    result = solve(corner(**{"tangential.creep": 0.06}))
    assert_contact_laws(result, result.tolerance_applied)
    assert not np.any(result.state == 1)  # no adhesion node
    mu_nodes = np.full_like(result.p_n, result.mu)
    q = full_sliding_force(result.weights, result.p_n, mu_nodes, result.creep)
    # both sums over the same nodes: they agree to the slip rows' residual, tol * mu |p_n| per node
    bound = result.tolerance_applied * result.mu * float(result.weights @ np.abs(result.p_n))
    assert abs(result.tangential_load - q) <= 10.0 * bound


def test_weakly_coupled_cases_keep_their_zone():
    """Under creepage control the corner's zone applies above mu |beta| = 1 only: mu = 1.8 gives 0.88."""
    case = load_case(corner(**{"friction.mu": 1.8, "tangential.creep": 0.002}))
    assert corner_rules.corner_zone(case, plan(case)) is case
    strong = load_case(corner(**{"tangential.creep": 0.002}))
    widened = corner_rules.corner_zone(strong, plan(strong))
    assert widened.discretization.zone == corner_rules.CORNER_ZONE
    # the same element length: 40 elements on 1.5 a, 67 on 2.5 a (rounded up)
    assert widened.discretization.contact_elements == math.ceil(40 * corner_rules.CORNER_ZONE / 1.5)


def test_a_warm_started_sweep_shares_a_system_on_the_corners_zone(curve):
    """``rollc sweep`` solves its cases on one contact system built once (``pipeline.prepare``): for a
    strongly coupled case it is on the corner's zone, as a solve alone takes it, so the cases do not
    grow their zone level by level. Along a creepage sweep, warm-started, every case converges, and
    at xi = 0.03 it agrees with the cold solve alone (another path to the same discrete solution)."""
    from rolling_cli import pipeline
    from rolling_cli.study.path import CasePath

    base = load_case(corner())
    the_plan, system = pipeline.prepare(base)
    assert the_plan.grid.x.shape == system.x.shape
    # the end nodes sit within one element of the zone's ends, +-2.5 a
    assert system.x[-1] - system.x[0] >= 2.0 * (corner_rules.CORNER_ZONE * the_plan.half_width - system.spacing)
    path = CasePath(system)
    results = {}
    for xi in (0.01, 0.02, 0.03):
        results[xi] = path.solve(load_case(corner(**{"tangential.creep": xi})), {"tangential.creep": xi})
    for xi, result in results.items():
        assert_contact_laws(result, result.tolerance_applied)
        assert result.x.shape == system.x.shape  # solved on the shared system: no enlarged zone
        assert result.attributes["start"] == ("cold" if xi == 0.01 else "warm")
    alone = curve[0.03]
    # both meet their residuals to tol mu P on the same grid: Q agrees to 2 tol mu P, times 10 for the
    # stick/slip node states' rounding (as the force-control test above)
    tol = max(alone.tolerance_applied, results[0.03].tolerance_applied)
    assert abs(results[0.03].tangential_load - alone.tangential_load) <= 10.0 * 2.0 * tol * alone.mu * alone.normal_load


def _corner_task(xi: float):
    """The solver task of the corner case at creepage ``xi`` on its own (corner-zone) contact system."""
    from rolling_cli import pipeline
    from rolling_cli.pipeline.mesh_path import _task

    case = load_case(corner(**{"tangential.creep": xi}))
    the_plan, system = pipeline.prepare(case)
    return _task(corner_rules.corner_zone(case, the_plan), the_plan, system)


def test_nudged_creepages_reach_the_task_from_a_neighbours_solution(curve):
    """``solver.corner.nudged`` from the converged solution at xi = 0.027 solves at xi = 0.03 (a nudged
    creepage, then the walk): the result has the task's creepage, meets the task's own residual
    tolerance (an independent evaluation of the projection equations), and its Q agrees with the cold
    solve alone at 0.03 to 2 tol mu P, times 10 for the stick/slip node states' rounding."""
    from rolling_cli.pipeline.branches import result_state
    from rolling_cli.solver import corner as corner_solver
    from rolling_cli.solver import formulation
    from rolling_cli.solver.budget import Budget

    task = _corner_task(0.03)
    budget = Budget(400)
    solution = corner_solver.nudged(task, result_state(curve[0.027]), budget)
    assert solution.state.creep == 0.03
    problem = task.problem(task.full_mode)
    state = task.prepared(solution.state)
    evaluation = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
    assert evaluation.relative_residual <= task.tolerance
    q = float(task.system.weights @ solution.state.p_t)
    alone = curve[0.03]
    assert abs(q - alone.tangential_load) <= 10.0 * 2.0 * task.tolerance * alone.mu * alone.normal_load
    assert 0 < budget.taken <= budget.limit


def test_a_nudged_creepage_takes_at_most_its_cap_from_the_shared_budget():
    """Each nudged creepage may take at most ``most`` Newton iterations, counted on the shared budget:
    from the closed-form start (which needs many more here) with a cap of 1 and two creepages, the
    solve fails having taken exactly 2."""
    from rolling_cli.solver import corner as corner_solver
    from rolling_cli.solver.budget import Budget
    from rolling_cli.solver.task import StrategyFailed

    task = _corner_task(0.03)
    case = load_case(corner(**{"tangential.creep": 0.03}))
    from rolling_cli.pipeline.planning import initial_state

    start = initial_state(corner_rules.corner_zone(case, plan(case)), plan(case), task.system)
    budget = Budget(400)
    with pytest.raises(StrategyFailed):
        corner_solver.nudged(task, start, budget, factors=(0.97, 1.03), most=1)
    assert budget.taken == 2


def test_force_control_takes_the_corners_zone_from_a_lower_coupling():
    """Under force control the corner's zone applies from mu |beta| = 0.6 (measured without a loss
    there, benchmarks/RESULTS.md): mu = 1.8 (0.88) takes it by force, not by creepage; mu = 1.0 (0.49)
    takes it neither way."""
    by_force = load_case(corner(**{"friction.mu": 1.8, "tangential.q_over_mu_p": -0.5}))
    widened = corner_rules.corner_zone(by_force, plan(by_force))
    assert widened.discretization.zone == corner_rules.CORNER_ZONE
    weak = load_case(corner(**{"friction.mu": 1.0, "tangential.q_over_mu_p": -0.5}))
    assert corner_rules.corner_zone(weak, plan(weak)) is weak
