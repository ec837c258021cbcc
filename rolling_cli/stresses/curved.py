"""Stresses inside a BEM body meshed with CURVED quadratic elements (the Somigliana identity).

The identity is :mod:`.bem`'s (Muskhelishvili's complex form; read its
docstring), written with dt = e^{i theta} ds so that every term is a Cauchy
integral in the complex boundary coordinate t. With F = g e^{-i theta} (the
boundary value of phi') and H = h e^{-i theta}, h = -i conj(tau) - conj(g):

    2 pi i phi'(zeta) = int F / (t - zeta) dt
    pi i (sigma_yy - sigma_xx + 2 i sigma_xy)
        = int H / (t - zeta) dt - int conj(t - zeta) F / (t - zeta)^2 dt.

On an isoparametric element t(xi) = m + c tau(xi) (m the chord's mid-point,
c its half-chord as a complex number, tau(xi) = xi + beta (1 - xi^2) the
element in its own chord frame, beta = (t_mid - m) / c) the point is
z = (zeta - m) / c and, with conj(tau - z) = (tau - z) - 2 i Im tau + 2 i Im z,

    int F/(t - zeta) dt = A[F],   int conj(t - zeta) F/(t - zeta)^2 dt
        = conj(c)/c (A[F] + 2 i Im z B[F] - 2 i B[(Im tau) F]),

A[f] = int_Gamma f / (tau - z) dtau, B[f] = int_Gamma f / (tau - z)^2 dtau
along the curved element Gamma from -1 to 1: no cancellation near the element.

Quadrature by distance (|z| in half-chords from the chord's mid-point):

* |z| >= :data:`FAR` (most pairs): Gauss-Legendre with :data:`FAR_NODES`
  points in xi, one dense matrix product per chunk of points (relative
  error about rho^(-2 n) for the Bernstein ellipse through z, rho >= 19.9:
  < 4e-11);
* :data:`MIDDLE` <= |z| < FAR: Gauss with :data:`MIDDLE_NODES` points
  (rho >= 7.9: < 2e-11), pair by pair;
* :data:`NEAR` <= |z| < MIDDLE: Gauss with :data:`MEDIUM_NODES` points
  (rho >= 4.8: < 3e-14), pair by pair;
* |z| < NEAR: product integration (Helsing & Ojala 2008): f along Gamma
  interpolated as a polynomial of degree NODES - 1 in tau at the Gauss
  points, whose monomials integrate exactly along the straight chord by the
  recursions p_{k+1} = z p_k + (1 - (-1)^(k+1))/(k+1), p_0 = log((1 - z)/(-1 - z)),
  q_k = p_{k-1} + z q_{k-1}, q_0 = -2/(1 - z^2); the chord and Gamma differ by
  the residue 2 pi i f(z) (or f'(z)) when z lies between them (the lens),
  with the sign of the loop's orientation. Exact for the interpolated data up
  to the interpolation of smooth functions of xi at any distance from the
  element (the recursion's growth |z|^NODES < 6e4 stays far below 1/eps).

Mirror pairs: on a mesh that is its own mirror image in x = 0 (a finite
cylinder's), a point and its mirror -conj(zeta) among the requested points
share the far rule's kernel: the mirror's difference to node q of the mirror
element is -conj of the point's to node n - 1 - q of the element, so its sums
are -conj of the kernel times the conjugated, permuted weights (more columns
of one matrix product: a symmetric field costs 0.7-0.85 of the plain
evaluation).

Boundary points (within :data:`ON_BOUNDARY` half-chords of an element, on
either side, or placed on their element by the caller: a point of the true
circle lies about R (h/2R)^4 off its quadratic element, 1e-4 h on an arc of
1/32 of the circle, so :mod:`.cylinder` places its surface and bore points
itself) get the stress recovered from the traction and the tangential strain
(:func:`boundary_stresses`), as :mod:`.bem`. Straight elements are the case
beta = 0, so the module also serves straight meshes (the tests compare them).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..influence.bem.elements import gauss, lagrange_coefficients
from ..influence.bem.mesh import BoundaryMesh
from .bem import surface_stresses

#: Gauss points of the product integration (its interpolation degree + 1).
NODES = 12
#: Gauss points of the medium rule.
MEDIUM_NODES = 10
#: Gauss points of the middle rule.
MIDDLE_NODES = 6
#: Gauss points of the far rule.
FAR_NODES = 4
#: |z| (half-chords) below which a pair is integrated by product integration.
NEAR = 2.5
#: |z| from which the middle rule serves.
MIDDLE = 4.0
#: |z| from which the far rule serves.
FAR = 10.0
#: A point within this many half-chords of an element is a boundary point (1e-9 element lengths, as :mod:`.bem`).
ON_BOUNDARY = 2e-9
#: Complex entries per chunk of the dense far sum (bounds its temporaries to ~50 MB).
CHUNK = 1_000_000


@dataclass(frozen=True)
class CurvedData:
    """Per-element data of a boundary solution on curved quadratic elements.

    ``mid`` (E,) chord mid-points and ``chord`` (E,) half-chords (complex) [length]; ``beta`` (E,)
    the element's bulge in its chord frame; ``coeff`` (E, 3, 3) Lagrange coefficients of its
    functional nodes; ``disp`` (E, 3) [length] and ``traction`` (E, 3) [stress] complex nodal
    values; ``shear`` G [stress], ``poisson`` nu.
    """

    mid: np.ndarray
    chord: np.ndarray
    beta: np.ndarray
    coeff: np.ndarray
    disp: np.ndarray
    traction: np.ndarray
    shear: float
    poisson: float

    def at(self, xi: np.ndarray, element: np.ndarray | None = None):
        """At local xi (E, G) of every element (or (K,) of ``element``): point t, dt/dxi, the
        displacement D, dD/dxi [length] and the traction [stress] (complex)."""
        sel = slice(None) if element is None else element
        x = np.asarray(xi, dtype=float)
        if element is None:
            x = np.broadcast_to(x, (self.mid.size,) + x.shape[-1:])
        mid, chord, beta = (v[sel] for v in (self.mid, self.chord, self.beta))
        expand = (lambda v: v[:, None]) if element is None else (lambda v: v)
        tau = x + expand(beta) * (1.0 - x * x)
        point = expand(mid) + expand(chord) * tau
        dpoint = expand(chord) * (1.0 - 2.0 * expand(beta) * x)
        coeff = self.coeff[sel]  # (K, 3 nodes, 3 powers)
        powers = np.stack([np.ones_like(x), x, x * x], axis=-1)
        dpowers = np.stack([np.zeros_like(x), np.ones_like(x), 2.0 * x], axis=-1)
        if element is None:
            shape, dshape = np.einsum("egm,ekm->egk", powers, coeff), np.einsum("egm,ekm->egk", dpowers, coeff)
            disp, trac = self.disp, self.traction
            return (
                point,
                dpoint,
                *(np.einsum("egk,ek->eg", s, v) for s, v in ((shape, disp), (dshape, disp))),
                (np.einsum("egk,ek->eg", shape, trac)),
            )
        shape, dshape = np.einsum("km,kjm->kj", powers, coeff), np.einsum("km,kjm->kj", dpowers, coeff)
        disp, trac = self.disp[sel], self.traction[sel]
        return point, dpoint, (shape * disp).sum(1), (dshape * disp).sum(1), (shape * trac).sum(1)


def curved_data(mesh: BoundaryMesh, u: np.ndarray, t: np.ndarray, shear: float, poisson: float) -> CurvedData:
    """The element data of nodal ``u`` [length] and ``t`` [stress] (N, 2) on ``mesh``; G [stress]."""
    g = mesh.geometry[..., 0] + 1j * mesh.geometry[..., 1]  # (E, 3) start, middle, end
    mid, chord = 0.5 * (g[:, 0] + g[:, 2]), 0.5 * (g[:, 2] - g[:, 0])
    conn = mesh.connectivity
    return CurvedData(
        mid=mid,
        chord=chord,
        beta=(g[:, 1] - mid) / chord,
        coeff=lagrange_coefficients(mesh.local),
        disp=u[conn, 0] + 1j * u[conn, 1],
        traction=t[conn, 0] + 1j * t[conn, 1],
        shear=float(shear),
        poisson=float(poisson),
    )


def densities(data: CurvedData, xi: np.ndarray) -> dict[str, np.ndarray]:
    """At local ``xi`` (G,) of every element: the point t, tau(xi), dt/dxi and F, H, (Im tau) F [stress]."""
    point, dpoint, _, ddisp, traction = data.at(xi)
    jac = np.abs(dpoint)
    back = np.conj(dpoint) / jac  # e^{-i theta}
    kappa = 3.0 - 4.0 * data.poisson
    g = (2.0 * data.shear * ddisp / jac + 1j * traction) / (1.0 + kappa)
    h = -1j * np.conj(traction) - np.conj(g)
    tau = (point - data.mid[:, None]) / data.chord[:, None]
    return {"t": point, "tau": tau, "dt": dpoint, "F": g * back, "H": h * back, "M": tau.imag * g * back}


def interior_stresses(data: CurvedData, points: np.ndarray) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], shape (3, P), at interior points (P, 2) [length]."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    return _evaluate(data, points[:, 0] + 1j * points[:, 1], find=False)[0]


def _evaluate(data: CurvedData, zeta: np.ndarray, find: bool = True, partner: np.ndarray | None = None):
    """The interior stresses (3, P) at ``zeta`` (P,), and the boundary points' element (P,) (-1 inside)
    and xi, found among the near pairs (within :data:`ON_BOUNDARY` half-chords) when ``find``; those
    get no interior value (NaN). One pass over the (point, element) pairs, in chunks of points.

    With the mirror ``partner`` of every element (:func:`mirror_partner`), also the stresses (3, P)
    at the mirror points -conj(zeta), whose far sums come from the same kernel (module docstring);
    a point is then a boundary point when it or its mirror is."""
    mirrored = partner is not None
    sums = np.zeros((2 if mirrored else 1, 2, zeta.size), dtype=complex)  # [point set, 2 pi i phi' | pi i (...)]
    element, xi = np.full(zeta.size, -1), np.zeros(zeta.size)
    step = max(1, CHUNK // ((2 if mirrored else 1) * FAR_NODES * data.mid.size))
    rules = {n: (gauss(n)[1], densities(data, gauss(n)[0])) for n in (FAR_NODES, MIDDLE_NODES, MEDIUM_NODES, NODES)}
    for start in range(0, zeta.size, step):  # chunks of points: the (point, element) arrays stay bounded
        rows = np.arange(start, min(start + step, zeta.size))
        z = _local(data, zeta[rows])
        sets = [(zeta[rows], z)]
        if partner is not None:
            z_mirror = np.empty_like(z)
            z_mirror[:, partner] = -np.conj(z)  # the mirror point seen from the mirror element
            sets.append((-np.conj(zeta[rows]), z_mirror))
        if find:
            for _, local in sets:
                found, at = _boundary_pairs(data, local, np.nonzero(np.abs(local) < NEAR))
                new = (found >= 0) & (element[rows] < 0)
                element[rows[new]], xi[rows[new]] = found[new], at[new]
            keep = element[rows] < 0
            rows, sets = rows[keep], [(points[keep], local[keep]) for points, local in sets]
            if rows.size == 0:
                continue
        far = np.abs(sets[0][1]) >= FAR
        parts = _far_sum(rules[FAR_NODES], sets[0][0], far, partner)  # (sets, 2, p)
        for k, (points, local) in enumerate(sets):
            one, two = parts[k]
            size = np.abs(local)
            _gauss_pairs(rules[MIDDLE_NODES], points, np.nonzero((size >= MIDDLE) & (size < FAR)), one, two)
            _gauss_pairs(rules[MEDIUM_NODES], points, np.nonzero((size >= NEAR) & (size < MIDDLE)), one, two)
            near = np.nonzero(size < NEAR)
            _product_pairs(data, rules[NODES][1], local[near], near, one, two)
            sums[k][:, rows] = parts[k]
    trace = 4.0 * (sums[:, 0] / (2j * np.pi)).real
    second = sums[:, 1] / (1j * np.pi)
    out = np.stack([0.5 * (trace - second.real), 0.5 * (trace + second.real), 0.5 * second.imag], axis=1)
    out[..., element >= 0] = np.nan
    return (out if mirrored else out[0]), element, xi


def _boundary_pairs(data: CurvedData, z: np.ndarray, near, tolerance: float = ON_BOUNDARY):
    """Among the ``near`` (point, element) pairs of z (p, E): each point's nearest element within
    ``tolerance`` half-chords (-1: none) and its xi there."""
    points, elements = near
    element, xi = np.full(z.shape[0], -1), np.zeros(z.shape[0])
    if points.size == 0:
        return element, xi
    foot, bulge = _foot(data.beta[elements], z[near])
    dist = np.where(np.abs(foot) <= 1.0 + 1e-12, np.abs(z[near].imag - bulge), np.inf)
    on = np.flatnonzero(dist <= tolerance)
    order = on[np.argsort(-dist[on] * np.abs(data.chord[elements[on]]))]  # the nearest last: it wins
    element[points[order]] = elements[order]
    xi[points[order]] = np.clip(foot[order], -1.0, 1.0)
    return element, xi


def _local(data: CurvedData, zeta: np.ndarray) -> np.ndarray:
    """z (P, E): the points in each element's chord frame."""
    return (zeta[:, None] - data.mid[None, :]) / data.chord[None, :]


