"""The BEM half-space (issue #10): far-field truncation, creepage without offset, the overlap's
meaning, the boundary solution, and the layer's free ends."""

from pathlib import Path

import numpy as np
import pytest

import rolling_cli
from helpers import case_dict, dissimilar, run_cli, solve, write_case
from rolling_cli.case import with_overrides
from rolling_cli.influence import bem, build, halfplane
from rolling_cli.influence.bem import farfield
from rolling_cli.influence.bem.elements import evaluate, gauss, lagrange_coefficients, map_points
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline import plan
from rolling_cli.references import approach, hertz

E = 2.0e5
CASES = Path(__file__).resolve().parents[1] / "cases"


def _derivative(values, grid):
    return (values[1:] - values[:-1]) / grid.spacing


def _strain_errors(grid, nu, size, far_field=True):
    """BEM minus half-plane surface strains under Hertz-shaped loads (a = 1, p0 = 1) over |x| < a,
    relative to the pressure-derivative scale: max of each block's error and the mean strain
    offsets from P (S_tn p: the creepage offset) and from Q (S_tt q)."""
    hp = halfplane.body_compliance(grid, E, nu)
    c = bem.condensed(bem.body_mesh(grid, size, size, far_field=far_field), grid, E, nu)
    p = -hertz.pressure(grid.x, 1.0, 1.0)
    q = -p
    inner = np.abs(grid.x[:-1]) < 1.0
    scale = np.abs(_derivative(hp.S_nn @ p, grid)).max()
    out = {}
    for name, load in (("S_nn", p), ("S_tt", q), ("S_tn", p), ("S_nt", q)):
        diff = (_derivative(getattr(c, name) @ load, grid) - _derivative(getattr(hp, name) @ load, grid))[inner]
        out[name] = np.abs(diff).max() / scale
        out[name + " mean"] = diff.mean() / scale
    return out


def test_far_field_removes_the_block_offset_and_the_rest_decays_with_the_truncation():
    """nu = 0.5: the contact discretisation of the BEM reproduces the half-plane kernels exactly
    (no (1 - 2 nu) terms), so what remains is the truncation: the tractions' moments, which the
    far field of the resultant leaves out, a quadrupole for these symmetric loads whose strain
    at the contact falls like (a/W)^3 (measured ratio 7-15 per step of 2-2.5x in W). Assert
    at least (a/W)^2 per step and 1e-6 of the scale at the default 100 a (measured 1.7e-7).
    nu = 0.3: the creepage offset from P (the mean strain error of S_tn p) is the contact
    discretisation's, ~1e-5 at any W (measured 1.2e-5 at 42 elements); the old block (fixed
    bottom, free sides) had 3.7e-3 at 100 a, decaying only like a/W: bound 5e-5."""
    grid = ContactGrid(1.5, 42, 2)
    sizes = (20.0, 50.0, 100.0, 200.0)
    incompressible = [_strain_errors(grid, 0.5, w) for w in sizes]
    for name in ("S_nn", "S_tt", "S_tn", "S_nt"):
        values = [e[name] for e in incompressible]
        for k in range(len(sizes) - 1):
            assert values[k + 1] <= values[k] * (sizes[k] / sizes[k + 1]) ** 2, (name, sizes[k + 1])
        assert values[2] <= 1e-6, name
    for w in (20.0, 100.0):
        assert abs(_strain_errors(grid, 0.3, w)["S_tn mean"]) <= 5e-5
    assert abs(_strain_errors(grid, 0.3, 100.0, far_field=False)["S_tn mean"]) > 1e-3  # the old block


RIGID = {"kind": "rigid", "radius": 50.0}
INCOMPRESSIBLE_FLAT = {"kind": "elastic", "radius": float("inf"), "young": 1.0e4, "poisson": 0.5}


@pytest.mark.parametrize("coupling", ["auto", "on"])
def test_rigid_on_incompressible_creepage_is_carters_for_any_friction(coupling):
    """Issue #10's case: rigid cylinder on an incompressible flat (beta = 0, Carter exact),
    P = 100, Q/(mu P) = 0.5, default 200 elements. The old block was off by a fixed amount
    (+16 % at mu = 0.1, 2.6x at mu = 0.01). Now within 0.5 % of Carter at mu = 0.1, 0.01 and
    0.001 (the issue's bound; measured 0.09-0.15 %, the half-plane model's discretisation
    error being 0.08 %). With coupling "auto" the exactly zero cross blocks are skipped;
    forced "on", their residual (the far field's truncation, ~1e-7 of the strain scale at
    100 a) must stay within the same bound at mu = 0.001 too."""
    for mu in (0.1, 0.01, 0.001):
        r = solve(
            case_dict(
                **{
                    "bodies.A": RIGID,
                    "bodies.B": INCOMPRESSIBLE_FLAT,
                    "friction.mu": mu,
                    "normal.load": 100.0,
                    "tangential.q_over_mu_p": 0.5,
                    "discretization.influence": "bem",
                    "effects.coupling": coupling,
                }
            )
        )
        assert r.creep == pytest.approx(r.carter_creep, rel=5e-3), mu
        assert ("coupling: skipped" in r.effects_line) == (coupling == "auto")


