"""Plane-strain elastic layer bonded to a rigid base: its surface compliance in Fourier space.

A layer of thickness b (unit Young's modulus, Poisson ratio nu) bonded to a
rigid base, loaded on its free surface by the normal traction p_n (negative in
compression) and the tangential traction p_t (along +x). With the Fourier
transform f~(k) = int f(x) exp(-i k x) dx, its surface displacements w (into the
body) and u (along +x) are

    [w~]   [H_nn   H_nt] [p_n~]        H_nn = -2 (1 - nu^2)/|k| (kappa sinh 2t - 2t) / D
    [u~] = [H_tn   H_tt] [p_t~],       H_tt =  2 (1 - nu^2)/|k| (kappa sinh 2t + 2t) / D
                                       H_nt = H_tn = -i sgn(k) (1 + nu)/|k|
                                                     [(1 - 2 nu) kappa (cosh 2t - 1) - 2 t^2] / D

with t = |k| b, kappa = 3 - 4 nu and D = kappa cosh 2t + 2 t^2 + (1 + kappa^2)/2.
Derived from Airy's stress function (A + B z) e^(kz) + (C + D z) e^(-kz), the
surface tractions given at z = 0 and u = 0 at z = -b (the 4 x 4 system solved
in closed form; ``tests/test_viscoelastic_layer.py`` checks it against the
numerical solution of the same system, the thin-layer springs
b (1 + nu)(1 - 2 nu)/(1 - nu) and 2 (1 + nu) b at k -> 0, and the BEM layer).
For b -> inf it is the half-plane's, H_nn = -H_tt = -2 (1 - nu^2)/|k|,
H_nt = -i sgn(k) (1 + nu)(1 - 2 nu)/|k| (the log and sign kernels of
:mod:`rolling_cli.influence.halfplane`). The layer minus the half-plane
(:func:`remainder`) decays like t^2 exp(-2t); it is written in exp(-2t) so
that no large numbers cancel.

:func:`remainder_power` is the hysteresis of a viscoelastic layer beyond the
half-plane's (:mod:`rolling_cli.references.hysteresis`): per unit |V|,

    Pi_R / |V| = (1/pi) sum_i c_i ell_i int_0^inf q^2 / (1 + q^2 ell_i^2)
                 [ -R_nn |p_n~|^2 + R_tt |t~|^2 - 2 g_R Im(conj(p_n~) t~) ] dq,

R the remainder, R_nt = -i g_R (q > 0): the loss part of the complex compliance
J*(q) = J_g + sum c_i / (1 - i q b_i) acting on the layer's (Hermitian) elastic
compliance, as the half-plane's formula, whose cross term it reproduces for
R = H_hp.
"""

from __future__ import annotations

import math

import numpy as np

#: Largest t = k b kept: the remainder is ~ 4 t^2 exp(-2t) / kappa < 2e-11 of the half-plane's beyond.
T_MAX = 16.0
#: Gauss-Legendre points per wavenumber panel, and per panel far below every feature's scale.
PANEL_POINTS = 12
LOW_POINTS = 6
_PANEL_RULE = np.polynomial.legendre.leggauss(PANEL_POINTS)
_LOW_RULE = np.polynomial.legendre.leggauss(LOW_POINTS)


