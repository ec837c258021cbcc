"""Discretisation of the potential contact zone (immutable).

The zone [centre - half_width, centre + half_width] is cut into ``elements``
equal elements. Tractions and displacements are interpolated on each element
independently (discontinuous elements):

* ``order = 2`` (the paper's element): quadratic, with the three nodes inside the
  element at local coordinates -2/3, 0, +2/3. The nodes are then uniformly
  spaced over the whole zone with spacing h/3 (h the element length), and the
  node weights (integrals of the shape functions) are h (3/8, 1/4, 3/8).
* ``order = 0``: piecewise constant, one node at each element's centre, weight h
  (the discretisation of Kalker's CONTACT).

Forces per unit axial length are weighted sums: P = -sum w p_n, Q = sum w p_t.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

#: Local coordinates of the functional nodes of each element order.
NODE_COORDINATES = {0: np.array([0.0]), 2: np.array([-2.0 / 3.0, 0.0, 2.0 / 3.0])}


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


@dataclass(frozen=True)
class ContactGrid:
    """Uniform discontinuous-element grid of the potential contact zone.

    Attributes: ``half_width`` and ``centre`` [length], ``elements`` (count),
    ``order`` (0 or 2).
    """

    half_width: float
    elements: int
    order: int = 2
    centre: float = 0.0

    def __post_init__(self) -> None:
        if self.order not in NODE_COORDINATES:
            raise ValueError(f"element order must be 0 or 2, got {self.order}")
        if self.elements < 1 or not self.half_width > 0.0:
            raise ValueError("a contact grid needs at least one element and a positive width")

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
        """Element length h [length]."""
        return 2.0 * self.half_width / self.elements

    @property
    def spacing(self) -> float:
        """Uniform distance between neighbouring nodes [length]."""
        return self.element_length / self.nodes_per_element

    @cached_property
    def edges(self) -> np.ndarray:
        """Element edges [length], shape (elements + 1,)."""
        return self.centre + np.linspace(-self.half_width, self.half_width, self.elements + 1)

    @cached_property
    def element_centres(self) -> np.ndarray:
        """Element mid-points [length]."""
        return 0.5 * (self.edges[:-1] + self.edges[1:])

    @cached_property
    def x(self) -> np.ndarray:
        """Node positions [length], increasing, shape (n,)."""
        local = NODE_COORDINATES[self.order]
        return (self.element_centres[:, None] + 0.5 * self.element_length * local[None, :]).ravel()

    @cached_property
    def weights(self) -> np.ndarray:
        """Quadrature weights w_i [length]: integrals of the node shape functions."""
        per_element = 0.5 * self.element_length * shape_integrals(self.order)
        return np.tile(per_element, self.elements)
