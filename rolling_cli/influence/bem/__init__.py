"""Boundary element influence of one body, condensed onto the contact nodes.

Pipeline: :mod:`.mesh` (immutable boundary mesh of the rectangular body) ->
:mod:`.assembly` (element integrals of Kelvin's solution, :mod:`.kelvin`, with
quadratic elements, :mod:`.elements`; in closed form on the element's own
line, :mod:`.collinear`) -> :mod:`.system` (the mixed boundary system A and
its 2 n_c + 2 right-hand sides, the last two the half-space far field of
:mod:`.farfield`, assembled straight from the integrals; a body that is its
own mirror image, as every body meshed here is, as two systems of half the
size, :mod:`.symmetry`) -> :mod:`.condense` (one LU in place per system, the
solves in place) -> :class:`~rolling_cli.influence.Compliance` in the body's
own frame, the same interface as the closed-form half-plane.

Two bodies are modelled: a **half-space** (an elastic cylinder near its
contact), truncated to [-W, W] x [-D, 0] with the half-space's far-field
displacement of the contact resultant on the sides and bottom; and a
**layer** of thickness D = b bonded to a rigid core (fixed bottom) whose ends,
at +-W, are traction-free.

A third, the **finite cylinder** (an annulus on a rigid shaft or core, curved
elements on both circles), is :mod:`.cylinder`, condensed in its contact
arc's own directions; its uniform contact arc is a ring of rotated copies,
whose mutual integrals :mod:`.ring` rotates from two computed rows, and its
systems, small, are solved by numpy's LU (:func:`.condense.solve_small`).

In the block's frame the body lies below y = 0, so the displacement into the
body is w = -u_y, the normal traction is p_n = t_y and the tangential one
p_t = t_x.
"""

from __future__ import annotations

import numpy as np

from ...model.grid import ContactGrid
from .. import Compliance
from .condense import Condensed, boundary_values, contact_blocks, factorise, prepare, solve
from .farfield import far_field_values
from .mesh import BoundaryMesh, rectangle
from .symmetry import reductions
from .system import mixed_systems

__all__ = ["BoundaryMesh", "Condensed", "body_mesh", "prepare_body", "condensed", "boundary_solution"]


def body_mesh(
    grid: ContactGrid, half_width: float, depth: float, largest: float | None = None, far_field: bool = False
) -> BoundaryMesh:
    """The rectangular body [-W, W] x [-D, 0] around the contact grid [length].

    ``far_field=True``: a half-space truncated there (far-field displacement on
    the sides and the bottom); otherwise a layer (fixed bottom, free ends).
    A graded grid's contact elements keep its edges (:func:`.mesh.rectangle`).
    """
    if grid.order != 2:
        raise ValueError("the BEM model uses the quadratic contact elements")
    return rectangle(half_width, depth, grid.edges, largest=largest, far_field=far_field, graded=not grid.uniform)


def _systems(mesh: BoundaryMesh, grid: ContactGrid, young: float, poisson: float, far_values, mirror: bool):
    nc = grid.size
    if mesh.contact.size != nc or not np.allclose(mesh.nodes[mesh.contact, 0], grid.x, atol=1e-9 * grid.half_width):
        raise ValueError("the BEM contact nodes do not match the contact grid")
    if far_values is None:
        depth = -float(mesh.geometry[..., 1].min())
        far_values = far_field_values(mesh, young, poisson, depth)
    shear = young / (2.0 * (1.0 + poisson))
    parts = reductions(mesh, far_values, grid.weights, mirror)
    return parts, mixed_systems(mesh, shear, poisson, far_values, parts), far_values


def prepare_body(
    mesh: BoundaryMesh,
    grid: ContactGrid,
    young: float,
    poisson: float,
    far_values: np.ndarray | None = None,
    mirror: bool = True,
) -> Condensed:
    """Assemble and factorise a BEM body ([length], E [stress]) for boundary solutions.

    ``far_values`` (2N, 2) the prescribed values on ``mesh.far`` per unit
    resultant force; default the half-space's (:func:`.farfield.far_field_values`,
    approach measured from (0, -D), D the mesh's depth). ``mirror``: split a
    mirror-symmetric body into its two halves (:mod:`.symmetry`; the same
    answer to round-off, a quarter of the work).
    """
    parts, systems, far_values = _systems(mesh, grid, young, poisson, far_values, mirror)
    return prepare(mesh, parts, systems, grid.weights, far_values)


def condensed(
    mesh: BoundaryMesh,
    grid: ContactGrid,
    young: float,
    poisson: float,
    far_values: np.ndarray | None = None,
    mirror: bool = True,
) -> Compliance:
    """Condensed compliance of a BEM body on the contact grid [length/stress] (``far_values`` and
    ``mirror`` as :func:`prepare_body`). Each system is factorised and solved in place, and the
    LUs are released before the blocks are formed: the peak is the systems' A and R."""
    parts, systems, _ = _systems(mesh, grid, young, poisson, far_values, mirror)
    solutions = []
    while systems:
        system = systems.pop(0)
        solutions.append(solve(factorise(system.matrix), system.rhs, overwrite=True))
        del system  # its LU
    blocks = contact_blocks(solutions, parts, mesh, grid.weights)
    return Compliance(x=grid.x, weights=grid.weights, definite_normal=True, **blocks)


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
