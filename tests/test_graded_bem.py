"""Graded contact grids for the BEM (issue #13 item 1): the body meshes take the grid's own element
edges, the compliance is keyed on them, and the physics is the half-plane model's on the same grid."""

from pathlib import Path

import numpy as np
import pytest

import rolling_cli
from helpers import assert_contact_laws, assert_force_balance, case_dict
from rolling_cli.adapt import grading, kinks
from rolling_cli.influence import bem, build, cache
from rolling_cli.influence.bem import symmetry
from rolling_cli.influence.bem.mesh import graded_edges
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline import explicit, measured_plan

CASES = Path(__file__).resolve().parents[1] / "cases"
E, NU = 2.0e5, 0.3


def _uniform_as_graded(grid: ContactGrid) -> ContactGrid:
    """``grid``'s own edges taken as a graded grid (bypassing ContactGrid.graded's snap to uniform),
    so that the graded code paths run on equal elements."""
    return ContactGrid(grid.half_width, grid.elements, grid.order, grid.centre, tuple(float(e) for e in grid.edges))


@pytest.mark.parametrize("far_field", [True, False], ids=["half-space", "layer"])
def test_uniform_edges_through_the_graded_path_give_the_uniform_compliance(far_field):
    """Equal elements through the graded path: the mesh starts its outer elements from the end
    elements' lengths (np.diff of linspace edges, equal to the first one to an ulp), so the mesh,
    and every compliance block, is the uniform one to round-off. The blocks are solutions of the
    boundary system; node shifts of ~1e-16 of the zone, amplified by its conditioning (~1e4 for
    these meshes), stay below 1e-10 of the largest coefficient."""
    uniform = ContactGrid(1.5, 12)
    graded = _uniform_as_graded(uniform)
    assert not graded.uniform and np.array_equal(graded.x, uniform.x)
    # a half-space block of 20 x 20; a layer 0.2 thick, 3 long, largest element its thickness (as built)
    width, depth, largest = (20.0, 20.0, None) if far_field else (3.0, 0.2, 0.2)
    meshes = [bem.body_mesh(g, width, depth, largest, far_field=far_field) for g in (uniform, graded)]
    assert meshes[0].elements == meshes[1].elements
    assert np.allclose(meshes[0].nodes, meshes[1].nodes, rtol=0.0, atol=1e-14 * width)
    blocks = [bem.condensed(m, g, E, NU) for m, g in zip(meshes, (uniform, graded), strict=True)]
    for name in ("S_nn", "S_nt", "S_tn", "S_tt"):
        a, b = getattr(blocks[0], name), getattr(blocks[1], name)
        assert np.allclose(a, b, rtol=0.0, atol=1e-10 * np.abs(blocks[0].S_nn).max()), name


def test_graded_mesh_takes_the_grids_edges_and_its_end_lengths():
    """The contact nodes of a graded mesh are the grid's (each element's -2/3, 0, 2/3 of its own
    half-length), and the top face continues from each end element's length: the first element
    beyond each end is the first of the graded sequence started from THAT end's element (0.1 on
    the left, 0.2 on the right), scaled to land on the corner."""
    grid = ContactGrid.graded(np.array([-1.0, -0.9, -0.5, 0.0, 0.2, 0.25, 0.3, 0.8, 1.0]))
    mesh = bem.body_mesh(grid, 10.0, 10.0, far_field=True)
    assert np.allclose(mesh.nodes[mesh.contact, 0], grid.x, rtol=0.0, atol=1e-15)
    assert np.all(mesh.nodes[mesh.contact, 1] == 0.0)
    on_top = (mesh.geometry[:, 0, 1] == 0.0) & (mesh.geometry[:, 2, 1] == 0.0)
    start, end = mesh.geometry[on_top, 0, 0], mesh.geometry[on_top, 2, 0]  # traversed from +W to -W
    beyond_right = mesh.lengths[on_top][np.isclose(end, 1.0, rtol=0, atol=1e-12)]
    beyond_left = mesh.lengths[on_top][np.isclose(start, -1.0, rtol=0, atol=1e-12)]
    largest = 10.0 / 4.0  # the default, min(D, W) / 4
    h_left, h_right = grid.element_lengths[0], grid.element_lengths[-1]
    for beside, c, inward, opposite in ((beyond_right, 1.0, h_right, h_left), (beyond_left, -1.0, h_left, h_right)):
        wanted = np.diff(graded_edges(c, 10.0 * c, inward, 1.4, largest))[0]
        other = np.diff(graded_edges(c, 10.0 * c, opposite, 1.4, largest))[0]  # from the other end's
        assert beside.size == 1 and beside[0] == pytest.approx(abs(wanted), rel=1e-12)
        assert abs(abs(other) - abs(wanted)) > 0.1 * abs(wanted)  # the check tells the two ends apart
    # an asymmetric graded grid: no mirror halves, the whole system is solved
    assert symmetry.mirror_nodes(mesh) is None


