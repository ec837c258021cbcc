"""McEwen (1949): the stresses below a frictionless Hertz line contact (plane strain).

A half-plane z >= 0 (z the depth into the body) under the Hertz pressure
p(x) = p0 sqrt(1 - x^2/a^2). With

    m^2 = [ sqrt((a^2 - x^2 + z^2)^2 + 4 x^2 z^2) + (a^2 - x^2 + z^2) ] / 2
    n^2 = [ sqrt((a^2 - x^2 + z^2)^2 + 4 x^2 z^2) - (a^2 - x^2 + z^2) ] / 2

(m >= 0; n has the sign of x), Johnson, Contact Mechanics, eq. 4.50:

    sigma_xx = -(p0/a) [ m (1 + (z^2 + n^2)/(m^2 + n^2)) - 2 z ]
    sigma_zz = -(p0/a) m (1 - (z^2 + n^2)/(m^2 + n^2))
    tau_xz   = -(p0/a) n (m^2 - z^2)/(m^2 + n^2)

Compression is negative. The shear sign is that of the Flamant kernel in the
frame (x, z into the body): tau_xz(x, 0) = -q(x) for a surface traction q on
the body along +x, so tau_xz < 0 at x > 0 under a pressure (Johnson prints the
opposite sign of tau_xz with his own orientation). In plane strain
sigma_yy = nu (sigma_xx + sigma_zz).

Classic values (checked in the tests): on the axis the principal shear
(sigma_xx - sigma_zz)/2 peaks at 0.300 p0 at z = 0.786 a; the orthogonal shear
|tau_xz| peaks at p0/4 at x = +-(sqrt(3)/2) a, z = a/2.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize_scalar


def mn(x, z, a: float) -> tuple[np.ndarray, np.ndarray]:
    """McEwen's m (>= 0) and n (sign of x) [length] at points (x, z) [length], z >= 0."""
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    k = a * a - x * x + z * z
    root = np.sqrt(k * k + 4.0 * x * x * z * z)
    m = np.sqrt(0.5 * np.maximum(root + k, 0.0))
    n = np.sign(x) * np.sqrt(0.5 * np.maximum(root - k, 0.0))
    return m, n


def stresses(x, z, a: float, p0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] below a Hertz pressure of half-width a and peak p0.

    Exact for z > 0; at z = 0 the limits (-p, -p, 0) inside the contact and
    (0, 0, 0) outside hold to the rounding of m and n.
    """
    m, n = mn(x, z, a)
    z = np.asarray(z, dtype=float)
    m2n2 = m * m + n * n
    safe = np.where(m2n2 > 0.0, m2n2, 1.0)
    ratio = np.where(m2n2 > 0.0, (z * z + n * n) / safe, 1.0)  # the contact edges x = +-a, z = 0
    sigma_xx = -(p0 / a) * (m * (1.0 + ratio) - 2.0 * z)
    sigma_zz = -(p0 / a) * m * (1.0 - ratio)
    tau_xz = -(p0 / a) * n * np.where(m2n2 > 0.0, (m * m - z * z) / safe, 0.0)
    return sigma_xx, sigma_zz, tau_xz


def axis(z, a: float, p0: float) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz) [stress] on the axis x = 0 (tau_xz = 0 there).

    sigma_zz = -p0 / sqrt(1 + z^2/a^2),
    sigma_xx = -p0 [ (1 + 2 z^2/a^2) / sqrt(1 + z^2/a^2) - 2 z/a ].
    """
    s = np.asarray(z, dtype=float) / a
    root = np.sqrt(1.0 + s * s)
    return -p0 * ((1.0 + 2.0 * s * s) / root - 2.0 * s), -p0 / root


def principal_shear_peak(a: float, p0: float) -> tuple[float, float]:
    """The largest principal shear (sigma_xx - sigma_zz)/2 on the axis [stress] and its depth [length].

    The maximum of :func:`axis`'s closed form (0.300 p0 at z = 0.786 a); in
    plane strain with nu <= 0.5 sigma_yy lies between sigma_xx and sigma_zz
    there, so this is also the Tresca maximum shear.
    """

    def negative(s):
        sx, sz = axis(s * a, a, p0)
        return -0.5 * float(sx - sz) / p0

    found = minimize_scalar(negative, bounds=(0.1, 3.0), method="bounded", options={"xatol": 1e-12})
    return -float(found.fun) * p0, float(found.x) * a


def von_mises_axis(z, a: float, p0: float, nu: float) -> np.ndarray:
    """Von Mises stress [stress] on the axis in plane strain (sigma_yy = nu (sigma_xx + sigma_zz))."""
    sx, sz = axis(z, a, p0)
    sy = nu * (sx + sz)
    return np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2))


def von_mises_peak(a: float, p0: float, nu: float) -> tuple[float, float]:
    """The largest von Mises stress [stress] and its depth [length]: the maximum of
    :func:`von_mises_axis` (the field's maximum lies on the axis; the tests check
    that against the whole closed-form field)."""
    found = minimize_scalar(
        lambda s: -float(von_mises_axis(s * a, a, p0, nu)) / p0,
        bounds=(0.05, 3.0),
        method="bounded",
        options={"xatol": 1e-12},
    )
    return -float(found.fun) * p0, float(found.x) * a


def orthogonal_shear_peak(a: float, p0: float) -> tuple[float, float, float]:
    """Largest |tau_xz| [stress] and where: (p0/4, x = sqrt(3)/2 a, z = a/2) [length].

    At x = +sqrt(3)/2 a tau_xz = -p0/4 and at x = -sqrt(3)/2 a +p0/4, so its
    range over a rolling pass at depth a/2 is p0/2.
    """
    return 0.25 * p0, 0.5 * np.sqrt(3.0) * a, 0.5 * a
