"""Start-up (issue #14 item 1): each command imports only what its case needs.

Each check runs ``rollc`` in a fresh interpreter and records ``sys.modules``
after the command: what the command imported, whatever imported it. Speed
itself is measured in benchmarks/startup.py (no timing here). The BEM case
checks the other direction, so that a check which never saw the BEM package
imported cannot pass by accident (for instance a broken recorder).
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rolling_cli import blas

CASES = Path(__file__).resolve().parent.parent / "cases"

#: Run ``rollc`` with the given arguments in this interpreter, then record its exit code and modules.
_RECORDER = """
import json, sys
out, args = sys.argv[1], sys.argv[2:]
sys.argv = ["rollc", *args]
from rolling_cli.cli import main
try:
    main()
    code = 0
except SystemExit as exit:
    code = exit.code or 0
with open(out, "w") as handle:
    json.dump({"code": code, "modules": sorted(sys.modules)}, handle)
"""

#: Packages the half-plane solve and write must not import (only other cases or commands need them).
HEAVY = ("rolling_cli.influence.bem", "matplotlib", "scipy.optimize", "scipy.special", "scipy.sparse", "xarray", "dask")


def _run(tmp_path: Path, *args: str) -> set[str]:
    """The modules loaded after ``rollc *args`` in a fresh interpreter run in ``tmp_path``."""
    record = tmp_path / "modules.json"
    done = subprocess.run(
        [sys.executable, "-c", _RECORDER, str(record), *args], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    data = json.loads(record.read_text())
    assert data["code"] == 0, done.stderr
    return set(data["modules"])


def _loaded(modules: set[str], package: str) -> list[str]:
    return sorted(m for m in modules if m == package or m.startswith(package + "."))


def test_version_imports_no_numerics(tmp_path):
    modules = _run(tmp_path, "--version")
    assert "rolling_cli.cli" in modules  # the recorder ran the command
    for package in ("numpy", "scipy", "h5py", "matplotlib", "rolling_cli.influence", "rolling_cli.solver"):
        assert not _loaded(modules, package), package
    assert "rolling_cli.pipeline" not in modules


@pytest.mark.parametrize("case", ["carter.toml", "carter_stresses.toml"])
def test_half_plane_solve_imports_no_bem_nor_plotting(tmp_path, case):
    """The half-plane solve and write (and its subsurface stresses) need neither BEM nor plotting."""
    modules = _run(tmp_path, "-q", "solve", str(CASES / case), "-o", "result.h5")
    assert (tmp_path / "result.h5").is_file()
    # what this path does need is there: the check sees the real solve and write
    assert {"rolling_cli.influence.halfplane", "rolling_cli.pipeline", "rolling_cli.files.writer", "h5py"} <= modules
    if case == "carter_stresses.toml":
        assert "rolling_cli.stresses.halfplane" in modules
    for package in HEAVY:
        assert not _loaded(modules, package), package
    assert "rolling_cli.adapt.levels" not in modules  # a fixed mesh, no summary printed: no adaptive levels


def test_bem_solve_imports_the_bem(tmp_path):
    """The counter-check: a BEM case built here does load the BEM package."""
    modules = _run(tmp_path, "-q", "solve", str(CASES / "paper_fig3_q051.toml"), "-o", "bem.h5", "--no-cache")
    assert (tmp_path / "bem.h5").is_file()
    assert _loaded(modules, "rolling_cli.influence.bem")
    assert not _loaded(modules, "matplotlib")


def test_bem_cache_hit_imports_no_bem(tmp_path, monkeypatch):
    """A BEM case whose influence is in the disk cache needs no BEM code: the first run builds (and
    imports the BEM), the second reads the cache only."""
    monkeypatch.setenv("ROLLC_CACHE_DIR", str(tmp_path / "cache"))  # empty: the first run must build
    args = ("-q", "solve", str(CASES / "paper_fig3_q051.toml"), "--overwrite", "-o")
    assert _loaded(_run(tmp_path, *args, "first.h5"), "rolling_cli.influence.bem")
    modules = _run(tmp_path, *args, "second.h5")
    assert (tmp_path / "second.h5").is_file()
    assert not _loaded(modules, "rolling_cli.influence.bem")


def _rollc(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    """``python -m rolling_cli *args`` (the console script's entry, :func:`rolling_cli.cli.entry`), with
    one BLAS thread (:data:`rolling_cli.blas.SINGLE_THREAD_ENV`: whatever this process's environment
    holds, which importing dask.distributed changes)."""
    from rolling_cli.blas import SINGLE_THREAD_ENV

    env = {**os.environ, **SINGLE_THREAD_ENV}
    return subprocess.run(
        [sys.executable, "-m", "rolling_cli", *args], cwd=tmp_path, capture_output=True, text=True, env=env
    )


def test_entry_quick_exit_keeps_output_file_and_exit_codes(tmp_path):
    """The console entry ends the process without the interpreter's teardown: what a command prints
    must still reach a pipe, its file must be complete, and its exit code must be kept."""
    import rolling_cli

    done = _rollc(tmp_path, "solve", str(CASES / "carter.toml"), "-o", "r.h5")
    assert done.returncode == 0, done.stderr
    assert done.stdout.rstrip().endswith("written        r.h5")  # the summary's last line, flushed
    written = rolling_cli.read_result(tmp_path / "r.h5")
    with blas.single_threaded():  # as the subprocess: one BLAS thread
        direct = rolling_cli.solve(rolling_cli.load_case(CASES / "carter.toml"))
    # the same solve in this process: the file holds every node's tractions (written, closed, flushed).
    # Bound: round-off of the summation order (a BLAS run with other threads, ~1e-14 relative to
    # p0), far below any truncated or unwritten value (O(1) relative).
    scale = float(np.max(np.abs(direct.p_n)))
    assert written.p_n.shape == direct.p_n.shape
    assert np.max(np.abs(written.p_n - direct.p_n)) <= 1e-12 * scale
    assert np.max(np.abs(written.p_t - direct.p_t)) <= 1e-12 * scale
    assert written.attributes["converged"]
    bad = _rollc(tmp_path, "solve", str(tmp_path / "missing.toml"))
    assert bad.returncode == 2 and bad.stderr.startswith("error: ") and not bad.stdout
    version = _rollc(tmp_path, "--version")
    assert version.returncode == 0 and version.stdout.startswith("rollc, version")
    usage = _rollc(tmp_path, "solve")  # click's usage error: its own exit code
    assert usage.returncode == 2 and "Missing argument" in usage.stderr


_SAFE = """
import sys, threading
import h5py
from rolling_cli import process
states = [process.fast_exit_safe()]
handle = h5py.File(sys.argv[1], "w")
states.append(process.fast_exit_safe())
handle.close()
stop = threading.Event()
worker = threading.Thread(target=stop.wait)
worker.start()
states.append(process.fast_exit_safe())
stop.set()
worker.join()
states.append(process.fast_exit_safe())
import multiprocessing  # noqa: F401
states.append(process.fast_exit_safe())
print(states)
"""


def test_quick_exit_only_when_the_process_is_quiet(tmp_path):
    """No quick exit while an HDF5 file is open, another thread runs or worker machinery is loaded."""
    done = subprocess.run([sys.executable, "-c", _SAFE, str(tmp_path / "f.h5")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[True, False, False, True, False]"


_GC = """
import atexit, gc, json, sys
from rolling_cli import cli, pipeline, process
seen = []
original = pipeline.solve
def solve(*args, **kwargs):
    seen.append(gc.isenabled())
    return original(*args, **kwargs)
pipeline.solve = solve
report = lambda: print(json.dumps({"during_solve": seen, "frozen": gc.get_freeze_count(), "after": gc.isenabled()}))
atexit.register(report)
process.fast_exit_safe = lambda: False  # the usual exit, which runs the report (this test is about collection)
sys.argv = ["rollc", "-q", "solve", sys.argv[1], "-o", "r.h5"]
cli.entry()
"""


def test_entry_collects_garbage_again_once_the_command_has_imported(tmp_path):
    """The console entry turns garbage collection off for the start-up's imports only: the solve
    itself runs with it on (the imports' objects frozen out of its reach)."""
    done = subprocess.run(
        [sys.executable, "-c", _GC, str(CASES / "carter.toml")], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    state = json.loads(done.stdout)
    assert state["during_solve"] == [True] and state["after"]
    assert state["frozen"] > 1000  # the modules' objects (numpy, h5py, the package): tens of thousands
