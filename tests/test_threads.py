"""BLAS threads of a single solve (issue 26 item 7): ``rollc solve`` runs one BLAS thread unless the
user sets a count (OMP_NUM_THREADS, OPENBLAS_NUM_THREADS, MKL_NUM_THREADS, BLIS_NUM_THREADS).

The counts are read back with threadpoolctl (what each loaded BLAS library reports). Each check
first gives the libraries two threads (or starts a process with none of the variables on a
machine of two or more CPUs), so that one thread can only come from the default.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

from helpers import case_dict, run_cli, write_case
from rolling_cli import blas, pipeline


def _counts() -> set[int]:
    return {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}


def _without_user_setting(monkeypatch) -> None:
    for name in blas.USER_THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)


def _recording_solve(monkeypatch) -> list:
    seen: list = []
    real = pipeline.solve

    def recording(*args, **kwargs):
        seen.append(_counts())
        return real(*args, **kwargs)

    monkeypatch.setattr(pipeline, "solve", recording)
    return seen


def test_user_setting_is_any_of_the_variables_and_empty_is_unset():
    assert blas.user_thread_setting({}) is None
    assert blas.user_thread_setting({"OMP_NUM_THREADS": " "}) is None
    for name in blas.USER_THREAD_VARIABLES:
        assert blas.user_thread_setting({name: "3"}) == name


def test_rollc_solve_runs_one_blas_thread_by_default_and_restores_the_count(tmp_path, monkeypatch):
    _without_user_setting(monkeypatch)
    seen = _recording_solve(monkeypatch)
    case = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 20}))
    with threadpool_limits(limits=2, user_api="blas"):
        assert _counts() == {2}
        done = run_cli("-q", "solve", case, "-o", tmp_path / "out.h5")
        assert done.exit_code == 0, done.output
        assert seen == [{1}]
        assert _counts() == {2}  # given back after the command


def test_rollc_solve_respects_the_users_thread_count(tmp_path, monkeypatch):
    _without_user_setting(monkeypatch)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    seen = _recording_solve(monkeypatch)
    case = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 20}))
    with threadpool_limits(limits=2, user_api="blas"):  # what the variable gives a library loaded now
        done = run_cli("-q", "solve", case, "-o", tmp_path / "out.h5")
        assert done.exit_code == 0, done.output
        assert seen == [{2}]


_LATE = """
import numpy  # loaded before the command, as in rollc
from threadpoolctl import threadpool_info
from rolling_cli import blas

def counts():
    return sorted({lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"})

with blas.command_threads() as applied:
    first = counts()
    import scipy.linalg  # scipy's own BLAS, first loaded inside the command
    blas.settle()
    late = counts()
print(applied, first, late, counts())
"""


def test_a_blas_loaded_during_the_command_runs_one_thread_and_gets_its_count_back():
    """In a process started without any of the variables, every library starts with one thread
    per usable CPU; scipy's, loaded inside the command, is limited by settle() (as the BEM and the
    large dense solves call it) and has its own count back afterwards. With a variable set, nothing
    is changed."""
    cpus = len(os.sched_getaffinity(0))
    if cpus < 2:
        pytest.skip("one usable CPU: one BLAS thread either way, nothing to tell apart")
    clean = {k: v for k, v in os.environ.items() if k not in blas.USER_THREAD_VARIABLES}
    done = subprocess.run([sys.executable, "-c", _LATE], capture_output=True, text=True, env=clean)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"1 [1] [1] [{cpus}]"
    chosen = subprocess.run(
        [sys.executable, "-c", _LATE], capture_output=True, text=True, env={**clean, "MKL_NUM_THREADS": "2"}
    )
    assert chosen.returncode == 0, chosen.stderr
    # MKL_NUM_THREADS does not set OpenBLAS: the libraries keep their CPU count, untouched by rollc
    assert chosen.stdout.strip() == f"None [{cpus}] [{cpus}] [{cpus}]"
