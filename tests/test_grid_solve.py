"""Solves on graded contact grids (half-plane model) against Hertz and Carter.

Graded meshes here have an element edge on each exact kink (the contact edges
x = +-a and Carter's stick/slip boundary x = a - 2c) and elements growing by 1.4
away from them, from ``smallest`` up to 0.05 a. The mesh near a kink is then
self-similar in ``smallest``: the error at the node next to a square-root kink
goes like sqrt(smallest) and the creepage error like smallest, while the
element count grows only like log(1/smallest).
"""

import math

import numpy as np
import pytest

import rolling_cli
from helpers import CARTER, assert_contact_laws, assert_force_balance, case_dict, dissimilar
from rolling_cli.adapt.grading import graded_grid
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline.explicit import solve_on_grid
from rolling_cli.references import carter, hertz

Q = 0.51


def _kinks(a: float) -> list[float]:
    c = a * math.sqrt(1.0 - Q)
    return [-a, a - 2.0 * c, a]  # V < 0: adhesion at the leading edge (+x)


@pytest.fixture(scope="module")
def graded_runs():
    """Carter solved on graded meshes with smallest element 1e-2, 1e-3, 1e-4 a, both slip schemes."""
    runs = {}
    for scheme in ("fd", "element"):
        case = rolling_cli.load_case(case_dict(**{"discretization.slip_derivative": scheme}))
        a = rolling_cli.solve(rolling_cli.load_case(case_dict(**{"discretization.contact_elements": 10}))).hertz_a
        zone = ContactGrid(1.5 * a, 10, 2)
        for smallest in (1e-2, 1e-3, 1e-4):
            grid = graded_grid(zone, _kinks(a), smallest * a, 0.05 * a, 1.4)
            runs[scheme, smallest] = (grid, solve_on_grid(case, grid))
    return runs


def _errors(r):
    traction = np.abs(r.p_t - carter.traction(r.x, Q, r.hertz_a, r.hertz_p0, r.mu, -1)).max() / (r.mu * r.hertz_p0)
    pressure = np.abs(r.p_n + hertz.pressure(r.x, r.hertz_a, r.hertz_p0)).max() / r.hertz_p0
    creep = abs(r.creep / r.carter_creep - 1.0)
    return traction, pressure, creep


@pytest.mark.parametrize("scheme", ["fd", "element"])
def test_graded_carter_and_hertz_converge_at_the_square_root_rate(graded_runs, scheme):
    """Max traction and pressure errors ~ smallest^(1/2), creepage ~ smallest^1 (measured:
    0.485-0.500, 0.493-0.498 and 0.99-1.00). Self-similarity near the kinks leaves only
    corrections of relative order sqrt(smallest / a) <= 0.03 between 1e-3 and 1e-4 a, the
    allowance on the orders (0.05 on the creepage, whose error is an integral over the
    whole, not self-similar, mesh)."""
    errors = np.array([_errors(graded_runs[scheme, s][1]) for s in (1e-2, 1e-3, 1e-4)])
    orders = np.log(errors[1] / errors[2]) / math.log(10.0)
    assert orders[0] == pytest.approx(0.5, abs=0.03)
    assert orders[1] == pytest.approx(0.5, abs=0.03)
    assert orders[2] == pytest.approx(1.0, abs=0.05)
    for s in (1e-2, 1e-3, 1e-4):
        grid, r = graded_runs[scheme, s]
        assert r.contact_elements == grid.elements
        assert_contact_laws(r)
        assert_force_balance(r, load=1812.5, q=Q * 0.1 * 1812.5)


def test_grading_beats_a_uniform_mesh_of_the_same_size(graded_runs):
    """144 graded elements (smallest 1e-4 a) against 160 uniform ones: the maximum traction
    error is more than ten times smaller (measured: 3.7e-4 against 8.6e-3 mu p0)."""
    grid, graded = graded_runs["fd", 1e-4]
    assert grid.elements <= 160
    uniform = rolling_cli.solve(rolling_cli.load_case(case_dict(**{"discretization.contact_elements": 160})))
    assert 10.0 * _errors(graded)[0] < _errors(uniform)[0]


