"""Quadratic isoparametric boundary elements.

Geometry: three geometric nodes (start, middle, end) with the standard
quadratic shape functions on xi in [-1, 1]. Fields (displacement, traction):
quadratic Lagrange shape functions through three functional nodes whose local
coordinates depend on the element kind:

* continuous: (-1, 0, 1), end nodes shared with the neighbours;
* discontinuous: (-2/3, 0, 2/3), all nodes inside (the paper's contact elements);
* partially discontinuous: the node at a corner (or at a change of element
  kind) is moved in to -2/3 or 2/3, so no collocation point sits at a corner.
"""

from __future__ import annotations

import functools

import numpy as np

DISCONTINUOUS = 2.0 / 3.0
GEOMETRY_NODES = np.array([-1.0, 0.0, 1.0])


def functional_nodes(start_discontinuous: bool, end_discontinuous: bool) -> np.ndarray:
    """Local coordinates of the three functional nodes of an element."""
    return np.array([-DISCONTINUOUS if start_discontinuous else -1.0, 0.0, DISCONTINUOUS if end_discontinuous else 1.0])


def lagrange_coefficients(nodes: np.ndarray) -> np.ndarray:
    """A[..., k, m] with N_k(xi) = sum_m A[k, m] xi^m for the given node sets (..., 3)."""
    vander = nodes[..., :, None] ** np.arange(3)  # V[k, m] = xi_k^m
    return np.swapaxes(np.linalg.inv(vander), -1, -2)


def evaluate(coefficients: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """Shape function values N[..., g, k] at points xi[..., g] (coefficients (..., 3, 3))."""
    xi = np.asarray(xi, dtype=float)
    powers = np.stack([np.ones_like(xi), xi, xi * xi], axis=-1)  # (..., g, m): products, 5x faster than pow
    return np.matmul(powers, np.swapaxes(coefficients, -1, -2))


GEOMETRY_COEFFICIENTS = lagrange_coefficients(GEOMETRY_NODES)


def map_points(geometry: np.ndarray, xi: np.ndarray):
    """Points, unit outward normals and Jacobians at local coordinates.

    ``geometry`` (E, 3, 2) geometric nodes; ``xi`` (E, G) or (G,). Returns
    points (E, G, 2), normals (E, G, 2) and |dx/dxi| (E, G). The boundary is
    traversed with the domain on the left, so n = (t_y, -t_x).
    """
    xi = np.broadcast_to(xi, geometry.shape[:1] + np.shape(xi)[-1:])
    shape = evaluate(GEOMETRY_COEFFICIENTS, xi)  # (E, G, 3)
    deriv_powers = np.stack([np.zeros_like(xi), np.ones_like(xi), 2.0 * xi], axis=-1)
    dshape = np.einsum("egm,km->egk", deriv_powers, GEOMETRY_COEFFICIENTS)
    points = np.einsum("egk,ekd->egd", shape, geometry)
    tangent = np.einsum("egk,ekd->egd", dshape, geometry)
    jac = np.sqrt(tangent[..., 0] ** 2 + tangent[..., 1] ** 2)
    normal = np.stack([tangent[..., 1], -tangent[..., 0]], axis=-1) / jac[..., None]
    return points, normal, jac


@functools.lru_cache(maxsize=32)
def gauss(order: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre points and weights on [-1, 1] (computed once per order: read-only arrays)."""
    points, weights = np.polynomial.legendre.leggauss(order)
    points.setflags(write=False)
    weights.setflags(write=False)
    return points, weights
