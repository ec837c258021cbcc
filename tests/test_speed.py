"""The cost work of issues 22 and 23: a reused factorisation, the viscoelastic cold start and the
hysteresis's digamma series, each against an independent route (a direct LU, Hertz's closed form,
the solved contact, scipy's digamma)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import psi
from test_friction_laws import EXPONENTIAL, law_case
from test_viscoelastic import ROLLER, _roller_a, _with_speed

import rolling_cli
from helpers import CARTER, case_dict, dissimilar
from rolling_cli.pipeline import prepare
from rolling_cli.references import hysteresis
from rolling_cli.solver import reuse
from rolling_cli.solver.initial import effective_hertz

EPS = np.finfo(float).eps


class _Owner:
    """A stand-in for the contact system a factorisation belongs to (weakly referenced)."""


def _scaled_system(rng, n: int, spread: float) -> tuple[np.ndarray, np.ndarray]:
    """A diagonally dominant matrix whose rows are scaled over ``spread`` decades, and a rhs."""
    matrix = rng.standard_normal((n, n)) + 2.0 * n**0.5 * np.eye(n)
    rows = 10.0 ** rng.uniform(-spread / 2, spread / 2, n)
    return rows[:, None] * matrix, rows * rng.standard_normal(n)


def _componentwise(matrix, x, rhs) -> float:
    """max_i |b - A x|_i / (|A| |x| + |b|)_i / eps: the backward error a direct solve leaves, ~1-10."""
    return float(np.max(np.abs(rhs - matrix @ x) / (np.abs(matrix) @ np.abs(x) + np.abs(rhs))) / EPS)


@pytest.mark.parametrize("n", [300, 1300], ids=["double LU", "single-precision LU"])
def test_reused_factorisation_solves_to_a_direct_solves_accuracy(n):
    """GMRES on an earlier matrix's LU solves a matrix 1 % away to a componentwise backward error of
    a few eps, rows scaled over 12 decades (a norm-wise target would leave the small rows
    inaccurate), no worse than a direct LU's. Bound 8 eps: the target is 4 eps against the kept
    matrix's |A|, which differs from the present one's by the 1 % perturbation. From 1200 unknowns
    the kept LU is single precision and even the first solve is refined to double by GMRES."""
    rng = np.random.default_rng(3)
    owner = _Owner()
    first, rhs = _scaled_system(rng, n, 12.0)
    reuse.release()
    record: dict = {}
    x0 = reuse.solve(first, rhs, owner, ("layout",), record)
    assert record["linear_solver"] == "dense LU"
    assert _componentwise(first, x0, rhs) <= 8.0
    moved = first * (1.0 + 0.01 * rng.standard_normal(first.shape))
    x1 = reuse.solve(moved, rhs, owner, ("layout",), record)
    assert record["linear_solver"] == "reused LU + GMRES" and record["reuse_iterations"] > 0
    assert _componentwise(moved, x1, rhs) <= 8.0
    # no worse than a direct solve's (partial pivoting favours the large rows: measured 160 eps)
    assert _componentwise(moved, x1, rhs) <= _componentwise(moved, np.linalg.solve(moved, rhs), rhs)
    other: dict = {}
    reuse.solve(moved, rhs, _Owner(), ("layout",), other)  # another system: a fresh LU
    assert other["linear_solver"] == "dense LU"
    reuse.release()


def test_falling_law_newton_steps_are_the_same_with_the_reused_factorisation(monkeypatch):
    """The reused LU changes the cost of a step, not the step: the same Newton iterations and the
    same solution as with a fresh LU every step (``REUSE_SIZE`` raised), to the round-off of the
    Newton systems (backward error ~eps, condition ~1e3 at 400 unknowns: 1e-12 of the traction)."""
    data = law_case(CARTER, EXPONENTIAL, **{"discretization.contact_elements": 200, "tangential.creep": -0.002})
    reused = rolling_cli.solve(rolling_cli.load_case(data))
    assert any(row.get("linear_solver") == "reused LU + GMRES" for row in reused.history)
    monkeypatch.setattr(reuse, "REUSE_SIZE", 10**9)
    fresh = rolling_cli.solve(rolling_cli.load_case(data))
    assert not any(row.get("linear_solver") == "reused LU + GMRES" for row in fresh.history)
    assert [row["residual"] > 1e-9 for row in reused.history] == [row["residual"] > 1e-9 for row in fresh.history]
    scale = float(np.max(np.abs(fresh.p_t)))
    assert np.max(np.abs(reused.p_t - fresh.p_t)) <= 1e-12 * scale
    assert reused.attributes["creep_slope"] == pytest.approx(fresh.attributes["creep_slope"], rel=1e-12)


@pytest.mark.parametrize("base", [CARTER, dissimilar()], ids=["similar", "dissimilar"])
def test_effective_hertz_is_hertz_on_elastic_half_planes(base):
    """On elastic half-planes the fitted Hertz pressure is Hertz's own: a within a tenth of an
    element of the Hertz half-width (the fit sees the displacement of the piecewise-constant
    pressure, exact to O(h^2) inside the contact; measured 0.03 h) and no shift (the problem is
    symmetric: round-off)."""
    case = rolling_cli.load_case(case_dict(base, **{"discretization.contact_elements": 100}))
    the_plan, system = prepare(case)
    a, centre = effective_hertz(system, the_plan.half_width, the_plan.load)
    assert abs(a - the_plan.half_width) <= 0.1 * system.spacing
    assert abs(centre) <= 1e-12 * the_plan.half_width


@pytest.mark.parametrize("ratio", [0.1, 1.0, 10.0])
def test_effective_hertz_finds_the_viscoelastic_contact_width(ratio):
    """A rigid roller on an SLS flat (E_g = 2 E_r): the fitted half-width is the solved contact's
    within 2.5 % of a_r over V tau_c / a_r = 0.1-10 (measured 0.1-2.1 %: the pressure is skewed,
    the fit's is Hertz's), between the glassy and relaxed Hertz widths (a_r / sqrt(2) and a_r), and
    the fitted centre lies on the leading side (the contact moves forward: sgn(V) x < 0)."""
    a_r = _roller_a()
    case = rolling_cli.load_case(_with_speed(ROLLER, ratio, a_r))
    the_plan, system = prepare(case)
    a, centre = effective_hertz(system, the_plan.half_width, the_plan.load)
    solved = rolling_cli.solve(case)
    x = np.asarray(solved.x)[np.asarray(solved.p_n) < 0.0]
    assert abs(a - 0.5 * (x.max() - x.min() + system.spacing)) <= 0.025 * a_r
    assert a_r / np.sqrt(2.0) * (1.0 - 1e-3) <= a <= a_r * (1.0 + 1e-3)
    assert case.rolling.direction * centre < 0.0


def test_digamma_difference_matches_scipy():
    """Re psi(1 + x - i beta) - psi(1 + x) by the recurrence and asymptotic series against scipy's
    complex digamma: 1e-14 absolute (the series' truncation 3e-16, the ten recurrence terms' and
    the logarithm's round-off a few eps of values ~1)."""
    x = np.linspace(0.0, 1.0, 101)
    for beta in (0.0, 1e-6, 1e-3, 0.1, 1.0, 30.0):
        exact = np.real(psi(1.0 + x - 1j * beta)) - psi(1.0 + x)
        assert np.max(np.abs(hysteresis._digamma_difference(x, beta) - exact)) <= 1e-14
