"""Plane-strain elastic constants of a body pair.

All functions are pure and take Young's moduli in stress units (any consistent
unit system; N/mm^2 = MPa with N and mm) and dimensionless Poisson ratios. A
rigid body is passed as ``young = inf``; every formula below then drops that
body's compliance exactly (1/inf = 0), so no special case is needed.
"""

from __future__ import annotations

import math


def shear_modulus(young: float, poisson: float) -> float:
    """Shear modulus G = E / (2 (1 + nu)) [stress]."""
    return young / (2.0 * (1.0 + poisson))


def plane_strain_compliance(young: float, poisson: float) -> float:
    """(1 - nu^2) / E [1/stress]: the direct (log-kernel) compliance of one body."""
    return (1.0 - poisson**2) / young


def coupling_compliance(young: float, poisson: float) -> float:
    """(1 - 2 nu)(1 + nu) / (2 E) = (1 - 2 nu) / (4 G) [1/stress].

    The normal-tangential cross compliance of one half-plane: the surface
    tangential displacement under a pressure p is -c int p(s) sgn(x - s) ds.
    It vanishes exactly for nu = 0.5 (incompressible) and for a rigid body.
    """
    return (1.0 - 2.0 * poisson) * (1.0 + poisson) / (2.0 * young)


def effective_modulus(young_a: float, poisson_a: float, young_b: float, poisson_b: float) -> float:
    """Plane-strain contact modulus E* [stress], 1/E* = sum (1 - nu^2)/E."""
    inv = plane_strain_compliance(young_a, poisson_a) + plane_strain_compliance(young_b, poisson_b)
    if inv <= 0.0:
        return math.inf
    return 1.0 / inv


def effective_radius(radius_a: float, radius_b: float) -> float:
    """Effective radius R* [length], 1/R* = 1/R_A + 1/R_B (inf for a flat)."""
    curvature = 1.0 / radius_a + 1.0 / radius_b
    if curvature <= 0.0:
        return math.inf
    return 1.0 / curvature


def beta_seed(young_a: float, poisson_a: float, young_b: float, poisson_b: float) -> float:
    """The seed paper's eq. 40 'beta' (twice Dundurs' beta), dimensionless.

    beta_seed = [(1-2nu_A)/G_A - (1-2nu_B)/G_B] / [(1-nu_A)/G_A + (1-nu_B)/G_B].
    Aluminium (G=23000, nu=0.31) on steel (G=82000, nu=0.28) gives 0.288.
    """
    g_a = shear_modulus(young_a, poisson_a)
    g_b = shear_modulus(young_b, poisson_b)
    num = (1.0 - 2.0 * poisson_a) / g_a - (1.0 - 2.0 * poisson_b) / g_b
    den = (1.0 - poisson_a) / g_a + (1.0 - poisson_b) / g_b
    if den <= 0.0:
        return 0.0
    return num / den


def dundurs_beta(young_a: float, poisson_a: float, young_b: float, poisson_b: float) -> float:
    """Dundurs' beta = beta_seed / 2 (dimensionless)."""
    return 0.5 * beta_seed(young_a, poisson_a, young_b, poisson_b)


def kalker_k_over_g(young_a: float, poisson_a: float, young_b: float, poisson_b: float) -> float:
    """Kalker's K/G = [(1-2nu_A)/G_A - (1-2nu_B)/G_B] / 4 [1/stress] (note the minus)."""
    return coupling_compliance(young_a, poisson_a) - coupling_compliance(young_b, poisson_b)
