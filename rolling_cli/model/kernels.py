"""Integrals of polynomial shape functions against the log and sign kernels.

On a straight element mapped to xi in [-1, 1], the half-plane influence and the
singular part of the BEM single-layer kernel need

    A_m(c) = int_{-1}^{1} xi^m ln|xi - c| d xi,
    G_m(c) = int_{-1}^{1} xi^m sgn(c - xi) d xi,         m = 0, 1, 2,

for a collocation point at local coordinate c (any real number). Both are done
in closed form; for 2 < |c| <= 4 the log integral switches to 12-point
Gauss-Legendre on the smooth integrand ln|c| + log1p(-xi/c), which avoids the
cancellation of the closed form far from the element (Gauss error < 1e-14
there: the nearest singularity lies outside the Bernstein ellipse of parameter
3.7), and for |c| > 4 to the series ln|c - xi| = ln|c| - sum_k (xi/c)^k / k
integrated term by term (14 terms in 1/c^2: truncation below 16^-14 ~ 1e-17
relative, no cancellation), the bulk of the pairs on a fine grid at a fraction
of the Gauss cost.
Arrays broadcast; results are dimensionless.
"""

from __future__ import annotations

import numpy as np

_FAR = 2.0
_SERIES = 4.0
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(12)
#: Gauss weights times xi^m, shape (12, 3), and the exact int xi^m over [-1, 1].
_GAUSS_MOMENTS = _GAUSS_W[:, None] * _GAUSS_X[:, None] ** np.arange(3)[None, :]
_POWER_INTEGRALS = np.array([2.0, 0.0, 2.0 / 3.0])
#: Far points per block of the Gauss sum (memory: 12 x this many values).
_CHUNK = 1 << 16
_TERMS = 14


def _series_coefficients() -> np.ndarray:
    """S[j, m]: A_m(c) = mu_m ln|c| - t^p_m sum_j S[j, m] s^j with t = 1/c, s = t^2, p = (2, 1, 2).

    From -int xi^m sum_k t^k xi^k / k: only k + m even survive, int xi^(m+k) = 2/(m+k+1).
    """
    j = np.arange(_TERMS, dtype=float)
    k_even = 2.0 * j + 2.0  # m = 0, 2: k = 2, 4, ...
    k_odd = 2.0 * j + 1.0  # m = 1: k = 1, 3, ...
    return np.column_stack(
        [2.0 / (k_even * (k_even + 1.0)), 2.0 / (k_odd * (k_odd + 2.0)), 2.0 / (k_even * (k_even + 3.0))]
    )


_SERIES_COEFFICIENTS = _series_coefficients()


def _far_log_moments(c: np.ndarray) -> np.ndarray:
    """A_m(c) for |c| > :data:`_SERIES` by the series (shape c.shape + (3,))."""
    t = 1.0 / c
    s = t * t
    log_c = np.log(np.abs(c))
    out = np.empty(c.shape + (3,))
    for m, scale in ((0, s), (1, t), (2, s)):
        coeffs = _SERIES_COEFFICIENTS[:, m]
        acc = np.full(c.shape, coeffs[-1])
        for coeff in coeffs[-2::-1]:  # Horner in s on contiguous arrays
            acc *= s
            acc += coeff
        acc *= scale
        out[..., m] = _POWER_INTEGRALS[m] * log_c - acc
    return out


def _antiderivative(u: np.ndarray, power: int) -> np.ndarray:
    """F_j(u) = int_0^u t^j ln|t| dt = u^(j+1)/(j+1) (ln|u| - 1/(j+1))."""
    k = power + 1.0
    magnitude = np.abs(u)
    # u^k ln|u| -> 0 as u -> 0: ln of 1 there instead of ln 0, so no warning fires (no scipy.special.xlogy)
    u_k = u**k
    return (u_k * np.log(np.where(magnitude > 0.0, magnitude, 1.0)) - u_k / k) / k


def log_moments(c: np.ndarray) -> np.ndarray:
    """A_m(c) for m = 0, 1, 2; returns an array of shape c.shape + (3,).

    The series covers the whole array first (the bulk of the pairs on a fine
    grid, with no gathering), then the few points with |c| <= 4 are overwritten.
    """
    c = np.asarray(c, dtype=float)
    series = np.abs(c) > _SERIES
    out = _far_log_moments(np.where(series, c, 2.0 * _SERIES))
    rest = np.flatnonzero(~series)
    if rest.size:
        out.reshape(-1, 3)[rest] = _near_log_moments(c.reshape(-1)[rest])
    return out


def _near_log_moments(c: np.ndarray) -> np.ndarray:
    """A_m(c) for |c| <= 4 (1-D ``c``): closed form for |c| <= 2, Gauss beyond."""
    out = np.empty(c.shape + (3,))
    near = np.abs(c) <= _FAR
    cn = c[near]
    u1, u0 = 1.0 - cn, -1.0 - cn
    f0 = _antiderivative(u1, 0) - _antiderivative(u0, 0)
    f1 = _antiderivative(u1, 1) - _antiderivative(u0, 1)
    f2 = _antiderivative(u1, 2) - _antiderivative(u0, 2)
    out[near, 0] = f0
    out[near, 1] = f1 + cn * f0
    out[near, 2] = f2 + 2.0 * cn * f1 + cn**2 * f0
    cf = c[~near]
    moments = np.empty(cf.shape + (3,))
    for start in range(0, cf.size, _CHUNK):  # bounded memory: (chunk, Gauss points) at a time
        part = cf[start : start + _CHUNK, None]
        values = np.log1p(-_GAUSS_X[None, :] / part)
        moments[start : start + _CHUNK] = values @ _GAUSS_MOMENTS + np.log(np.abs(part)) * _POWER_INTEGRALS
    out[~near] = moments
    return out


def sign_moments(c: np.ndarray) -> np.ndarray:
    """G_m(c) = int_{-1}^{1} xi^m sgn(c - xi) d xi for m = 0, 1, 2; shape c.shape + (3,)."""
    t = np.clip(np.asarray(c, dtype=float), -1.0, 1.0)[..., None]
    k = np.arange(3) + 1.0
    return (2.0 * t**k - (-1.0) ** k - 1.0) / k