def test_graded_grids_key_the_influence_on_their_edges(tmp_path, monkeypatch):
    """A graded level's BEM inputs name its edges (a uniform grid's keep their old key), the disk
    cache stores and verifies the entry on the graded grid's nodes, and a second build reads it."""
    monkeypatch.setenv("ROLLC_CACHE_DIR", str(tmp_path))
    dotted = {"discretization.influence": "bem", "discretization.contact_elements": 10}
    case = rolling_cli.load_case(case_dict(**dotted))
    the_plan = measured_plan(case)
    assert "element_edges" not in build.bem_inputs(case, the_plan, case.bodies.A)
    edges = np.sort(np.concatenate([the_plan.grid.edges, [0.55 * the_plan.grid.half_width]]))
    graded = the_plan.__class__(**{**the_plan.__dict__, "grid": ContactGrid.graded(edges)})
    inputs = build.bem_inputs(case, graded, case.bodies.A)
    assert inputs["element_edges"] == tuple(edges) and cache.key(inputs) != cache.key(
        build.bem_inputs(case, the_plan, case.bodies.A)
    )
    first, origin = build.pair_compliance(case, graded)
    again, origin_again = build.pair_compliance(case, graded)
    assert origin["A"] == "computed" and origin_again["A"] == "cache"
    assert np.array_equal(first.x, graded.grid.x) and np.array_equal(again.S_nn, first.S_nn)


def test_graded_bem_half_space_matches_the_half_plane_model_on_the_same_grid():
    """Carter's case (similar bodies: a graded grid towards the contact edges and the stick/slip
    boundary, 54 elements of 0.01 a to 0.1 a) and aluminium on steel (towards the contact edges):
    the BEM half-space and the half-plane model on the SAME graded grid. On uniform grids the two
    differ by a discretisation difference that falls with the element at the contact edges
    (tests/test_halfspace_bem.py: creepage within 0.5 %, tractions within 0.2 % of mu p0 at 400
    elements, up to 0.3 % on coarser meshes; here 0.26 % and 0.36 % at 40 uniform elements). The
    graded grids' elements at the contact edges are finer than the 40 uniform ones, so the same
    bounds hold: creepage 5e-3, tractions 4e-3 of mu p0 (measured 4e-5 and 8e-6 in the creepage,
    2.3e-4 and 1.6e-3 in the tractions)."""
    from helpers import dissimilar

    for base, q in ((case_dict(), 0.51), (dissimilar(), None)):
        dotted = {"discretization.contact_elements": 40}
        hp_case = rolling_cli.load_case(case_dict(base, **dotted))
        bem_case = rolling_cli.load_case(case_dict(base, **dotted, **{"discretization.influence": "bem"}))
        zone = measured_plan(hp_case).grid
        a = zone.half_width / hp_case.discretization.zone
        anchors = [-a, a] + ([a * (1.0 - 2.0 * np.sqrt(1.0 - q))] if q else [])
        grid = grading.graded_grid(zone, anchors, zone.element_length / 8, 1.5 * zone.element_length, 1.4)
        assert not grid.uniform
        hp = explicit.solve_on_grid(hp_case, grid)
        bm = explicit.solve_on_grid(bem_case, grid)
        assert np.array_equal(bm.x, grid.x)
        assert bm.creep == pytest.approx(hp.creep, rel=5e-3)
        scale = hp.mu * hp.hertz_p0
        assert np.max(np.abs(bm.p_t - hp.p_t)) <= 4e-3 * scale
        assert np.max(np.abs(bm.p_n - hp.p_n)) <= 4e-3 * hp.hertz_p0
        assert_contact_laws(bm)


