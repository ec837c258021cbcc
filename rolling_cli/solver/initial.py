"""Cold-start initial state: Hertz pressure, Carter traction and creepage.

The closed forms are exact for similar half-planes and a fair guess otherwise;
they put the Newton iteration close to the right node states, so the solver
needs no hand-tuning. A warm start (sweeps) replaces this with a neighbouring
converged state.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..references import carter, hertz
from .formulation import State
from .system import ContactSystem


def carter_ratio_for_creep(creep: float, full_slip_creep: float) -> float:
    """Q/(mu P) [-] that Carter's relation gives for a creepage xi (saturates at +-1)."""
    if full_slip_creep <= 0.0:
        return 0.0
    ratio = min(abs(creep) / full_slip_creep, 1.0)
    return float(-np.sign(creep) * (1.0 - (1.0 - ratio) ** 2))


def cold_start(
    system: ContactSystem,
    half_width: float,
    load: float,
    mu: float,
    q_over_mu_p: float,
    creep: float | None,
    overlap: float | None,
    centre: float = 0.0,
) -> State:
    """Initial state from Hertz (half-width ``half_width`` [length], load P [force/length],
    centred on x = ``centre`` [length]) and Carter (ratio ``q_over_mu_p``, creepage ``creep``).

    The pressure is scaled so that the discrete load is exactly P. When the
    overlap is unknown (``overlap=None``), its guess makes the mean gap over the
    Hertz contact zero. When the creepage is unknown (``creep=None``), its guess
    makes the mean slip over Carter's adhesion zone zero, which also captures
    the free-rolling creepage of dissimilar materials.
    """
    w = system.load_weights  # of the load P (a finite cylinder's shaft load: w cos theta; p_t's term left out)
    x = system.x - centre
    p0 = hertz.peak_pressure(load, half_width)
    p_n = -hertz.pressure(x, half_width, p0)
    total = -(w @ p_n)
    if total > 0.0:
        p_n *= load / total
    q = float(np.clip(q_over_mu_p, -1.0, 1.0))
    p_t = carter.traction(x, q, half_width, p0, mu, system.direction) if q != 0.0 else np.zeros_like(x)
    p_t = np.clip(p_t, mu * p_n, -mu * p_n)
    inside = p_n < 0.0
    if overlap is None:
        gap = system.gap(p_n, p_t, 0.0)
        overlap = float(np.mean(gap[inside])) if inside.any() else float(gap.min())
    if creep is None:
        creep = 0.0
        if mu > 0.0:
            strain = system.slip(p_n, p_t, 0.0)
            c = carter.stick_half_width(q, half_width)
            middle = carter.stick_centre(q, half_width, system.direction)
            stick = inside & (np.abs(x - middle) < c) & (system.creep_vector > 0.0)
            creep = float(-np.mean(strain[stick])) if stick.any() else 0.0
    return State(p_n, p_t, float(overlap), float(creep))


#: Fixed-point steps of :func:`effective_friction` at most (it stops once mu_e moves by less than
#: 1e-12; the iteration is monotone and settles in 5-15 steps on the laws of issue 23).
EFFECTIVE_FRICTION_STEPS = 50


