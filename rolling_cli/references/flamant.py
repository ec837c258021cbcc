"""Flamant: a line force on the surface of an elastic half-plane (plane strain).

Frame: x along the surface, z the depth into the body (z >= 0), the force at
the origin. Polar coordinates r and theta, theta measured from the +z axis
towards +x (the surface is theta = +-pi/2). A force per unit length with
components F_x (tangential, along +x) and F_z (normal, into the body: a
compressive load P has F_z = P) gives the purely radial stress

    sigma_rr = -(2 / pi) (F_z cos(theta) + F_x sin(theta)) / r.

With k = 2 (1 - nu^2) / (pi E) and c = 2 nu (1 + nu) / (pi E) the plane-strain
displacements (integrated from Hooke's law) are, in polar components,

    F_z:  u_r = -k cos(theta) ln(r/D) - (k - c)/2 theta sin(theta)
          u_t =  k sin(theta) ln(r/D) + (k + c)/2 sin(theta) - (k - c)/2 theta cos(theta)
    F_x:  u_r = -k sin(theta) ln(r/D) + (k - c)/2 theta cos(theta)
          u_t = -k cos(theta) ln(r/D) - (k + c)/2 cos(theta) - (k - c)/2 theta sin(theta)

plus, for F_x, the translation u_x = (k + c)/2. These rigid-body terms make
the displacement vanish at the point (0, D), at depth D below the force (the
reference of the normal approach); the rotation vanishes at infinity (the
fields are bounded in theta and homogeneous of degree 0 in r, as the
closed-form half-plane kernels of :mod:`rolling_cli.influence.halfplane`).
On the surface they reduce to Johnson's (Contact Mechanics, 2.2):
u_x = -(1 - 2 nu)(1 + nu)/(2E) F_z sgn(x) - k F_x ln|x| + const and
u_z = -k F_z ln|x| + (1 - 2 nu)(1 + nu)/(2E) F_x sgn(x) + const.
"""

from __future__ import annotations

import numpy as np


def _polar(x: np.ndarray, z: np.ndarray):
    x = np.asarray(x, dtype=float)
    z = np.asarray(z, dtype=float)
    r = np.hypot(x, z)
    theta = np.arctan2(x, z)  # from +z towards +x; +-pi/2 on the surface
    return r, theta, np.sin(theta), np.cos(theta)


def displacement(x, z, young: float, poisson: float, reference_depth: float) -> np.ndarray:
    """Displacements per unit line force, u[..., k, l] [length / (force/length)].

    Component k (0: u_x, 1: u_z, z into the body) at the points (x, z)
    (z >= 0, not at the origin) for a unit force along axis l (0: F_x
    tangential, 1: F_z normal, into the body) at the surface origin. Zero at
    (0, ``reference_depth``).
    """
    r, theta, s, c_ = _polar(x, z)
    k = 2.0 * (1.0 - poisson**2) / (np.pi * young)
    c = 2.0 * poisson * (1.0 + poisson) / (np.pi * young)
    log = np.log(r / reference_depth)
    half_minus, half_plus = 0.5 * (k - c), 0.5 * (k + c)
    # normal force F_z
    ur_n = -k * c_ * log - half_minus * theta * s
    ut_n = k * s * log + half_plus * s - half_minus * theta * c_
    # tangential force F_x
    ur_t = -k * s * log + half_minus * theta * c_
    ut_t = -k * c_ * log - half_plus * c_ - half_minus * theta * s
    out = np.empty(r.shape + (2, 2))
    # e_r = (sin, cos), e_theta = (cos, -sin) in (x, z)
    out[..., 0, 1] = ur_n * s + ut_n * c_
    out[..., 1, 1] = ur_n * c_ - ut_n * s
    out[..., 0, 0] = ur_t * s + ut_t * c_ + half_plus  # translation: u_x(0, D) = 0
    out[..., 1, 0] = ur_t * c_ - ut_t * s
    return out


def stress(x, z) -> np.ndarray:
    """Stresses per unit line force, sigma[..., (xx, zz, xz), l] [1/length].

    For a unit force along axis l (0: F_x, 1: F_z into the body) at the
    surface origin; independent of the material. Tension positive.
    """
    r, theta, s, c_ = _polar(x, z)
    out = np.empty(r.shape + (3, 2))
    for axis, amplitude in ((0, s), (1, c_)):
        radial = -(2.0 / np.pi) * amplitude / r
        out[..., 0, axis] = radial * s * s
        out[..., 1, axis] = radial * c_ * c_
        out[..., 2, axis] = radial * s * c_
    return out
