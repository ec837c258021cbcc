"""The boundary element engine: patch tests, quadrature, and the half-plane limit."""

import numpy as np
import pytest

from helpers import case_dict, solve
from rolling_cli.influence import bem
from rolling_cli.influence.bem import assembly, collinear, condense, farfield, symmetry
from rolling_cli.influence.bem.elements import evaluate, gauss, lagrange_coefficients, map_points
from rolling_cli.influence.bem.kelvin import displacement_kernel, traction_kernel
from rolling_cli.influence.bem.mesh import rectangle
from rolling_cli.model.grid import ContactGrid
from rolling_cli.references import carter, hertz

E = 2.0e5


def _node_normals(mesh):
    normals = np.zeros((mesh.size, 2))
    for e in range(mesh.elements):
        tangent = mesh.geometry[e, 2] - mesh.geometry[e, 0]
        tangent /= np.linalg.norm(tangent)
        normals[mesh.connectivity[e]] = [tangent[1], -tangent[0]]
    return normals


@pytest.mark.parametrize("kind", ["continuous", "discontinuous", "mixed", "far field"])
@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_patch_uniform_stress(kind, nu):
    """A uniform stress state (linear u, constant t) is represented exactly by
    quadratic elements, so only quadrature and round-off remain: the solved
    boundary values must match to near machine precision. Measured ~1e-13;
    the bound 1e-11 leaves room for the condition number of the BEM system.
    "far field": the half-space's mesh, displacement prescribed on the sides too."""
    if kind == "far field":
        mesh = rectangle(2.0, 1.0, np.linspace(-0.5, 0.5, 6), far_field=True)
    else:
        mesh = rectangle(2.0, 1.0, np.linspace(-0.5, 0.5, 6), kind=kind)
    shear = E / (2 * (1 + nu))
    H, G = assembly.assemble(mesh, shear, nu)
    sxx, syy, sxy = 1.0, 0.5, 0.3
    exx = ((1 - nu**2) * sxx - nu * (1 + nu) * syy) / E
    eyy = ((1 - nu**2) * syy - nu * (1 + nu) * sxx) / E
    exy = sxy / (2 * shear)
    X = mesh.nodes
    u = np.column_stack([exx * X[:, 0] + exy * X[:, 1], exy * X[:, 0] + eyy * X[:, 1]]).ravel()
    t = (_node_normals(mesh) @ np.array([[sxx, sxy], [sxy, syy]])).ravel()
    A, B = condense.boundary_system(mesh, H, G)
    fixed = np.repeat(mesh.fixed, 2)
    solved = np.linalg.solve(A, B @ np.where(fixed, u, t))
    exact = np.where(fixed, t, u)
    assert np.max(np.abs(solved - exact)[~fixed]) <= 1e-11 * np.abs(u).max()
    assert np.max(np.abs(solved - exact)[fixed]) <= 1e-11 * np.abs(t).max()


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_rigid_body_motions_give_zero_traction(nu):
    """A rigid motion imposed on the fixed bottom, zero traction elsewhere: the
    whole body follows the motion and the bottom traction vanishes. (With every
    displacement imposed, nu = 0.5 would leave a hydrostatic traction free:
    a uniform pressure does not strain an incompressible body.)"""
    mesh = rectangle(2.0, 1.0, np.linspace(-0.5, 0.5, 6))
    H, G = assembly.assemble(mesh, E / (2 * (1 + nu)), nu)
    A, B = condense.boundary_system(mesh, H, G)
    fixed = np.repeat(mesh.fixed, 2)
    X = mesh.nodes
    for u in (
        np.tile([1.0, 0.0], mesh.size),
        np.tile([0.0, 1.0], mesh.size),
        np.column_stack([-X[:, 1], X[:, 0]]).ravel(),  # small rotation
    ):
        solved = np.linalg.solve(A, B @ np.where(fixed, u, 0.0))
        # a traction of E |u| / L would be a genuine deformation; zero to round-off
        assert np.max(np.abs(solved[fixed])) <= 1e-10 * E * np.abs(u).max() / 2.0
        assert np.max(np.abs(solved[~fixed] - u[~fixed])) <= 1e-10 * np.abs(u).max()


