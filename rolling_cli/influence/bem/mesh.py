"""Immutable boundary meshes and the rectangular body generator.

A body near its contact is a rectangle [-W, W] x [-D, 0] whose top face y = 0
holds the potential contact zone [-c, c]: the truncated half-space of a
cylinder (D and W large against the contact) or the layer of a tyred cylinder
(D = b). Its top face is traction-free outside the contact. A layer's bottom
is fixed (u = 0, bonded to the rigid core) and its ends are traction-free. A
half-space's sides and bottom are its truncation boundary (``far``): their
displacement is prescribed from the far field of the half-space (see
:mod:`.farfield`). The contact zone is meshed with the contact grid's
(uniform or graded) discontinuous elements; the rest of the top face with continuous
elements graded away from it; the sides and the bottom with continuous
elements, partially discontinuous at the corners and where a continuous
element meets a discontinuous one, so that every collocation point lies on a
smooth part of the boundary.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .elements import functional_nodes


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.setflags(write=False)
    return array


@dataclass(frozen=True)
class BoundaryMesh:
    """A closed boundary of quadratic elements, traversed with the domain on the left.

    ``geometry`` (E, 3, 2) element geometric nodes [length]; ``local`` (E, 3)
    local coordinates of each element's functional nodes; ``connectivity``
    (E, 3) their global node numbers; ``nodes`` (N, 2) node positions;
    ``fixed`` (N,) True where the displacement is prescribed, else the
    traction; ``far`` (N,) True on the truncation boundary of a half-space,
    where the prescribed displacement is the far field (elsewhere a prescribed
    displacement is zero and a prescribed traction is zero off the contact);
    ``contact`` the contact node numbers in increasing x. All arrays are
    read-only.
    """

    geometry: np.ndarray
    local: np.ndarray
    connectivity: np.ndarray
    nodes: np.ndarray
    fixed: np.ndarray
    far: np.ndarray
    contact: np.ndarray

    @property
    def elements(self) -> int:
        return self.geometry.shape[0]

    @property
    def size(self) -> int:
        """Number of functional nodes N (2N degrees of freedom)."""
        return self.nodes.shape[0]

    @property
    def lengths(self) -> np.ndarray:
        """Element chord lengths [length]."""
        return np.linalg.norm(self.geometry[:, 2] - self.geometry[:, 0], axis=1)


def graded_edges(start: float, end: float, first: float, growth: float, largest: float) -> np.ndarray:
    """Edges from ``start`` to ``end`` with sizes first, first*growth, ... capped at ``largest``.

    The sizes are scaled uniformly so that the last edge lands on ``end``.
    """
    length = abs(end - start)
    sizes = []
    total = 0.0
    size = min(first, largest)
    while total < length * (1 - 1e-9):
        sizes.append(size)
        total += size
        size = min(size * growth, largest)
    if len(sizes) > 1 and total - length > 0.5 * sizes[-1]:
        total -= sizes.pop()
    scaled = np.array(sizes) * (length / total)
    direction = np.sign(end - start)
    return start + direction * np.concatenate([[0.0], np.cumsum(scaled)])


@dataclass
class _Builder:
    geometry: list
    local: list
    connectivity: list
    nodes: list
    fixed: list

    def segment(self, points: np.ndarray, fixed: bool, discontinuous: bool = False) -> list[int]:
        """Add the elements between consecutive ``points`` (K + 1, 2) along a straight side.

        End elements are discontinuous at the segment ends (corners and changes
        of element kind); inner ends are shared continuous nodes unless the
        whole segment is ``discontinuous``. Returns the new node numbers.
        """
        new_nodes = []
        count = len(points) - 1
        shared = None
        for k in range(count):
            p0, p2 = points[k], points[k + 1]
            start_disc = discontinuous or k == 0
            end_disc = discontinuous or k == count - 1
            local = functional_nodes(start_disc, end_disc)
            ids = []
            for a, xi in enumerate(local):
                if a == 0 and not start_disc and shared is not None:
                    ids.append(shared)
                    continue
                self.nodes.append(p0 + 0.5 * (xi + 1.0) * (p2 - p0))
                self.fixed.append(fixed)
                ids.append(len(self.nodes) - 1)
                new_nodes.append(ids[-1])
            shared = ids[2] if not end_disc else None
            self.geometry.append(np.array([p0, 0.5 * (p0 + p2), p2]))
            self.local.append(local)
            self.connectivity.append(ids)
        return new_nodes

    def mesh(self, far: np.ndarray, contact: np.ndarray) -> BoundaryMesh:
        """The finished, read-only mesh; ``far`` (N,) the truncation nodes, ``contact`` the contact nodes."""
        nodes = np.array(self.nodes)
        contact = np.asarray(contact)
        return BoundaryMesh(
            geometry=_frozen(np.array(self.geometry)),
            local=_frozen(np.array(self.local)),
            connectivity=_frozen(np.array(self.connectivity, dtype=np.int64)),
            nodes=_frozen(nodes),
            fixed=_frozen(np.array(self.fixed, dtype=bool)),
            far=_frozen(far),
            contact=_frozen(contact[np.argsort(nodes[contact, 0])]),
        )


def rectangle(
    half_width: float,
    depth: float,
    zone_edges: np.ndarray,
    growth: float = 1.4,
    largest: float | None = None,
    kind: str = "mixed",
    far_field: bool = False,
    graded: bool = False,
) -> BoundaryMesh:
    """The rectangular body [-W, W] x [-D, 0] with contact elements ``zone_edges`` on top.

    ``zone_edges`` are the contact grid's element edges (increasing x, inside
    (-W, W)): equal ones, or with ``graded`` any increasing ones (each contact
    element keeps its nodes at -2/3, 0, 2/3 of its own half-length, so the
    contact nodes are the graded grid's). Away from the zone, elements grow by
    ``growth`` per element from the adjacent contact element's length (the
    first element's when not ``graded``; under the zone the bottom starts from
    the longest) up to ``largest`` (default: min(D, W) / 4).
    ``kind``: "mixed" (discontinuous contact elements, continuous elsewhere),
    "discontinuous" or "continuous" (contact zone too) everywhere; the last two
    exist for patch tests of each element kind. ``far_field``: the sides and
    the bottom are a half-space's truncation boundary (displacement prescribed,
    ``far``); otherwise the bottom is fixed and the sides are traction-free.
    """
    if kind not in ("mixed", "discontinuous", "continuous"):
        raise ValueError(f"unknown element kind {kind!r}")
    all_disc = kind == "discontinuous"
    zone_edges = np.asarray(zone_edges, dtype=float)
    h = float(zone_edges[1] - zone_edges[0])
    h_lo, h_hi, h_big = h, h, h  # equal elements: the first one's length, bit for bit as ever
    if graded:  # the graded beyond the zone start from the end elements' lengths; the bottom from the longest
        h_hi = float(zone_edges[-1] - zone_edges[-2])
        h_big = float(np.diff(zone_edges).max())
    c_lo, c_hi = float(zone_edges[0]), float(zone_edges[-1])
    if not (-half_width < c_lo and c_hi < half_width):
        raise ValueError("the contact zone must lie inside the top face")
    big = largest if largest is not None else min(depth, half_width) / 4.0
    b = _Builder([], [], [], [], [])

    def line(xs, ys):
        return np.column_stack([xs, ys])

    # bottom, from (-W, -D) to (W, -D): fine under the zone, graded outwards
    right = graded_edges(0.0, half_width, min(big, max(h_big, depth / 8.0)), growth, big)
    bottom_x = np.concatenate([-right[::-1], right[1:]])
    b.segment(line(bottom_x, np.full(bottom_x.size, -depth)), fixed=True, discontinuous=all_disc)
    on_bottom = len(b.nodes)
    # right side, from (W, -D) up to (W, 0): fine at the top corner
    top_corner = graded_edges(c_hi, half_width, h_hi, growth, big)
    corner_size = float(top_corner[-1] - top_corner[-2])
    side = graded_edges(0.0, -depth, corner_size, growth, big)[::-1]
    right_side = b.segment(line(np.full(side.size, half_width), side), fixed=far_field, discontinuous=all_disc)
    # top face, from (W, 0) to (-W, 0): graded, contact zone, graded
    left = graded_edges(c_lo, -half_width, h_lo, growth, big)
    if kind == "continuous":  # one continuous segment across the whole top face
        top = np.concatenate([top_corner[::-1], zone_edges[::-1][1:-1], left])
        new = b.segment(line(top, np.zeros(top.size)), fixed=False)
        xs = np.array(b.nodes)[new, 0]
        contact = np.array(new)[(xs > c_lo - 1e-12 * h) & (xs < c_hi + 1e-12 * h)]
    else:
        b.segment(line(top_corner[::-1], np.zeros(top_corner.size)), fixed=False, discontinuous=all_disc)
        first_contact = len(b.nodes)
        b.segment(line(zone_edges[::-1], np.zeros(zone_edges.size)), fixed=False, discontinuous=True)
        contact = np.arange(first_contact, len(b.nodes))
        b.segment(line(left, np.zeros(left.size)), fixed=False, discontinuous=all_disc)
    # left side, from (-W, 0) down to (-W, -D)
    side = graded_edges(0.0, -depth, float(left[-2] - left[-1]), growth, big)
    left_side = b.segment(line(np.full(side.size, -half_width), side), fixed=far_field, discontinuous=all_disc)

    far = np.zeros(len(b.nodes), dtype=bool)
    if far_field:
        far[:on_bottom] = True
        far[right_side] = True
        far[left_side] = True
    return b.mesh(far, contact)
