"""The closed-form reference modules checked against independent facts.

The references are used to judge the solver, so they must themselves be
right: integrals by independent quadrature, limits, signs and symmetry.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from rolling_cli.model import materials
from rolling_cli.references import carter, hertz


def test_hertz_pressure_integrates_to_load():
    P, R, E = 1812.5, 50.0, 115384.6
    a = hertz.half_width(P, R, E)
    p0 = hertz.peak_pressure(P, a)
    total, _ = quad(lambda x: hertz.pressure(np.array([x]), a, p0)[0], -a, a, limit=200)
    assert total == pytest.approx(P, rel=1e-9)
    assert hertz.load_for_half_width(a, R, E) == pytest.approx(P, rel=1e-14)


@pytest.mark.parametrize("q", [-0.84, -0.2, 0.2, 0.51, 0.84, 0.999])
@pytest.mark.parametrize("direction", [-1, 1])
def test_carter_traction_integrates_to_q_and_respects_friction(q, direction):
    a, p0, mu = 1.0, 1000.0, 0.1
    P = np.pi * a * p0 / 2.0
    c = carter.stick_half_width(q, a)
    d = carter.stick_centre(q, a, direction)
    pts = sorted({-a, d - c, d + c, a})
    total = sum(
        quad(lambda x: carter.traction(np.array([x]), q, a, p0, mu, direction)[0], lo, hi)[0]
        for lo, hi in zip(pts[:-1], pts[1:], strict=True)
    )
    assert total == pytest.approx(q * mu * P, rel=1e-8)
    x = np.linspace(-a, a, 2001)
    pt = carter.traction(x, q, a, p0, mu, direction)
    assert np.all(np.abs(pt) <= mu * hertz.pressure(x, a, p0) + 1e-9)
    assert np.all(np.sign(pt[np.abs(pt) > 0]) == np.sign(q))
    # adhesion at the leading edge: the edge the material enters, at -direction * a
    assert np.sign(d) == -direction or c == pytest.approx(a)


def test_carter_creepage_limits_and_sign():
    a, R, mu = 1.0, 50.0, 0.1
    assert carter.creepage(0.0, a, R, mu) == 0.0
    assert carter.creepage(1.0, a, R, mu) == pytest.approx(-mu * a / R)
    assert carter.creepage(-0.5, a, R, mu) == pytest.approx(-carter.creepage(0.5, a, R, mu))
    assert carter.full_slip_creepage(a, R, mu) == pytest.approx(mu * a / R)


def test_materials_beta_seed_aluminium_steel():
    """PHYSICS.md: aluminium/steel gives beta_seed = 0.288 and Kalker K = 0.100 (K/G * G)."""
    e_al, e_st = 2 * 23000 * 1.31, 2 * 82000 * 1.28
    beta = materials.beta_seed(e_al, 0.31, e_st, 0.28)
    assert beta == pytest.approx(0.288, abs=5e-4)
    assert materials.dundurs_beta(e_al, 0.31, e_st, 0.28) == pytest.approx(beta / 2)
    g = 2.0 / (1 / 23000 + 1 / 82000)
    assert materials.kalker_k_over_g(e_al, 0.31, e_st, 0.28) * g == pytest.approx(0.100, abs=5e-4)
    # exact zeros: similar materials, rigid against incompressible
    assert materials.kalker_k_over_g(2e5, 0.3, 2e5, 0.3) == 0.0
    assert materials.kalker_k_over_g(np.inf, 0.0, 2e5, 0.5) == 0.0
