"""rollc sweep: parameter studies, lazy ranges, reuse, parallel equality, resume and its identity
check, failures, interruption."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from helpers import CARTER, case_dict, run_cli, without_timings, write_case
from rolling_cli.case import load_case
from rolling_cli.errors import CaseError
from rolling_cli.files.reader import case_table, cases_complete
from rolling_cli.study import sweep

CASES = Path(__file__).resolve().parents[1] / "cases"
SMALL = case_dict(**{"discretization.contact_elements": 40})

_write = write_case
_run = run_cli


def _table(path):
    with h5py.File(path) as f:
        return case_table(f)


def _same_sweep(a, b):
    """Two sweep files hold the same cases with bitwise equal values, in any row order (wall times and the
    provenance of the run aside: ``created``, ``history``)."""
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(a) as x, xr.open_dataset(b) as y:
        x, y = (without_timings(d.sortby("case")) for d in (x, y))
        for d in (x, y):
            d.attrs = {k: v for k, v in d.attrs.items() if k not in ("created", "history")}
        xr.testing.assert_identical(x, y)


def test_friction_sweep_writes_one_row_per_value(tmp_path):
    out = tmp_path / "s.h5"
    result = _run("sweep", _write(tmp_path, SMALL), "--set", "friction.mu=0.1,0.2,0.3,0.4", "-o", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert "friction.mu  converged" in result.output  # the summary table
    table = _table(out)
    assert list(table["case"]) == [0, 1, 2, 3]
    assert list(table["friction_mu"]) == [0.1, 0.2, 0.3, 0.4] and np.array_equal(table["mu"], table["friction_mu"])
    assert table["converged"].all() and np.allclose(table["q_over_mu_p"], 0.51, rtol=1e-9)
    with h5py.File(out) as f:
        assert f.attrs["format"] == "rolling_cli.result" and f.attrs["format_version"] == 2
        assert f.attrs["cases_complete"] == 4 and "rollc sweep" in f.attrs["history"]
        assert f["p_t"].shape[0] == 4


def test_values_ranges_product_and_zip():
    spec = sweep.spec_from_options(["friction.mu=0.1:0.4:4", "tangential.q_over_mu_p=0.2,0.5"], zipped=False)
    assert list(spec.values[0]) == [0.1, 0.2, 0.3, 0.4]  # as typed: 0.3, not numpy's 0.30000000000000004
    assert spec.size == 8 and spec.combination(1) == {"friction.mu": 0.1, "tangential.q_over_mu_p": 0.5}
    assert list(spec.combinations())[-1] == {"friction.mu": 0.4, "tangential.q_over_mu_p": 0.5}
    zipped = sweep.spec_from_options(["friction.mu=0.1,0.2", "tangential.q_over_mu_p=0.2,0.5"], zipped=True)
    assert list(zipped.combinations()) == [
        {"friction.mu": 0.1, "tangential.q_over_mu_p": 0.2},
        {"friction.mu": 0.2, "tangential.q_over_mu_p": 0.5},
    ]
    assert tuple(sweep.spec_from_options(["discretization.contact_elements=10:40:4"], False).values[0]) == (
        10,
        20,
        30,
        40,
    )
    with pytest.raises(CaseError, match="unknown case key"):
        sweep.spec_from_options(["friction.muu=0.1"], False)
    with pytest.raises(CaseError, match="friction.mu = -0.1: out of range"):
        sweep.spec_from_options(["friction.mu=-0.1,0.2"], False)


def test_long_ranges_are_lazy_and_match_numpy():
    """Ten million values cost nothing until they run; each value is numpy's linspace value
    rounded to 15 significant digits (a relative change below 1e-15)."""
    spec = sweep.spec_from_options(["friction.mu=0.1:0.9:10000000"], False)
    assert spec.size == 10_000_000
    reference = np.linspace(0.1, 0.9, 10_000_000)
    for i in (0, 1, 12345, 5_000_000, 9_999_998, 9_999_999):
        assert spec.combination(i)["friction.mu"] == pytest.approx(reference[i], rel=1e-15, abs=0)


def test_a_sweep_that_cannot_fit_is_refused_before_anything(tmp_path):
    out = tmp_path / "huge.h5"
    result = _run("sweep", _write(tmp_path, SMALL), "--set", "friction.mu=0.1:0.9:1000000000", "-o", out)
    assert result.exit_code == 2, result.output
    line = result.output.strip()
    assert "\n" not in line and "friction.mu: 1000000000 values" in line and "per case" in line and "allowed" in line
    assert not out.exists()
    ranges = ["--set", "friction.mu=0.1:0.9:1000000", "--set", "tangential.creep=-0.001:0.001:1000000"]
    tracked = _run("sweep", _write(tmp_path, SMALL), *ranges, "-o", out)  # 1e12 cases: 3 TB just to track them
    assert tracked.exit_code == 2 and "of memory to track" in tracked.output and not out.exists()


def test_the_same_set_key_twice_is_one_line(tmp_path):
    result = _run("sweep", _write(tmp_path, SMALL), "--set", "friction.mu=0.1", "--set", "friction.mu=0.2")
    assert result.exit_code == 2
    assert result.output.strip() == (
        "error: --set friction.mu: given twice; allowed: each key once, with all its values in one --set"
    )


def test_every_case_is_validated_before_the_first_solve(tmp_path):
    out = tmp_path / "s.h5"
    case = _write(tmp_path, SMALL)
    result = _run("sweep", case, "--set", "bodies.A.poisson=0.3,0.7", "-o", out)
    assert result.exit_code == 2
    assert "bodies.A.poisson = 0.7: out of range" in result.output
    assert not out.exists()


def test_workers_give_the_serial_result_exactly(tmp_path):
    case = _write(tmp_path, SMALL)
    serial, parallel = tmp_path / "serial.h5", tmp_path / "parallel.h5"
    values = "friction.mu=0.05:0.5:20"  # 20 cases: three chunks, so both workers work
    assert _run("-q", "sweep", case, "--set", values, "-o", serial, "--workers", 1).exit_code == 0
    assert _run("-q", "sweep", case, "--set", values, "-o", parallel, "--workers", 2).exit_code == 0
    assert list(_table(parallel)["case"]) == list(range(20))  # released in sweep order
    _same_sweep(serial, parallel)


def test_blas_runs_one_thread_in_a_sweep_and_is_restored_after():
    """threadpoolctl sets every loaded BLAS to one thread for the body and back after it."""
    import scipy.linalg  # noqa: F401  (the libraries numpy and scipy load)
    from threadpoolctl import threadpool_info

    from rolling_cli import blas

    def counts():
        return {lib["filepath"]: lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}

    before = counts()
    assert before
    with blas.single_threaded():
        assert set(counts().values()) == {1}
    assert counts() == before


SHIPPED = Path(__file__).resolve().parent.parent / "cases"

_LATE_BLAS = """
import sys
from threadpoolctl import threadpool_info
from rolling_cli import blas; from rolling_cli.study import sweep
from rolling_cli.case import load_case
base = load_case(sys.argv[1])
sweep.run(base, sweep.curve_spec(base, "load", 3), sys.argv[2], workers=1)
half_plane_sweep_imported_scipy = "scipy.linalg" in sys.modules
with blas.single_threaded():
    import scipy.linalg  # first loaded inside the body
    inside = {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}
