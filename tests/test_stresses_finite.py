"""Subsurface stresses of finite cylinders (issue 21 item 5): the Somigliana identity on curved elements.

References: the straight patch test (the curved integration with no curvature), Michell's series for the
annulus on a rigid shaft (exact boundary data, then the BEM's own boundary solution), the closed-form
half-plane (R/a = 1000), the applied tractions and the equilibrium of the bore, and the pipeline.
"""

import numpy as np
import pytest
from test_stresses_bem import boundary_data, kelvin_state, linear_state, node_normals

from helpers import case_dict, solve
from rolling_cli import pipeline, read_result, write_result
from rolling_cli.adapt.kinks import locate_kinks
from rolling_cli.case import load_case
from rolling_cli.influence import build
from rolling_cli.influence.bem.annulus_solution import annulus_solution, prepare_annulus
from rolling_cli.influence.bem.elements import map_points
from rolling_cli.influence.bem.mesh import BoundaryMesh, rectangle
from rolling_cli.model.grid import ContactGrid
from rolling_cli.references import hertz
from rolling_cli.references.annulus_field import amplitudes, annulus_field
from rolling_cli.stresses import bem, compute, curved, cylinder, halfplane

G, NU = 80.0, 0.3


def test_straight_elements_reproduce_the_patch_test_to_round_off():
    """With no curvature (beta = 0) the curved integration must reproduce a stress varying linearly in y
    exactly (quadratic u, linear t), 1e-3 and 1e-6 element lengths from the boundary included. Bound:
    the far rule's relative error rho^(-12) < 2e-11 (module docstring) times the ~10 elements that use
    it at comparable weight, plus the near end's round-off amplification (1e3 eps): 1e-9 of the scale."""
    h = 0.2
    mesh = rectangle(3.0, 2.0, np.linspace(-1.0, 1.0, 11), largest=0.5, kind="mixed")
    points = np.array(
        [[0.0, -1.0], [0.1, -1e-3 * h], [0.1, -1e-6 * h], [0.2 + 1e-3 * h, -1e-3 * h], [2.999, -1.5], [0.3, 0.0],
         [-2.0, -2.0 + 1e-3 * h], [3.0, -0.5], [0.13, -2.0], [2.9999, -1e-4]]
    )  # fmt: skip
    u, t = boundary_data(mesh, linear_state)
    expected = linear_state(points)[0]
    assert curved.stresses(mesh, u, t, G, NU, points) == pytest.approx(expected, abs=1e-9 * np.abs(expected).max())


def test_straight_elements_match_the_closed_form_identity_near_the_boundary():
    """Kelvin's point force outside a straight-sided mesh: the curved integration (beta = 0: product
    integration near, Gauss far) against :mod:`rolling_cli.stresses.bem`'s closed form for the same
    interpolated data, from 1e-2 down to 1e-9 element lengths (the latter boundary points in both).
    Bound: the far rules' 4e-11 plus the closed form's own rounding near element ends (~1e-12): 1e-10
    of the scale (measured 1.3e-11)."""
    mesh = rectangle(3.0, 2.0, np.linspace(-1.0, 1.0, 11), largest=0.5, kind="mixed")
    u, t = boundary_data(mesh, kelvin_state(np.array([0.3, 0.5]), np.array([1.0, -0.4])))
    x = np.array([0.05, 0.1, 0.13, 0.199, 0.7, -2.2])
    points = np.concatenate([np.column_stack([x, np.full_like(x, -d * 0.2)]) for d in (1e-2, 1e-4, 1e-7, 1e-9)])
    expected = bem.stresses(mesh, u, t, G, NU, points)
    found = curved.stresses(mesh, u, t, G, NU, points)
    assert np.abs(found - expected).max() <= 1e-10 * np.abs(expected).max()


