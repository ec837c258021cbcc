"""Michell's series for a cover bonded to an elastic core on a rigid shaft (plane strain).

Two bonded annuli: the core r_i < r < r_c (shear modulus G_c, Poisson's ratio
nu_c), its bore fixed (u = 0 at r_i), and the cover r_c < r < R (G, nu) under a
given surface traction at R, as :mod:`.annulus`. Per Fourier mode n >= 1 each
region is the span of the four solutions of :func:`.annulus._basis` with its
own k = 2 (1 - nu) / (1 - 2 nu); eight coefficients follow from eight
conditions (an 8x8 system per mode):

* U = V = 0 at r_i (the core's bore);
* U, V continuous at r_c (the bond);
* sigma_rr and sigma_rtheta continuous at r_c, each region's
  G [k U' + (k - 2)(U + n V)/r] and G [V' - (V + n U)/r];
* the cover's tractions at R: unit sigma_rr (cos n theta) or unit sigma_rtheta
  (sin n theta).

The core's solutions are written in r / r_c (its positive powers normalised
at r_c, its negative ones at r_i; the n = 1 logarithm in r / r_c differs from
the one in r / R by a multiple of the translation, another basis solution), so
nothing overflows or vanishes for large n. For n = 0 the axisymmetric pair
u_r = A r + B / r and the torsion u_theta = C r + D / r in each region, by the
same conditions (4x4 each). A core of the cover's material is the single
annulus r_i < r < R of :mod:`.annulus` (checked in the tests).
"""

from __future__ import annotations

import numpy as np

from .annulus import _basis, synthesis

__all__ = ["mode_responses", "axisymmetric", "surface_displacement"]


def _k(poisson: float) -> float:
    return 2.0 * (1.0 - poisson) / (1.0 - 2.0 * poisson)


def _values(n: np.ndarray, rho: float, scale: float, rho_ref: float, k: float, g: float):
    """(U, V, sigma_rr/G, sigma_rtheta/G) (modes, 4) at ``rho`` (r / R) of the four solutions written
    in r / (``scale`` R), negative powers normalised at ``rho_ref`` (r / R); stresses per the
    cover's G, the region's G being ``g`` times it."""
    U, dU, V, dV = _basis(n, rho / scale, rho_ref / scale, k)
    dU, dV = dU / scale, dV / scale  # d/d(rho) of functions of rho / scale
    nn = n[:, None].astype(float)
    srr = g * (k * dU + (k - 2.0) * (U + nn * V) / rho)
    srt = g * (dV - (V + nn * U) / rho)
    return U, V, srr, srt


def mode_responses(
    modes: int, bore_ratio: float, core_ratio: float, poisson: float, core_poisson: float, shear_ratio: float
) -> np.ndarray:
    """Outer-surface response of modes n = 1 .. ``modes``: (modes, 2, 2) dimensionless, as
    :func:`.annulus.mode_responses` (G the cover's shear modulus): ``bore_ratio`` r_i / R,
    ``core_ratio`` r_c / R, ``shear_ratio`` G_c / G; nu < 0.5 in both regions."""
    k, kc = _k(poisson), _k(core_poisson)
    n = np.arange(1, modes + 1)
    ri, rc = float(bore_ratio), float(core_ratio)
    core_bore = _values(n, ri, rc, ri, kc, shear_ratio)
    core_bond = _values(n, rc, rc, ri, kc, shear_ratio)
    cover_bond = _values(n, rc, 1.0, rc, k, 1.0)
    cover_out = _values(n, 1.0, 1.0, rc, k, 1.0)
    zero = np.zeros((n.size, 4))
    rows = [np.concatenate([core_bore[q], zero], axis=1) for q in (0, 1)]
    rows += [np.concatenate([core_bond[q], -cover_bond[q]], axis=1) for q in range(4)]
    rows += [np.concatenate([zero, cover_out[q]], axis=1) for q in (2, 3)]
    system = np.stack(rows, axis=1)  # (modes, 8 conditions, 8 coefficients)
    rhs = np.zeros((n.size, 8, 2))
    rhs[:, 6, 0] = 1.0
    rhs[:, 7, 1] = 1.0
    coeff = np.linalg.solve(system, rhs)[:, 4:]  # the cover's (modes, 4, 2)
    U, V = cover_out[0], cover_out[1]
    return np.stack([np.einsum("mc,mcq->mq", U, coeff), np.einsum("mc,mcq->mq", V, coeff)], axis=1)


def axisymmetric(
    bore_ratio: float, core_ratio: float, poisson: float, core_poisson: float, shear_ratio: float
) -> tuple[float, float]:
    """n = 0: G u_r / R per unit uniform sigma_rr and G u_theta / R per unit uniform sigma_rtheta at
    r = R (arguments as :func:`mode_responses`). Per region u = A rho + B / rho: sigma_rr / G =
    A (2k - 2) - 2 B / rho^2, and u_theta = C rho + D / rho: sigma_rtheta / G = -2 D / rho^2."""
    k, kc = _k(poisson), _k(core_poisson)
    ri, rc, g = float(bore_ratio), float(core_ratio), float(shear_ratio)
    radial = np.array(
        [
            [ri, 1.0 / ri, 0.0, 0.0],
            [rc, 1.0 / rc, -rc, -1.0 / rc],
            [g * (2.0 * kc - 2.0), -2.0 * g / rc**2, -(2.0 * k - 2.0), 2.0 / rc**2],
            [0.0, 0.0, 2.0 * k - 2.0, -2.0],
        ]
    )
    a = np.linalg.solve(radial, [0.0, 0.0, 0.0, 1.0])
    torsion = np.array(
        [
            [ri, 1.0 / ri, 0.0, 0.0],
            [rc, 1.0 / rc, -rc, -1.0 / rc],
            [0.0, -2.0 * g / rc**2, 0.0, 2.0 / rc**2],
            [0.0, 0.0, 0.0, -2.0],
        ]
    )
    b = np.linalg.solve(torsion, [0.0, 0.0, 0.0, 1.0])
    return float(a[2] + a[3]), float(b[2] + b[3])


def surface_displacement(
    sigma_rr: np.ndarray,
    sigma_rt: np.ndarray,
    radius: float,
    core_radius: float,
    inner_radius: float,
    shear: float,
    poisson: float,
    core_shear: float,
    core_poisson: float,
) -> tuple[np.ndarray, np.ndarray]:
    """u_r and u_theta [length] at r = R for tractions sampled at theta_j = 2 pi j / M, as
    :func:`.annulus.surface_displacement`: the cover r_c < r < R (``core_radius`` r_c; ``shear`` G
    [stress], ``poisson``) on the core r_i < r < r_c (``inner_radius`` r_i; ``core_shear`` G_c
    [stress], ``core_poisson``), the core's bore fixed; lengths [length]; nu < 0.5."""
    sigma_rr = np.asarray(sigma_rr, dtype=float)
    sigma_rt = np.asarray(sigma_rt, dtype=float)
    m = sigma_rr.size
    if m % 2 or sigma_rt.size != m:
        raise ValueError("the samples must be an even number M of points, the same for both tractions")
    ratios = (inner_radius / radius, core_radius / radius, poisson, core_poisson, core_shear / shear)
    response = mode_responses(m // 2 - 1, *ratios)
    radial, torsion = axisymmetric(*ratios)
    return synthesis(sigma_rr, sigma_rt, response, radial, torsion, radius / shear)
