"""The closed forms of McEwen and Smith & Liu, checked against independent facts.

They judge the stress fields, so they are first checked themselves: against
adaptive quadrature of the Flamant line-load kernels (Johnson 2.15, 2.19) over
the Hertz densities (quadrature tolerance 1e-11 of p0), and for the classic
values quoted in the literature. The quoted values carry three digits, so
they are compared to half a unit of their last digit.
"""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import minimize

from rolling_cli.references import mcewen, smith_liu
from rolling_cli.stresses import invariants

A, P0 = 1.3, 250.0


def flamant(x, z, pressure, traction):
    """(sigma_xx, sigma_zz, tau_xz) of densities on [-A, A] by adaptive quadrature of the line-load kernels."""

    def kernel(s, k):
        u = x - s
        r4 = (u * u + z * z) ** 2
        p, q = pressure(s), traction(s)
        if k == 0:
            return -(2 / np.pi) * (p * u * u * z + q * u**3) / r4
        if k == 1:
            return -(2 / np.pi) * (p * z**3 + q * u * z * z) / r4
        return -(2 / np.pi) * (p * u * z * z + q * u * u * z) / r4

    points = [x] if abs(x) < A else None
    return np.array(
        [quad(kernel, -A, A, args=(k,), points=points, limit=400, epsabs=1e-11 * P0, epsrel=1e-12)[0] for k in range(3)]
    )


def hertz(s):
    return P0 * np.sqrt(max(1.0 - (s / A) ** 2, 0.0))


POINTS = [(0.3, 0.5), (-0.7, 0.2), (1.9, 0.4), (-2.6, 1.3), (0.0, 2.0), (1.1, 0.05), (-1.25, 0.01)]


@pytest.mark.parametrize("x, z", POINTS)
def test_mcewen_is_the_flamant_integral_of_the_hertz_pressure(x, z):
    expected = flamant(x * A, z * A, hertz, lambda s: 0.0)
    assert np.array(mcewen.stresses(x * A, z * A, A, P0)) == pytest.approx(expected, abs=1e-9 * P0)


@pytest.mark.parametrize("x, z", POINTS)
def test_smith_liu_is_the_flamant_integral_of_the_hertz_traction(x, z):
    mu = 0.4
    expected = flamant(x * A, z * A, lambda s: 0.0, lambda s: mu * hertz(s))
    assert np.array(smith_liu.traction_stresses(x * A, z * A, A, mu * P0)) == pytest.approx(expected, abs=1e-9 * P0)


def test_surface_limits_of_the_closed_forms():
    """At z = 0: sigma_zz = -p, tau_xz = -q, and sigma_xx of Smith & Liu's surface formula."""
    x = np.linspace(-2.5, 2.5, 101) * A
    sxx, szz, txz = smith_liu.stresses(x, 0.0, A, P0, 0.3)
    p = np.array([hertz(s) for s in x])
    assert szz == pytest.approx(-p, abs=1e-12 * P0)
    assert txz == pytest.approx(-0.3 * p, abs=1e-12 * P0)
    assert sxx == pytest.approx(smith_liu.surface_sigma_xx(x, A, P0, 0.3), abs=1e-12 * P0)
    # the pressure part alone: sigma_xx = -p inside, 0 outside
    assert mcewen.stresses(x, 0.0, A, P0)[0] == pytest.approx(-p, abs=1e-12 * P0)


def test_surface_sigma_xx_is_the_hilbert_transform_of_the_traction():
    """-p - (2/pi) pv int q(s)/(x - s) ds, the principal value by quadrature (Cauchy weight)."""
    mu = 0.25
    for x in (-1.7, -0.6, 0.2, 0.9, 2.2):
        pv = quad(lambda s: mu * hertz(s), -A, A, weight="cauchy", wvar=x * A, epsabs=1e-12 * P0)[0]
        expected = -hertz(x * A) + (2.0 / np.pi) * pv  # int q/(s - x) = -int q/(x - s)
        assert smith_liu.surface_sigma_xx(x * A, A, P0, mu) == pytest.approx(expected, abs=1e-9 * P0)


def test_classic_mcewen_values():
    """Maximum shear 0.300 p0 at z = 0.786 a on the axis; orthogonal shear extremes -+p0/4 at
    x = +-sqrt(3)/2 a, z = a/2 (their range over a pass p0/2); von Mises maximum on the axis."""
    value, depth = mcewen.principal_shear_peak(A, P0)
    assert value / P0 == pytest.approx(0.300, abs=5e-4) and depth / A == pytest.approx(0.786, abs=5e-4)
    # the orthogonal shear peak is the maximum of |tau_xz| over the whole field
    peak, x_peak, z_peak = mcewen.orthogonal_shear_peak(A, P0)
    found = minimize(
        lambda v: -abs(float(mcewen.stresses(v[0], v[1], A, P0)[2])),
        x0=[0.8 * A, 0.6 * A],
        method="Nelder-Mead",
        options={"xatol": 1e-10, "fatol": 1e-12 * P0},
    )
    assert -found.fun == pytest.approx(peak, rel=1e-9)
    assert found.x == pytest.approx([x_peak, z_peak], abs=1e-5 * A)
    assert peak / P0 == 0.25 and x_peak / A == pytest.approx(0.866, abs=5e-4)
    assert mcewen.stresses(-x_peak, z_peak, A, P0)[2] == pytest.approx(peak, rel=1e-12)
    # von Mises: the axis maximum is the maximum over the field (nu = 0.3: 0.5575 p0 at z = 0.704 a)
    vm, vm_depth = mcewen.von_mises_peak(A, P0, 0.3)
    X, Z = np.meshgrid(np.linspace(-2.0, 2.0, 401) * A, np.linspace(0.01, 2.0, 200) * A)
    field = invariants.von_mises(*mcewen.stresses(X, Z, A, P0), 0.3)
    assert field.max() <= vm * (1 + 1e-12)
    assert vm / P0 == pytest.approx(0.5575, abs=5e-5) and vm_depth / A == pytest.approx(0.704, abs=5e-4)


def test_full_sliding_surface_tension_and_where_the_von_mises_maximum_goes():
    """Smith & Liu: the largest tension 2 mu p0 at the trailing edge x = -a; the von Mises maximum
    leaves the subsurface for the surface as mu passes mu* (0.263 for nu = 0.3)."""
    mu = 0.3
    x = np.linspace(-3.0, 3.0, 60001) * A
    surface = smith_liu.surface_sigma_xx(x, A, P0, mu)
    tension, where = smith_liu.max_surface_tension(A, P0, mu)
    assert surface.max() == pytest.approx(tension, rel=1e-12) and x[surface.argmax()] == pytest.approx(where)
    assert tension == 2.0 * mu * P0 and where == -A

    def gap(mu):  # surface maximum minus subsurface maximum of the von Mises stress
        X, Z = np.meshgrid(np.linspace(-1.5, 1.5, 301) * A, np.linspace(0.0, 1.5, 151) * A)
        field = invariants.von_mises(*smith_liu.stresses(X, Z, A, P0, mu), 0.3)
        return field[0].max() - field[3:].max()

    assert gap(0.2) < 0.0 < gap(0.35)
    low, high = 0.2, 0.35
    for _ in range(12):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if gap(mid) < 0.0 else (low, mid)
    assert 0.25 < low < 0.30  # "about 0.3"; the grids above resolve it to ~0.01
