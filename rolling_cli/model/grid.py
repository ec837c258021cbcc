"""Discretisation of the potential contact zone (immutable).

The zone [centre - half_width, centre + half_width] is cut into ``elements``
elements: equal ones (the default, :class:`ContactGrid` built from its width
and count) or of any increasing edges (:meth:`ContactGrid.graded`, for meshes
graded towards the square-root kinks of the traction). Tractions and
displacements are interpolated on each element independently (discontinuous
elements):

* ``order = 2`` (the paper's element): quadratic, with the three nodes inside the
  element at local coordinates -2/3, 0, +2/3. On a uniform grid the nodes are
  then uniformly spaced over the whole zone with spacing h/3 (h the element
  length); the node weights (integrals of the shape functions) are
  h (3/8, 1/4, 3/8) on every element, whatever its length.
* ``order = 0``: piecewise constant, one node at each element's centre, weight h
  (the discretisation of Kalker's CONTACT).

Forces per unit axial length are weighted sums: P = -sum w p_n, Q = sum w p_t.
Each node owns a cell, half way to its neighbours (:func:`node_cell_edges`):
the contact half-width and the state zones are reported over these cells.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

#: Local coordinates of the functional nodes of each element order.
NODE_COORDINATES = {0: np.array([0.0]), 2: np.array([-2.0 / 3.0, 0.0, 2.0 / 3.0])}

#: Edges within this many ulps (of the zone's largest |x|) of the uniform ones are the uniform grid.
UNIFORM_ULPS = 16


def shape_coefficients(order: int) -> np.ndarray:
    """Monomial coefficients A[k, m] of the shape functions, N_k(xi) = sum_m A[k, m] xi^m.

    Lagrange polynomials through :data:`NODE_COORDINATES`; shape (k nodes, k powers).
    """
    nodes = NODE_COORDINATES[order]
    vander = np.vander(nodes, len(nodes), increasing=True)  # V[k, m] = xi_k^m
    return np.linalg.inv(vander).T  # A @ V.T = I


def shape_integrals(order: int) -> np.ndarray:
    """Integrals of the shape functions over the reference element [-1, 1] (dimensionless)."""
    powers = np.arange(len(NODE_COORDINATES[order]))
    moments = np.where(powers % 2 == 0, 2.0 / (powers + 1.0), 0.0)
    return shape_coefficients(order) @ moments


def node_cell_edges(x: np.ndarray) -> np.ndarray:
    """Edges of the node cells [length], shape (n + 1,), for increasing node positions ``x``.

    Interior edges lie half way between neighbouring nodes; the end cells
    reach half the end spacing beyond the end nodes (on quadratic elements that
    is exactly the zone's edge). One node: a cell of zero length.
    """
    x = np.asarray(x, dtype=float)
    if x.size < 2:
        return np.concatenate([x, x])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


@dataclass(frozen=True)
class ContactGrid:
    """Discontinuous-element grid of the potential contact zone.

    Attributes: ``half_width`` and ``centre`` [length], ``elements`` (count),
    ``order`` (0 or 2), and for a graded grid ``element_edges`` (the increasing
    edges [length], a tuple so the grid stays hashable; ``None`` for the
    uniform grid). Build graded grids with :meth:`graded`.
    """

    half_width: float
    elements: int
    order: int = 2
    centre: float = 0.0
    element_edges: tuple[float, ...] | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        if self.order not in NODE_COORDINATES:
            raise ValueError(f"element order must be 0 or 2, got {self.order}")
        if self.elements < 1 or not self.half_width > 0.0:
            raise ValueError("a contact grid needs at least one element and a positive width")
        if self.element_edges is not None:
            edges = np.asarray(self.element_edges, dtype=float)
            if edges.size != self.elements + 1 or not np.all(np.isfinite(edges)) or not np.all(np.diff(edges) > 0):
                raise ValueError("element edges must be elements + 1 finite, strictly increasing positions")

    @classmethod
    def graded(cls, edges, order: int = 2) -> ContactGrid:
        """A grid with the given increasing element ``edges`` [length] (at least two).

        Edges that are the uniform ones to round-off (:data:`UNIFORM_ULPS`) give
        the uniform grid itself, so a uniform mesh given as a graded one takes
        the uniform code paths and reproduces the uniform result bit for bit.
        """
        edges = np.asarray(edges, dtype=float)
        if edges.ndim != 1 or edges.size < 2:
            raise ValueError("a graded grid needs at least two element edges")
        centre = 0.5 * (edges[0] + edges[-1])
        half = 0.5 * (edges[-1] - edges[0])
        uniform = cls(float(half), edges.size - 1, order, float(centre)) if half > 0.0 else None
        if uniform is not None:
            tol = UNIFORM_ULPS * np.finfo(float).eps * float(np.max(np.abs(edges)))
            if np.max(np.abs(edges - uniform.edges)) <= tol:
                return uniform
        return cls(float(half), edges.size - 1, order, float(centre), tuple(float(e) for e in edges))

    @property
    def uniform(self) -> bool:
        """True for equal elements: the influence matrices are then block-Toeplitz."""
        return self.element_edges is None

    @property
    def nodes_per_element(self) -> int:
        """Functional nodes per element (1 or 3)."""
        return len(NODE_COORDINATES[self.order])

    @property
    def size(self) -> int:
        """Number of contact nodes n."""
        return self.elements * self.nodes_per_element

    @property
    def element_length(self) -> float:
        """Element length h [length]; on a graded grid the longest element's."""
        if self.uniform:
            return 2.0 * self.half_width / self.elements
        return float(self.element_lengths.max())

    @property
    def spacing(self) -> float:
        """Distance between neighbouring nodes [length]; on a graded grid the largest one."""
        if self.uniform:
            return self.element_length / self.nodes_per_element
        return float(np.diff(self.x).max())

    @cached_property
    def edges(self) -> np.ndarray:
        """Element edges [length], shape (elements + 1,)."""
        if self.element_edges is not None:
            return np.array(self.element_edges)
        return self.centre + np.linspace(-self.half_width, self.half_width, self.elements + 1)

    @cached_property
    def element_lengths(self) -> np.ndarray:
        """Length of every element [length], shape (elements,)."""
        if self.uniform:
            return np.full(self.elements, self.element_length)
        return np.diff(self.edges)

    @cached_property
    def element_centres(self) -> np.ndarray:
        """Element mid-points [length]."""
        return 0.5 * (self.edges[:-1] + self.edges[1:])

    @cached_property
    def x(self) -> np.ndarray:
        """Node positions [length], increasing, shape (n,)."""
        local = NODE_COORDINATES[self.order]
        half = 0.5 * (self.element_length if self.uniform else self.element_lengths[:, None])
        return (self.element_centres[:, None] + half * local[None, :]).ravel()

    @cached_property
    def weights(self) -> np.ndarray:
        """Quadrature weights w_i [length]: integrals of the node shape functions."""
        integrals = shape_integrals(self.order)
        if self.uniform:
            return np.tile(0.5 * self.element_length * integrals, self.elements)
        return (0.5 * self.element_lengths[:, None] * integrals[None, :]).ravel()

    @cached_property
    def cell_edges(self) -> np.ndarray:
        """Edges of the node cells [length], shape (n + 1,) (:func:`node_cell_edges`)."""
        return node_cell_edges(self.x)

    def element_of(self, x: np.ndarray) -> np.ndarray:
        """Index of the element containing each position ``x`` [length] (clipped to the zone)."""
        index = np.searchsorted(self.edges, np.asarray(x, dtype=float), side="right") - 1
        return np.clip(index, 0, self.elements - 1)
