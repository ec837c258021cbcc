"""Block-Toeplitz influence operators against the dense matrices they replace.

Entries are gathered from the same offset values as the dense matrices, so they
must be equal bit for bit (and so must the slip derivative, which repeats the
dense arithmetic on them). Products go through an FFT convolution: their error
is a few eps log2(L) (L the transform length) of the magnitudes summed, against
n eps for the dense product itself, so they are compared to 10 eps log2(L)
times max_i sum_j |M_ij p_j|.
"""

import numpy as np
import pytest

from rolling_cli.influence import halfplane
from rolling_cli.influence.toeplitz import BlockToeplitz, apply_sum, products
from rolling_cli.model import slip
from rolling_cli.model.grid import ContactGrid
from rolling_cli.solver.system import automatic_penalties

EPS = np.finfo(float).eps


def _pair(order: int, elements: int):
    grid = ContactGrid(1.5, elements, order)
    args = (grid, 6.0e4, 0.31, 2.1e5, 0.28)
    return grid, halfplane.pair_compliance(*args, operators=False), halfplane.pair_compliance(*args, operators=True)


def _bound(op: BlockToeplitz, dense: np.ndarray, p: np.ndarray) -> float:
    """10 eps log2(L) max_i sum_j |M_ij p_j| (see the module docstring)."""
    return 10.0 * EPS * np.log2(op.transform_length) * float(np.max(np.abs(dense) @ np.abs(p)))


@pytest.mark.parametrize("order,elements", [(2, 40), (0, 61)])
def test_entries_equal_the_dense_matrices_bit_for_bit(order, elements):
    grid, dense, fast = _pair(order, elements)
    for name in ("S_nn", "S_tt", "S_nt", "S_tn"):
        assert isinstance(getattr(fast, name), BlockToeplitz)
        assert np.array_equal(getattr(fast, name).toarray(), getattr(dense, name)), name
    rng = np.random.default_rng(1)
    i, j = rng.integers(0, grid.size, (2, 50))
    assert np.array_equal(fast.S_nn.entries(i, j), dense.S_nn[i, j])
    rows, cols = np.array([3, 0, grid.size - 1]), np.array([grid.size - 2, 5])
    assert np.array_equal(fast.S_nt.block(rows, cols), dense.S_nt[np.ix_(rows, cols)])


@pytest.mark.parametrize("order,elements", [(2, 40), (0, 61)])
def test_products_match_the_dense_products(order, elements):
    grid, dense, fast = _pair(order, elements)
    rng = np.random.default_rng(2)
    p = rng.standard_normal(grid.size)
    block = rng.standard_normal((grid.size, 3))
    for name in ("S_nn", "S_nt"):
        op, matrix = getattr(fast, name), getattr(dense, name)
        assert np.max(np.abs(op @ p - matrix @ p)) <= _bound(op, matrix, p)
        for k in range(3):
            assert np.max(np.abs((op @ block)[:, k] - matrix @ block[:, k])) <= _bound(op, matrix, block[:, k])
    q = rng.standard_normal(grid.size)
    both = apply_sum([(fast.S_nn, p), (fast.S_nt, q)])
    reference = dense.S_nn @ p + dense.S_nt @ q
    bound = _bound(fast.S_nn, dense.S_nn, p) + _bound(fast.S_nt, dense.S_nt, q)
    assert np.max(np.abs(both - reference)) <= bound
    first, second = products([[(fast.S_nn, p)], [(fast.S_nt, p), (fast.S_nn, q)]])
    assert np.array_equal(first, fast.S_nn @ p)
    assert np.max(np.abs(second - dense.S_nt @ p - dense.S_nn @ q)) <= bound


@pytest.mark.parametrize("order,elements", [(2, 30), (0, 45)])
@pytest.mark.parametrize("direction", [-1, 1])
@pytest.mark.parametrize("scheme", ["fd", "element"])
def test_slip_derivative_repeats_the_dense_arithmetic(order, elements, direction, scheme):
    grid, dense, fast = _pair(order, elements)
    derived = fast.S_tt.upwind_derivative(grid.spacing, direction, scheme)
    reference = slip.apply_t(dense.S_tt, grid.spacing, direction, scheme)
    assert np.array_equal(derived.toarray(), reference)
    g = slip.gauge_index(grid.size, direction)
    assert g in derived.rows  # the gauge row (and its neighbour) are the explicit ones
    assert derived.rows.size == 2 and np.all(np.abs(derived.rows - g) <= 1)
    p = np.random.default_rng(3).standard_normal(grid.size)
    assert np.max(np.abs(derived @ p - reference @ p)) <= _bound(derived, reference, p)


