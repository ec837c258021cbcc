"""A-posteriori error indicator per element: the jumps of the discontinuous traction.

The tractions are interpolated element by element (discontinuous elements),
so at every element edge the two neighbouring interpolants give two values.
For a smooth traction they differ by the interpolation error, O(h^3) on
quadratic elements; at a square-root kink (contact edge, stick/slip boundary)
by about the kink's amplitude over one element, A sqrt(h), which is where the
maximum error sits. The indicator of an element is the largest jump at its two edges, of
p_t / (mu p0) and of p_n / p0 (only the latter when mu = 0); at the zone's ends
the interpolant is compared with zero (the traction vanishes outside the
contact). The global estimate of the maximum traction error is the largest
indicator.

Measured against the true error (benchmarks/adaptive.py, results in
benchmarks/results/adaptive.md): the largest indicator was 2.2 to 59 times the
largest nodal traction error (median 4-9) on uniform meshes, on graded meshes
with an edge on each exact kink and on every level of the adaptive runs, for
Carter's case (closed form) and the dissimilar case (fine reference). It is
an upper bound there, not a sharp one.

A limit: the jumps see local errors only. The kinks' positions are coupled
through the whole solution, and a kink displaced by a tiny distance d turns a
square root A sqrt(x - x_k) into a traction error of about A sqrt(d) next to
it with small jumps on a fine local mesh. A mesh that resolves one kink far
more coarsely than another can hide such an error (measured on the dissimilar
case: a leading stick/slip boundary left at 7e-3 a moved the trailing one by
5e-7 a, a 2e-3 mu p0 error under a largest jump of 4e-4). On uniform meshes,
and on the adaptive meshes of :mod:`.remesh`, which refine every kink alike,
the study found no such case.
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid, shape_coefficients


def edge_values(grid: ContactGrid, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each element's interpolant of nodal ``values`` at its left and right edge (elements,) each."""
    per_element = np.asarray(values, dtype=float).reshape(grid.elements, grid.nodes_per_element)
    monomials = per_element @ shape_coefficients(grid.order)  # coefficients of 1, xi, xi^2
    powers = np.arange(monomials.shape[1])
    return monomials @ (-1.0) ** powers, monomials.sum(axis=1)


def edge_jumps(grid: ContactGrid, values: np.ndarray) -> np.ndarray:
    """|jump| of the interpolated ``values`` at every element edge (elements + 1,), zero outside the zone."""
    left, right = edge_values(grid, values)
    outer = np.concatenate([[0.0], right])  # value from the element on the left of each edge
    inner = np.concatenate([left, [0.0]])  # value from the element on the right
    return np.abs(inner - outer)


def element_indicator(grid: ContactGrid, p_n: np.ndarray, p_t: np.ndarray, mu: float, p0: float) -> np.ndarray:
    """Indicator eta_e [-] per element: the largest traction jump at its edges, / (mu p0) or / p0.

    ``p_n``, ``p_t`` [stress] are the nodal tractions on ``grid``, ``mu`` the
    friction coefficient and ``p0`` the peak pressure [stress].
    """
    jumps = edge_jumps(grid, p_n) / p0
    if mu > 0.0:
        jumps = np.maximum(jumps, edge_jumps(grid, p_t) / (mu * p0))
    return np.maximum(jumps[:-1], jumps[1:])


def patch_indicator(indicator: np.ndarray) -> np.ndarray:
    """The largest indicator over each element and its two neighbours (a local bound that
    covers the spreading of a kink's error onto the next element)."""
    padded = np.pad(np.asarray(indicator, dtype=float), 1)
    return np.maximum(np.maximum(padded[:-2], padded[1:-1]), padded[2:])