def _brute_force(data, zeta):
    """The identity at one interior point by composite 16-point Gauss on every element, panels halving
    towards the point's foot (down to 1e-9 of the element): a reference for the near integration."""
    x16, w16 = np.polynomial.legendre.leggauss(16)
    kappa = 3.0 - 4.0 * data.poisson
    first = second = 0j
    for e in range(data.mid.size):
        foot = float(
            np.clip(
                curved._foot(data.beta[e : e + 1], (zeta - data.mid[e : e + 1]) / data.chord[e : e + 1])[0][0], -1, 1
            )
        )
        cuts = [foot] + [foot + side * abs(side - foot) * 0.5**k for side in (-1.0, 1.0) for k in range(31)]
        edges = np.unique(np.clip(cuts, -1.0, 1.0))
        a, b = edges[:-1, None], edges[1:, None]
        xi, w = (0.5 * (a + b) + 0.5 * (b - a) * x16).ravel(), (0.5 * (b - a) * w16).ravel()
        point, dpoint, _, ddisp, traction = data.at(xi, np.full(xi.size, e))
        jac = np.abs(dpoint)
        g = (2.0 * data.shear * ddisp / jac + 1j * traction) / (1.0 + kappa)
        F, H = g * np.conj(dpoint) / jac, (-1j * np.conj(traction) - np.conj(g)) * np.conj(dpoint) / jac
        diff = point - zeta
        first += np.sum(w * dpoint * F / diff)
        second += np.sum(w * dpoint * (H / diff - np.conj(diff) * F / diff**2))
    trace, second = 4.0 * (first / (2j * np.pi)).real, second / (1j * np.pi)
    return np.array([0.5 * (trace - second.real), 0.5 * (trace + second.real), 0.5 * second.imag])


def test_near_integration_on_curved_elements_and_in_the_lens():
    """Coarse curved elements (16 per circle, 22.5 degrees: the sagitta 5 % of an element) and points
    0.3 down to 1e-7 element lengths inside them, many between an outer element's chord and its arc
    (the lens, where the residue enters), against brute-force quadrature of the same data. Bound 1e-6
    of the scale: the degree-11 interpolation of the densities along such bulging elements (measured
    5e-9; 3e-7 at 1e-3 of an element from its end, where two elements are near-singular at once)."""
    radius, inner = 1.0, 0.6
    n = np.arange(9)
    state = _michell_state(np.exp(0.3j * n) / (1.0 + n) ** 2, 0.5 * np.exp(-0.7j * n) / (1.0 + n) ** 2, radius, inner)
    mesh = _uniform_annulus(radius, inner, 16)
    sigma, u = state(mesh.nodes)
    normals = node_normals(mesh)
    t = np.stack(
        [sigma[0] * normals[:, 0] + sigma[2] * normals[:, 1], sigma[2] * normals[:, 0] + sigma[1] * normals[:, 1]], 1
    )
    h = 2.0 * np.pi * radius / 16
    on, normal, _ = map_points(mesh.geometry[[0, 5, 20]], np.array([0.0, 0.37, -0.9, 0.999]))  # outer, outer, bore
    points = np.concatenate([(on - d * h * normal).reshape(-1, 2) for d in (0.3, 1e-2, 1e-4, 1e-7)])
    data = curved.curved_data(mesh, u, t, G, NU)
    z = (points[:, 0] + 1j * points[:, 1] - data.mid[0]) / data.chord[0]
    assert np.sum(curved._lens(np.full(z.size, data.beta[0]), z)[0]) >= 4  # the lens is exercised
    found = curved.stresses(mesh, u, t, G, NU, points)
    expected = np.stack([_brute_force(data, p[0] + 1j * p[1]) for p in points], axis=1)
    assert np.abs(found - expected).max() <= 1e-6 * np.abs(expected).max()


def _uniform_annulus(radius, inner, n):
    """n continuous curved elements on each circle (centre (0, -radius), the outer one counter-clockwise,
    the bore clockwise: the annulus on the left), every node on its circle."""
    geometry, connectivity, nodes, fixed = [], [], [], []
    for r, sign, bonded in ((radius, 1.0, False), (inner, -1.0, True)):
        phi = sign * np.linspace(0.0, 2.0 * np.pi, 2 * n + 1)[:-1]
        start = len(nodes)
        points = np.column_stack([r * np.cos(phi), -radius + r * np.sin(phi)])
        nodes.extend(points)
        fixed.extend([bonded] * (2 * n))
        for k in range(n):
            ids = [2 * k, 2 * k + 1, (2 * k + 2) % (2 * n)]
            connectivity.append([start + i for i in ids])
            geometry.append(points[ids])
    e = len(connectivity)
    local = np.tile([-1.0, 0.0, 1.0], (e, 1))
    return BoundaryMesh(
        np.array(geometry), local, np.array(connectivity), np.array(nodes), np.array(fixed), np.zeros(len(nodes), bool),
        np.zeros(0, int),
    )  # fmt: skip


