"""BEM model of a finite cylinder: the annulus r_i < r < R bonded to a rigid shaft at r = r_i.

Frame (the block frame of :mod:`.mesh`): the cylinder's centre at (0, -R), the
contact at the top, around (0, 0); x along the surface, y up, the body below.
A contact grid coordinate s [length] is the arc length along the outer circle
from the top towards +x, at the angle theta = s / R (clockwise from +y).

Mesh (:func:`annulus_mesh`): curved quadratic (isoparametric) elements whose
three geometric nodes lie on the circles. The outer circle carries the contact
grid's discontinuous elements (edges at the grid's angles; the contact nodes
lie on the quadratic arcs through points of the circle) and continuous traction-free elements graded
away from the zone by arc length, up to ``largest``; the bore's elements have
their displacement prescribed (zero: bonded to the shaft, which is the
reference of the body's motion) and are graded from the top, starting at the
size of the contact zone's longest element or a quarter of the section's
thickness, whichever is larger. Away from the zone each element is
``GROWTH`` times its neighbour (so about 0.8 times its distance from the
zone) up to ``ARC_FRACTION`` of the circumference: against a four times
finer far mesh (growth 1.2, 1/128 of the circle, an eighth of the thickness
under the zone), creepage moves by at most 6e-5 and peak pressure and approach
by 5e-6 over a covered, a thin-covered, a hollow roller and the half-space
limit (mesh rules 5, growth 1.4 and 1/64: 5e-6; 200 contact elements give
2e-4 against 100), for 16 % fewer boundary nodes at a/R = 0.2. The mesh is its own mirror image in x = 0, so
the boundary system splits into two halves (:mod:`.symmetry`).

Condensation (:func:`condensed`): the contact displacements per unit nodal
traction, first in the frame's x and y components (:func:`.condense.contact_blocks`,
no far field), then rotated into each contact node's own directions on the
arc: the tangent tau = (cos theta, -sin theta) (along increasing s) and the
outward normal nu = (sin theta, cos theta). Per the
:class:`~rolling_cli.influence.Compliance` convention p_n = t . nu
(negative in compression), p_t = t . tau, w = -u . nu (into the body),
u_t = u . tau, theta the node's polar angle. The elements are curved
(isoparametric arcs), so the node's polar frame is the boundary's own: on
straight elements (chords) a traction in the polar frame has a tangential
component +-p h/(3R) relative to each chord, which left a saw-tooth in
du_t/ds at the element junctions of 9 % of the strain at a/R = 0.3 and 100
elements (the slip rows see it). The bore being fixed, the normal displacement is definite: the approach of
the contact surface towards the shaft.
"""

from __future__ import annotations

import numpy as np

from ...model.grid import ContactGrid
from .. import Compliance
from . import ring as rings
from .condense import contact_blocks, solve_all
from .elements import GEOMETRY_COEFFICIENTS, evaluate, functional_nodes
from .mesh import BoundaryMesh, _Builder, graded_edges
from .symmetry import reductions
from .system import mixed_systems

__all__ = ["annulus_mesh", "annulus_size", "contact_angles", "condensed", "xy_compliance", "rotate"]

#: Version of the meshing rules below, part of the cache key of a finite body (bump it when they change).
MESH_RULES = 6

#: Default largest element, as a fraction of the circumference (32 elements round a circle at least).
ARC_FRACTION = 1.0 / 32.0
#: Size ratio of neighbouring elements away from the contact zone (module docstring).
GROWTH = 1.8
#: The bore's elements under the zone: at least this fraction of the section's thickness.
BORE_FRACTION = 0.25


