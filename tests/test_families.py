"""Families of creep-force curves (``rollc sweep --curve KIND --set ...``) and the sweep figure's
grouping of cases into one line per combination of the keys not on its x axis."""

import csv

import h5py
import numpy as np
import pytest

from helpers import case_dict, run_cli, write_case
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError
from rolling_cli.files.reader import case_table, read_case
from rolling_cli.references import carter
from rolling_cli.report.plot import plot_file
from rolling_cli.study import families, sweep

SMALL = case_dict(**{"discretization.contact_elements": 40})
MUS = (0.1, 0.3, 0.5)
POINTS = 41


@pytest.fixture(scope="module")
def family(tmp_path_factory):
    """A family of three creep curves of 41 points (one per mu), written by the CLI."""
    directory = tmp_path_factory.mktemp("family")
    out = directory / "family.h5"
    args = ("--curve", "creep", "--set", "friction.mu=0.1,0.3,0.5", "-o", out, "--workers", 1)
    result = run_cli("sweep", write_case(directory, SMALL), *args)
    assert result.exit_code == 0, result.output
    return out


def test_a_family_has_one_curve_per_value_each_at_its_mu(family):
    with h5py.File(family) as f:
        table = case_table(f)
        h = read_case(f, 0).x[1] - read_case(f, 0).x[0]  # the element length [length]
        a = float(read_case(f, 0).attributes["hertz_a"])  # the Hertz half-width [length]
    assert list(table["case"]) == list(range(3 * POINTS)) and table["converged"].all()
    for curve, mu in enumerate(MUS):
        rows = slice(curve * POINTS, (curve + 1) * POINTS)
        assert np.all(table["mu"][rows] == mu) and np.all(table["friction_mu"][rows] == mu)  # every case at its mu
        creep, q = table["tangential_creep"][rows], table["q_over_mu_p"][rows]
        assert np.array_equal(creep, table["creep"][rows])
        full = carter.full_slip_creepage(a, 50.0, mu)  # R* = 100 * 100 / 200 = 50
        # this curve's own range, +-1.5 times its full slip (to the 15 digits the values are rounded to)
        assert creep[0] == pytest.approx(-1.5 * full, rel=1e-12) and creep[-1] == pytest.approx(1.5 * full, rel=1e-12)
        assert np.all(np.diff(creep) > 0)
        # Q is monotone (non-increasing) in the creepage: the solver's residual tolerance 1e-10 allows that much
        # rounding on the plateaus of full slip
        assert np.all(np.diff(q) <= 1e-10)
        # Beyond full slip every node slides: |Q| = mu P (to the same tolerance)
        sliding = np.abs(creep) > full * (1 + h / a)
        assert sliding.sum() >= 10 and np.allclose(np.abs(q[sliding]), 1.0, rtol=0, atol=1e-10)
        # Inside, Carter's closed form: the slip-zone edge is placed to within one node spacing h, so the
        # creepage is within h/a of the full-slip creepage (d xi / d(c/a) = full; h/a = 2.5 %, measured 1.75 %)
        inside = np.abs(q) < 0.999
        reference = np.array([carter.creepage(v, a, 50.0, mu) for v in q[inside]])
        assert inside.sum() >= 20
        assert np.max(np.abs(np.abs(creep[inside]) - np.abs(reference))) <= full * h / a


