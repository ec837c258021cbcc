"""Condensation of a BEM body onto its contact nodes (the paper's eq. 13).

The body's boundary values are known everywhere except the unknowns of the
square system A X = B y (u where the traction is known, t where u is known).
A load case is the contact tractions t_c (zero traction elsewhere on the top
face) plus, on a half-space's truncation boundary, the far-field displacement
of their resultant F = sum_j w_j t_j (:mod:`.farfield`):

    y = E_c t_c + V F,   F = W t_c,

with E_c the injection of the contact dofs, V the far-field values per unit
force (2N, 2) and W (2, 2 n_c) the resultant weights. The contact
displacements are then linear in t_c, and all 2 n_c unit load cases plus the
2 far-field ones share one LU factorisation of A (many right-hand sides):

    C = (A^-1 B E_c)_c + (A^-1 B V)_c W.
"""

from __future__ import annotations

from dataclasses import dataclass

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


def resultant_weights(weights: np.ndarray) -> np.ndarray:
    """W (2, 2 n_c): the resultant force F_l = sum_j w_j t_(j, l) of contact nodal tractions."""
    out = np.zeros((2, weights.size, 2))
    out[0, :, 0] = weights
    out[1, :, 1] = weights
    return out.reshape(2, 2 * weights.size)


@dataclass(frozen=True)
class Condensed:
    """A factorised BEM body, ready for load cases (plain arrays, read-only use).

    ``lu`` the LU of A; ``rhs`` = [B E_c | B V] (2N, 2 n_c + 2), column-major:
    the right-hand sides per unit contact traction and per unit resultant
    force; ``far_values`` = V (2N, 2); ``resultant`` = W (2, 2 n_c).
    """

    mesh: BoundaryMesh
    lu: tuple
    rhs: np.ndarray
    far_values: np.ndarray
    resultant: np.ndarray


def prepare(mesh: BoundaryMesh, H: np.ndarray, G: np.ndarray, weights: np.ndarray, far_values: np.ndarray) -> Condensed:
    """Factorise the boundary system of ``mesh`` and form its load right-hand sides.

    ``weights`` (n_c,) are the contact nodes' quadrature weights [length];
    ``far_values`` (2N, 2) the prescribed values per unit resultant force
    (:func:`.farfield.far_field_values`; zeros for a body without far field).
    """
    A, B = boundary_system(mesh, H, G)
    dofs = contact_dofs(mesh)
    rhs = np.empty((B.shape[0], dofs.size + 2), order="F")
    rhs[:, : dofs.size] = B[:, dofs]
    np.matmul(B, far_values, out=rhs[:, dofs.size :])
    return Condensed(mesh, factorise(A), rhs, far_values, resultant_weights(weights))


def contact_compliance(body: Condensed, consume: bool = False) -> np.ndarray:
    """Contact displacements per unit contact nodal traction, (2 n_c, 2 n_c) [length/stress].

    Row 2i + k: displacement component k (x, y) at contact node i; column
    2j + l: unit traction component l at contact node j. Contact nodes in
    increasing x. One LU, 2 n_c + 2 right-hand sides. ``consume=True`` solves
    in the body's own right-hand sides (no copy; the body is unusable after).
    """
    dofs = contact_dofs(body.mesh)
    solution = scipy.linalg.lu_solve(body.lu, body.rhs, overwrite_b=consume, check_finite=False)[dofs]
    n = dofs.size
    flex = solution[:, :n]
    flex += solution[:, n:] @ body.resultant
    return flex


def boundary_values(body: Condensed, tractions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every boundary node's displacement and traction for contact nodal tractions.

    ``tractions`` (n_c, 2) [stress]: (t_x, t_y) at the contact nodes in
    increasing x. Returns u (N, 2) [length] and t (N, 2) [stress] at the
    mesh nodes, far-field conditions included.
    """
    t_c = np.asarray(tractions, dtype=float).reshape(-1)
    force = body.resultant @ t_c
    solution = scipy.linalg.lu_solve(body.lu, body.rhs @ np.concatenate([t_c, force]), check_finite=False)
    known = body.far_values @ force
    known[contact_dofs(body.mesh)] = t_c
    fixed = np.repeat(body.mesh.fixed, 2)
    u = np.where(fixed, known, solution)
    t = np.where(fixed, solution, known)
    return u.reshape(-1, 2), t.reshape(-1, 2)
