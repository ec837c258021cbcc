"""Graded (non-uniform) contact grids: nodes, weights, the slip operator T and penalties.

Orders of accuracy are measured on a smoothly graded family (the image of a
uniform grid under x = xi + 0.4 sin(pi xi) / pi: neighbouring elements differ
by a factor of up to 2.3 over the zone), refined by doubling. Exactness tests
use randomly graded grids.
"""

import numpy as np
import pytest

from rolling_cli.influence import halfplane
from rolling_cli.model import slip
from rolling_cli.model.grid import NODE_COORDINATES, ContactGrid, node_cell_edges, shape_integrals
from rolling_cli.result import state_zones
from rolling_cli.solver.system import PENALTY_BAND, automatic_penalties

EPS = np.finfo(float).eps


def smooth_family(elements: int, order: int = 2) -> ContactGrid:
    """A smoothly graded grid of [-1.5, 1.5] with ``elements`` elements."""
    xi = np.linspace(-1.0, 1.0, elements + 1)
    return ContactGrid.graded(1.5 * (xi + 0.4 * np.sin(np.pi * xi) / np.pi), order)


def random_grid(elements: int, order: int = 2, seed: int = 1) -> ContactGrid:
    """Element lengths varying randomly by a factor of up to 100."""
    lengths = 10.0 ** np.random.default_rng(seed).uniform(-2.0, 0.0, elements)
    return ContactGrid.graded(np.concatenate([[0.0], np.cumsum(lengths)]) - 0.3, order)


def observed_order(errors, sizes) -> float:
    """Slope of log(error) against log(size) between the last two members."""
    return float(np.log(errors[-2] / errors[-1]) / np.log(sizes[-2] / sizes[-1]))


@pytest.mark.parametrize("order", [0, 2])
def test_graded_grid_nodes_weights_and_cells(order):
    grid = random_grid(9, order)
    assert not grid.uniform and grid.size == 9 * grid.nodes_per_element
    h = np.diff(grid.edges)
    assert np.allclose(grid.element_lengths, h, rtol=0.0, atol=0.0)
    # every node sits at its local coordinate inside its own element
    local = NODE_COORDINATES[order]
    expected = (0.5 * (grid.edges[:-1] + grid.edges[1:]))[:, None] + 0.5 * h[:, None] * local[None, :]
    assert np.allclose(grid.x, expected.ravel(), rtol=0.0, atol=4 * EPS * np.abs(grid.edges).max())
    assert np.all(np.diff(grid.x) > 0.0)
    # weights: the shape-function integrals scaled by each element's half-length; they sum to the zone
    w = grid.weights.reshape(9, -1)
    assert np.allclose(w, 0.5 * h[:, None] * shape_integrals(order)[None, :], rtol=1e-15, atol=0.0)
    assert grid.weights.sum() == pytest.approx(grid.edges[-1] - grid.edges[0], rel=1e-14)
    # node cells partition the zone, each node inside its own cell
    cells = grid.cell_edges
    assert cells.size == grid.size + 1 and np.all(np.diff(cells) > 0.0)
    assert np.all((cells[:-1] < grid.x) & (grid.x < cells[1:]))
    assert grid.spacing == pytest.approx(np.diff(grid.x).max()) and grid.element_length == pytest.approx(h.max())


def test_grid_is_immutable_hashable_and_validated():
    grid = random_grid(5)
    assert hash(grid) == hash(random_grid(5)) and grid == random_grid(5)
    with pytest.raises(AttributeError):
        grid.elements = 3
    with pytest.raises(ValueError):
        ContactGrid.graded([0.0, 1.0, 1.0, 2.0])
    with pytest.raises(ValueError):
        ContactGrid(1.0, 2, 2, 0.0, (0.0, 1.0))  # edge count does not match


