"""Flamant's line-force solution and the half-space approach: the closed forms the BEM far field rests on."""

import numpy as np
import pytest
from scipy import integrate

from rolling_cli.references import approach, flamant, hertz

E, NU, DEPTH = 2.0e5, 0.3, 7.0


def _points(count=25, seed=3):
    rng = np.random.default_rng(seed)
    return rng.uniform(-3.0, 3.0, count), rng.uniform(0.05, 3.0, count)


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.5])
def test_displacements_give_flamant_stresses_through_hookes_law(nu):
    """Central differences of u (step h = 1e-5, truncation ~h^2 / r^2 ~ 1e-8 at r >= 0.05,
    round-off ~1e-16 / h ~ 1e-11 relative) through plane-strain Hooke's law must give
    Flamant's radial stress field to 1e-6 of its largest value."""
    x, z = _points()
    h = 1e-5
    u = lambda x, z: flamant.displacement(x, z, E, nu, DEPTH)  # noqa: E731
    du_dx = (u(x + h, z) - u(x - h, z)) / (2 * h)
    du_dz = (u(x, z + h) - u(x, z - h)) / (2 * h)
    e_xx, e_zz = du_dx[:, 0, :], du_dz[:, 1, :]
    e_xz = 0.5 * (du_dz[:, 0, :] + du_dx[:, 1, :])
    shear = E / (2 * (1 + nu))
    if nu == 0.5:  # incompressible: the pressure is not given by the strains; compare deviators and e_kk = 0
        assert np.abs(e_xx + e_zz).max() <= 1e-6 * np.abs(e_xx).max()
        s = flamant.stress(x, z)
        assert np.allclose(2 * shear * (e_xx - e_zz), s[:, 0] - s[:, 1], rtol=0, atol=1e-6 * np.abs(s).max())
        assert np.allclose(2 * shear * e_xz, s[:, 2], rtol=0, atol=1e-6 * np.abs(s).max())
        return
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    stress = np.stack(
        [lam * (e_xx + e_zz) + 2 * shear * e_xx, lam * (e_xx + e_zz) + 2 * shear * e_zz, 2 * shear * e_xz], 1
    )
    exact = flamant.stress(x, z)
    assert np.abs(stress - exact).max() <= 1e-6 * np.abs(exact).max()


def test_stresses_balance_the_unit_forces_and_free_the_surface():
    """The traction on a semicircle around the force balances it (Gauss-Legendre, exact to
    1e-13 for this trigonometric integrand), and the surface z = 0 is traction-free."""
    theta, w = np.polynomial.legendre.leggauss(40)
    theta, w = 0.5 * np.pi * theta, 0.5 * np.pi * w
    r = 2.5
    x, z = r * np.sin(theta), r * np.cos(theta)
    s = flamant.stress(x, z)  # (q, 3, l)
    n = np.stack([np.sin(theta), np.cos(theta)], 1)  # outward normal of the inner body
    t_x = s[:, 0] * n[:, 0, None] + s[:, 2] * n[:, 1, None]
    t_z = s[:, 2] * n[:, 0, None] + s[:, 1] * n[:, 1, None]
    force = np.stack([w @ (t_x * r), w @ (t_z * r)])  # [component, unit force axis]
    assert np.allclose(force, -np.eye(2), atol=1e-13)
    surface = flamant.stress(np.array([-2.0, 0.7]), np.zeros(2))
    # sigma_zz, sigma_xz vanish on z = 0, to the round-off of cos(pi/2) ~ 6e-17 against sigma_xx
    assert np.abs(surface[:, 1:]).max() <= 1e-15 * np.abs(surface[:, 0]).max()


def test_surface_displacements_match_the_half_plane_kernels_and_vanish_at_the_reference():
    """On the surface, Johnson's kernels (the closed-form half-plane model): the
    normal force gives u_x = -c sgn(x), the tangential one u_z = c sgn(x), and the log
    terms are -k ln|x| up to a constant; the displacement is zero at (0, DEPTH)."""
    k = 2 * (1 - NU**2) / (np.pi * E)
    c = (1 - 2 * NU) * (1 + NU) / (2 * E)
    x = np.array([-3.0, -0.4, 0.2, 1.0, 5.0])
    u = flamant.displacement(x, np.zeros_like(x), E, NU, DEPTH)
    assert np.allclose(u[:, 0, 1], -c * np.sign(x), rtol=1e-14, atol=0)
    assert np.allclose(u[:, 1, 0], c * np.sign(x), rtol=1e-14, atol=0)
    for comp, load in ((1, 1), (0, 0)):
        rest = u[:, comp, load] + k * np.log(np.abs(x))
        assert np.ptp(rest) <= 1e-14 * k
    assert np.abs(flamant.displacement(0.0, DEPTH, E, NU, DEPTH)).max() == 0.0


@pytest.mark.parametrize("nu", [0.25, 0.5])
def test_approach_equals_the_integrated_flamant_displacement(nu):
    """The closed-form approach against an independent quadrature of Flamant's relative
    displacement under the Hertz pressure (adaptive, the log point split off, converged to
    ~1e-12). The closed form drops O((a/d)^4) = 1e-8 terms, times the mean of (s/a)^4 (1/8)
    over ln(2d/a) ~ 5: 1e-9 relative."""
    load, a, depth = 300.0, 0.4, 40.0
    p0 = hertz.peak_pressure(load, a)

    def relative(s):  # u_z at the surface point x = 0 minus u_z at (0, depth), for the force at s
        u = flamant.displacement(np.array([-s, -s]), np.array([0.0, depth]), E, nu, depth)
        return hertz.pressure(np.array([s]), a, p0)[0] * (u[0, 1, 1] - u[1, 1, 1])

    value = integrate.quad(relative, -a, 0.0, limit=200)[0] + integrate.quad(relative, 0.0, a, limit=200)[0]
    assert value == pytest.approx(approach.approach(load, a, E, nu, depth), rel=1e-9)
    assert approach.approach(load, a, float("inf"), nu, depth) == 0.0