def test_uniform_mesh_given_as_graded_reproduces_the_uniform_result_bit_for_bit():
    """The plan's grid (zone centred at 0) given by its edges IS the uniform grid
    (:meth:`ContactGrid.graded` recognises it), so the same code paths run on the same
    numbers: identical arrays, not merely close ones."""
    case = rolling_cli.load_case(dissimilar(**{"discretization.contact_elements": 30}))
    uniform = rolling_cli.solve(case)
    zone = ContactGrid(1.5 * uniform.mesh_half_width, 30, 2)
    graded = solve_on_grid(case, ContactGrid.graded(zone.edges, 2))
    for name in ("x", "weights", "p_n", "p_t", "s_t", "delta_n", "state"):
        assert np.array_equal(getattr(graded, name), getattr(uniform, name)), name
    assert graded.creep == uniform.creep


def test_graded_code_paths_on_a_uniform_mesh_agree_to_round_off():
    """The same uniform edges forced through the graded paths (element integrals per pair,
    node distances in T, no Toeplitz gathering): the influence matrices differ by about
    1e-14 relative (test_halfplane), the node states come out the same, so each Newton
    system is the same linear system perturbed by ~1e-14, and its solution moves by at most
    its condition number times that (the contact/adhesion block here: kappa = 150 by
    numpy.linalg.cond): 1e-11 relative allowed (measured 5e-14)."""
    case = rolling_cli.load_case(dissimilar(**{"discretization.contact_elements": 30}))
    uniform = rolling_cli.solve(case)
    zone = ContactGrid(1.5 * uniform.mesh_half_width, 30, 2)
    forced = ContactGrid(zone.half_width, 30, 2, 0.0, tuple(zone.edges))  # uniform edges, graded paths
    assert not forced.uniform
    graded = solve_on_grid(case, forced)
    assert np.array_equal(graded.state, uniform.state)
    scale = np.abs(uniform.p_n).max()
    for name in ("p_n", "p_t"):
        assert np.allclose(getattr(graded, name), getattr(uniform, name), rtol=0.0, atol=1e-11 * scale), name
    assert graded.creep == pytest.approx(uniform.creep, rel=1e-11)


def test_graded_dissimilar_solve_keeps_contact_laws_and_forces():
    """A coupled case (beta != 0) on a graded mesh: the contact laws and the loads hold."""
    case = rolling_cli.load_case(dissimilar(**{"discretization.contact_elements": 20, "tangential.q_over_mu_p": 0.04}))
    coarse = rolling_cli.solve(case)
    a = coarse.mesh_half_width
    grid = graded_grid(ContactGrid(1.5 * a, 20, 2), [-0.998 * a, -0.965 * a, 0.875 * a, 0.997 * a], 3e-3 * a, 0.15 * a)
    r = solve_on_grid(case, grid)
    assert_contact_laws(r)
    assert_force_balance(r, load=1000.0, q=0.04 * 0.1 * 1000.0)
    assert [z[0] for z in r.zones()] == ["separation", "slip", "adhesion", "slip", "separation"]


def test_explicit_grid_keeps_the_case_reference():
    """solve_on_grid changes nothing but the mesh: the loads and the Hertz scale are the case's.
    The BEM takes the graded grid too (its influence keyed on the edges): its nodes and weights are
    the grid's and the case's load is carried."""
    case = rolling_cli.load_case(CARTER)
    grid = graded_grid(ContactGrid(1.5, 10, 2), [-1.0, 1.0], 0.01, 0.1)
    r = solve_on_grid(case, grid)
    assert r.normal_load == pytest.approx(1812.5, rel=1e-10)
    assert r.x.size == grid.size and np.array_equal(r.weights, grid.weights)
    bem = solve_on_grid(rolling_cli.load_case(case_dict(**{"discretization.influence": "bem"})), grid)
    assert bem.converged and np.array_equal(bem.x, grid.x) and np.array_equal(bem.weights, grid.weights)
    assert bem.normal_load == pytest.approx(1812.5, rel=1e-10)