def _reference_integral(mesh, i, e, shear, nu, pieces=400):
    """Brute force: the element cut into ``pieces`` equal parts, 20 Gauss points each."""
    xg, wg = gauss(20)
    edges = np.linspace(-1, 1, pieces + 1)
    xi = (0.5 * (edges[:-1] + edges[1:])[:, None] + 0.5 * np.diff(edges)[:, None] * xg).ravel()
    w = (0.5 * np.diff(edges)[:, None] * wg).ravel()
    pts, nrm, jac = map_points(mesh.geometry[e : e + 1], xi)
    shape = evaluate(lagrange_coefficients(mesh.local[e]), xi)
    d = pts[0] - mesh.nodes[i]
    U = displacement_kernel(d, shear, nu)
    T = traction_kernel(d, nrm[0], nu)
    ws = (w * jac[0])[:, None] * shape
    return np.einsum("qa,qkl->akl", ws, U), np.einsum("qa,qkl->akl", ws, T)


@pytest.mark.parametrize("depth", [1.0, 0.05])
def test_nearly_singular_integrals_match_refined_subdivision(depth):
    """Nodes near a corner (a side's first node against the top face's last element) and, for the thin
    layer (depth 0.05 against contact elements of 0.1), points across the layer: the graded subdivision
    must match a brute-force 8000-point rule to 1e-12 of the entry scale (the brute-force rule is itself
    converged to ~1e-14)."""
    mesh = rectangle(1.0, depth, np.linspace(-0.5, 0.5, 11), largest=2 * depth)
    nu, shear = 0.5, E / 3
    H, G = assembly.assemble(mesh, shear, nu)
    geo = assembly.geometry(mesh)
    _, (i, e, t, dist), _ = assembly.classify(mesh, geo, np.arange(mesh.size), np.arange(mesh.elements))
    assert len(i)
    rng = np.random.default_rng(1)
    chosen = rng.choice(len(i), size=min(12, len(i)), replace=False)
    pairs = np.column_stack([i, e])[chosen]
    h, g = assembly.near_integrals(mesh, geo, pairs, t[chosen], dist[chosen], shear, nu)
    for (node, element), h_found, g_found in zip(pairs, h, g, strict=True):
        ref_g, ref_h = _reference_integral(mesh, node, element, shear, nu)
        assert np.max(np.abs(g_found - ref_g)) <= 1e-12 * np.abs(G).max()
        assert np.max(np.abs(h_found - ref_h)) <= 1e-12 * np.abs(H).max()


@pytest.mark.parametrize("nu", [0.3, 0.5])
def test_collinear_closed_form_matches_refined_subdivision(nu):
    """Pairs whose node lies on the element's own line (the contact zone and the top face; not the node's
    own element) are integrated in closed form, by Gauss on the smooth integrand, or by the series in
    1/c, by the distance c in half-lengths: the brute-force 8000-point rule must agree to 1e-12 of the
    entry scale in each regime (nearest neighbours of discontinuous nodes at h/6, c = 4/3; c in (2, 8];
    c > 8, on the bottom and the top face, where the elements grow)."""
    mesh = rectangle(3.0, 1.0, np.linspace(-0.5, 0.5, 11), far_field=True)
    shear = E / (2 * (1 + nu))
    H, G = assembly.assemble(mesh, shear, nu)
    geo = assembly.geometry(mesh)
    runs, _, _ = assembly.classify(mesh, geo, np.arange(mesh.size), np.arange(mesh.elements))
    i = np.concatenate([np.broadcast_to(nodes, c.shape).ravel() for _, nodes, c, _ in runs])
    e = np.concatenate([np.broadcast_to(qs[:, None], c.shape).ravel() for qs, _, c, _ in runs])
    c = np.concatenate([c.ravel() for _, _, c, _ in runs])
    own = np.concatenate([own.ravel() for _, _, _, own in runs])
    rng = np.random.default_rng(2)
    for regime in (np.abs(c) <= 2.0, (np.abs(c) > 2.0) & (np.abs(c) <= 8.0), np.abs(c) > 8.0):
        candidates = np.flatnonzero(regime & (own < 0))
        assert candidates.size
        chosen = rng.choice(candidates, size=min(8, candidates.size), replace=False)
        h, g = collinear.integrals(c[chosen, None], own[chosen, None], geo.coeff[e[chosen]], geo.half[e[chosen]],
                                   geo.tangent[e[chosen]], shear, nu)  # fmt: skip
        for node, element, h_found, g_found in zip(i[chosen], e[chosen], h[:, :, :, 0], g[:, :, :, 0], strict=True):
            ref_g, ref_h = _reference_integral(mesh, node, element, shear, nu)
            assert np.max(np.abs(g_found.swapaxes(-1, -2) - ref_g)) <= 1e-12 * np.abs(G).max()
            assert np.max(np.abs(h_found.swapaxes(-1, -2) - ref_h)) <= 1e-12 * np.abs(H).max()


