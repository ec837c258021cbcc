"""The mixed boundary system of a BEM body, assembled straight from the element integrals.

Collocating H u = G t at every node and moving the known boundary values y to
the right gives A X = B y, X the unknowns: u where the traction is known (the
top face), t where u is known (a layer's bonded bottom, a half-space's
truncation boundary). Only what the condensation needs is formed, each array
once and column-major for LAPACK:

* A (M, M), M = 2N: H's columns for the free degrees of freedom, -G's for the
  fixed ones, the diagonal 2x2 blocks of H from the rigid-body condition;
* the right-hand sides R = [B E_c | B V] (M, 2 n_c + 2): B's columns for the
  contact tractions (G's contact columns) and B V, the far field per unit
  resultant force (V the prescribed values per unit force, on ``mesh.far``).

B's other columns multiply zero data (zero traction off the contact, zero
displacement on a bonded bottom) and are never stored, nor are H and G.
Unknown order: the contact nodes' u_x in increasing x, then their u_y, then
the other degrees of freedom in node order; right-hand sides: t_x at the
contact nodes, then t_y, then the far field's F_x and F_y. So the first
2 n_c rows of A^-1 R are the contact displacements.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .assembly import element_blocks
from .mesh import BoundaryMesh


@dataclass(frozen=True)
class MixedSystem:
    """A X = R: ``matrix`` A (M, M) and ``rhs`` R (M, 2 n_c + 2), both column-major;
    ``unknowns`` (N, 2) the unknown number (row of X) of each node's x and y component."""

    matrix: np.ndarray
    rhs: np.ndarray
    unknowns: np.ndarray


def unknown_numbers(mesh: BoundaryMesh) -> np.ndarray:
    """(N, 2): the unknown of node j's component l; contact u_x, then contact u_y (increasing x), then the rest."""
    n, nc = mesh.size, mesh.contact.size
    out = np.empty((n, 2), dtype=np.int64)
    out[mesh.contact, 0] = np.arange(nc)
    out[mesh.contact, 1] = nc + np.arange(nc)
    others = np.setdiff1d(np.arange(n), mesh.contact)
    out[others] = 2 * nc + np.arange(2 * others.size).reshape(-1, 2)
    return out


def mixed_system(mesh: BoundaryMesh, shear: float, poisson: float, far_values: np.ndarray) -> MixedSystem:
    """Assemble A and R (module docstring) for ``mesh``: G [stress], nu, ``far_values`` V (2N, 2)
    [length / (force/length)] (row 2j + l: node j's prescribed component l per unit force along
    axis f = column; zero off ``mesh.far``)."""
    n, nc = mesh.size, mesh.contact.size
    unknowns = unknown_numbers(mesh)
    slot = np.full(n, -1)
    slot[mesh.contact] = np.arange(nc)
    far = np.asarray(far_values, dtype=float).reshape(n, 2, 2)  # [node j, component l, force axis f]
    matrix_t = np.zeros((2 * n, n, 2))  # [unknown, equation node i, direction k]: A transposed
    rhs_t = np.zeros((2 * nc + 2, n, 2))
    rowsum = np.zeros((2, n, 2))  # sum_j H[(i, k), (j, l)] as [l, i, k]
    for elements, h, g in element_blocks(mesh, shear, poisson):
        rowsum += h.sum(axis=(0, 1))
        for a in range(3):  # within one slot a, the nodes of distinct elements are distinct
            nodes = mesh.connectivity[elements, a]
            fixed = mesh.fixed[nodes]
            contact = slot[nodes] >= 0
            for l in range(2):
                matrix_t[unknowns[nodes[~fixed], l]] += h[~fixed, a, l]
                matrix_t[unknowns[nodes[fixed], l]] -= g[fixed, a, l]
                rhs_t[l * nc + slot[nodes[contact]]] += g[contact, a, l]
            on_far = mesh.far[nodes]
            if np.any(on_far):  # B V: -H's columns where u is prescribed, G's where t is
                columns = np.where(fixed[on_far, None, None, None], -h[on_far, a], g[on_far, a])
                rhs_t[2 * nc :] += np.einsum("plik,plf->fik", columns, far[nodes[on_far]])
    diagonal = -rowsum  # H[(i, k), (i, l)] as [l, i, k]: each row of H sums to zero per direction
    free = np.flatnonzero(~mesh.fixed)
    for l in range(2):
        matrix_t[unknowns[free, l], free] += diagonal[l, free]
    far_fixed = np.flatnonzero(mesh.far & mesh.fixed)
    rhs_t[2 * nc :, far_fixed] -= np.einsum("lik,ilf->fik", diagonal[:, far_fixed], far[far_fixed])
    return MixedSystem(matrix_t.reshape(2 * n, 2 * n).T, rhs_t.reshape(2 * nc + 2, 2 * n).T, unknowns)
