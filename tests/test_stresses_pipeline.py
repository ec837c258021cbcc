"""The [stresses] table, the result file's stresses group, summary, sweeps, plots and the frictional power."""

import json
import subprocess
import sys

import h5py
import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, run_cli, write_case
from rolling_cli import pipeline, read_result, write_result
from rolling_cli.case import case_to_toml, load_case
from rolling_cli.errors import CaseError
from rolling_cli.stresses import compute

SMALL = {"points": [41, 21], "depth": 2.0}


def _case(**dotted):
    return case_dict(**{"discretization.contact_elements": 60, **dotted})


def test_the_table_is_optional_and_its_defaults_are_the_documented_ones(tmp_path):
    assert load_case(_case()).stresses is None
    table = load_case(_case(stresses={})).stresses
    assert (table.depth, table.points, table.bodies) == (3.0, (201, 101), ("A", "B"))
    # the resolved case keeps the table, with its defaults, and only when given
    again = load_case(write_case(tmp_path, {"title": "x"} | _read_toml(case_to_toml(load_case(_case(stresses={}))))))
    assert again.stresses == table
    assert "stresses" not in case_to_toml(load_case(_case()))


def _read_toml(text):
    import tomllib

    return tomllib.loads(text)


@pytest.mark.parametrize(
    "key, value, allowed",
    [
        ("points", [201], "[nx, nz]"),
        ("points", [2, 101], "[nx, nz]"),
        ("points", [201, 1.5], "[nx, nz]"),
        ("points", [4001, 4001], "nx nz <= 4000000"),
        ("bodies", ["C"], '["A", "B"]'),
        ("bodies", [], '["A", "B"]'),
        ("bodies", ["A", "A"], '["A", "B"]'),
        ("depth", -1.0, "> 0"),
        ("depth", 500.0, "<= 100"),
        ("deep", 1.0, "keys depth, points, bodies"),
    ],
)
def test_bad_values_are_one_line_errors_naming_file_key_value_and_what_is_allowed(tmp_path, key, value, allowed):
    path = write_case(tmp_path, _case(stresses={key: value}))
    with pytest.raises(CaseError) as err:
        load_case(path)
    message = str(err.value)
    assert "\n" not in message and str(path) in message and f"stresses.{key}" in message and allowed in message
    result = run_cli("check", path)
    assert result.exit_code == 2 and f"stresses.{key}" in result.output