def test_uniform_edges_given_as_graded_are_the_uniform_grid():
    """Edges equal to the uniform ones to round-off give a uniform grid, which takes the
    block-Toeplitz and scalar-spacing paths. For the zone centred at 0 (the pipeline's) the
    edges give back the same half-width exactly, so it is THE uniform grid (equal, same
    hash, same arrays): results bit for bit. Elsewhere the recovered half-width and centre
    may differ in the last bit: the same grid to round-off."""
    uniform = ContactGrid(1.5, 40, 2)
    graded = ContactGrid.graded(uniform.edges, 2)
    assert graded.uniform and graded == uniform and hash(graded) == hash(uniform)
    assert np.array_equal(graded.x, uniform.x) and np.array_equal(graded.weights, uniform.weights)
    shifted = ContactGrid(1.5, 40, 2, centre=0.1)
    for edges in (shifted.edges, 0.1 + np.cumsum(np.concatenate([[-1.5], np.full(40, 3.0 / 40)]))):
        graded = ContactGrid.graded(edges, 2)
        assert graded.uniform
        assert np.allclose(graded.x, shifted.x, rtol=0.0, atol=8 * EPS * 1.6)
        assert np.allclose(graded.weights, shifted.weights, rtol=8 * EPS, atol=0.0)


@pytest.mark.parametrize(("order", "expected"), [(2, 4.0), (0, 2.0)])
def test_weights_converge_at_their_order_on_graded_grids(order, expected):
    """sum w f -> int f like h^4 (quadratic elements: the symmetric three-node rule is exact
    for cubics) or h^2 (midpoint rule). Both error expansions are in even powers of h, so
    between 32 and 64 elements the observed order is within (h/L)^2 ~ 1 % of the
    theoretical one (0.1 allowed)."""

    def exact(x):
        return np.exp(x) * (np.cos(2 * x) + 2 * np.sin(2 * x)) / 5.0  # antiderivative of e^x cos 2x

    errors, sizes = [], []
    for n in (16, 32, 64):
        grid = smooth_family(n, order)
        value = grid.weights @ (np.exp(grid.x) * np.cos(2 * grid.x))
        errors.append(abs(value - (exact(grid.edges[-1]) - exact(grid.edges[0]))))
        sizes.append(grid.element_length)
    assert observed_order(errors, sizes) == pytest.approx(expected, abs=0.1)


def test_quadratic_weights_are_exact_for_cubics_on_any_grid():
    grid = random_grid(13)
    a, b = grid.edges[0], grid.edges[-1]
    for k in range(4):
        exact = (b ** (k + 1) - a ** (k + 1)) / (k + 1)
        assert grid.weights @ grid.x**k == pytest.approx(exact, rel=1e-13, abs=1e-13)


def _slip_rows(n: int, direction: int, scheme: str) -> np.ndarray:
    """Rows of T that are the scheme's own stencil (not the gauge, not the fallback row)."""
    rows = np.arange(n) if direction < 0 else np.arange(n)[::-1]
    skip = 2 if scheme == "element" else 1
    return np.sort(rows[:-skip])


@pytest.mark.parametrize("direction", [-1, 1])
@pytest.mark.parametrize(("scheme", "degree"), [("fd", 1), ("element", 2)])
def test_slip_operator_is_exact_for_its_polynomials_on_any_spacing(direction, scheme, degree):
    """fd differentiates linear, element quadratic displacements exactly, whatever the
    spacing; round-off: a few eps |u| / (smallest distance) per row."""
    grid = random_grid(15)
    x = grid.x
    gaps = np.diff(x)
    u = 0.3 + 0.7 * x + (0.5 * x**2 if degree == 2 else 0.0)
    du = 0.7 + (x if degree == 2 else 0.0 * x)
    out = slip.apply_t(u, gaps, direction, scheme)
    rows = _slip_rows(x.size, direction, scheme)
    bound = 16 * EPS * np.abs(u).max() / gaps.min()
    assert np.max(np.abs(out[rows] - direction * du[rows])) <= bound
    g = slip.gauge_index(x.size, direction)
    assert out[g] == u[g]  # the gauge row holds the displacement itself
    # matrices: each column transformed like a vector
    stacked = slip.apply_t(np.column_stack([u, 2 * u]), gaps, direction, scheme)
    assert np.allclose(stacked[:, 1], 2 * out, rtol=1e-15, atol=0.0)