def test_each_curve_is_warm_started_along_itself():
    """Chunks (the unit of warm starting) never cross from one curve into the next, for any length."""
    base = load_case(SMALL)
    spec = families.family_spec(base, "creep", 11, sweep.spec_from_options(["friction.mu=0.1,0.3,0.5"], False))
    chunks = list(sweep._todo(spec, np.zeros(spec.size, dtype=bool)))
    assert sum(len(c) for c in chunks) == 33
    for chunk in chunks:
        assert len({index // 11 for index, _ in chunk}) == 1
        assert len({combo["friction.mu"] for _, combo in chunk}) == 1


def test_the_family_figure_draws_one_labelled_line_per_curve(family, tmp_path):
    fig = plot_file(str(family), str(tmp_path / "f.png"))
    panel = fig.axes[-1]
    lines = [line for line in panel.lines if not line.get_label().startswith("_")]
    assert [line.get_label() for line in lines] == [f"friction.mu = {mu:g}" for mu in MUS]
    assert [len(line.get_xdata()) for line in lines] == [POINTS] * 3
    assert [t.get_text() for t in panel.get_legend().get_texts()] == [f"friction.mu = {mu:g}" for mu in MUS]


def test_the_family_exports_as_a_tidy_table(family, tmp_path):
    out = tmp_path / "family.csv"
    result = run_cli("export", family, "-o", out)
    assert result.exit_code == 0, result.output
    with open(out) as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 3 * POINTS
    assert list(rows[0])[:3] == ["case", "friction_mu", "tangential_creep"]
    assert [float(r["friction_mu"]) for r in rows] == [mu for mu in MUS for _ in range(POINTS)]


def test_a_two_key_sweep_figure_draws_one_line_per_group(tmp_path):
    """mu x Q/(mu P): the creep-force panel has one line per mu (three points each), not one zig-zag."""
    out = tmp_path / "p.h5"
    args = ("--set", "friction.mu=0.1,0.2", "--set", "tangential.q_over_mu_p=0.2,0.5,0.8", "-o", out)
    result = run_cli("sweep", write_case(tmp_path, SMALL), *args, "--workers", 1)
    assert result.exit_code == 0, result.output
    panel = plot_file(str(out)).axes[-1]
    lines = [line for line in panel.lines if not line.get_label().startswith("_")]
    assert [line.get_label() for line in lines] == ["friction.mu = 0.1", "friction.mu = 0.2"]
    assert [len(line.get_xdata()) for line in lines] == [3, 3]
    for line in lines:  # each line runs along its own group: increasing creepage, decreasing Q
        assert np.all(np.diff(line.get_xdata()) > 0)


@pytest.mark.parametrize(
    ("settings", "expected"),
    [
        (["tangential.creep=0.001,0.002"], "--curve creep --set tangential.creep: the curve sets"),
        (["tangential.q_over_p=0.01"], "--curve creep --set tangential.q_over_p: the curve sets"),
        (["friction.mu=0,0.2"], "--curve creep --set friction.mu: value 0.0: no creep-force curve without friction"),
    ],
)
def test_a_family_that_is_not_meaningful_is_refused_in_one_line(tmp_path, settings, expected):
    out = tmp_path / "bad.h5"
    args = [a for s in settings for a in ("--set", s)]
    result = run_cli("sweep", write_case(tmp_path, SMALL), "--curve", "creep", *args, "-o", out)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], result.output
    assert not out.exists()


def test_a_family_resumes_as_itself(family, tmp_path):
    """--resume compares the family (curve keys, values, kind and points) and finds nothing left to do."""
    spec = families.family_spec(
        load_case(SMALL), "creep", POINTS, sweep.spec_from_options(["friction.mu=0.1,0.3,0.5"], False)
    )
    copy = tmp_path / "copy.h5"
    copy.write_bytes(family.read_bytes())
    report = sweep.run(load_case(SMALL), spec, str(copy), resume=True)
    assert report.skipped == 3 * POINTS and report.solved == 0
    other = families.family_spec(load_case(SMALL), "creep", 21, spec.curves)
    with pytest.raises(CaseError, match="the values of tangential.creep differ"):
        sweep.run(load_case(SMALL), other, str(copy), resume=True)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--set", "friction.mu=0.1,0.2", "--points", "11"], "--points 11 without --curve"),
        (["--curve", "load", "--zip"], "--zip without --set"),
    ],
)
def test_options_that_would_be_dropped_are_refused(tmp_path, args, expected):
    result = run_cli("sweep", write_case(tmp_path, SMALL), *args, "-o", tmp_path / "x.h5")
    lines = result.output.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1 and lines[0].startswith("error: ") and expected in lines[0]


def test_a_family_of_load_curves_shares_the_load_values():
    """--curve load: Q/(mu P) from -0.99 to 0.99 on every curve, the curve keys constant along each."""
    base = load_case(SMALL)
    spec = families.family_spec(base, "load", 5, sweep.spec_from_options(["friction.mu=0.2,0.4"], False))
    combos = list(spec.combinations())
    assert spec.keys == ("friction.mu", "tangential.q_over_mu_p") and spec.size == 10
    assert [c["friction.mu"] for c in combos] == [0.2] * 5 + [0.4] * 5
    assert [c["tangential.q_over_mu_p"] for c in combos] == [-0.99, -0.495, 0.0, 0.495, 0.99] * 2
