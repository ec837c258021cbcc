"""One BLAS thread for sweeps and, unless the user sets a count, for ``rollc solve``; through threadpoolctl.

Sweeps run many small solves: in worker processes BLAS must use one thread
each, or the workers' BLAS threads oversubscribe the cores (OpenBLAS threads
busy-wait) and run several times slower. And BLAS results depend on the
thread count in the last bits, so the serial sweep uses one thread too: the
serial and parallel runs then compute exactly the same numbers.

A single solve (:func:`command_threads`, used by ``rollc solve``) runs
:data:`DEFAULT_THREADS` BLAS thread unless the user chose a count in one of
:data:`USER_THREAD_VARIABLES` (read, never written, here): on a machine whose
cores are busy with other work a second BLAS thread made solves 2-6x slower, and
on an idle one it saved at most a few per cent (benchmarks/bench_threads.py,
benchmarks/RESULTS.md). The Python API (:func:`rolling_cli.solve`) leaves the
threads to its caller.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator
from dataclasses import dataclass, field

#: Environment variables that fix the BLAS thread count of a new process.
SINGLE_THREAD_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def limit_threads():
    """Limit every BLAS/OpenMP library loaded so far to one thread, until the returned limiter's
    ``restore_original_limits()`` (or for good, in a worker); libraries loaded later (scipy's own
    BLAS, which only BEM and large dense cases import) read :data:`SINGLE_THREAD_ENV`, set here
    (for good in a worker; :func:`single_threaded` restores it). Importing scipy.linalg only to
    limit its threads cost every sweep ~0.2 s."""
    from threadpoolctl import threadpool_limits

    os.environ.update(SINGLE_THREAD_ENV)
    return threadpool_limits(limits=1)


@contextlib.contextmanager
def single_threaded():
    """Run the body with one BLAS thread; after it every library has its thread count back: those
    loaded before the body their own, one first loaded inside it (reading :data:`SINGLE_THREAD_ENV`)
    the count it would have had: the value of the caller's environment variable, else the CPUs
    this process may use."""
    from threadpoolctl import ThreadpoolController

    before = {lib.filepath for lib in ThreadpoolController().lib_controllers}
    saved = {k: os.environ.get(k) for k in SINGLE_THREAD_ENV}
    with single_thread_environment():
        limiter = limit_threads()
        try:
            yield
        finally:
            limiter.restore_original_limits()
    for lib in ThreadpoolController().lib_controllers:
        if lib.filepath not in before:
            lib.set_num_threads(_default_threads(lib.internal_api, saved))


def _default_threads(internal_api: str, environment: dict) -> int:
    """The thread count a BLAS/OpenMP library loaded with the given environment would take."""
    names = {"openblas": ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"), "mkl": ("MKL_NUM_THREADS", "OMP_NUM_THREADS")}
    for name in names.get(internal_api, ("OMP_NUM_THREADS",)):
        value = environment.get(name)
        if value and value.split(",")[0].strip().isdigit() and int(value.split(",")[0]) > 0:
            return int(value.split(",")[0])
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def single_thread_environment():
    """Set :data:`SINGLE_THREAD_ENV` for processes started in the body (they inherit it)."""
    saved = {k: os.environ.get(k) for k in SINGLE_THREAD_ENV}
    os.environ.update(SINGLE_THREAD_ENV)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


#: The environment variables through which a user sets the BLAS thread count (read only).
USER_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
#: BLAS threads of ``rollc solve`` when the user sets none (benchmarks/bench_threads.py).
DEFAULT_THREADS = 1
#: The modules whose import loads a BLAS library (numpy's, and scipy's own in scipy wheels).
BLAS_MODULES = ("numpy", "scipy.linalg")


def user_thread_setting(environment=None) -> str | None:
    """The name of the first of :data:`USER_THREAD_VARIABLES` set (non-empty) in ``environment``
    (default ``os.environ``), or None: the user has chosen the BLAS threads."""
    environment = os.environ if environment is None else environment
    for name in USER_THREAD_VARIABLES:
        if environment.get(name, "").strip():
            return name
    return None


@dataclass
class _Command:
    """The thread limit of the running command: its count, the BLAS modules seen, the limiters to undo."""

    threads: int
    seen: set = field(default_factory=set)
    limiters: list = field(default_factory=list)


_command: _Command | None = None


@contextlib.contextmanager
def command_threads(threads: int = DEFAULT_THREADS) -> Iterator[int | None]:
    """Run the body (one command) with ``threads`` BLAS threads, unless the user set a count in one
    of :data:`USER_THREAD_VARIABLES` (then the libraries keep the count they read from it).
    Yields the count applied, or None. Libraries loaded inside the body are limited by
    :func:`settle` (called where the code first needs them); every library gets its count back
    after the body."""
    global _command
    if user_thread_setting() is not None or _command is not None:
        yield None
        return
    _command = _Command(threads)
    try:
        settle()
        yield threads
    finally:
        command, _command = _command, None
        for limiter in reversed(command.limiters):
            limiter.restore_original_limits()


def settle() -> None:
    """Inside :func:`command_threads`: limit the BLAS libraries loaded since the last call (those
    of :data:`BLAS_MODULES` newly imported) to the command's count; otherwise, or when none is new,
    nothing (a set lookup: cheap enough to call before every dense solve)."""
    command = _command
    if command is None:
        return
    loaded = {name for name in BLAS_MODULES if name in sys.modules}
    if loaded <= command.seen:
        return
    from threadpoolctl import threadpool_limits

    command.seen |= loaded
    command.limiters.append(threadpool_limits(limits=command.threads, user_api="blas"))
