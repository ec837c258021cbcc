"""Cold-start initial state: Hertz pressure, Carter traction and creepage.

The closed forms are exact for similar half-planes and a fair guess otherwise;
they put the Newton iteration close to the right node states, so the solver
needs no hand-tuning. A warm start (sweeps) replaces this with a neighbouring
converged state.
"""

from __future__ import annotations

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
) -> State:
    """Initial state from Hertz (half-width ``half_width`` [length], load P [force/length])
    and Carter (ratio ``q_over_mu_p``, creepage ``creep``).

    The pressure is scaled so that the discrete load is exactly P. When the
    overlap is unknown (``overlap=None``), its guess makes the mean gap over the
    Hertz contact zero. When the creepage is unknown (``creep=None``), its guess
    makes the mean slip over Carter's adhesion zone zero, which also captures
    the free-rolling creepage of dissimilar materials.
    """
    x, w = system.x, system.weights
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
            centre = carter.stick_centre(q, half_width, system.direction)
            stick = inside & (np.abs(x - centre) < c) & (system.creep_vector > 0.0)
            creep = float(-np.mean(strain[stick])) if stick.any() else 0.0
    return State(p_n, p_t, float(overlap), float(creep))
