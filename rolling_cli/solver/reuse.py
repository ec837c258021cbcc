"""An LU factorisation reused across Newton steps whose matrices differ a little.

With a velocity-dependent friction law every Newton step solves a dense system
over all contact nodes (:mod:`rolling_cli.solver.velocity`), and from one step
to the next only the slip rows' gains h_i = |lambda_n| |V| (-mu'(s_a)), the
bound's mu(s_a) and the odd node's state change. The LU of an earlier step is
then a close preconditioner of the present matrix: GMRES
(:func:`rolling_cli.solver.krylov.gmres`, right-preconditioned by that LU,
started from its solution) reaches the accuracy of a fresh LU in 3-8
iterations, each a product by the matrix and a pair of triangular solves
(O(n^2)), where a fresh LU costs O(n^3). The result is the solution of the
present matrix to the residual a direct solve leaves (max |b - A x| <=
4 eps (max row sum |A| max |x| + max |b|), the target of
:func:`rolling_cli.solver.linalg.solve_dense`), so a Newton step is the same
step whichever way it was solved: only the cost changes, never the iterates
beyond round-off. When GMRES does not reach that target within
:data:`MAX_ITERATIONS` (the matrix moved too far: the node states changed in
many rows, or the slip speeds far) the matrix is factorised afresh and that LU kept instead.

One factorisation is kept per process (the last one), with the identity of the
contact system it belongs to (a weak reference) and the layout of its unknowns
(``key``): a step of another system or another set of unknowns factorises
afresh. Small systems (below :data:`REUSE_SIZE` unknowns) are always
factorised afresh: their LU costs less than a GMRES iteration's overhead. Large
ones (from :data:`~rolling_cli.solver.linalg.MIXED_PRECISION_SIZE` unknowns)
keep a single-precision LU, as :func:`~rolling_cli.solver.linalg.solve_dense`
factorises them, and even their first solve is GMRES on it (flexible GMRES takes
an inexact preconditioner: the iterative refinement of solve_dense, with Krylov
acceleration).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from . import krylov
from .linalg import _SINGULAR, MIXED_PRECISION_SIZE, solve_dense

#: Systems with fewer unknowns are factorised afresh every time (an LU of 100 unknowns costs
#: ~0.2 ms, a preconditioned GMRES iteration ~0.1 ms plus its set-up).
REUSE_SIZE = 200

#: GMRES iterations tried on an earlier LU before factorising afresh: one per
#: :data:`UNKNOWNS_PER_ITERATION` unknowns, within [:data:`MIN_ITERATIONS`, :data:`MAX_ITERATIONS`].
#: An iteration (a product by A, a pair of triangular solves) costs O(n^2), a fresh LU O(n^3):
#: measured on 2-core x86_64, 0.2-0.35 ms against 2.7-5 ms at 400 unknowns, 1.2 ms against 31 ms
#: at 800, so a failed attempt costs about the LU it tried to save.
UNKNOWNS_PER_ITERATION = 32
MIN_ITERATIONS = 8
MAX_ITERATIONS = 40


@dataclass(frozen=True)
class _Kept:
    """The kept factorisation: its owner (weak), the unknowns' layout, LAPACK's LU and pivots (of
    A, or of A^T for a matrix in row order: ``trans`` 1; in single precision from
    :data:`~rolling_cli.solver.linalg.MIXED_PRECISION_SIZE` unknowns), and |A| of the matrix it
    factorised (the rows' scales of the target)."""

    owner: weakref.ref
    key: tuple
    lu: np.ndarray
    pivots: np.ndarray
    trans: int
    magnitude: np.ndarray

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """A_kept^-1 rhs (in the LU's precision, returned in double)."""
        from scipy.linalg import lapack

        if self.lu.dtype == np.float32:
            return lapack.sgetrs(self.lu, self.pivots, rhs.astype(np.float32), trans=self.trans)[0].astype(float)
        return lapack.dgetrs(self.lu, self.pivots, rhs, trans=self.trans)[0]


_kept: _Kept | None = None


def solve(matrix: np.ndarray, rhs: np.ndarray, owner: object, key: tuple, record: dict | None = None) -> np.ndarray:
    """x with ``matrix`` @ x = ``rhs`` to the accuracy of a direct solve (module docstring).

    ``owner`` is the object the matrix belongs to (its contact system) and ``key`` the layout of
    the unknowns (hashable); the kept LU is tried only for the same owner and key. ``record``
    (a dict, optional) receives ``linear_solver``: "dense LU" or "reused LU + GMRES" (the step's
    history column) and ``reuse_iterations`` (GMRES iterations, 0 for a fresh LU)."""
    global _kept
    size = matrix.shape[0]
    record = {} if record is None else record
    record.update(linear_solver="dense LU", reuse_iterations=0)
    if size < REUSE_SIZE:
        return solve_dense(matrix, rhs)
    kept = _kept
    if kept is not None and kept.owner() is owner and kept.key == key:
        found = _refined(matrix, rhs, kept)
        if found is not None:
            record.update(linear_solver="reused LU + GMRES", reuse_iterations=found[1])
            return found[0]
    fresh = _factor(matrix, owner, key)
    if fresh is None or fresh.lu.dtype == np.float32:  # refined to double precision by the same GMRES
        found = None if fresh is None else _refined(matrix, rhs, fresh)
        if fresh is None or found is None:  # the single-precision LU does not serve: as solve_dense
            _kept = None
            return solve_dense(matrix, rhs)
        x = found[0]
    else:
        x = fresh.solve(rhs)
    if not np.all(np.isfinite(x)):  # an exactly singular pivot
        raise np.linalg.LinAlgError(_SINGULAR)
    _kept = fresh
    return x


def _factor(matrix: np.ndarray, owner: object, key: tuple) -> _Kept | None:
    """The LU of ``matrix`` (single precision from MIXED_PRECISION_SIZE unknowns, as
    :func:`~rolling_cli.solver.linalg.solve_dense`, None where that one is singular); raises
    LinAlgError for an exactly singular matrix in double precision."""
    from scipy.linalg import lapack  # lazy: start-up (issue #14 item 1)

    from .. import blas

    blas.settle()  # scipy's BLAS, perhaps loaded just now, on the command's threads
    # LAPACK works on columns: a matrix in row order is factorised as its transpose (a view, no copy)
    trans = 0 if matrix.flags.f_contiguous else 1
    columns = matrix if trans == 0 else matrix.T
    if matrix.shape[0] >= MIXED_PRECISION_SIZE:
        lu, pivots, info = lapack.sgetrf(columns.astype(np.float32, order="F"))
        magnitude = np.abs(matrix).astype(np.float32)
    else:
        lu, pivots, info = lapack.dgetrf(columns)
        magnitude = np.abs(matrix)
    if info != 0:
        if lu.dtype == np.float32:
            return None
        raise np.linalg.LinAlgError(_SINGULAR)
    return _Kept(weakref.ref(owner), key, lu, pivots, trans, magnitude)


def _refined(matrix: np.ndarray, rhs: np.ndarray, kept: _Kept) -> tuple[np.ndarray, int] | None:
    """(x, GMRES iterations) by GMRES on the kept LU, or None when it does not reach the target.

    The target is componentwise, as a direct solve's backward error: |b - A x|_i <= 4 eps
    (sum_j |A_ij| |x_j| + |b_i|) for every row i (Oettli-Prager), with |A| of the kept matrix
    (within a few per cent of the present one) and x the kept LU's first solution. The rows of
    the Newton systems differ in scale by orders of magnitude (penalty-scaled gap rows, unit
    slip rows, the load and force rows): a target on the largest residual alone lets the small
    rows stay inaccurate, and Newton then stalls just above its tolerance (measured: the coupled
    dissimilar case of tests/test_friction_laws.py at 2.5e-10 against 1e-10). So GMRES solves the
    rows divided by these scales, D A x = D b, preconditioned by (D A_kept)^-1 = LU^-1 D^-1."""
    first = kept.solve(rhs)
    if not np.all(np.isfinite(first)):
        return None
    scale = (kept.magnitude @ np.abs(first).astype(kept.magnitude.dtype)).astype(float) + np.abs(rhs)
    if not np.all(scale > 0.0):
        return None
    d = 1.0 / scale
    result = krylov.gmres(
        lambda v: d * (matrix @ v),
        d * rhs,
        lambda v: kept.solve(v / d),
        4.0 * np.finfo(float).eps,
        start=first,
        max_iterations=int(np.clip(matrix.shape[0] // UNKNOWNS_PER_ITERATION, MIN_ITERATIONS, MAX_ITERATIONS)),
    )
    return (result.x, result.iterations) if result.converged else None


def release() -> None:
    """Drop the kept factorisation (its memory: n^2 floats)."""
    global _kept
    _kept = None