def _polar(points, radius):
    rel = points - np.array([0.0, -radius])
    return np.hypot(rel[:, 0], rel[:, 1]), np.arctan2(rel[:, 0], rel[:, 1])  # theta clockwise from +y


def _michell_state(S, T, radius, inner):
    """Michell's exact field as (stress (3, P) in x, y; u (P, 2)) of points (P, 2) in the mesh frame."""

    def state(points):
        r, theta = _polar(points, radius)
        f = annulus_field(S, T, radius, inner, G, NU, r, theta)
        e_r = np.column_stack([np.sin(theta), np.cos(theta)])
        e_t = np.column_stack([np.cos(theta), -np.sin(theta)])

        def comp(a, b):
            return (
                f[2] * e_r[:, a] * e_r[:, b]
                + f[3] * e_t[:, a] * e_t[:, b]
                + f[4] * (e_r[:, a] * e_t[:, b] + e_t[:, a] * e_r[:, b])
            )

        return np.stack([comp(0, 0), comp(1, 1), comp(0, 1)]), f[0, :, None] * e_r + f[1, :, None] * e_t

    return state


def test_michell_reference_meets_its_boundary_conditions():
    """The interior series: sigma_rr and sigma_rtheta at r = R are the given series, u = 0 on the bore
    (round-off of a few terms: 1e-13 of the scale)."""
    n = np.arange(9)
    S, T = np.exp(0.3j * n) / (1.0 + n) ** 2, 0.5 * np.exp(-0.7j * n) / (1.0 + n) ** 2
    theta = np.linspace(-3.0, 3.0, 13)
    f = annulus_field(S, T, 1.0, 0.6, G, NU, np.ones_like(theta), theta)
    waves = np.exp(1j * np.outer(theta, n))
    assert f[2] == pytest.approx((waves @ S).real, abs=1e-13)
    assert f[4] == pytest.approx((waves @ T).real, abs=1e-13)
    bore = annulus_field(S, T, 1.0, 0.6, G, NU, np.full_like(theta, 0.6), theta)
    assert np.abs(bore[:2]).max() <= 1e-13 * np.abs(f[:2]).max()


def test_identity_on_curved_elements_converges_to_michell():
    """Exact boundary data (Michell's u and t at the nodes of uniform curved meshes) through the identity:
    the error is the quadratic interpolation's, whose strain is off by about (h/2)^2 |u'''| / 3 per mode,
    (n h / 2R)^2 / 3 of mode n's stress; summed over the load's modes this bounds the interior error
    (points at least 1e-6 h from the mesh's own boundary, both circles, the lens between the chords and the
    arcs included). Bound: twice that sum; and each halving of h divides the error by more than 3 (second
    order at least: measured 3.7, 11.8 and 2.6 inside from 16 to 128 elements per circle, 3.9 and 4.1
    over all the points from 32 to 128)."""
    radius, inner = 1.0, 0.6
    n = np.arange(9)
    S, T = np.exp(0.3j * n) / (1.0 + n) ** 2, 0.5 * np.exp(-0.7j * n) / (1.0 + n) ** 2
    state = _michell_state(S, T, radius, inner)
    rng = np.random.default_rng(1)
    r, theta = inner + (radius - inner) * rng.random(200), 2.0 * np.pi * rng.random(200)
    inside = np.column_stack([r * np.sin(theta), -radius + r * np.cos(theta)])
    errors = []
    for count in (32, 64, 128):
        mesh = _uniform_annulus(radius, inner, count)
        h = 2.0 * np.pi * radius / count
        on, normal, _ = map_points(mesh.geometry[::3], np.array([0.37]))  # every third element, both circles
        near = np.concatenate([on[:, 0] - d * h * normal[:, 0] for d in (1e-2, 1e-4, 1e-6)])
        points = np.concatenate([inside, near])
        sigma, u = state(mesh.nodes)
        normals = node_normals(mesh)
        t = np.stack(
            [sigma[0] * normals[:, 0] + sigma[2] * normals[:, 1], sigma[2] * normals[:, 0] + sigma[1] * normals[:, 1]],
            1,
        )
        expected = state(points)[0]
        error = np.abs(curved.stresses(mesh, u, t, G, NU, points) - expected).max()
        bound = 2.0 * np.sum((np.abs(S) + np.abs(T)) * (n * h / (2.0 * radius)) ** 2 / 3.0)
        assert error <= bound
        errors.append(error)
    assert errors[0] / errors[1] > 3.0 and errors[1] / errors[2] > 3.0


