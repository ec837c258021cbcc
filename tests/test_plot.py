"""rollc plot: figures checked through matplotlib's objects, not pixels."""

from pathlib import Path

import pytest
from click.testing import CliRunner

from helpers import case_dict, dissimilar, solve
from rolling_cli.case import load_case
from rolling_cli.cli import main
from rolling_cli.files.io_hdf5 import write_result
from rolling_cli.report.plot import plot_file
from rolling_cli.study import sweep

SMALL = case_dict(**{"discretization.contact_elements": 40})


def _labels(ax):
    return ax.get_xlabel() + " " + ax.get_ylabel()


def test_single_result_figure(tmp_path):
    path = tmp_path / "r.h5"
    write_result(solve(SMALL), path)
    png = tmp_path / "r.png"
    fig = plot_file(str(path), str(png))
    assert png.stat().st_size > 10_000
    main_ax, slip_ax = fig.axes
    assert "x" in main_ax.get_xlabel() and "/a" in main_ax.get_xlabel()
    assert r"\mu p_0" in main_ax.get_ylabel() and "p_n" in main_ax.get_ylabel()
    assert "slip velocity" in slip_ax.get_ylabel()
    labels = [line.get_label() for line in main_ax.get_lines()]
    assert any("p_t" in s for s in labels) and any("p_n" in s for s in labels)
    assert "Hertz" in labels and "Carter" in labels  # the similar case carries its references
    assert len(slip_ax.get_lines()) == 1
    assert len(main_ax.patches) >= 2  # shaded adhesion and slip bands


def test_dissimilar_result_has_no_reference_lines(tmp_path):
    path = tmp_path / "d.h5"
    write_result(solve(dissimilar(**{"discretization.contact_elements": 40})), path)
    fig = plot_file(str(path))
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "Carter" not in labels and len(labels) == 2


def test_sweep_figures(tmp_path):
    base = load_case(SMALL)
    mu_file = str(tmp_path / "mu.h5")
    sweep.run(base, sweep.spec_from_options(["friction.mu=0.1,0.2,0.3"], False), mu_file)
    fig = plot_file(mu_file, str(tmp_path / "mu.svg"))
    assert len(fig.axes) == 1 and len(fig.axes[0].get_lines()) == 3
    assert [t.get_text() for t in fig.axes[0].get_legend().get_texts()] == ["mu = 0.1", "mu = 0.2", "mu = 0.3"]
    curve_file = str(tmp_path / "curve.h5")
    sweep.run(base, sweep.curve_spec(base, "load", 5), curve_file)
    fig = plot_file(curve_file, str(tmp_path / "curve.pdf"))
    assert len(fig.axes) == 2
    assert "creepage" in fig.axes[1].get_xlabel() and "Q/(\\mu P)" in fig.axes[1].get_ylabel()
    assert len(fig.axes[1].get_lines()[0].get_xdata()) == 5
    assert (tmp_path / "curve.pdf").stat().st_size > 1000


def test_plot_cli_and_errors(tmp_path):
    path = tmp_path / "r.h5"
    write_result(solve(SMALL), path)
    runner = CliRunner()
    ok = runner.invoke(main, ["plot", str(path)])
    assert ok.exit_code == 0 and (tmp_path / "r.png").exists()
    bad_ext = runner.invoke(main, ["plot", str(path), "-o", str(tmp_path / "r.jpg")])
    assert bad_ext.exit_code == 2 and "unsupported figure format" in bad_ext.output
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    bad = runner.invoke(main, ["plot", str(junk)])
    assert bad.exit_code == 2 and "not a readable" in bad.output and "Traceback" not in bad.output


