"""Far-field conditions that make a truncated BEM body model a half-space.

A finite block with a fixed bottom and free sides carries the resultant of the
contact tractions as a column does: a uniform lateral strain and a rotation
that a half-space does not have, decaying only like a/W. Instead, the
truncation boundary (sides and bottom) is given the displacement of the
half-space under the resultant force, Flamant's solution
(:mod:`rolling_cli.references.flamant`) for a line force at the origin. The
remainder, the half-space field of the tractions' moments (a dipole, ~1/r
against Flamant's ln r), decays like a/r on the boundary, so the strain it
leaves at the contact falls like (a/W)^2 relative to the contact strains.

The resultant F = sum_j w_j t_j is linear in the contact tractions, so the far
field is a rank-2 term of the condensed compliance: the responses to two extra
right-hand sides (unit F_x, unit F_y) of the same LU.

Reference of the normal approach: the far field vanishes at the point
(0, -D) at depth D below the contact centre (the middle of the bottom face),
so the condensed normal displacement is the approach of the contact surface
towards that point, each body being a half-space.

Frame of the block: x along the surface, y up, the body below y = 0 (Flamant's
depth z = -y, F_z = -F_y, u_z = -u_y).
"""

from __future__ import annotations

import numpy as np

from ...references import flamant
from .mesh import BoundaryMesh


def half_space_displacement(points: np.ndarray, young: float, poisson: float, reference_depth: float) -> np.ndarray:
    """Half-space displacement per unit resultant force, (..., 2, 2) [length / (force/length)].

    Entry [..., k, l]: component k (x, y) at ``points`` (..., 2) in the block
    frame for a unit force on the body along axis l (x, y) at the origin; zero
    at (0, -``reference_depth``).
    """
    points = np.asarray(points, dtype=float)
    u = flamant.displacement(points[..., 0], -points[..., 1], young, poisson, reference_depth)
    flip = np.array([1.0, -1.0])  # y = -z, for the component and for the force axis
    return u * flip[:, None] * flip[None, :]


def far_field_values(mesh: BoundaryMesh, young: float, poisson: float, reference_depth: float) -> np.ndarray:
    """Prescribed boundary values per unit resultant force, (2N, 2) [length / (force/length)].

    Row 2i + k: the half-space displacement component k at node i when i is on
    the truncation boundary (``mesh.far``), zero elsewhere; column l: a unit
    force on the body along axis l (x, y). Multiplied by the resultant and
    added to the prescribed values of a load case.
    """
    values = np.zeros((mesh.size, 2, 2))
    values[mesh.far] = half_space_displacement(mesh.nodes[mesh.far], young, poisson, reference_depth)
    return values.reshape(2 * mesh.size, 2)
