"""numpy's own LAPACK LU (getrf/getrs), to keep a factorisation that ``numpy.linalg.solve`` discards.

``numpy.linalg.solve`` is LAPACK's gesv, which in OpenBLAS is getrf then getrs
(interface/lapack/gesv.c); numpy does not expose the two halves, and scipy's
``lu_factor``/``lu_solve`` run on scipy's own OpenBLAS build, whose last bits
differ (measured: 0 of 19 Newton matrices of the half-plane cases solved
alike), and importing scipy.linalg costs ~0.2 s of start-up (issue #14). So
this module calls getrf and getrs of the very library numpy's gesv calls
(found next to numpy in a wheel, ``numpy.libs/libscipy_openblas64_*.so``,
ILP64, through ctypes): the factorisation and one solve give exactly
``numpy.linalg.solve``'s numbers (checked bit for bit on a test matrix when the
library is first loaded, and on every Newton matrix of the shipped cases by
tests/test_lapack.py). Where that library is not found (another numpy build)
or the check fails, :func:`available` is False and callers keep
``numpy.linalg.solve``.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os

import numpy as np

_INT = ctypes.c_int64  # ILP64: the "64_" symbols of numpy's wheel library
_NAMES = (("scipy_dgetrf_64_", "scipy_dgetrs_64_"), ("dgetrf_64_", "dgetrs_64_"))


@functools.cache
def _routines() -> tuple | None:
    """(getrf, getrs) of numpy's LAPACK, or None when not found or not giving numpy's numbers."""
    here = os.path.dirname(np.__file__)
    for path in sorted(glob.glob(os.path.join(here, os.pardir, "numpy.libs", "*openblas*.so*"))):
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for getrf, getrs in _NAMES:
            if hasattr(lib, getrf) and hasattr(lib, getrs):
                found = (getattr(lib, getrf), getattr(lib, getrs))
                return found if _same_as_numpy(found) else None
    return None


def available() -> bool:
    """True when :func:`factor` and :func:`solve` run numpy's own LAPACK (module docstring)."""
    return _routines() is not None


def factor(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """LU of the square ``matrix`` in place (it must be Fortran-ordered float64; it then holds
    the factors): returns (lu, pivots, info), info > 0 for an exactly singular matrix."""
    routines = _routines()
    if routines is None:
        raise RuntimeError("numpy's LAPACK was not found")
    return _getrf(routines[0], matrix)


def solve(lu: np.ndarray, pivots: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with A x = rhs from :func:`factor`'s (lu, pivots); ``rhs`` a vector or a matrix of columns
    (not changed)."""
    routines = _routines()
    if routines is None:
        raise RuntimeError("numpy's LAPACK was not found")
    return _getrs(routines[1], lu, pivots, rhs)


def _getrf(routine, matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    if not (matrix.flags.f_contiguous and matrix.dtype == np.float64 and matrix.ndim == 2):
        raise ValueError("the LU needs a Fortran-ordered float64 matrix")
    size, info = _INT(matrix.shape[0]), _INT(0)
    pivots = np.zeros(matrix.shape[0], dtype=np.int64)
    routine(
        ctypes.byref(size), ctypes.byref(size), matrix.ctypes.data_as(ctypes.c_void_p), ctypes.byref(size),
        pivots.ctypes.data_as(ctypes.c_void_p), ctypes.byref(info),
    )  # fmt: skip
    return matrix, pivots, int(info.value)


def _getrs(routine, lu: np.ndarray, pivots: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    x = np.array(rhs, dtype=np.float64, order="F", copy=True)
    size, info = _INT(lu.shape[0]), _INT(0)
    columns = _INT(1 if x.ndim == 1 else x.shape[1])
    routine(
        ctypes.c_char_p(b"N"), ctypes.byref(size), ctypes.byref(columns), lu.ctypes.data_as(ctypes.c_void_p),
        ctypes.byref(size), pivots.ctypes.data_as(ctypes.c_void_p), x.ctypes.data_as(ctypes.c_void_p),
        ctypes.byref(size), ctypes.byref(info), ctypes.c_size_t(1),
    )  # fmt: skip
    return x


def _same_as_numpy(routines: tuple) -> bool:
    """Whether getrf + getrs of ``routines`` give numpy.linalg.solve's numbers bit for bit (on a
    fixed 80 x 80 matrix: larger than OpenBLAS's unblocked size, so its blocked kernels run)."""
    rng = np.random.default_rng(12345)
    a = rng.standard_normal((80, 80))
    b = rng.standard_normal(80)
    try:
        lu, pivots, info = _getrf(routines[0], np.array(a, order="F"))
        x = _getrs(routines[1], lu, pivots, b)
    except Exception:  # noqa: BLE001 - any failure of the foreign call: keep numpy.linalg.solve
        return False
    return info == 0 and bool(np.array_equal(x, np.linalg.solve(a, b)))
