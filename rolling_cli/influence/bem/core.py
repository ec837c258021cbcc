"""A cover bonded to an elastic core: the finite roller with two bonded regions (issue 21).

The cover is the annulus r_c < r < R of :func:`.cylinder.annulus_mesh` (its
"bore" at r = r_c is now the interface); the core is the annulus r_i < r < r_c,
its bore bonded to the rigid shaft (u = 0), the body's reference. Both are
plane-strain BEM regions of their own moduli, bonded at r = r_c.

The core enters the cover's system as a stiffness on the interface, its
Dirichlet-to-Neumann map K (:func:`interface_stiffness`): the core's own BEM
(:func:`core_mesh`, every displacement prescribed: the outer circle's nodes are
the cover's interface nodes, the same elements traversed the other way; the
bore's elements uniform) gives its nodal tractions on r = r_c per unit nodal
interface displacement, t_core = K u_I (frame components, the core's outward
normal +e_r). The cover's outward normal there is -e_r, so the bond's balance
of the stress vector is t_cover = -K u_I, and in the cover's H u = G t the
interface columns become H_I + G_I K with u_I unknown (a Robin condition in
place of "u = 0"). The contact compliance then follows by one solve with the
contact dofs' G columns as right-hand sides, the unit nodal contact tractions
(:func:`xy_compliance`), and is rotated into the arc's directions as
:func:`.cylinder.condensed`.

The two systems are dense and whole (no mirror halves, no ring of rotated
copies: the rigid core's fast path stays untouched); a rigid core (K -> inf)
is the limit u_I = 0, the columns -G_I with t_I unknown, which
:func:`xy_compliance` builds with ``stiffness=None`` (a check on the path
against :func:`.cylinder.xy_compliance`).
"""

from __future__ import annotations

import numpy as np

from ...model.grid import ContactGrid
from .. import Compliance
from .assembly import assemble
from .cylinder import _arc_segment, annulus_mesh, contact_angles, rotate
from .mesh import BoundaryMesh, _Builder

__all__ = ["core_mesh", "interface_stiffness", "xy_compliance", "condensed", "boundary_solution", "BORE_ELEMENTS"]

#: Elements round the core's bore at least (more if the core is thinner than an element).
BORE_ELEMENTS = 32


def _interface_angles(cover: BoundaryMesh, radius: float) -> np.ndarray:
    """The polar angles (clockwise from +y about (0, -R)) of the cover's interface element edges,
    increasing from -pi to pi (the order :func:`.cylinder.annulus_mesh` meshes its bore in)."""
    on_bore = cover.fixed[cover.connectivity].all(axis=1)
    ends = cover.geometry[on_bore][:, [0, 2]]  # (e, 2 ends, 2)
    angles = np.arctan2(ends[..., 0], ends[..., 1] + radius)
    first = angles[:, 0]
    first = np.where(first > np.pi - 1e-12, -np.pi, first)  # the bottom point starts the sweep
    return np.concatenate([np.sort(first), [np.pi]])


def core_mesh(cover: BoundaryMesh, radius: float, core_radius: float, inner_radius: float) -> BoundaryMesh:
    """The core r_i < r < r_c [length] (centre (0, -R)): its outer circle the cover's interface
    elements, counter-clockwise (domain on the left); its bore, clockwise, in uniform elements
    (``BORE_ELEMENTS``, or as many as make them no longer than the core's thickness). Every
    node's displacement is prescribed (``fixed``); ``contact`` is empty."""
    if not 0.0 < inner_radius < core_radius < radius:
        raise ValueError("the core needs 0 < inner_radius < core_radius < radius")
    theta = _interface_angles(cover, radius)
    b = _Builder([], [], [], [], [])
    _arc_segment(b, core_radius, -radius, theta[::-1], fixed=True)
    count = max(BORE_ELEMENTS, int(np.ceil(2.0 * np.pi * inner_radius / (core_radius - inner_radius))))
    _arc_segment(b, inner_radius, -radius, np.linspace(-np.pi, np.pi, count + 1), fixed=True)
    return b.mesh(np.zeros(len(b.nodes), dtype=bool), np.zeros(0, dtype=np.int64))


def _match(points: np.ndarray, targets: np.ndarray, scale: float) -> np.ndarray:
    """For each of ``points`` (n, 2) the index of the coinciding row of ``targets`` (m, 2) (within
    1e-9 ``scale``), or ValueError."""
    dist = np.linalg.norm(points[:, None, :] - targets[None, :, :], axis=2)
    index = dist.argmin(axis=1)
    if not np.all(dist[np.arange(points.shape[0]), index] <= 1e-9 * scale):
        raise ValueError("the core's outer nodes do not coincide with the cover's interface nodes")
    return index


