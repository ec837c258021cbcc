"""Hysteresis power of a viscoelastic half-plane in steady rolling, from its loss compliance.

An independent route to the energy lost in a body (the solver works in real
space with the creep compliance; this works in Fourier space with the complex
compliance). A traction pattern steady in the contact frame excites the
material at the frequency omega = k |V| for the wavenumber k, where a body with
J(t) = J_g + sum_i c_i (1 - exp(-t/lambda_i)) has the loss compliance
J''(omega) = sum_i c_i omega lambda_i / (1 + omega^2 lambda_i^2). With the
surface power into the body, (p_n <= 0 the normal traction, t the tangential
traction on the body, w, u its surface displacements)

    Pi = sgn(V) |V| int [ -p_n w'(x) + t u'(x) ] dx,

the elastic (J_g) part integrates to zero, and Parseval gives, per unit |V|
(ell_i = |V| lambda_i, kappa = 2 (1 - nu^2)/pi, chi = (1 - 2 nu)(1 + nu)/2, ~ the
Fourier transform, f~(k) = int f e^(-ikx) dx):

    Pi / |V| = sum_i c_i ell_i int_0^inf [ kappa (|p_n~|^2 + |t~|^2)
                                          + (4 chi / pi) Im(conj(t~) p_n~) ] k / (1 + k^2 ell_i^2) dk   >= 0.

For piecewise-constant tractions on a uniform grid (spacing h),
p~(k) = h sinc(k h / 2) P(k) with P(k) = sum_j p_j exp(-i k x_j), periodic in k
with period 2 pi / h: P is summed directly at Gauss-Legendre nodes of one
period (:func:`_nodes`), the integral over :data:`PERIODS` periods, and the
remaining tail, where the weight is smooth against the period, added in closed
form (int_K^inf dk / (k (1 + k^2 ell^2)) = ln(1 + 1/(K ell)^2) / 2).
"""

from __future__ import annotations

import numpy as np

#: Periods of P(k) summed before the closed-form tail; Gauss-Legendre points per panel.
PERIODS = 64
PANEL_POINTS = 12


def _nodes(h: float, extent: float, ell: float) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights over one period [0, 2 pi / h) [1/length]: panels of
    2 pi / extent (at most one oscillation of |P|^2), and below the first panel geometric
    ones down to 1e-4 / max(ell, extent), which resolve the weight's peak at k = 1/ell."""
    period = 2.0 * np.pi / h
    step = 2.0 * np.pi / extent
    uniform = np.arange(0.0, period + 0.5 * step, step)
    uniform[-1] = period
    small = step * 0.5 ** np.arange(1, 60)
    small = small[small > 1e-4 / max(ell, extent)]
    edges = np.unique(np.concatenate([[0.0], small, uniform[1:]]))
    t, wt = np.polynomial.legendre.leggauss(PANEL_POINTS)
    lo, hi = edges[:-1, None], edges[1:, None]
    k = 0.5 * (hi + lo) + 0.5 * (hi - lo) * t[None, :]
    return k.ravel(), (0.5 * (hi - lo) * wt[None, :]).ravel()


def loss_integrals(h: float, p_n: np.ndarray, t: np.ndarray, ell: float) -> tuple[float, float]:
    """(int_0^inf (|p_n~|^2 + |t~|^2) w dk, int_0^inf Im(conj(t~) p_n~) w dk), w = k / (1 + k^2 ell^2),
    for nodal tractions [stress] on a uniform grid of constant elements of length h [length]
    (nodes j h from the first loaded one); ``ell`` > 0 [length]. Units stress^2 length."""
    p_n, t = np.asarray(p_n, float), np.asarray(t, float)
    loaded = np.flatnonzero((p_n != 0.0) | (t != 0.0))
    if loaded.size == 0:
        return 0.0, 0.0
    p_n, t = p_n[loaded[0] : loaded[-1] + 1], t[loaded[0] : loaded[-1] + 1]
    xj = h * np.arange(p_n.size)
    k, wk = _nodes(h, h * p_n.size, ell)
    phase = np.exp(-1j * np.outer(k, xj))  # P(k) = sum_j p_j exp(-i k x_j), periodic in k (2 pi / h)
    fn, ft = phase @ p_n, phase @ t
    direct, cross = np.abs(fn) ** 2 + np.abs(ft) ** 2, np.imag(np.conj(ft) * fn)
    period = 2.0 * np.pi / h
    kk = k[None, :] + period * np.arange(PERIODS)[:, None]
    box = h * np.sinc(kk * h / (2.0 * np.pi))  # h sin(kh/2) / (kh/2)
    weight = wk * (box**2 * kk / (1.0 + (kk * ell) ** 2)).sum(axis=0)
    # beyond PERIODS periods |p~|^2 w = 4 sin^2(kh/2) |P|^2 / (k (1 + k^2 ell^2)): the period mean of
    # 4 sin^2 |P|^2 times int_K^inf dk / (k (1 + k^2 ell^2)) = ln(1 + 1/(K ell)^2) / 2
    tail = 0.5 * np.log1p(1.0 / (period * PERIODS * ell) ** 2) / period
    sin2 = wk * 4.0 * np.sin(k * h / 2.0) ** 2
    return float(direct @ (weight + tail * sin2)), float(cross @ (weight + tail * sin2))


def body_power(h: float, p_n, t, compliances, lengths, poisson: float) -> float:
    """Hysteresis power of one viscoelastic half-plane per unit rolling speed and axial length
    [force/length]: ``compliances`` c_i [1/stress], ``lengths`` ell_i = |V| lambda_i [length],
    ``t`` the tangential traction on this body (along +x of its frame) [stress]."""
    kappa = 2.0 * (1.0 - poisson**2) / np.pi
    chi = 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson)
    total = 0.0
    for c, ell in zip(compliances, lengths, strict=True):
        if ell <= 0.0:
            continue
        direct, cross = loss_integrals(h, p_n, t, ell)
        total += c * ell * (kappa * direct + 4.0 * chi / np.pi * cross)
    return total