def effective_friction(
    mu_of_slip: Callable[[float], float],
    mu_static: float,
    half_width: float,
    radius: float,
    q_over_mu_p: float | None = None,
    creep: float | None = None,
) -> float:
    """The friction coefficient mu_e [-] at which Carter's solution starts a velocity-dependent law.

    ``mu_of_slip(s)`` is the law at the normalised slip |s_t| = s [-] (mu(|V| s)). Under creepage
    control (``creep`` = xi) mu_e = mu(|xi|): the slip zone's slip is of the order of the
    creepage. Under force control (``q_over_mu_p`` = Q/(mu_static P)) the creepage is not known:
    mu_e is the fixed point of mu_e = mu(|xi_C(Q, mu_e)|) with xi_C Carter's creepage at the
    ratio Q/(mu_e P) (at most 1: full slip), approached from mu_static (a falling law lowers
    mu_e and raises xi_C at each step, so the sequence falls monotonically to the largest fixed
    point; where it reaches full slip, xi_C = mu_e a / R* falls with mu_e and the fixed point is
    bracketed by the last two iterates and bisected). Carter's stick zone at mu_e is within a few
    nodes of the law's (Carter's cylinders, s_h = 100 mm/s, |V| = 45000 mm/s, 50 elements: 59 of
    100 nodes stick at xi = -0.002, 60 predicted; 23 at Q/(mu_s P) = 0.7, 25 predicted), where
    mu_static's is far larger (67, 55), and Newton moves a stick/slip boundary only a few nodes an
    iteration (benchmarks/RESULTS.md).
    ``half_width`` a [length] and ``radius`` R* [length] are Carter's.
    """
    if creep is not None:
        return float(mu_of_slip(abs(creep)))
    ratio = abs(float(q_over_mu_p or 0.0))

    def step(mu: float) -> float:  # the law at Carter's creepage for mu (full slip's beyond ratio 1)
        return float(mu_of_slip(abs(carter.creepage(min(ratio * mu_static / mu, 1.0), half_width, radius, mu))))

    mu = above = float(mu_static)
    for _ in range(EFFECTIVE_FRICTION_STEPS):
        following = step(mu)
        if abs(following - mu) <= 1e-12 * mu:
            return following
        if following > mu:  # past full slip, where the step rises as mu falls: bisect [mu, above]
            break
        mu, above = following, mu
    else:
        return mu
    below = mu  # step(below) > below, step(above) < above
    while above - below > 1e-12 * above:
        middle = 0.5 * (below + above)
        below, above = (middle, above) if step(middle) > middle else (below, middle)
    return 0.5 * (below + above)


#: Fixed-point steps of :func:`effective_hertz` (measured on the SLS roller: a and the centre settle to
#: 1e-3 a in 4; with 3, one speed of five took a Newton iteration more: the contact set is node-sharp).
EFFECTIVE_STEPS = 4


def effective_hertz(system: ContactSystem, half_width: float, load: float) -> tuple[float, float]:
    """The half-width [length] and centre [length] of the Hertz pressure (load P [force/length])
    whose normal displacement under ``system``'s compliance best fits the rigid profile: no
    tilt, and the curvature of the gap's rigid part gap0 (-1/R*).

    For elastic half-planes this is Hertz's own a (curvature ratio 1, no tilt). A viscoelastic
    body is stiffer than its relaxed modulus by an amount that depends on the time a point spends
    in the contact, and lags: the displacement of a centred Hertz pressure, fitted over the
    contact by a parabola c0 + c1 x + c2 x^2, has the curvature of an elastic body with the
    compliance k J_r (k = c2 / the rigid curvature) and its lowest point at x0 = -c1 / (2 c2).
    So a -> a sqrt(k) (a^2 grows with the compliance) and the centre moves by -x0, and again
    from there (:data:`EFFECTIVE_STEPS` times). A cold start from this Hertz pressure puts the
    Newton iteration within a node or two of the contact set (rigid roller on an SLS flat, 200
    elements, V tau_c / a = 0.9: contact half-width 0.815 a_r against 0.81 solved; 8 Newton
    iterations against 11 from Hertz with E_r). Returns the input (a, 0) where a fit is not
    possible (fewer than 5 nodes in the contact) or is not a stiffening within a factor 10.
    """
    x, w = system.x, system.weights
    a, centre = half_width, 0.0
    zero = np.zeros_like(x)
    for _ in range(EFFECTIVE_STEPS):
        inside = np.abs(x - centre) < a
        if inside.sum() < 5:
            break
        p_n = -hertz.pressure(x - centre, a, hertz.peak_pressure(load, a))
        p_n *= load / -(w @ p_n)
        shape = system.gap(p_n, zero, 0.0) - system.gap0  # the displacement, up to a constant
        t = (x[inside] - centre) / a  # centred and scaled to [-1, 1]: well-conditioned normal equations
        vandermonde = np.stack([t * t, t, np.ones_like(t)], axis=1)
        values = np.stack([shape[inside], system.gap0[inside]], axis=1)
        fit = np.linalg.solve(vandermonde.T @ vandermonde, vandermonde.T @ values)  # least squares, 3 x 3
        (c2, rigid), (c1, _) = fit[0] / a**2, fit[1] / a
        k = -c2 / rigid if rigid != 0.0 else np.nan
        if not 0.1 < k < 10.0:
            break
        # the displacement's lowest point is at centre - c1 / (2 c2): move the pressure by as much the other way
        a, centre = a * float(np.sqrt(k)), float(c1 / (2.0 * c2))
    if not abs(centre) < a:
        return half_width, 0.0
    return a, centre
