"""The half-plane solver against Hertz and Carter (similar cylinders).

Tolerances (measured values in brackets, for 200 quadratic elements over 1.5 a,
node spacing Delta = a/200):
* Contact edge: the discrete contact ends at a node cell, so its half-width is
  resolved to one node spacing Delta [error 0 or Delta/2].
* Hertz pressure away from the edges (|x| < 0.9 a), where it is smooth:
  1e-3 p0 [1e-5 p0].
* Maximum traction and pressure errors: both closed forms have a square-root
  edge (Hertz at x = +-a, Carter at the adhesion/slip boundary too), so moving
  the discrete edge by a fraction of a cell changes the traction by
  ~ p0 sqrt(Delta / a). Bound 0.15 sqrt(Delta/a) [largest measured constant
  0.11, from the worst alignment of a within a cell]. At 200 elements this is
  0.0106 mu p0, inside the issue's 2 %.
* Creepage: within 1 % of Carter's formula [0.08-0.12 %].
"""

import numpy as np
import pytest

from helpers import assert_contact_laws, assert_force_balance, case_dict, solve
from rolling_cli.references import carter, hertz


def _edge_bound(result):
    return 0.15 * np.sqrt(result.node_spacing / result.hertz_a)


def test_hertz_pressure_and_half_width():
    r = solve(case_dict(**{"tangential.q_over_mu_p": None}))
    a, p0 = r.hertz_a, r.hertz_p0
    exact = hertz.pressure(r.x, a, p0)
    assert abs(r.contact_half_width - a) <= r.node_spacing
    assert abs(r.contact_centre) <= r.node_spacing
    inner = np.abs(r.x) < 0.9 * a
    assert np.max(np.abs(-r.p_n[inner] - exact[inner])) <= 1e-3 * p0
    assert np.max(np.abs(-r.p_n - exact)) <= _edge_bound(r) * p0
    assert_contact_laws(r)
    assert_force_balance(r, load=1812.5)
    assert np.all(r.p_t == 0.0) and r.creep == 0.0  # beta = 0 and Q = 0: tangential skipped, exact


@pytest.mark.parametrize("q", [0.2, 0.51, 0.84])
def test_carter(q):
    r = solve(case_dict(**{"tangential.q_over_mu_p": q}))
    a, p0, mu = r.hertz_a, r.hertz_p0, r.mu
    exact = carter.traction(r.x, q, a, p0, mu, direction=-1)
    error = np.max(np.abs(r.p_t - exact)) / (mu * p0)
    assert error <= 0.02
    assert error <= _edge_bound(r)
    # adhesion zone at the leading edge (+x for V < 0), half-width c = a sqrt(1 - q)
    stick = r.state == 1
    lo, hi = r.x[stick].min(), r.x[stick].max()
    c = 0.5 * (hi - lo + r.node_spacing)
    assert abs(c - a * np.sqrt(1 - q)) <= r.node_spacing
    assert abs(hi + 0.5 * r.node_spacing - a) <= r.node_spacing  # touches the leading edge
    assert np.all(r.state[r.x < lo] != 1)
    assert r.creep == pytest.approx(carter.creepage(q, a, 50.0, mu), rel=0.01)  # R* = 50 mm
    assert_contact_laws(r)
    assert_force_balance(r, load=1812.5, q=q * mu * 1812.5)


@pytest.mark.parametrize("q", [0.2, 0.51, 0.84])
def test_carter_error_falls_under_refinement(q):
    """Refining by 4 at fixed edge alignment must shrink the error (rate ~ N^-1/2, so >= 1.5x)."""
    errors = []
    for elements in (50, 200, 800):
        r = solve(case_dict(**{"tangential.q_over_mu_p": q, "discretization.contact_elements": elements}))
        exact = carter.traction(r.x, q, r.hertz_a, r.hertz_p0, r.mu, direction=-1)
        errors.append(np.max(np.abs(r.p_t - exact)) / (r.mu * r.hertz_p0))
    assert errors[0] > 1.5 * errors[1] > 2.25 * errors[2]


def test_reversing_the_rolling_direction_mirrors_the_solution():
    fwd = solve(case_dict(**{"rolling.direction": -1}))
    back = solve(case_dict(**{"rolling.direction": 1}))
    assert np.allclose(back.x, -fwd.x[::-1])
    scale = fwd.mu * fwd.hertz_p0
    assert np.max(np.abs(back.p_t - fwd.p_t[::-1])) <= 1e-9 * scale
    assert np.max(np.abs(back.p_n - fwd.p_n[::-1])) <= 1e-9 * fwd.hertz_p0
    assert np.array_equal(back.state, fwd.state[::-1])
    assert back.creep == pytest.approx(fwd.creep, rel=1e-9)
    # the adhesion zone follows the leading edge: +x for V < 0, -x for V > 0
    assert fwd.x[fwd.state == 1].mean() > 0 > back.x[back.state == 1].mean()


@pytest.mark.parametrize("kind,value", [("load", 50.0), ("q_over_p", 0.03), ("creep", -4e-4)])
def test_other_tangential_controls_agree_with_carter(kind, value):
    r = solve(case_dict(**{f"tangential.{kind}": value}))
    q = r.tangential_load / (r.mu * r.normal_load)
    if kind == "load":
        assert r.tangential_load == pytest.approx(value, rel=1e-9)
    elif kind == "q_over_p":
        assert q * r.mu == pytest.approx(value, rel=1e-9)
    else:
        assert r.creep == value
    assert r.creep == pytest.approx(carter.creepage(q, r.hertz_a, 50.0, r.mu), rel=0.01)
    assert_contact_laws(r)