after = {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}
print(half_plane_sweep_imported_scipy, sorted(inside), sorted(after))
"""


def test_a_half_plane_sweep_imports_no_scipy_linalg_and_later_blas_runs_one_thread(tmp_path):
    """A BLAS library first loaded inside the body (scipy's own, which only BEM and large dense
    cases import) runs one thread too: it reads the environment set by blas.limit_threads. So the
    half-plane sweep need not import scipy.linalg just to limit its threads (~0.2 s a process).
    After the body it has the count it would have had: the CPUs this process may use (no thread
    variable in the environment here)."""
    cpus = len(os.sched_getaffinity(0))
    if cpus < 2:
        pytest.skip("one usable CPU: one BLAS thread either way, nothing to tell apart")
    done = subprocess.run(
        [sys.executable, "-c", _LATE_BLAS, str(SHIPPED / "carter.toml"), str(tmp_path / "s.h5")],
        capture_output=True,
        text=True,
        env={k: v for k, v in os.environ.items() if k not in blas_env_names()},
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[-2] == f"False [1] [{cpus}]"


def blas_env_names():
    from rolling_cli.blas import SINGLE_THREAD_ENV

    return set(SINGLE_THREAD_ENV)


def test_an_existing_output_needs_overwrite_or_resume(tmp_path):
    case = _write(tmp_path, SMALL)
    out = tmp_path / "s.h5"
    assert _run("-q", "sweep", case, "--set", "friction.mu=0.1,0.2,0.3,0.4", "-o", out).exit_code == 0
    again = _run("-q", "sweep", case, "--set", "friction.mu=0.1", "-o", out)
    assert again.exit_code == 2
    allowed = "allowed: --overwrite to replace it, or --resume to continue it, or another output name"
    assert again.output.strip() == f"error: {out}: exists; {allowed}"
    assert len(_table(out)["case"]) == 4  # untouched
    replaced = _run("-q", "sweep", case, "--set", "friction.mu=0.1", "-o", out, "--overwrite")
    assert replaced.exit_code == 0 and len(_table(out)["case"]) == 1


def test_resume_solves_nothing_twice(tmp_path):
    """Ctrl-C inside a chunk keeps its finished cases; a resume solves only the rest. Interrupted at a
    chunk's end (where a kill leaves the file), the resumed file is the uninterrupted one bit for bit."""
    base = load_case(SMALL)
    spec = sweep.spec_from_options(["friction.mu=0.05:0.8:16"], False)  # two chunks
    whole = str(tmp_path / "whole.h5")
    sweep.run(base, spec, whole)

    def stop_after(count):
        def progress(done, total, failed):
            if done == count:
                raise KeyboardInterrupt

        return progress

    for stop, name in ((3, "inside.h5"), (sweep.CHUNK, "boundary.h5")):
        out = str(tmp_path / name)
        with pytest.raises(KeyboardInterrupt):
            sweep.run(base, spec, out, progress=stop_after(stop))
        with h5py.File(out) as f:
            assert cases_complete(f) == stop and f["case"].shape == (stop,)  # committed, trimmed on the way out
        rest = sweep.run(base, spec, out, resume=True)
        assert sorted(rest.records) == list(range(stop, 16)) and rest.skipped == stop
        again = sweep.run(base, spec, out, resume=True)
        assert len(again.records) == 0 and again.skipped == 16
        assert list(_table(out)["case"]) == list(range(16))
    _same_sweep(str(tmp_path / "boundary.h5"), whole)  # in sweep order, bit for bit


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"normal.load": 900.0}, "the base case differs at normal.load: file 1812.5, now 900.0"),
        ({}, "the values of friction.mu differ"),
    ],
)
def test_resume_refuses_another_sweep(tmp_path, change, named):
    """The issue's example: the base case edited between runs (normal.load 1812.5 -> 900)."""
    out = str(tmp_path / "s.h5")
    sweep.run(load_case(SMALL), sweep.spec_from_options(["friction.mu=0.1,0.2"], False), out)
    values = "friction.mu=0.1,0.2" if change else "friction.mu=0.1,0.3"
    with pytest.raises(CaseError, match="--resume refused: " + named):
        sweep.run(load_case(case_dict(SMALL, **change)), sweep.spec_from_options([values], False), out, resume=True)
    with pytest.raises(CaseError, match="warm starts differ"):
        sweep.run(
            load_case(SMALL), sweep.spec_from_options(["friction.mu=0.1,0.2"], False), out, resume=True, warm=False
        )
    assert len(_table(out)["case"]) == 2


