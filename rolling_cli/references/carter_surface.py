"""Surface stress sigma_xx(x, 0) of Carter's rolling contact, in closed form.

Half-plane frame and signs of :mod:`rolling_cli.stresses.halfplane`: on the
surface of a body carrying the pressure p (p_n = -p) and the tangential
traction q on that body along +x,

    sigma_xx(x, 0) = -p(x) - (2/pi) pv int q(s) / (x - s) ds       (tension > 0).

Carter's traction on body A (:mod:`.carter`) is
q_A = sgn(Q) mu p0 [ sqrt(1 - s^2/a^2) - (c/a) sqrt(1 - (s - d)^2/c^2) ]
and body B carries q_B = -q_A. Both terms are semi-ellipses, whose Hilbert
transforms are elementary: with y = (x - m)/r for a semi-ellipse of centre m
and half-width r,

    pv int_{m-r}^{m+r} sqrt(1 - (s - m)^2/r^2) / (x - s) ds = pi (y - sgn(y) sqrt(y^2 - 1) [|y| > 1]).

At the trailing edge (x = -a for direction -1, +a for direction +1) the
pressure vanishes and, with k = c/a = sqrt(1 - |Q|/(mu P)), the surface
carries the tension

    sigma_xx = 2 mu p0 (k - 1 + 2 sqrt(1 - k))

on the body whose traction points away from that edge (A when Q > 0 and the
trailing edge is at -a), the largest surface tension of the contact; k = 0
(full slip) gives Smith & Liu's 2 mu p0, k = 1 (free rolling) zero.
"""

from __future__ import annotations

import numpy as np

from . import carter


def semi_ellipse_hilbert(x, centre: float, half_width: float) -> np.ndarray:
    """pv int sqrt(1 - (s - centre)^2/half_width^2) / (x - s) ds [-] over |s - centre| < half_width."""
    y = (np.asarray(x, dtype=float) - centre) / half_width
    outside = np.sqrt(np.clip(y * y - 1.0, 0.0, None))
    return np.pi * (y - np.sign(y) * outside)


def sigma_xx(x, q_over_mu_p: float, a: float, p0: float, mu: float, direction: int, body: str = "A") -> np.ndarray:
    """Carter's surface sigma_xx(x, 0) [stress] of ``body`` ("A" or "B") at positions ``x`` [length].

    ``a`` the contact half-width [length], ``p0`` the peak pressure [stress],
    ``direction`` the rolling direction sgn(V) (the leading edge at
    -direction * a), ``q_over_mu_p`` the signed Q/(mu P) with Q on body A.
    """
    x = np.asarray(x, dtype=float)
    c = carter.stick_half_width(q_over_mu_p, a)
    d = carter.stick_centre(q_over_mu_p, a, direction)
    hilbert = semi_ellipse_hilbert(x, 0.0, a)
    if c > 0.0:
        hilbert = hilbert - (c / a) * semi_ellipse_hilbert(x, d, c)
    sign = float(np.sign(q_over_mu_p)) * (1.0 if body == "A" else -1.0)
    pressure = p0 * np.sqrt(np.clip((a - x) * (a + x), 0.0, None)) / a
    return -pressure - (2.0 / np.pi) * sign * mu * p0 * hilbert


def trailing_edge_tension(q_over_mu_p: float, p0: float, mu: float) -> float:
    """The surface tension [stress] at the trailing contact edge: 2 mu p0 (k - 1 + 2 sqrt(1 - k))."""
    k = float(np.sqrt(1.0 - abs(q_over_mu_p)))
    return 2.0 * mu * p0 * (k - 1.0 + 2.0 * np.sqrt(1.0 - k))


def trailing_edge(q_over_mu_p: float, a: float, direction: int) -> tuple[float, str]:
    """Where the trailing-edge tension sits: (x [length], body label)."""
    x = float(direction) * a  # the trailing edge is opposite the leading one (-direction * a)
    body = "A" if (q_over_mu_p > 0.0) == (x < 0.0) else "B"
    return x, body
