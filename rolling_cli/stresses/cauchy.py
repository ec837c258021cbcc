"""Cauchy integrals of piecewise-polynomial densities on a straight line, in closed form.

Both stress models reduce to two integrals per density f on a line (a
half-plane's surface, or one straight side of a BEM body) with coordinate s
along it, at a point omega = s_p + i d on the side d > 0:

    A(omega) = int f(s) / (omega - s) ds,      B(omega) = int f(s) / (omega - s)^2 ds = -A'(omega).

f is a polynomial F_e(s) = sum_m c[e, m] (s - m_e)^m (degree <= 2, m_e the mid-point)
on each element [s_e, t_e]. Per element,
int F_e/(omega - s) ds = F_e(omega) [log(omega - s_e) - log(omega - t_e)] - 2 h_e (c1 + c2 (omega - m_e)),
h_e the half-length. Summed over the elements the logarithms gather at the
distinct element ends v_k ("edges"): A(omega) = sum_k log(omega - v_k) J_k(omega)
+ alpha + beta omega, with J_k the jump of the interpolation at v_k (a quadratic
in omega - v_k; small for a smooth density). So only one logarithm and one
reciprocal are evaluated per (point, edge) pair, in real arithmetic
(log|w| and atan2), and everything else is a matrix product with a few vectors
per density (LAPACK). With d > 0, arg(omega - v_k) lies in (0, pi) and is
continuous along the line, so the principal logarithm is the right branch; at
d = 0 the same formula gives the principal value (arg = pi left of the
point, 0 right of it: the limit from the side d > 0), and a point exactly on
an edge gets the finite part (arg = pi/2, log 0 dropped).

Rounding: the jumps are expanded in powers of omega, so it is bounded by
machine epsilon times sum_k |log(omega - v_k)| |J_k| (|omega| + |v_k|)^2, below
1e-9 of the traction scale for fields a few contact widths across; centre the
coordinates near the points.
"""

from __future__ import annotations

import numpy as np

#: (point, edge) pairs per chunk of the vectorised evaluation (bounds memory to ~100 MB).
CHUNK_PAIRS = 1_500_000


def line_integrals(
    s: np.ndarray, d: np.ndarray, starts: np.ndarray, ends: np.ndarray, coefficients: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """A [density] and B [density/length] (module docstring) at points (s, d), d >= 0.

    ``starts``, ``ends`` (E,) element ends along the line (start < end), ``coefficients``
    (D, E, 3) real or complex, about each element's mid-point. Returns two complex
    arrays (P, D). B is finite at d = 0 except that a point on an edge gets 0
    for its reciprocal there (B is only used multiplied by d).
    """
    s = np.asarray(s, dtype=float)
    d = np.asarray(d, dtype=float) + 0.0  # -0.0 -> +0.0: the line is approached from d > 0
    coeff = np.asarray(coefficients)
    nd, ne = coeff.shape[0], coeff.shape[1]
    mids, half = 0.5 * (starts + ends), 0.5 * (ends - starts)
    edges, where = np.unique(np.concatenate([starts, ends]), return_inverse=True)
    c0, c1, c2 = coeff[..., 0], coeff[..., 1], coeff[..., 2]  # (D, E)

    def about(offset):  # coefficients of F_e(v + w) in powers of w, offset = v - m_e
        return np.stack([c0 + c1 * offset + c2 * offset**2, c1 + 2.0 * c2 * offset, c2], axis=-1)

    jumps = np.zeros((nd, edges.size, 3), dtype=coeff.dtype)
    jumps[:, where[:ne]] += about(-half)  # starts are distinct, so are ends: no repeated index per update
    jumps[:, where[ne:]] -= about(half)
    j0, j1, j2 = (jumps[..., m].T for m in range(3))  # (K, D)
    v = edges[:, None]
    log_vectors = np.concatenate([j0 - j1 * v + j2 * v * v, j1 - 2.0 * j2 * v, j2], axis=1)  # (K, 3D)
    log_real = np.concatenate([log_vectors.real, log_vectors.imag], axis=1)
    j0_real = np.concatenate([j0.real, j0.imag], axis=1)
    alpha = -(2.0 * half * (c1 - c2 * mids)).sum(axis=1)  # (D,)
    beta = -(2.0 * half * c2).sum(axis=1)
    sum_j1, sum_j2, sum_j2v = j1.sum(axis=0), j2.sum(axis=0), (j2 * v).sum(axis=0)
    A = np.empty((s.size, nd), dtype=complex)
    B = np.empty((s.size, nd), dtype=complex)
    step = max(1, CHUNK_PAIRS // edges.size)
    for start in range(0, s.size, step):
        part = slice(start, min(s.size, start + step))
        X = s[part, None] - edges[None, :]
        Z = np.broadcast_to(d[part, None], X.shape)
        rho2 = X * X + Z * Z
        at_edge = rho2 == 0.0
        safe = np.where(at_edge, 1.0, rho2)
        lam = _complex(0.5 * np.log(safe) @ log_real, 3 * nd)
        theta = _complex(np.where(at_edge, 0.5 * np.pi, np.arctan2(Z, X)) @ log_real, 3 * nd)
        ell = lam + 1j * theta  # sum_k log(omega - v_k) times the three vectors
        recip = _complex(np.where(at_edge, 0.0, X) / safe @ j0_real, nd) - 1j * _complex(Z / safe @ j0_real, nd)
        omega = (s[part] + 1j * d[part])[:, None]
        l0, l1, l2 = ell[:, :nd], ell[:, nd : 2 * nd], ell[:, 2 * nd :]
        A[part] = l0 + omega * (l1 + omega * l2) + alpha + beta * omega
        B[part] = -(recip + sum_j1 + omega * sum_j2 - sum_j2v + l1 + 2.0 * omega * l2 + beta)
    return A, B


def _complex(stacked: np.ndarray, width: int) -> np.ndarray:
    """Columns [real parts | imaginary parts] -> complex (a real matrix times complex vectors)."""
    return stacked[:, :width] + 1j * stacked[:, width:]