@pytest.mark.parametrize("mirror", [True, False])
@pytest.mark.parametrize("far_field", [True, False])
@pytest.mark.parametrize("elements", [12, 13])
def test_direct_system_condenses_as_the_dense_matrices(elements, far_field, mirror):
    """The model assembles its boundary systems straight from the element integrals (contact unknowns
    first, no H or G), for a mirror-symmetric body as two halves (symmetric and antisymmetric, collocated
    on x >= 0; with 13 elements a contact node sits on x = 0); condensing the dense H and G of the same
    integrals, whole, must give the same compliance to round-off: relative 1e-12 (a condition number
    ~1e3 of a 400-unknown system times 1e-16, with room). A half-space block with its far field, and a
    layer (fixed bottom)."""
    grid = ContactGrid(1.5, elements, 2)
    depth = 20.0 if far_field else 0.5
    width, largest = (20.0, None) if far_field else (3.0, depth)
    mesh = bem.body_mesh(grid, width, depth, largest=largest, far_field=far_field)
    nu = 0.3
    far = farfield.far_field_values(mesh, E, nu, depth)
    assert len(symmetry.reductions(mesh, far, grid.weights, mirror)) == (2 if mirror else 1)
    found = bem.condensed(mesh, grid, E, nu, mirror=mirror)
    H, G = assembly.assemble(mesh, E / (2 * (1 + nu)), nu)
    A, B = condense.boundary_system(mesh, H, G)
    dofs = (2 * mesh.contact[:, None] + np.arange(2)).reshape(-1)
    solved = np.linalg.solve(A, np.hstack([B[:, dofs], B @ far]))[dofs]
    resultant = np.zeros((2, grid.size, 2))  # F_l = sum_j w_j t_(j, l)
    resultant[0, :, 0] = resultant[1, :, 1] = grid.weights
    flex = (solved[:, : dofs.size] + solved[:, dofs.size :] @ resultant.reshape(2, -1)).reshape(grid.size, 2, -1, 2)
    expected = {"S_tt": flex[:, 0, :, 0], "S_tn": flex[:, 0, :, 1], "S_nt": -flex[:, 1, :, 0]}
    expected["S_nn"] = -flex[:, 1, :, 1]
    for name, block in expected.items():
        assert getattr(found, name) == pytest.approx(block, abs=1e-12 * np.abs(expected["S_nn"]).max()), name


def test_mirror_halves_give_the_whole_boundary_solution():
    """The full boundary solution (every node's u and t) of a mirror-symmetric half-space block under an
    asymmetric load (Hertz pressure plus Carter's traction, whose resultant has both components), from
    the two halves and from the whole system: the same to round-off (1e-12 of each field's scale). A
    block whose contact zone is off-centre is not its own mirror image: it keeps the whole system."""
    grid = ContactGrid(1.5, 13, 2)
    mesh = bem.body_mesh(grid, 20.0, 20.0, far_field=True)
    p_n = -hertz.pressure(grid.x, 1.0, 1.0)
    p_t = carter.traction(grid.x, 0.5, 1.0, 1.0, 0.3, -1)
    halves = bem.boundary_solution(bem.prepare_body(mesh, grid, E, 0.3), p_n, p_t)
    whole = bem.boundary_solution(bem.prepare_body(mesh, grid, E, 0.3, mirror=False), p_n, p_t)
    for found, expected in zip(halves[1:], whole[1:], strict=True):
        assert found == pytest.approx(expected, abs=1e-12 * np.abs(expected).max())
    shifted = rectangle(20.0, 20.0, grid.edges + 0.1, far_field=True)
    far = farfield.far_field_values(shifted, E, 0.3, 20.0)
    assert symmetry.mirror_nodes(shifted) is None
    assert len(symmetry.reductions(shifted, far, grid.weights)) == 1


