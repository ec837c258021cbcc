"""Local worker processes of a sweep: one BLAS thread each, dead with their parent, stoppable.

* Each worker runs one BLAS thread (the environment it is spawned with, and
  threadpoolctl), so ``--workers N`` computes the serial run's numbers.
* A worker dies with the sweep process: Linux delivers SIGKILL to it when its
  parent dies (``PR_SET_PDEATHSIG``), and a watchdog thread checks the parent
  every second elsewhere. A killed sweep leaves no orphans.
* SIGINT (Ctrl-C reaches the whole process group; the sweep forwards it on
  SIGTERM) stops a worker after the statement it is in: the chunk function
  returns the cases it finished, so none of them is lost. An idle worker only
  notes the stop and takes no new chunk.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time

from .. import blas

_stopped = False
_busy = False
_limits = None


class _Stop(BaseException):
    """Raised inside a busy worker by SIGINT."""


def _on_interrupt(signum, frame) -> None:
    global _stopped, _busy
    _stopped = True
    if _busy:
        _busy = False
        raise _Stop


def _die_with_parent(parent: int) -> None:
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the parent died before the line above
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, name="parent-watchdog", daemon=True).start()


def initialize(parent: int) -> None:
    """Worker initializer: die with ``parent``, one BLAS thread, SIGINT stops the chunk."""
    global _limits
    _die_with_parent(parent)
    signal.signal(signal.SIGINT, _on_interrupt)
    _limits = blas.limit_threads()


def solve_chunk_until_stopped(base, chunk, warm: bool, use_cache: bool) -> list:
    """The records of ``chunk`` (see :func:`rolling_cli.study.chunk.solve_items`), up to a stop."""
    global _busy
    from .chunk import solve_items

    records: list = []
    if _stopped:
        return records
    _busy = True
    try:
        for record in solve_items(base, chunk, warm, use_cache):
            records.append(record)
            if _stopped:
                break
    except _Stop:
        pass
    finally:
        _busy = False
    return records


def executor(workers: int) -> concurrent.futures.ProcessPoolExecutor:
    """A pool of ``workers`` spawned processes set up by :func:`initialize`.

    Workers are spawned as tasks arrive: submit inside
    :func:`rolling_cli.blas.single_thread_environment`, so they start with one BLAS thread.
    """
    return concurrent.futures.ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=initialize,
        initargs=(os.getpid(),),
    )


def interrupt(pool: concurrent.futures.ProcessPoolExecutor) -> None:
    """Ask every worker to stop after its current statement (SIGINT). The workers are this
    process's children (``multiprocessing.active_children``: the pool is its only source of them)."""
    del pool  # its workers are the children; the pool has no public list of them
    for process in multiprocessing.active_children():
        with contextlib.suppress(ProcessLookupError, PermissionError):
            if process.pid is not None:
                os.kill(process.pid, signal.SIGINT)


def default_count() -> int:
    """The CPUs this process may run on (its affinity set, as a batch scheduler assigns it)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)