def test_mirror_pairs_share_the_far_kernel_exactly():
    """On a mesh that is its own mirror image, points given with their mirrors take their far sums from
    one kernel (the mirror point's differences are -conj of the point's to the mirror nodes): the same
    stresses as the plain evaluation to round-off (1e-12 of the scale), near-boundary points included."""
    radius, inner = 1.0, 0.6
    n = np.arange(9)
    state = _michell_state(np.exp(0.3j * n) / (1.0 + n) ** 2, 0.5 * np.exp(-0.7j * n) / (1.0 + n) ** 2, radius, inner)
    mesh = _uniform_annulus(radius, inner, 16)
    sigma, u = state(mesh.nodes)
    normals = node_normals(mesh)
    t = np.stack(
        [sigma[0] * normals[:, 0] + sigma[2] * normals[:, 1], sigma[2] * normals[:, 0] + sigma[1] * normals[:, 1]], 1
    )
    rng = np.random.default_rng(2)
    r, theta = inner + (radius - inner) * rng.random(60), np.pi * rng.random(60)
    r[:10] = radius - 1e-4  # near the outer circle (inside the lens)
    half = np.column_stack([r * np.sin(theta), -radius + r * np.cos(theta)])
    points = np.concatenate([half, half * [-1.0, 1.0], [[0.0, -0.2]]])
    data = curved.curved_data(mesh, u, t, G, NU)
    assert curved.mirror_partner(data) is not None and curved._mirror_pairs(points)[0].size == 60
    expected = curved.interior_stresses(data, points)
    assert np.abs(curved.stresses(mesh, u, t, G, NU, points) - expected).max() <= 1e-12 * np.abs(expected).max()


def _bump(s, a):
    """The C1 load of tests/test_cylinder_bem.py: its quadratic interpolation is within (h/a)^3 of it."""
    return np.where(np.abs(s) < a, (1.0 - (s / a) ** 2) ** 2, 0.0)


def test_bem_annulus_stresses_match_michell():
    """The BEM body's own boundary solution (hollow roller r_i = R/2, a/R = 0.1, nu = 0.3) for a smooth
    pressure and tangential traction, through the identity, against Michell's series for the same
    piecewise-quadratic tractions (their Fourier coefficients in closed form, 4000 modes: the tail decays
    like exp(-n z / R), below 1e-8 at z = 0.05 a). What remains is the BEM's discretisation of the free
    surface and the bore: the strain of the free elements graded from the zone's, largest over the
    first free elements (measured 7e-4 p0 at z = 0.05 a, 2e-4 at 0.2 a, 2e-5 below a). Bound 2e-3 p0."""
    radius, inner, a = 1.0, 0.5, 0.1
    grid = ContactGrid(1.2 * a, 60, 2)
    p_n = -_bump(grid.x, a)
    p_t = 0.3 * p_n
    young = 2.0 * (1.0 + NU) * G
    mesh, u, t = annulus_solution(prepare_annulus(grid, radius, inner, young, NU), radius, p_n, p_t)
    x, z = np.linspace(-2.0 * a, 2.0 * a, 41), np.array([0.05, 0.2, 0.5, 1.0, 4.0]) * a
    points, theta = cylinder.grid_points(x, z, radius)
    found = cylinder.polar_components(*curved.stresses(mesh, u, t, G, NU, points), theta)
    half = 0.5 * (grid.edges[1] - grid.edges[0])
    S, T = amplitudes(4000, radius, 0.5 * (grid.edges[:-1] + grid.edges[1:]), half, p_n, p_t)
    f = annulus_field(S, T, radius, inner, G, NU, radius - np.repeat(z, x.size), theta)
    expected = (f[3], f[2], -f[4])  # sigma_ss, sigma_rr and tau_xz = -sigma_rtheta
    for got, ref in zip(found, expected, strict=True):
        assert np.abs(got - ref).max() <= 2e-3


