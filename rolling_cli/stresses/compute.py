"""The stress fields of the requested bodies of a solved case: :func:`compute_stresses`.

Each body is reported in its own frame: x the global rolling coordinate, z >= 0
the depth into that body (its mirror frame, as the influence models describe
it). tau_xz is the shear stress in that frame, so on the surface
tau_xz(x, 0) = -(tangential traction on the body along +x):
-p_t for body A and +p_t for body B (p_t the traction on A, B carries -p_t);
in global axes (y up) that is sigma_xy for A and -sigma_xy for B. Below the
surface, the integral of tau_xz along x over a whole line z = const equals its
surface integral, -Q for A and +Q for B (Q the tangential force on A).
Compression is negative.

Models: the closed-form half-plane (:mod:`.halfplane`) where the case's
influence model resolves to "half-plane", the BEM body's Somigliana identity
(:mod:`.bem`) on the full boundary solution of the influence model's own BEM
body (:func:`rolling_cli.influence.build.boundary_solution`: the half-space
block with its far field, or the layer) where it resolves to "bem"; a finite
cylinder's annulus on its curved elements (:mod:`.curved`), on its own
curvilinear grid (x the arc length, z the radial depth, down to the bore at
most: :mod:`.cylinder`); rigid bodies have no field. The grid: nx points over the potential contact zone plus a
margin of :data:`MARGIN` of its half-width on each side (inside a layer's top
face), nz depths from the surface to ``depth`` a (a layer: to its bond line at
most, which is then the last row).

The surface: besides the field's first row (z = 0), the stresses at the
surface samples, the contact nodes and the located kinks (contact edges and
stick/slip boundaries), where the surface stresses peak in square-root cusps.
A half-plane's surface (that row and the samples) comes from the continuous
traction of :mod:`.surface`, not from the discontinuous element interpolation,
whose surface sigma_xx is log-singular at the element ends.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..influence import build
from ..influence.choice import influence_model
from ..model import materials
from . import halfplane, invariants, surface

#: Field margin beyond the potential contact zone, as a fraction of its half-width.
MARGIN = 0.25
#: A layer's field stays inside this fraction of its free length beyond the zone.
LAYER_MARGIN = 0.5
#: A block's field stays above this fraction of its depth.
BLOCK_DEPTH = 0.5


@dataclass
class BodyStresses:
    """One body's stresses: ``arrays`` by dataset name [length] or [stress], ``attributes`` scalars.

    Arrays: ``x`` (nx,), ``z`` (nz,); (nz, nx) fields ``sigma_xx``, ``sigma_zz``,
    ``tau_xz``, ``sigma_yy``, ``von_mises``, ``tresca``, ``sigma_1``,
    ``sigma_2``, ``sigma_3``; ``tau_xz_range`` (nz,); ``surface_x`` (the
    surface samples: the contact nodes and the located contact edges and
    stick/slip boundaries, increasing), ``surface_sigma_xx``,
    ``surface_sigma_zz``, ``surface_tau_xz`` there; for a layer ``bond_x``,
    ``bond_sigma_zz``, ``bond_tau_xz`` on the bond-line nodes.
    """

    label: str
    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    attributes: dict = field(default_factory=dict)


def model_name(case, label: str) -> str:
    """The stress model of body ``label``: "half-plane", "BEM block", "BEM layer", "BEM cylinder" or "rigid"."""
    body = getattr(case.bodies, label)
    if body.rigid:
        return "rigid"
    if body.finite:
        return "BEM cylinder"
    if influence_model(case)[0] == "half-plane":
        return "half-plane"
    return "BEM layer" if body.kind == "layered" else "BEM block"


def field_grid(case, the_plan, label: str) -> tuple[np.ndarray, np.ndarray]:
    """The field's x (nx,) and z (nz,) [length] for body ``label`` (module docstring)."""
    request = case.stresses
    nx, nz = request.points
    grid = the_plan.grid
    body = getattr(case.bodies, label)
    reach = (1.0 + MARGIN) * grid.half_width
    depth = request.depth * the_plan.half_width
    if body.finite:  # arc length and radial depth (:mod:`.cylinder`), down to the bore at most
        return grid.centre + np.linspace(-reach, reach, nx), np.linspace(0.0, min(depth, body.body_shape.thickness), nz)
    if body.kind == "layered":
        thickness = float(body.layer_thickness)
        reach = min(reach, grid.half_width + LAYER_MARGIN * case.discretization.layer_length * thickness)
        depth = min(depth, thickness)
    elif influence_model(case)[0] == "bem":
        depth = min(depth, BLOCK_DEPTH * case.discretization.block_depth * the_plan.half_width)
    return grid.centre + np.linspace(-reach, reach, nx), np.linspace(0.0, depth, nz)


