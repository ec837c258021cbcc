"""A finite cover bonded to an elastic core (issue 21 item 1): the two-region BEM of
:mod:`rolling_cli.influence.bem.core` against Michell's two-region series
(:mod:`rolling_cli.references.annulus_core`), the rigid-core and homogeneous limits, and the
case keys (core_young, core_poisson, inner_radius)."""

import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, run_cli, solve, write_case
from rolling_cli.case import load_case
from rolling_cli.influence import build
from rolling_cli.influence.bem import core, cylinder
from rolling_cli.model.grid import ContactGrid
from rolling_cli.references import annulus, annulus_core

E, NU = 2.0e5, 0.3
R, RC, RI = 20.0, 16.0, 1.0  # a cover b = 4 = 4 a on a core, bore 0.05 R
GRID = ContactGrid(1.5, 30, 2)  # a = 1: a/R = 0.05


def _bump(s, a=1.0):
    """A smooth unit load (1 - s^2/a^2)^2 on |s| < a (C1: the BEM's quadratic interpolation of it
    is within ~(h/a)^3, so the comparison measures the body model; as tests/test_cylinder_bem.py)."""
    return np.where(np.abs(s) < a, (1.0 - (s / a) ** 2) ** 2, 0.0)


def _largest(c):
    return max(np.abs(getattr(c, n)).max() for n in ("S_nn", "S_nt", "S_tn", "S_tt"))


def _difference(c, d):
    return max(np.abs(getattr(c, n) - getattr(d, n)).max() for n in ("S_nn", "S_nt", "S_tn", "S_tt"))


def test_michell_core_limits():
    """The reference's own limits. (1) A core of the cover's material is the single annulus
    r_i < r < R (:mod:`.annulus`): the same functions, only differently normalised, so round-off
    (bound 1e-12 of the largest response). (2) A core 1e6 times stiffer is the rigid core of
    the annulus r_c < r < R: the core's own compliance is G / G_c = 1e-6 of the cover's times a
    geometry factor, largest for the torsion (u_theta = D / r in each region): the core's
    1/r_i^2 - 1/r_c^2 over the cover's 1/r_c^2 - 1/R^2 (~710 here); bound twice their product."""
    modes = 4096
    bound = 2.0 * 1e-6 * (1.0 / RI**2 - 1.0 / RC**2) / (1.0 / RC**2 - 1.0 / R**2)
    same = annulus_core.mode_responses(modes, RI / R, RC / R, NU, NU, 1.0)
    single = annulus.mode_responses(modes, RI / R, NU)
    assert np.abs(same - single).max() <= 1e-12 * np.abs(single).max()
    assert np.allclose(annulus_core.axisymmetric(RI / R, RC / R, NU, NU, 1.0), annulus._axisymmetric(RI / R, NU))
    stiff = annulus_core.mode_responses(modes, RI / R, RC / R, NU, 0.25, 1e6)
    rigid = annulus.mode_responses(modes, RC / R, NU)
    assert np.abs(stiff - rigid).max() <= bound * np.abs(rigid).max()
    a0, b0 = annulus_core.axisymmetric(RI / R, RC / R, NU, 0.25, 1e6)
    a1, b1 = annulus._axisymmetric(RC / R, NU)
    assert abs(a0 - a1) <= bound * a1 and abs(b0 - b1) <= bound * b1


def _michell(radius, core_radius, inner, young_core, poisson_core, sigma_rr, sigma_rt, samples=2**18):
    """Michell's two-region w (into the body) and u_t at the contact nodes for tractions given as
    functions of the arc length s (as tests/test_cylinder_bem.py)."""
    theta = 2.0 * np.pi * np.arange(samples) / samples
    theta = np.where(theta > np.pi, theta - 2.0 * np.pi, theta)
    s = radius * theta
    u_r, u_t = annulus_core.surface_displacement(
        sigma_rr(s),
        sigma_rt(s),
        radius,
        core_radius,
        inner,
        E / (2.0 * (1.0 + NU)),
        NU,
        young_core / (2.0 * (1.0 + poisson_core)),
        poisson_core,
    )
    order = np.argsort(theta)
    angles = GRID.x / radius
    return np.interp(angles, theta[order], -u_r[order]), np.interp(angles, theta[order], u_t[order])