@pytest.mark.parametrize("direction", [-1, 1])
def test_row_norms_and_penalties(direction):
    grid, dense, fast = _pair(2, 50)
    derived = fast.S_tt.upwind_derivative(grid.spacing, direction, "element")
    reference = slip.apply_t(dense.S_tt, grid.spacing, direction, "element")
    for op, matrix in ((fast.S_nn, dense.S_nn), (fast.S_nt, dense.S_nt), (derived, reference)):
        sums = np.abs(matrix).sum(axis=1)
        # cumulative sums over the offsets: rounding of a few eps times the largest cumulative sum, <= 2 sums
        assert np.max(np.abs(op.abs_row_sums() - sums)) <= 4 * grid.size * EPS * sums.max()
        rows = np.ones(grid.size, dtype=bool)
        rows[slip.gauge_index(grid.size, direction)] = False
        assert op.abs_max(rows) == np.abs(matrix[rows]).max()
        assert op.abs_max(np.array([0, 7, grid.size - 1])) == np.abs(matrix[[0, 7, grid.size - 1]]).max()
        assert op.abs_max() == np.abs(matrix).max()
    assert automatic_penalties(fast.S_nn, derived, direction) == automatic_penalties(dense.S_nn, reference, direction)


def test_scalar_arithmetic_and_checks():
    _, dense, fast = _pair(2, 12)
    assert np.array_equal((2.5 * fast.S_nt).toarray(), 2.5 * dense.S_nt)
    assert np.array_equal((fast.S_nt * np.float64(-0.5)).toarray(), dense.S_nt * -0.5)
    assert np.array_equal((-fast.S_nn).toarray(), -dense.S_nn)
    with pytest.raises(ValueError, match="offset blocks"):
        BlockToeplitz(np.zeros((4, 3, 3)))
    with pytest.raises(ValueError, match="distinct"):
        BlockToeplitz(np.zeros((5, 3, 3)), rows=[1, 1], row_values=np.zeros((2, 9)))
    with pytest.raises(ValueError, match="rows"):
        fast.S_nn @ np.zeros(5)


@pytest.mark.parametrize("order,elements", [(2, 40), (0, 61)])
def test_corner_sums_are_the_cumulated_matrix(order, elements):
    """sum_{a < x, b < y} M[a, b] (the coarse grid of the Krylov preconditioner) against the dense
    matrix cumulated over rows and columns, for the half-plane blocks and the slip operator's
    derivative (explicit rows), at node counts on and off the element boundaries. The Toeplitz
    sums are differences of the twice cumulated offset values, which grow to ~(2 N_e)^2 m^2
    max|v|: their round-off is a few eps of that (against ~n^2 eps max|M| for the dense sums)."""
    grid, dense, fast = _pair(order, elements)
    derivative = fast.S_tt.upwind_derivative(grid.spacing, -1, "element")
    n = grid.size
    rng = np.random.default_rng(4)
    x = np.concatenate([[0, n], rng.integers(0, n + 1, 12)])
    y = np.concatenate([[0, n], rng.integers(0, n + 1, 9)])
    for op in (fast.S_nn, fast.S_nt, derivative):
        assert op is not derivative or op.rows.size  # the explicit rows are covered
        matrix = op.toarray()
        cumulated = np.zeros((n + 1, n + 1))
        cumulated[1:, 1:] = np.cumsum(np.cumsum(matrix, axis=0), axis=1)
        m = op.block_size
        bound = 8 * EPS * (2 * op.elements + 1) ** 2 * m**2 * np.abs(op.values).max() + 8 * EPS * n * np.abs(
            op.row_values
        ).sum(initial=0.0)
        assert np.abs(op.corner_sums(x, y) - cumulated[np.ix_(x, y)]).max() <= bound
        aligned = np.arange(0, n + 1, m)  # all on element boundaries: the positions' sums at once
        assert np.abs(op.corner_sums(aligned, aligned) - cumulated[np.ix_(aligned, aligned)]).max() <= bound
