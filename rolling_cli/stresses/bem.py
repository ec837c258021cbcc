"""Stresses inside a BEM body from its boundary solution (the Somigliana stress identity).

Input: a :class:`~rolling_cli.influence.bem.mesh.BoundaryMesh` of straight
quadratic elements (domain on the left of the traversal) and the nodal
displacements u and tractions t on every boundary node, however they were
obtained. Output: sigma_xx, sigma_yy, sigma_xy in the mesh frame.

Complex form (Muskhelishvili). With zeta = x + i y, D = u_x + i u_y,
tau = t_x + i t_y, kappa = 3 - 4 nu and, along the boundary (arclength s, unit
tangent e^{i theta}),

    g(s) = (2 G dD/ds + i tau) / (1 + kappa)

the Kolosov potentials' boundary values are phi'(t) = g e^{-i theta}, and
Cauchy's formula over the closed boundary, integrated by parts where a term
would need the traction resultant, gives the Somigliana identity as

    sigma_xx + sigma_yy = 4 Re phi'(zeta),  phi'(zeta) = 1/(2 pi i) int g / (t - zeta) ds
    sigma_yy - sigma_xx + 2 i sigma_xy
        = 1/(pi i) [ int (-i conj(tau) - conj(g)) / (t - zeta) ds
                     - int conj(t - zeta) g / (t - zeta)^2 ds ]

a layer of point forces (tau) and of dislocations (dD/ds): the stress
boundary integral equation written with the tangential derivative of the
displacement, so it needs no traction resultant and no strongly singular
double layer. On a straight element with polynomial g and tau every integral
is elementary, ``int f(xi)/(zeta_l - xi) d xi = f(zeta_l) L - 2 (f_1 + f_2 zeta_l)``
with L = log((zeta_l + 1)/(zeta_l - 1)) and zeta_l the point in the element's
local coordinate, and its zeta_l-derivative. The elements are grouped by the
straight side they lie on and each side is integrated at once in its own
coordinate (the point at s + i d, d > 0 inside), by the Cauchy-integral
engine the half-plane uses (:mod:`.cauchy`). The identity is thus exact for
the interpolated boundary data at any distance from the boundary, which is
the near-boundary treatment (no quadrature to grade, no singular subtraction
needed); rounding grows only like (element length / distance) near an
element's end points.

On the boundary itself the stress follows from the traction and the
tangential strain (:func:`boundary_stresses`): sigma_nn and sigma_sn are the
traction, and sigma_ss = (2 G eps_ss + nu sigma_nn) / (1 - nu).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..influence.bem.elements import lagrange_coefficients
from ..influence.bem.mesh import BoundaryMesh
from .cauchy import line_integrals

#: A point closer to an element than this fraction of its length is a boundary point.
ON_BOUNDARY = 1e-9


@dataclass(frozen=True)
class BoundaryDensities:
    """Per-element polynomial data in the local coordinate xi in [-1, 1].

    ``mid`` (E,) complex mid-points and ``turn`` (E,) unit tangents e^{i theta};
    ``half`` (E,) half-lengths [length]; ``traction`` (E, 3) and ``g`` (E, 3)
    complex monomial coefficients of tau(xi) [stress] and g(xi) [stress];
    ``strain`` (E, 2) coefficients of dD/ds [-]; ``shear`` G [stress] and
    ``poisson`` nu of the body.
    """

    mid: np.ndarray
    turn: np.ndarray
    half: np.ndarray
    traction: np.ndarray
    g: np.ndarray
    strain: np.ndarray
    shear: float
    poisson: float


def densities(mesh: BoundaryMesh, u: np.ndarray, t: np.ndarray, shear: float, poisson: float) -> BoundaryDensities:
    """Element data of the boundary solution: ``u``, ``t`` (N, 2) nodal [length], [stress]; G [stress]."""
    p0, mid, p2 = mesh.geometry[:, 0], mesh.geometry[:, 1], mesh.geometry[:, 2]
    chord = p2 - p0
    length = np.hypot(chord[:, 0], chord[:, 1])
    if not np.allclose(mid, 0.5 * (p0 + p2), atol=1e-12 * length.max()):
        raise NotImplementedError("interior stresses are implemented for straight elements")
    coeff = lagrange_coefficients(mesh.local)  # (E, k, m)
    conn = mesh.connectivity
    disp = np.einsum("ekm,ek->em", coeff, u[conn, 0] + 1j * u[conn, 1])
    traction = np.einsum("ekm,ek->em", coeff, t[conn, 0] + 1j * t[conn, 1])
    half = 0.5 * length
    strain = np.stack([disp[:, 1], 2.0 * disp[:, 2]], axis=1) / half[:, None]  # dD/ds = (d1 + 2 d2 xi) / half
    kappa = 3.0 - 4.0 * poisson
    g = 1j * traction
    g[:, :2] += 2.0 * shear * strain
    g /= 1.0 + kappa
    return BoundaryDensities(
        mid=(p0[:, 0] + p2[:, 0]) * 0.5 + 0.5j * (p0[:, 1] + p2[:, 1]),
        turn=(chord[:, 0] + 1j * chord[:, 1]) / length,
        half=half,
        traction=traction,
        g=g,
        strain=strain,
        shear=shear,
        poisson=poisson,
    )


def interior_stresses(data: BoundaryDensities, points: np.ndarray) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], shape (3, P), at interior points (P, 2) [length]."""
    points = np.asarray(points, dtype=float)
    zeta = points[:, 0] + 1j * points[:, 1]
    centre = zeta.mean()
    phi = np.zeros(zeta.size, dtype=complex)  # phi'(zeta) times 2 pi i
    second = np.zeros(zeta.size, dtype=complex)  # (sigma_yy - sigma_xx + 2 i sigma_xy) times pi i
    h = -1j * np.conj(data.traction) - np.conj(data.g)
    for members in lines(data):
        turn = data.turn[members[0]]
        back = np.conj(turn)
        origin = data.mid[members[0]] + turn * ((centre - data.mid[members[0]]) * back).real  # centre's foot
        omega = (zeta - origin) * back  # s + i d, d > 0 inside (the domain lies left of the traversal)
        mid = ((data.mid[members] - origin) * back).real
        half = data.half[members]
        scale = half[:, None] ** -np.arange(3)[None, :]  # xi = (s - mid)/half
        coeff = np.stack([data.g[members] * scale, h[members] * scale])
        A, B = line_integrals(omega.real, omega.imag, mid - half, mid + half, coeff)
        phi -= back * A[:, 0]
        second -= back * A[:, 1] + back**3 * (2j * omega.imag * B[:, 0] - A[:, 0])
    trace = 4.0 * (phi / (2j * np.pi)).real  # sigma_xx + sigma_yy
    second /= 1j * np.pi
    return np.stack([0.5 * (trace - second.real), 0.5 * (trace + second.real), 0.5 * second.imag])