@pytest.mark.parametrize(("core_young", "core_poisson"), [(0.2 * E, 0.25), (5.0 * E, 0.35)])
def test_bem_core_matches_michell(core_young, core_poisson):
    """The cover on a softer and on a stiffer core, at a/R = 0.05, against Michell's two-region
    series: the contact nodes' displacements under a normal and a tangential unit bump within
    0.5 % of the largest (the brief's bound; the one-region BEM meets Michell within 6e-6 in
    tests/test_cylinder_bem.py, the interface adds the core's BEM of the same element sizes;
    measured 7e-5 at most)."""
    c = core.condensed(GRID, R, RC, RI, E, NU, core_young, core_poisson)
    load = -_bump(GRID.x)
    zero = np.zeros_like(load)
    for p_n, p_t in ((load, zero), (zero, load)):
        w = c.S_nn @ p_n + c.S_nt @ p_t
        u_t = c.S_tn @ p_n + c.S_tt @ p_t
        sigma_rr = (lambda s: -_bump(s)) if p_n is load else (lambda s: 0.0 * s)
        sigma_rt = (lambda s: -_bump(s)) if p_t is load else (lambda s: 0.0 * s)
        w_ref, u_ref = _michell(R, RC, RI, core_young, core_poisson, sigma_rr, sigma_rt)
        scale = max(np.abs(w_ref).max(), np.abs(u_ref).max())
        assert np.abs(w - w_ref).max() <= 5e-3 * scale
        assert np.abs(u_t - u_ref).max() <= 5e-3 * scale


def test_rigid_path_is_the_rigid_core_cover():
    """The two-region solve with ``stiffness=None`` (u_I = 0) is the rigid-core cover of
    :func:`.cylinder.xy_compliance` (mirror halves, ring rotation): the same equations by another
    assembly, so round-off (bound 1e-10 of the largest entry; measured 1e-13)."""
    mesh = cylinder.annulus_mesh(GRID, R, RC)
    ref = cylinder.xy_compliance(mesh, GRID, E, NU, radius=R)
    assert np.abs(core.xy_compliance(mesh, E, NU, None) - ref).max() <= 1e-10 * np.abs(ref).max()


def test_stiff_core_and_core_of_the_cover_material():
    """(1) core_young = 1e6 E: the rigid-core cover (:func:`.cylinder.condensed` at r_i = r_c)
    within the core's own compliance, G/G_c = 1e-6 times the geometry factor of
    test_michell_core_limits (the torsion's, ~710; bound twice it, of the largest entry;
    measured 1.6e-5). (2) A core of the cover's material: the homogeneous annulus r_i < r < R
    (:func:`.cylinder.condensed`, another mesh): each within 7e-5 of Michell's series
    (test_bem_core_matches_michell, tests/test_cylinder_bem.py), bound 1e-3 of the largest
    entry (measured 5e-5)."""
    stiff = core.condensed(GRID, R, RC, RI, E, NU, 1e6 * E, 0.25)
    rigid = cylinder.condensed(GRID, R, RC, E, NU)
    factor = (1.0 / RI**2 - 1.0 / RC**2) / (1.0 / RC**2 - 1.0 / R**2)
    assert _difference(stiff, rigid) <= 2.0 * 1e-6 * factor * _largest(rigid)
    same = core.condensed(GRID, R, RC, RI, E, NU, E, NU)
    whole = cylinder.condensed(GRID, R, RI, E, NU)
    assert _difference(same, whole) <= 1e-3 * _largest(whole)


