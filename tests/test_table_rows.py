"""Two-axis tables on the sweep machinery (issue 24 item 2): rows in worker processes, a journal, --resume.

rolling_cli/study/table_rows.py. References: the serial build itself (worker processes and a
resumed run must give its table bit for bit: every row is solved alike wherever it runs, starting
cold and warm-starting only along itself, with one BLAS thread), and the count of rows solved.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from helpers import dissimilar, run_cli, write_case
from rolling_cli import table
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError
from rolling_cli.study import table_rows, tabulate

#: Aluminium on steel at 40 elements, mu 0.1 .. 0.2, tolerance 0.02: a few rows (~1 s serially).
DATA = dissimilar(**{"discretization.contact_elements": 40})
REQUEST = (-1.0, 1.0, 0.1, 0.2, 0.02)


def _same(a, b) -> None:
    assert len(a.rows) == len(b.rows)
    for x, y in zip(a.rows, b.rows, strict=True):
        assert x.mu == y.mu
        for name in ("nodes", "values", "slopes", "mu_slopes"):
            assert np.array_equal(getattr(x, name), getattr(y, name)), name
    assert a.error_bound == b.error_bound and np.array_equal(a.friction_error, b.friction_error)


@pytest.fixture(scope="module")
def serial_table():
    return tabulate.build_friction(load_case(DATA), *REQUEST)[0]


def test_workers_compute_the_serial_table(serial_table):
    """Two worker processes: the same rows, values and estimates as the serial build."""
    made, _ = tabulate.build_friction(load_case(DATA), *REQUEST, workers=2)
    assert len(made.rows) >= 3
    _same(made, serial_table)
    assert made.attributes["cases"] == serial_table.attributes["cases"]


def test_a_dask_cluster_computes_the_serial_table(serial_table):
    """The rows on a two-worker local Dask cluster (--scheduler local:2): the serial table bit for bit."""
    pytest.importorskip("distributed")
    made, _ = tabulate.build_friction(load_case(DATA), *REQUEST, scheduler="local:2")
    _same(made, serial_table)
    assert made.attributes["cases"] == serial_table.attributes["cases"]


def test_scheduler_needs_the_mu_axis(tmp_path):
    """--scheduler distributes the rows of --mu: with one axis, or with --workers, a one-line refusal."""
    case = write_case(tmp_path, DATA)
    result = run_cli("table", case, "-o", tmp_path / "t.h5", "--scheduler", "local:2")
    assert result.exit_code == 2 and "allowed: --scheduler with --mu" in result.output
    assert result.output.count("\n") == 1 and not (tmp_path / "t.h5").exists()


def test_resume_solves_only_the_missing_rows(serial_table, tmp_path, monkeypatch):
    """A journal cut after its first two rows (an interrupted run): the resumed build takes those two
    from it, solves the others (counted), and gives the serial table."""
    case = load_case(DATA)
    path = str(tmp_path / "t.h5.rows")
    head = table_rows.header(case, *REQUEST, tabulate.INITIAL)
    journal = table_rows.Journal(path, head, resume=False)
    tabulate.build_friction(case, *REQUEST, journal=journal)
    journal.close()
    with open(path, encoding="utf-8") as handle:
        lines = handle.readlines()
    rows_in_all = len(lines) - 1
    with open(path, "w", encoding="utf-8") as handle:
        handle.writelines(lines[:3])
    solved = []
    original = tabulate._row

    def counted(*args):
        solved.append(args[3])
        return original(*args)

    monkeypatch.setattr(tabulate, "_row", counted)
    resumed = table_rows.Journal(path, head, resume=True)
    assert len(resumed.done) == 2
    made, _ = tabulate.build_friction(case, *REQUEST, journal=resumed)
    resumed.close(remove=True)
    assert len(solved) == rows_in_all - 2
    assert not set(solved) & {json.loads(line)["mu"] for line in lines[1:3]}
    _same(made, serial_table)


def test_resume_refuses_another_request(tmp_path):
    """A journal written for another tolerance is refused with one line naming --resume."""
    case = load_case(DATA)
    path = str(tmp_path / "t.h5.rows")
    table_rows.Journal(path, table_rows.header(case, *REQUEST, tabulate.INITIAL), resume=False).close()
    other = table_rows.header(case, *REQUEST[:4], 0.01, tabulate.INITIAL)
    with pytest.raises(CaseError, match="--resume refused"):
        table_rows.Journal(path, other, resume=True)


def test_cli_workers_and_resume(tmp_path, serial_table):
    """``rollc table --mu --workers 2`` writes the serial table and removes its journal; a journal left
    by an interrupted run is refused without --resume (exit 2), continued with it."""
    case = write_case(tmp_path, DATA)
    out = tmp_path / "t.h5"
    options = ("--mu", "0.1:0.2", "--tolerance", "0.02")
    result = run_cli("table", case, "-o", out, *options, "--workers", "2")
    assert result.exit_code == 0, result.output
    _same(table.load(str(out)), serial_table)
    assert not (tmp_path / "t.h5.rows").exists()
    out2 = tmp_path / "u.h5"
    head = table_rows.header(load_case(case), *REQUEST, tabulate.INITIAL)
    table_rows.Journal(str(out2) + ".rows", head, resume=False).close()
    refused = run_cli("table", case, "-o", out2, *options)
    assert refused.exit_code == 2 and "--resume" in refused.output
    resumed = run_cli("table", case, "-o", out2, *options, "--resume")
    assert resumed.exit_code == 0, resumed.output
    _same(table.load(str(out2)), serial_table)


def test_dissimilar_table_reproduces_direct_solves(serial_table):
    """The coupled pair's two-axis table (its kinks in mu are what the quarter-point tests are for)
    meets its estimate, and reproduces direct creepage-controlled solves at 12 random (u, mu) within
    its tolerance 0.02 (the requirement itself)."""
    import dataclasses

    from rolling_cli import pipeline

    assert serial_table.attributes["met"] and serial_table.error_bound <= 0.02
    case = load_case(DATA)
    the_plan, system = pipeline.prepare(case)
    rng = np.random.default_rng(3)
    for u, mu in zip(rng.uniform(-1.0, 1.0, 12), rng.uniform(0.1, 0.2, 12), strict=True):
        creep = float(u * mu * the_plan.half_width / the_plan.radius)
        point = dataclasses.replace(
            case,
            friction=dataclasses.replace(case.friction, mu=float(mu)),
            tangential=type(case.tangential)(creep=creep),
        )
        direct = pipeline.solve(point, system=system).q_over_mu_p
        assert abs(float(serial_table(u, mu)) - direct) <= 0.02, (u, mu)