def _far_sum(rule, zeta, mask, partner=None) -> np.ndarray:
    """The far pairs' (``mask`` (p, E)) sums (2 pi i phi', pi i (...)) by the Gauss ``rule``
    (weights, :func:`densities` at its points), shape (1, 2, p): dense, one chunk of points, none on
    the boundary, so no difference vanishes. With the elements' mirror ``partner`` also those of the
    mirror points -conj(zeta) (shape (2, 2, p)): the mirror point's difference to node q of element
    partner[e] is -conj of the point's to node n - 1 - q of e, so its sums are -conj of the kernel's
    products with the conjugated, permuted weights (more columns, the same kernel)."""
    w, d = rule
    nodes = w.size
    weights = np.stack([(w * d["dt"] * d["F"]).ravel(), (w * d["dt"] * d["H"]).ravel()], axis=1)
    if partner is not None:
        permuted = weights.reshape(-1, nodes, 2)[partner, ::-1].reshape(-1, 2)
        weights = np.concatenate([weights, np.conj(permuted)], axis=1)
    diff = d["t"].ravel()[None, :] - zeta[:, None]  # (p, E G)
    kernel = np.reciprocal(diff)
    kernel.reshape(zeta.size, -1, nodes)[...] *= mask[:, :, None]
    direct = kernel @ weights
    diff = np.conj(diff, out=diff)
    diff *= kernel
    diff *= kernel
    double = diff @ weights[:, 0::2]  # the F columns
    out = [np.stack([direct[:, 0], direct[:, 1] - double[:, 0]])]
    if partner is not None:
        out.append(np.stack([-np.conj(direct[:, 2]), -np.conj(direct[:, 3]) + np.conj(double[:, 1])]))
    return np.array(out)


