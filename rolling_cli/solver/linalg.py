"""Dense solves of the reduced Newton system (LAPACK LU).

Large systems are factorised in single precision and the solution refined in
double precision (mixed-precision iterative refinement): the LU then costs
~40 % less on this kind of machine, and the refined solution has a double
precision residual. If refinement does not converge (condition number near
1/eps_single), the system is refactorised in double precision. Small systems
go straight to numpy's LAPACK solve (the same getrf/getrs as scipy's LU, so
the same answer; scipy.linalg is not imported for them: start-up, issue #14).
A degenerate contact or adhesion set makes the matrix singular: an exactly
singular one raises, a numerically singular one gives a non-finite or huge
step, and both end the strategy (:mod:`rolling_cli.solver.newton`).

:class:`Factor` keeps an LU for further right-hand sides with the same numbers
(small systems through numpy's own getrf/getrs, :mod:`rolling_cli.solver.lapack`):
the Newton's last factorisation then serves the sensitivities (issue 24).
"""

from __future__ import annotations

import warnings
from typing import Protocol

import numpy as np

#: Systems at least this large use the single-precision LU with refinement.
MIXED_PRECISION_SIZE = 1200
_REFINE_STEPS = 8
_SINGULAR = (
    "singular Newton system: the contact or adhesion set is degenerate (for example no contact node, "
    "or a gauge node in contact); the potential zone may be too small"
)


def _factor(matrix: np.ndarray) -> tuple:
    import scipy.linalg  # lazy: start-up (issue #14 item 1)

    with warnings.catch_warnings():  # an exactly singular pivot is reported below, as an error
        warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
        lu = scipy.linalg.lu_factor(matrix, check_finite=False)
    diag = np.abs(np.diag(lu[0]))
    if diag.size and not diag.min() > 1e-13 * diag.max():
        raise np.linalg.LinAlgError(_SINGULAR)
    return lu


def solve_dense(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """x with matrix @ x = rhs to double-precision accuracy."""
    if matrix.shape[0] == 0:
        return np.zeros(0)
    if matrix.shape[0] < MIXED_PRECISION_SIZE:
        try:
            x = np.linalg.solve(matrix, rhs)
        except np.linalg.LinAlgError:
            raise np.linalg.LinAlgError(_SINGULAR) from None
        if not np.all(np.isfinite(x)):
            raise np.linalg.LinAlgError(_SINGULAR)
        return x
    return Factor(matrix).solve(rhs)


class Solver(Protocol):
    """What solves with a kept factorisation: :class:`Factor`, or one updated from it
    (:mod:`rolling_cli.solver.kept`)."""

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """x with A x = rhs; ``rhs`` a vector or columns."""
        ...


class Factor:
    """A kept LU factorisation of a dense ``matrix``: :meth:`solve` gives :func:`solve_dense`'s
    numbers bit for bit, for as many right-hand sides as wanted (the Newton's last factorisation
    reused by the sensitivities, issue 24). Small systems: numpy's own getrf/getrs
    (:mod:`rolling_cli.solver.lapack`; build with :func:`factorise`, which returns None where
    that library is not found); large ones: the single-precision LU with refinement of the
    module docstring, the double-precision LU made when refinement first fails and kept.
    Raises ``numpy.linalg.LinAlgError`` for a singular matrix."""

    def __init__(self, matrix: np.ndarray) -> None:
        self.matrix = matrix
        self.size = matrix.shape[0]
        self._lu64: tuple | None = None
        if self.size < MIXED_PRECISION_SIZE:
            from . import lapack

            lu, pivots, info = lapack.factor(np.array(matrix, dtype=float, order="F"))
            if info > 0:
                raise np.linalg.LinAlgError(_SINGULAR)
            self._small = (lu, pivots)
            return
        from .. import blas

        blas.settle()  # scipy's BLAS, perhaps loaded just now, on the command's threads
        self._lu32 = _factor(matrix.astype(np.float32))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """x with matrix @ x = rhs [rhs's units / matrix's]; ``rhs`` a vector or columns."""
        if self.size < MIXED_PRECISION_SIZE:
            from . import lapack

            x = lapack.solve(*self._small, rhs)
            if not np.all(np.isfinite(x)):
                raise np.linalg.LinAlgError(_SINGULAR)
            return x
        import scipy.linalg  # lazy: start-up (issue #14 item 1); only large systems use it

        matrix = self.matrix
        if self._lu64 is None:
            x = scipy.linalg.lu_solve(self._lu32, rhs.astype(np.float32), check_finite=False).astype(float)
            scale = np.abs(matrix).sum(axis=1).max() * np.abs(x).max() + np.abs(rhs).max()
            target = 4.0 * np.finfo(float).eps * scale
            for _ in range(_REFINE_STEPS):
                residual = rhs - matrix @ x
                if np.abs(residual).max() <= target:
                    return x
                x += scipy.linalg.lu_solve(self._lu32, residual.astype(np.float32), check_finite=False)
            self._lu64 = _factor(matrix)
        return scipy.linalg.lu_solve(self._lu64, rhs, check_finite=False)


def factorise(matrix: np.ndarray) -> Factor | None:
    """A kept :class:`Factor` of ``matrix``, or None where a small system has no LAPACK handle
    (:func:`rolling_cli.solver.lapack.available`) or the matrix is empty: callers then use
    :func:`solve_dense`. Raises ``numpy.linalg.LinAlgError`` for an exactly singular matrix."""
    from . import lapack

    if matrix.shape[0] == 0 or (matrix.shape[0] < MIXED_PRECISION_SIZE and not lapack.available()):
        return None
    return Factor(matrix)


def _index(idx: np.ndarray):
    """A slice when the index set is one contiguous run (the usual contact or adhesion zone), else the
    index array: slicing a block is a view, several times cheaper than a fancy-index gather."""
    if idx.size and idx[-1] - idx[0] + 1 == idx.size:
        return slice(int(idx[0]), int(idx[-1]) + 1)
    return idx


def block(matrix: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """matrix[rows][:, cols] for index arrays (views where both index sets are contiguous runs)."""
    r, c = _index(rows), _index(cols)
    if isinstance(r, slice) and isinstance(c, slice):
        return matrix[r, c]
    if isinstance(r, slice):
        return matrix[r][:, c]
    if isinstance(c, slice):
        return matrix[r, c]
    return matrix[np.ix_(r, c)]
