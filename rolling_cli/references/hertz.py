"""Hertz line contact between two cylinders in plane strain.

Inputs: ``load`` P [force/length], ``radius`` R* [length], ``modulus`` E*
[stress]. Outputs in the same unit system.
"""

from __future__ import annotations

import numpy as np


def half_width(load: float, radius: float, modulus: float) -> float:
    """Hertz half-width a [length]: a^2 = 4 P R* / (pi E*)."""
    return float(np.sqrt(4.0 * load * radius / (np.pi * modulus)))


def peak_pressure(load: float, half_width_a: float) -> float:
    """Hertz peak pressure p0 [stress] = 2 P / (pi a)."""
    return float(2.0 * load / (np.pi * half_width_a))


def load_for_half_width(half_width_a: float, radius: float, modulus: float) -> float:
    """Inverse of :func:`half_width`: P [force/length] = pi a^2 E* / (4 R*)."""
    return float(np.pi * half_width_a**2 * modulus / (4.0 * radius))


def pressure(x: np.ndarray, half_width_a: float, p0: float, centre: float = 0.0) -> np.ndarray:
    """Hertz pressure p(x) = p0 sqrt(1 - (x - centre)^2 / a^2) [stress], >= 0, 0 outside."""
    xi = (np.asarray(x, dtype=float) - centre) / half_width_a
    return p0 * np.sqrt(np.clip((1.0 - xi) * (1.0 + xi), 0.0, None))  # factored: exact 0 at the edges