def mirror_partner(data: CurvedData) -> np.ndarray | None:
    """(E,) each element's mirror image in x = 0, traversed the other way (its chord's mid-point at
    -conj(mid), half-chord conj(chord), bulge -conj(beta)), or None when the mesh has none."""
    scale = float(np.abs(data.mid).max() + np.abs(data.chord).max())
    key = np.round(np.stack([data.mid.real, data.mid.imag], axis=1) / (1e-9 * scale)).astype(np.int64)
    wanted = np.round(np.stack([-data.mid.real, data.mid.imag], axis=1) / (1e-9 * scale)).astype(np.int64)
    order, back = np.lexsort(key.T[::-1]), np.lexsort(wanted.T[::-1])
    if not np.array_equal(key[order], wanted[back]):
        return None
    partner = np.empty(data.mid.size, dtype=np.int64)
    partner[back] = order
    close = np.allclose(data.chord[partner], np.conj(data.chord), rtol=0.0, atol=1e-9 * scale)
    if not (close and np.allclose(data.beta[partner], -np.conj(data.beta), rtol=0.0, atol=1e-9)):
        return None
    return partner


def _gauss_pairs(rule, zeta, pairs, first, second) -> None:
    """Add the (point, element) ``pairs`` by the Gauss ``rule`` (as :func:`_far_sum`), pair by pair."""
    points, elements = pairs
    if points.size == 0:
        return
    w, d = rule
    diff = d["t"][elements] - zeta[points, None]  # (K, G)
    kernel = 1.0 / diff
    wdt = w * d["dt"][elements]
    first += _gather(points, (kernel * wdt * d["F"][elements]).sum(1), first.size)
    term = kernel * wdt * (d["H"][elements] - np.conj(diff) * kernel * d["F"][elements])
    second += _gather(points, term.sum(1), second.size)