@pytest.mark.parametrize("name", ["paper_fig3_q051", "tyred_fig11_q41"])
def test_solve_plot_writes_figure_beside_result(tmp_path, name):
    out = tmp_path / f"{name}.h5"
    case = Path(__file__).resolve().parents[1] / "cases" / f"{name}.toml"
    result = CliRunner().invoke(main, ["-q", "solve", str(case), "-o", str(out), "--plot"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / f"{name}.png").stat().st_size > 10_000


@pytest.mark.parametrize("name", ["v1_result", "v1_sweep"])
def test_format_1_files_still_plot(tmp_path, name):
    """Files written before the current layout (one group per case) plot as before."""
    source = Path(__file__).parent / "data" / f"{name}.h5"
    fig = plot_file(str(source), str(tmp_path / f"{name}.png"))
    assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    if name == "v1_sweep":
        # Q/(mu P) swept, one case failed (gross sliding): two traction curves and the creep-force curve
        assert len(fig.axes) == 2 and len(fig.axes[0].get_lines()) == 2
        assert len(fig.axes[1].get_lines()[0].get_xdata()) == 2
    else:
        assert "Carter" in [line.get_label() for line in fig.axes[0].get_lines()]


def test_plot_refuses_to_replace_a_figure_unless_asked(tmp_path):
    path = tmp_path / "r.h5"
    write_result(solve(SMALL), path)
    figure = tmp_path / "r.png"
    figure.write_bytes(b"my own picture")
    runner = CliRunner()
    refused = runner.invoke(main, ["plot", str(path)])
    assert refused.exit_code == 2 and "exists; allowed: --overwrite" in refused.output
    assert figure.read_bytes() == b"my own picture"
    assert runner.invoke(main, ["plot", str(path), "--overwrite"]).exit_code == 0
    assert figure.read_bytes()[:4] == b"\x89PNG"


def test_branch_segments_split_at_the_slope_sign_and_find_the_turn():
    """Q(xi) = xi exp(-xi/x0) on xi in [-3 x0, 0]: dQ/dxi = (1 - xi/x0) exp(-xi/x0) > 0 everywhere
    there (unstable), and on [0, 3 x0]: zero at xi = x0 (the turn). The slope is interpolated
    linearly between the points around the sign change: its error is O(h^2 |s''/s'|) = O(h^2)/x0
    for spacing h = 3 x0 / 30 (1.2e-2 x0 at most; 0.02 x0 allowed)."""
    import numpy as np

    from rolling_cli.report.plot import branch_segments

    x0 = 2e-3
    xi = np.linspace(0.0, 3.0 * x0, 31)[::-1]  # any order
    q = xi * np.exp(-xi / x0)
    slope = (1.0 - xi / x0) * np.exp(-xi / x0)
    segments, turns = branch_segments(xi, q, slope)
    assert [stable for _, _, stable in segments] == [False, True]
    assert segments[0][0][-1] == segments[1][0][0]  # the runs share their boundary point
    assert sum(len(s[0]) for s in segments) == len(xi) + 1
    assert len(turns) == 1 and abs(turns[0][0] - x0) < 0.02 * x0
    assert turns[0][1] == pytest.approx(x0 / np.e, rel=1e-2)  # the nearer point's Q: O(h^2) below the peak
    coulomb, none = branch_segments(xi, q, np.full_like(xi, np.nan))  # no slope recorded: one stable run
    assert [s[2] for s in coulomb] == [True] and none == []


def test_falling_friction_curve_draws_its_unstable_branch_dashed(tmp_path):
    """A creep curve on the exponential law crosses the peak of |Q|: the plot has a solid (stable)
    and a dashed (unstable) run and one turning point on each side of xi = 0."""
    base = load_case("cases/falling_exponential.toml")
    import dataclasses

    base = dataclasses.replace(base, discretization=dataclasses.replace(base.discretization, contact_elements=60))
    path = str(tmp_path / "falling.h5")
    sweep.run(base, sweep.curve_spec(base, "creep", 13), path)
    fig = plot_file(path, str(tmp_path / "falling.png"))
    styles = {line.get_linestyle() for line in fig.axes[1].get_lines()}
    assert {"-", "--"} <= styles
    turns = [line for line in fig.axes[1].get_lines() if line.get_marker() == "D"]
    assert len(turns) == 1 and len(turns[0].get_xdata()) == 2
    assert turns[0].get_xdata()[0] < 0.0 < turns[0].get_xdata()[1]