def transfer(k, thickness: float, poisson: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(H_nn, H_tt, g) [length/stress at unit modulus: length^2] of the layer at wavenumbers k > 0
    [1/length], H_nt = H_tn = -i g (for k < 0 the complex conjugates)."""
    k = np.asarray(k, dtype=float)
    nn, tt, g = remainder(k, thickness, poisson)
    hp_nn, hp_tt, hp_g = halfplane(k, poisson)
    return hp_nn + nn, hp_tt + tt, hp_g + g


def halfplane(k, poisson: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(H_nn, H_tt, g) of the unit-modulus half-plane at k > 0 [length^2]."""
    k = np.asarray(k, dtype=float)
    direct = 2.0 * (1.0 - poisson**2) / k
    return -direct, direct, (1.0 + poisson) * (1.0 - 2.0 * poisson) / k


def remainder(k, thickness: float, poisson: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(R_nn, R_tt, g_R): the layer's transfer matrix minus the half-plane's, k > 0 [length^2]:
    with e = exp(-2t) and D' = D e = kappa (1 + e^2)/2 + (2 t^2 + (1 + kappa^2)/2) e,

        R_nn = -2 (1 - nu^2)/k (-kappa e^2 - (2t + 2t^2 + (1 + kappa^2)/2) e) / D'
        R_tt =  2 (1 - nu^2)/k (-kappa e^2 + (2t - 2t^2 - (1 + kappa^2)/2) e) / D'
        g_R  = -(1 + nu)/k (8 (1 - 2 nu)(1 - nu)^2 + 4 (1 - nu) t^2) e / D'."""
    k = np.asarray(k, dtype=float)
    nu = poisson
    kappa = 3.0 - 4.0 * nu
    t = k * thickness
    e = np.exp(-2.0 * t)
    tail = 2.0 * t * t + 0.5 * (1.0 + kappa**2)
    den = 0.5 * kappa * (1.0 + e * e) + tail * e
    direct = 2.0 * (1.0 - nu**2) / k
    r_nn = -direct * (-kappa * e * e - (2.0 * t + tail) * e) / den
    r_tt = direct * (-kappa * e * e + (2.0 * t - tail) * e) / den
    g_r = -(1.0 + nu) / k * (8.0 * (1.0 - 2.0 * nu) * (1.0 - nu) ** 2 + 4.0 * (1.0 - nu) * t * t) * e / den
    return r_nn, r_tt, g_r


def wavenumbers(span: float, thickness: float, scales=()) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes q [1/length] and weights on (0, T_MAX / b] for integrands made of the
    remainder (scale 1/b, exponential decay), phases exp(i q y) with |y| <= ``span`` [length], and
    Lorentzians of the ``scales`` [length] (e.g. 1/(1 - i q b_i)).

    Uniform panels of width min(4 pi / span, 1 / b) (at most two turns of the phase: 12-point
    Gauss-Legendre integrates exp(i pi t) on [-1, 1] to ~pi^24 / 24! ~ 1e-12; the remainder's
    complex poles, ~1/b off the axis, stay outside the panel's Bernstein ellipse);
    below the first panel, panels halving towards 1e-10 / L, L = max(span, b, scales), whose
    neglected rest is ~1e-10 of the integral (the integrands are bounded at q -> 0). Panels below
    0.1 / L, where the integrand is analytic in a disc ten times the panel's size, take
    :data:`LOW_POINTS` points (error ~ 20^-12)."""
    largest = max(span, thickness, *(abs(s) for s in scales))
    width = min(4.0 * math.pi / span, 1.0 / thickness)
    top = T_MAX / thickness
    panels = max(1, int(math.ceil(top / width)))
    width = top / panels
    halvings = max(1, int(math.ceil(math.log2(width * largest / 1e-10))))
    edges_low = width * 0.5 ** np.arange(halvings, -1, -1)  # lowest .. width
    edges = np.concatenate([edges_low, width * np.arange(2, panels + 1)])
    lo, hi = edges[:-1], edges[1:]
    small = hi <= 0.1 / largest
    nodes, weights = [], []
    for (x, w), chosen in ((_LOW_RULE, small), (_PANEL_RULE, ~small)):
        a, b = lo[chosen, None], hi[chosen, None]
        nodes.append((0.5 * (a + b) + 0.5 * (b - a) * x[None, :]).ravel())
        weights.append((0.5 * (b - a) * w[None, :]).ravel())
    return np.concatenate(nodes), np.concatenate(weights)


def _spherical_bessel(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """j0, j1, j2 at theta >= 0: the closed forms, their Taylor series below 0.2 (where the closed
    forms cancel; the series' first omitted terms are < 3e-15 of the leading ones there)."""
    t = np.maximum(theta, 0.2)
    sin, cos = np.sin(t), np.cos(t)
    j0, j1 = sin / t, sin / t**2 - cos / t
    j2 = (3.0 / t**2 - 1.0) * sin / t - 3.0 * cos / t**2
    small = theta < 0.2
    if small.any():
        u = theta[small]
        v = u * u
        j0[small] = 1.0 - v / 6.0 * (1.0 - v / 20.0 * (1.0 - v / 42.0 * (1.0 - v / 72.0)))
        j1[small] = u / 3.0 * (1.0 - v / 10.0 * (1.0 - v / 28.0 * (1.0 - v / 54.0 * (1.0 - v / 88.0))))
        j2[small] = v / 15.0 * (1.0 - v / 14.0 * (1.0 - v / 36.0 * (1.0 - v / 66.0 * (1.0 - v / 104.0))))
    return j0, j1, j2


def quadratic_spectra(q: np.ndarray, half: float) -> np.ndarray:
    """N~_k(q) = int N_k(s) exp(-i q s) ds over one quadratic element of half-length ``half``
    [length] centred at 0 (nodes at -2/3, 0, 2/3), shape (q, 3) [length]: with
    I_m = int_{-1}^{1} xi^m exp(-i theta xi) d xi, theta = q half: I_0 = 2 j0, I_1 = -2i j1,
    I_2 = (2/3)(j0 - 2 j2) (spherical Bessel functions, no cancellation at small theta)."""
    # the shape coefficients of rolling_cli.model.grid (Lagrange through -2/3, 0, 2/3), here to
    # keep the references below the model layer: N = (9/8 xi^2 - 3/4 xi, 1 - 9/4 xi^2, 9/8 xi^2 + 3/4 xi)
    coeff = np.array([[0.0, -0.75, 1.125], [1.0, 0.0, -2.25], [0.0, 0.75, 1.125]])
    j0, j1, j2 = _spherical_bessel(np.abs(np.asarray(q, dtype=float)) * half)
    moments = np.stack([2.0 * j0 + 0j, -2j * np.sign(q) * j1, (2.0 / 3.0) * (j0 - 2.0 * j2) + 0j], axis=-1)
    return half * moments @ coeff.T


def element_spectrum(q: np.ndarray, centres: np.ndarray, half: float, *nodal: np.ndarray) -> np.ndarray:
    """f~(q) [stress length] of the piecewise-quadratic traction with ``nodal`` values (3 per element,
    elements centred at the equally spaced ``centres`` [length], half-length ``half``), at the
    wavenumbers q: the phases exp(-i q c_e) as a running product over the elements. Several
    tractions (``nodal`` arrays) share the phases: shape (q, tractions), else (q,)."""
    shapes = quadratic_spectra(q, half)  # (q, 3)
    values = np.concatenate([np.asarray(v, dtype=float).reshape(-1, 3) for v in nodal], axis=1)  # (e, 3 t)
    phases = np.empty((centres.size, q.size), dtype=complex)
    phases[0] = np.exp(-1j * q * centres[0])
    if centres.size > 1:
        phases[1:] = np.exp(-1j * q * (centres[1] - centres[0]))[None, :]
        np.cumprod(phases, axis=0, out=phases)
    out = np.sum((phases.T @ values).reshape(q.size, len(nodal), 3) * shapes[:, None, :], axis=2)
    return out if len(nodal) > 1 else out[:, 0]


def remainder_power(
    centres: np.ndarray, half: float, p_n, t, thickness: float, compliances, lengths, poisson: float
) -> float:
    """Hysteresis power [force/length per unit |V|, i.e. force/length] of a viscoelastic layer beyond
    the half-plane's, for piecewise-quadratic tractions p_n, t [stress] on this body (elements at
    ``centres``, half-length ``half`` [length]); ``compliances`` c_i [1/stress], ``lengths``
    ell_i = |V| lambda_i [length]."""
    p_n, t = np.asarray(p_n, dtype=float), np.asarray(t, dtype=float)
    if not (np.any(p_n) or np.any(t)):
        return 0.0
    span = float(np.ptp(centres)) + 2.0 * half
    ells = [ell for ell in lengths if ell > 0.0]
    q, w = wavenumbers(span, thickness, ells)
    spectra = element_spectrum(q, centres, half, p_n, t)
    fn, ft = spectra[:, 0], spectra[:, 1]
    r_nn, r_tt, g_r = remainder(q, thickness, poisson)
    quad = -r_nn * np.abs(fn) ** 2 + r_tt * np.abs(ft) ** 2 - 2.0 * g_r * np.imag(np.conj(fn) * ft)
    total = 0.0
    for c, ell in zip(compliances, lengths, strict=True):
        if ell <= 0.0:
            continue
        total += c * ell * float(np.sum(w * q * q / (1.0 + (q * ell) ** 2) * quad)) / math.pi
    return total
