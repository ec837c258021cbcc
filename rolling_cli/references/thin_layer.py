"""Thin elastic layer (thickness b) bonded to a rigid core, pressed by a rigid
cylinder of radius R: the two classical limits for b << a (plane strain).

Both are sanity bounds and first guesses, not exact references (PHYSICS.md).

* Compressible layer, a bed of springs (Winkler) of stiffness
  k = E (1 - nu) / ((1 + nu)(1 - 2 nu) b) [stress/length]:
  p(x) = k (a^2 - x^2) / (2R), so a^2 = 2 R overlap, P = 2 k a^3 / (3R),
  p0 a / P = 3/4.
* Incompressible layer (nu = 0.5), squeezed sideways: with no slip at both
  faces the sideways displacement is parabolic across the layer, its flux is
  -(b^3 / (12 G)) dp/dx, and continuity with the indentation gives
  p(x) = G (a^2 - x^2)^2 / (2 R b^3), so a^2 = 6 R overlap,
  P = 8 G a^5 / (15 R b^3), p0 a / P = 15/16.
"""

from __future__ import annotations

import math


def winkler_stiffness(young: float, poisson: float, thickness: float) -> float:
    """Foundation stiffness k [stress/length] of a compressible bonded layer (inf at nu = 0.5)."""
    if poisson >= 0.5:
        return math.inf
    return young * (1.0 - poisson) / ((1.0 + poisson) * (1.0 - 2.0 * poisson) * thickness)


def compressible_half_width(load: float, radius: float, young: float, poisson: float, thickness: float) -> float:
    """a [length] of the Winkler limit under load P [force/length]: (3 P R / (2 k))^(1/3)."""
    k = winkler_stiffness(young, poisson, thickness)
    return 0.0 if math.isinf(k) else (1.5 * load * radius / k) ** (1.0 / 3.0)


def incompressible_half_width(load: float, radius: float, young: float, thickness: float) -> float:
    """a [length] of the incompressible limit under load P: (15 P R b^3 / (8 G))^(1/5), G = E/3."""
    shear = young / 3.0
    return (15.0 * load * radius * thickness**3 / (8.0 * shear)) ** 0.2


def half_width_for_overlap(overlap: float, radius: float, incompressible: bool) -> float:
    """a [length] for an imposed overlap: sqrt(2 R d) (Winkler) or sqrt(6 R d) (incompressible)."""
    return math.sqrt((6.0 if incompressible else 2.0) * radius * overlap)
