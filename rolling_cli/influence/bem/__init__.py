"""Boundary element influence of one body, condensed onto the contact nodes.

Pipeline: :mod:`.mesh` (immutable boundary mesh of the rectangular body) ->
:mod:`.assembly` (H and G from Kelvin's solution, :mod:`.kelvin`, with
quadratic elements, :mod:`.elements`) -> :mod:`.condense` (one LU, 2 n_c
right-hand sides) -> :class:`~rolling_cli.influence.Compliance` in the body's
own frame, the same interface as the closed-form half-plane.

In the block's frame the body lies below y = 0, so the displacement into the
body is w = -u_y, the normal traction is p_n = t_y and the tangential one
p_t = t_x.
"""

from __future__ import annotations

import numpy as np

from ...grid import ContactGrid
from .. import Compliance
from .assembly import assemble
from .condense import contact_compliance
from .mesh import BoundaryMesh, rectangle


def body_mesh(grid: ContactGrid, half_width: float, depth: float, largest: float | None = None) -> BoundaryMesh:
    """The rectangular body [-W, W] x [-D, 0] around the contact grid [length]."""
    if grid.order != 2:
        raise ValueError("the BEM model uses the quadratic contact elements")
    return rectangle(half_width, depth, grid.edges, largest=largest)


def condensed(mesh: BoundaryMesh, grid: ContactGrid, young: float, poisson: float) -> Compliance:
    """Condensed compliance of a BEM body on the contact grid [length/stress]."""
    shear = young / (2.0 * (1.0 + poisson))
    H, G = assemble(mesh, shear, poisson)
    flex = contact_compliance(mesh, H, G)
    nc = grid.size
    if mesh.contact.size != nc or not np.allclose(mesh.nodes[mesh.contact, 0], grid.x, atol=1e-9 * grid.half_width):
        raise ValueError("the BEM contact nodes do not match the contact grid")
    c4 = flex.reshape(nc, 2, nc, 2)  # (node i, u_x/u_y, node j, t_x/t_y)
    return Compliance(
        x=grid.x,
        weights=grid.weights,
        S_nn=-c4[:, 1, :, 1].copy(),
        S_nt=-c4[:, 1, :, 0].copy(),
        S_tn=c4[:, 0, :, 1].copy(),
        S_tt=c4[:, 0, :, 0].copy(),
        definite_normal=True,
    )
