"""The surface displacement of an elastic half-plane under a Hertzian pressure (plane strain).

For p(s) = p0 sqrt(1 - s^2/a^2) on |s| < a and the project's kernel
w(x) = k int p_n(s) ln|x - s| ds (p_n = -p, k = 2 (1 - nu^2) / (pi E), w into the
body, :mod:`rolling_cli.influence.halfplane`), the Cauchy integral of the
semi-ellipse (Johnson, Contact Mechanics, §2.8) gives

    dw/dx = -(k pi p0 / a) (x - sgn(x) sqrt(x^2 - a^2) [|x| > a]),

so, relative to the centre (the log kernel's constant drops out):

    w(x) - w(0) = -(k pi p0 / a) x^2 / 2                                   (|x| <= a)
    w(x) - w(0) = -(k pi p0 / a) [x^2/2 - |x| sqrt(x^2 - a^2)/2 + a^2/2 ln((|x| + sqrt(x^2 - a^2))/a)]

(|x| > a), continuous at |x| = a. Inside, with Hertz's a and p0 and a rigid
counterpart, this is -x^2 / (2 R): the surface fits the flat.
"""

from __future__ import annotations

import numpy as np

__all__ = ["relative_displacement"]


def relative_displacement(x, half_width_a: float, p0: float, young: float, poisson: float) -> np.ndarray:
    """w(x) - w(0) [length] of a half-plane (E [stress], nu) under the Hertz pressure of half-width a
    [length] and peak p0 [stress], at positions ``x`` [length] from the pressure's centre."""
    x = np.abs(np.asarray(x, dtype=float))
    a = float(half_width_a)
    scale = 2.0 * (1.0 - poisson**2) / (np.pi * young) * np.pi * p0 / a
    root = np.sqrt(np.maximum(x**2 - a**2, 0.0))
    outside = 0.5 * x**2 - 0.5 * x * root + 0.5 * a**2 * np.log(np.maximum(x + root, a) / a)
    return -scale * np.where(x <= a, 0.5 * x**2, outside)
