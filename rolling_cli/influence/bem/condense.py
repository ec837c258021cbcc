"""Condensation of a BEM body onto its contact nodes (the paper's eq. 13).

With the bottom fixed and every other boundary traction-free, a unit nodal
traction is applied at each contact node, normally and tangentially, and the
contact displacements are solved for. All 2 n_c load cases share one LU
factorisation of the BEM system (many right-hand sides).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from .mesh import BoundaryMesh


def boundary_system(mesh: BoundaryMesh, H: np.ndarray, G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The square system A X = B y: X the unknown boundary values (u where the
    traction is known, t where u is known), y the known values; returns (A, B)."""
    fixed = np.repeat(mesh.fixed, 2)
    A = np.where(fixed[None, :], -G, H)
    B = np.where(fixed[None, :], -H, G)
    return A, B


def contact_dofs(mesh: BoundaryMesh) -> np.ndarray:
    """Degrees of freedom (2i, 2i + 1) of the contact nodes, in increasing x."""
    return (2 * mesh.contact[:, None] + np.arange(2)[None, :]).reshape(-1)


def factorise(A: np.ndarray) -> tuple:
    """LU of the boundary system, in LAPACK's column-major layout."""
    return scipy.linalg.lu_factor(np.asfortranarray(A), overwrite_a=True, check_finite=False)


def unit_load_responses(lu: tuple, B: np.ndarray, dofs: np.ndarray) -> np.ndarray:
    """Contact displacements for unit tractions at the contact dofs: all load cases at once."""
    rhs = np.asfortranarray(B[:, dofs])  # the known traction columns of the contact nodes
    solution = scipy.linalg.lu_solve(lu, rhs, overwrite_b=True, check_finite=False)
    return solution[dofs]


def contact_compliance(mesh: BoundaryMesh, H: np.ndarray, G: np.ndarray) -> np.ndarray:
    """Contact displacements per unit contact nodal traction, (2 n_c, 2 n_c) [length/stress].

    Row 2i + k: displacement component k (x, y) at contact node i; column
    2j + l: unit traction component l at contact node j. Contact nodes in
    increasing x. One LU, 2 n_c right-hand sides.
    """
    A, B = boundary_system(mesh, H, G)
    return unit_load_responses(factorise(A), B, contact_dofs(mesh))
