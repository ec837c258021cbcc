"""One adaptive step: from a solution on a grid to the next grid (kinks, grading, indicator).

The composition that the adaptive loop repeats (phase 2 runs it on the
solver's continuation driver; ``benchmarks/adaptive.py`` prototypes it):

1. the indicator eta_e of every element (:mod:`.indicator`);
2. the kinks (:mod:`.kinks`): contact edges and stick/slip boundaries;
3. the smallest element at the kinks: there eta ~ sqrt(h), so the elements
   touching a kink ask for h (safety tolerance / eta)^2; the smallest request
   applies to every kink (:func:`kink_sizes` says why), but not below a
   fraction of the element that holds the kink
   (:data:`KINK_RESOLUTION`, per kind): the kink is only known to a fraction
   of that element (:mod:`.kinks`: contact edges to about 0.04 node spacings
   from the gap, stick/slip boundaries to 0.35), and elements finer than the
   uncertainty would grade towards the wrong point; the next solve locates
   it better;
4. a grid graded geometrically towards the kinks from those sizes (:mod:`.grading`),
   no element longer than the current longest;
5. every other element whose indicator exceeds safety * tolerance imposes
   h (safety tolerance / eta)^(1/(order + 1)) over its extent
   (:func:`.refine.limit_lengths`): away from a kink the traction is smooth and
   the jumps fall like h^(order + 1). Optionally (``coarsen``, the adaptive
   loop's choice) elements far below the target may grow by a bounded factor,
   so that a fine uniform start does not stay fine where nothing happens.
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid
from . import kinks as kinks_mod
from .grading import graded_edges
from .refine import desired_lengths, limit_lengths

#: Fraction of the tolerance aimed at, and the grading ratio near kinks (measured best of
#: 1.3 to 2.0 on Carter's case: benchmarks/adaptive.py).
SAFETY = 0.5
GROWTH = 1.6
#: The smallest element relative to the element that holds a kink (its location uncertainty).
KINK_RESOLUTION = {kinks_mod.CONTACT_EDGE: 0.03, kinks_mod.STICK_SLIP: 0.1}
#: The smallest element relative to the zone width (round-off of the slip differences).
SMALLEST_FRACTION = 1e-8


def kink_elements(grid: ContactGrid, kinks: np.ndarray) -> np.ndarray:
    """Mask of the elements containing or touching a kink position [length]."""
    mask = np.zeros(grid.elements, dtype=bool)
    if kinks.size:
        index = grid.element_of(kinks)
        for shift in (-1, 0, 1):
            mask[np.clip(index + shift, 0, grid.elements - 1)] = True
    return mask


def kink_sizes(
    grid: ContactGrid, indicator: np.ndarray, kinks: np.ndarray, kinds: np.ndarray, target: float
) -> np.ndarray:
    """Element length [length] wanted at each kink: the smallest request (h (target / eta)^2) of the
    elements touching ANY kink, bounded below by :data:`KINK_RESOLUTION` of the element holding it.

    Every kink gets the same request, however small its own jumps: the kinks' positions are
    coupled through the whole solution, and a weak kink left coarse (located to a fraction of
    a coarse element) moves a strong one, whose square root turns a tiny displacement into a
    large traction error that no local jump shows (measured on the dissimilar case: the
    leading stick/slip boundary, resolved to 7e-3 a, moved the trailing one by 5e-7 a and
    its traction by 2e-3 mu p0 while the largest jump was 4e-4).
    """
    requested = desired_lengths(grid, indicator, target)
    index = grid.element_of(kinks)
    touching = np.clip(index[:, None] + np.arange(-1, 2)[None, :], 0, grid.elements - 1)
    resolution = np.array([KINK_RESOLUTION[kind] for kind in kinds])
    floor = np.maximum(resolution * grid.element_lengths[index], SMALLEST_FRACTION * 2.0 * grid.half_width)
    return np.maximum(requested[touching].min(), floor)


def next_grid(
    grid: ContactGrid,
    indicator: np.ndarray,
    kinks: np.ndarray,
    kinds: np.ndarray,
    tolerance: float,
    safety: float = SAFETY,
    growth: float = GROWTH,
    coarsen: float = 1.0,
    largest: float | None = None,
) -> ContactGrid:
    """The grid for the next solve, from the ``indicator`` per element of ``grid``, the ``kinks``
    [length] of its solution and their ``kinds`` (:func:`rolling_cli.adapt.kinks.locate_kinks`), and
    the ``tolerance`` (the indicator's units, e.g. a fraction of mu p0).

    ``coarsen`` > 1 lets elements away from the kinks whose indicator is below the target grow by
    up to that factor (the smooth field's rate, h^(order + 1)), and the longest element grow to
    ``coarsen`` times the current longest but not beyond ``largest`` [length]; by default no
    element grows.
    """
    target = safety * tolerance
    near = kink_elements(grid, kinks)
    h = grid.element_lengths
    longest = float(h.max())
    if coarsen > 1.0 and largest is not None:
        longest = max(longest, min(coarsen * longest, largest))
    sizes = kink_sizes(grid, indicator, kinks, kinds, target) if kinks.size else h.min()
    lower, upper = grid.centre - grid.half_width, grid.centre + grid.half_width
    edges = graded_edges(lower, upper, kinks, np.minimum(sizes, longest), longest, growth)
    smooth = desired_lengths(grid, indicator, target, rate=grid.order + 1.0, coarsen=coarsen)
    smooth = np.maximum(smooth, SMALLEST_FRACTION * 2.0 * grid.half_width)  # the same floor as at the kinks
    edges = limit_lengths(edges, grid.edges, np.where(near, np.inf, smooth))
    return ContactGrid.graded(edges, grid.order)
