"""Subsurface stresses of half-planes: exact element integrals, McEwen, Smith & Liu, signs, equilibrium.

Tolerances. The element integrals are exact for the interpolated tractions, so
they are compared with adaptive quadrature to its own tolerance. Against the
closed forms, the difference is the field of the traction error
delta(s) = (interpolated numerical traction) - (exact traction); every Flamant
kernel is bounded by 1/z (u^2 z/r^4, z^3/r^4, u z^2/r^4, |u|^3/r^4 <= 1/z),
so each stress component differs by at most

    eps(z) = (2/pi) (||delta p||_1 + ||delta q||_1) / z,

computed from the discretisation itself (:func:`l1_error`). Invariants move by
at most a Lipschitz multiple of eps: the von Mises stress by
sqrt(6 (1 + nu^2)) eps, a principal stress by (1 + sqrt(2)) eps.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from helpers import case_dict
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.model.grid import ContactGrid, shape_coefficients
from rolling_cli.references import hertz, mcewen, smith_liu
from rolling_cli.stresses import halfplane, invariants


def interpolated(grid, nodal, s):
    """The element interpolation of nodal values at points s (each strictly inside its element)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    e = np.clip(((s - grid.edges[0]) // grid.element_length).astype(int), 0, grid.elements - 1)
    xi = (s - grid.element_centres[e]) * 2.0 / grid.element_length
    coeff = np.asarray(nodal).reshape(grid.elements, grid.nodes_per_element) @ shape_coefficients(grid.order)
    return np.einsum("pm,pm->p", coeff[e], xi[:, None] ** np.arange(grid.nodes_per_element))


def l1_error(grid, nodal, exact, breaks=()):
    """int |interpolation of nodal - exact| ds over the zone, Gauss on each element cut at ``breaks``."""
    xg, wg = np.polynomial.legendre.leggauss(40)
    total = 0.0
    for lo, hi in zip(grid.edges[:-1], grid.edges[1:], strict=True):
        cuts = [lo, *sorted(b for b in breaks if lo < b < hi), hi]
        for c0, c1 in zip(cuts[:-1], cuts[1:], strict=True):
            s = 0.5 * (c0 + c1) + 0.5 * (c1 - c0) * xg
            total += 0.5 * (c1 - c0) * wg @ np.abs(interpolated(grid, nodal, s) - exact(s))
    return total


def flamant_quadrature(grid, p_n, q, x, z):
    """(sigma_xx, sigma_zz, tau_xz) by adaptive quadrature element by element (z > 0), or the surface
    values -p, -q and the principal value of the Hilbert transform (Cauchy weight) at z = 0."""
    out = np.zeros(3)
    for lo, hi in zip(grid.edges[:-1], grid.edges[1:], strict=True):
        mid = 0.5 * (lo + hi)

        def density(s, values):
            return interpolated(grid, values, mid + (s - mid) * (1 - 1e-14))[0]  # stay inside this element

        if z == 0.0:
            inside = lo < x < hi
            kwargs = {"weight": "cauchy", "wvar": x} if inside else {}
            f = (lambda s: density(s, q)) if inside else (lambda s: density(s, q) / (x - s))
            integral = quad(f, lo, hi, epsabs=1e-13, limit=200, **kwargs)[0]
            out[0] -= (2 / np.pi) * (-integral if inside else integral)  # cauchy weight: int f/(s - x)
            continue

        def kernel(s, k):
            u = x - s
            r4 = (u * u + z * z) ** 2
            p, t = -density(s, p_n), density(s, q)
            rows = ((p * u * u * z + t * u**3), (p * z**3 + t * u * z * z), (p * u * z * z + t * u * u * z))
            return -(2 / np.pi) * rows[k] / r4

        points = [x] if lo < x < hi else None
        for k in range(3):
            out[k] += quad(kernel, lo, hi, args=(k,), points=points, limit=400, epsabs=1e-13, epsrel=1e-12)[0]
    if z == 0.0 and grid.edges[0] < x < grid.edges[-1]:
        out[0] += interpolated(grid, p_n, x)[0]
        out[1] = interpolated(grid, p_n, x)[0]
        out[2] = -interpolated(grid, q, x)[0]
    return out


@pytest.mark.parametrize("order", [2, 0])
def test_element_integrals_equal_adaptive_quadrature_up_to_the_surface(order):
    """Random nodal tractions; points deep, shallow (1e-4 element lengths), at the surface and outside."""
    rng = np.random.default_rng(7)
    grid = ContactGrid(1.5, 7, order)
    p_n, q = -rng.random(grid.size), 0.3 * rng.standard_normal(grid.size)
    h = grid.element_length
    points = [(0.1, 0.5), (0.33, 0.01), (-1.2, 1e-4 * h), (2.0, 0.3), (0.7, 2.0), (0.05, 0.0), (-0.77, 0.0), (2.4, 0.0)]
    for x, z in points:
        expected = flamant_quadrature(grid, p_n, q, x, z)
        found = np.array([v.item() for v in halfplane.stresses_at(grid, p_n, q, x, z)])
        assert found == pytest.approx(expected, abs=1e-10), (x, z)


def _frictionless_solution(elements=100):
    case = load_case(
        case_dict(**{"friction.mu": 0.0, "tangential.q_over_mu_p": None, "discretization.contact_elements": elements})
    )
    result = pipeline.solve(case)
    return result, pipeline.plan(case).grid


def test_frictionless_hertz_contact_reproduces_mcewen():
    """A solved frictionless half-plane contact: the whole field below 0.25 a within eps(z) of McEwen's,
    the axis maximum shear 0.300 p0 at 0.786 a, the orthogonal shear extremes -+p0/4 at x = +-0.87 a,
    z = a/2, and the von Mises maximum for nu = 0.3 (0.5575 p0 at 0.704 a), each within the bound."""
    result, grid = _frictionless_solution()
    a, p0 = result.hertz_a, result.hertz_p0
    eps_l1 = (2 / np.pi) * l1_error(grid, result.p_n, lambda s: -hertz.pressure(s, a, p0), (-a, a))
    assert np.all(result.p_t == 0.0)

    x = np.linspace(-1.875, 1.875, 151) * a
    z = np.linspace(0.25, 3.0, 56) * a
    fields = halfplane.field(grid, result.p_n, result.p_t, x, z)
    closed = mcewen.stresses(x[None, :], z[:, None], a, p0)
    for found, expected in zip(fields, closed, strict=True):
        assert np.all(np.abs(found - expected) <= eps_l1 / z[:, None])

    # the axis maximum of the principal shear (sigma_xx - sigma_zz)/2: value within eps, depth within the
    # curvature bound 2 sqrt(eps/k), k = -f'' at the maximum
    peak, depth = mcewen.principal_shear_peak(a, p0)
    zz = np.linspace(0.5, 1.1, 601) * a
    sxx, szz, _ = halfplane.stresses_at(grid, result.p_n, result.p_t, 0.0, zz)
    shear = 0.5 * (sxx - szz)
    eps = eps_l1 / zz.min()
    step = 1e-3 * a
    curvature = -np.diff([0.5 * np.subtract(*mcewen.axis(depth + d, a, p0)) for d in (-step, 0, step)], 2)[0] / step**2
    assert abs(shear.max() - peak) <= eps
    assert abs(zz[shear.argmax()] - depth) <= 2.0 * np.sqrt(eps / curvature) + (zz[1] - zz[0])
    assert peak / p0 == pytest.approx(0.300, abs=5e-4)

    # orthogonal shear at z = a/2: extremes -+p0/4 at x = +-sqrt(3)/2 a, so a range of p0/2 over a pass
    top, x_top, z_top = mcewen.orthogonal_shear_peak(a, p0)
    xs = np.concatenate([np.linspace(-1.5, 1.5, 301) * a, [-x_top, x_top]])
    tau = halfplane.stresses_at(grid, result.p_n, result.p_t, xs, z_top)[2]
    eps = eps_l1 / z_top
    assert abs(tau.max() - top) <= eps and abs(tau.min() + top) <= eps
    assert abs(np.ptp(tau) - 2 * top) <= 2 * eps
    assert tau[-2] > 0.0 > tau[-1]  # +p0/4 at x = -0.87 a, -p0/4 at +0.87 a (the Flamant sign)

    # von Mises maximum (nu = 0.3)
    vm, vm_depth = mcewen.von_mises_peak(a, p0, 0.3)
    X, Z = np.meshgrid(np.linspace(-0.2, 0.2, 41) * a, np.linspace(0.55, 0.85, 61) * a)
    found = invariants.von_mises(*halfplane.stresses_at(grid, result.p_n, result.p_t, X, Z), 0.3)
    lipschitz = np.sqrt(6 * (1 + 0.3**2))
    assert abs(found.max() - vm) <= lipschitz * eps_l1 / Z.min()
    assert vm / p0 == pytest.approx(0.5575, abs=5e-5) and vm_depth / a == pytest.approx(0.704, abs=5e-4)


def _full_sliding(mu, elements=200, zone=1.5):
    """Hertz pressure and q = mu p sampled at the nodes (a = p0 = 1): Smith & Liu's tractions."""
    grid = ContactGrid(zone, elements, 2)
    p = hertz.pressure(grid.x, 1.0, 1.0)
    return grid, -p, mu * p


def test_full_sliding_matches_smith_liu_and_the_von_mises_maximum_reaches_the_surface():
    """Below the surface within eps(z); the von Mises maximum lies below the surface at mu = 0.2 and on it at
    mu = 0.35 (mu* = 0.263, test_stresses_references): the closed-form gaps between the surface and the
    subsurface maxima there (0.055 p0 and 0.030 p0) exceed the discretisation's error bound many times."""
    x = np.linspace(-1.875, 1.875, 151)
    z = np.linspace(0.0, 1.5, 76)
    for mu in (0.2, 0.35):
        grid, p_n, q = _full_sliding(mu)
        exact_p = lambda s: -hertz.pressure(s, 1.0, 1.0)  # noqa: E731
        exact_q = lambda s: mu * hertz.pressure(s, 1.0, 1.0)  # noqa: E731
        eps_l1 = (2 / np.pi) * (l1_error(grid, p_n, exact_p, (-1, 1)) + l1_error(grid, q, exact_q, (-1, 1)))
        fields = halfplane.field(grid, p_n, q, x, z)
        closed = smith_liu.stresses(x[None, :], z[:, None], 1.0, 1.0, mu)
        deep = z >= 0.1
        for found, expected in zip(fields, closed, strict=True):
            assert np.all(np.abs(found - expected)[deep] <= eps_l1 / z[deep, None])
        vm = invariants.von_mises(*fields, 0.3)
        iz, _ = np.unravel_index(vm.argmax(), vm.shape)
        assert (iz > 0) == (mu < 0.263)
        assert (z[iz] == pytest.approx(0.565, abs=0.05)) if mu < 0.263 else z[iz] == 0.0


def test_trailing_edge_tension_converges_to_two_mu_p0():
    """Full sliding, q = mu p on the body along +x: the surface tension peaks at x = -a (within a node
    spacing) and, sampled at the nodes, falls short of 2 mu p0 like the square root of the node spacing (a
    square-root cusp). With x = -a on an element edge the nearest node is h/6 away for every element count,
    so the deficit scales exactly: Richardson extrapolation from N and 4N with order 1/2 recovers 2 mu p0 up
    to the next term, O(h/a) (h/a = 0.005 at 4N = 600)."""
    mu = 0.3
    peaks = []
    for elements in (150, 600):
        grid, p_n, q = _full_sliding(mu, elements)
        sxx = halfplane.stresses_at(grid, p_n, q, grid.x, 0.0)[0]
        assert abs(grid.x[sxx.argmax()] + 1.0) <= grid.spacing
        peaks.append(sxx.max())
        assert sxx.max() < 2 * mu
    extrapolated = peaks[1] + (peaks[1] - peaks[0])  # deficit(N) = 2 deficit(4N)
    assert extrapolated == pytest.approx(2 * mu, rel=2 * 3 * 0.005)


def _carter():
    case = load_case(case_dict(**{"discretization.contact_elements": 60}))
    return pipeline.solve(case), pipeline.plan(case).grid


def _line_rule(z, inner, reach, order=20):
    """Composite Gauss rule on [-reach, reach] for fields at depth >= z below loads inside |x| < inner/2:
    panels z/2 wide over |x| < inner, then growing by 1.5 per panel. Each panel is at least its half-width
    from the integrand's complex poles (x = s +- i z), so 20 points give a relative error below 1e-15."""
    near = np.linspace(-inner, inner, int(np.ceil(2 * inner / (0.5 * z))) + 1)
    far = [inner]
    while far[-1] < reach:
        far.append(min(1.5 * far[-1], reach))
    edges = np.concatenate([-np.array(far[::-1]), near[1:-1], np.array(far)])
    xg, wg = np.polynomial.legendre.leggauss(order)
    mid, half = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
    return (mid[:, None] + half[:, None] * xg).ravel(), (half[:, None] * wg).ravel()


def _tails(load, at_load, force, at_force, z, reach):
    """int over |x| > reach of (sigma_zz, tau_xz) at depth z of line loads P at x = at_load and Q at x = at_force
    (Flamant: -(2/pi) (P z^3 + Q u z^2, P u z^2 + Q u^2 z) / r^4, u = x - at); the loads' moments about
    their centroids change them by a relative (a/reach)^2."""

    def one_sided(c):  # int_c^inf of z^3/r^4, u z^2/r^4 and u^2 z/r^4 du (r^2 = u^2 + z^2)
        atan = np.arctan(c / z)
        return (
            (np.pi / 2 - atan) / 2 - c * z / (2 * (c * c + z * z)),
            z * z / (2 * (c * c + z * z)),
            ((np.pi / 2 - atan) + c * z / (c * c + z * z)) / 2,
        )

    def both(at):  # right tail from reach - at, left from reach + at (odd kernels change sign)
        right, left = one_sided(reach - at), one_sided(reach + at)
        return right[0] + left[0], right[1] - left[1], right[2] + left[2]

    p0, p1, _ = both(at_load)
    _, q1, q2 = both(at_force)
    return -(2 / np.pi) * (load * p0 + force * q1), -(2 / np.pi) * (load * p1 + force * q2)


def test_surface_values_sign_convention_and_equilibrium_of_both_bodies():
    """Each body in its own frame: sigma_zz(x_i, 0) = p_n and tau_xz(x_i, 0) = -p_t on A, +p_t on B at the
    nodes (to rounding). Along a whole line at depth z, int tau_xz dx = -Q on A and +Q on B, and
    int sigma_zz dx = -P (slab equilibrium): quadrature over |x| < L = 20 a (:func:`_line_rule`) plus the
    tails beyond L of the resultant loads at their centroids (:func:`_tails`), which the loads' spread
    changes by a relative (a/L)^2 = 1/400: the tolerance is 1/100 of the tails plus rounding (1e-9 of P)."""
    result, grid = _carter()
    load, force = result.normal_load, result.tangential_load
    a = result.hertz_a
    reach = 20.0 * a
    assert force > 0.0
    nodes, weights = _line_rule(0.05 * a, 2.0 * a, reach)
    at_load = -(result.weights * result.p_n) @ result.x / load
    for sign in (1.0, -1.0):  # A, B
        q = sign * result.p_t
        _, szz, txz = halfplane.stresses_at(grid, result.p_n, q, grid.x, 0.0)
        scale = np.abs(result.p_n).max()
        assert szz == pytest.approx(result.p_n, abs=1e-12 * scale)
        assert txz == pytest.approx(-sign * result.p_t, abs=1e-12 * scale)
        at_force = (result.weights * q) @ result.x / (sign * force)
        for z in (0.05 * a, 0.7 * a):
            line = halfplane.stresses_at(grid, result.p_n, q, nodes, z)
            tail_zz, tail_xz = _tails(load, at_load, sign * force, at_force, z, reach)
            assert weights @ line[1] + tail_zz == pytest.approx(-load, abs=abs(tail_zz) / 100 + 1e-9 * load)
            assert weights @ line[2] + tail_xz == pytest.approx(-sign * force, abs=abs(tail_xz) / 100 + 1e-9 * load)


def test_invariants_equal_the_eigenvalues_of_the_plane_strain_tensor():
    rng = np.random.default_rng(3)
    sxx, szz, txz = rng.standard_normal((3, 500))
    nu = 0.27
    principal = invariants.principal(sxx, szz, txz, nu)
    tensors = np.zeros((500, 3, 3))
    tensors[:, 0, 0], tensors[:, 2, 2], tensors[:, 0, 2], tensors[:, 2, 0] = sxx, szz, txz, txz
    tensors[:, 1, 1] = nu * (sxx + szz)
    eig = np.linalg.eigvalsh(tensors)[:, ::-1].T
    assert principal == pytest.approx(eig, abs=1e-13)
    deviator = tensors - np.trace(tensors, axis1=1, axis2=2)[:, None, None] / 3 * np.eye(3)
    mises = np.sqrt(1.5 * np.einsum("pij,pij->p", deviator, deviator))
    assert invariants.von_mises(sxx, szz, txz, nu) == pytest.approx(mises, abs=1e-13)
    assert invariants.tresca(principal) == pytest.approx(eig[0] - eig[2], abs=1e-13)
    tau = rng.standard_normal((4, 9))
    assert invariants.orthogonal_shear_range(tau) == pytest.approx(tau.max(axis=1) - tau.min(axis=1))
