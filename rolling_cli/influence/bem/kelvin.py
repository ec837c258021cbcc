"""Kelvin's fundamental solution of plane-strain elastostatics.

For a unit point force at the source x and a field point y, r = |y - x|,
r_k = (y_k - x_k)/r, n the outward normal at y, G the shear modulus:

    U_kl = 1/(8 pi G (1 - nu)) [ (3 - 4 nu) ln(1/r) delta_kl + r_k r_l ]
    T_kl = -1/(4 pi (1 - nu) r) { dr/dn [ (1 - 2 nu) delta_kl + 2 r_k r_l ]
                                  - (1 - 2 nu) (r_k n_l - r_l n_k) }

(Brebbia & Dominguez). Nothing divides by (1 - 2 nu), so nu = 0.5 is exact.
Arrays broadcast over leading axes; the last axis holds the two components.
U is in [length/stress] per unit force per length, T in [1/length].
"""

from __future__ import annotations

import numpy as np


def displacement_kernel(d: np.ndarray, shear: float, poisson: float) -> np.ndarray:
    """U_kl for separation vectors d = y - x (shape (..., 2)); returns (..., 2, 2)."""
    dx, dy = d[..., 0], d[..., 1]
    r2 = dx * dx + dy * dy
    c = 1.0 / (8.0 * np.pi * shear * (1.0 - poisson))
    log_term = (-0.5 * (3.0 - 4.0 * poisson)) * np.log(r2)  # (3 - 4 nu) ln(1/r)
    out = np.empty(d.shape[:-1] + (2, 2))
    out[..., 0, 1] = dx * dy / r2
    out[..., 1, 0] = out[..., 0, 1]
    out[..., 0, 0] = dx * dx / r2 + log_term
    out[..., 1, 1] = dy * dy / r2 + log_term
    out *= c
    return out


def traction_kernel(d: np.ndarray, normal: np.ndarray, poisson: float) -> np.ndarray:
    """T_kl for separation vectors d = y - x and outward normals at y; returns (..., 2, 2)."""
    dx, dy = d[..., 0], d[..., 1]
    nx, ny = normal[..., 0], normal[..., 1]
    r = np.sqrt(dx * dx + dy * dy)
    rx, ry = dx / r, dy / r
    drdn = rx * nx + ry * ny
    a = 1.0 - 2.0 * poisson
    skew = a * (rx * ny - ry * nx)  # (1 - 2 nu)(r_0 n_1 - r_1 n_0)
    factor = -1.0 / (4.0 * np.pi * (1.0 - poisson)) / r
    cross = 2.0 * rx * ry * drdn
    out = np.empty(d.shape[:-1] + (2, 2))
    out[..., 0, 0] = (a + 2.0 * rx * rx) * drdn
    out[..., 1, 1] = (a + 2.0 * ry * ry) * drdn
    out[..., 0, 1] = cross - skew
    out[..., 1, 0] = cross + skew
    out *= factor[..., None, None]
    return out
