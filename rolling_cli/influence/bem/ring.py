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
    if np.any(np.diff(np.sort(nodes.ravel())) == 0):  # a node shared by two elements
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
    p = p[np.argsort(position[points[p]], kind="stable")]  # the points in ring order
    at = position[points[p]]  # (m,) their ring positions 3 k + a, increasing
    k_e = order[elements[q]]
    # Q M Q^T for each 2x2 block, stored transposed (X = M^T, X' = Q X Q^T): vec(X') = (Q kron Q) vec(X)
    spins = [_kron(ring.angles[k_e] - ring.angles[end]).swapaxes(-1, -2) for end in (0, n - 1)]  # (e, 4, 4)
    # values (2 rows, 3 j, 2 l, 3 n, 2 k) -> (2 rows, 3 n, 12 (j, l, k)): a node's values contiguous
    per_node = [values.transpose(0, 3, 1, 2, 4).reshape(2, 3 * n, 12) for values in template]
    contiguous = bool(np.all(np.diff(at) == 1))
    splits = np.searchsorted(at, 3 * k_e)  # points before: the last element's row; from there: the first's
    for target, nodes in zip((h, g), per_node, strict=True):
        out = np.empty((q.size, p.size, 3, 4))
        for k in range(q.size):  # one rotation per element and row: two matrix products (3 m', 4) x (4, 4)
            cut = splits[k]
            for lo, hi, row, shift in ((cut, p.size, 0, -3 * k_e[k]), (0, cut, 1, 3 * (n - 1 - k_e[k]))):
                if hi > lo:
                    source = slice(at[lo] + shift, at[hi - 1] + shift + 1) if contiguous else at[lo:hi] + shift
                    block = nodes[row, source].reshape(-1, 4)
                    np.matmul(block, spins[row][k], out=out[k, lo:hi].reshape(-1, 4))
        rotated = out.reshape(q.size, p.size, 3, 2, 2).transpose(0, 2, 3, 1, 4)  # (e, j, l, m, k)
        rows, columns = _progression(q), _progression(p)
        if rows is not None and columns is not None:  # one strided copy
            target[rows, :, :, columns] = rotated
            continue
        for k, element in enumerate(q):
            target[element][:, :, p] = rotated[k]
    return p, q


def _progression(index: np.ndarray) -> slice | None:
    """A slice for an index array in steps of +1 or -1, else None."""
    if index.size == 1:
        return slice(int(index[0]), int(index[0]) + 1)
    step = int(index[1] - index[0])
    if step not in (1, -1) or not np.all(np.diff(index) == step):
        return None
    stop = int(index[-1]) + step
    return slice(int(index[0]), stop if stop >= 0 else None, step)


def _kron(angles: np.ndarray) -> np.ndarray:
    """Q kron Q (n, 4, 4) for rotations by ``angles`` (n,) [rad]: acts on a 2x2 matrix flattened by rows."""
    q = rotation(angles)
    return np.einsum("nab,ncd->nacbd", q, q).reshape(-1, 4, 4)