def lines(data: BoundaryDensities) -> list[np.ndarray]:
    """The elements grouped by the straight line they lie on (same direction and offset)."""
    size = float(np.abs(data.mid - data.mid.mean()).max() + data.half.max())
    offset = (data.mid * np.conj(data.turn)).imag / size  # signed distance of the line from the origin
    key = np.round(np.stack([data.turn.real, data.turn.imag, offset], axis=1), 9)
    _, group = np.unique(key, axis=0, return_inverse=True)
    return [np.flatnonzero(group.ravel() == k) for k in range(group.max() + 1)]


def boundary_stresses(data: BoundaryDensities, element: np.ndarray, xi: np.ndarray) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], shape (3, P), at boundary points given by element and local xi.

    From the interpolated traction (sigma_nn, sigma_sn) and tangential strain
    eps_ss = Re(dD/ds e^{-i theta}): sigma_ss = (2 G eps_ss + nu sigma_nn) / (1 - nu).
    """
    xi = np.asarray(xi, dtype=float)
    back = np.conj(data.turn[element])
    coeff = data.traction[element]
    local = ((coeff[:, 2] * xi + coeff[:, 1]) * xi + coeff[:, 0]) * back  # tau in the (s, n) frame
    strain = ((data.strain[element, 1] * xi + data.strain[element, 0]) * back).real
    return surface_stresses(local, strain, back, data.shear, data.poisson)


def surface_stresses(
    local: np.ndarray, strain: np.ndarray, back: np.ndarray, shear: float, poisson: float
) -> np.ndarray:
    """sigma_xx, sigma_yy, sigma_xy [stress] on the boundary from the traction ``local`` = sigma_sn -
    i sigma_nn in the (s, n) frame [stress], the tangential strain ``strain`` [-] and ``back`` =
    e^{-i theta} (the tangent's angle): sigma_ss = (2 G eps_ss + nu sigma_nn) / (1 - nu), shear G."""
    sigma_sn, sigma_nn = local.real, -local.imag  # outward normal n = -i e^{i theta}
    sigma_ss = (2.0 * shear * strain + poisson * sigma_nn) / (1.0 - poisson)
    c, s = back.real, -back.imag  # tangent (c, s), outward normal (s, -c)
    sxx = sigma_ss * c * c + sigma_nn * s * s + 2.0 * sigma_sn * c * s
    syy = sigma_ss * s * s + sigma_nn * c * c - 2.0 * sigma_sn * c * s
    sxy = (sigma_ss - sigma_nn) * c * s + sigma_sn * (s * s - c * c)
    return np.stack([sxx, syy, sxy])


def locate(data: BoundaryDensities, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Boundary points among ``points`` (P, 2): the element each lies on (-1: interior) and its local xi.

    A point is on the boundary when it lies within :data:`ON_BOUNDARY` element
    lengths of an element's line and between the element's ends.
    """
    zeta = points[:, 0] + 1j * points[:, 1]
    element = np.full(zeta.size, -1)
    xi = np.zeros(zeta.size)
    for members in lines(data):
        back = np.conj(data.turn[members[0]])
        origin = data.mid[members[0]]
        omega = (zeta - origin) * back
        mid = ((data.mid[members] - origin) * back).real
        order = np.argsort(mid)
        mid, half, members = mid[order], data.half[members][order], members[order]
        k = np.clip(np.searchsorted(mid - half, omega.real, side="right") - 1, 0, members.size - 1)
        local = (omega.real - mid[k]) / half[k]
        on = (np.abs(omega.imag) <= 2.0 * ON_BOUNDARY * half[k]) & (np.abs(local) <= 1.0 + ON_BOUNDARY)
        element[on] = members[k[on]]
        xi[on] = np.clip(local[on], -1.0, 1.0)
    return element, xi


def stresses(mesh: BoundaryMesh, u: np.ndarray, t: np.ndarray, shear: float, poisson: float, points) -> np.ndarray:
    """(sigma_xx, sigma_yy, sigma_xy) [stress], shape (3, P), at points (P, 2) inside or on the boundary.

    ``u`` [length] and ``t`` [stress] are the nodal boundary displacements and
    tractions (N, 2), ``shear`` G [stress]. Boundary points get the recovered
    boundary stress, interior points the Somigliana identity.
    """
    points = np.atleast_2d(np.asarray(points, dtype=float))
    data = densities(mesh, np.asarray(u, dtype=float), np.asarray(t, dtype=float), shear, poisson)
    element, xi = locate(data, points)
    on = element >= 0
    out = np.empty((3, points.shape[0]))
    if np.any(on):
        out[:, on] = boundary_stresses(data, element[on], xi[on])
    if np.any(~on):
        out[:, ~on] = interior_stresses(data, points[~on])
    return out
