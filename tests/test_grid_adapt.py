"""The mesh-adaptation pieces: kink location, grading, the indicator, refinement, transfer."""

import math

import numpy as np
import pytest

import rolling_cli
from helpers import case_dict
from rolling_cli.adapt import grading, indicator, kinks, refine, remesh, transfer
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline.explicit import solve_on_grid
from rolling_cli.references import carter

EPS = np.finfo(float).eps


def test_square_root_kinks_are_located_exactly():
    """p_n^2 and the friction reserve squared are linear next to a pure square-root kink,
    so the two-node extrapolation hits it to round-off."""
    x = np.linspace(-1.0, 1.0, 41)
    edge_lo, edge_hi, boundary = -0.7371, 0.8123, 0.2057
    p_n = -np.sqrt(np.clip(x - edge_lo, 0.0, None)) * np.sqrt(np.clip(edge_hi - x, 0.0, None))
    left = x < 0.0  # near each edge only one root varies: make each side a pure square root
    p_n = np.where(left, -np.sqrt(np.clip(x - edge_lo, 0.0, None)), -np.sqrt(np.clip(edge_hi - x, 0.0, None)))
    found = kinks.contact_edges(x, p_n)
    assert np.allclose(found, [edge_lo, edge_hi], rtol=0.0, atol=64 * EPS)
    mu = 0.3
    stick = (x < boundary) & (p_n < 0.0)
    p_t = np.where(stick, mu * np.abs(p_n) - np.sqrt(np.clip(boundary - x, 0.0, None)), mu * np.abs(p_n))
    state = np.where(p_n < 0.0, np.where(stick, 1, 2), 0).astype(np.int8)
    found = kinks.stick_slip_boundaries(x, p_n, p_t, state, mu)
    assert found.size == 1 and found[0] == pytest.approx(boundary, abs=64 * EPS)


def test_hertzian_edges_are_located_to_second_order():
    """For p_n^2 = a^2 - x^2 the straight line through nodes x1 < x2 < a (a secant of a
    concave function, above it beyond x2) vanishes (a - x1)(a - x2) / (2a) beyond a, to
    leading order in the node spacing (10 % allowed: the next term is relatively O((a - x1)/a))."""
    a = 0.9
    x = np.linspace(-1.0, 1.0, 57)
    p_n = -np.sqrt(np.clip(a * a - x * x, 0.0, None))
    found = kinks.contact_edges(x, p_n)
    x1, x2 = x[x < a][-2:]
    expected = (a - x1) * (a - x2) / (2 * a)
    assert found[1] - a == pytest.approx(expected, rel=0.1)
    assert found[0] == pytest.approx(-found[1], abs=1e-14)


@pytest.mark.parametrize("elements", [17, 40])
def test_kinks_of_a_carter_solution(elements):
    """On uniform meshes whose kinks fall at generic places (zone 1.41 a), the contact edges
    are found within 0.15 node spacings and the stick/slip boundary within 0.35 (the
    discrete solution's own kinks are shifted by the discretisation: measured on 120 meshes,
    10 to 160 elements, Q/(mu P) = 0.3 to 0.8, zones 1.37 to 1.6 a: 0.15 and 0.34)."""
    case = rolling_cli.load_case(
        case_dict(**{"discretization.contact_elements": elements, "discretization.zone": 1.41})
    )
    r = rolling_cli.solve(case)
    a, d = r.hertz_a, r.node_spacing
    positions, kinds = kinks.locate_kinks(r, ContactGrid(1.41 * r.mesh_half_width, elements, 2))
    edges = positions[kinds == kinks.CONTACT_EDGE]
    assert edges.size == 2 and np.all(np.abs(edges - [-a, a]) <= 0.15 * d)
    boundary = a - 2 * a * math.sqrt(1 - 0.51)
    found = positions[kinds == kinks.STICK_SLIP]
    assert np.min(np.abs(found - boundary)) <= 0.35 * d
    # every kink lies between two neighbouring nodes whose states differ
    i = np.searchsorted(r.x, positions) - 1
    assert np.all(r.state[i] != r.state[i + 1])


