"""Power balance and rolling resistance of a steadily rolling finite roller on a rigid flat.

Body A is a finite cylinder (annulus on a rigid shaft or core, outer radius
R, :mod:`rolling_cli.influence.finite`) turning about its fixed shaft at
omega, V_A = omega R; the rigid flat B moves at V_B; xi = (V_A - V_B)/|V|.
Arc frame: a node at arc length s sits at theta = s / R, with outward normal
nu and tangent tau; the traction on A is p nu + t tau (p = p_n <= 0,
t = p_t), the surface displacement -w nu + u tau (w into the body, u along
tau). Per unit axial length, and per unit |V| where a power is meant.

**Power put in**: the shaft's torque T on A (angular
momentum: T = -(moment of the contact tractions about the centre)) at omega,
and the force F_B that drives the flat (its equilibrium: F_B = the contact
force on A, F) at V_B:

    Pi_in = T omega + F_x V_B.

**Losses**: the hysteresis D_A (the deformation power in A's material frame,
which rotates with it: the rate of the displacement components at a material
point is V d/ds, so D_A = sgn(V) |V| int (-p w' + t u') ds, the loss
compliance of :func:`rolling_cli.references.annulus.hysteresis_power` mode by
mode) and friction D_f = -|V| int t s_t ds, with the model's slip
s_t = xi + sgn(V) eps, eps = u' - w/R the hoop strain.

**The linear model's identity.** Adding D_A and D_f, and eliminating w' with
the derivative of the model's gap on the contact (the flat's gap is
g0 - d + cos(theta) w + sin(theta) u = 0 with g0 = R (1 - cos theta), so
-w' = tan(theta) (1 + eps) + u/R):

    (D_A + D_f) / |V| + xi Q = sgn(V) [ int p tan(theta) (1 + eps) ds + int (p u + t w) / R ds ].

Each term on the right is a force on the pair's kinematics: the first is the
horizontal resultant of the pressure on the stretched arc (the pressure
pushes the flat back along x: the half-space's sum w p_n x / R up to the
strain eps and O(a/R)^2);
the second is T's second-order part divided by R: the moment about the shaft
of the tractions at their displaced points of application (lever R - w for
the shear, u for the radial pressure), T = -(R Q + T_u), T_u =
-int (w t + u p) ds (``shaft_torque_displacement``). With F_x = Q + int p
tan(theta) (1 + eps) ds (the arc sum Q of the shear plus the pressure's
push), the identity is Pi_in = D_A + D_f to second order in the
displacements:

    sgn(V) (F_x - (R Q + T_u) / R) = (D_A + D_f) / |V| + xi Q.

So the **rolling-resistance force** of a finite roller is

    F_rr = sgn(V) [ int p tan(theta) (1 + eps) ds + int (p u + t w) / R ds ]
         = (hysteresis + frictional power) / |V| + xi Q,

the power balance's force (positive resisting), computed from the tractions
and the solver's surface displacements, and the rolling-resistance
coefficient is F_rr / P. Its F_x is the one the linearised gap implies (Q
plus the pressure's push on the stretched arc), not the x-resultant of the
arc-frame tractions, sum w (p_n sin(theta) + p_t cos(theta))
(``shaft_tangential_load``): with that resultant the balance misses the
losses by 0.5-7 % at a/R = 0.05-0.31 (the review's measurement), the linear
theory's O(P (a/R)^2) ambiguity of the traction directions, the order of
T_u / R itself. So the identity, like the half-space's M / R, checks the
contact side against the bodies' loss (Michell's modal route), not the
direction of the tractions at large a/R. On a half-space (R -> inf at
fixed a) F_rr -> sgn(V) sum w p_n x / R = M / R, so F_rr / P is M / (P R) in
that limit. The naive |V| M / R keeps the first term only: T_u is O(a/R)
relative to the pressure's push times a / (the pressure shift), 17 % of the
losses in the shipped rubber roller (a/R = 0.12); the identity itself closes
to the discretisation (0.2 %, tests/test_viscoelastic_roller_power.py).

Scope: a finite body A against a rigid flat B, quadratic elements (the
viscoelastic finite cylinder's grid); otherwise :func:`roller_on_flat` is
not used and the outputs are NaN.
"""

from __future__ import annotations

import numpy as np

from .grid import shape_coefficients

__all__ = ["roller_on_flat"]

_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def roller_on_flat(
    x: np.ndarray,
    element_length: float,
    radius: float,
    direction: int,
    p_n: np.ndarray,
    p_t: np.ndarray,
    w: np.ndarray,
    u: np.ndarray,
) -> dict[str, float]:
    """The finite roller's rolling-resistance force and the displaced points' torque (module docstring).

    ``x`` arc lengths of the nodes [length] (3 per quadratic element of length ``element_length``),
    ``radius`` R [length], ``direction`` sgn(V), ``p_n``, ``p_t`` [stress] the tractions on A,
    ``w``, ``u`` [length] A's surface displacements (into the body, along the arc). Returns
    ``rolling_resistance_force`` F_rr [force/length] and ``shaft_torque_displacement`` T_u
    [moment/length], each element's quadratic integrated by 12-point Gauss-Legendre.
    """
    coeff = shape_coefficients(2)
    shapes = (coeff @ np.vstack([np.ones_like(_GL_X), _GL_X, _GL_X**2])).T  # (g, 3)
    slopes = (coeff @ np.vstack([np.zeros_like(_GL_X), np.ones_like(_GL_X), 2.0 * _GL_X])).T
    half = 0.5 * float(element_length)

    def at_points(f):
        return np.asarray(f, dtype=float).reshape(-1, 3) @ shapes.T

    s, p, t, wg, ug = (at_points(f) for f in (x, p_n, p_t, w, u))
    eps = np.asarray(u, dtype=float).reshape(-1, 3) @ slopes.T / half - wg / radius  # hoop strain u' - w/R
    weights = half * _GL_W

    def integral(f):
        return float(np.sum(weights * f))

    push = integral(p * np.tan(s / radius) * (1.0 + eps))
    torque_u = -integral(wg * t + ug * p)
    return {
        "rolling_resistance_force": float(direction) * (push - torque_u / radius),
        "shaft_torque_displacement": torque_u,
    }
