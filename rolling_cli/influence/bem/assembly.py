"""Assembly of the BEM matrices H and G (collocation at the functional nodes).

For collocation node i and element e, the integrals of T_kl N_j and U_kl N_j
over e are computed in one of three ways, vectorised over all pairs of a kind:

* **collinear** (i lies on the straight line of e: its own element, and every
  element of the same side, so the whole top face for a top-face node; most
  pairs): in closed form (:mod:`.collinear`). The strongly singular own-node
  part of T and the free term are not computed: the diagonal 2x2 blocks of H
  come from the rigid-body condition (rows of H sum to zero for each
  direction).
* **nearly singular** (not collinear, distance from i to e below ``NEAR``
  element lengths: nodes near a corner, or across a thin layer): the element
  is cut into sub-intervals graded geometrically towards the point of e
  nearest to i, each no longer than its distance to i, with ``GAUSS_NEAR``
  Gauss points on each (error < 1e-13 for a pole at one sub-interval length).
* **regular**: Gauss points by distance (:func:`regular_orders`): ``GAUSS``
  up to 2 element lengths (error < 2e-11 at the ``NEAR`` threshold), fewer
  further away, down to 5 beyond 15 lengths (each band's error measured
  below 6e-13).
* **own node of a curved element** (an isoparametric arc, as a finite
  cylinder's): each side of the node by the substitution xi = c +- L u^3
  (:func:`own_integrals`; 6e-9 of the entries against a 31-level graded
  rule, 16 times cheaper); the own node's strongly singular H part is left to
  the rigid-body condition, as on straight elements.

The element geometry and the regular rule's points are computed once
(:class:`Geometry`). The integrals come a block of elements at a time
(:func:`element_blocks`; each block (e, 3, 2, P, 2) for H and for G, P
collocation nodes, at most :data:`BLOCK` doubles together, in two reused
buffers), and a consumer adds them into the columns it needs:
:func:`assemble` into the dense H and G, :func:`.system.mixed_systems`
straight into the boundary systems.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from . import collinear, kelvin
from .elements import evaluate, gauss, lagrange_coefficients, map_points
from .mesh import BoundaryMesh

NEAR = 1.0
GAUSS = 10
GAUSS_NEAR = 12
#: The regular rule's Gauss orders by distance: ``ORDERS[m]`` points from ``BREAKS[m - 1]`` element
#: lengths (``NEAR`` for m = 0) up to ``BREAKS[m]`` (:func:`regular_orders`).
ORDERS = (GAUSS, 9, 8, 7, 6, 5)
BREAKS = (2.0, 2.5, 4.0, 6.0, 15.0)
GRADING = 0.5
#: A node closer to an element's line than this fraction of the element's length lies on it.
ON_LINE = 1e-9
#: Quadrature points per vectorised chunk of the regular and nearly singular rules (bounds memory).
_CHUNK = 50_000
#: Doubles of one element block's H and G integrals together (bounds memory).
BLOCK = 1_000_000


@dataclass(frozen=True)
class Geometry:
    """Per-element data shared by every block: straight elements (E,) with start ``p0`` (E, 2),
    unit ``tangent`` (E, 2), ``half``-length J [length], shape-function ``coeff`` (E, 3, 3), the
    ``line`` (E,) each lies on (a number per straight line and direction); the regular rule's
    ``points`` and ``normals`` (E, GAUSS, 2) and weighted shapes ``weighted`` (E, GAUSS, 3) =
    w_g J N_j(xi_g) [length]; ``rules`` the same three for every order of :func:`regular_orders`."""

    p0: np.ndarray
    tangent: np.ndarray
    half: np.ndarray
    coeff: np.ndarray
    line: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    weighted: np.ndarray
    rules: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]


def geometry(mesh: BoundaryMesh) -> Geometry:
    """The shared element data of ``mesh``. Straight elements lie on lines (numbered); a curved
    one (its middle geometric node off its chord: an arc) is alone, line -1 - its number, and its
    ``p0``, ``tangent`` and ``half`` are its chord's."""
    p0, mid, p2 = mesh.geometry[:, 0], mesh.geometry[:, 1], mesh.geometry[:, 2]
    chord = p2 - p0
    length = np.linalg.norm(chord, axis=1)
    curved = np.linalg.norm(mid - 0.5 * (p0 + p2), axis=1) > 1e-12 * length.max()
    coeff = lagrange_coefficients(mesh.local)  # (E, 3, 3)
    rules = {}
    for order in ORDERS:  # odd orders have a point at xi = 0, but a regular pair's node lies off the element
        xg, wg = gauss(order)
        points, normals, jac = map_points(mesh.geometry, xg)
        weighted = (wg[None, :] * jac)[..., None] * evaluate(coeff, np.broadcast_to(xg, jac.shape))
        rules[order] = (points, normals, weighted)
    points, normals, weighted = rules[GAUSS]
    tangent = chord / length[:, None]
    size = float(np.abs(mesh.nodes).max())
    offset = (p0[:, 0] * tangent[:, 1] - p0[:, 1] * tangent[:, 0]) / size  # the line's signed distance from 0
    _, line = np.unique(np.round(np.column_stack([tangent, offset]), 9), axis=0, return_inverse=True)
    line = np.where(curved, -1 - np.arange(mesh.elements), line.ravel())
    return Geometry(p0, tangent, 0.5 * length, coeff, line, points, normals, weighted, rules)


