"""The normal approach of a half-space under a Hertz pressure, from a point at depth d.

In two dimensions the approach of a loaded half-plane is defined only against a
reference point (the log kernel leaves a free constant). Taking the point at
depth d below the contact centre (where the BEM half-space of
:mod:`rolling_cli.influence.bem` puts it, d = its truncation depth D), the
surface at the centre of a Hertz pressure of load P and half-width a moves
towards it by

    w = P [k (ln(2 d / a) + 1/2) - (k + c)/2 + (k + c/2) a^2 / (4 d^2)] + O((a/d)^4),

k = 2 (1 - nu^2) / (pi E), c = 2 nu (1 + nu) / (pi E); that is

    w = (2 P (1 - nu^2) / (pi E)) [ln(2 d / a) - nu / (2 (1 - nu))] + O((a/d)^2).

It is Flamant's u_z(x = 0) - u_z(0, d) (:mod:`rolling_cli.references.flamant`)
integrated against p0 sqrt(1 - s^2/a^2): the mean of ln|s| over that weight
is ln(a/2) - 1/2, that of s^2 is a^2/4, and for a force at s the point (0, d)
lies at r^2 = s^2 + d^2, where u_z = -k ln(r/d) - (k + c)/2 s^2/r^2. The
overlap of two bodies is the sum of their approaches; a rigid body adds nothing.
"""

from __future__ import annotations

import math


def approach(load: float, half_width_a: float, young: float, poisson: float, depth: float) -> float:
    """Approach w [length] of one half-space's surface at the contact centre towards the point at ``depth``.

    ``load`` P [force/length], ``half_width_a`` a [length], ``young`` E
    [stress] (inf for a rigid body: 0), ``poisson`` nu, ``depth`` d [length].
    Exact to O((a/d)^4) relative.
    """
    if math.isinf(young):
        return 0.0
    k = 2.0 * (1.0 - poisson**2) / (math.pi * young)
    c = 2.0 * poisson * (1.0 + poisson) / (math.pi * young)
    log = math.log(2.0 * depth / half_width_a)
    return load * (k * (log + 0.5) - 0.5 * (k + c) + (k + 0.5 * c) * half_width_a**2 / (4.0 * depth**2))