def test_resume_refuses_a_format_1_file(tmp_path):
    out = tmp_path / "old.h5"
    out.write_bytes((Path(__file__).parent / "data" / "v1_sweep.h5").read_bytes())
    spec = sweep.spec_from_options(["tangential.q_over_mu_p=0.3,0.9,0.8"], False)  # (the fixture's 1.2 is refused now)
    base = load_case(case_dict(SMALL, **{"discretization.contact_elements": 10, "title": "format 1 fixture"}))
    with pytest.raises(CaseError, match="format version 1, this rollc writes 2"):
        sweep.run(base, spec, str(out), resume=True)


def test_failing_case_is_recorded_and_the_others_finish(tmp_path):
    out = tmp_path / "s.h5"
    case = _write(tmp_path, SMALL)
    args = ("--set", "solver.max_iterations=100,1,100", "--no-warm-start", "-o", out, "--workers", 1)
    result = _run("sweep", case, *args)
    assert result.exit_code == 1
    assert "1 of 3 cases failed" in result.output
    table = _table(out)
    assert list(table["converged"]) == [True, False, True]
    assert table["message"][1].startswith("sweep case (solver.max_iterations = 1): ")


def test_gross_sliding_is_refused_before_any_solve(tmp_path, monkeypatch):
    """Every case gets rollc solve's pre-solve checks first: exit 2, one line naming the key and the
    value as given (1.2, not a continuation step's value), and nothing solved or written."""
    from rolling_cli import pipeline

    def no_solve(*args, **kwargs):
        raise AssertionError("a case was solved")

    monkeypatch.setattr(pipeline, "prepare", no_solve)
    out = tmp_path / "s.h5"
    result = _run("sweep", _write(tmp_path, SMALL), "--set", "tangential.q_over_mu_p=0.3,1.2,0.8", "-o", out)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "tangential.q_over_mu_p = 1.2" in lines[0] and "gross sliding" in lines[0]
    assert not out.exists()