def test_half_space_limit_near_the_contact():
    """R/a = 1000, a hollow cylinder (r_i = R/2) under a Hertz pressure and a tangential traction against
    the closed-form half-plane (exact for the same element tractions), z from 0.1 a to 3 a. They differ by
    the section's global stress, of order P/(R - r_i) (the load carried through the section: 3.1e-3 p0
    here), plus the BEM's near-surface discretisation (<= 1e-3 p0, the Michell test): bound
    P/(R - r_i) + 1e-3 p0 (measured 2.8e-3 p0)."""
    radius, inner = 1000.0, 500.0
    grid = ContactGrid(1.5, 60, 2)
    p_n = -hertz.pressure(grid.x, 1.0, 1.0)
    p_t = 0.3 * p_n * np.where(grid.x > 0.2, 1.0, 0.5)
    young = 2.0 * (1.0 + NU) * G
    mesh, u, t = annulus_solution(prepare_annulus(grid, radius, inner, young, NU), radius, p_n, p_t)
    x, z = np.linspace(-1.875, 1.875, 61), np.array([0.1, 0.2, 0.5, 1.0, 2.0, 3.0])
    points, theta = cylinder.grid_points(x, z, radius)
    found = cylinder.polar_components(*curved.stresses(mesh, u, t, G, NU, points), theta)
    expected = halfplane.stresses_at(grid, p_n, p_t, x[None, :], z[:, None])
    load = -grid.weights @ p_n
    bound = load / (radius - inner) + 1e-3 * np.abs(p_n).max()
    for got, ref in zip(found, expected, strict=True):
        assert np.abs(got - ref.ravel()).max() <= bound


def _finite_case(**dotted):
    cylinder_body = {"kind": "elastic", "radius": 10.0, "young": 1000.0, "poisson": 0.3, "shape": "cylinder",
                     "inner_radius": 4.0}  # fmt: skip
    data = case_dict(
        **{
            "bodies.A": cylinder_body,
            "bodies.B": {"kind": "rigid", "radius": float("inf")},
            "normal.load": 20.0,
            "friction.mu": 0.3,
            "tangential.q_over_mu_p": 0.5,
            "discretization.contact_elements": 40,
            "discretization.influence": None,
        },
        stresses={"points": [41, 21], "depth": 3.0},
    )
    return case_dict(data, **dotted)


