"""The full boundary solution of a finite cylinder's BEM annulus for given contact tractions.

The compliance of :mod:`.cylinder` keeps only the contact block; interior
stresses (:mod:`rolling_cli.stresses.curved`) need every boundary node's
displacement and traction. :func:`prepare_annulus` assembles the same mesh
(:func:`.cylinder.annulus_mesh` with its default rules, so the same
discretisation as the solved compliance) and factorises its systems once;
:func:`annulus_solution` turns the contact nodal tractions, given in the
arc's own directions (p_n along the outward normal nu = (sin theta, cos theta),
p_t along the tangent tau = (cos theta, -sin theta), theta the node's polar
angle, as :mod:`.cylinder`), into the frame's x and y components and solves.
The bore is bonded (u = 0, its traction solved); the rest of the outer circle
is traction-free.
"""

from __future__ import annotations

import numpy as np

from ...model.grid import ContactGrid
from . import ring as rings
from .condense import Condensed, boundary_values, prepare
from .cylinder import annulus_mesh, contact_angles
from .mesh import BoundaryMesh
from .symmetry import reductions
from .system import mixed_systems

__all__ = ["prepare_annulus", "annulus_solution"]


def prepare_annulus(
    grid: ContactGrid, radius: float, inner_radius: float, young: float, poisson: float, mirror: bool = True
) -> Condensed:
    """Assemble and factorise the bonded annulus ``inner_radius`` < r < ``radius`` [length] around
    the contact grid (E ``young`` [stress], ``poisson``) for boundary solutions."""
    mesh = annulus_mesh(grid, radius, inner_radius)
    far = np.zeros((2 * mesh.size, 2))  # no far field: the shaft is the reference
    shear = young / (2.0 * (1.0 + poisson))
    parts = reductions(mesh, far, grid.weights, mirror)
    ring = rings.find(mesh, np.arange(grid.elements), np.array([0.0, -radius]))
    return prepare(mesh, parts, mixed_systems(mesh, shear, poisson, far, parts, ring), grid.weights, far)


def annulus_solution(
    body: Condensed, radius: float, p_n: np.ndarray, p_t: np.ndarray
) -> tuple[BoundaryMesh, np.ndarray, np.ndarray]:
    """``(mesh, u, t)``: every node's displacement u (N, 2) [length] and traction t (N, 2) [stress]
    in the frame's components, for the contact tractions ``p_n`` (negative in compression) and
    ``p_t`` (n_c,) [stress] along the arc's directions (module docstring) on the outer circle of
    ``radius`` [length]."""
    theta = contact_angles(body.mesh, radius)
    normal = np.column_stack([np.sin(theta), np.cos(theta)])
    tangent = np.column_stack([np.cos(theta), -np.sin(theta)])
    tractions = np.asarray(p_n, dtype=float)[:, None] * normal + np.asarray(p_t, dtype=float)[:, None] * tangent
    u, t = boundary_values(body, tractions)
    return body.mesh, u, t
