"""Reductions of a BEM body's boundary system: the whole system, or its two mirror halves.

A body whose mesh is its own mirror image in x = 0 (the rectangle around a
contact zone centred there) has a boundary system that commutes with the
reflection P, (P v)_j = S v_j' with j' the mirror node of j and S = diag(-1, 1).
Every load splits into a symmetric part (P y = y) and an antisymmetric one
(P y = -y), whose responses stay in their own subspaces: two systems of half
the size, collocated at the nodes with x >= 0 only. The LU and the solves
cost a quarter, the element integrals half.

A :class:`Reduction` parametrises its subspace by values at the nodes with
x >= 0: node j's component l is ``sign[j, l]`` times parameter
``unknown[j, l]`` (-1 and 0: none). Symmetric half: on x > 0 both components
(sign 1), at the mirror node S (signs -1, 1); on x = 0 only u_y (u_x
vanishes there). Antisymmetric: -S at the mirror nodes; on x = 0 only u_x.
The whole system is the reduction with every node its own parameter. The
parameters (and the equations, collocated at the same node components) are
numbered with the contact nodes' x components first, then their y
components (increasing x), then the rest in node order; so the first
``contact`` rows of the solution are contact displacements. A unit load on
node j's component l is the sum over the reductions of ``weight[j, l]``
times the unit load on its parameter (weight = sign / 2 on a mirrored pair,
sign on x = 0 and in the whole system).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh import BoundaryMesh

#: Nodes (or values) mirror each other within this fraction of the mesh size (of the values' scale).
MIRROR_TOLERANCE = 1e-10


@dataclass(frozen=True)
class Reduction:
    """One system: ``points`` (P,) its collocation nodes; ``unknown`` (N, 2) each node
    component's parameter (-1: none); ``sign`` and ``weight`` (N, 2); ``forces`` the
    far-field force axes (0: x, 1: y) whose responses it carries; ``size`` its number of
    unknowns M and ``contact`` how many of them (the first) are contact displacements."""

    points: np.ndarray
    unknown: np.ndarray
    sign: np.ndarray
    weight: np.ndarray
    forces: tuple[int, ...]
    size: int
    contact: int


def reductions(mesh: BoundaryMesh, far_values: np.ndarray, weights: np.ndarray, mirror: bool = True):
    """The two mirror halves when ``mirror`` and the body is mirror-symmetric (mesh, supports,
    far-field values (2N, 2), contact weights (n_c,)), else the whole system: a list of
    :class:`Reduction`."""
    if mirror:
        pairs = mirror_nodes(mesh)
        if pairs is not None and _symmetric_data(mesh, pairs, far_values, weights):
            return [_half(mesh, pairs, parity) for parity in (1.0, -1.0)]
    n = mesh.size
    keep = np.ones((n, 2), dtype=bool)
    return [_numbered(mesh, np.arange(n), keep, np.ones((n, 2)), np.ones((n, 2)), (0, 1))]


def mirror_nodes(mesh: BoundaryMesh) -> np.ndarray | None:
    """(N,) the mirror node j' of each node j (j' = j on x = 0), or None when the mesh is not its own
    mirror image in x = 0 (nodes, elements with their local node coordinates, supports)."""
    nodes = mesh.nodes
    tolerance = MIRROR_TOLERANCE * float(np.abs(nodes).max())
    pairs = _match(nodes, nodes * np.array([-1.0, 1.0]), tolerance)
    if pairs is None:
        return None
    if not (np.array_equal(mesh.fixed[pairs], mesh.fixed) and np.array_equal(mesh.far[pairs], mesh.far)):
        return None
    if not np.array_equal(np.sort(pairs[mesh.contact]), np.sort(mesh.contact)):
        return None
    # elements: the mirror of each is an element, traversed the other way round
    mirrored = pairs[mesh.connectivity[:, ::-1]]
    found = {tuple(row): e for e, row in enumerate(mesh.connectivity.tolist())}
    partner = np.array([found.get(tuple(row), -1) for row in mirrored.tolist()])
    if np.any(partner < 0) or not np.allclose(mesh.local[partner], -mesh.local[:, ::-1], rtol=0.0, atol=1e-12):
        return None
    return pairs


def _match(points: np.ndarray, targets: np.ndarray, tolerance: float) -> np.ndarray | None:
    """The permutation with points[match] = targets within ``tolerance``, or None. Coordinates are
    binned at the tolerance, on two grids half a bin apart (a pair that round-off puts on both sides of
    a bin edge of one grid lies inside a bin of the other)."""
    for offset in (0.0, 0.5):
        keys = np.round(points / tolerance + offset).astype(np.int64)
        wanted = np.round(targets / tolerance + offset).astype(np.int64)
        order = np.lexsort((keys[:, 0], keys[:, 1]))
        back = np.lexsort((wanted[:, 0], wanted[:, 1]))
        if np.array_equal(keys[order], wanted[back]):
            match = np.empty(points.shape[0], dtype=np.int64)
            match[back] = order  # points[order[r]] matches targets[back[r]]
            if np.abs(points[match] - targets).max() <= tolerance:
                return match
    return None


def _symmetric_data(mesh: BoundaryMesh, pairs: np.ndarray, far_values: np.ndarray, weights: np.ndarray) -> bool:
    """The far field of F_x antisymmetric and of F_y symmetric; the contact weights symmetric."""
    far = np.asarray(far_values, dtype=float).reshape(mesh.size, 2, 2)  # [node, component, force axis]
    flip = np.array([-1.0, 1.0])
    scale = max(float(np.abs(far).max()), np.finfo(float).tiny)
    mirrored = far[pairs] * flip[None, :, None] * np.array([-1.0, 1.0])[None, None, :]
    if np.abs(mirrored - far).max() > MIRROR_TOLERANCE * scale:
        return False
    index = np.full(mesh.size, -1)
    index[mesh.contact] = np.arange(mesh.contact.size)
    w = np.asarray(weights, dtype=float)
    return bool(np.abs(w[index[pairs[mesh.contact]]] - w).max() <= MIRROR_TOLERANCE * np.abs(w).max())


def _half(mesh: BoundaryMesh, pairs: np.ndarray, parity: float) -> Reduction:
    """The symmetric (parity 1) or antisymmetric (-1) half."""
    x = mesh.nodes[:, 0]
    size = float(np.abs(mesh.nodes).max())
    axis = pairs == np.arange(mesh.size)
    right = ~axis & (x > 0.0)
    sign = np.zeros((mesh.size, 2))
    sign[right] = 1.0
    left = ~axis & ~right
    sign[left] = parity * np.array([-1.0, 1.0])
    keep = np.zeros((mesh.size, 2), dtype=bool)
    keep[right] = True
    keep[axis, 1 if parity > 0 else 0] = True  # u_x (symmetric) or u_y (antisymmetric) vanishes on x = 0
    sign[axis] = keep[axis]
    weight = np.where(axis[:, None], sign, 0.5 * sign)
    if np.any(np.abs(x[axis]) > MIRROR_TOLERANCE * size):
        raise ValueError("mirror nodes off x = 0 map to themselves")
    representative = np.where(left, pairs, np.arange(mesh.size))
    forces = (1,) if parity > 0 else (0,)  # F_y loads the symmetric half, F_x the antisymmetric one
    return _numbered(mesh, np.flatnonzero(right | axis), keep, sign, weight, forces, representative)


def _numbered(mesh, points, keep, sign, weight, forces, representative=None) -> Reduction:
    """Number the kept components of ``points``; every node component takes its representative's parameter."""
    n = mesh.size
    is_contact = np.zeros(n, dtype=bool)
    is_contact[mesh.contact] = True
    contact = mesh.contact  # increasing x
    own = np.full((n, 2), -1, dtype=np.int64)
    count = 0
    for component in range(2):  # contact x components, then contact y components
        chosen = contact[keep[contact, component]]
        own[chosen, component] = count + np.arange(chosen.size)
        count += chosen.size
    contact_count = count
    rest = points[~is_contact[points]]
    rest_keep = keep[rest]
    order = np.flatnonzero(rest_keep.ravel())
    own.reshape(-1)[(2 * rest[:, None] + np.arange(2)).ravel()[order]] = count + np.arange(order.size)
    count += order.size
    representative = np.arange(n) if representative is None else representative
    unknown = np.where(sign != 0.0, own[representative], -1)
    return Reduction(points, unknown, sign, weight, tuple(forces), count, contact_count)
