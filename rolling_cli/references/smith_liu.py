"""Smith & Liu (1953): a Hertz line contact in full sliding (plane strain).

The half-plane z >= 0 (z the depth into the body) carries the Hertz pressure
p(x) = p0 sqrt(1 - x^2/a^2) and the sliding-friction traction
q(x) = mu p(x) on the body along +x. The pressure part is McEwen's
(:mod:`.mcewen`); the traction part, with McEwen's m and n, is

    sigma_xx = (q0/a) [ n (2 - (z^2 - m^2)/(m^2 + n^2)) - 2 x ]
    sigma_zz = -(q0/a) n (m^2 - z^2)/(m^2 + n^2)
    tau_xz   = -(q0/a) [ m (1 + (z^2 + n^2)/(m^2 + n^2)) - 2 z ]

with q0 = mu p0 (compression negative, tau_xz(x, 0) = -q(x): the Flamant
kernel's sign in the frame (x, z into the body)). On the surface

    sigma_xx(x, 0) = -p0 sqrt(1 - x^2/a^2) - 2 mu p0 x/a                 (|x| <= a)
                   = -2 mu p0 (x - sgn(x) sqrt(x^2 - a^2))/a             (|x| >  a)

so the largest tension, 2 mu p0, sits at x = -a: the edge the traction on the
body points away from (behind a slider moving along +x, the trailing edge).
"""

from __future__ import annotations

import numpy as np

from . import mcewen


def traction_stresses(x, z, a: float, q0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] of the traction q0 sqrt(1 - x^2/a^2) on the body along +x."""
    m, n = mcewen.mn(x, z, a)
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    m2n2 = m * m + n * n
    safe = np.where(m2n2 > 0.0, m2n2, 1.0)
    sigma_xx = (q0 / a) * (n * (2.0 - np.where(m2n2 > 0.0, (z * z - m * m) / safe, 0.0)) - 2.0 * x)
    sigma_zz = -(q0 / a) * n * np.where(m2n2 > 0.0, (m * m - z * z) / safe, 0.0)
    ratio = np.where(m2n2 > 0.0, (z * z + n * n) / safe, 1.0)
    tau_xz = -(q0 / a) * (m * (1.0 + ratio) - 2.0 * z)
    return sigma_xx, sigma_zz, tau_xz


def stresses(x, z, a: float, p0: float, mu: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] in full sliding: McEwen plus mu times the traction part."""
    normal = mcewen.stresses(x, z, a, p0)
    tangential = traction_stresses(x, z, a, mu * p0)
    return tuple(n + t for n, t in zip(normal, tangential, strict=True))


def surface_sigma_xx(x, a: float, p0: float, mu: float) -> np.ndarray:
    """sigma_xx(x, 0) [stress] on the surface (see the module docstring)."""
    s = np.asarray(x, dtype=float) / a
    inside = np.abs(s) <= 1.0
    root_in = np.sqrt(np.clip((1.0 - s) * (1.0 + s), 0.0, None))
    root_out = np.sqrt(np.clip(s * s - 1.0, 0.0, None))
    return np.where(inside, -p0 * root_in - 2.0 * mu * p0 * s, -2.0 * mu * p0 * (s - np.sign(s) * root_out))


def max_surface_tension(a: float, p0: float, mu: float) -> tuple[float, float]:
    """The largest surface tension [stress] and where [length]: (2 mu p0, x = -a)."""
    return 2.0 * mu * p0, -a