def test_graded_layer_converges_and_obeys_the_laws():
    """The tyred case (incompressible layer, b/a = 0.1) on a grid graded towards the kinks of its
    60-element solution, no element longer than b/2 (the layer rule; here 0.04): it converges,
    obeys the contact laws and the force balance, and its creepage lies within the 60-element
    solution's (60 elements of b/2 hold a discretisation error of 1.5e-3 RMS of mu p0,
    tests/test_halfspace_bem.py; bound 1 % in the creepage, measured 4.6e-5 on 91 graded elements)."""
    base = rolling_cli.load_case(CASES / "tyred_fig11_q41.toml")
    coarse_case = rolling_cli.case.with_overrides(base, {"discretization.contact_elements": 60})
    coarse = rolling_cli.solve(coarse_case)
    positions, _ = kinks.locate_kinks(coarse)
    zone = measured_plan(coarse_case).grid
    thickness = float(base.bodies.B.layer_thickness)
    grid = grading.graded_grid(zone, positions, 0.1 * thickness, 0.4 * thickness, 1.4)
    assert not grid.uniform and grid.element_length <= 0.5 * thickness
    r = explicit.solve_on_grid(coarse_case, grid)
    assert r.converged and np.array_equal(r.x, grid.x)
    assert_contact_laws(r)
    assert_force_balance(r, q=0.41 * r.mu * r.normal_load)
    assert r.creep == pytest.approx(coarse.creep, rel=1e-2)


def test_subsurface_stresses_of_an_adaptive_bem_result_on_its_graded_grid():
    """Stresses of an adaptive BEM result come from the body's boundary solution on the final
    graded grid (the factorised body keyed on its edges). Carter's case, tolerance 0.02 from 20
    elements: the maximum von Mises stress agrees with the adaptive half-plane result's (a
    different graded grid and model): each result's tractions lie within 0.02 mu p0 of the exact
    ones, mu = 0.1, so the surface loads differ by at most 4e-3 p0, under 1 % of the maximum von
    Mises stress (about 0.56 p0); bound 1 %, measured 2e-4."""
    case = rolling_cli.load_case(CASES / "carter_stresses.toml")
    dotted = {"discretization.contact_elements": 20, "discretization.tolerance": 0.02, "stresses.points": [41, 21]}
    bm = rolling_cli.solve(rolling_cli.case.with_overrides(case, {**dotted, "discretization.influence": "bem"}))
    hp = rolling_cli.solve(rolling_cli.case.with_overrides(case, {**dotted, "discretization.influence": "half-plane"}))
    assert bm.adaptive_met and not ContactGrid.graded(bm.element_edges, bm.element_order).uniform
    assert sorted(bm.stresses) == ["A", "B"]
    vm_bem, vm_hp = bm.attributes["stress_max_von_mises"], hp.attributes["stress_max_von_mises"]
    assert vm_bem == pytest.approx(vm_hp, rel=1e-2)
    assert 0.5 * bm.hertz_p0 < vm_bem < 0.6 * bm.hertz_p0
