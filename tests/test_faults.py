"""Hostile environments, made to happen for real: a file-size limit (a full disk, as the kernel
reports it: EFBIG) in a subprocess, kill -9 of a running sweep at random moments, the orphans a
killed parallel sweep could leave, SIGTERM of a parallel sweep in the middle of its chunks."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from helpers import case_dict, without_timings, write_case
from rolling_cli.case import load_case
from rolling_cli.files.reader import case_table, cases_complete
from rolling_cli.study import sweep

SMALL = case_dict(**{"discretization.contact_elements": 40})
linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc and RLIMIT_FSIZE semantics of Linux")


def _rollc(args, limit=None, env=None, setup="", **kwargs):
    """``rollc ARGS`` as a new process, optionally under a file-size limit of ``limit`` bytes
    (``setup``: Python run first)."""
    code = f"import sys\n{setup}\n"
    if limit is not None:
        code += f"import resource\nresource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))\n"
    code += "from rolling_cli.cli import main\nmain()\n"
    return subprocess.Popen(
        [sys.executable, "-c", code, *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "PYTHONWARNINGS": "ignore", **(env or {})},
        **kwargs,
    )


def _finish(proc, timeout=300):
    """Wait for a process (its pipes read and closed); returns its exit code."""
    proc.communicate(timeout=timeout)
    return proc.returncode


def _rows(path):
    with h5py.File(path) as f:
        table = case_table(f)
        n = cases_complete(f)
        return table, {name: f[name][:n] for name in ("p_n", "p_t", "s_t", "state") if n}


def _leftovers(directory):
    return [p for p in os.listdir(directory) if p.endswith((".tmp", ".lock"))]


@linux
def test_a_full_disk_during_solve_fails_cleanly(tmp_path):
    """The result needs ~100 kB; the process may write 40 kB. Exit 1 with one line naming the path and
    the OS error, no segmentation fault, no temporary file, and the existing output untouched."""
    case = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 200}))
    out = tmp_path / "r.h5"
    out.write_bytes(b"an older result")
    proc = _rollc(["-q", "solve", case, "-o", out, "--overwrite"], limit=40_000)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 1, err
    lines = err.decode().strip().splitlines()
    assert lines == [f"error: {out}: cannot write: File too large; nothing was written"]
    assert out.read_bytes() == b"an older result"
    assert not _leftovers(tmp_path)


@linux
def test_a_full_disk_during_a_sweep_keeps_the_committed_cases(tmp_path):
    """The sweep file grows by rebuilds (here from 16 rows, four times larger each time, as a large
    study grows from 256 MB); the one that does not fit the limit fails before HDF5 writes. The cases
    committed before stay readable, and --resume completes the study exactly."""
    case = write_case(tmp_path, SMALL)
    spec = "friction.mu=0.02:1:80"
    args = ["-q", "sweep", case, "--set", spec, "--workers", 1]
    out = tmp_path / "s.h5"
    small_steps = (
        "import rolling_cli.files.writer as w, rolling_cli.study.sweep as s\n"
        "w.PREALLOCATE, w.FIRST_ROWS, s.COMMIT_SHARE = 0, 16, 1e9  # small steps, a commit after every case"
    )
    # measured reservations: ~650 kB for the 16-row file, ~1.2 MB for the 64-row one; the limit lies between
    proc = _rollc([*args, "-o", out], limit=900_000, env={"ROLLC_FLUSH_SECONDS": "0"}, setup=small_steps)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 1, err
    message = err.decode().strip()
    assert message.startswith(f"error: {out}: cannot write: File too large; the ") and "--resume" in message
    kept, _ = _rows(out)
    assert 16 <= len(kept["case"]) < 80 and kept["converged"].all()
    assert not _leftovers(tmp_path)
    assert _finish(_rollc([*args, "-o", out, "--resume"])) == 0
    whole = tmp_path / "whole.h5"
    sweep.run(load_case(case), sweep.spec_from_options([spec], False), str(whole))
    _assert_same(out, whole)


def _assert_same(a, b):
    xr = pytest.importorskip("xarray")
    with xr.open_dataset(a) as x, xr.open_dataset(b) as y:
        x, y = (without_timings(d) for d in (x, y))
        for d in (x, y):
            d.attrs = {k: v for k, v in d.attrs.items() if k not in ("created", "history")}
        xr.testing.assert_identical(x, y)


@linux
def test_kill_9_at_random_moments_always_leaves_a_file_that_resumes_to_the_same_result(tmp_path):
    """Ten kills (fixed seed) while a sweep commits every 10 ms: after each, the file opens, each of its
    trusted rows is the uninterrupted run's row bit for bit, and --resume ends with the same file."""
    rng = np.random.default_rng(11)
    case = write_case(tmp_path, SMALL)
    spec = ["--set", "friction.mu=0.005:1:300"]
    whole = tmp_path / "whole.h5"
    sweep.run(load_case(case), sweep.spec_from_options([spec[1]], False), str(whole))
    reference, fields = _rows(whole)
    out = tmp_path / "s.h5"
    kills = 0
    while kills < 10:
        proc = _rollc(
            ["-q", "sweep", case, *spec, "-o", out, "--workers", 1, "--resume"], env={"ROLLC_FLUSH_SECONDS": "0.01"}
        )
        started = time.time()
        while not out.exists() and proc.poll() is None and time.time() - started < 120:
            time.sleep(0.01)
        time.sleep(rng.uniform(0.0, 0.4))
        if proc.poll() is not None:
            break  # finished before the kill: the remaining kills have nothing to hit
        proc.send_signal(signal.SIGKILL)
        proc.communicate()
        kills += 1
        table, values = _rows(out)  # opens, and holds complete rows only
        rows = table["case"]
        assert list(rows) == list(range(len(rows)))  # a serial run commits in sweep order
        for name, array in values.items():
            assert np.array_equal(array, fields[name][: len(rows)], equal_nan=True), name
    assert kills == 10, "the study ended before ten kills; make it longer"
    final = _rollc(["-q", "sweep", case, *spec, "-o", out, "--workers", 1, "--resume"])
    assert _finish(final) == 0
    _assert_same(out, whole)
    assert not _leftovers(tmp_path)


