"""Refinement of a contact grid where an error indicator exceeds a target.

An element whose indicator eta_e exceeds the target is split into k equal
elements, with k from the indicator's convergence rate: eta ~ h^rate gives
k = ceil((eta_e / target)^(1 / rate)), capped at ``max_split``. The default rate
1/2 is that of a square-root kink (the elements that need refining); smooth
regions converge faster, so they are over-refined rather than under-refined.
The refined grid is then smoothed so that neighbouring elements differ in
length by at most ``max_ratio`` (the larger one is split), which keeps the
node spacing, and with it the slip operator, regular. Elements are never merged.

:func:`desired_lengths` and :func:`limit_lengths` do the same through a
length field: the length each element of one grid should have, imposed on the
elements of another (a freshly graded grid, :mod:`.grading`).
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid


def split_counts(indicator: np.ndarray, target: float, rate: float = 0.5, max_split: int = 16) -> np.ndarray:
    """Pieces per element [-]: 1 where eta_e <= target, else ceil((eta_e/target)^(1/rate)) <= max_split."""
    eta = np.asarray(indicator, dtype=float)
    ratio = np.maximum(eta / target, 1.0)
    counts = np.ceil(ratio ** (1.0 / rate) - 1e-9).astype(int)
    return np.clip(counts, 1, max_split)


def split_elements(edges: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Edges [length] with element e cut into counts[e] equal parts."""
    edges = np.asarray(edges, dtype=float)
    counts = np.asarray(counts, dtype=int)
    element = np.repeat(np.arange(counts.size), counts)
    piece = np.arange(element.size) - np.repeat(np.cumsum(counts) - counts, counts)
    lo, length = edges[element], np.diff(edges)[element]
    return np.concatenate([lo + length * piece / counts[element], edges[-1:]])


def smooth_edges(edges: np.ndarray, max_ratio: float = 2.0, max_passes: int = 64) -> np.ndarray:
    """Split elements until neighbouring lengths differ by at most ``max_ratio`` (> 1)."""
    edges = np.asarray(edges, dtype=float)
    for _ in range(max_passes):  # each pass halves the excess ratio; a few passes suffice
        h = np.diff(edges)
        neighbour = np.minimum(np.concatenate([h[1:], [np.inf]]), np.concatenate([[np.inf], h[:-1]]))
        counts = np.ceil(h / (max_ratio * neighbour) - 1e-9).astype(int)
        counts = np.maximum(counts, 1)
        if np.all(counts == 1):
            return edges
        edges = split_elements(edges, np.minimum(counts, 2))
    return edges


def desired_lengths(
    grid: ContactGrid, indicator: np.ndarray, target: float, rate: float = 0.5, coarsen: float = 1.0
) -> np.ndarray:
    """Element length [length] that brings each element's indicator to ``target``: h (target/eta)^(1/rate).

    Elements below the target may grow by at most ``coarsen`` (>= 1; 1: they keep their length).
    """
    eta = np.asarray(indicator, dtype=float)
    ratio = target / np.maximum(eta, np.finfo(float).tiny)
    factor = np.minimum(ratio ** (1.0 / rate), coarsen) if coarsen > 1.0 else np.minimum(ratio, 1.0) ** (1.0 / rate)
    return grid.element_lengths * factor


def limit_lengths(
    edges: np.ndarray, field_edges: np.ndarray, lengths: np.ndarray, max_ratio: float = 2.0
) -> np.ndarray:
    """Edges [length] split so that no element is longer than the field's length where it lies.

    The field is piecewise constant: ``lengths[e]`` [length] over
    [field_edges[e], field_edges[e+1]]; an element gets the smallest value of the
    field elements it overlaps. The result is smoothed (:func:`smooth_edges`).
    """
    edges = np.asarray(edges, dtype=float)
    field_edges = np.asarray(field_edges, dtype=float)
    last = lengths.size - 1
    first = np.clip(np.searchsorted(field_edges, edges[:-1], side="right") - 1, 0, last)
    final = np.clip(np.searchsorted(field_edges, edges[1:], side="left") - 1, first, last)
    # min over each overlapped range [first, final]: reduceat over interleaved (start, stop) pairs
    padded = np.concatenate([np.asarray(lengths, dtype=float), [np.inf]])
    bounds = np.column_stack([first, final + 1]).ravel()
    allowed = np.minimum.reduceat(padded, bounds)[::2]
    counts = np.maximum(np.ceil(np.diff(edges) / allowed - 1e-9).astype(int), 1)
    return smooth_edges(split_elements(edges, counts), max_ratio)


def refine(
    grid: ContactGrid,
    indicator: np.ndarray,
    target: float,
    rate: float = 0.5,
    max_split: int = 16,
    max_ratio: float = 2.0,
) -> ContactGrid:
    """The grid with every element of ``indicator`` > ``target`` split (:func:`split_counts`), smoothed.

    ``indicator`` and ``target`` share their units (the indicator's, e.g. a
    fraction of mu p0). Returns ``grid`` itself when nothing exceeds the target.
    """
    counts = split_counts(indicator, target, rate, max_split)
    if np.all(counts == 1):
        return grid
    edges = smooth_edges(split_elements(grid.edges, counts), max_ratio)
    return ContactGrid.graded(edges, grid.order)