def test_paper_similar_case_against_carter_and_under_refinement():
    """The paper's Fig. 3 model (overlap 0.015 mm, BEM) against Carter at the solved load.

    The maximum error is bounded at every mesh by the square-root edge estimate
    C sqrt(Delta/a): moving the discrete edge by a fraction of a node cell
    changes the traction there by ~ sqrt(Delta/a). Measured C over 10-320
    elements: up to 0.18 (0.11 for the half-plane model; the BEM adds its
    displacement interpolation near the edges); bound C = 0.25 (0.055 of mu p0
    at the paper's 21 elements, measured 0.040). The maximum is not monotone
    in the mesh, because it depends on where the edge falls within a cell; so
    is the RMS at the coarsest meshes (0.0075, 0.0082 of mu p0 at 10 and 21
    elements), which then falls to 0.0009 at 160: at least the order 1/2 of a
    square-root kink, RMS(160) <= RMS(10) / 4. The creepage error of the
    first-order upwind difference is ~ C Delta/a with C = 0.2-0.6 depending on
    where the contact edge falls in a node cell (the same on the half-plane
    model at the same zone, benchmarks/RESULTS.md): bound 0.75 Delta/a (measured
    2.1 % at 21 elements, 0.29 % at 160), and it falls with the mesh here."""
    rms, creep = [], []
    for elements in (10, 21, 40, 80, 160):
        r = solve(
            case_dict(
                **{
                    "normal.overlap": 0.015,
                    "discretization.influence": "bem",
                    "discretization.contact_elements": elements,
                }
            )
        )
        exact = carter.traction(r.x, 0.51, r.hertz_a, r.hertz_p0, r.mu, -1)
        error = np.abs(r.p_t - exact) / (r.mu * r.hertz_p0)
        assert error.max() <= 0.25 * np.sqrt(r.node_spacing / r.hertz_a)
        rms.append(np.sqrt(np.mean(error**2)))
        creep.append(abs(r.creep / r.carter_creep - 1.0))
        assert creep[-1] <= 0.75 * r.node_spacing / r.hertz_a
        assert r.overlap == 0.015
    assert rms[-1] <= rms[0] / 4.0
    assert all(a > b for a, b in zip(creep, creep[1:], strict=False))


def test_identical_bodies_are_computed_once_and_cached(tmp_path, monkeypatch):
    from rolling_cli.influence import build

    monkeypatch.setenv("ROLLC_CACHE_DIR", str(tmp_path))
    build.clear_memo()
    data = case_dict(**{"discretization.influence": "bem", "discretization.contact_elements": 12})
    first = solve(data)
    assert "influence A: simulated: BEM half-space (computed)" in first.effects_line
    assert "influence B: reused: identical to body A" in first.effects_line
    assert len(list(tmp_path.glob("*.npz"))) == 1
    build.clear_memo()
    second = solve(data)
    assert "from disk cache" in second.effects_line
    assert np.array_equal(first.p_t, second.p_t)
    monkeypatch.setenv("ROLLC_NO_CACHE", "1")
    build.clear_memo()
    third = solve(case_dict(**{"discretization.influence": "bem", "discretization.contact_elements": 13}))
    assert "(computed)" in third.effects_line
    assert len(list(tmp_path.glob("*.npz"))) == 1  # nothing written with the cache off


def test_rigid_body_gets_no_mesh():
    data = case_dict(
        **{
            "bodies.A": {"kind": "rigid", "radius": 100.0},
            "discretization.influence": "bem",
            "discretization.contact_elements": 12,
        }
    )
    r = solve(data)
    assert "influence A: skipped: rigid body, no mesh" in r.effects_line