def _arc_segment(
    b: _Builder, radius: float, centre_y: float, theta: np.ndarray, fixed: bool, discontinuous: bool = False
):
    """Add curved quadratic elements between consecutive angles ``theta`` along a circle: geometric
    nodes at the ends and the middle angle, on the circle; functional nodes where the isoparametric
    map puts their local coordinates (within (h/R)^4 R of the circle). Continuity as
    :meth:`.mesh._Builder.segment`: discontinuous at the segment's ends (or everywhere)."""
    count = theta.size - 1
    starts = np.full(count, discontinuous)
    ends = np.full(count, discontinuous)
    starts[0] = ends[-1] = True
    local = np.where(
        np.stack([starts, np.zeros(count, bool), ends], axis=1),
        functional_nodes(True, True)[None, :],
        functional_nodes(False, False)[None, :],
    )  # (count, 3) as functional_nodes(start, end) per element
    middle = 0.5 * (theta[:-1] + theta[1:])
    geometry = _circle(radius, centre_y, np.stack([theta[:-1], middle, theta[1:]], axis=1).ravel()).reshape(count, 3, 2)
    positions = np.matmul(evaluate(GEOMETRY_COEFFICIENTS, local), geometry)  # (count, 3 nodes, 2)
    positions[np.abs(positions[..., 0]) < 1e-14 * radius, 0] = 0.0
    shared = None
    for k in range(count):
        ids = []
        for a in range(3):
            if a == 0 and not starts[k] and shared is not None:
                ids.append(shared)
                continue
            b.nodes.append(positions[k, a])
            b.fixed.append(fixed)
            ids.append(len(b.nodes) - 1)
        shared = ids[2] if not ends[k] else None
        b.geometry.append(geometry[k])
        b.local.append(local[k])
        b.connectivity.append(ids)


def _circle(radius: float, centre_y: float, theta: np.ndarray) -> np.ndarray:
    """Points at angles ``theta`` (clockwise from +y) on the circle of ``radius`` centred at (0, centre_y)."""
    x = radius * np.sin(theta)
    x[np.abs(x) < 1e-14 * radius] = 0.0  # the top and bottom points exactly on the mirror axis
    return np.column_stack([x, centre_y + radius * np.cos(theta)])


def annulus_mesh(
    grid: ContactGrid, radius: float, inner_radius: float, growth: float = GROWTH, largest: float | None = None
) -> BoundaryMesh:
    """The annulus ``inner_radius`` < r < ``radius`` [length] with the contact grid on its outer circle.

    The grid (quadratic elements, centred on s = 0) is in arc length along the
    outer circle and must span less than half of it. Elements away from the
    zone grow by ``growth`` per element from the adjacent contact element's
    length up to ``largest`` [length] (default: the smaller of the section's
    thickness and the outer circumference / 32; on the bore, at most its own
    circumference / 32).
    """
    if grid.order != 2:
        raise ValueError("the BEM model uses the quadratic contact elements")
    if not 0.0 < inner_radius < radius:
        raise ValueError("the annulus needs 0 < inner_radius < radius")
    edges = np.asarray(grid.edges, dtype=float)
    if abs(edges[0] + edges[-1]) > 1e-9 * (edges[-1] - edges[0]):
        raise ValueError("the contact grid must be centred on the top of the cylinder")
    c = float(edges[-1])
    if not c < 0.5 * np.pi * radius:
        raise ValueError("the contact zone must span less than half the circumference")
    thickness = radius - inner_radius
    lengths = np.diff(edges)
    half, big = _outer_edges(c, float(lengths[-1]), radius, thickness, growth, largest)
    centre_y = -radius
    b = _Builder([], [], [], [], [])
    # the contact zone, counter-clockwise (from +s to -s)
    first_contact = len(b.nodes)
    _arc_segment(b, radius, centre_y, edges[::-1] / radius, fixed=False, discontinuous=True)
    contact = np.arange(first_contact, len(b.nodes))
    # the free outer arc, counter-clockwise from s = -c round the bottom to s = +c; mirror-symmetric
    arc = np.concatenate([-half, half[::-1][1:] - 2.0 * np.pi * radius])
    _arc_segment(b, radius, centre_y, arc / radius, fixed=False)
    # the bore, clockwise (the domain on the left), from the bottom through -x, the top and +x back
    half = _bore_edges(float(lengths.max()), c / radius, inner_radius, thickness, growth, big)
    bore = np.concatenate([-half[::-1], half[1:]]) / inner_radius
    _arc_segment(b, inner_radius, centre_y, bore, fixed=True)
    return b.mesh(np.zeros(len(b.nodes), dtype=bool), contact)


