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
with period 2 pi / h: P is taken at Gauss-Legendre nodes of one period
(:func:`_spectrum`, by FFTs), and the weight summed over all periods in closed
form (digamma functions, :func:`_period_sum`, evaluated by their recurrence and
asymptotic series, :func:`_digamma_difference`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

#: Gauss-Legendre points per panel of one period of P(k).
PANEL_POINTS = 12


@functools.lru_cache(maxsize=1)
def _gauss() -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1] (:data:`PANEL_POINTS` of them; computed once)."""
    return np.polynomial.legendre.leggauss(PANEL_POINTS)


def _spectrum(h: float, p: np.ndarray, ell: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes k [1/length] and weights over one period [0, 2 pi / h), and the
    columns of P(k) = sum_j p_j exp(-i k j h) there for the columns of ``p`` (n, c).

    Panels of 2 pi / (n h) (at most one oscillation of |P|^2): on every panel but the first the
    Gauss point t_g gives P by one FFT of p_j exp(-i pi j (1 + t_g) / n) (all points in one
    batched FFT); the first panel is cut geometrically down to 1e-4 / max(ell, n h), resolving
    the weight's peak at k = 1/ell, and P is summed directly there."""
    n = p.shape[0]
    step = 2.0 * np.pi / (n * h)
    t, wt = _gauss()
    j = np.arange(n)
    k_uniform = (np.arange(1, n)[:, None] + 0.5 + 0.5 * t[None, :]) * step  # (panel, point)
    shifted = p[None, :, :] * np.exp(-1j * np.pi * np.outer(1.0 + t, j) / n)[:, :, None]  # (point, j, c)
    values = np.fft.fft(shifted, axis=1)[:, 1:, :].transpose(1, 0, 2)  # (panel, point, c)
    small = step * 0.5 ** np.arange(0, 60)
    small = np.concatenate([[0.0], small[small > 1e-4 / max(ell, n * h)][::-1]])
    lo, hi = small[:-1, None], small[1:, None]
    k_small = (0.5 * (hi + lo) + 0.5 * (hi - lo) * t[None, :]).ravel()
    w_small = (0.5 * (hi - lo) * wt[None, :]).ravel()
    v_small = _small_spectrum(k_small, j * h, p)
    k = np.concatenate([k_small, k_uniform.ravel()])
    w = np.concatenate([w_small, np.tile(0.5 * step * wt, n - 1)])
    return k, w, np.concatenate([v_small, values.reshape(-1, p.shape[1])])


#: k x_j at most this (over the loaded nodes) for :func:`_small_spectrum`'s series, and its terms
#: (1 / 20! < 1e-18).
TAYLOR_PHASE = 1.0
TAYLOR_TERMS = 20


