"""The bodies' surface displacements in the result and ``rollc plot --deformed`` (issue 21 item 5).

Each check is against something independent of the stored displacements' route
(:mod:`rolling_cli.influence.surface`): the solver's own gap (the drawn surfaces of the two bodies
meet over the contact and are apart by the gap elsewhere), the closed-form displacement of a
Hertzian pressure (:mod:`rolling_cli.references.hertz_surface`) and the BEM body's full boundary
solution (no condensation) of a finite roller.
"""

import h5py
import numpy as np
import pytest
from click.testing import CliRunner

import rolling_cli
from rolling_cli import pipeline
from rolling_cli.case.io import case_from_dict, read_toml
from rolling_cli.cli import main
from rolling_cli.influence.build import boundary_solution
from rolling_cli.references import hertz_surface
from rolling_cli.report.plot_deformed import deformed_bodies

CASES = "cases"


def _hertz_case():
    """cases/carter.toml's body A (R = 100, steel) on a rigid flat, frictionless: Hertz."""
    data = read_toml(f"{CASES}/carter.toml")
    data["bodies"]["B"] = {"kind": "rigid", "radius": "inf"}
    data["friction"]["mu"] = 0.0
    del data["tangential"]
    return case_from_dict(data, None)


def _elastic_roller_case():
    """cases/rubber_roller_finite.toml made elastic (E = 30, nu = 0.49 cover on a rigid core, R = 25,
    a/R ~ 0.1) on 40 contact elements: a finite cylinder A on a rigid flat, rolling with traction."""
    data = read_toml(f"{CASES}/rubber_roller_finite.toml")
    for key in ("viscoelastic", "relaxed_young", "creep_time"):
        data["bodies"]["A"].pop(key)
    data["rolling"].pop("speed")
    data["discretization"]["contact_elements"] = 40
    return case_from_dict(data, None)


@pytest.fixture(scope="module")
def hertz_result():
    return rolling_cli.solve(_hertz_case())


@pytest.fixture(scope="module")
def carter_result():
    return rolling_cli.solve(rolling_cli.load_case(f"{CASES}/carter.toml"))


@pytest.fixture(scope="module")
def roller():
    case = _elastic_roller_case()
    return case, rolling_cli.solve(case)


def _drawn_gap(result):
    drawn, _ = deformed_bodies(result)
    return drawn[0].surface[1] - drawn[1].surface[1], drawn


@pytest.mark.parametrize("name", ["hertz_result", "carter_result", "roller"])
def test_drawn_surfaces_meet_over_the_contact_and_are_apart_by_the_gap(name, request):
    """The vertical distance of the drawn surfaces at each node is the solver's gap delta_n (from the
    pair compliance, not the bodies' own blocks): equal to rounding, 1e-12 of the displacement scale
    allowed (the sums of the bodies' blocks equal the pair's up to float addition; measured ~1e-14).
    Over the contact (p_n < 0) it vanishes to the solver's tolerance times a (1e-10 a on these cases
    solved to 1e-10; measured ~1e-16 of a). Covers two elastic half-planes with traction (Carter), a
    half-plane on a rigid flat (Hertz) and a finite cylinder on a flat (arc frame)."""
    found = request.getfixturevalue(name)
    result = found[1] if isinstance(found, tuple) else found
    gap, drawn = _drawn_gap(result)
    scale = max(float(np.abs(result.surface_w_A).max()), float(np.abs(result.delta_n).max()))
    assert np.abs(gap - result.delta_n).max() <= 1e-12 * scale
    contact = result.p_n < 0.0
    assert contact.sum() >= 10
    assert np.abs(gap[contact]).max() <= 1e-10 * result.contact_half_width
    assert (gap[~contact] > 0.0).all()  # apart outside (a zero gap there would be a contact node)


def test_hertz_surface_equals_the_closed_form(hertz_result):
    """The stored w of body A (the rigid flat B has none) equals the half-plane's displacement
    under Hertz's pressure at the solved load, relative to the centre (the log kernel's datum drops
    out): within 1e-4 of its largest value over the zone (1.5 a). The solved pressure differs from
    Hertz's by the discretisation (200 quadratic elements, the square-root edge): measured 1.3e-5;
    a wrong kernel constant, sign or frame is an O(1) error."""
    r = hertz_result
    assert r.surface_w_B is None and r.surface_u_B is None
    centre = int(np.argmin(np.abs(r.x)))
    reference = hertz_surface.relative_displacement(r.x, r.hertz_a, r.hertz_p0, 210000.0, 0.3)
    w = r.surface_w_A - r.surface_w_A[centre]
    assert np.abs(w - reference).max() <= 1e-4 * np.abs(reference).max()