def element_blocks(
    mesh: BoundaryMesh, shear: float, poisson: float, points: np.ndarray | None = None, ring=None
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Yield ``(elements, h, g)``: element numbers (e,) and their integrals, each (e, 3, 2, P, 2).

    h[q, j, l, p, k] = int T_kl N_j over element ``elements[q]`` for collocation
    node ``points[p]`` (default every node; zero for the own-node term),
    likewise g with U_kl [length/stress times length]: a node's column (j, l)
    of H is contiguous. ``shear`` G [stress], ``poisson`` nu. h and g are views
    of two buffers reused by the next block: use them before asking for it.
    ``ring`` (a :class:`.ring.Ring` of the mesh, or None): its nodes' integrals over its
    elements by rotation of two computed rows (:mod:`.ring`).
    """
    geo = geometry(mesh)
    points = np.arange(mesh.size) if points is None else np.asarray(points)
    template = None
    if ring is not None:  # the first and the last ring element against every ring node
        ring_points = ring.nodes.ravel()
        template = np.zeros((2, 2, 3, 2, ring_points.size, 2))
        _block(mesh, geo, ring_points, ring.elements[[0, -1]], shear, poisson, template[0], template[1])
    step = max(1, BLOCK // (24 * points.size))  # 12 doubles of H and 12 of G per node-element pair
    buffers = np.empty((2, min(step, mesh.elements), 3, 2, points.size, 2))
    for start in range(0, mesh.elements, step):
        elements = np.arange(start, min(mesh.elements, start + step))
        h, g = buffers[0, : elements.size], buffers[1, : elements.size]
        _block(mesh, geo, points, elements, shear, poisson, h, g, ring, template)
        yield elements, h, g


def assemble(mesh: BoundaryMesh, shear: float, poisson: float) -> tuple[np.ndarray, np.ndarray]:
    """H and G, each (2N, 2N): H u = G t for nodal displacements u and tractions t.

    ``shear`` G [stress], ``poisson`` nu. Rows 2i, 2i+1 are the x and y
    equations at node i; columns 2j, 2j+1 the x and y components at node j.
    """
    n = mesh.size
    # built transposed, (column node j, l, row node i, k): a block's columns are contiguous
    H_t = np.zeros((n, 2, n, 2))
    G_t = np.zeros((n, 2, n, 2))
    for elements, h, g in element_blocks(mesh, shear, poisson):
        for a in range(3):  # within one slot a, the nodes of distinct elements are distinct
            nodes = mesh.connectivity[elements, a]
            H_t[nodes] += h[:, a]
            G_t[nodes] += g[:, a]
    rows = np.arange(n)
    # rigid-body condition: H_ii = -sum_{j != i} H_ij, as :mod:`.system` (an own-node integral that is
    # not exactly zero, as beside contact elements of 1e-5 of their neighbours, is replaced, not summed)
    H_t[rows, :, rows, :] = 0.0
    H_t[rows, :, rows, :] = -H_t.sum(axis=0).transpose(1, 0, 2)
    return H_t.reshape(2 * n, 2 * n).T, G_t.reshape(2 * n, 2 * n).T


def classify(mesh: BoundaryMesh, geo: Geometry, points: np.ndarray, elements: np.ndarray):
    """The pairs of collocation nodes ``points`` and ``elements`` by kind, both numbered locally (p, q).

    Returns ``collinear``: per line among the elements, (q (e,), its points p
    (n,), c (e, n), own (e, n)): every point on that line against every element
    on it, with the point's local coordinate c on the element's line and its
    position among the element's nodes (-1: none); the elements alone on their
    lines (a polygon's sides, as a circle's) in one entry whose points are
    per element, p (e, 3) its own nodes (-1: not a point), c (e, 3), own (e, 3)
    (a curved element's own nodes are ``near`` pairs at distance 0, which
    :func:`own_integrals` takes, without the own node's strongly singular H
    term, as the closed forms); ``near`` (p, q, t, dist):
    the nearest point's fraction t along the element and the distance
    [length]; ``regular`` (p, q, dist).
    """
    p0, tangent, half = geo.p0[elements], geo.tangent[elements], geo.half[elements]
    rel = mesh.nodes[points][:, None, :] - p0[None]  # (P, e, 2)
    along = np.einsum("ned,ed->ne", rel, tangent)
    across = rel[..., 1] * tangent[None, :, 0] - rel[..., 0] * tangent[None, :, 1]
    length = 2.0 * half[None, :]
    curved = geo.line[elements] < 0
    on_line = (np.abs(across) <= ON_LINE * length) & ~curved[None, :]
    position = np.full(mesh.size, -1)
    position[points] = np.arange(points.size)
    member = np.full(on_line.shape, -1)
    q = np.arange(elements.size)
    for a in range(3):
        p = position[mesh.connectivity[elements, a]]
        member[p[p >= 0], q[p >= 0]] = a
    collinear = []
    lines = geo.line[elements]
    unique, counts = np.unique(lines, return_counts=True)
    alone = np.isin(lines, unique[counts == 1]) & ~curved  # a straight element alone on its line
    own_points = np.where(member >= 0, 1, 0).sum(axis=0)  # per element: its nodes among the points
    alone &= np.count_nonzero(on_line, axis=0) == own_points  # ... and no other point on its line
    if np.any(alone):  # all at once: each against its own nodes (rows (e, 3): -1 where not a point)
        qs = np.flatnonzero(alone)
        slots = position[mesh.connectivity[elements[qs]]]
        collinear.append((qs, slots, mesh.local[elements[qs]].copy(), np.broadcast_to(np.arange(3), slots.shape)))
    for line in distinct(lines[~alone & ~curved]):
        qs = np.flatnonzero(lines == line)
        nodes = np.flatnonzero(on_line[:, qs[0]])
        if not on_line[nodes][:, qs].all() or np.count_nonzero(on_line[:, qs]) != nodes.size * qs.size:
            raise ValueError("elements of one line see different nodes on it")
        own = member[nodes][:, qs].T
        c = along[nodes][:, qs].T / half[qs, None] - 1.0
        inside = own >= 0
        c[inside] = mesh.local[elements[qs, None], np.maximum(own, 0)][inside]
        collinear.append((qs, nodes, c, own))
    t = np.clip(along / length, 0.0, 1.0)
    dist = np.hypot(along - t * length, across)
    own_curved = curved[None, :] & (member >= 0)  # a curved element's own nodes: at their local coordinates
    p_own, q_own = np.nonzero(own_curved)
    t[p_own, q_own] = 0.5 * (mesh.local[elements[q_own], member[p_own, q_own]] + 1.0)
    dist[own_curved] = 0.0
    near = ~on_line & ((dist < NEAR * length) | own_curved)
    i_near, q_near = np.nonzero(near)
    regular = ~on_line & ~near
    i_reg, q_reg = np.nonzero(regular)
    return collinear, (i_near, q_near, t[near], dist[near]), (i_reg, q_reg, dist[regular])


def _block(mesh, geo, points, elements, shear, poisson, h, g, ring=None, template=None) -> None:
    """The integrals of ``elements`` into h and g (:func:`element_blocks`); every pair is of exactly one
    kind, or is a ``ring`` pair, rotated from the ``template`` rows (h and g stacked)."""
    collinear_runs, near, regular = classify(mesh, geo, points, elements)
    if ring is not None:
        near, regular = _ring_pairs(ring, template, points, elements, near, regular, h, g)
    for qs, nodes, c, own in collinear_runs:
        e = elements[qs]
        if nodes.ndim == 2:  # elements alone on their lines, against their own nodes: scatter the valid pairs
            values = collinear.integrals(c, own, geo.coeff[e], geo.half[e], geo.tangent[e], shear, poisson)
            pair, slot = np.nonzero(nodes >= 0)
            h[qs[pair], :, :, nodes[pair, slot], :] = values[0][pair, :, :, slot, :]
            g[qs[pair], :, :, nodes[pair, slot], :] = values[1][pair, :, :, slot, :]
            continue
        rows, columns = _span(qs), _span(nodes)
        if isinstance(rows, slice) and isinstance(columns, slice):  # written in place
            out = (h[rows, :, :, columns], g[rows, :, :, columns])
            collinear.integrals(c, own, geo.coeff[e], geo.half[e], geo.tangent[e], shear, poisson, out)
            continue
        values = collinear.integrals(c, own, geo.coeff[e], geo.half[e], geo.tangent[e], shear, poisson)
        if isinstance(rows, slice) or isinstance(columns, slice):
            h[rows, :, :, columns], g[rows, :, :, columns] = values
        else:  # neither is a contiguous range: one element at a time
            for k, q in enumerate(qs):
                h[q, :, :, nodes], g[q, :, :, nodes] = (v[k].transpose(2, 0, 1, 3) for v in values)
    i, q, t, dist = near
    own = dist == 0.0  # a curved element's own nodes (a node at distance 0 from another element is its own)
    for part in (~own, own):  # apart: the own nodes' subdivision goes down to 1e-12 of the element
        if not np.any(part):
            continue
        pairs = np.column_stack([points[i[part]], elements[q[part]]])
        if part is own:
            values = own_integrals(mesh, geo, pairs, 2.0 * t[part] - 1.0, shear, poisson)
        else:
            values = near_integrals(mesh, geo, pairs, t[part], dist[part], shear, poisson)
        if part is own:  # leave out the own node's strongly singular H term (the rigid-body diagonal)
            slot = np.argmax(mesh.connectivity[pairs[:, 1]] == pairs[:, :1], axis=1)
            values[0][np.arange(slot.size), slot] = 0.0
        _put(h, g, q[part], i[part], [v.swapaxes(-1, -2) for v in values])
    i, q, dist = regular
    values = regular_integrals(mesh, geo, points[i], elements[q], shear, poisson, dist)
    _put(h, g, q, i, [v.swapaxes(-1, -2) for v in values])


def _ring_pairs(ring, template, points, elements, near, regular, h, g):
    """Put the ring's pairs, rotated from the template (:mod:`.ring`), into h and g; return the near
    and regular pairs left to integrate (the ring's elements are curved: never collinear pairs)."""
    from . import ring as rings

    p, q = rings.fill(ring, template, points, elements, h, g)
    if not (p.size and q.size):
        return near, regular
    in_ring = np.zeros((points.size, elements.size), dtype=bool)
    in_ring[np.ix_(p, q)] = True
    keep_near = ~in_ring[near[0], near[1]]
    keep_regular = ~in_ring[regular[0], regular[1]]
    return tuple(v[keep_near] for v in near), tuple(v[keep_regular] for v in regular)


def distinct(values: np.ndarray) -> np.ndarray:
    """The sorted distinct values, as ``np.unique``; asking for the counts keeps numpy 2's plain
    ``np.unique`` from importing numpy.ma (~15 ms of a process that needs it nowhere else)."""
    return np.unique(values, return_counts=True)[0]


def _span(index: np.ndarray):
    """A slice for a contiguous increasing index array, else the array."""
    if index.size and index[-1] - index[0] == index.size - 1 and np.all(np.diff(index) == 1):
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


def _put(h, g, q, i, values) -> None:
    """h[q, :, :, i, :], g[...] = values (P, 3, 2, 2) each, through flat indices (faster than two index arrays)."""
    n = h.shape[3]
    offsets = (np.arange(3)[:, None, None] * 4 * n + np.arange(2)[None, :, None] * 2 * n + np.arange(2)).ravel()
    flat = ((q * (12 * n) + 2 * i)[:, None] + offsets).ravel()
    h.reshape(-1)[flat] = values[0].reshape(-1)
    g.reshape(-1)[flat] = values[1].reshape(-1)


def _contract(kernel: np.ndarray, weighted_shape: np.ndarray) -> np.ndarray:
    """sum_q kernel[..., q, k, l] * weighted_shape[..., q, a] -> (..., a, k, l), as a batched matmul."""
    lead = kernel.shape[:-3]
    q = kernel.shape[-3]
    k4 = kernel.reshape(*lead, q, 4)
    out = np.matmul(np.swapaxes(weighted_shape, -1, -2), k4)  # (..., a, 4)
    return out.reshape(*lead, weighted_shape.shape[-1], 2, 2)


def _chunks(count: int, per_item: int):
    step = max(1, _CHUNK // max(per_item, 1))
    for start in range(0, count, step):
        yield slice(start, min(count, start + step))


def regular_orders(ratio: np.ndarray) -> np.ndarray:
    """Gauss points for pairs at ``ratio`` = distance / element length (>= ``NEAR``) (P,) -> (P,).

    The kernels times the shape functions are analytic on the element but for the node's pole (U's
    log, T's 1/r) and, on a curved element, the branch points of its Jacobian (at ~2/angle in local
    coordinates), so Gauss's error falls geometrically with the order, the faster the farther the
    node. The table (``ORDERS``, ``BREAKS``) is measured against a 40-point rule over the regular
    pairs of five meshes (a covered, a solid and a thin-walled annulus, a layer, a half-space block):
    the largest error of a pair's H and G integrals, relative to its largest entry, is at most
    6e-13 in every band (``GAUSS`` points err by up to 2e-11 at one element length, the ``NEAR``
    threshold); 4 points would err by 2e-11 even beyond 80 lengths (a small bore's curved
    elements), so 5 is the least.
    """
    return np.asarray(ORDERS)[np.searchsorted(np.asarray(BREAKS), np.asarray(ratio, dtype=float), side="right")]


def regular_integrals(mesh, geo, nodes, elements, shear, poisson, dist=None) -> tuple[np.ndarray, np.ndarray]:
    """Gauss rules for pairs (nodes[p], elements[p]): H and G integrals, each (P, 3, 2, 2); ``dist``
    (P,) [length] each node's distance from its element's chord sets the order (:func:`regular_orders`;
    None: ``GAUSS`` points for every pair)."""
    h = np.empty((nodes.size, 3, 2, 2))
    g = np.empty_like(h)
    if dist is None:
        orders = np.full(nodes.size, GAUSS)
    else:
        orders = regular_orders(np.asarray(dist) / (2.0 * geo.half[elements]))
    for order in distinct(orders):
        points, normals, weighted = geo.rules[int(order)]
        chosen = np.flatnonzero(orders == order) if dist is not None else np.arange(nodes.size)
        for part in _chunks(chosen.size, int(order)):
            pick = chosen[part]
            e = elements[pick]
            d = points[e] - mesh.nodes[nodes[pick], None, :]  # (p, n, 2)
            g[pick] = _contract(kelvin.displacement_kernel(d, shear, poisson), weighted[e])
            h[pick] = _contract(kelvin.traction_kernel(d, normals[e], poisson), weighted[e])
    return h, g


def near_integrals(mesh, geo, pairs, t, dist, shear, poisson) -> tuple[np.ndarray, np.ndarray]:
    """Graded subdivision towards the nearest point of the element, for pairs (P, 2) of (node,
    element) with the nearest point's fraction ``t`` along the element and its distance ``dist``
    [length]: H and G integrals, each (P, 3, 2, 2)."""
    length = 2.0 * geo.half[pairs[:, 1]]
    centre = 2.0 * t - 1.0  # nearest point in local coordinates
    scale = np.abs(mesh.nodes[pairs[:, 0]]).max(axis=1)  # at least the rounding of the node's position:
    d_xi = np.maximum(2.0 * dist / length, np.maximum(1e-12, 1e3 * np.finfo(float).eps * 2.0 * scale / length))
    levels = int(np.ceil(np.log(max(2.0 / d_xi.min(), 1.0)) / np.log(1.0 / GRADING))) + 1
    # sub-interval edges on each side of the centre: centre +- d_xi / GRADING^k, clipped
    k = np.arange(levels + 1)
    offsets = np.hstack([np.zeros((len(pairs), 1)), d_xi[:, None] * (1.0 / GRADING) ** k[None, :]])
    right = np.clip(centre[:, None] + offsets, -1.0, 1.0)
    left = np.clip(centre[:, None] - offsets, -1.0, 1.0)
    edges = np.hstack([left[:, ::-1], right[:, 1:]])  # (P, 2 levels + 3), increasing
    # sub-intervals clipped to nothing (beyond an end of the element, the more of them the farther
    # the pair from the nearest one) carry no weight: integrate each pair's others only, in groups
    # of pairs with as many (the same points and weights, summed in another order)
    lo, hi = edges[:, :-1], edges[:, 1:]
    empty = hi <= lo
    first = np.argsort(empty, axis=1, kind="stable")  # the non-empty sub-intervals first, in order
    lo, hi = np.take_along_axis(lo, first, axis=1), np.take_along_axis(hi, first, axis=1)
    counts = np.count_nonzero(~empty, axis=1)
    xg, wg = gauss(GAUSS_NEAR)
    h = np.empty((len(pairs), 3, 2, 2))
    g = np.empty_like(h)
    for count in distinct(counts):
        chosen = np.flatnonzero(counts == count)
        low, high = lo[chosen, :count], hi[chosen, :count]
        half = 0.5 * (high - low)
        xi = (0.5 * (high + low))[:, :, None] + half[:, :, None] * xg[None, None, :]
        w = half[:, :, None] * wg[None, None, :]
        per = xi.shape[1] * xi.shape[2]
        h[chosen], g[chosen] = _integrate(
            mesh, geo, pairs[chosen], xi.reshape(chosen.size, per), w.reshape(chosen.size, per), shear, poisson
        )
    return h, g


def _integrate(mesh, geo, pairs, xi, w, shear, poisson) -> tuple[np.ndarray, np.ndarray]:
    """H and G integrals (P, 3, 2, 2) of pairs (P, 2) of (node, element) by the rules of local points
    ``xi`` and weights ``w`` (P, Q) on each element."""
    per = xi.shape[1]
    h = np.empty((len(pairs), 3, 2, 2))
    g = np.empty_like(h)
    for part in _chunks(len(pairs), per):
        i, e = pairs[part, 0], pairs[part, 1]
        d, nrm, jac = map_points(mesh.geometry[e] - mesh.nodes[i][:, None, :], xi[part])  # relative: no cancellation
        ws = (w[part] * jac)[..., None] * evaluate(geo.coeff[e], xi[part])  # (p, Q, 3)
        g[part] = _contract(kelvin.displacement_kernel(d, shear, poisson), ws)
        h[part] = _contract(kelvin.traction_kernel(d, nrm, poisson), ws)
    return h, g


#: Gauss points on each side of a curved element's own node, and the power of the substitution.
OWN_GAUSS = 24
OWN_POWER = 3


def own_integrals(mesh, geo, pairs, centre, shear, poisson) -> tuple[np.ndarray, np.ndarray]:
    """A curved element's integrals for its own nodes, pairs (P, 2) of (node, element) with the node's
    local coordinate ``centre`` (P,): each side of the node, xi = c +- L u^3 (L the side's length,
    u in [0, 1], ``OWN_GAUSS`` Gauss points), which turns the log singularity of U into u^2 ln u and
    leaves T N_j (j not the node's own, which vanishes at the node) bounded. The own node's strongly
    singular H term is left to the caller. Each (P, 3, 2, 2)."""
    xg, wg = gauss(OWN_GAUSS)
    u = 0.5 * (xg + 1.0)
    du = OWN_POWER * u ** (OWN_POWER - 1) * 0.5 * wg  # d(u^k) for the Gauss weights on [0, 1]
    lengths = np.stack([centre + 1.0, 1.0 - centre], axis=1)  # (P, 2): left and right of the node
    side = np.array([-1.0, 1.0])
    xi = centre[:, None, None] + side[None, :, None] * lengths[:, :, None] * u[None, None, :] ** OWN_POWER
    w = lengths[:, :, None] * du[None, None, :]
    # a side of length 0 (the node at an end of its element, a continuous element's) carries no
    # weight: those pairs integrate their other side only
    h = np.empty((len(pairs), 3, 2, 2))
    g = np.empty_like(h)
    one_sided = lengths.min(axis=1) == 0.0
    for chosen, sides in ((np.flatnonzero(~one_sided), slice(None)), (np.flatnonzero(one_sided), None)):
        if not chosen.size:
            continue
        if sides is None:  # the side with the length
            keep = np.argmax(lengths[chosen], axis=1)
            x, weight = xi[chosen, keep][:, None], w[chosen, keep][:, None]
        else:
            x, weight = xi[chosen], w[chosen]
        h[chosen], g[chosen] = _integrate(
            mesh, geo, pairs[chosen], x.reshape(chosen.size, -1), weight.reshape(chosen.size, -1), shear, poisson
        )
    return h, g