def _outer_edges(c: float, h_end: float, radius: float, thickness: float, growth: float, largest: float | None):
    """The free outer arc's edges from the zone's end at s = c to the bottom, and the element cap."""
    big = largest if largest is not None else 2.0 * np.pi * radius * ARC_FRACTION
    return graded_edges(c, np.pi * radius, h_end, growth, big), big


def _bore_edges(
    h_max: float, zone_angle: float, inner_radius: float, thickness: float, growth: float, big: float
) -> np.ndarray:
    """The bore's edges in arc length from its top to its bottom: equal ones of the larger of the
    longest contact element and ``BORE_FRACTION`` of the thickness (at most the thickness, as a flat
    layer's bottom) under the zone (angles up to ``zone_angle``), then graded by distance."""
    inner_big = min(big, 2.0 * np.pi * inner_radius * ARC_FRACTION)
    first = min(inner_big, thickness, max(h_max, BORE_FRACTION * thickness))
    under = zone_angle * inner_radius
    count = max(1, int(np.ceil(under / first - 1e-9)))
    uniform = np.linspace(0.0, under, count + 1)
    graded = graded_edges(under, np.pi * inner_radius, float(uniform[1] - uniform[0]), growth, inner_big)
    return np.concatenate([uniform, graded[1:]])


def annulus_size(
    zone_half_width: float, elements: int, radius: float, inner_radius: float, growth: float = GROWTH
) -> tuple[int, int]:
    """Boundary nodes N and elements E of :func:`annulus_mesh` for a uniform contact grid, without building it.

    Contact: 3 nodes per element; the free arc and the bore are one segment each of k elements
    with 2 k + 1 nodes (continuous inside, partially discontinuous at the segment's two ends).
    """
    h = 2.0 * zone_half_width / elements
    thickness = radius - inner_radius
    outer, big = _outer_edges(zone_half_width, h, radius, thickness, growth, None)
    k_outer = 2 * (outer.size - 1)
    k_bore = 2 * (_bore_edges(h, zone_half_width / radius, inner_radius, thickness, growth, big).size - 1)
    return 3 * elements + 2 * k_outer + 1 + 2 * k_bore + 1, elements + k_outer + k_bore


def contact_angles(mesh: BoundaryMesh, radius: float) -> np.ndarray:
    """The polar angle theta (clockwise from +y, about the centre (0, -R)) of each contact node (n_c,)."""
    nodes = mesh.nodes[mesh.contact]
    return np.arctan2(nodes[:, 0], nodes[:, 1] + radius)


def xy_compliance(
    mesh: BoundaryMesh,
    grid: ContactGrid,
    young: float,
    poisson: float,
    mirror: bool = True,
    radius: float | None = None,
) -> np.ndarray:
    """C (n_c, 2, n_c, 2) [length/stress]: C[i, k, j, l] = du_k(i) / dt_l(j), the x and y components of
    the contact displacement at node i per unit nodal traction at node j, for the bonded bore.
    With the outer ``radius`` [length] (of :func:`annulus_mesh`'s circle centred at (0, -R)), a
    uniform contact grid's elements are one ring (:mod:`.ring`): their mutual integrals by rotation."""
    blocks = _frame_blocks(mesh, grid, young, poisson, mirror, radius)
    nc = grid.size
    out = np.empty((nc, 2, nc, 2))
    out[:, 0, :, 0] = blocks["S_tt"]
    out[:, 0, :, 1] = blocks["S_tn"]
    out[:, 1, :, 0] = -blocks["S_nt"]
    out[:, 1, :, 1] = -blocks["S_nn"]
    return out


