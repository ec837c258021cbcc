"""Restarted flexible GMRES with right preconditioning (the matrix-free Newton steps).

:func:`gmres` solves A x = b for an operator given as a function, with a
preconditioner M^-1 ~ A^-1 applied on the right: it iterates on A M^-1 y = b
and returns x, so the residual it minimises is the true residual b - A x, not
a preconditioned one, and the stop test is on what the caller needs. The
preconditioned directions z_k = M^-1 v_k are kept and x is built from them
(flexible GMRES, Saad 1993): the Arnoldi relation A Z = V H holds whatever M^-1
does, so a preconditioner applied in single precision (not exactly linear)
costs no accuracy. The Arnoldi basis is orthogonalised by classical
Gram-Schmidt applied twice (matrix-vector products, orthogonal to working
precision), the residual norm follows from Givens rotations. After each cycle
(at most ``restart`` iterations) the true residual is recomputed, since the
recurrence drifts from it in floating point; the solve stops when the true
residual's largest component is at most ``target``, and gives up when a cycle
no longer halves it near the target (round-off), barely reduces it, or the
iterations run out.

Pure numpy; units are the caller's (the Newton system's, scaled to be
dimensionless).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: A cycle that does not halve the largest residual ends the solve when that residual is within
#: ROUNDOFF_ZONE x ``target`` (the round-off level: more cycles would not help) or above SLOW x
#: the residual before it (no progress); far from the target a slower cycle is followed by another.
ROUNDOFF_ZONE = 10.0
SLOW = 0.9

#: Iterations between checks of the residual's largest component inside a cycle (the 2-norm
#: the recurrence gives bounds it loosely: up to sqrt(N) times).
CHECK_EVERY = 5

#: Iterations per GMRES cycle (the Arnoldi basis holds RESTART + 1 vectors).
RESTART = 100


@dataclass(frozen=True)
class KrylovResult:
    """The solution ``x``, the Krylov iterations taken, the final true residual max|b - A x|
    and whether it met the target."""

    x: np.ndarray
    iterations: int
    residual: float
    converged: bool


def gmres(
    apply: Callable[[np.ndarray], np.ndarray],
    rhs: np.ndarray,
    precondition: Callable[[np.ndarray], np.ndarray],
    target: float,
    start: np.ndarray | None = None,
    restart: int = RESTART,
    max_iterations: int = 600,
) -> KrylovResult:
    """x with max|rhs - apply(x)| <= ``target`` (see the module docstring); ``start`` is the first
    guess (zero if None)."""
    x = np.zeros_like(rhs) if start is None else np.array(start, dtype=float)
    residual = rhs - apply(x) if start is not None else rhs.copy()
    size = float(np.max(np.abs(residual), initial=0.0))
    taken = 0
    while size > target and taken < max_iterations:
        steps = min(restart, max_iterations - taken)
        correction, used = _cycle(apply, residual, precondition, target, steps)
        taken += used
        trial = x + correction
        found = rhs - apply(trial)
        previous, now = size, float(np.max(np.abs(found)))
        if now >= previous:  # a cycle that made things worse (round-off): keep what was there
            break
        x, residual, size = trial, found, now
        if size > 0.5 * previous and (size <= ROUNDOFF_ZONE * target or size > SLOW * previous):
            break  # no longer halving near the target (the round-off level), or barely moving
    return KrylovResult(x, taken, size, size <= target)


def _cycle(apply, residual: np.ndarray, precondition, target: float, steps: int) -> tuple[np.ndarray, int]:
    """One GMRES cycle from zero for A d = residual: the correction d and the iterations used.

    Stops when the estimated 2-norm of the residual is below ``target`` (which bounds its
    largest component), when the largest component itself is (checked every
    :data:`CHECK_EVERY` iterations once the 2-norm allows it, :func:`_largest_residual`), or
    after ``steps`` iterations.
    """
    beta = float(np.linalg.norm(residual))
    basis = np.empty((steps + 1, residual.size))
    directions = np.empty((steps, residual.size))  # M^-1 of each basis vector (flexible GMRES)
    basis[0] = residual / beta
    hessenberg = np.zeros((steps + 1, steps))
    cosines = np.zeros(steps)
    sines = np.zeros(steps)
    g = np.zeros(steps + 1)
    g[0] = beta
    used = 0
    for k in range(steps):
        directions[k] = precondition(basis[k])
        w = apply(directions[k])
        h = basis[: k + 1] @ w
        w -= h @ basis[: k + 1]
        again = basis[: k + 1] @ w  # the second pass of Gram-Schmidt
        w -= again @ basis[: k + 1]
        h += again
        norm = float(np.linalg.norm(w))
        for j in range(k):  # earlier rotations on the new column
            h[j], h[j + 1] = cosines[j] * h[j] + sines[j] * h[j + 1], -sines[j] * h[j] + cosines[j] * h[j + 1]
        radius = float(np.hypot(h[k], norm))
        cosines[k], sines[k] = (1.0, 0.0) if radius == 0.0 else (h[k] / radius, norm / radius)
        hessenberg[: k + 1, k] = h[: k + 1]
        hessenberg[k, k] = radius
        g[k + 1] = -sines[k] * g[k]
        g[k] = cosines[k] * g[k]
        used = k + 1
        if norm == 0.0 or abs(g[k + 1]) <= target:
            break
        basis[k + 1] = w / norm
        if used % CHECK_EVERY == 0 and abs(g[k + 1]) <= target * np.sqrt(residual.size):
            if _largest_residual(basis[: k + 2], cosines[:used], sines[:used], g[k + 1]) <= target:
                break
    y = _back_substitute(hessenberg[:used, :used], g[:used])
    return y @ directions[:used], used


def _largest_residual(basis: np.ndarray, cosines: np.ndarray, sines: np.ndarray, last: float) -> float:
    """max|r_k| of the cycle's current least-squares residual r_k = V_{k+1} Q_k^T (0, ..., 0, g_{k+1})
    (the Arnoldi relation A Z_k = V_{k+1} H_k; Q_k the Givens rotations), without a product by A."""
    coefficients = np.zeros(basis.shape[0])
    coefficients[-1] = last
    for j in range(cosines.size - 1, -1, -1):  # Q^T: the transposed rotations, last first
        a, b = coefficients[j], coefficients[j + 1]
        coefficients[j], coefficients[j + 1] = cosines[j] * a - sines[j] * b, sines[j] * a + cosines[j] * b
    return float(np.max(np.abs(coefficients @ basis)))


def _back_substitute(upper: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Solution of the upper triangular system (the rotated Hessenberg matrix)."""
    from scipy.linalg import solve_triangular

    return solve_triangular(upper, values, lower=False, check_finite=False)