def test_gross_sliding_of_a_huge_range_is_found_lazily(tmp_path):
    """A range of a million values is checked at its ends (gross sliding is monotone in |Q|): refused
    at once, naming the end value as given."""
    base = load_case(case_dict(SMALL))
    spec = sweep.spec_from_options(["tangential.q_over_mu_p=0.1:1.5:1000000"], False)
    start = time.perf_counter()
    with pytest.raises(CaseError, match=r"tangential.q_over_mu_p = 1.5\): .*gross sliding"):
        sweep.validate(base, spec)
    assert time.perf_counter() - start < 10.0


def test_a_killed_sweep_leaves_a_valid_file(tmp_path):
    """SIGTERM to the running command: exit 130, a readable file with the finished cases."""
    case = _write(tmp_path, SMALL)
    out = tmp_path / "s.h5"
    command = [sys.executable, "-m", "rolling_cli", "-q", "sweep", str(case), "--set", "friction.mu=0.01:1:3000"]
    proc = subprocess.Popen(
        [*command, "-o", str(out), "--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    deadline = time.time() + 120
    while time.time() < deadline:
        time.sleep(0.5)
        try:
            with h5py.File(out) as f:
                if cases_complete(f) >= 1:
                    break
        except (OSError, KeyError):
            continue
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert b"continue with --resume" in err
    table = _table(out)
    assert 1 <= len(table["case"]) < 3000 and table["converged"].all()
    assert list(table["case"]) == list(range(len(table["case"])))
    assert not [p for p in os.listdir(tmp_path) if p.endswith((".tmp", ".lock"))]


def test_case_file_sweep_table_and_creep_force_curve(tmp_path):
    data = case_dict(SMALL, **{"tangential.q_over_p": 0.051})
    data["sweep"] = {"friction.mu": [0.1, 0.2, 0.3, 0.4]}  # the paper's Fig. 4
    out = tmp_path / "fig4.h5"
    assert _run("-q", "sweep", _write(tmp_path, data), "-o", out, "--workers", 1).exit_code == 0
    with h5py.File(out) as f:
        stick = np.sum(f["state"][()] == 1, axis=1)
    assert len(stick) == 4 and list(stick) == sorted(stick)  # the adhesion zone grows with friction (paper, Fig. 4)
    curve = tmp_path / "curve.h5"
    assert _run("-q", "sweep", _write(tmp_path, SMALL), "--curve", "load", "--points", 9, "-o", curve).exit_code == 0
    table = _table(curve)
    assert table["q_over_mu_p"][0] == pytest.approx(-0.99) and table["q_over_mu_p"][-1] == pytest.approx(0.99)
    assert np.all(np.diff(table["creep"]) < 0)  # Q falls as the creepage rises: a monotone creep-force curve


def test_no_sweep_given_is_a_bad_input(tmp_path):
    result = _run("sweep", _write(tmp_path, CARTER))
    assert result.exit_code == 2 and "no sweep given" in result.output


def test_shipped_sweep_case(tmp_path):
    out = tmp_path / "fig8.h5"
    result = _run("-q", "sweep", CASES / "paper_fig4.toml", "-o", out, "--workers", 1)
    assert result.exit_code == 0, result.output
    assert list(_table(out)["friction_mu"]) == [0.1, 0.2, 0.3, 0.4]


def test_a_case_beyond_the_memory_is_refused_before_any_solve(monkeypatch, tmp_path):
    """rollc solve's memory check runs on every contact system of a sweep first: the case that does
    not fit is named by its key and value, before anything is solved."""
    from rolling_cli import pipeline
    from rolling_cli.pipeline import resources

    base = load_case(case_dict(SMALL))
    small = resources.estimate(base).bytes
    big = resources.estimate(sweep.build(base, {"discretization.contact_elements": 400})).bytes
    assert big > 2 * small
    monkeypatch.setattr(resources, "available_memory", lambda: (small + big) / 2)  # 40 elements fit, 400 do not

    def no_solve(*args, **kwargs):
        raise AssertionError("a case was solved")

    monkeypatch.setattr(pipeline, "prepare", no_solve)
    spec = sweep.spec_from_options(["discretization.contact_elements=40,400"], False)
    with pytest.raises(CaseError, match=r"^sweep case \(discretization.contact_elements = 400\): "):
        sweep.run(base, spec, str(tmp_path / "s.h5"))
    assert not (tmp_path / "s.h5").exists()