def _descendants(pid):
    """Processes whose parent chain leads to ``pid`` (from /proc)."""
    parents = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            parents[int(entry.name)] = int(fields[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {child for child, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _alive(pid):
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"  # a zombie is dead; only its parent's wait is missing


@linux
def test_kill_9_of_a_parallel_sweep_leaves_no_orphans(tmp_path):
    case = write_case(tmp_path, SMALL)
    proc = _rollc(["-q", "sweep", case, "--set", "friction.mu=0.001:1:20000", "-o", tmp_path / "s.h5", "--workers", 2])
    deadline = time.time() + 120
    children = set()
    while time.time() < deadline:
        children = _descendants(proc.pid)
        if len(children) >= 3 and (tmp_path / "s.h5").exists():  # two workers and the resource tracker
            break
        time.sleep(0.2)
    assert len(children) >= 3, children
    proc.send_signal(signal.SIGKILL)
    proc.communicate()
    deadline = time.time() + 20
    while time.time() < deadline and any(_alive(pid) for pid in children):
        time.sleep(0.2)
    assert not [pid for pid in children if _alive(pid)]


@linux
def test_sigterm_of_a_parallel_sweep_keeps_the_cases_finished_in_its_workers(tmp_path):
    """Chunks of 8 cold-started cases (~0.1 s each), eight chunks, two workers: SIGTERM soon after the
    first commit, while both workers are inside later chunks. The file keeps the parts of the chunks
    they had finished (before, only whole chunks were kept), and --resume completes it. The signal
    lands inside a chunk only as timing allows (on a loaded machine it can fall between two chunks),
    so up to three runs are made, each on a fresh file, until one cuts a chunk short."""
    case = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 300}))
    args = ["-q", "sweep", case, "--set", "friction.mu=0.1:0.9:64", "--no-warm-start"]
    for attempt in range(3):
        out = tmp_path / f"s{attempt}.h5"
        proc = _rollc([*args, "-o", out, "--workers", 2], env={"ROLLC_FLUSH_SECONDS": "0"})
        deadline = time.time() + 300
        while time.time() < deadline:
            try:
                with h5py.File(out) as f:
                    if cases_complete(f) >= 1:
                        case_seconds = float(np.mean(f["time"][: cases_complete(f)]))
                        break
            except (OSError, KeyError):
                pass
            time.sleep(0.02)
        time.sleep(0.25 * sweep.CHUNK * case_seconds)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 130, err
        table, _ = _rows(out)
        assert table["converged"].all()
        present = np.zeros(64, dtype=bool)
        present[table["case"]] = True
        per_chunk = present.reshape(8, sweep.CHUNK).sum(axis=1)
        if np.any((per_chunk > 0) & (per_chunk < sweep.CHUNK)):  # a chunk cut short, its cases kept
            break
    else:
        raise AssertionError(f"no run kept a chunk cut short: {per_chunk}")
    assert _finish(_rollc([*args, "-o", out, "--workers", 2, "--resume"])) == 0
    done, _ = _rows(out)
    assert list(done["case"]) == list(range(64))  # back in sweep order (the workers' parts came first)
    assert not _leftovers(tmp_path)