def _product_pairs(data, d, z, pairs, first, second) -> None:
    """Add the near ``pairs`` (z (K,) in the chord frames) by product integration (module docstring),
    ``d`` the :func:`densities` at the NODES Gauss points."""
    points, elements = pairs
    if points.size == 0:
        return
    tau = d["tau"][elements]  # (K, G) interpolation nodes along Gamma
    vander = tau[:, :, None] ** np.arange(NODES)  # (K, G, k)
    values = np.stack([d[name][elements] for name in ("F", "H", "M")], axis=-1)  # (K, G, 3)
    coeff = np.linalg.solve(vander, values)  # (K, k, 3) monomial coefficients in tau
    lens, sign, z = _lens(data.beta[elements], z)
    p, q = _monomials(z)  # (K, k)
    A = np.einsum("kn,knd->kd", p, coeff)
    B = np.einsum("kn,knd->kd", q, coeff)
    if np.any(lens):  # the residues of the loop between the chord and Gamma
        powers = z[lens, None] ** np.arange(NODES)
        dpowers = np.zeros_like(powers)
        dpowers[:, 1:] = np.arange(1, NODES) * powers[:, :-1]
        A[lens] += 2j * np.pi * sign[lens, None] * np.einsum("kn,knd->kd", powers, coeff[lens])
        B[lens] += 2j * np.pi * sign[lens, None] * np.einsum("kn,knd->kd", dpowers, coeff[lens])
    chord = data.chord[elements]
    A_F, A_H, B_F, B_M = A[:, 0], A[:, 1], B[:, 0], B[:, 2]
    conj_term = np.conj(chord) / chord * (A_F + 2j * z.imag * B_F - 2j * B_M)
    first += _gather(points, A_F, first.size)
    second += _gather(points, A_H - conj_term, second.size)