def compute_stresses(case, the_plan, p_n: np.ndarray, p_t: np.ndarray, kinks=None) -> dict[str, BodyStresses]:
    """Fields of the bodies in ``case.stresses.bodies`` (rigid ones skipped) from the nodal tractions.

    ``p_n`` (<= 0 in compression) and ``p_t`` (on body A along +x) [stress] on
    the plan's contact grid. ``kinks``: (positions [length], kinds) of the
    solution's contact edges and stick/slip boundaries
    (:func:`rolling_cli.adapt.kinks.locate_kinks`); without them the contact
    edges are located from p_n alone. They are surface samples (where the
    surface stresses have their square-root cusps) and, for half-planes, the
    ends of the surface's traction representation (:mod:`.surface`).
    Half-plane bodies share one evaluation of the integrals (they carry p_n
    and +-p_t); identical BEM bodies share one factorised boundary system.
    """
    labels = [label for label in case.stresses.bodies if model_name(case, label) != "rigid"]
    if not labels:
        return {}
    samples, edges, boundaries = surface_samples(the_plan.grid, p_n, kinks)
    if influence_model(case)[0] == "half-plane":
        components = _halfplane(case, the_plan, p_n, p_t, labels, samples, (edges, boundaries))
    else:
        components = _bem(case, the_plan, p_n, p_t, labels, samples)
    out = {}
    for label in labels:
        body = getattr(case.bodies, label)
        arrays, (sxx, szz, txz) = components[label]
        arrays.update(derived(sxx, szz, txz, float(body.poisson)))
        attributes = {"body": label, "model": model_name(case, label), "poisson": float(body.poisson)}
        if body.finite:  # the bore, bonded to the shaft or the core
            attributes["bond_depth"] = float(body.body_shape.thickness)
        elif body.kind == "layered":
            attributes["bond_depth"] = float(body.layer_thickness)
        out[label] = BodyStresses(label, arrays, attributes)
    return out