def _small_spectrum(k: np.ndarray, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """sum_j p_j exp(-i k x_j) for wavenumbers k [1/length], positions x >= 0 [length] and the
    columns of p (n, c): by the power series of the exponential where k max(x) <= :data:`TAYLOR_PHASE`
    (coefficients: the moments sum_j (x_j / X)^m p_j, X = max(x); most of the geometric panels below
    the first period panel), by real cosines and sines elsewhere."""
    out = np.empty((k.size, p.shape[1]), dtype=complex)
    span = float(x.max()) if x.size else 0.0
    series = k * span <= TAYLOR_PHASE
    if series.any() and span > 0.0:
        m = np.arange(TAYLOR_TERMS)
        moments = np.vander(x / span, TAYLOR_TERMS, increasing=True).T @ p  # (m, c)
        factorial = np.array([math.factorial(int(i)) for i in m], dtype=float)
        coefficients = (-1j * (k[series] * span))[:, None] ** m[None, :] / factorial  # (k, m): (-i k X)^m / m!
        out[series] = coefficients @ moments
    else:
        series[:] = False
    phase = np.outer(k[~series], x)
    out[~series] = np.cos(phase) @ p - 1j * (np.sin(phase) @ p)  # exp(-i k x_j) @ p, real transcendentals
    return out


def loss_integrals(h: float, p_n: np.ndarray, t: np.ndarray, ell: float) -> tuple[float, float]:
    """(int_0^inf (|p_n~|^2 + |t~|^2) w dk, int_0^inf Im(conj(t~) p_n~) w dk), w = k / (1 + k^2 ell^2),
    for nodal tractions [stress] on a uniform grid of constant elements of length h [length]
    (nodes j h from the first loaded one); ``ell`` > 0 [length]. Units stress^2 length."""
    p_n, t = np.asarray(p_n, float), np.asarray(t, float)
    loaded = np.flatnonzero((p_n != 0.0) | (t != 0.0))
    if loaded.size == 0:
        return 0.0, 0.0
    p_n, t = p_n[loaded[0] : loaded[-1] + 1], t[loaded[0] : loaded[-1] + 1]
    k, wk, values = _spectrum(h, np.stack([p_n, t], axis=1), ell)
    fn, ft = values[:, 0], values[:, 1]
    direct, cross = np.abs(fn) ** 2 + np.abs(ft) ** 2, np.imag(np.conj(ft) * fn)
    weight = wk * _period_sum(k, h, ell)
    return float(direct @ weight), float(cross @ weight)


def _period_sum(k: np.ndarray, h: float, ell: float) -> np.ndarray:
    """sum_{r >= 0} (h sinc(k_r h / 2))^2 k_r / (1 + k_r^2 ell^2), k_r = k + 2 pi r / h [length], for
    0 < k < 2 pi / h: with sin^2(k_r h / 2) = sin^2(k h / 2) and the partial fractions
    1/(k (1 + k^2 ell^2)) = 1/k - Re 1/(k - i/ell), the sum over r >= 1 is the digamma difference
    (Re psi(1 + (k - i/ell)/P) - psi(1 + k/P)) / P, P = 2 pi / h (exact, no tail), evaluated at
    every k by :func:`_digamma_difference`."""
    period = 2.0 * np.pi / h
    beta = 1.0 / (ell * period)
    first = 1.0 / (k * (1.0 + (k * ell) ** 2))
    rest = _digamma_difference(k / period, beta) / period
    return 4.0 * np.sin(0.5 * k * h) ** 2 * (first + rest)


#: Recurrence steps and Bernoulli terms of :func:`_digamma_difference`: psi(z) = psi(z + N) -
#: sum_{m < N} 1/(z + m), and the asymptotic series of psi at |z + N| >= N + 1 = 11, whose first
#: neglected term, B_14 / (14 w^14), is below 3e-16.
DIGAMMA_SHIFT = 10
_BERNOULLI = (1.0 / 6.0, -1.0 / 30.0, 1.0 / 42.0, -1.0 / 30.0, 5.0 / 66.0, -691.0 / 2730.0)


def _digamma_difference(x: np.ndarray, beta: float) -> np.ndarray:
    """Re psi(1 + x - i beta) - psi(1 + x) for x >= 0, beta >= 0 [-], vectorised: the recurrence
    to w = 1 + x + N (- i beta) and the asymptotic series there (:data:`DIGAMMA_SHIFT`), the two
    arguments' series subtracted term by term in real arithmetic (u = 1 + x + m, U = 1 + x + N):
    Re 1/(u - i beta) - 1/u = -beta^2 / (u (u^2 + beta^2)), Re ln(U - i beta) - ln U =
    ln(1 + beta^2/U^2) / 2, the 1/(2w) and first Bernoulli terms' differences in closed form, the
    higher ones from the real and imaginary parts of (U - i beta)^-2 and its powers. No complex
    arrays; within 5e-15 absolute of the complex series' difference, and ~1e-9 relative at beta =
    1e-6 (against -beta^2/2 psi''(1 + x)), where subtracting the two complex series lost 6e-3."""
    u = 1.0 + np.asarray(x, dtype=float)
    b2 = float(beta) ** 2
    total = np.zeros_like(u)
    for m in range(DIGAMMA_SHIFT):  # - sum_m [Re 1/(z + m) - 1/(x + 1 + m)]
        v = u + m
        total += b2 / (v * (v * v + b2))
    big = u + DIGAMMA_SHIFT  # U
    modulus = big * big + b2  # |w|^2
    total += 0.5 * np.log1p(b2 / (big * big)) + 0.5 * b2 / (big * modulus)
    square = big * big
    re, im = (square - b2) / (modulus * modulus), 2.0 * big * float(beta) / (modulus * modulus)  # w^-2
    real = 1.0 / square
    total += _BERNOULLI[0] / 2.0 * b2 * (3.0 * square + b2) / (square * modulus * modulus)  # Re w^-2 - U^-2 exactly
    power_re, power_im, real_power = re, im, real
    for order, bernoulli in enumerate(_BERNOULLI[1:], start=2):  # |U^-2k| <= 11^-4: round-off ~1e-20 absolute
        power_re, power_im = power_re * re - power_im * im, power_re * im + power_im * re
        real_power = real_power * real
        total -= bernoulli / (2 * order) * (power_re - real_power)
    return total


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
