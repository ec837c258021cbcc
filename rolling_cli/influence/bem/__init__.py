"""Boundary element influence of one body, condensed onto the contact nodes.

Pipeline: :mod:`.mesh` (immutable boundary mesh of the rectangular body) ->
:mod:`.assembly` (H and G from Kelvin's solution, :mod:`.kelvin`, with
quadratic elements, :mod:`.elements`) -> :mod:`.condense` (one LU, 2 n_c + 2
right-hand sides, the last two the half-space far field of :mod:`.farfield`)
-> :class:`~rolling_cli.influence.Compliance` in the body's own frame, the
same interface as the closed-form half-plane.

Two bodies are modelled: a **half-space** (an elastic cylinder near its
contact), truncated to [-W, W] x [-D, 0] with the half-space's far-field
displacement of the contact resultant on the sides and bottom; and a
**layer** of thickness D = b bonded to a rigid core (fixed bottom) whose ends,
at +-W, are traction-free.

In the block's frame the body lies below y = 0, so the displacement into the
body is w = -u_y, the normal traction is p_n = t_y and the tangential one
p_t = t_x.
"""

from __future__ import annotations

import numpy as np

from ...grid import ContactGrid
from .. import Compliance
from .assembly import assemble
from .condense import Condensed, boundary_values, contact_compliance, prepare
from .farfield import far_field_values
from .mesh import BoundaryMesh, rectangle

__all__ = ["BoundaryMesh", "Condensed", "body_mesh", "prepare_body", "condensed", "compliance", "boundary_solution"]


def body_mesh(
    grid: ContactGrid, half_width: float, depth: float, largest: float | None = None, far_field: bool = False
) -> BoundaryMesh:
    """The rectangular body [-W, W] x [-D, 0] around the contact grid [length].

    ``far_field=True``: a half-space truncated there (far-field displacement on
    the sides and the bottom); otherwise a layer (fixed bottom, free ends).
    """
    if grid.order != 2:
        raise ValueError("the BEM model uses the quadratic contact elements")
    return rectangle(half_width, depth, grid.edges, largest=largest, far_field=far_field)


def prepare_body(mesh: BoundaryMesh, grid: ContactGrid, young: float, poisson: float) -> Condensed:
    """Assemble and factorise a BEM body ([length], E [stress]); the far field's
    reference depth is the mesh's depth D (the approach is measured from (0, -D))."""
    nc = grid.size
    if mesh.contact.size != nc or not np.allclose(mesh.nodes[mesh.contact, 0], grid.x, atol=1e-9 * grid.half_width):
        raise ValueError("the BEM contact nodes do not match the contact grid")
    shear = young / (2.0 * (1.0 + poisson))
    H, G = assemble(mesh, shear, poisson)
    depth = -float(mesh.geometry[..., 1].min())
    far = far_field_values(mesh, young, poisson, depth)
    return prepare(mesh, H, G, grid.weights, far)


def compliance(body: Condensed, grid: ContactGrid, consume: bool = False) -> Compliance:
    """Condensed compliance of a prepared BEM body on the contact grid [length/stress].

    ``consume=True`` reuses the body's right-hand-side storage (the body
    cannot be used again): no copy of the (2N, 2 n_c) right-hand sides.
    """
    nc = grid.size
    c4 = contact_compliance(body, consume).reshape(nc, 2, nc, 2)  # (node i, u_x/u_y, node j, t_x/t_y)
    return Compliance(
        x=grid.x,
        weights=grid.weights,
        S_nn=-c4[:, 1, :, 1].copy(),
        S_nt=-c4[:, 1, :, 0].copy(),
        S_tn=c4[:, 0, :, 1].copy(),
        S_tt=c4[:, 0, :, 0].copy(),
        definite_normal=True,
    )


def condensed(mesh: BoundaryMesh, grid: ContactGrid, young: float, poisson: float) -> Compliance:
    """Condensed compliance of a BEM body on the contact grid [length/stress]."""
    return compliance(prepare_body(mesh, grid, young, poisson), grid, consume=True)


def boundary_solution(body: Condensed, p_n: np.ndarray, p_t: np.ndarray) -> tuple[BoundaryMesh, np.ndarray, np.ndarray]:
    """The full boundary solution of a BEM body for contact nodal tractions.

    ``p_n``, ``p_t`` (n_c,) [stress]: the normal (negative in compression) and
    tangential traction on this body at the contact nodes, in increasing x, in
    the body's own frame (for body B of a pair, whose frame is mirrored, the
    tangential traction on B is -p_t of the pair).

    Returns ``(mesh, u, t)``: the boundary mesh (block frame: x along the
    surface, y up, the body below y = 0; nodes ``mesh.nodes`` (N, 2)
    [length]), the displacement u (N, 2) [length] and the traction t (N, 2)
    [stress] (the traction vector on the boundary, outward normal) at every
    node: the contact tractions, zero traction on the free top face, and on a
    half-space's truncation boundary its far-field displacement and the
    solved traction. With Kelvin's kernels this is all Somigliana's identity
    needs for interior displacements and stresses.
    """
    tractions = np.column_stack([np.asarray(p_t, dtype=float), np.asarray(p_n, dtype=float)])
    u, t = boundary_values(body, tractions)
    return body.mesh, u, t
