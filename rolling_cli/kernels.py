"""Integrals of polynomial shape functions against the log and sign kernels.

On a straight element mapped to xi in [-1, 1], the half-plane influence and the
singular part of the BEM single-layer kernel need

    A_m(c) = int_{-1}^{1} xi^m ln|xi - c| d xi,
    G_m(c) = int_{-1}^{1} xi^m sgn(c - xi) d xi,         m = 0, 1, 2,

for a collocation point at local coordinate c (any real number). Both are done
in closed form; for |c| > 2 the log integral switches to 12-point Gauss-Legendre
on the smooth integrand ln|c| + log1p(-xi/c), which avoids the cancellation of
the closed form far from the element (Gauss error < 1e-14 there: the nearest
singularity lies outside the Bernstein ellipse of parameter 3.7).
Arrays broadcast; results are dimensionless.
"""

from __future__ import annotations

import numpy as np
from scipy.special import xlogy

_FAR = 2.0
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(12)


def _antiderivative(u: np.ndarray, power: int) -> np.ndarray:
    """F_j(u) = int_0^u t^j ln|t| dt = u^(j+1)/(j+1) (ln|u| - 1/(j+1))."""
    k = power + 1.0
    return (xlogy(u**k, np.abs(u)) - u**k / k) / k


def log_moments(c: np.ndarray) -> np.ndarray:
    """A_m(c) for m = 0, 1, 2; returns an array of shape c.shape + (3,)."""
    c = np.asarray(c, dtype=float)
    out = np.empty(c.shape + (3,))
    near = np.abs(c) <= _FAR
    if np.any(near):
        cn = c[near]
        u1, u0 = 1.0 - cn, -1.0 - cn
        f0 = _antiderivative(u1, 0) - _antiderivative(u0, 0)
        f1 = _antiderivative(u1, 1) - _antiderivative(u0, 1)
        f2 = _antiderivative(u1, 2) - _antiderivative(u0, 2)
        out[near, 0] = f0
        out[near, 1] = f1 + cn * f0
        out[near, 2] = f2 + 2.0 * cn * f1 + cn**2 * f0
    far = ~near
    if np.any(far):
        cf = c[far][:, None]
        values = np.log(np.abs(cf)) + np.log1p(-_GAUSS_X[None, :] / cf)
        powers = _GAUSS_X[None, :, None] ** np.arange(3)[None, None, :]
        out[far] = np.einsum("pg,g,gm->pm", values, _GAUSS_W, powers[0])
    return out


def sign_moments(c: np.ndarray) -> np.ndarray:
    """G_m(c) = int_{-1}^{1} xi^m sgn(c - xi) d xi for m = 0, 1, 2; shape c.shape + (3,)."""
    t = np.clip(np.asarray(c, dtype=float), -1.0, 1.0)[..., None]
    k = np.arange(3) + 1.0
    return (2.0 * t**k - (-1.0) ** k - 1.0) / k
