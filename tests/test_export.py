"""rollc export (tables for spreadsheets and multibody codes) and rolling_cli.open_result."""

import csv
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import rolling_cli
from helpers import case_dict, run_cli, solve, write_case
from rolling_cli.case import load_case
from rolling_cli.files.io_hdf5 import write_result
from rolling_cli.files.reader import case_table, cases_complete
from rolling_cli.files.rows import row_from_result
from rolling_cli.files.writer import ResultFile
from rolling_cli.study import sweep

DATA = Path(__file__).parent / "data"
SMALL = case_dict(**{"discretization.contact_elements": 40})


def _rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def _number(cell):
    return float("nan") if cell == "" else float(cell)


def test_summary_and_fields_tables_hold_the_files_values(tmp_path):
    study = tmp_path / "study.h5"
    spec = sweep.spec_from_options(["solver.max_iterations=100,1,100"], False)  # case 1 fails in the run
    sweep.run(load_case(SMALL), spec, study, warm=False)
    result = run_cli("export", study, "--fields")
    assert result.exit_code == 0, result.output
    assert f"written {tmp_path / 'study.csv'}" in result.output
    rows = _rows(tmp_path / "study.csv")
    header = list(rows[0])
    assert header[:5] == ["case", "solver_max_iterations", "converged", "q_over_mu_p", "creep"]
    with h5py.File(study) as f:
        table = case_table(f)
        assert len(rows) == cases_complete(f) == 3
        for name in ("q_over_mu_p", "creep", "normal_load", "tangential_load", "residual"):
            stored = table[name]
            cells = np.array([_number(row[name]) for row in rows])
            assert np.array_equal(cells, stored, equal_nan=True), name  # full precision: exact round trip
        assert [row["converged"] for row in rows] == ["true", "false", "true"]
        assert rows[1]["message"].startswith("sweep case (solver.max_iterations = 1): ")
        fields = _rows(tmp_path / "study_fields.csv")
        nodes = f["nodes"][()]
        assert len(fields) == nodes.sum() and nodes[1] == 0  # the failed case has no nodes
        last = [row for row in fields if row["case"] == "2"]
        assert np.array_equal([float(row["p_t"]) for row in last], f["p_t"][2, : nodes[2]])
        assert np.array_equal([float(row["x"]) for row in last], f["x"][: nodes[2]])
        assert {row["state"] for row in last} <= {"0", "1", "2"}


def test_creep_force_curve_table(tmp_path):
    study = tmp_path / "curve.h5"
    base = load_case(SMALL)
    sweep.run(base, sweep.curve_spec(base, "creep", 5), study)
    out = tmp_path / "curve_table.csv"
    assert run_cli("export", study, "-o", out).exit_code == 0
    rows = _rows(out)
    assert list(rows[0])[:6] == ["case", "tangential_creep", "converged", "q_over_mu_p", "creep", "normal_load"]
    creep = [float(row["creep"]) for row in rows]
    q = [float(row["q_over_mu_p"]) for row in rows]
    assert creep == [
        float(row["tangential_creep"]) for row in rows
    ]  # creep control: the solved creepage is the set one
    assert q[0] == pytest.approx(1.0) and q[-1] == pytest.approx(-1.0)  # 1.5x full slip saturates: |Q| = mu P
    assert np.all(np.diff(q) <= 0)
    again = run_cli("export", study, "-o", out)
    assert again.exit_code == 2 and "exists; allowed: --overwrite" in again.output


def test_export_of_a_format_1_sweep(tmp_path):
    out = tmp_path / "old.csv"
    assert run_cli("export", DATA / "v1_sweep.h5", "-o", out).exit_code == 0
    rows = _rows(out)
    assert [row["tangential_q_over_mu_p"] for row in rows] == ["0.3", "1.2", "0.8"]
    assert [row["converged"] for row in rows] == ["true", "false", "true"]


def test_open_result_gives_the_trusted_rows_as_a_dataset(tmp_path):
    xr = pytest.importorskip("xarray")
    result = solve(SMALL)
    path = str(tmp_path / "open.h5")
    writer = ResultFile(path, {"format": "rolling_cli.result", "format_version": 2}, total=100)
    for i in range(3):
        writer.add(row_from_result(result, i))
    writer.commit()  # as a running sweep leaves it: room for more rows than are complete
    raw = xr.open_dataset(path)
    assert raw.sizes["case"] == 3 and raw.attrs["cases_complete"] == 3  # room for 100 in the chunks, none shown
    ds = rolling_cli.open_result(path)
    assert ds.sizes["case"] == 3 and np.array_equal(ds.p_t.values[2], result.p_t)
    old = rolling_cli.open_result(DATA / "v1_sweep.h5")
    assert isinstance(old, xr.Dataset) and list(old.converged.values) == [True, False, True]


def test_open_result_without_xarray_gives_results(tmp_path, monkeypatch):
    result = solve(SMALL)
    path = tmp_path / "r.h5"
    write_result(result, path)
    monkeypatch.setitem(sys.modules, "xarray", None)  # import xarray now fails
    back = rolling_cli.open_result(path)
    assert isinstance(back, rolling_cli.Result) and np.array_equal(back.p_t, result.p_t)
    cases = rolling_cli.open_result(DATA / "v1_sweep.h5")
    assert [c.converged for c in cases] == [True, False, True]


def test_export_errors_are_one_line(tmp_path):
    junk = tmp_path / "junk.h5"
    junk.write_text("not hdf5")
    result = run_cli("export", junk)
    assert result.exit_code == 2 and "not a readable rolling_cli result" in result.output
    case = write_case(tmp_path, SMALL)
    same = run_cli("export", DATA / "v1_result.h5", "-o", case, "--overwrite")
    assert same.exit_code == 0  # a CSV may replace a file when asked, but never an input:
    refused = run_cli("export", DATA / "v1_result.h5", "-o", DATA / "v1_result.h5", "--overwrite")
    assert refused.exit_code == 2 and "an input of this command" in refused.output
