"""Frictional power: the energy that slip dissipates in the contact (cheap, in every result).

p_t is the traction on body A and s_t the slip velocity of A relative to B
divided by |V|, so the friction power that A's surface receives is
p_t s_t |V| per unit area, and Coulomb friction (p_t opposes the slip) makes it
<= 0. The dissipation density is its opposite, reported per unit rolling speed:

    d = -p_t s_t  [stress]  (>= 0; times |V| the power per unit contact area)

It is exactly zero on adhesion nodes (no slip) and on separated ones, and
equals mu |p_n| |s_t| on slip nodes. Its integral sum(w d) is the dissipated
power per unit axial length and per unit rolling speed [force/length].
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

#: The node state of slip (:data:`rolling_cli.result.STATE_NAMES`).
SLIP = 2


def density(p_t: np.ndarray, s_t: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Dissipation density per unit rolling speed, -p_t s_t on slip nodes and 0 elsewhere [stress]."""
    return np.where(np.asarray(state) == SLIP, -np.asarray(p_t) * np.asarray(s_t), 0.0)


def total(weights: np.ndarray, dissipation: np.ndarray) -> float:
    """Dissipated power per unit axial length and unit rolling speed, sum(w d) [force/length]."""
    return float(np.asarray(weights) @ np.asarray(dissipation))


def summary_line(attributes: Mapping[str, Any], line_force_unit: str) -> str | None:
    """The summary line of the frictional power, or None for results that do not carry it."""
    value = attributes.get("frictional_power_total")
    if value is None:
        return None
    return f"  friction power {value:.6g} {line_force_unit} per unit rolling speed (dissipated, sum w (-p_t s_t))"
