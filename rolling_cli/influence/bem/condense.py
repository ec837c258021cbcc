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

:mod:`.system` assembles A and R = [B E_c | B V] directly, column-major, with
the contact unknowns first; here A is factorised in place (LAPACK getrf), the
2 n_c + 2 right-hand sides are solved in place (getrs), and the first 2 n_c
rows of the solution give C. One LU, no copies of the (2N, 2N) matrix.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import lapack

from .mesh import BoundaryMesh
from .system import MixedSystem

#: Rows of a compliance block updated at once by the far field's rank-one terms (bounds a temporary).
_ROWS = 1024


def boundary_system(mesh: BoundaryMesh, H: np.ndarray, G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The dense square system A X = B y from H and G, in node order: X the unknown
    boundary values (u where the traction is known, t where u is known), y the
    known values; returns (A, B). (The model itself assembles A straight from
    the element integrals, :mod:`.system`; this form serves checks.)"""
    fixed = np.repeat(mesh.fixed, 2)
    A = np.where(fixed[None, :], -G, H)
    B = np.where(fixed[None, :], -H, G)
    return A, B


def factorise(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """LU of a column-major float64 matrix, in place (its storage becomes the factors): (lu, pivots)."""
    lu, pivots, info = lapack.dgetrf(matrix, overwrite_a=True)
    if info > 0:
        raise np.linalg.LinAlgError("the BEM boundary system is singular")
    return lu, pivots


def solve(factors: tuple[np.ndarray, np.ndarray], rhs: np.ndarray, overwrite: bool = False) -> np.ndarray:
    """A^-1 rhs for the factors of :func:`factorise`; ``overwrite`` solves in the (column-major) rhs."""
    x, info = lapack.dgetrs(*factors, rhs, overwrite_b=overwrite)
    if info != 0:
        raise ValueError(f"getrs: illegal argument {-info}")
    return x


def contact_blocks(solution: np.ndarray, weights: np.ndarray) -> dict[str, np.ndarray]:
    """The body's compliance blocks from the solved right-hand sides [length/stress], each (n_c, n_c).

    ``solution`` = A^-1 R (:mod:`.system` order): rows u_x, u_y at the contact
    nodes, columns t_x, t_y, F_x, F_y; ``weights`` (n_c,) [length] the
    contact quadrature weights (F = sum_j w_j t_j). In the body's frame the
    displacement into the body is -u_y, p_n = t_y and p_t = t_x:
    S_tt = du_x/dt_x, S_tn = du_x/dt_y, S_nt = -du_y/dt_x, S_nn = -du_y/dt_y,
    each plus its far-field term (du/dF) w. C-contiguous copies.
    """
    nc = weights.size
    out = {}
    blocks = (("S_tt", 0, 0, 1.0), ("S_tn", 0, 1, 1.0), ("S_nt", 1, 0, -1.0), ("S_nn", 1, 1, -1.0))
    for name, rows, column, sign in blocks:
        block = np.array(solution[rows * nc : (rows + 1) * nc, column * nc : (column + 1) * nc], order="C")
        far = solution[rows * nc : (rows + 1) * nc, 2 * nc + column]
        for start in range(0, nc, _ROWS):
            block[start : start + _ROWS] += np.outer(far[start : start + _ROWS], weights)
        if sign < 0:
            np.negative(block, out=block)
        out[name] = block
    return out


@dataclass(frozen=True)
class Condensed:
    """A factorised BEM body, ready for load cases (plain arrays, read-only use).

    ``factors`` the LU of A; ``rhs`` = R = [B E_c | B V] (M, 2 n_c + 2);
    ``unknowns`` (N, 2) the row of X for each node's component; ``far_values``
    = V (2N, 2) [length / (force/length)]; ``weights`` (n_c,) the contact
    quadrature weights [length].
    """

    mesh: BoundaryMesh
    factors: tuple
    rhs: np.ndarray
    unknowns: np.ndarray
    far_values: np.ndarray
    weights: np.ndarray


def prepare(mesh: BoundaryMesh, system: MixedSystem, weights: np.ndarray, far_values: np.ndarray) -> Condensed:
    """Factorise ``system`` (in place: its matrix becomes the LU) for load cases on ``mesh``."""
    return Condensed(mesh, factorise(system.matrix), system.rhs, system.unknowns, far_values, weights)


def boundary_values(body: Condensed, tractions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every boundary node's displacement and traction for contact nodal tractions.

    ``tractions`` (n_c, 2) [stress]: (t_x, t_y) at the contact nodes in
    increasing x. Returns u (N, 2) [length] and t (N, 2) [stress] at the
    mesh nodes, far-field conditions included.
    """
    t_c = np.asarray(tractions, dtype=float)
    force = body.weights @ t_c  # (F_x, F_y)
    loads = np.concatenate([t_c[:, 0], t_c[:, 1], force])
    solution = solve(body.factors, body.rhs @ loads)
    mesh = body.mesh
    known = body.far_values.reshape(mesh.size, 2, 2) @ force  # (N, 2): the far field, zero elsewhere
    known[mesh.contact] = t_c
    unknown = solution[body.unknowns]
    fixed = mesh.fixed[:, None]
    return np.where(fixed, known, unknown), np.where(fixed, unknown, known)