def test_a_finite_cylinder_through_the_pipeline(tmp_path):
    """A hollow roller on a rigid flat (a/R ~ 0.1): the field in the body's curvilinear frame, its
    surface samples equal to the applied tractions (sigma_zz = p_n, tau_xz = -p_t: the boundary stress is
    the traction, to round-off), the bore's stresses balancing the contact force (the BEM satisfies
    equilibrium to its discretisation error, within 1e-5 of the resultant in tests/test_finite_shaft.py;
    measured 6e-6 of P here: bound 2e-5 P), the maxima, the file."""
    result = solve(_finite_case())
    stresses = result.stresses["A"]
    arrays, attributes = stresses.arrays, stresses.attributes
    assert attributes["model"] == "BEM cylinder" and attributes["bond_depth"] == 6.0
    p0 = float(np.max(-result.p_n))
    at_nodes = np.searchsorted(arrays["surface_x"], result.x)
    assert arrays["surface_x"][at_nodes] == pytest.approx(result.x, abs=1e-12)
    assert arrays["surface_sigma_zz"][at_nodes] == pytest.approx(result.p_n, abs=1e-9 * p0)
    assert arrays["surface_tau_xz"][at_nodes] == pytest.approx(-result.p_t, abs=1e-9 * p0)
    # the bore: sum w sigma . e_r over it is the contact force on the body (mesh frame: body below)
    angle = arrays["bond_x"] / 10.0
    e_r = np.column_stack([np.sin(angle), np.cos(angle)])
    e_s = np.column_stack([np.cos(angle), -np.sin(angle)])
    bore = arrays["bond_weights"] @ (arrays["bond_sigma_zz"][:, None] * e_r - arrays["bond_tau_xz"][:, None] * e_s)
    theta = result.x / 10.0
    contact = result.weights @ (
        result.p_n[:, None] * np.column_stack([np.sin(theta), np.cos(theta)])
        + result.p_t[:, None] * np.column_stack([np.cos(theta), -np.sin(theta)])
    )
    assert bore == pytest.approx(contact, abs=2e-5 * result.normal_load)
    # the field's first row lies on the surface, its components continuous with the interior rows
    assert arrays["z"][0] == 0.0 and arrays["sigma_zz"].shape == (21, 41)
    assert 0.4 * p0 < attributes["max_von_mises"] < p0 and 0.1 < attributes["max_von_mises_z"] / result.mesh_half_width
    # approaching the surface (1e-3 element lengths) the identity tends to the applied tractions: exactly
    # for consistent data; the BEM's u meets its integral equation at the collocation nodes only, so
    # what is left is its discretisation of the surface strain, largest at the traction's square-root
    # kinks (contact edges: 2 % p0; stick/slip boundaries: 0.9 %), measured 3e-4 (sigma_zz) and 1.1e-3
    # (tau_xz) p0 at the contact nodes more than two elements from every kink. Bound 5e-3 p0 on those.
    case = load_case(_finite_case())
    the_plan = pipeline.plan(case, half_width=result.mesh_half_width)
    mesh, u, t = build.boundary_solution(case, the_plan, "A", result.p_n, result.p_t)
    h = 2.0 * the_plan.grid.half_width / the_plan.grid.elements
    points, theta = cylinder.grid_points(result.x, np.array([1e-3 * h]), 10.0)
    _, sigma_rr, tau_xz = cylinder.polar_components(*curved.stresses(mesh, u, t, 1000.0 / 2.6, 0.3, points), theta)
    kinks = locate_kinks(result, the_plan.grid)[0]
    far = np.abs(result.x[:, None] - kinks[None, :]).min(axis=1) > 2.0 * h
    inside = np.flatnonzero((result.p_n < 0.0) & far)
    assert inside.size > 10
    assert np.abs(sigma_rr - result.p_n)[inside].max() <= 5e-3 * p0
    assert np.abs(tau_xz + result.p_t)[inside].max() <= 5e-3 * p0
    path = tmp_path / "finite.h5"
    write_result(result, path)
    back = read_result(path).stresses["A"].arrays
    assert np.array_equal(back["tau_xz"], arrays["tau_xz"]) and "bond_sigma_zz" in back


def test_twin_finite_cylinders_carry_opposite_shear():
    """Two identical finite cylinders: the same normal stresses, opposite surface shear (B carries
    -p_t in its mirror frame): tau_xz = -p_t on A and +p_t on B at the contact nodes."""
    twin = {"kind": "elastic", "radius": 10.0, "young": 1000.0, "poisson": 0.3, "shape": "cylinder",
            "inner_radius": 4.0}  # fmt: skip
    result = solve(_finite_case(**{"bodies.B": twin, "stresses.points": [21, 11]}))
    a, b = result.stresses["A"].arrays, result.stresses["B"].arrays
    p0 = float(np.max(-result.p_n))
    nodes = np.searchsorted(a["surface_x"], result.x)
    assert a["surface_tau_xz"][nodes] == pytest.approx(-result.p_t, abs=1e-9 * p0)
    assert b["surface_tau_xz"][nodes] == pytest.approx(result.p_t, abs=1e-9 * p0)
    assert b["surface_sigma_zz"][nodes] == pytest.approx(result.p_n, abs=1e-9 * p0)


def test_viscoelastic_finite_cylinders_are_accepted():
    """The stresses of a body with a prescribed surface traction and a bonded bore do not depend on its
    modulus (nor, with a constant Poisson ratio, on its history): the elastic BEM's field is the
    viscoelastic body's, as for the viscoelastic layer. The case validates and names the model."""
    data = _finite_case()
    data["bodies"]["A"].update({"kind": "viscoelastic", "relaxed_young": 300.0, "creep_time": 1e-3})
    data["rolling"]["speed"] = 100.0
    case = load_case(data)
    assert compute.model_name(case, "A") == "BEM cylinder"
