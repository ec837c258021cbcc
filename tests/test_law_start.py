"""The cost of a falling-law solve (issue 23, "Numbers to reach"): its closed-form start on the
coarse grids (Carter at the law's effective mu) and the creep slope shared with the sensitivities.

References: the fixed-point equation itself and Carter's creepage (references/carter.py), the
converged solution's stick zone, and the creep slope's own solve on the bordered Newton matrix
(solver/velocity.py, the computation the shared slope replaced).
"""

from __future__ import annotations

import math

import pytest

import rolling_cli
from helpers import CARTER, case_dict
from rolling_cli import pipeline
from rolling_cli.model import friction
from rolling_cli.pipeline.mesh_path import MeshPath
from rolling_cli.references import carter
from rolling_cli.solver import formulation, reduced, strategies
from rolling_cli.solver.budget import Budget
from rolling_cli.solver.initial import effective_friction

EXPONENTIAL = {"law": "exponential", "mu_static": 0.30, "mu_kinetic": 0.18, "slip_velocity_half": 100.0}
SPEED = 45000.0
COARSE = {"discretization.contact_elements": 50, "discretization.influence": "half-plane"}


def law_case(**dotted) -> dict:
    data = case_dict(CARTER, **dotted)
    data["friction"] = dict(EXPONENTIAL)
    data.setdefault("rolling", {})["speed"] = SPEED
    return data


def _law():
    law = friction.Exponential(0.30, 0.18, 100.0)
    return law, (lambda s: float(law.mu(SPEED * s)))


@pytest.mark.parametrize("ratio", [0.1, 0.5, 0.7, 0.95])
def test_effective_friction_under_force_control_is_the_fixed_point(ratio):
    """mu_e = mu(|V| |xi_C(Q/(mu_e P), mu_e)|) with Carter's creepage xi_C, between mu_k and mu_s.
    Tolerance 1e-12 relative: the iteration stops when a step moves mu_e by less than that, and it
    contracts (the law's slope times Carter's dxi/dmu is below 1 here), so the residual of the
    equation is of the last step's size. At 0.95 the law cannot carry Q at partial slip: xi_C is
    full slip's, mu_e a / R*."""
    law, mu_of = _law()
    a, r_star = 0.5, 50.0
    mu_e = effective_friction(mu_of, 0.30, a, r_star, q_over_mu_p=ratio)
    assert law.mu_kinetic <= mu_e <= law.mu_static
    xi = carter.creepage(min(ratio * 0.30 / mu_e, 1.0), a, r_star, mu_e)
    assert abs(mu_of(abs(xi)) - mu_e) <= 1e-12 * mu_e


def test_effective_friction_limits():
    """Creepage control: the law at |xi| (exactly). A flat law (mu_k = mu_s) gives mu_s exactly under
    either control, and Q = 0 gives mu(0) = mu_s."""
    law, mu_of = _law()
    assert effective_friction(mu_of, 0.30, 0.5, 50.0, creep=-0.002) == float(law.mu(SPEED * 0.002))
    flat = friction.Exponential(0.30, 0.30, 100.0)
    assert effective_friction(lambda s: float(flat.mu(SPEED * s)), 0.30, 0.5, 50.0, q_over_mu_p=0.6) == 0.30
    assert effective_friction(mu_of, 0.30, 0.5, 50.0, q_over_mu_p=0.0) == 0.30


@pytest.mark.parametrize("tangential", [{"tangential.creep": -0.002}, {"tangential.q_over_mu_p": 0.7}])
def test_effective_start_puts_the_stick_zone_near_the_laws(tangential):
    """On a coarse grid (50 elements, 100 contact nodes) Carter at mu_e has the solution's stick zone
    within 5 nodes (measured 1-5 on creepages -0.002, -0.004 and Q/(mu_s P) = 0.3, 0.7: Carter's zone
    belongs to one mu, the law's mu varies over the slip zone), closer than Carter at mu_static's
    (4-32 nodes off), and direct Newton needs no more iterations from it (measured 7 against 12 and
    22 here)."""
    case = rolling_cli.load_case(law_case(**COARSE, **tangential))
    the_plan, system = pipeline.prepare(case)
    task = pipeline._task(case, the_plan, system)
    problem = task.problem("tangential")
    sticks, taken = [], []
    for effective in (False, True):
        start = task.prepared(pipeline.initial_state(case, the_plan, system, effective_law=effective))
        ev = formulation.evaluate(problem, start, formulation.traction_scales(problem, start), cold=True)
        sticks.append(int(ev.stick.sum()))
        budget = Budget(200)
        solution = strategies.first_success(strategies.direct)(task, start, budget, cold=True)
        taken.append(budget.taken)
    solved = int(solution.stick.sum())
    assert abs(sticks[1] - solved) <= 5
    assert abs(sticks[1] - solved) < abs(sticks[0] - solved)
    assert taken[1] <= taken[0]


@pytest.mark.parametrize("tangential", [{"tangential.creep": -0.002}, {"tangential.q_over_mu_p": 0.5}])
def test_shared_creep_slope_matches_its_own_solve(tangential):
    """The recorded creep_slope (the sensitivities' dQ/dxi, or 1/(dxi/dQ) under force control: a fresh
    LU of the held matrix) against the slope's own solve (the bordered Newton matrix under force
    control, by GMRES on the Newton's kept LU to a direct solve's backward error). The same
    linear system solved two ways: 1e-10 relative covers cond(A) eps (measured 2e-16 to 1.3e-15)."""
    case = rolling_cli.load_case(law_case(**{"discretization.contact_elements": 100}, **tangential))
    path = MeshPath(case, pipeline.plan(case))
    final = path.run()
    result = pipeline.assemble(final, path.history, path.timings)
    problem, state = final.solved.problem, final.solved.state
    ev = formulation.evaluate(problem, state, formulation.traction_scales(problem, state))
    own = reduced.creep_sensitivity(problem, state, ev)
    assert math.isfinite(result.creep_slope) and own < 0.0
    assert abs(result.creep_slope - own) <= 1e-10 * abs(own)
    assert result.branch == "rising"