def test_dissimilar_bem_matches_the_half_plane_model():
    """Aluminium on steel at 400 elements, both models on the same grid (the issue's check):
    creepage within 0.5 % (measured 1e-5 and 7e-5) and tractions within 0.2 % of mu p0
    (measured 0.03 % and 0.15 %; at coarser meshes the BEM's displacement interpolation at
    the contact edges differs from the closed form's point values by up to 0.3 %, a
    discretisation difference that falls with the mesh). Q/(mu P) = 0.04 has the smallest
    creepage (the old block's offset was largest there relatively), -0.83 the largest
    traction difference."""
    for q in (-0.83, 0.04):
        base = {"tangential.q_over_mu_p": q, "discretization.contact_elements": 400}
        hp = solve(dissimilar(**base))
        bm = solve(dissimilar(**base, **{"discretization.influence": "bem"}))
        assert "coupling: simulated" in bm.effects_line
        assert bm.creep == pytest.approx(hp.creep, rel=5e-3)
        assert np.max(np.abs(bm.p_t - hp.p_t)) <= 2e-3 * hp.mu * hp.hertz_p0
        assert np.max(np.abs(bm.p_n - hp.p_n)) <= 2e-3 * hp.hertz_p0


def test_creepage_does_not_depend_on_the_truncation():
    """W = D = 20, 50, 100, 200 a, aluminium on steel, Q/(mu P) = 0.04, 60 elements: the
    same creepage to 0.5 % (the issue's bound). Measured against the half-plane model on the
    same grid: +4.8e-4, +7.6e-5, +2.5e-5, +1.3e-5, falling like (a/W)^2 (the tractions' first
    moments, left out of the far field) to the two models' discretisation difference, ~1e-5
    here (bound 1e-4 at 200 a); the old block gave -7 %, -3.5 %, -1.4 %, -0.9 %."""
    base = {"tangential.q_over_mu_p": 0.04, "discretization.contact_elements": 60}
    hp = solve(dissimilar(**base))
    creep = []
    for size in (20.0, 50.0, 100.0, 200.0):
        extra = {"discretization.block_width": size, "discretization.block_depth": size}
        creep.append(solve(dissimilar(**base, **{"discretization.influence": "bem"}, **extra)).creep)
    assert np.ptp(creep) <= 5e-3 * abs(np.mean(creep))
    assert abs(creep[-1] / hp.creep - 1.0) <= abs(creep[0] / hp.creep - 1.0)
    assert abs(creep[-1] / hp.creep - 1.0) <= 1e-4


@pytest.mark.parametrize(
    "bodies",
    [
        {},
        {"bodies.A": {"kind": "rigid", "radius": 100.0}, "bodies.B.poisson": 0.5},
        {"bodies.A": {"kind": "rigid", "radius": 100.0}, "friction.mu": 0.0, "tangential.q_over_mu_p": None},
    ],
    ids=["similar", "rigid on nu = 0.5", "rigid on nu = 0.3, frictionless"],
)
def test_overlap_is_the_approach_of_the_points_at_depth_d(bodies):
    """The overlap is the approach of the two bodies' points at depth D = block_depth a below
    the contact centre, each body a half-space: the solved load must reproduce the overlap
    through the closed-form approach of a Hertz pressure (exact for these uncoupled pairs)
    at D = 30 a and 300 a, where the load differs by 60 %. Measured within 6e-5 at 40
    elements (the normal problem's discretisation and the far field's (a/D)^2); bound 3e-4."""
    loads = []
    for depth in (30.0, 300.0):
        data = case_dict(
            **{
                "normal.overlap": 0.015,
                "discretization.influence": "bem",
                "discretization.contact_elements": 40,
                "discretization.block_depth": depth,
                **bodies,
            }
        )
        r = solve(data)
        case = rolling_cli.load_case(data)
        d = depth * r.mesh_half_width
        w = sum(
            approach.approach(r.normal_load, r.hertz_a, b.modulus, b.ratio, d) for b in (case.bodies.A, case.bodies.B)
        )
        assert w == pytest.approx(0.015, rel=3e-4)
        loads.append(r.normal_load)
    assert loads[0] > 1.3 * loads[1]