def _frame_blocks(
    mesh: BoundaryMesh, grid: ContactGrid, young: float, poisson: float, mirror: bool, radius: float | None
) -> dict[str, np.ndarray]:
    """The blocks of :func:`.condense.contact_blocks` (n_c, n_c) [length/stress] in the mesh frame's
    x (t) and y (n) components: S_tt = du_x/dt_x, S_tn = du_x/dt_y, S_nt = -du_y/dt_x,
    S_nn = -du_y/dt_y (arguments as :func:`xy_compliance`)."""
    if mesh.contact.size != grid.size:
        raise ValueError("the BEM contact nodes do not match the contact grid")
    far = np.zeros((2 * mesh.size, 2))  # no far field: the shaft is the reference
    shear = young / (2.0 * (1.0 + poisson))
    parts = reductions(mesh, far, grid.weights, mirror)
    ring = None if radius is None else rings.find(mesh, np.arange(grid.elements), np.array([0.0, -radius]))
    solutions = solve_all(mixed_systems(mesh, shear, poisson, far, parts, ring))
    return contact_blocks(solutions, parts, mesh, grid.weights)


def _frames(angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The outward normals nu and the tangents tau (n, 2) at the polar ``angles`` (module docstring)."""
    return np.column_stack([np.sin(angles), np.cos(angles)]), np.column_stack([np.cos(angles), -np.sin(angles)])


def _arc_blocks(
    xy: list[list[np.ndarray]], signs: tuple[float, float], theta: np.ndarray, theta_loads: np.ndarray | None
) -> dict[str, np.ndarray]:
    """The arc-frame blocks S_nn, S_nt, S_tn, S_tt (n_c, n_c) of the xy compliance whose component
    (k, l) is ``signs[k] * xy[k][l]`` (n_c, n_c) (du_k/dt_l) [length/stress], as :func:`rotate`:
    sum_kl left[i, k] C_kl[i, j] right[j, l] for the directions ``left`` at ``theta`` and
    ``right`` at ``theta_loads``, by whole-array products (the signs ride on the direction
    vectors: exact)."""
    nu, tau = _frames(theta)
    nu_load, tau_load = (nu, tau) if theta_loads is None else _frames(theta_loads)

    def along(right: np.ndarray) -> list[np.ndarray]:  # sum_l C_kl[i, j] right[j, l], per k (up to its sign)
        out = []
        for k in range(2):
            term = xy[k][0] * right[None, :, 0]
            term += xy[k][1] * right[None, :, 1]
            out.append(term)
        return out

    loads = {"t": along(tau_load), "n": along(nu_load)}
    result = {}
    for name, left, sign in (("S_tt", tau, 1.0), ("S_tn", tau, 1.0), ("S_nt", nu, -1.0), ("S_nn", nu, -1.0)):
        inner = loads[name[-1]]
        factor = sign * left * np.asarray(signs)[None, :]  # (n_c, 2)
        block = inner[0] * factor[:, 0, None]
        block += inner[1] * factor[:, 1, None]
        result[name] = block
    return result


def rotate(xy: np.ndarray, theta: np.ndarray, theta_loads: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The arc-frame blocks S_nn, S_nt, S_tn, S_tt (n_c, n_c) [length/stress] of an xy compliance
    (n_c, 2, n_c, 2): displacements in the directions at the angles ``theta`` (module docstring),
    tractions in those at ``theta_loads`` (default the same)."""
    components = [[xy[:, k, :, l] for l in range(2)] for k in range(2)]
    return _arc_blocks(components, (1.0, 1.0), theta, theta_loads)


def condensed(
    grid: ContactGrid,
    radius: float,
    inner_radius: float,
    young: float,
    poisson: float,
    largest: float | None = None,
    mirror: bool = True,
) -> Compliance:
    """Condensed compliance of the bonded annulus on the contact grid, in the arc's directions
    [length/stress] (module docstring); lengths [length], ``young`` E [stress]."""
    mesh = annulus_mesh(grid, radius, inner_radius, largest=largest)
    frame = _frame_blocks(mesh, grid, young, poisson, mirror, radius)
    xy = [[frame["S_tt"], frame["S_tn"]], [frame["S_nt"], frame["S_nn"]]]  # du_y/dt_l = -S_n., by the sign below
    blocks = _arc_blocks(xy, (1.0, -1.0), contact_angles(mesh, radius), None)
    return Compliance(x=grid.x, weights=grid.weights, definite_normal=True, **blocks)
