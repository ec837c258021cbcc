"""A sweep file being written or killed shows plain xarray only its complete rows, and a resumed
file ends with its rows in sweep order (issue 25, item 7).

The writer sizes the ``case`` and ``row`` dimensions to the committed rows (its capacity lives in
the chunks), so no padding row (``case = -1``) reaches a reader that does not know the
``cases_complete`` counter. xarray's default engine is netCDF-C when netCDF4 is installed: it is
read in a subprocess (a crash of netCDF-C fails the test instead of killing pytest).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from helpers import case_dict, solve, write_case
from rolling_cli.files.reader import cases_complete
from rolling_cli.files.rows import Row, row_from_result
from rolling_cli.files.writer import ResultFile

xr = pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")

SMALL = case_dict(**{"discretization.contact_elements": 40})
ATTRS = {"format": "rolling_cli.result", "format_version": 2}

#: Prints the case coordinate and the node count of every row that xarray's default engine shows.
DEFAULT_ENGINE = r"""
import json, sys
import xarray as xr
with xr.open_dataset(sys.argv[1]) as ds, xr.open_dataset(sys.argv[1], group="convergence") as conv:
    print(json.dumps([ds.case.values.tolist(), ds.nodes.values.tolist(), conv.case_index.values.tolist()]))
"""


def _plain(path) -> tuple[list, list, list]:
    """(case, nodes, history case_index) as the h5netcdf engine and the default engine show them;
    both must agree."""
    with (
        xr.open_dataset(path, engine="h5netcdf") as ds,
        xr.open_dataset(path, engine="h5netcdf", group="convergence") as c,
    ):
        seen = [ds.case.values.tolist(), ds.nodes.values.tolist(), c.case_index.values.tolist()]
    done = subprocess.run(
        [sys.executable, "-c", DEFAULT_ENGINE, str(path)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout) == seen
    return seen


def test_a_file_left_by_a_killed_writer_shows_only_its_committed_rows(tmp_path):
    """Commits of 3 then 2 rows into room for 40, never closed (what a kill leaves): xarray sees 5
    rows, the 5 cases, each with its nodes, and 5 histories; no padding row."""
    result = solve(SMALL)
    path = tmp_path / "killed.h5"
    writer = ResultFile(str(path), ATTRS, ("friction.mu",), total=40)
    for batch in ((0, 1, 2), (3, 4)):
        for i in batch:
            writer.add(row_from_result(result, i, {"friction.mu": 0.1 + 0.01 * i}))
        writer.commit()
    with h5py.File(path) as handle:  # the capacity is there (the chunks), only the extent is short
        assert cases_complete(handle) == 5 and handle["p_n"].chunks[0] > 5
    cases, nodes, history = _plain(path)
    n = len(result.history)
    assert cases == [0, 1, 2, 3, 4] and nodes == [result.x.size] * 5
    assert history == [k for k in range(5) for _ in range(n)]


def test_a_sweep_killed_mid_run_opens_in_plain_xarray_with_only_complete_rows(tmp_path):
    """SIGKILL (no handler runs, no trim): every row xarray shows is a solved case, in sweep order,
    at least the ``cases_complete`` the file counts."""
    case = write_case(tmp_path, SMALL)
    out = tmp_path / "s.h5"
    command = [sys.executable, "-m", "rolling_cli", "-q", "sweep", str(case), "--set", "friction.mu=0.01:1:3000"]
    proc = subprocess.Popen(
        [*command, "-o", str(out), "--workers", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    deadline = time.time() + 120
    try:
        while time.time() < deadline:
            time.sleep(0.3)
            try:
                with h5py.File(out, "r") as f:
                    if cases_complete(f) >= 1:
                        break
            except (OSError, KeyError):
                continue
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    with h5py.File(out, "r") as f:
        complete = cases_complete(f)
    cases, nodes, _ = _plain(out)
    assert 1 <= complete <= len(cases) < 3000
    assert cases == list(range(len(cases))) and min(nodes) > 0


def test_rows_end_in_sweep_order_after_a_resume(tmp_path):
    """An interrupted parallel run commits cases 0-2 and 5-6 (a later chunk had finished); the resume
    adds 3-4. Closed, the file holds 0..6 in order, every variable and history moved with its case."""
    result = solve(SMALL)
    path = str(tmp_path / "resumed.h5")
    n = len(result.history)

    def row(i):
        history = [{**entry, "residual": float(i)} for entry in result.history]  # each case's own marker
        base = row_from_result(result, i, {"friction.mu": 0.1 + 0.01 * i}, title=f"case {i}")
        return Row(i, base.coords, base.scalars, base.arrays, history, base.extras, base.units)

    attrs = {**ATTRS, "sweep_keys": json.dumps(["friction.mu"]), "cases_total": 7}  # what --resume reads back
    writer = ResultFile(path, attrs, ("friction.mu",), total=7)
    for i in (0, 1, 2, 5, 6):
        writer.add(row(i))
    writer.commit()  # the run is killed here: nothing more
    writer = ResultFile.open(path)
    for i in (3, 4):
        writer.add(row(i))
    writer.close()
    cases, _, history = _plain(path)
    assert cases == list(range(7)) and history == [k for k in range(7) for _ in range(n)]
    with (
        xr.open_dataset(path, engine="h5netcdf") as ds,
        xr.open_dataset(path, engine="h5netcdf", group="convergence") as c,
    ):
        assert list(ds.title.values) == [f"case {i}" for i in range(7)]
        assert np.allclose(ds.friction_mu.values, 0.1 + 0.01 * np.arange(7))
        assert list(c.residual.values) == [float(k) for k in range(7) for _ in range(n)]
        assert np.array_equal(ds.p_t.values, np.tile(result.p_t, (7, 1)))
    assert rolling_read(path, 4).title == "case 4"


def rolling_read(path, row):
    from rolling_cli import read_result

    return read_result(path, row=row)
