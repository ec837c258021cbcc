"""Closed-form half-plane influence against independent quadrature and physics."""

import numpy as np
import pytest
from scipy.integrate import quad

from rolling_cli.influence import combine, halfplane
from rolling_cli.model import materials
from rolling_cli.model.grid import NODE_COORDINATES, ContactGrid, shape_coefficients
from rolling_cli.model.kernels import log_moments


def _shape(grid, j, s):
    """Value of node j's shape function at position s (independent evaluation)."""
    m = grid.nodes_per_element
    e, k = divmod(j, m)
    lo, hi = grid.edges[e], grid.edges[e + 1]
    if not lo <= s <= hi:
        return 0.0
    xi = (2 * s - lo - hi) / (hi - lo)
    nodes = NODE_COORDINATES[grid.order]
    others = [n for i, n in enumerate(nodes) if i != k]
    return float(np.prod([(xi - o) / (nodes[k] - o) for o in others]))


@pytest.mark.parametrize("order", [0, 2])
def test_log_and_sign_matrices_match_quadrature(order):
    grid = ContactGrid(half_width=1.5, elements=7, order=order)
    L = 2.0
    log = halfplane.log_matrix(grid, L)
    sgn = halfplane.sign_matrix(grid)
    rng = np.random.default_rng(3)
    n = grid.size
    pairs = [(0, 0), (n - 1, 0), (n // 2, n // 2), (n // 2, n // 2 + 1)]
    pairs += [tuple(rng.integers(0, n, 2)) for _ in range(8)]
    for i, j in pairs:
        e = j // grid.nodes_per_element
        lo, hi = grid.edges[e], grid.edges[e + 1]
        xi = grid.x[i]
        brk = [xi] if lo < xi < hi else None
        ref_log = quad(
            lambda s: _shape(grid, j, s) * np.log(abs(xi - s) / L) if s != xi else 0.0, lo, hi, points=brk, limit=200
        )[0]
        ref_sgn = quad(lambda s: _shape(grid, j, s) * np.sign(xi - s), lo, hi, points=brk)[0]
        assert log[i, j] == pytest.approx(ref_log, abs=1e-11)
        assert sgn[i, j] == pytest.approx(ref_sgn, abs=1e-12)


def test_shape_functions_are_lagrange():
    coeff = shape_coefficients(2)
    nodes = NODE_COORDINATES[2]
    values = coeff @ np.vander(nodes, 3, increasing=True).T
    assert np.allclose(values, np.eye(3), atol=1e-14)


def test_pressure_pushes_surface_into_body_and_draws_it_inward():
    """Johnson 2.2: a pressure moves the surface into the body, most under the load,
    and (nu < 0.5) pulls the surface towards the load: u_x < 0 right of it."""
    grid = ContactGrid(half_width=1.0, elements=40, order=2)
    body = halfplane.body_compliance(grid, 2e5, 0.3)
    p_n = -np.where(np.abs(grid.x) < 0.3, 1.0, 0.0)  # compressive strip
    w = body.S_nn @ p_n
    u = body.S_tn @ p_n
    assert np.argmax(w) in range(grid.size // 2 - 2, grid.size // 2 + 2)
    assert w[grid.size // 2] - w[0] > 0
    assert u[-1] < 0 < u[0]
    # the displacement difference between two points matches Johnson's strip-load formula
    k = 2 * materials.plane_strain_compliance(2e5, 0.3) / np.pi

    def antiderivative(t):  # int ln|t| dt
        return t * np.log(abs(t)) - t if t != 0 else 0.0

    def w_exact(x):  # -k int_{-b}^{b} ln|x - s| ds under a unit pressure
        b = 0.3
        return -k * (antiderivative(x + b) - antiderivative(x - b))

    i, j = grid.size // 2, 5
    exact = w_exact(grid.x[i]) - w_exact(grid.x[j])
    assert w[i] - w[j] == pytest.approx(exact, rel=1e-3)  # strip edge inside an element: O(h) error


def test_pair_is_sum_of_bodies_and_coupling_cancels_for_identical_bodies():
    grid = ContactGrid(half_width=1.0, elements=10, order=2)
    a = halfplane.body_compliance(grid, 6e4, 0.31)
    b = halfplane.body_compliance(grid, 2.1e5, 0.28)
    pair = halfplane.pair_compliance(grid, 6e4, 0.31, 2.1e5, 0.28)
    combined = combine(a, b, coupling=True)
    for name in ("S_nn", "S_tt", "S_nt", "S_tn"):
        assert np.allclose(getattr(pair, name), getattr(combined, name), rtol=1e-12, atol=1e-20)
    same = combine(a, a, coupling=True)
    assert np.all(same.S_nt == 0.0) and np.all(same.S_tn == 0.0)
    rigid_a = combine(None, b, coupling=True)
    assert np.array_equal(rigid_a.S_nt, -b.S_nt)
    assert halfplane.pair_compliance(grid, 6e4, 0.31, 2.1e5, 0.28, coupling=False).S_nt is None


def test_the_influence_takes_material_values():
    """The builder's Material interface is the numeric one: identical blocks (the same arithmetic),
    None is a rigid body, and a viscoelastic material is refused (its kernels are another module's)."""
    from rolling_cli.model.viscoelastic import elastic, standard_linear_solid

    grid = ContactGrid(half_width=1.0, elements=10, order=2)
    by_value = halfplane.materials_pair(grid, elastic(6e4, 0.31), elastic(2.1e5, 0.28))
    by_number = halfplane.pair_compliance(grid, 6e4, 0.31, 2.1e5, 0.28)
    for name in ("S_nn", "S_tt", "S_nt"):
        assert np.array_equal(getattr(by_value, name), getattr(by_number, name))
    rigid = halfplane.materials_pair(grid, None, elastic(2.1e5, 0.28))
    assert np.array_equal(rigid.S_nn, halfplane.pair_compliance(grid, np.inf, 0.0, 2.1e5, 0.28).S_nn)
    with pytest.raises(ValueError, match="SLS"):
        halfplane.materials_pair(grid, standard_linear_solid(20.0, 10.0, 0.01, 0.3), None)


def _graded(elements, order, seed=4):
    lengths = 10.0 ** np.random.default_rng(seed).uniform(-2.0, 0.0, elements)  # lengths within 100x
    return ContactGrid.graded(np.concatenate([[0.0], np.cumsum(lengths)]) - 0.4, order)


@pytest.mark.parametrize("order", [0, 2])
def test_graded_log_and_sign_matrices_match_quadrature(order):
    """Exact element integrals on elements of very different lengths (no Toeplitz structure)."""
    grid = _graded(9, order)
    assert not grid.uniform
    L = 2.0
    log = halfplane.log_matrix(grid, L)
    sgn = halfplane.sign_matrix(grid)
    n = grid.size
    rng = np.random.default_rng(5)
    pairs = [(0, n - 1), (n - 1, 0), (n // 2, n // 2)] + [tuple(rng.integers(0, n, 2)) for _ in range(12)]
    for i, j in pairs:
        e = j // grid.nodes_per_element
        lo, hi = grid.edges[e], grid.edges[e + 1]
        xi = grid.x[i]
        brk = [xi] if lo < xi < hi else None
        ref_log, err = quad(
            lambda s: _shape(grid, j, s) * np.log(abs(xi - s) / L) if s != xi else 0.0, lo, hi, points=brk, limit=200
        )
        ref_sgn = quad(lambda s: _shape(grid, j, s) * np.sign(xi - s), lo, hi, points=brk)[0]
        # entries scale with the source element's length h_e: round-off of O(1) terms times h_e
        h = hi - lo
        assert log[i, j] == pytest.approx(ref_log, abs=max(10 * err, 1e-13 * h))
        assert sgn[i, j] == pytest.approx(ref_sgn, abs=1e-13 * h)


@pytest.mark.parametrize("order", [0, 2])
def test_toeplitz_and_graded_paths_agree_on_a_uniform_grid(order):
    """The same integrals by both paths: equal to round-off (the local coordinates differ in
    the last bits: exact integers in the Toeplitz path, (x_i - centre_e) / half_e here)."""
    grid = ContactGrid(1.5, 60, order, centre=0.2)
    L = halfplane._length_scale(grid)
    toeplitz = halfplane.log_matrix(grid, L)
    graded = halfplane.graded_log_matrix(grid, L)
    assert np.abs(graded - toeplitz).max() <= 1e-13 * np.abs(toeplitz).max()
    assert np.abs(halfplane.graded_sign_matrix(grid) - halfplane.sign_matrix(grid)).max() <= 1e-14 * grid.half_width


@pytest.mark.parametrize("c", [-1e6, -4.0001, -3.9999, 4.0001, 17.0, 1e8])
def test_far_field_log_moments_around_the_series_switch(c):
    """|c| > 4 uses the series in 1/c^2, 2 < |c| <= 4 12-point Gauss. Reference: 80-point
    Gauss-Legendre of log1p(-x/c), converged to round-off for |c| >= 2 (error below
    3.7^-160), plus the exact ln|c| int x^m; agreement to round-off of the O(ln|c|) terms."""
    got = log_moments(np.array([c]))[0]
    nodes, weights = np.polynomial.legendre.leggauss(80)
    for m in range(3):
        ref = weights @ (nodes**m * np.log1p(-nodes / c)) + np.log(abs(c)) * (2.0 / (m + 1) if m % 2 == 0 else 0.0)
        assert got[m] == pytest.approx(ref, rel=1e-13, abs=1e-15 * max(1.0, np.log(abs(c))))