def surface_samples(grid, p_n: np.ndarray, kinks=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The surface samples [length] (contact nodes and kinks inside the zone, increasing), the contact
    edges and the stick/slip boundaries [length]."""
    from ..adapt import kinks as locate  # numpy only

    if kinks is None:
        positions = edges = locate.contact_edges(grid.x, np.asarray(p_n, dtype=float))
        boundaries = np.empty(0)
    else:
        positions, kinds = (np.asarray(v) for v in kinks)
        edges = positions[kinds == locate.CONTACT_EDGE].astype(float)
        boundaries = positions[kinds == locate.STICK_SLIP].astype(float)
    positions = np.asarray(positions, dtype=float)
    inside = (positions > grid.edges[0]) & (positions < grid.edges[-1])
    return np.union1d(grid.x, positions[inside]), edges, boundaries


def _halfplane(case, the_plan, p_n, p_t, labels, samples, kinks) -> dict:
    grid = the_plan.grid
    signs = [1.0 if label == "A" else -1.0 for label in labels]  # B carries -p_t
    x, z = field_grid(case, the_plan, labels[0])  # the same grid for every half-plane body
    deep = z > 0.0  # the surface row from the continuous traction (:mod:`.surface`), the rest exact per element
    below = halfplane.both_signs(grid, p_n, p_t, x[None, :], z[deep, None], signs)
    edges, boundaries = kinks
    top = surface.both_signs(grid, p_n, p_t, x, edges, signs, boundaries)
    at_samples = surface.both_signs(grid, p_n, p_t, samples, edges, signs, boundaries)
    out = {}
    for label, deep_rows, row, sample in zip(labels, below, top, at_samples, strict=True):
        components = []
        for deeper, on_top in zip(deep_rows, row, strict=True):
            full = np.empty((z.size, x.size))
            full[deep], full[~deep] = deeper, on_top
            components.append(full)
        arrays = {"x": x, "z": z, **_surface_arrays(samples, *sample)}
        out[label] = (arrays, tuple(components))
    return out


def _surface_arrays(samples, sigma_xx, sigma_zz, tau_xz) -> dict[str, np.ndarray]:
    return {"surface_x": samples, "surface_sigma_xx": sigma_xx, "surface_sigma_zz": sigma_zz, "surface_tau_xz": tau_xz}


def _bem(case, the_plan, p_n, p_t, labels, samples) -> dict:
    from . import bem  # the BEM package only for BEM bodies (start-up)

    out = {}
    solutions = _boundary_solutions(case, the_plan, p_n, p_t, labels)
    for label in labels:
        body = getattr(case.bodies, label)
        mesh, u, t = solutions[label]
        shear, nu = materials.shear_modulus(float(body.young), float(body.poisson)), float(body.poisson)
        x, z = field_grid(case, the_plan, label)
        if body.finite:
            out[label] = _cylinder(body, mesh, u, t, shear, nu, x, z, samples)
            continue
        X, Z = np.meshgrid(x, z)
        points = np.concatenate([np.stack([X.ravel(), -Z.ravel()], axis=1), np.stack([samples, 0.0 * samples], axis=1)])
        s = bem.stresses(mesh, u, t, shear, nu, points)  # the field, then the surface samples
        field, surface_values = s[:, : X.size], s[:, X.size :]
        arrays = {"x": x, "z": z, **_surface_arrays(samples, surface_values[0], surface_values[1], -surface_values[2])}
        if body.kind == "layered":
            arrays.update(bond_line(mesh, t))
        sxx, syy, sxy = (component.reshape(X.shape) for component in field)
        out[label] = (arrays, (sxx, syy, -sxy))  # the mesh frame has y = -z
    return out


def _cylinder(body, mesh, u, t, shear, nu, x, z, samples) -> tuple:
    """A finite cylinder's arrays and (sigma_xx, sigma_zz, tau_xz) on its curvilinear grid (:mod:`.cylinder`)."""
    from . import cylinder

    shape = body.body_shape
    components, on_surface = cylinder.field(mesh, u, t, shear, nu, shape.radius, x, z, samples, shape.thickness)
    arrays = {"x": x, "z": z, **_surface_arrays(samples, *on_surface), **cylinder.bond_line(mesh, t, shape.radius)}
    return arrays, components


def derived(sigma_xx, sigma_zz, tau_xz, poisson: float) -> dict[str, np.ndarray]:
    """The components with sigma_yy, the principal stresses, von Mises, Tresca and the tau_xz range."""
    principal = invariants.principal(sigma_xx, sigma_zz, tau_xz, poisson)
    return {
        "sigma_xx": sigma_xx,
        "sigma_zz": sigma_zz,
        "tau_xz": tau_xz,
        "sigma_yy": invariants.out_of_plane(sigma_xx, sigma_zz, poisson),
        "von_mises": invariants.von_mises(sigma_xx, sigma_zz, tau_xz, poisson),
        "tresca": invariants.tresca(principal),
        "sigma_1": principal[0],
        "sigma_2": principal[1],
        "sigma_3": principal[2],
        "tau_xz_range": invariants.orthogonal_shear_range(tau_xz),
    }


def bond_line(mesh, t: np.ndarray) -> dict[str, np.ndarray]:
    """Normal and shear stress along a layer's bonded bottom (its fixed nodes), with integration weights.

    The layer's outward normal there is +z, so sigma_zz = -t_y and
    tau_xz = t_x of the BEM traction (mesh frame, y up). Returns the nodes'
    ``bond_x`` [length], ``bond_sigma_zz``, ``bond_tau_xz`` [stress] in
    increasing x and ``bond_weights`` [length] (integrals of the nodal shape
    functions along the bond, so sum(w sigma) is the force per unit length).
    """
    from ..influence.bem.elements import lagrange_coefficients

    nodes = np.flatnonzero(mesh.fixed)
    order = np.argsort(mesh.nodes[nodes, 0])
    nodes = nodes[order]
    weights = np.zeros(mesh.size)
    on_bond = mesh.fixed[mesh.connectivity].all(axis=1)
    coeff = lagrange_coefficients(mesh.local[on_bond])  # (e, k, m)
    moments = np.array([2.0, 0.0, 2.0 / 3.0])
    per_node = 0.5 * mesh.lengths[on_bond, None] * (coeff @ moments)
    np.add.at(weights, mesh.connectivity[on_bond], per_node)
    return {
        "bond_x": mesh.nodes[nodes, 0],
        "bond_sigma_zz": -t[nodes, 1],
        "bond_tau_xz": t[nodes, 0],
        "bond_weights": weights[nodes],
    }


def _boundary_solutions(case, the_plan, p_n, p_t, labels) -> dict[str, tuple]:
    """(mesh, u, t) of the BEM bodies ``labels``: the influence model's own boundary solution."""
    return {label: build.boundary_solution(case, the_plan, label, p_n, p_t) for label in labels}
