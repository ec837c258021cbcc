"""Thread count of the BLAS libraries numpy and scipy loaded (OpenBLAS).

Sweeps run many small solves: in worker processes BLAS must use one thread
each, or the workers' BLAS threads oversubscribe the cores (OpenBLAS threads
busy-wait) and run several times slower. And BLAS results depend on the
thread count in the last bits, so the serial sweep uses one thread too: the
serial and parallel runs then compute exactly the same numbers.

The thread count is set through OpenBLAS's own ``*_set_num_threads`` entry
points (found among the shared objects loaded into this process; Linux).
Where that is impossible :func:`single_threaded` does nothing and says so.
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import re

log = logging.getLogger(__name__)

_SYMBOLS = (
    ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
    ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
    ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
    ("openblas_set_num_threads", "openblas_get_num_threads"),
)

#: Environment variables that fix the BLAS thread count of a new process.
SINGLE_THREAD_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def _controls() -> list[tuple]:
    """(setter, getter) pairs of every loaded OpenBLAS."""
    import numpy  # noqa: F401  (load the libraries whose threads we control)
    import scipy.linalg  # noqa: F401

    try:
        with open("/proc/self/maps") as handle:
            paths = sorted(set(re.findall(r"(/\S*openblas\S*\.so\S*)", handle.read())))
    except OSError:
        return []
    found = []
    for path in paths:
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for set_name, get_name in _SYMBOLS:
            setter, getter = getattr(lib, set_name, None), getattr(lib, get_name, None)
            if setter is not None and getter is not None:
                setter.argtypes = [ctypes.c_int]
                getter.restype = ctypes.c_int
                found.append((setter, getter))
                break
    return found


@contextlib.contextmanager
def single_threaded():
    """Run the body with one BLAS thread; yields True when the count could be set."""
    controls = _controls()
    if not controls:
        log.info("BLAS thread count not controllable here; serial and parallel sweeps agree to round-off only")
        yield False
        return
    saved = [getter() for _, getter in controls]
    try:
        for setter, _ in controls:
            setter(1)
        yield True
    finally:
        for (setter, _), count in zip(controls, saved, strict=True):
            setter(count)