@pytest.mark.parametrize("direction", [-1, 1])
@pytest.mark.parametrize(("scheme", "expected"), [("fd", 1.0), ("element", 2.0)])
def test_slip_operator_converges_at_its_order_on_graded_grids(direction, scheme, expected):
    """Truncation error of T on a smooth displacement: O(Delta) for fd (Delta/2 u''),
    O(Delta^2) for element (h1 (h1 + h2) / 6 u'''). The next terms are one power of Delta
    higher; between 64 and 128 elements (Delta <= 0.02) the observed order is within 0.1."""
    errors, sizes = [], []
    for n in (32, 64, 128):
        grid = smooth_family(n)
        x = grid.x
        out = slip.apply_t(np.sin(3 * x), np.diff(x), direction, scheme)
        rows = _slip_rows(x.size, direction, scheme)
        errors.append(np.max(np.abs(out[rows] - direction * 3 * np.cos(3 * x[rows]))))
        sizes.append(grid.spacing)
    assert observed_order(errors, sizes) == pytest.approx(expected, abs=0.1)


@pytest.mark.parametrize("scheme", ["fd", "element"])
def test_graded_slip_operator_on_uniform_spacing_is_the_uniform_one(scheme):
    grid = ContactGrid(1.5, 20, 2)
    u = halfplane.log_matrix(grid, 10.0)
    for direction in (-1, 1):
        uniform = slip.apply_t(u, grid.spacing, direction, scheme)
        graded = slip.apply_t(u, np.diff(grid.x), direction, scheme)
        scale = np.abs(uniform).max()
        assert np.allclose(graded, uniform, rtol=0.0, atol=1e-13 * scale)
        assert np.allclose(
            slip.downwind_row(u, np.diff(grid.x), direction),
            slip.downwind_row(u, grid.spacing, direction),
            rtol=0.0,
            atol=1e-13 * scale,
        )


def test_penalties_need_no_spacing_and_match_the_uniform_formula():
    """r_n = 1 / max|S_nn[i] - S_nn[up]| equals the former 1 / (Delta max|D S_nn|) on a uniform grid."""
    grid = ContactGrid(1.5, 30, 2)
    s_nn = halfplane.log_matrix(grid, 10.0)
    for direction in (-1, 1):
        b_tt = slip.apply_t(-s_nn, grid.spacing, direction)
        r_n, r_t = automatic_penalties(s_nn, b_tt, direction)
        n = grid.size
        rows = np.delete(np.arange(n), slip.gauge_index(n, direction))
        cols = np.clip(rows[:, None] + np.arange(-PENALTY_BAND, PENALTY_BAND + 1)[None, :], 0, n - 1)
        d_nn = (s_nn[rows[:, None], cols] - s_nn[(rows - direction)[:, None], cols]) / (-direction * grid.spacing)
        assert r_n == pytest.approx(1.0 / (grid.spacing * np.abs(d_nn).max()), rel=1e-13)
        assert r_t == 1.0 / np.abs(b_tt[rows[:, None], cols]).max()


def test_state_zones_follow_the_node_cells_on_graded_grids():
    x = np.array([0.0, 1.0, 1.5, 3.5, 4.0])
    state = np.array([0, 2, 2, 1, 0], dtype=np.int8)
    assert np.allclose(node_cell_edges(x), [-0.5, 0.5, 1.25, 2.5, 3.75, 4.25])
    assert state_zones(x, state) == [
        ("separation", -0.5, 0.5),
        ("slip", 0.5, 2.5),
        ("adhesion", 2.5, 3.75),
        ("separation", 3.75, 4.25),
    ]
    uniform = np.linspace(0.0, 1.0, 5)
    zones = state_zones(uniform, np.array([0, 1, 1, 2, 2], dtype=np.int8))
    assert zones[1][1] == pytest.approx(0.125) and zones[-1][-1] == pytest.approx(1.125)
