"""Carter (1926): steady rolling of similar elastic cylinders.

Normal and tangential problems decouple. The adhesion zone, of half-width c,
sits at the leading edge, c/a = sqrt(1 - |Q|/(mu P)). Traction (force on body A,
sign of Q):

    p_t(x) = sgn(Q) mu p0 [ sqrt(1 - x^2/a^2) - (c/a) sqrt(1 - (x - d)^2/c^2) ]

where the second term acts only inside the adhesion zone |x - d| < c and
d = a - c when the leading edge is at +x (rolling direction V < 0), d = -(a - c)
otherwise. The creepage xi = (V_A - V_B)/|V| has the sign opposite to Q:

    |xi| = (mu a / R*) (1 - sqrt(1 - |Q|/(mu P))).
"""

from __future__ import annotations

import numpy as np


def stick_half_width(q_over_mu_p: float, half_width_a: float) -> float:
    """Adhesion half-width c [length] = a sqrt(1 - |Q|/(mu P))."""
    return float(half_width_a * np.sqrt(1.0 - abs(q_over_mu_p)))


def stick_centre(q_over_mu_p: float, half_width_a: float, direction: int) -> float:
    """Centre d [length] of the adhesion zone; the leading edge is at -direction * a."""
    c = stick_half_width(q_over_mu_p, half_width_a)
    return float(-direction * (half_width_a - c))


def traction(
    x: np.ndarray, q_over_mu_p: float, half_width_a: float, p0: float, mu: float, direction: int
) -> np.ndarray:
    """Carter's tangential traction on body A, p_t(x) [stress], for rolling direction sgn(V)."""
    x = np.asarray(x, dtype=float)
    sign = float(np.sign(q_over_mu_p))
    a = half_width_a
    full = np.sqrt(np.clip((a - x) * (a + x), 0.0, None)) / a  # factored: exact 0 at the edges
    c = stick_half_width(q_over_mu_p, a)
    if c > 0.0:
        d = stick_centre(q_over_mu_p, a, direction)
        corr = np.sqrt(np.clip((c - (x - d)) * (c + (x - d)), 0.0, None)) / a
    else:
        corr = np.zeros_like(full)
    return sign * mu * p0 * np.clip(full - corr, 0.0, None)


def creepage(q_over_mu_p: float, half_width_a: float, radius: float, mu: float) -> float:
    """Carter's creepage xi = (V_A - V_B)/|V| [-]; its sign is opposite to that of Q."""
    q = float(q_over_mu_p)
    magnitude = mu * half_width_a / radius * (1.0 - np.sqrt(1.0 - abs(q)))
    return float(-np.sign(q) * magnitude)


def full_slip_creepage(half_width_a: float, radius: float, mu: float) -> float:
    """|xi| [-] at the onset of full slip (|Q| = mu P): mu a / R*."""
    return float(mu * half_width_a / radius)


# --- derivatives of Carter's creep-force law (issue 24): Q/(mu P) = 1 - (1 - s)^2, s = |xi| R* / (mu a) ---


def _slip_measure(q_over_mu_p: float) -> float:
    """s = |xi| R* / (mu a) = 1 - sqrt(1 - |Q|/(mu P)) [-]."""
    return float(1.0 - np.sqrt(1.0 - abs(q_over_mu_p)))


def creep_coefficient(q_over_mu_p: float, load: float, half_width_a: float, radius: float) -> float:
    """dQ/dxi [force/length] at fixed mu and P: -(2 P R*/a)(1 - |xi| R*/(mu a)) = -(2 P R*/a) c/a
    (negative: Q falls as xi rises, whatever the sign of Q)."""
    return float(-2.0 * load * radius / half_width_a * (1.0 - _slip_measure(q_over_mu_p)))


def friction_derivative(q_over_mu_p: float, load: float) -> float:
    """dQ/dmu [force/length] at fixed xi and P: sgn(Q) P s^2 (a at fixed P does not depend on mu)."""
    return float(np.sign(q_over_mu_p) * load * _slip_measure(q_over_mu_p) ** 2)


def load_derivative(q_over_mu_p: float, mu: float) -> float:
    """dQ/dP [-] at fixed xi and mu, with a proportional to sqrt(P) (Hertz): sgn(Q) mu s."""
    return float(np.sign(q_over_mu_p) * mu * _slip_measure(q_over_mu_p))