def test_finite_roller_displacements_equal_the_bem_boundary_solution(roller):
    """A finite cylinder's stored (w, u) on its arc equal the BEM annulus solved in full for the
    solved tractions (every boundary value, :func:`boundary_solution`), projected on the arc's
    inward normal and tangent: the condensation is exact algebra, so only rounding of the two
    factorisations differs; 1e-7 of max |w| allowed (measured 4e-9)."""
    case, r = roller
    the_plan = pipeline.plan(case, half_width=r.mesh_half_width)
    mesh, u, _ = boundary_solution(case, the_plan, "A", r.p_n, r.p_t)
    theta = r.x / float(case.bodies.A.radius)
    outward = np.column_stack([np.sin(theta), np.cos(theta)])  # block frame: body below, centre (0, -R)
    tangent = np.column_stack([np.cos(theta), -np.sin(theta)])
    contact = u[mesh.contact]
    w_ref, u_ref = -(contact * outward).sum(axis=1), (contact * tangent).sum(axis=1)
    scale = np.abs(w_ref).max()
    assert np.abs(r.surface_w_A - w_ref).max() <= 1e-7 * scale
    assert np.abs(r.surface_u_A - u_ref).max() <= 1e-7 * scale


def test_plot_deformed_writes_the_figure_and_refuses_an_old_file(tmp_path, carter_result):
    """``rollc plot FILE --deformed`` writes NAME_deformed.png (exit 0); a file without the
    displacements (an older rollc's: the variables removed) gets one line naming the file, exit 2."""
    path = tmp_path / "carter.h5"
    rolling_cli.write_result(carter_result, str(path))
    runner = CliRunner()
    done = runner.invoke(main, ["plot", str(path), "--deformed", "--magnify", "2"])
    assert done.exit_code == 0, done.output
    assert (tmp_path / "carter_deformed.png").stat().st_size > 0
    with h5py.File(path, "a") as handle:
        for name in ("surface_w_A", "surface_u_A", "surface_w_B", "surface_u_B"):
            del handle[name]
    old = runner.invoke(main, ["plot", str(path), "--deformed", "-o", str(tmp_path / "old.png")])
    assert old.exit_code == 2
    lines = old.output.strip().splitlines()
    assert len(lines) == 1 and "no surface displacements" in lines[0] and "carter.h5" in lines[0]
    assert not (tmp_path / "old.png").exists()


@pytest.mark.parametrize("name", ["carter", "dissimilar_q75"])
def test_closed_form_bodies_from_the_pair_equal_each_body_integrated(name):
    """Elastic half-planes take their blocks from the solved pair's, scaled (no kernel integrated
    again): equal to each body's own closed form integrated as a pair with a rigid counterpart, to
    rounding (1e-12 of max |w|; measured ~1e-15), with the coupling off (similar materials) and on
    (aluminium on steel: the cross kernel then comes from the pair's S_nt / (c_A - c_B))."""
    from rolling_cli.influence.surface import body_displacements
    from rolling_cli.pipeline.planning import build_contact_system

    case = rolling_cli.load_case(f"{CASES}/{name}.toml")
    r = rolling_cli.solve(case)
    the_plan = pipeline.plan(case, half_width=r.mesh_half_width)
    system = build_contact_system(case, the_plan)
    fast = body_displacements(case, the_plan, r.p_n, r.p_t, system)
    integrated = body_displacements(case, the_plan, r.p_n, r.p_t)
    assert set(fast) == set(integrated) == {"A", "B"}
    for label, (w, u) in integrated.items():
        scale = np.abs(w).max()
        assert np.abs(fast[label][0] - w).max() <= 1e-12 * scale
        assert np.abs(fast[label][1] - u).max() <= 1e-12 * scale


def test_a_sweep_file_leaves_the_displacements_out(tmp_path):
    """A sweep's rows leave out the four surface variables (``--deformed`` draws single results:
    four more node arrays per case would grow a sweep file by about half for nothing it can plot);
    ``rollc plot SWEEP --deformed`` says it needs a single result, exit 2."""
    out = tmp_path / "study.h5"
    runner = CliRunner()
    done = runner.invoke(main, ["-q", "sweep", f"{CASES}/carter.toml", "--set", "friction.mu=0.1,0.2", "-o", str(out)])
    assert done.exit_code == 0, done.output
    with h5py.File(out, "r") as handle:
        assert "p_n" in handle and not any(name.startswith("surface_") for name in handle)
    refused = runner.invoke(main, ["plot", str(out), "--deformed"])
    assert refused.exit_code == 2 and "single result" in refused.output