def interface_stiffness(
    cover: BoundaryMesh, radius: float, core_radius: float, inner_radius: float, young: float, poisson: float
) -> np.ndarray:
    """K (2 n_I, 2 n_I) [stress/length]: the core's nodal tractions (frame x, y; outward normal
    +e_r) per unit nodal displacement of the cover's interface nodes, in the cover's order of
    ``np.flatnonzero(cover.fixed)`` (row/column 2 q + l: node q's component l); the core's bore
    fixed. ``young`` E [stress] and ``poisson`` of the core."""
    mesh = core_mesh(cover, radius, core_radius, inner_radius)
    H, G = assemble(mesh, young / (2.0 * (1.0 + poisson)), poisson)
    interface = np.flatnonzero(cover.fixed)
    outer = np.flatnonzero(np.linalg.norm(mesh.nodes - [0.0, -radius], axis=1) > 0.5 * (inner_radius + core_radius))
    order = _match(cover.nodes[interface], mesh.nodes[outer], radius)
    dofs = (2 * outer[order][:, None] + np.arange(2)).ravel()  # the core's dofs in the cover's order
    return np.linalg.solve(G, H[:, dofs])[dofs]


def _system(cover: BoundaryMesh, young: float, poisson: float, stiffness: np.ndarray | None):
    """(A, G's contact columns, the interface dofs): the cover's system A X = G_c t_c, X every
    node's displacement (the interface's too) for the ``stiffness`` K, or X the displacements and
    the interface tractions for a rigid core (None)."""
    H, G = assemble(cover, young / (2.0 * (1.0 + poisson)), poisson)
    dofs = (2 * np.flatnonzero(cover.fixed)[:, None] + np.arange(2)).ravel()
    A = H
    A[:, dofs] = -G[:, dofs] if stiffness is None else H[:, dofs] + G[:, dofs] @ stiffness
    contact = (2 * cover.contact[:, None] + np.arange(2)).ravel()
    return A, G[:, contact], dofs


def xy_compliance(cover: BoundaryMesh, young: float, poisson: float, stiffness: np.ndarray | None) -> np.ndarray:
    """C (n_c, 2, n_c, 2) [length/stress]: du_k(i)/dt_l(j) of the cover's contact nodes per unit
    nodal contact traction (frame components), its interface held by the ``stiffness`` K of
    :func:`interface_stiffness` (t_I = -K u_I), or bonded to a rigid core for None (u_I = 0).
    ``young`` E [stress] and ``poisson`` of the cover."""
    A, rhs, _ = _system(cover, young, poisson, stiffness)
    solution = np.linalg.solve(A, rhs)  # columns: unit nodal tractions at the contact dofs
    contact = (2 * cover.contact[:, None] + np.arange(2)).ravel()
    nc = cover.contact.size
    return solution[contact].reshape(nc, 2, nc, 2)


def boundary_solution(
    grid: ContactGrid,
    radius: float,
    core_radius: float,
    inner_radius: float,
    moduli: tuple[float, float, float, float],
    p_n: np.ndarray,
    p_t: np.ndarray,
) -> tuple[BoundaryMesh, np.ndarray, np.ndarray]:
    """``(mesh, u, t)`` of the cover on its elastic core for the contact tractions ``p_n``, ``p_t``
    (n_c,) [stress] along the arc's directions, as :func:`.annulus_solution.annulus_solution`: the
    cover's mesh, every node's displacement u (N, 2) [length] and traction t (N, 2) [stress] in the
    frame's components, the interface's (``mesh.fixed``) t = -K u (the core's push on the cover).
    ``moduli`` = (E, nu) of the cover, then (E_c, nu_c) of the core [stress]."""
    young, poisson, core_young, core_poisson = moduli
    cover = annulus_mesh(grid, radius, core_radius)
    stiffness = interface_stiffness(cover, radius, core_radius, inner_radius, core_young, core_poisson)
    theta = contact_angles(cover, radius)
    normal = np.column_stack([np.sin(theta), np.cos(theta)])
    tangent = np.column_stack([np.cos(theta), -np.sin(theta)])
    t_c = np.asarray(p_n, dtype=float)[:, None] * normal + np.asarray(p_t, dtype=float)[:, None] * tangent
    A, rhs, dofs = _system(cover, young, poisson, stiffness)
    u = np.linalg.solve(A, rhs @ t_c.ravel())
    t = np.zeros(2 * cover.size)
    t[(2 * cover.contact[:, None] + np.arange(2)).ravel()] = t_c.ravel()
    t[dofs] = -stiffness @ u[dofs]
    return cover, u.reshape(cover.size, 2), t.reshape(cover.size, 2)


def condensed(
    grid: ContactGrid,
    radius: float,
    core_radius: float,
    inner_radius: float,
    young: float,
    poisson: float,
    core_young: float,
    core_poisson: float,
) -> Compliance:
    """Condensed compliance of the cover r_c < r < R on the elastic core r_i < r < r_c (bore fixed)
    on the contact grid, in the arc's directions [length/stress] as :func:`.cylinder.condensed`;
    lengths [length], moduli E [stress] of the cover (``young``) and the core (``core_young``)."""
    cover = annulus_mesh(grid, radius, core_radius)
    if cover.contact.size != grid.size:
        raise ValueError("the BEM contact nodes do not match the contact grid")
    stiffness = interface_stiffness(cover, radius, core_radius, inner_radius, core_young, core_poisson)
    xy = xy_compliance(cover, young, poisson, stiffness)
    blocks = rotate(xy, contact_angles(cover, radius))
    return Compliance(x=grid.x, weights=grid.weights, definite_normal=True, **blocks)
