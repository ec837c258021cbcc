"""LU of a banded matrix bordered by a few dense rows and columns (the Krylov preconditioner).

    M = [K U]    K banded (LAPACK gbtrf, O(N b^2)), U and V a few border columns and rows,
        [V D]    D their crossing; the Schur complement S = D - V K^-1 U is dense but tiny.

A solve is one banded triangular solve (gbtrs, O(N b)) and the small border
system. ``single=True`` factorises and solves K in single precision (s-gbtrf/
s-gbtrs: 3-5x faster, half the memory), for a preconditioner. When K (or S) is singular, :class:`BorderedBandLU` raises
``numpy.linalg.LinAlgError``; :func:`sparse_lu` factorises the whole matrix
(SuperLU, minimum degree ordering) instead.
"""

from __future__ import annotations

import numpy as np


class BorderedBandLU:
    """The factorised M of the module docstring.

    ``band``: K in LAPACK's band storage with room for the fill, shape
    (2 ``lower`` + ``upper`` + 1, N): K[i, j] at ``band[lower + upper + i - j, j]``
    (overwritten); ``columns`` U (N, b), ``rows`` V (b, N), ``corner`` D (b, b).
    """

    def __init__(self, band: np.ndarray, lower: int, upper: int, columns, rows, corner, single: bool = False) -> None:
        from scipy.linalg.lapack import dgbtrf, sgbtrf

        from .. import blas

        blas.settle()  # scipy's BLAS, perhaps loaded just now, on the command's threads

        self.lower, self.upper = lower, upper
        self.single = single
        if single:
            band = np.asfortranarray(band, dtype=np.float32)
        self.factor, self.pivots, info = (sgbtrf if single else dgbtrf)(band, lower, upper, overwrite_ab=1)
        if info != 0:
            raise np.linalg.LinAlgError(f"singular banded part (LAPACK gbtrf info {info})")
        self.rows = np.asarray(rows, dtype=float)
        nb = self.rows.shape[0]
        columns = np.asarray(columns, dtype=float)
        self.inner = self._band_solve(columns) if nb else columns  # K^-1 U
        self.schur = np.asarray(corner, dtype=float) - self.rows @ self.inner
        if nb and not np.linalg.cond(self.schur) < 1e14:
            raise np.linalg.LinAlgError("singular border block")

    def _band_solve(self, rhs: np.ndarray) -> np.ndarray:
        from scipy.linalg.lapack import dgbtrs, sgbtrs

        if self.single:
            x, info = sgbtrs(self.factor, self.lower, self.upper, np.asarray(rhs, dtype=np.float32), self.pivots)
            x = x.astype(float)
        else:
            x, info = dgbtrs(self.factor, self.lower, self.upper, rhs, self.pivots)
        if info != 0:  # an argument error: a programming error, not a property of the matrix
            raise ValueError(f"LAPACK gbtrs info {info}")
        return x

    def solve(self, core: np.ndarray, border: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(x_core, x_border) with M [x_core; x_border] = [core; border]."""
        y = self._band_solve(core)
        if not border.size:
            return y, border
        y_border = np.linalg.solve(self.schur, border - self.rows @ y)
        return y - self.inner @ y_border, y_border


class SparseLU:
    """SuperLU of a matrix given as COO entries (the fallback of :class:`BorderedBandLU`)."""

    def __init__(self, rows, cols, values, size: int) -> None:
        import scipy.sparse
        import scipy.sparse.linalg

        matrix = scipy.sparse.csc_matrix((values, (rows, cols)), shape=(size, size))
        try:
            self._lu = scipy.sparse.linalg.splu(matrix, permc_spec="MMD_AT_PLUS_A")
        except RuntimeError as err:  # SuperLU: "Factor is exactly singular"
            raise np.linalg.LinAlgError(f"singular Newton system ({err})") from None

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """M^-1 rhs."""
        return self._lu.solve(rhs)


def band_entries(band: np.ndarray, lower: int, upper: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """COO (rows, cols, values) of the nonzero entries of K in LAPACK band storage (before factorising)."""
    offset, col = np.nonzero(band[lower:])
    row = offset - upper + col
    return row, col, band[lower:][offset, col]
