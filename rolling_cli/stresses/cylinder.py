"""The stresses of a finite cylinder (``shape = "cylinder"``) on its own curvilinear grid.

The body is the BEM annulus of :mod:`rolling_cli.influence.bem.cylinder`
(frame: centre at (0, -R), contact at the top around the origin, the body
below). Its field is reported as the half-space's, in the body's own frame
with the origin at the contact centre, but curvilinear: x is the arc length
s along the outer circle (the contact grid's coordinate, so x of the field,
of the surface samples and of the tractions agree) and z >= 0 the radial
depth below the outer circle, the point at polar angle theta = s / R and
radius R - z. The components are those along the circle and the radius:
sigma_xx the hoop stress sigma_ss, sigma_zz the radial stress sigma_rr and
tau_xz the shear in the (s, -r) frame, so on the surface sigma_zz = p_n and
tau_xz = -p_t (body A; +p_t on B), as for a half-space, to which the frame
reduces as R grows. The field reaches the bore at z = R - r_i at most; the
bore's row and the surface's are boundary points (stress from the traction
and the tangential strain). The bore is the bond line (to the shaft or the
core): ``bond_x`` is its nodes' polar angle times R (the outer arc length at
the same angle, whole circle), ``bond_sigma_zz`` the radial and ``bond_tau_xz``
the shear stress there, ``bond_weights`` the integrals of the nodal shape
functions along the bore [length] (sum w sigma_rr is the integral of the
radial stress along the bore, per unit axial length).
"""

from __future__ import annotations

import numpy as np

from . import curved


def grid_points(x: np.ndarray, z: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Mesh-frame points (nz * nx, 2) [length] of the curvilinear grid x (nx,) (arc length) and
    z (nz,) (depth) on the outer circle of ``radius``, row by row, and their polar angles (nz * nx,)."""
    angles, radii = np.meshgrid(np.asarray(x, dtype=float) / radius, radius - np.asarray(z, dtype=float))
    theta, r = angles.ravel(), radii.ravel()
    return np.stack([r * np.sin(theta), -radius + r * np.cos(theta)], axis=1), theta


def polar_components(sxx, syy, sxy, theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sigma_ss, sigma_rr, tau_xz) [stress] of mesh-frame components at polar angles ``theta``:
    e_s = (cos, -sin) along increasing s, e_r = (sin, cos) outward, z along -e_r."""
    c, s = np.cos(theta), np.sin(theta)
    sigma_ss = c * c * sxx - 2.0 * c * s * sxy + s * s * syy
    sigma_rr = s * s * sxx + 2.0 * c * s * sxy + c * c * syy
    sigma_sr = c * s * (sxx - syy) + (c * c - s * s) * sxy
    return sigma_ss, sigma_rr, -sigma_sr


def field(mesh, u, t, shear: float, poisson: float, radius: float, x, z, samples, bore_depth: float):
    """The (nz, nx) components (sigma_xx, sigma_zz, tau_xz) [stress] on the grid x (arc length), z
    (depth) and the surface samples' (each (n,)), from the annulus' boundary solution (mesh, u, t).
    The surface and the bore are boundary points placed on their elements by :func:`on_circle`."""
    points, theta = grid_points(x, z, radius)
    surface, theta_s = grid_points(samples, np.zeros(1), radius)
    rows = np.repeat(np.asarray(z, dtype=float), np.size(x))
    theta_all = np.concatenate([theta, theta_s])
    element = np.full(theta_all.size, -1)
    xi = np.zeros(theta_all.size)
    scale = float(np.min(mesh.lengths))
    top = np.concatenate([rows <= 1e-12 * scale, np.ones(theta_s.size, bool)])
    bottom = np.concatenate([rows >= bore_depth - 1e-12 * scale, np.zeros(theta_s.size, bool)])
    for where, bore in ((top, False), (bottom, True)):
        element[where], xi[where] = on_circle(mesh, theta_all[where], radius, bore)
    found = curved.stresses(mesh, u, t, shear, poisson, np.concatenate([points, surface]), located=(element, xi))
    polar = polar_components(found[0], found[1], found[2], theta_all)
    n = points.shape[0]
    shape = (np.size(z), np.size(x))
    return tuple(c[:n].reshape(shape) for c in polar), tuple(c[n:] for c in polar)


def on_circle(mesh, theta: np.ndarray, radius: float, bore: bool) -> tuple[np.ndarray, np.ndarray]:
    """The outer circle's (or the bore's) element at each polar angle ``theta`` [rad] and its local xi,
    linear in the angle between the element's end points: on the contact elements, whose ends lie at
    the grid's edges / R, this is the grid's own local coordinate, so a contact node's arc length gives
    that node (its traction exactly)."""
    ends = mesh.geometry[:, [0, 2]] - np.array([0.0, -radius])  # (E, 2 ends, 2)
    angles = np.arctan2(ends[..., 0], ends[..., 1])
    candidates = np.flatnonzero(mesh.fixed[mesh.connectivity].all(axis=1) == bore)
    start = _wrap(angles[candidates, 0][None, :] - theta[:, None])  # (P, e), each end relative to theta
    end = _wrap(angles[candidates, 1][None, :] - theta[:, None])
    inside = (start * end <= 0.0) & (np.abs(end - start) < np.pi)
    k = np.argmax(inside, axis=1)
    rows = np.arange(theta.size)
    xi = -1.0 - 2.0 * start[rows, k] / (end[rows, k] - start[rows, k])
    return candidates[k], np.clip(xi, -1.0, 1.0)


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def bond_line(mesh, t: np.ndarray, radius: float) -> dict[str, np.ndarray]:
    """The bore's radial and shear stresses at its nodes (module docstring), in increasing angle."""
    from ..influence.bem.elements import lagrange_coefficients

    nodes = np.flatnonzero(mesh.fixed)
    centre = np.array([0.0, -radius])
    rel = mesh.nodes[nodes] - centre
    theta = np.arctan2(rel[:, 0], rel[:, 1])
    order = np.argsort(theta)
    nodes, theta = nodes[order], theta[order]
    e_r = np.stack([np.sin(theta), np.cos(theta)], axis=1)
    e_s = np.stack([np.cos(theta), -np.sin(theta)], axis=1)
    traction = t[nodes]  # outward normal of the body at the bore: -e_r
    on_bore = mesh.fixed[mesh.connectivity].all(axis=1)
    coeff = lagrange_coefficients(mesh.local[on_bore])
    from ..influence.bem.elements import gauss, map_points

    xi, w = gauss(6)
    _, _, jac = map_points(mesh.geometry[on_bore], xi)
    shape = np.einsum("gm,ekm->egk", xi[:, None] ** np.arange(3), coeff)
    per_node = np.einsum("g,eg,egk->ek", w, jac, shape)
    weights = np.zeros(mesh.size)
    np.add.at(weights, mesh.connectivity[on_bore], per_node)
    return {
        "bond_x": radius * theta,
        "bond_sigma_zz": -np.einsum("nd,nd->n", traction, e_r),
        "bond_tau_xz": np.einsum("nd,nd->n", traction, e_s),
        "bond_weights": weights[nodes],
    }