def test_without_the_table_nothing_runs_and_nothing_is_imported(tmp_path):
    """The effects note says so, the result has no stresses, and the stress machinery is never imported."""
    path = write_case(tmp_path, _case())
    script = (
        "import sys, rolling_cli, json\n"
        f"r = rolling_cli.solve({str(path)!r})\n"
        f"rolling_cli.write_result(r, {str(tmp_path / 'r.h5')!r})\n"
        "from rolling_cli.report.summary import summary; summary(r)\n"
        "print(json.dumps([m for m in sys.modules if m.startswith('rolling_cli.stresses')]))\n"
        "print(json.loads(r.effects)['notes']['stresses'])\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout.splitlines()
    assert json.loads(out[0]) == ["rolling_cli.stresses", "rolling_cli.stresses.power"]
    assert out[1] == "skipped: not requested (no [stresses] table)"
    result = read_result(tmp_path / "r.h5")
    assert result.stresses == {} and "stress_bodies" not in result.attributes
    with h5py.File(tmp_path / "r.h5") as handle:
        assert "stresses" not in handle


def test_result_file_layout_read_back_and_summary(tmp_path):
    """stresses/A and stresses/B: coordinates x, z (z >= 0, the case's length unit), (z, x) fields with units
    and long_name; the maxima as attributes (per body and over both, with x/a, z/a and the body); the
    summary lines; everything read back equal."""
    result = pipeline.solve(load_case(_case(stresses=SMALL)))
    path = tmp_path / "r.h5"
    write_result(result, path)
    fields = ("sigma_xx", "sigma_zz", "tau_xz", "sigma_yy", "von_mises", "tresca", "sigma_1", "sigma_2", "sigma_3")
    with h5py.File(path) as handle:
        # one layout for results and sweeps: /stresses/case_000000/A; a single result also links stresses/A to it
        assert sorted(handle["stresses"]) == ["A", "B", "case_000000"]
        assert handle["stresses/A"] == handle["stresses/case_000000/A"]
        for label in "AB":
            group = handle["stresses"][label]
            assert group["x"].shape == (41,) and group["z"].shape == (21,)
            assert group["z"][0] == 0.0 and group["z"][-1] == pytest.approx(2.0 * result.mesh_half_width)
            assert group["x"].attrs["units"] == "mm" and group["sigma_xx"].attrs["units"] == "N/mm^2"
            for name in fields:
                assert group[name].shape == (21, 41) and group[name].attrs["long_name"]
                assert [d[0].name.split("/")[-1] for d in group[name].dims] == ["z", "x"]
            assert group["tau_xz_range"].shape == (21,)
            assert group.attrs["model"] == "half-plane" and group.attrs["body"] == label
            assert "+p_t on body B" in group["tau_xz"].attrs["long_name"]
    back = read_result(path)
    for label in "AB":
        for name, values in result.stresses[label].arrays.items():
            assert np.array_equal(back.stresses[label].arrays[name], values), name
        assert back.stresses[label].attributes == pytest.approx(result.stresses[label].attributes, nan_ok=True)
    attrs = result.attributes
    a = result.mesh_half_width
    for name in ("von_mises", "tresca", "tau_xz_range", "sigma_1", "surface_tension"):
        body = result.stresses[attrs[f"stress_max_{name}_body"]]
        assert attrs[f"stress_max_{name}"] == max(result.stresses[b].attributes[f"max_{name}"] for b in "AB")
        assert attrs[f"stress_max_{name}_z_over_a"] * a == body.attributes[f"max_{name}_z"]
    vm = result.stresses["A"].arrays["von_mises"]
    iz, ix = np.unravel_index(vm.argmax(), vm.shape)
    assert result.stresses["A"].attributes["max_von_mises"] == vm.max()
    assert result.stresses["A"].attributes["max_von_mises_x"] == result.stresses["A"].arrays["x"][ix]
    assert attrs["stress_max_tau_xz_range"] == max(
        np.ptp(result.stresses[b].arrays["tau_xz"], axis=1).max() for b in "AB"
    )
    notes = json.loads(attrs["effects"])["notes"]
    assert notes["stresses"] == "simulated: A (half-plane), B (half-plane), 41 x 21 points"
    from rolling_cli.report.summary import summary

    text = summary(back, str(path))
    for label in ("von Mises", "Tresca", "orth. shear", "surface sxx", "friction power", "stresses"):
        assert label in text


def test_rigid_bodies_are_skipped_and_a_failed_solve_gets_none(tmp_path):
    data = _case(
        **{"bodies.A": {"kind": "rigid", "radius": 100.0}, "discretization.influence": "half-plane"}, stresses=SMALL
    )
    result = pipeline.solve(load_case(data))
    assert list(result.stresses) == ["B"]
    assert json.loads(result.effects)["notes"]["stresses"].endswith("A skipped (rigid: no stress field)")
    failed = pipeline.solve(load_case(case_dict(data, **{"solver.max_iterations": 1})), keep_failed=True)
    assert not failed.converged and failed.stresses == {}
    assert json.loads(failed.effects)["notes"]["stresses"] == "skipped: the solve did not converge"
    assert "stresses: skipped: the solve did not converge" in failed.effects_line


def test_a_layered_body_through_the_pipeline_and_the_cli(tmp_path):
    """A rigid cylinder on a layer (BEM): the layer's field down to its bond line, the bond-line stresses
    in the file, the summary, and the contour plot."""
    layer = {"kind": "layered", "radius": 100.0, "young": 10.0, "poisson": 0.3, "layer_thickness": 0.1}
    data = case_dict(
        **{
            "bodies.A": {"kind": "rigid", "radius": 100.0},
            "bodies.B": layer,
            "discretization.influence": "bem",
            "discretization.contact_elements": 60,
            "normal.overlap": 0.004,
            "tangential.q_over_mu_p": 0.4,
        },
        stresses={"points": [41, 11]},
    )
    path = write_case(tmp_path, data)
    out = tmp_path / "layer.h5"
    run = run_cli("solve", path, "-o", out)
    assert run.exit_code == 0, run.output
    assert "bond |txz|" in run.output and "bond szz" in run.output
    result = read_result(out)
    assert_contact_laws(result)
    arrays = result.stresses["B"].arrays
    assert arrays["z"][-1] == 0.1 and result.stresses["B"].attributes["model"] == "BEM layer"
    assert arrays["bond_weights"] @ arrays["bond_tau_xz"] == pytest.approx(result.tangential_load, rel=1e-5)
    assert arrays["bond_weights"] @ arrays["bond_sigma_zz"] == pytest.approx(-result.normal_load, rel=1e-5)
    plotted = run_cli("plot", out, "--stresses")
    assert plotted.exit_code == 0 and (tmp_path / "layer_stresses.png").stat().st_size > 10_000


def test_plot_option_errors_are_one_line_exit_2(tmp_path):
    out = tmp_path / "plain.h5"
    write_result(pipeline.solve(load_case(_case())), out)
    result = run_cli("plot", out, "--stresses")
    assert result.exit_code == 2 and "no stresses" in result.output and "[stresses]" in result.output


def test_sweeps_carry_the_per_case_maxima(tmp_path):
    from rolling_cli.study import sweep

    base = load_case(_case(stresses=SMALL))
    spec = sweep.spec_from_options(["tangential.q_over_mu_p=0.2,0.6"], False)
    out = tmp_path / "s.h5"
    report = sweep.run(base, spec, str(out), workers=1)
    assert not report.failed
    with h5py.File(out) as handle:  # the per-case maxima are (case) variables; the fields per case
        for name in ("stress_max_von_mises", "stress_max_tresca", "stress_max_tau_xz_range", "frictional_power_total"):
            assert handle[name].shape == (2,) and np.all(np.isfinite(handle[name][()]))
        for k in range(2):
            assert f"stresses/case_{k:06d}/A/von_mises" in handle
            assert handle["stress_max_von_mises"][k] == read_result(out, row=k).stress_max_von_mises


def test_grid_sequencing_and_error_estimates_do_not_compute_stresses_twice(monkeypatch):
    calls = []
    original = compute.compute_stresses

    def counting(case, the_plan, p_n, p_t, kinks=None):
        calls.append(the_plan.grid.elements)
        return original(case, the_plan, p_n, p_t, kinks)

    monkeypatch.setattr(compute, "compute_stresses", counting)
    aluminium = {"kind": "elastic", "radius": 100.0, "young": 60260.0, "poisson": 0.31}
    case = load_case(_case(**{"bodies.A": aluminium, "discretization.contact_elements": 240}, stresses=SMALL))
    result = pipeline.solve(case)  # coupled, >= 240 elements: starts from a solve on 60 elements
    assert any(row.get("level") == "coarse grid" for row in result.history)
    from rolling_cli.pipeline.estimate import add_error_estimate

    add_error_estimate(case, result)
    assert calls == [240]


def test_frictional_power_is_zero_in_adhesion_and_mu_pn_st_in_slip():
    """Every result carries d = -p_t s_t per node (per unit rolling speed) and its integral. On slip nodes
    d = mu |p_n| |s_t| to the contact laws' tolerance (|p_t| = mu |p_n| within 2 f, the slip against the
    traction within f / r_t, f = tolerance x traction scale), exactly 0 on adhesion and separation nodes."""
    result = pipeline.solve(load_case(_case()))
    assert_contact_laws(result)
    d, state = result.frictional_power, result.state
    assert np.all(d[state != 2] == 0.0) and np.any(state == 1) and np.any(state == 2)
    slip = state == 2
    f = 1e-10 * result.traction_scale
    s, p_t, p_n = result.s_t[slip], result.p_t[slip], result.p_n[slip]
    bound = 2 * f * np.abs(s) + f / result.reference_penalty_t * np.abs(p_t)
    assert np.all(np.abs(d[slip] - result.mu * np.abs(p_n) * np.abs(s)) <= bound)
    assert np.all(d >= -bound.max())
    assert result.frictional_power_total == pytest.approx(result.weights @ d, rel=1e-14)


def test_frictional_power_balances_the_creep_force_power_at_first_order():
    """Steady rolling of similar bodies: the dissipation equals the creep-force power -Q xi (per unit speed;
    the elastic part of the slip does no net work, int q H[q] = 0). Against Carter's exact creepage the
    discrete dissipation converges at first order (the upwind slip derivative): doubling the elements halves
    the error (within 10 %), and Richardson's extrapolation removes 90 % of it."""
    errors = []
    for elements in (100, 200):
        result = pipeline.solve(load_case(case_dict(**{"discretization.contact_elements": elements})))
        exact = -result.tangential_load * result.carter_creep
        errors.append(result.frictional_power_total - exact)
    assert abs(errors[1]) <= 0.55 * abs(errors[0])
    assert abs(2 * errors[1] - errors[0]) <= 0.1 * abs(errors[1])


def test_the_shipped_case_and_the_readme_commands(tmp_path, monkeypatch):
    """`rollc solve cases/carter_stresses.toml` then `rollc plot carter_stresses.h5 --stresses` (README)."""
    from pathlib import Path

    monkeypatch.chdir(tmp_path)
    case = Path(__file__).resolve().parents[1] / "cases" / "carter_stresses.toml"
    solved = run_cli("solve", case)
    assert solved.exit_code == 0, solved.output
    for line in ("friction power", "von Mises      max 0.56", "orth. shear    range 0.50", "(body A)"):
        assert line in solved.output
    plotted = run_cli("plot", "carter_stresses.h5", "--stresses")
    assert plotted.exit_code == 0 and (tmp_path / "carter_stresses_stresses.png").stat().st_size > 10_000
