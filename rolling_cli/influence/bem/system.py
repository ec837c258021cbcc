"""The mixed boundary systems of a BEM body, assembled straight from the element integrals.

Collocating H u = G t at the nodes and moving the known boundary values y to
the right gives A X = B y, X the unknowns: u where the traction is known (the
top face), t where u is known (a layer's bonded bottom, a half-space's
truncation boundary). Per :class:`~.symmetry.Reduction` (the whole system, or
each mirror half: equations at its collocation nodes, unknowns its
parameters) only what the condensation needs is formed, each array once and
column-major for LAPACK:

* A (M, M): H's columns for the free degrees of freedom, -G's for the fixed
  ones (combined by the reduction's signs), the diagonal 2x2 blocks of H from
  the rigid-body condition;
* the right-hand sides R = [B E_c | B V] (M, m + f): B's columns for the
  reduction's m contact parameters (G's contact columns) and B V, the far
  field per unit resultant force along its force axes (V the prescribed values
  per unit force, on ``mesh.far``).

B's other columns multiply zero data (zero traction off the contact, zero
displacement on a bonded bottom) and are never stored, nor are H and G. The
equations are ordered as the collocation nodes' kept components; the
unknowns as the reduction numbers them (contact first), so the first m rows
of A^-1 R are contact displacements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .assembly import element_blocks
from .mesh import BoundaryMesh
from .symmetry import Reduction


@dataclass(frozen=True)
class MixedSystem:
    """A X = R: ``matrix`` A (M, M) and ``rhs`` R (M, m + f), both column-major."""

    matrix: np.ndarray
    rhs: np.ndarray


def mixed_systems(
    mesh: BoundaryMesh, shear: float, poisson: float, far_values: np.ndarray, parts: list[Reduction], ring=None
) -> list[MixedSystem]:
    """Assemble A and R (module docstring) of each reduction in ``parts`` (which share their
    collocation nodes) for ``mesh``: G [stress], nu, ``far_values`` V (2N, 2) [length / (force/length)]
    (row 2j + l: node j's prescribed component l per unit force along axis f = column; zero off
    ``mesh.far``). One pass over the element integrals serves them all; ``ring`` as
    :func:`.assembly.element_blocks`."""
    points = parts[0].points
    far = np.asarray(far_values, dtype=float).reshape(mesh.size, 2, 2)  # [node j, component l, force axis f]
    sinks = [_Sink(mesh, part, points) for part in parts]
    rowsum = np.zeros((2, points.size, 2))  # sum_j H[(i, k), (j, l)] as [l, p, k], i = points[p]
    for elements, h, g in element_blocks(mesh, shear, poisson, points, ring):
        rowsum += h.sum(axis=(0, 1))
        for a in range(3):  # within one slot a, the nodes of distinct elements are distinct
            nodes = mesh.connectivity[elements, a]
            for sink in sinks:
                sink.add(nodes, h[:, a], g[:, a], far)
    return [sink.finish(-rowsum, far) for sink in sinks]


class _Sink:
    """Accumulates one reduction's A (transposed: [unknown, equation]) and R from the element blocks."""

    def __init__(self, mesh: BoundaryMesh, part: Reduction, points: np.ndarray):
        self.mesh, self.part, self.points = mesh, part, points
        valid = (part.unknown[points] >= 0).ravel()  # the equations: the kept components (p, k) of the points
        if np.count_nonzero(valid) != part.size:
            raise ValueError("a reduction needs as many equations as unknowns")
        self.row_of = np.where(valid, np.cumsum(valid) - 1, -1).reshape(points.size, 2)
        # the kept equations as runs of consecutive (p, k) positions: source and target slices
        edges = np.flatnonzero(np.diff(np.concatenate([[False], valid, [False]]).astype(np.int8)))
        rank = self.row_of.ravel()
        starts, stops = edges[::2], edges[1::2]
        self.runs = [(slice(lo, hi), slice(rank[lo], rank[lo] + hi - lo)) for lo, hi in zip(starts, stops, strict=True)]
        self.matrix_t = np.zeros((part.size, part.size))
        self.rhs_t = np.zeros((part.contact + len(part.forces), part.size))
        # each parameter gathers two node columns on a mirrored pair: add the nodes in two passes,
        # the collocation nodes (their own representatives) and the others, so no parameter repeats in a pass
        self.first = np.zeros(mesh.size, dtype=bool)
        self.first[points] = True

    def _add(self, target: np.ndarray, cols: np.ndarray, columns: np.ndarray, sign: float) -> None:
        """target[cols] += sign * the kept equations of ``columns`` (count, P, 2); sign +-1.

        Strided runs of ``cols`` are added through views, in place."""
        flat = columns.reshape(columns.shape[0], -1)
        where = _span(cols)
        for source, kept in self.runs:
            if sign > 0:
                target[where, kept] += flat[:, source]
            else:
                target[where, kept] -= flat[:, source]

    def add(self, nodes, h, g, far) -> None:
        """Add the columns of ``nodes`` (e,), one per element: h, g (e, 2, P, 2) = [element, l, p, k]."""
        part, mesh = self.part, self.mesh
        first, fixed = self.first[nodes], mesh.fixed[nodes]
        for l in range(2):
            has = part.unknown[nodes, l] >= 0
            for own in (True, False):  # the sign is the same for every node of one pass
                for prescribed in (False, True):
                    index = np.flatnonzero(has & (first == own) & (fixed == prescribed))
                    if not index.size:
                        continue
                    sign = part.sign[nodes[index], l]
                    if np.any(sign != sign[0]):
                        raise ValueError("a pass of node columns mixes signs")
                    cols = part.unknown[nodes[index], l]
                    rows = _span(index)
                    if prescribed:  # A's column is -G's
                        self._add(self.matrix_t, cols, g[rows, l], -sign[0])
                        continue
                    self._add(self.matrix_t, cols, h[rows, l], sign[0])
                    contact = cols < part.contact  # contact parameters: the first unknowns (free nodes)
                    if np.all(contact):
                        self._add(self.rhs_t, cols, g[rows, l], sign[0])
                    elif np.any(contact):
                        self._add(self.rhs_t, cols[contact], g[index[contact], l], sign[0])
        on_far = np.flatnonzero(mesh.far[nodes])
        if on_far.size:  # B V over every far node column: -H's where u is prescribed, G's where t is
            columns = np.where(mesh.fixed[nodes[on_far], None, None, None], -h[on_far], g[on_far])
            values = far[nodes[on_far]][:, :, list(part.forces)]  # (count, l, f)
            product = np.einsum("clpk,clf->fpk", columns, values)
            self._add(self.rhs_t, part.contact + np.arange(len(part.forces)), product, 1.0)

    def finish(self, diagonal: np.ndarray, far: np.ndarray) -> MixedSystem:
        """Add H's diagonal blocks (``diagonal`` [l, p, k] = H[(i, k), (i, l)], i = points[p]); return A, R."""
        part, mesh, points = self.part, self.mesh, self.points
        for l in range(2):
            free = np.flatnonzero(~mesh.fixed[points] & (part.unknown[points, l] >= 0))
            cols = part.unknown[points[free], l]
            sign = part.sign[points[free], l]
            for k in range(2):
                rows = self.row_of[free, k]
                kept = rows >= 0
                self.matrix_t[cols[kept], rows[kept]] += sign[kept] * diagonal[l, free[kept], k]
        far_fixed = np.flatnonzero(mesh.far[points] & mesh.fixed[points])
        if far_fixed.size:  # B V: -H's diagonal blocks where u is prescribed (the points' own columns)
            values = far[points[far_fixed]][:, :, list(part.forces)]  # (count, l, f)
            product = np.einsum("lck,clf->fck", diagonal[:, far_fixed], values)  # (f, count, k)
            for k in range(2):
                rows = self.row_of[far_fixed, k]
                kept = rows >= 0
                self.rhs_t[part.contact :, rows[kept]] -= product[:, kept, k]
        return MixedSystem(self.matrix_t.T, self.rhs_t.T)


def _span(index: np.ndarray):
    """A slice for an index array in arithmetic progression (so the addition goes through a view), else the array."""
    if index.size == 1:
        return slice(int(index[0]), int(index[0]) + 1)
    step = int(index[1] - index[0]) if index.size > 1 else 0
    if step != 0 and np.all(np.diff(index) == step):
        stop = int(index[-1]) + step
        return slice(int(index[0]), stop if stop >= 0 else None, step)
    return index
