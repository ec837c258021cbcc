"""Transfer (prolongation) of a solution onto another contact grid of the same zone.

Each nodal field is interpolated with the shape functions of the OLD element
that contains the new node (the discontinuous interpolant of the solution
itself, so a field that the old grid represents exactly is transferred
exactly, e.g. from a grid to its refinement). The tractions are then made
admissible: p_n <= 0 and |p_t| <= mu |p_n|. The overlap and the creepage carry
over unchanged: the zone, and with it the reference length of the log kernel,
are the same.
"""

from __future__ import annotations

import numpy as np

from ..model.grid import NODE_COORDINATES, ContactGrid, shape_coefficients

#: Old node spacings by which a located contact edge is pulled into the contact.
EDGE_MARGIN = 0.3


def interpolate(grid: ContactGrid, values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The element interpolant of nodal ``values`` on ``grid`` at positions ``x`` [length] (same units)."""
    per_element = np.asarray(values, dtype=float).reshape(grid.elements, grid.nodes_per_element)
    x = np.asarray(x, dtype=float)
    element = grid.element_of(x)
    xi = (x - grid.element_centres[element]) / (0.5 * grid.element_lengths[element])
    coeff = shape_coefficients(grid.order)  # N_k(xi) = sum_m coeff[k, m] xi^m
    powers = xi[:, None] ** np.arange(len(NODE_COORDINATES[grid.order]))[None, :]
    shapes = powers @ coeff.T  # (points, k)
    return np.einsum("ik,ik->i", shapes, per_element[element])


def prolong(grid: ContactGrid, values: np.ndarray, new_grid: ContactGrid) -> np.ndarray:
    """Nodal ``values`` on ``grid`` interpolated at the nodes of ``new_grid`` (same units)."""
    return interpolate(grid, values, new_grid.x)


def transfer_tractions(
    grid: ContactGrid,
    p_n: np.ndarray,
    p_t: np.ndarray,
    mu: float,
    new_grid: ContactGrid,
    contact_edges: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Tractions [stress] of a solution on ``grid`` carried to ``new_grid``, admissible.

    Near each end of the contact the pressure follows the square root of a
    Hertzian edge instead of the old interpolant: from the second outermost
    old contact node x_in to the edge x_e (``contact_edges`` [length], the
    located ones of :func:`rolling_cli.adapt.kinks.contact_edges`; without
    them, the old outermost contact node), p_n(x) = p_n(x_in) sqrt((x_e - x) /
    (x_e - x_in)), and zero beyond. A finer grid then starts with the contact
    set of the located edges, pulled in by :data:`EDGE_MARGIN` old node
    spacings (their uncertainty): Newton gains missing contact nodes in one
    iteration but sheds surplus ones about one per iteration.
    """
    new_n = np.minimum(prolong(grid, p_n, new_grid), 0.0)
    contact = np.flatnonzero(p_n < 0.0)
    x = new_grid.x
    if contact.size < 3:
        new_n[:] = 0.0
    else:
        ends = [(contact[0], contact[1], -1), (contact[-1], contact[-2], 1)]
        for outer, inner, side in ends:  # the two ends of the contact
            edge = grid.x[outer]
            if contact_edges is not None and np.size(contact_edges):
                nearest = np.asarray(contact_edges)[np.argmin(np.abs(np.asarray(contact_edges) - edge))]
                edge = float(nearest)
            x_in = grid.x[inner]
            edge += EDGE_MARGIN * (x_in - grid.x[outer])  # towards the inner node: err on the small side
            beyond = side * (x - edge) >= 0.0
            between = ~beyond & (side * (x - x_in) > 0.0)
            new_n[beyond] = 0.0
            new_n[between] = p_n[inner] * np.sqrt((edge - x[between]) / (edge - x_in))
    bound = -mu * new_n
    new_t = np.clip(prolong(grid, p_t, new_grid), -bound, bound)
    return new_n, new_t