def test_graded_edges_anchor_grade_and_bound():
    anchors = [-1.0, 0.3, 1.05]
    smallest, largest, growth = 1e-4, 0.05, 1.3
    edges = grading.graded_edges(-1.5, 1.5, anchors, smallest, largest, growth)
    h = np.diff(edges)
    assert edges[0] == -1.5 and edges[-1] == 1.5 and np.all(h > 0.0)
    for anchor in anchors:
        assert np.min(np.abs(edges - anchor)) <= 4 * EPS
        k = np.argmin(np.abs(edges - anchor))
        # the elements touching an anchor: at most the size function over one step of Phi
        assert h[k - 1] <= smallest * growth and h[k] <= smallest * growth
    assert h.max() <= largest * (1 + 1e-12)
    # geometric growth: neighbours differ by at most the growth ratio, up to the rounding of
    # each piece's element count (one step of Phi: another factor growth at most)
    ratios = np.maximum(h[1:] / h[:-1], h[:-1] / h[1:])
    assert ratios.max() <= growth**2
    # the element count is logarithmic in largest/smallest near each anchor
    assert h.size < 3 * 2 * math.log(largest / smallest) / math.log(growth) + 3.0 / largest


def test_graded_edges_merge_close_anchors_and_ignore_outside_ones():
    edges = grading.graded_edges(0.0, 1.0, [0.5, 0.5 + 1e-6, 2.0, -1.0], 1e-3, 0.1, 1.5)
    assert np.min(np.abs(edges - (0.5 + 0.5e-6))) <= 4 * EPS
    assert np.all(np.diff(edges) > 0.0) and edges[0] == 0.0 and edges[-1] == 1.0
    uniform = grading.graded_edges(0.0, 1.0, [], 1e-3, 0.1, 1.5)
    assert np.allclose(np.diff(uniform), 0.1)