RIGID_FLAT = {"kind": "rigid", "radius": float("inf")}
COVER = {"kind": "layered", "shape": "cylinder", "radius": 25.0, "layer_thickness": 5.0, "young": 10.0, "poisson": 0.45}


def _case(a, elements=30, **dotted):
    data = case_dict(
        **{
            "normal.load": 2.0,
            "friction.mu": 0.5,
            "tangential.q_over_mu_p": 0.3,
            "discretization.contact_elements": elements,
            "discretization.influence": None,
        }
    )
    data["bodies"] = {"A": a, "B": RIGID_FLAT}
    return case_dict(data, **dotted)


def test_solve_core_of_the_cover_material_is_the_homogeneous_roller():
    """The whole solve: a cover on a core of its own material, bore 10, against the homogeneous
    finite roller (kind = "elastic", inner_radius = 10): the compliances differ by the BEM's
    mesh error (1e-3 of the largest entry at most, above; measured 5e-5), so creepage, overlap and
    peak pressure within 1e-3 relative (measured 7e-5, 2e-5, 5e-6). The effects line names the core."""
    cover = solve(_case({**COVER, "core_young": 10.0, "core_poisson": 0.45, "inner_radius": 10.0}))
    homogeneous = {k: v for k, v in COVER.items() if k != "layer_thickness"}
    whole = solve(_case(homogeneous | {"kind": "elastic", "inner_radius": 10.0}))
    assert_contact_laws(cover)
    assert "body shape: finite cylinder (A: R = 25, cover 5 on an elastic core, bore 10)" in cover.effects_line
    assert "cover on an elastic core" in cover.effects_line
    for name in ("creep", "overlap"):
        assert abs(getattr(cover, name) - getattr(whole, name)) <= 1e-3 * abs(getattr(whole, name)), name
    assert abs(cover.p_n.min() - whole.p_n.min()) <= 1e-3 * abs(whole.p_n.min())


def test_absent_core_keys_leave_the_rigid_core_unchanged():
    """Without core_young the BEM inputs (the cache key) are today's, so the same compliance bit
    for bit; with it, the core's moduli and bore join them (a default bore CORE_BORE R)."""
    from rolling_cli import pipeline

    rigid = load_case(case_dict(_case(COVER)))
    the_plan = pipeline.plan(rigid)
    inputs = build.bem_inputs(rigid, the_plan, rigid.bodies.A)
    assert not any(key.startswith("core") for key in inputs)
    elastic = load_case(case_dict(_case({**COVER, "core_young": 50.0, "core_poisson": 0.3})))
    inputs = build.bem_inputs(elastic, pipeline.plan(elastic), elastic.bodies.A)
    assert inputs["core_young"] == 50.0 and inputs["core_poisson"] == 0.3 and inputs["core_bore"] == 0.05 * 25.0


@pytest.mark.parametrize(
    ("extra", "key", "why"),
    [
        ({"core_young": 0.0, "core_poisson": 0.3}, "bodies.A.core_young", ""),
        ({"core_young": 50.0, "core_poisson": 0.6}, "bodies.A.core_poisson", ""),
        ({"core_young": 50.0, "core_poisson": -1.0}, "bodies.A.core_poisson", ""),
        ({"core_young": 50.0}, "bodies.A.core_poisson", "missing key"),
        ({"core_poisson": 0.3}, "bodies.A.core_young", "missing key"),
        (
            {"core_young": 50.0, "core_poisson": 0.3, "inner_radius": 20.0},
            "bodies.A.inner_radius = 20",
            "not inside the core",
        ),
        ({"inner_radius": 2.0}, "bodies.A.inner_radius = 2", "rigid core"),
        ({"core_young": 50.0, "core_poisson": 0.3, "shape": None}, "bodies.A.core_young", "needs kind"),
        (
            {"core_young": 50.0, "core_poisson": 0.3, "viscoelastic": True, "relaxed_young": 5.0, "creep_time": 1.0},
            "bodies.A.core_young",
            "viscoelastic cover",
        ),
    ],
)
def test_bad_core_keys_are_one_line_errors(tmp_path, extra, key, why):
    body = {k: v for k, v in (COVER | extra).items() if v is not None}
    result = run_cli("solve", write_case(tmp_path, _case(body)), "-o", tmp_path / "out.h5")
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and key in lines[0] and why in lines[0], result.output


