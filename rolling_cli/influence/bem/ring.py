"""A ring of identical elements: integrals by rotation instead of quadrature.

A finite cylinder's uniform contact grid lies on its outer circle as n
curved elements that are rotated copies of one another: element k is element
0 turned by k times the angle ``step`` about the circle's centre, with the
same local node coordinates, each with its own three (discontinuous) nodes.
Kelvin's kernels are isotropic tensors, U(Q d) = Q U(d) Q^T and
T(Q d, Q n) = Q T(d, n) Q^T for a rotation Q, so the integrals of element
k_e for the node in slot a of element k_p equal those of element 0 for the
node in slot a of element k_p - k_e, turned by Q(k_e step) on both indices.

Every such pair (the contact nodes against the contact elements: at a/R = 0.2
with 200 elements, 37 % of the pairs, and nearly all the nearly singular and
own-node ones, the costly rules) then comes from two rows computed once
(:func:`template`): the first element against every ring node (offsets
0..n-1) and the last one against every ring node (offsets -(n-1)..0), 6 n
pairs instead of 3 n^2. The rotated values agree with direct quadrature to
rounding (1e-13 of the entries: the rotated copies agree with the mesh's
elements within ``TOLERANCE`` of the radius).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh import BoundaryMesh

#: Geometric nodes of the ring's elements must match the rotated first element within this fraction of the radius.
TOLERANCE = 1e-12


@dataclass(frozen=True)
class Ring:
    """``elements`` (n,) in order round the ring; ``nodes`` (n, 3) their functional nodes;
    ``angles`` (n,) [rad] each element's rotation from element 0 (counter-clockwise)."""

    elements: np.ndarray
    nodes: np.ndarray
    angles: np.ndarray


def find(mesh: BoundaryMesh, elements: np.ndarray, centre: np.ndarray) -> Ring | None:
    """The ring of ``elements`` (in order) about ``centre`` (2,) [length], or None when they are not
    rotated copies of the first (a graded grid), share nodes, or are fewer than three."""
    elements = np.asarray(elements)
    if elements.size < 3:
        return None
    nodes = mesh.connectivity[elements]
    if np.unique(nodes).size != nodes.size:
        return None
    geometry = mesh.geometry[elements] - centre  # (n, 3, 2)
    radius = float(np.linalg.norm(geometry[0, 1]))
    mid = geometry[:, 1]
    angles = np.unwrap(np.arctan2(mid[:, 1], mid[:, 0]) - np.arctan2(mid[0, 1], mid[0, 0]))
    steps = np.diff(angles)
    if np.abs(steps - steps.mean()).max() > TOLERANCE * 1e3:  # not uniform: not a ring (avoid the check's cost)
        return None
    rotated = np.einsum("nkl,ml->nmk", rotation(angles), geometry[0])
    if np.abs(rotated - geometry).max() > TOLERANCE * radius:
        return None
    local = mesh.local[elements]
    if np.abs(local - local[0]).max() > 0.0:
        return None
    return Ring(elements, nodes, angles)


def rotation(angles: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 2, 2) by ``angles`` [rad], counter-clockwise."""
    c, s = np.cos(angles), np.sin(angles)
    return np.stack([np.stack([c, -s], axis=-1), np.stack([s, c], axis=-1)], axis=-2)


def fill(ring: Ring, template: np.ndarray, points: np.ndarray, elements: np.ndarray, h, g):
    """Write the ring's pairs among collocation ``points`` (P,) and ``elements`` (e,) into h and g
    (e, 3, 2, P, 2) (:func:`.assembly.element_blocks`' layout), rotated from ``template`` (2 for h
    and g, 2 rows: the first and the last ring element, 3, 2, 3 n ring nodes, 2). Returns the
    local numbers (p, q) of the ring's points and elements: every pair of them is written."""
    n = ring.elements.size
    position = np.full(int(max(points.max(), ring.nodes.max())) + 1, -1)
    position[ring.nodes.ravel()] = np.arange(3 * n)
    p = np.flatnonzero(position[points] >= 0)
    order = np.full(int(max(elements.max(), ring.elements.max())) + 1, -1)
    order[ring.elements] = np.arange(n)
    q = np.flatnonzero(order[elements] >= 0)
    if not (p.size and q.size):
        return p, q
    k_p, slot = np.divmod(position[points[p]], 3)
    k_e = order[elements[q]]
    offset = k_p[None, :] - k_e[:, None]  # (e, m)
    last = offset < 0
    index = np.where(last, 3 * n, 0) + 3 * np.where(last, n - 1 + offset, offset) + slot[None, :]
    # Q M Q^T for each 2x2 block, stored transposed (X = M^T, X' = Q X Q^T): vec(X') = (Q kron Q) vec(X)
    spin = [_kron(ring.angles[k_e] - ring.angles[end]) for end in (0, n - 1)]  # (e, 4, 4) each
    kron = np.where(last[:, :, None, None], spin[1][:, None], spin[0][:, None]).swapaxes(-1, -2)  # (e, m, 4, 4)
    rows_q, cols_p = _span(q), _span(p)
    for target, values in ((h, template[0]), (g, template[1])):
        # values (2 rows, 3 j, 2 l, 3 n, 2 k) -> (2 * 3 n, 3 j, 4 (l, k)): a node's values contiguous
        per_node = values.transpose(0, 3, 1, 2, 4).reshape(6 * n, 3, 4)
        rotated = np.matmul(per_node[index], kron)  # (e, m, 3, 4)
        rotated = rotated.reshape(q.size, p.size, 3, 2, 2).transpose(0, 2, 3, 1, 4)  # (e, j, l, m, k)
        if isinstance(rows_q, slice) and isinstance(cols_p, slice):
            target[rows_q, :, :, cols_p] = rotated
        else:
            for k, element in enumerate(q):
                target[element][:, :, p] = rotated[k]
    return p, q


def _kron(angles: np.ndarray) -> np.ndarray:
    """Q kron Q (n, 4, 4) for rotations by ``angles`` (n,) [rad]: acts on a 2x2 matrix flattened by rows."""
    q = rotation(angles)
    return np.einsum("nab,ncd->nacbd", q, q).reshape(-1, 4, 4)


def _span(index: np.ndarray):
    """A slice for a contiguous increasing index array, else the array."""
    if index[-1] - index[0] == index.size - 1 and np.all(np.diff(index) == 1):
        return slice(int(index[0]), int(index[-1]) + 1)
    return index