def test_boundary_solution_balances_the_contact_load_and_matches_the_compliance():
    """The full boundary solution of a half-space body: (1) its contact displacements equal the
    condensed compliance times the tractions (same LU, round-off); (2) on the truncation
    boundary the displacement is Flamant's for the resultant; (3) the boundary tractions are in
    equilibrium: sum over elements of int t ds = 0 to the quadrature of the solved tractions,
    measured 1e-4 of P (the truncation's element interpolation of the far-field tractions);
    bound 1e-3."""
    data = dissimilar(
        **{"discretization.influence": "bem", "discretization.contact_elements": 12, "discretization.block_width": 20.0}
    )
    case = rolling_cli.load_case(data)
    r = rolling_cli.solve(case)
    the_plan = plan(case, half_width=r.mesh_half_width)
    for label, sign in (("A", 1.0), ("B", -1.0)):
        mesh, u, t = build.boundary_solution(case, the_plan, label, r.p_n, r.p_t)
        body = getattr(case.bodies, label)
        compliance = build._compute_bem(build.bem_inputs(case, the_plan, body))
        w = -u[mesh.contact, 1]
        assert np.allclose(w, compliance.S_nn @ r.p_n + compliance.S_nt @ (sign * r.p_t), rtol=1e-9, atol=0)
        assert np.allclose(t[mesh.contact], np.column_stack([sign * r.p_t, r.p_n]), rtol=0, atol=0)
        resultant = np.array([r.weights @ (sign * r.p_t), r.weights @ r.p_n])
        depth = 100.0 * r.mesh_half_width
        far = farfield.half_space_displacement(mesh.nodes[mesh.far], body.young, body.poisson, depth) @ resultant
        assert np.allclose(u[mesh.far], far, rtol=1e-12, atol=1e-15 * np.abs(far).max())
        # equilibrium: integrate the (quadratic) traction over every element
        xg, wg = gauss(6)
        _, _, jac = map_points(mesh.geometry, xg)
        shape = evaluate(lagrange_coefficients(mesh.local), np.broadcast_to(xg, jac.shape))
        total = np.einsum("eg,egk,ekd->d", wg * jac, shape, t[mesh.connectivity])
        assert np.abs(total).max() <= 1e-3 * abs(r.normal_load)


def test_the_layers_free_ends_do_not_matter_at_the_default_length():
    """The layer keeps its real rigid-core bottom; its ends are a truncation. The layer's
    stresses decay along the bond over a few b, so 10 b (the default) and 40 b of free
    length give the same answer: measured 1e-5 of mu p0 and 1e-6 in the creepage at 60-100
    elements (the mesh difference of the longer layer), far below the 1.5e-3 RMS
    discretisation error at 60 elements; bounds 1e-4 and 1e-5."""
    base = rolling_cli.load_case(CASES / "tyred_fig11_q41.toml")
    results = [
        rolling_cli.solve(
            with_overrides(base, {"discretization.contact_elements": 60, "discretization.layer_length": length})
        )
        for length in (10.0, 40.0)
    ]
    scale = results[0].mu * float(np.max(-results[0].p_n))
    assert np.max(np.abs(results[0].p_t - results[1].p_t)) <= 1e-4 * scale
    assert results[0].creep == pytest.approx(results[1].creep, rel=1e-5)


def test_error_estimate_refines_a_layer_whose_half_mesh_is_not_allowed(tmp_path):
    """The tyred case at its minimum mesh (60 elements: b/2 each): halving breaks the layer's
    element rule, so the estimate compares with 120 elements and says so."""
    data = rolling_cli.case.case_to_dict(rolling_cli.load_case(CASES / "tyred_fig11_q41.toml"))
    data["discretization"]["contact_elements"] = 60
    out = tmp_path / "t.h5"
    result = run_cli("solve", write_case(tmp_path, data), "-o", out, "--error-estimate")
    assert result.exit_code == 0, result.output
    assert "error estimate against 120 elements (refined mesh" in result.output
    r = rolling_cli.read_result(out)
    assert r.error_estimate_elements == 120 and r.error_estimate_method.startswith("refined mesh")
    assert 0.0 < r.error_estimate_rms < r.error_estimate < 0.2
