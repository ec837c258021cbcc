"""The finite cylinder's faster BEM build (issue 21, speed): the regular rule's Gauss orders by
distance, the small systems solved without scipy, the ring of identical contact elements."""

import numpy as np
import pytest

from rolling_cli.influence import bem
from rolling_cli.influence.bem import assembly, cylinder, kelvin, ring
from rolling_cli.influence.bem.elements import evaluate, gauss, map_points
from rolling_cli.model.grid import ContactGrid


def _meshes():
    """A covered and a solid annulus and a half-space block: curved and straight elements."""
    return {
        "cover": cylinder.annulus_mesh(ContactGrid(0.8, 40, 2), 5.0, 4.0),
        "solid": cylinder.annulus_mesh(ContactGrid(0.5, 20, 2), 5.0, 0.5),
        "block": bem.body_mesh(ContactGrid(1.0, 20, 2), 5.0, 5.0),
    }


def _rule(mesh, geo, nodes, elements, order, shear, poisson):
    """An ``order``-point Gauss rule for every pair, straight from the kernels (independent of
    :func:`assembly.regular_integrals`)."""
    xg, wg = gauss(order)
    points, normals, jac = map_points(mesh.geometry[elements], xg)
    weighted = (wg[None] * jac)[..., None] * evaluate(geo.coeff[elements], np.broadcast_to(xg, jac.shape))
    d = points - mesh.nodes[nodes][:, None]
    g = np.einsum("pqkl,pqa->pakl", kelvin.displacement_kernel(d, shear, poisson), weighted)
    h = np.einsum("pqkl,pqa->pakl", kelvin.traction_kernel(d, normals, poisson), weighted)
    return h, g


@pytest.mark.parametrize("name", ["cover", "solid", "block"])
def test_regular_orders_match_a_40_point_rule(name):
    """Every regular pair's H and G integrals by the distance-dependent orders against a 40-point
    rule (exact to rounding at >= 1 element length): within 2e-11 of the pair's largest entry,
    the error of the former fixed 10-point rule at one element length (measured: < 6e-13 beyond
    two lengths, where the orders drop)."""
    mesh = _meshes()[name]
    geo = assembly.geometry(mesh)
    _, _, (i, q, dist) = assembly.classify(mesh, geo, np.arange(mesh.size), np.arange(mesh.elements))
    orders = assembly.regular_orders(dist / (2.0 * geo.half[q]))
    assert orders.min() < assembly.GAUSS  # the rule does drop
    h, g = assembly.regular_integrals(mesh, geo, i, q, 1.0, 0.3, dist)
    h_ref, g_ref = _rule(mesh, geo, i, q, 40, 1.0, 0.3)
    for value, ref in ((h, h_ref), (g, g_ref)):
        scale = np.abs(ref).reshape(len(i), -1).max(axis=1)
        error = np.abs(value - ref).reshape(len(i), -1).max(axis=1)
        assert np.all(error <= 2e-11 * scale)


def test_regular_orders_fall_with_distance():
    """More distant pairs never get more points; the threshold pairs get ``GAUSS``."""
    ratio = np.geomspace(1.0, 1e3, 200)
    orders = assembly.regular_orders(ratio)
    assert orders[0] == assembly.GAUSS and np.all(np.diff(orders) <= 0) and orders[-1] == min(assembly.ORDERS)


def test_small_systems_skip_scipy_and_agree():
    """:func:`condense.solve_small` (numpy's gesv) against the in-place LAPACK path: the same
    factorisation, so within rounding (1e-12 of the largest entry, a condition number ~1e3 times
    the double precision); above ``SMALL_SYSTEM`` it declines."""
    from rolling_cli.influence.bem import condense

    rng = np.random.default_rng(1)
    a = rng.standard_normal((60, 60)) + 60.0 * np.eye(60)
    b = rng.standard_normal((60, 7))
    small = condense.solve_small(a, b)
    full = condense.solve(condense.factorise(np.array(a, order="F")), np.array(b, order="F"))
    assert np.abs(small - full).max() <= 1e-12 * np.abs(full).max()
    big = np.eye(condense.SMALL_SYSTEM + 1)
    assert condense.solve_small(big, big[:, :1]) is None


@pytest.mark.parametrize("inner", [4.0, 0.5])
def test_ring_rotation_matches_quadrature(inner):
    """The contact elements' mutual integrals rotated from two computed rows (:mod:`.ring`) against
    quadrature of every pair: the contact compliance within 1e-12 of its largest entry (rounding:
    the mesh's elements are rotated copies within 1e-12 of the radius; measured 1e-13)."""
    grid = ContactGrid(0.8, 30, 2)
    mesh = cylinder.annulus_mesh(grid, 5.0, inner)
    found = ring.find(mesh, np.arange(grid.elements), np.array([0.0, -5.0]))
    assert found is not None and found.elements.size == grid.elements
    rotated = cylinder.xy_compliance(mesh, grid, 10.0, 0.45, radius=5.0)
    direct = cylinder.xy_compliance(mesh, grid, 10.0, 0.45)
    assert np.abs(rotated - direct).max() <= 1e-12 * np.abs(direct).max()


def test_graded_grid_is_no_ring():
    """Elements of unequal lengths are not rotated copies: no ring, every pair by quadrature."""
    grid = ContactGrid.graded(np.concatenate([np.linspace(-0.8, 0.0, 11), np.linspace(0.0, 0.8, 6)[1:]]), 2)
    mesh = cylinder.annulus_mesh(grid, 5.0, 4.0)
    assert ring.find(mesh, np.arange(grid.elements), np.array([0.0, -5.0])) is None


_BEM_THREADS = """
import sys
from threadpoolctl import threadpool_info
from rolling_cli import blas
from rolling_cli.influence.bem import cylinder
from rolling_cli.model.grid import ContactGrid
grid = ContactGrid(0.5, 8, 2)
with blas.command_threads(1):
    cylinder.condensed(grid, 5.0, 4.0, 10.0, 0.3)  # a small body: numpy's LAPACK
    small = "scipy.linalg" in sys.modules
    from rolling_cli.influence.bem import condense
    import numpy as np
    condense.factorise(np.asfortranarray(np.eye(3)))  # the in-place path imports scipy.linalg now
    counts = sorted({lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"})
print(small, "scipy.linalg" in sys.modules, counts)
"""


def test_small_bodies_skip_scipy_and_a_late_scipy_runs_the_commands_threads():
    """A small finite body's build imports no scipy.linalg (its ~0.2 s of start-up); the in-place
    LU, which imports it when first needed, limits scipy's BLAS to the command's one thread (as
    the BEM's LAPACK did when scipy came with the package's import). In a process without the
    thread variables, where each library starts with one thread per CPU."""
    import os
    import subprocess
    import sys

    from rolling_cli import blas

    clean = {k: v for k, v in os.environ.items() if k not in blas.USER_THREAD_VARIABLES}
    done = subprocess.run([sys.executable, "-c", _BEM_THREADS], capture_output=True, text=True, env=clean)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False True [1]"