def test_split_and_smooth():
    counts = refine.split_counts(np.array([0.5, 1.0, 2.0, 100.0]), 1.0, rate=0.5, max_split=16)
    assert counts.tolist() == [1, 1, 4, 16]
    edges = refine.split_elements(np.array([0.0, 1.0, 3.0]), np.array([2, 4]))
    assert np.allclose(edges, [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
    rough = np.array([0.0, 0.01, 1.0, 3.0])
    smooth = refine.smooth_edges(rough, max_ratio=2.0)
    h = np.diff(smooth)
    assert np.all(np.maximum(h[1:] / h[:-1], h[:-1] / h[1:]) <= 2.0 + 1e-12)
    assert set(np.round(rough, 12)) <= set(np.round(smooth, 12))  # only splits, no moved edges


def test_refine_splits_only_where_the_indicator_exceeds_the_target():
    grid = ContactGrid(1.0, 8, 2)
    eta = np.full(8, 1e-4)
    assert refine.refine(grid, eta, 1e-3) is grid
    eta[3] = 4e-3  # sqrt rate: 16 pieces to bring 4x the target down to it
    new = refine.refine(grid, eta, 1e-3, max_ratio=2.0)
    h = new.element_lengths
    inside = (new.element_centres > grid.edges[3]) & (new.element_centres < grid.edges[4])
    assert np.allclose(h[inside], grid.element_length / 16)
    assert np.all(np.maximum(h[1:] / h[:-1], h[:-1] / h[1:]) <= 2.0 + 1e-12)


def test_limit_lengths_imposes_the_field():
    field_edges = np.array([0.0, 0.5, 1.5, 3.0])
    lengths = np.array([1.0, 0.25, 2.0])
    edges = refine.limit_lengths(np.array([0.0, 1.0, 2.0, 3.0]), field_edges, lengths)
    h, mid = np.diff(edges), 0.5 * (edges[1:] + edges[:-1])
    allowed = lengths[np.searchsorted(field_edges, mid) - 1]
    assert np.all(h <= allowed + 1e-12)


@pytest.mark.parametrize("order", [0, 2])
def test_prolongation_is_exact_onto_a_refinement(order):
    """A field that the old grid represents exactly (its own piecewise polynomials) is
    carried exactly onto a refinement: each new node lies in one old element."""
    old = ContactGrid.graded([-1.0, -0.3, 0.1, 0.8, 1.2], order)
    rng = np.random.default_rng(2)
    coefficients = rng.normal(size=(old.elements, 3 if order == 2 else 1))
    new = ContactGrid.graded(refine.split_elements(old.edges, np.array([3, 1, 2, 5])), order)

    def field(grid):
        e = np.clip(np.searchsorted(old.edges, grid.x) - 1, 0, old.elements - 1)
        t = grid.x - old.element_centres[e]
        return sum(coefficients[e, k] * t**k for k in range(coefficients.shape[1]))

    assert np.allclose(transfer.prolong(old, field(old), new), field(new), rtol=0.0, atol=1e-13)
    assert np.allclose(transfer.prolong(old, field(old), old), field(old), rtol=0.0, atol=1e-13)


def test_transferred_tractions_are_admissible_and_end_at_the_edges():
    case = rolling_cli.load_case(case_dict(**{"discretization.contact_elements": 20}))
    r = rolling_cli.solve(case)
    grid = ContactGrid(1.5 * r.mesh_half_width, 20, 2)
    edges = kinks.contact_edges(r.x, r.p_n, r.delta_n)
    new = grading.graded_grid(grid, edges, 1e-3, 0.05)
    p_n, p_t = transfer.transfer_tractions(grid, r.p_n, r.p_t, r.mu, new, edges)
    assert np.all(p_n <= 0.0) and np.all(np.abs(p_t) <= -r.mu * p_n)
    assert np.all(p_n[(new.x < edges[0]) | (new.x > edges[1])] == 0.0)
    inside = (new.x > edges[0] + 0.1) & (new.x < edges[1] - 0.1)
    assert np.all(p_n[inside] < 0.0)


def test_indicator_sees_jumps_only():
    grid = ContactGrid.graded([-1.0, -0.5, 0.2, 0.6, 1.0], 2)
    x = grid.x
    smooth = 1.0 - x**2  # one quadratic over the whole zone: no interior jump
    eta = indicator.element_indicator(grid, -smooth, np.zeros_like(x), 0.0, 1.0)
    ends = indicator.edge_jumps(grid, smooth)
    assert np.allclose(ends[1:-1], 0.0, atol=1e-14) and ends[0] == pytest.approx(0.0, abs=1e-14)
    assert np.all(eta <= 1e-14)
    step = np.where(x > 0.2, -2.0, -1.0)
    step[(x < -0.5) | (x > 0.6)] = 0.0
    eta = indicator.element_indicator(grid, step, 0.1 * step, 0.1, 2.0)
    # jumps / p0: 0.5 at x = -0.5, 0.5 at 0.2, 1.0 at 0.6 (the tangential ones equal, / (mu p0))
    assert np.allclose(eta, [0.5, 0.5, 1.0, 1.0])
    assert np.allclose(indicator.patch_indicator(np.array([0.1, 0.0, 0.0, 0.3])), [0.1, 0.1, 0.3, 0.3])


@pytest.mark.parametrize("elements", [20, 40])
def test_indicator_bounds_the_carter_error(elements):
    """The largest jump bounds the largest nodal traction error (measured on Carter's case:
    2.2 to 20 times it, uniform and graded meshes; benchmarks/adaptive.py reports the ratios)."""
    case = rolling_cli.load_case(case_dict(**{"discretization.contact_elements": elements}))
    r = rolling_cli.solve(case)
    grid = ContactGrid(1.5 * r.mesh_half_width, elements, 2)
    eta = indicator.element_indicator(grid, r.p_n, r.p_t, r.mu, r.hertz_p0)
    error = np.abs(r.p_t - carter.traction(r.x, 0.51, r.hertz_a, r.hertz_p0, r.mu, -1)) / (r.mu * r.hertz_p0)
    assert eta.max() >= error.max()


def test_one_adaptive_step_grades_towards_the_kinks_and_reduces_the_error():
    """From a uniform 20-element Carter solution, one step of remesh.next_grid: an element
    edge on every located kink, the smallest element not below a tenth of the element that
    held a kink (their location uncertainty), and both the estimate and the true error fall."""
    case = rolling_cli.load_case(case_dict(**{"discretization.contact_elements": 20}))
    r = rolling_cli.solve(case)
    grid = ContactGrid(1.5 * r.mesh_half_width, 20, 2)
    positions, kinds = kinks.locate_kinks(r, grid)
    eta = indicator.element_indicator(grid, r.p_n, r.p_t, r.mu, r.hertz_p0)
    new = remesh.next_grid(grid, eta, positions, kinds, 1e-2)
    assert all(np.min(np.abs(new.edges - k)) <= 4 * EPS for k in positions)
    assert new.element_lengths.min() >= min(remesh.KINK_RESOLUTION.values()) * grid.element_length * (1 - 1e-12)
    r2 = solve_on_grid(case, new)
    eta2 = indicator.element_indicator(new, r2.p_n, r2.p_t, r2.mu, r2.hertz_p0)

    def error(res):
        exact = carter.traction(res.x, 0.51, res.hertz_a, res.hertz_p0, res.mu, -1)
        return np.abs(res.p_t - exact).max() / (res.mu * res.hertz_p0)

    assert eta2.max() < 0.5 * eta.max() and error(r2) < 0.5 * error(r)
    assert eta2.max() >= error(r2)
