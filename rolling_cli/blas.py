"""One BLAS thread for sweeps, through threadpoolctl (OpenBLAS, MKL, BLIS; every platform).

Sweeps run many small solves: in worker processes BLAS must use one thread
each, or the workers' BLAS threads oversubscribe the cores (OpenBLAS threads
busy-wait) and run several times slower. And BLAS results depend on the
thread count in the last bits, so the serial sweep uses one thread too: the
serial and parallel runs then compute exactly the same numbers.
"""

from __future__ import annotations

import contextlib
import os

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
