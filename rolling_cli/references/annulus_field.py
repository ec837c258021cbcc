"""Michell's series inside an annulus bonded to a rigid shaft: displacements and stresses everywhere.

The modes of :mod:`.annulus` (read its derivation), evaluated at any radius.
A mode u_r = U(r) cos(n theta), u_theta = V(r) sin(n theta) strains as
eps_rr = U', eps_thth = (U + n V)/r, gamma_rth = V' - (V + n U)/r, so with
k = (lambda + 2G)/G and lambda = (k - 2) G (plane strain)

    sigma_rr = G [k U' + (k - 2)(U + n V)/r] cos(n theta),
    sigma_thth = G [(k - 2) U' + k (U + n V)/r] cos(n theta),
    sigma_rth = G [V' - (V + n U)/r] sin(n theta).

n = 0: u_r = A r + B/r (sigma_rr = G [(2k - 2) A - 2B/r^2], sigma_thth =
G [(2k - 2) A + 2B/r^2]) and u_theta = C r + D/r (sigma_rth = -2 G D / r^2),
with u = 0 at r_i. The load on r = R is given by complex amplitudes,
sigma_rr(R, theta) = Re sum_n S_n e^{i n theta} and
sigma_rth(R, theta) = Re sum_n T_n e^{i n theta} (n = 0 .. M); the response
of each mode follows by the rotation invariance of the equations (a phase
turns cos(n theta) and sin(n theta) together). :func:`amplitudes` gives
S_n, T_n for a piecewise-quadratic traction on the outer circle in closed form.
"""

from __future__ import annotations

import numpy as np

from .annulus import _basis
from .layer_fourier import element_spectrum

__all__ = ["amplitudes", "annulus_field"]


def amplitudes(modes: int, radius: float, centres: np.ndarray, half: float, sigma_rr, sigma_rt):
    """S_n, T_n (n = 0 .. ``modes``) [stress] of piecewise-quadratic tractions on the outer circle:
    elements of half-length ``half`` [length] at arc lengths ``centres`` [length] (equally spaced),
    nodal values (3 per element, at xi = -2/3, 0, 2/3) ``sigma_rr`` and ``sigma_rt`` [stress].
    c_n = f~(n / R) / (2 pi R), S_0 = c_0, S_n = 2 c_n (the real series)."""
    q = np.arange(modes + 1) / radius
    spectra = element_spectrum(q, np.asarray(centres, dtype=float), half, sigma_rr, sigma_rt)
    coeff = spectra / (2.0 * np.pi * radius)
    coeff[1:] *= 2.0
    return coeff[:, 0], coeff[:, 1]


def _modes(n: np.ndarray, rho: np.ndarray, rho_i: float, k: float) -> np.ndarray:
    """Per mode n >= 1 and radius rho (r/R): (5 quantities, 2 loads, rho, n) dimensionless responses
    G u_r / R, G u_theta / R, sigma_rr, sigma_thth, sigma_rth per unit sigma_rr (cos) and unit
    sigma_rth (sin) amplitude at r = R."""
    Ui, _, Vi, _ = _basis(n, rho_i, rho_i, k)
    Uo, dUo, Vo, dVo = _basis(n, 1.0, rho_i, k)
    nn = n[:, None].astype(float)
    system = np.stack([Ui, Vi, k * dUo + (k - 2.0) * (Uo + nn * Vo), dVo - (Vo + nn * Uo)], axis=1)
    rhs = np.zeros((n.size, 4, 2))
    rhs[:, 2, 0] = rhs[:, 3, 1] = 1.0
    coeff = np.linalg.solve(system, rhs)  # (modes, 4 solutions, 2 loads)
    out = np.empty((5, 2, rho.size, n.size))
    for j, r in enumerate(rho):
        U, dU, V, dV = (np.einsum("mc,mcq->qm", f, coeff) for f in _basis(n, float(r), rho_i, k))
        out[0, :, j], out[1, :, j] = U, V
        out[2, :, j] = k * dU + (k - 2.0) * (U + n * V) / r
        out[3, :, j] = (k - 2.0) * dU + k * (U + n * V) / r
        out[4, :, j] = dV - (V + n * U) / r
    return out


def annulus_field(S, T, radius: float, inner_radius: float, shear: float, poisson: float, r, theta) -> np.ndarray:
    """u_r, u_theta [length] and sigma_rr, sigma_thth, sigma_rth [stress], shape (5, P), at polar points
    (``r`` [length], ``theta`` [rad]) (P,) of the annulus ``inner_radius`` <= r <= ``radius`` bonded at
    its bore, for the load amplitudes ``S``, ``T`` (M + 1,) [stress] (module docstring); G ``shear``
    [stress], 0 <= ``poisson`` < 0.5. Modes are evaluated per distinct radius (a grid's rows)."""
    S, T = np.asarray(S, dtype=complex), np.asarray(T, dtype=complex)
    r, theta = np.asarray(r, dtype=float), np.asarray(theta, dtype=float)
    k = 2.0 * (1.0 - poisson) / (1.0 - 2.0 * poisson)
    rho_i = inner_radius / radius
    rows, where = np.unique(r / radius, return_inverse=True)
    n = np.arange(1, S.size)
    resp = _modes(n, rows, rho_i, k)[:, :, where]  # (5, 2, P, M)
    sine = 1j * T[1:]  # sigma_rth = Re(T e^{i n th}) = Re((i T)(-i e^{i n th})): a sine amplitude i T
    amp = resp[:, 0] * S[1:] + resp[:, 1] * sine  # (5, P, M)
    phase = np.exp(1j * np.outer(theta, n))  # (P, M)
    cos_type = np.einsum("qpm,pm->qp", amp, phase)
    out = np.empty((5, r.size))
    out[[0, 2, 3]] = cos_type[[0, 2, 3]].real
    out[[1, 4]] = (-1j * cos_type[[1, 4]]).real
    rho = r / radius
    a = 1.0 / (2.0 * k - 2.0 + 2.0 * rho_i**2)  # n = 0, radial: u_r = a (rho - rho_i^2 / rho)
    s0, t0 = S[0].real, T[0].real
    out[0] += s0 * a * (rho - rho_i**2 / rho)
    out[2] += s0 * ((2.0 * k - 2.0) * a + 2.0 * a * rho_i**2 / rho**2)
    out[3] += s0 * ((2.0 * k - 2.0) * a - 2.0 * a * rho_i**2 / rho**2)
    out[1] += t0 * 0.5 * (rho / rho_i**2 - 1.0 / rho)  # torsion: u_theta = C rho + D / rho, D = -1/2
    out[4] += t0 / rho**2
    out[:2] *= radius / shear
    return out
