"""The finite cylinder's BEM (issue 21, stage A): the bonded annulus against Michell's series,
the half-space limit, the mesh, and the body shapes."""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from rolling_cli.influence import halfplane
from rolling_cli.influence.bem import cylinder
from rolling_cli.influence.bem.symmetry import mirror_nodes
from rolling_cli.model.grid import ContactGrid
from rolling_cli.model.shapes import Cylinder, HalfSpace, covered
from rolling_cli.references import annulus, hertz

E = 2.0e5


def _bump(s, a):
    """A smooth unit load (1 - s^2/a^2)^2 on |s| < a: C1 at its ends, so the BEM's quadratic
    interpolation of its nodal values is within ~(h/a)^3 of it and the comparison measures the
    body model, not the sampling of a kink."""
    return np.where(np.abs(s) < a, (1.0 - (s / a) ** 2) ** 2, 0.0)


def _michell(grid, radius, inner, poisson, sigma_rr, sigma_rt, samples=2**18):
    """Michell's w (into the body) and u_t at the contact nodes for tractions given as functions of s."""
    theta = 2.0 * np.pi * np.arange(samples) / samples
    theta = np.where(theta > np.pi, theta - 2.0 * np.pi, theta)
    s = radius * theta
    u_r, u_t = annulus.surface_displacement(
        sigma_rr(s), sigma_rt(s), radius, inner, E / (2.0 * (1.0 + poisson)), poisson
    )
    order = np.argsort(theta)
    angles = grid.x / radius  # the nodes' arc lengths (on quadratic arcs through points of the circle)
    return np.interp(angles, theta[order], -u_r[order]), np.interp(angles, theta[order], u_t[order])


def test_michell_modes_tend_to_the_half_plane_and_solve_navier():
    """The reference's own checks. (1) At large n the annulus looks like a half-plane under a
    wave of wavenumber n/R: G u_r/R per unit sigma_rr -> (1 - nu)/n and the cross terms ->
    (1 - 2 nu)/(2 n) (Johnson 2.2; the next term is O(1/n^2): bound 1e-3 at n = 2000).
    (2) Each basis solution satisfies Navier's equations (central differences, step 1e-4:
    truncation ~1e-8 of the terms; bound 1e-6)."""
    nu = 0.3
    n = 2000
    r = annulus.mode_responses(n, 0.5, nu)[-1] * n
    assert abs(r[0, 0] - (1 - nu)) <= 1e-3 and abs(r[1, 1] - (1 - nu)) <= 1e-3
    assert abs(r[0, 1] - (1 - 2 * nu) / 2) <= 1e-3 and abs(r[1, 0] - (1 - 2 * nu) / 2) <= 1e-3
    k = 2.0 * (1.0 - nu) / (1.0 - 2.0 * nu)
    modes = np.array([1, 2, 5])
    h = 1e-4
    for rho in (0.6, 0.8):
        vals = [annulus._basis(modes, rho + d, 0.5, k) for d in (-h, 0.0, h)]
        U, dU, V, dV = vals[1]
        d2U = (vals[2][0] - 2 * U + vals[0][0]) / h**2
        d2V = (vals[2][2] - 2 * V + vals[0][2]) / h**2
        nn = modes[:, None].astype(float)
        # E = U' + (U + n V)/r, W = V' + (V + n U)/r; k E' = n W / r and W' = k n E / r
        dE = d2U + (dU + nn * dV) / rho - (U + nn * V) / rho**2
        dW = d2V + (dV + nn * dU) / rho - (V + nn * U) / rho**2
        Ev = dU + (U + nn * V) / rho
        Wv = dV + (V + nn * U) / rho
        scale = np.abs(np.stack([dE, dW])).max()
        assert np.abs(k * dE - nn * Wv / rho).max() <= 1e-6 * k * scale
        assert np.abs(dW - k * nn * Ev / rho).max() <= 1e-6 * k * scale


@pytest.mark.parametrize(
    ("radius", "inner", "poisson"),
    [(20.0, 2.0, 0.3), (20.0, 10.0, 0.3), (20.0, 18.0, 0.45)],  # solid-like, hollow, covered (b = 2 a)
)
def test_bem_annulus_matches_michell(radius, inner, poisson):
    """Compliance of the bonded annulus (displacements of the contact nodes under a unit load
    distribution, normal and tangential) at a/R = 0.05 against Michell's series: within 0.5 % of
    the largest displacement (measured 4e-6 to 6e-6 with the curved elements; 0.01-0.14 % with
    straight ones; the series is cut at 131071 modes, whose tail is below 1e-6 for this C1 load).
    Absolute levels: the bore fixes them."""
    a = 1.0
    grid = ContactGrid(1.5 * a, 30, 2)
    c = cylinder.condensed(grid, radius, inner, E, poisson)
    load = -_bump(grid.x, a)
    zero = np.zeros_like(load)
    for p_n, p_t in ((load, zero), (zero, load)):
        w = c.S_nn @ p_n + c.S_nt @ p_t
        u_t = c.S_tn @ p_n + c.S_tt @ p_t
        sigma_rr = (lambda s: -_bump(s, a)) if p_n is load else (lambda s: 0.0 * s)
        sigma_rt = (lambda s: -_bump(s, a)) if p_t is load else (lambda s: 0.0 * s)
        w_ref, u_ref = _michell(grid, radius, inner, poisson, sigma_rr, sigma_rt)
        scale = max(np.abs(w_ref).max(), np.abs(u_ref).max())
        assert np.abs(w - w_ref).max() <= 5e-3 * scale
        assert np.abs(u_t - u_ref).max() <= 5e-3 * scale