def _gather(index: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """Sums of complex ``values`` by ``index`` (0 .. size - 1)."""
    return np.bincount(index, values.real, size) + 1j * np.bincount(index, values.imag, size)


def _lens(beta: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Which z lie between the chord and the element (the residue's sign: +1 when the element lies
    below its chord, -1 above), and z nudged off the chord inside the lens (its log's branch cut)."""
    xi, bulge = _foot(beta, z)
    lens = (np.abs(z.real) < 1.0) & (bulge != 0.0) & (z.imag / np.where(bulge == 0.0, 1.0, bulge) > 0.0)
    lens &= np.abs(z.imag) < np.abs(bulge)
    on_chord = (np.abs(z.real) < 1.0) & (np.abs(z.imag) < 1e-13) & (bulge != 0.0)
    z = np.where(on_chord, z.real + 1e-13j * np.sign(bulge), z)
    lens |= on_chord
    return lens, np.where(bulge > 0.0, -1.0, 1.0), z


def _foot(beta: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """xi where Re tau(xi) = Re z on an element (the root in [-1, 1] near Re z) and Im tau there."""
    b = beta.real
    x = z.real
    root = np.sqrt(np.maximum(1.0 - 4.0 * b * (x - b), 0.0))
    xi = 2.0 * (x - b) / (1.0 + root)
    return xi, beta.imag * (1.0 - xi * xi) + 0.0 * b


def _monomials(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """p_k = int_{-1}^{1} tau^k/(tau - z), q_k = int tau^k/(tau - z)^2 along the chord, k < NODES."""
    p = np.empty((z.size, NODES), dtype=complex)
    q = np.empty_like(p)
    p[:, 0] = np.log((1.0 - z) / (-1.0 - z))
    q[:, 0] = -2.0 / (1.0 - z * z)
    for k in range(1, NODES):  # recursions over the degree (not over points or elements)
        p[:, k] = z * p[:, k - 1] + (1.0 - (-1.0) ** k) / k
        q[:, k] = p[:, k - 1] + z * q[:, k - 1]
    return p, q


def locate(data: CurvedData, points: np.ndarray, tolerance: float = ON_BOUNDARY) -> tuple[np.ndarray, np.ndarray]:
    """The element each point (P, 2) lies on (-1: none) and its xi, within ``tolerance`` (< 1)
    half-chords of the element (the nearest element wins)."""
    zeta = points[:, 0] + 1j * points[:, 1]
    z = _local(data, zeta)
    return _boundary_pairs(data, z, np.nonzero(np.abs(z) < NEAR), tolerance)


def boundary_stresses(data: CurvedData, element: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], (3, P), at boundary points (element, xi): sigma_nn and
    sigma_sn from the traction, sigma_ss = (2 G eps_ss + nu sigma_nn) / (1 - nu) from the tangential
    strain eps_ss = Re(dD/ds e^{-i theta}) (plane strain)."""
    _, dpoint, _, ddisp, traction = data.at(np.asarray(xi, dtype=float), np.asarray(element))
    jac = np.abs(dpoint)
    back = np.conj(dpoint) / jac
    local = traction * back  # (sigma_sn, -sigma_nn): outward normal n = -i e^{i theta}
    strain = (ddisp / jac * back).real
    return surface_stresses(local, strain, back, data.shear, data.poisson)


def stresses(
    mesh: BoundaryMesh, u: np.ndarray, t: np.ndarray, shear: float, poisson: float, points, located=None
) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], (3, P), at points (P, 2) [length] inside or on the boundary.

    ``u`` [length], ``t`` [stress] the nodal boundary values (N, 2), G [stress]. ``located``: the
    boundary points' (element, xi) when the caller knows them ((P,) each, element -1 elsewhere);
    other points are boundary points within :data:`ON_BOUNDARY` half-chords of an element.
    """
    points = np.atleast_2d(np.asarray(points, dtype=float))
    data = curved_data(mesh, np.asarray(u, dtype=float), np.asarray(t, dtype=float), shear, poisson)
    element, xi = np.full(points.shape[0], -1), np.zeros(points.shape[0])
    if located is not None:
        element, xi = np.array(located[0], dtype=int), np.array(located[1], dtype=float)
    out = np.empty((3, points.shape[0]))
    rest = np.flatnonzero(element < 0)
    partner = mirror_partner(data) if rest.size > 1 else None
    half, mirror = _mirror_pairs(points[rest]) if partner is not None else (np.empty(0, int), np.empty(0, int))
    if half.size:  # the mirror pairs share their far sums' kernel (:func:`_far_sum`)
        h, m = rest[half], rest[mirror]
        both, element[h], xi[h] = _evaluate(data, points[h, 0] + 1j * points[h, 1], partner=partner)
        out[:, h], out[:, m] = both[0], both[1]
        found = element[h] >= 0  # on the boundary, or its mirror is: both evaluated alone below
        element[m[found]] = -1
        rest = np.setdiff1d(rest, np.concatenate([h[~found], m[~found]]))
        element[h[found]] = -1
    out[:, rest], element[rest], xi[rest] = _evaluate(data, points[rest, 0] + 1j * points[rest, 1])
    on = element >= 0
    out[:, on] = boundary_stresses(data, element[on], xi[on])
    return out


def _mirror_pairs(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices (i, j) of the points with x > 0 whose mirror image in x = 0 is also a point, within
    1e-12 of the points' extent (binned; a pair that rounding puts in two bins stays unpaired)."""
    scale = 1e-12 * float(np.abs(points).max())
    key = np.round(points / scale).astype(np.int64)
    n = key.shape[0]
    # one integer per bin, for the points' bins and their mirrors' together (row ranks: no overflow)
    _, rank = np.unique(np.concatenate([key, key * np.array([-1, 1])]), axis=0, return_inverse=True)
    rank = rank.reshape(-1)
    code, mirror_code = rank[:n], rank[n:]
    order = np.argsort(code)
    found = np.clip(np.searchsorted(code[order], mirror_code), 0, code.size - 1)
    j = order[found]
    pair = (code[j] == mirror_code) & (key[:, 0] > 0)
    i = np.flatnonzero(pair)
    return i, j[i]
