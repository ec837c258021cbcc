"""The accuracy estimate of one adaptive level: the traction jumps and the kink motion.

The estimate of the maximum traction error, as a fraction of mu p0 (of p0 when
mu = 0; p0 the solution's peak pressure), is the larger of

* the **jumps**: the largest element indicator, the jump of the discontinuous
  traction at an element edge, of p_t / (mu p0) and p_n / p0
  (:mod:`.indicator`): the local error next to a square-root kink;
* the **kink motion**: how far each kink (contact edge, stick/slip boundary)
  moved since the previous level, Delta, through the traction change that
  makes next to it (:func:`.kinks.displacement_change`, about A sqrt(Delta)).
  The jumps do not see a kink that is well resolved at a slightly wrong place:
  the kinks are coupled through the whole solution. Measured on Carter's case
  at the finest levels (smallest elements 2e-8 a): a contact edge displaced by
  4e-9 a made an error of 3e-5 mu p0 under jumps of 2e-5; with the motion
  term the estimate was 2.3 to 34 times the true error on every level.

How the estimate compares with the true error over the study:
``benchmarks/results/adaptive.md`` (never below it there).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.grid import ContactGrid
from . import indicator, kinks


@dataclass(frozen=True)
class LevelFields:
    """What the adaptive decision needs of a solved level: its grid and nodal fields.

    ``p_n``, ``p_t`` [stress], ``gap`` [length], ``state`` (0 separation,
    1 adhesion, 2 slip), ``overlap`` [length], ``creep`` [-], ``mu`` [-],
    ``iterations`` and ``seconds`` of its solve.
    """

    grid: ContactGrid
    p_n: np.ndarray
    p_t: np.ndarray
    gap: np.ndarray
    state: np.ndarray
    overlap: float
    creep: float
    mu: float
    iterations: int = 0
    seconds: float = 0.0


@dataclass(frozen=True)
class Estimate:
    """One level's estimate [-] and its parts: ``jumps``, ``motion``, the indicator per element
    ``eta`` [-], and the located kinks (``positions`` [length], ``kinds``)."""

    value: float
    jumps: float
    motion: float
    eta: np.ndarray
    positions: np.ndarray
    kinds: np.ndarray


def estimate(level: LevelFields, previous: tuple | None = None) -> Estimate:
    """The estimate of ``level``'s maximum traction error; ``previous`` the kinks (positions,
    kinds) of the level before it (None for the first)."""
    grid = level.grid
    eta, jumps = traction_estimate(grid, level.p_n, level.p_t, level.mu)
    positions, kinds = kinks.locate(grid.x, level.p_n, level.p_t, level.gap, level.state, level.mu, grid)
    p0 = float(np.max(-level.p_n)) if level.p_n.size else 0.0
    shifts = kink_shifts(previous, positions, kinds)
    changes = kinks.displacement_change(
        grid.x, level.p_n, level.p_t, level.state, level.mu, positions, kinds, p0, shifts
    )
    motion = float(changes.max(initial=0.0))
    return Estimate(max(jumps, motion), jumps, motion, eta, positions, kinds)


def traction_estimate(grid: ContactGrid, p_n: np.ndarray, p_t: np.ndarray, mu: float) -> tuple[np.ndarray, float]:
    """Element indicators eta_e [-] and the estimate of the maximum traction error, max eta_e [-].

    Tractions [stress] on ``grid``'s nodes; scales mu p0 (p0 = max(-p_n), the
    solution's peak pressure) for p_t and p0 for p_n.
    """
    p0 = float(np.max(-p_n)) if p_n.size else 0.0
    if not p0 > 0.0:
        return np.zeros(grid.elements), 0.0
    eta = indicator.element_indicator(grid, p_n, p_t, mu, p0)
    return eta, float(eta.max())


def kink_shifts(previous: tuple | None, positions: np.ndarray, kinds: np.ndarray) -> np.ndarray:
    """Distance [length] from each kink to the nearest kink of the same kind in ``previous`` =
    (positions, kinds) (0 without a previous level, or for a kink with no previous one of its
    kind: its own jumps measure it)."""
    shifts = np.zeros(positions.shape)
    if previous is None:
        return shifts
    before, before_kinds = np.asarray(previous[0]), np.asarray(previous[1])
    for k, (position, kind) in enumerate(zip(positions, kinds, strict=True)):  # a handful of kinks
        same = before[before_kinds == kind]
        if same.size:
            shifts[k] = float(np.min(np.abs(same - position)))
    return shifts