def test_half_space_limit():
    """R/a = 1000, a hollow cylinder against the closed-form half-plane under a Hertz pressure,
    in differences of displacements (the absolute level depends on the far boundary: here the
    bore). Direct blocks: the curvature's corrections are O(a/R) (measured 3e-4 of the scale):
    bound 1e-3. Coupling: the curved surface adds the hoop strain w/R to du_t/ds (eps_theta =
    du_t/ds + u_r/R), a term of order (a/R) ln(R/a) (0.7 % here, measured); with it added to the
    half-plane's, what is left is O(a/R) (measured 8e-4 at nu = 0.3, 1e-3 at 0.5): bound 2e-3.
    And without it the difference is at least half the hoop term (the term is really there)."""
    radius = 1000.0
    grid = ContactGrid(1.5, 30, 2)
    p = -hertz.pressure(grid.x, 1.0, 1.0)
    mid = grid.size // 2

    def diff(v):
        return v - v[mid]

    for nu in (0.3, 0.5):
        c = cylinder.condensed(grid, radius, 0.5 * radius, 1.0, nu)
        h = halfplane.body_compliance(grid, 1.0, nu, True)
        scale = np.abs(diff(h.S_nn @ p)).max()
        for name in ("S_nn", "S_tt"):
            assert np.abs(diff(getattr(c, name) @ p) - diff(getattr(h, name) @ p)).max() <= 1e-3 * scale
        hoop = cumulative_trapezoid(c.S_nn @ p / radius, grid.x, initial=0.0)
        error = np.abs(diff(c.S_tn @ p) - diff(h.S_tn @ p) - diff(hoop)).max()
        assert error <= 2e-3 * scale
        assert np.abs(diff(c.S_tn @ p) - diff(h.S_tn @ p)).max() >= 0.5 * np.abs(diff(hoop)).max()


def test_annulus_mesh():
    """Closed, mirror-symmetric, counter-clockwise outer circle and clockwise bore (domain on the
    left: the signed area of the two loops is pi (R^2 - r_i^2) to the chords' O((h/R)^2)), the
    contact nodes on the contact arc (curved elements; a chord's would be within h^2 / 8R) in increasing x,
    the bore fixed, no far field."""
    radius, inner = 20.0, 12.0
    grid = ContactGrid(1.5, 20, 2)
    mesh = cylinder.annulus_mesh(grid, radius, inner)
    assert mirror_nodes(mesh) is not None
    p0, p2 = mesh.geometry[:, 0], mesh.geometry[:, 2]
    area = 0.5 * np.sum(p0[:, 0] * p2[:, 1] - p2[:, 0] * p0[:, 1])
    assert abs(area / (np.pi * (radius**2 - inner**2)) - 1.0) <= 1e-2
    centre = np.array([0.0, -radius])
    contact = mesh.nodes[mesh.contact]
    assert np.all(np.diff(contact[:, 0]) > 0)
    r = np.linalg.norm(contact - centre, axis=1)
    h = grid.element_length
    assert np.all(r <= radius + 1e-12) and np.all(r >= radius - h**2 / (8 * radius) - 1e-12)
    r_all = np.linalg.norm(mesh.nodes - centre, axis=1)
    assert np.all(mesh.fixed == (r_all < 0.5 * (radius + inner)))
    assert not mesh.far.any()
    angles = cylinder.contact_angles(mesh, radius)
    assert np.allclose(angles * radius, grid.x, rtol=0, atol=1e-3 * h)


def test_shapes():
    assert HalfSpace().describe() == "half-space"
    cyl = Cylinder(5.0, 2.0)
    assert cyl.describe() == "finite cylinder (R = 5, bore 2)" and cyl.thickness == 3.0
    assert covered(5.0, 1.0) == Cylinder(5.0, 4.0)
    assert hash(cyl) == hash(Cylinder(5.0, 2.0))
    for bad in ((5.0, 5.0), (5.0, 0.0), (5.0, 6.0), (float("inf"), 1.0)):
        with pytest.raises(ValueError):
            Cylinder(*bad)


def test_annulus_size_counts_the_mesh():
    """The resource model's count (without building) equals the built mesh's, for a solid-like
    roller, a thin cover and a large hollow cylinder."""
    for half, elements, radius, inner in ((1.5, 30, 20.0, 2.0), (1.5, 200, 5.0, 4.0), (0.3, 20, 1000.0, 500.0)):
        mesh = cylinder.annulus_mesh(ContactGrid(half, elements, 2), radius, inner)
        assert cylinder.annulus_size(half, elements, radius, inner) == (mesh.size, mesh.elements)


def test_case_bodies_give_their_shapes():
    """bodies.X resolve to the BodyShape the influence model builds: a bore, a cover's core, the
    half-space default, none for a rigid body."""
    from rolling_cli.case import load_case

    data = {
        "bodies": {
            "A": {"kind": "layered", "radius": 5.0, "young": 1.0, "poisson": 0.45, "layer_thickness": 1.0,
                  "shape": "cylinder"},
            "B": {"kind": "rigid", "radius": float("inf")},
        },
        "friction": {"mu": 0.3},
        "normal": {"load": 1.0},
    }  # fmt: skip
    case = load_case(data)
    assert case.bodies.A.body_shape == covered(5.0, 1.0) and case.bodies.B.body_shape is None
    data["bodies"]["A"] = {"kind": "elastic", "radius": 5.0, "young": 1.0, "poisson": 0.3}
    assert load_case(data).bodies.A.body_shape == HalfSpace()
    data["bodies"]["A"] |= {"shape": "cylinder", "inner_radius": 2.0}
    assert load_case(data).bodies.A.body_shape == Cylinder(5.0, 2.0)
