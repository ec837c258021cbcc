"""Assembly of the BEM matrices H and G (collocation at the functional nodes).

For collocation node i and element e, the integrals of T_kl N_j and U_kl N_j
over e are computed in one of three ways, vectorised over all pairs of a kind
and their quadrature points:

* **singular** (i is a node of e; elements are straight): the log part of U is
  integrated in closed form (:func:`rolling_cli.kernels.log_moments`), the rest
  of U is constant along the element; for T, dr/dn = 0 and T N_j J reduces to a
  constant times N_j(xi) / (xi - xi_i), a polynomial for j != i, integrated
  exactly. The strongly singular N_i part of T and the free term are not
  computed: the diagonal 2x2 blocks of H come from the rigid-body condition
  (rows of H sum to zero for each direction).
* **nearly singular** (distance from i to e below ``NEAR`` element lengths, as
  for neighbours of discontinuous nodes or across a thin layer): the element
  is cut into sub-intervals graded geometrically towards the point of e
  nearest to i, each no longer than its distance to i, with ``GAUSS_NEAR``
  Gauss points on each (error < 1e-13 for a pole at one sub-interval length).
* **regular**: ``GAUSS`` Gauss points (error < 1e-12 at the ``NEAR`` threshold).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse

from ...kernels import log_moments
from . import kelvin
from .elements import evaluate, gauss, lagrange_coefficients, map_points
from .mesh import BoundaryMesh

NEAR = 1.0
GAUSS = 10
GAUSS_NEAR = 12
GRADING = 0.5
_CHUNK = 2_000_000  # quadrature points per vectorised chunk (bounds memory)


def assemble(mesh: BoundaryMesh, shear: float, poisson: float) -> tuple[np.ndarray, np.ndarray]:
    """H and G, each (2N, 2N): H u = G t for nodal displacements u and tractions t.

    ``shear`` G [stress], ``poisson`` nu. Rows 2i, 2i+1 are the x and y
    equations at node i; columns 2j, 2j+1 the x and y components at node j.
    """
    n = mesh.size
    coeff = lagrange_coefficients(mesh.local)  # (E, 3, 3)
    h_loc = np.zeros((n, mesh.elements, 3, 2, 2))
    g_loc = np.zeros((n, mesh.elements, 3, 2, 2))
    singular, near, regular = _classify(mesh)
    _regular(mesh, coeff, regular, shear, poisson, h_loc, g_loc)
    _near(mesh, coeff, near, shear, poisson, h_loc, g_loc)
    _singular(mesh, coeff, singular, shear, poisson, h_loc, g_loc)
    H = _scatter(mesh, h_loc)
    G = _scatter(mesh, g_loc)
    # rigid-body condition: each row of H sums to zero per displacement direction
    for k in range(2):
        for l in range(2):
            rows = 2 * np.arange(n) + k
            cols = 2 * np.arange(n) + l
            H[rows, cols] = 0.0
            H[rows, cols] = -H[rows, l::2].sum(axis=1)
    return H, G


def _scatter(mesh: BoundaryMesh, local: np.ndarray) -> np.ndarray:
    """Sum element-node contributions (N, E, 3, 2, 2) into a (2N, 2N) matrix.

    A shared (continuous) node collects the columns of both its elements:
    the sum is a product with the sparse element-node incidence matrix.
    """
    n = mesh.size
    cols = mesh.connectivity.reshape(-1)
    incidence = scipy.sparse.csr_matrix((np.ones(cols.size), (np.arange(cols.size), cols)), shape=(cols.size, n))
    flat = local.transpose(0, 3, 1, 2, 4).reshape(2 * n, mesh.elements * 3, 2)  # rows (i, k), cols (e, a), l
    out = np.empty((2 * n, n, 2))
    for l in range(2):
        out[:, :, l] = (incidence.T @ flat[:, :, l].T).T
    return out.reshape(2 * n, 2 * n)


def _classify(mesh: BoundaryMesh):
    """Singular pairs (i, e); nearly singular pairs with their nearest point and
    distance; and the (N, E) mask of the regular pairs."""
    n, ne = mesh.size, mesh.elements
    member = np.zeros((n, ne), dtype=bool)
    member[mesh.connectivity, np.arange(ne)[:, None]] = True
    p0, p2 = mesh.geometry[:, 0], mesh.geometry[:, 2]
    seg = p2 - p0
    length = np.linalg.norm(seg, axis=1)
    rel = mesh.nodes[:, None, :] - p0[None, :, :]
    t = np.clip(np.einsum("ned,ed->ne", rel, seg) / length**2, 0.0, 1.0)
    closest = p0[None] + t[..., None] * seg[None]
    dist = np.linalg.norm(mesh.nodes[:, None, :] - closest, axis=2)
    near = ~member & (dist < NEAR * length[None, :])
    regular = ~member & ~near
    return np.argwhere(member), (np.argwhere(near), t[near], dist[near]), regular


def _contract(kernel: np.ndarray, weighted_shape: np.ndarray) -> np.ndarray:
    """sum_q kernel[..., q, k, l] * weighted_shape[..., q, a] -> (..., a, k, l), as a batched matmul."""
    lead = kernel.shape[:-3]
    q = kernel.shape[-3]
    k4 = kernel.reshape(*lead, q, 4)
    out = np.matmul(np.swapaxes(weighted_shape, -1, -2), k4)  # (..., a, 4)
    return out.reshape(*lead, weighted_shape.shape[-1], 2, 2)


def _integrate(points_xi, weights, pairs, mesh, coeff, shear, poisson, h_loc, g_loc):
    """Accumulate quadrature over individual pairs: points_xi/weights (P, Q) per pair."""
    i, e = pairs[:, 0], pairs[:, 1]
    pts, nrm, jac = map_points(mesh.geometry[e], points_xi)
    d = pts - mesh.nodes[i][:, None, :]
    shape = evaluate(coeff[e], points_xi)  # (P, Q, 3)
    ws = (weights * jac)[..., None] * shape
    # pairs are unique within a call, so fancy-index accumulation is safe
    g_loc[i, e] += _contract(kelvin.displacement_kernel(d, shear, poisson), ws)
    h_loc[i, e] += _contract(kelvin.traction_kernel(d, nrm, poisson), ws)


def _chunks(count: int, per_item: int):
    step = max(1, _CHUNK // max(per_item, 1))
    for start in range(0, count, step):
        yield slice(start, min(count, start + step))


def _regular(mesh, coeff, regular, shear, poisson, h_loc, g_loc):
    """All pairs with one Gauss rule: geometry and shapes once per element, kernels densely
    over chunks of collocation points; the pairs that are not regular are discarded."""
    xg, wg = gauss(GAUSS)  # an even order: no Gauss point sits on a node
    pts, nrm, jac = map_points(mesh.geometry, xg)  # (E, G, 2)
    ws = (wg[None, :] * jac)[..., None] * evaluate(coeff, np.broadcast_to(xg, jac.shape))  # (E, G, 3)
    for part in _chunks(mesh.size, mesh.elements * GAUSS * 10):
        d = pts[None] - mesh.nodes[part, None, None, :]  # (c, E, G, 2)
        keep = regular[part][..., None, None, None]
        g_loc[part] += np.where(keep, _contract(kelvin.displacement_kernel(d, shear, poisson), ws), 0.0)
        h_loc[part] += np.where(keep, _contract(kelvin.traction_kernel(d, nrm[None], poisson), ws), 0.0)


def _near(mesh, coeff, near, shear, poisson, h_loc, g_loc):
    """Graded subdivision towards the nearest point of the element."""
    pairs, t, dist = near
    if len(pairs) == 0:
        return
    length = mesh.lengths[pairs[:, 1]]
    centre = 2.0 * t - 1.0  # nearest point in local coordinates
    d_xi = np.maximum(2.0 * dist / length, 1e-12)  # distance in local units
    levels = int(np.ceil(np.log(max(2.0 / d_xi.min(), 1.0)) / np.log(1.0 / GRADING))) + 1
    # sub-interval edges on each side of the centre: centre +- d_xi / GRADING^k, clipped
    k = np.arange(levels + 1)
    offsets = np.hstack([np.zeros((len(pairs), 1)), d_xi[:, None] * (1.0 / GRADING) ** k[None, :]])
    right = np.clip(centre[:, None] + offsets, -1.0, 1.0)
    left = np.clip(centre[:, None] - offsets, -1.0, 1.0)
    edges = np.hstack([left[:, ::-1], right[:, 1:]])  # (P, 2 levels + 3), increasing
    lo, hi = edges[:, :-1], edges[:, 1:]
    xg, wg = gauss(GAUSS_NEAR)
    half = 0.5 * (hi - lo)
    xi = (0.5 * (hi + lo))[:, :, None] + half[:, :, None] * xg[None, None, :]
    w = half[:, :, None] * wg[None, None, :]
    per = xi.shape[1] * xi.shape[2]
    xi = xi.reshape(len(pairs), per)
    w = w.reshape(len(pairs), per)
    for part in _chunks(len(pairs), per):
        _integrate(xi[part], w[part], pairs[part], mesh, coeff, shear, poisson, h_loc, g_loc)


def _singular(mesh, coeff, pairs, shear, poisson, h_loc, g_loc):
    """Closed-form integrals over the (straight) element holding the collocation node."""
    i, e = pairs[:, 0], pairs[:, 1]
    a = np.argmax(mesh.connectivity[e] == i[:, None], axis=1)  # position of i in e
    xi_c = mesh.local[e, a]
    p0, p2 = mesh.geometry[e, 0], mesh.geometry[e, 2]
    mid = mesh.geometry[e, 1]
    if not np.allclose(mid, 0.5 * (p0 + p2), atol=1e-12 * np.abs(p2 - p0).max()):
        raise NotImplementedError("singular integration is implemented for straight elements")
    chord = p2 - p0
    jac = 0.5 * np.linalg.norm(chord, axis=1)
    tan = chord / (2.0 * jac[:, None])
    nrm = np.stack([tan[:, 1], -tan[:, 0]], axis=1)
    C = coeff[e]  # (P, k, m)
    moments = np.array([2.0, 0.0, 2.0 / 3.0])
    integral_n = C @ moments  # int N_k
    log_int = np.einsum("pkm,pm->pk", C, log_moments(xi_c))  # int N_k ln|xi - xi_c|
    cu = 1.0 / (8.0 * np.pi * shear * (1.0 - poisson))
    g = (
        cu
        * jac[:, None, None, None]
        * (
            (3.0 - 4.0 * poisson)
            * (-np.log(jac)[:, None] * integral_n - log_int)[:, :, None, None]
            * np.eye(2)[None, None]
            + integral_n[:, :, None, None] * (tan[:, :, None] * tan[:, None, :])[:, None]
        )
    )
    g_loc[i, e] += g
    # T N_k J = (1-2nu)/(4 pi (1-nu)) (t_k n_l - t_l n_k) N_k(xi)/(xi - xi_c), for k != i:
    # N_k(xi)/(xi - xi_c) = A2 xi + (A1 + A2 xi_c), whose integral over [-1, 1] is 2 (A1 + A2 xi_c)
    poly = 2.0 * (C[:, :, 1] + C[:, :, 2] * xi_c[:, None])
    poly[np.arange(len(pairs)), a] = 0.0  # the node's own term goes to the rigid-body diagonal
    skew = tan[:, :, None] * nrm[:, None, :] - tan[:, None, :] * nrm[:, :, None]
    h = (1.0 - 2.0 * poisson) / (4.0 * np.pi * (1.0 - poisson)) * poly[:, :, None, None] * skew[:, None]
    h_loc[i, e] += h