def _stressed(body: dict):
    data = _case(body)
    data["stresses"] = {"points": [41, 21], "depth": 2.0}  # down to 2 a ~ 4.7 < b = 5: the cover alone
    return solve(data).stresses["A"]


def test_stresses_in_the_cover_on_an_elastic_core():
    """Subsurface stresses of the cover (Somigliana on its boundary, the interface's tractions
    t = -K u): (1) a core 1e6 times stiffer gives the rigid core's field within the core's own
    compliance, bound 2e-6 times the torsion's geometry factor (~8 at bore 10; 1.6e-5, of the
    largest stress; measured 7e-7); (2) a core of the cover's material gives the homogeneous
    roller's field (another mesh): each BEM body's field is within 7e-4 p0 of Michell's near the
    surface (benchmarks/RESULTS.md, finite stresses) and the compliances within 1e-3, so bound
    5e-3 of the largest stress (measured 7e-4). The bond line is the interface (bond_depth = b)."""
    bore = {"inner_radius": 10.0}
    stiff = _stressed({**COVER, "core_young": 1e7, "core_poisson": 0.3, **bore})
    rigid = _stressed(COVER)
    same = _stressed({**COVER, "core_young": 10.0, "core_poisson": 0.45, **bore})
    homogeneous = {k: v for k, v in COVER.items() if k != "layer_thickness"} | {"kind": "elastic", **bore}
    whole = _stressed(homogeneous)
    factor = (1.0 / 10.0**2 - 1.0 / 20.0**2) / (1.0 / 20.0**2 - 1.0 / 25.0**2)  # r_i, r_c, R of COVER
    assert same.attributes["bond_depth"] == 5.0
    for name in ("sigma_xx", "sigma_zz", "tau_xz"):
        scale = np.abs(rigid.arrays[name]).max()
        assert np.abs(stiff.arrays[name] - rigid.arrays[name]).max() <= 2.0 * 1e-6 * factor * scale, name
        scale = np.abs(whole.arrays[name]).max()
        assert np.abs(same.arrays[name] - whole.arrays[name]).max() <= 5e-3 * scale, name


def test_graded_grid_with_tiny_elements():
    """An adaptive level's graded grid (elements down to 1e-5 of their neighbours beside a kink):
    the two-region path's rigid limit is still the rigid-core cover to round-off (bound 1e-10;
    the whole-system assembly replaces the own-node integrals by the rigid-body condition, as the
    mirror-half systems do: summing them in had left 3 % here), and a core 1e6 times stiffer within
    the core's compliance (bound as test_stiff_core_and_core_of_the_cover_material)."""
    uniform = np.linspace(-1.5, 1.5, 31)
    edges = np.sort(np.concatenate([uniform, [0.55 + 1e-5, 0.55 + 2e-5, 0.55 + 1e-3, 0.55 + 1e-2]]))
    grid = ContactGrid.graded(edges, 2)
    mesh = cylinder.annulus_mesh(grid, R, RC)
    ref = cylinder.xy_compliance(mesh, grid, E, NU, radius=R)
    assert np.abs(core.xy_compliance(mesh, E, NU, None) - ref).max() <= 1e-10 * np.abs(ref).max()
    stiff = core.condensed(grid, R, RC, RI, E, NU, 1e6 * E, 0.25)
    rigid = cylinder.condensed(grid, R, RC, E, NU)
    factor = (1.0 / RI**2 - 1.0 / RC**2) / (1.0 / RC**2 - 1.0 / R**2)
    assert _difference(stiff, rigid) <= 2.0 * 1e-6 * factor * _largest(rigid)
