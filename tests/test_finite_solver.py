"""Finite cylinders in the solver (issue 21, stage B): the half-space limit, convergence at
a/R = 0.3, the effects line and the bad inputs."""

import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, run_cli, solve, write_case

E, NU = 210000.0, 0.3
RIGID_FLAT = {"kind": "rigid", "radius": float("inf")}


def _cylinder(radius, inner, young=E, poisson=NU):
    return {
        "kind": "elastic",
        "radius": radius,
        "young": young,
        "poisson": poisson,
        "shape": "cylinder",
        "inner_radius": inner,
    }


def _case(a, b, load, elements, **dotted):
    data = case_dict(
        **{
            "normal.load": load,
            "friction.mu": 0.3,
            "tangential.q_over_mu_p": 0.5,
            "discretization.contact_elements": elements,
            "discretization.influence": None,
        }
    )
    data["bodies"] = {"A": a, "B": b}
    return case_dict(data, **dotted)


def _half_space(body):
    return {k: v for k, v in body.items() if k not in ("shape", "inner_radius")}


def _edges_width(result):
    """Contact half-width from the nodal pressure: p_n^2 is linear in x at a square-root edge, so
    its line through the two outermost contact nodes on each side meets zero at the edge (the
    node cells' width only resolves the node spacing, 0.25 % of a at 200 elements)."""
    x, p = result.x, result.p_n
    inside = np.flatnonzero(p < 0.0)

    def edge(i, j):
        return x[i] + (x[i] - x[j]) * p[i] ** 2 / (p[j] ** 2 - p[i] ** 2)

    return 0.5 * (edge(inside[-1], inside[-2]) - edge(inside[0], inside[1]))


@pytest.mark.parametrize("pair", ["cylinder on a rigid flat", "twin cylinders"])
def test_half_space_limit(pair):
    """R/a = 1340: the finite cylinder against the closed-form half-plane on the same contact grid.
    Creepage within 0.5 % and tractions within 0.5 % of mu p0 (the issue's bounds). What differs
    is the curvature: the hoop strain w/R and the arc's turning, O(a/R) ln(R/a) ~ 0.5 % of the
    coupling terms, which carry part of the creepage here (measured: creepage 0.14 % on the flat,
    0.02 % for the twins; p_n 0.24 % and 0.15 % of p0; p_t 0.24 % and 0.23 % of mu p0)."""
    radius = 20000.0
    cylinder = _cylinder(radius, 0.5 * radius)
    if pair == "twin cylinders":
        a_body, b_body = cylinder, dict(cylinder)
    else:
        a_body, b_body = cylinder, RIGID_FLAT
    finite = solve(_case(a_body, b_body, 2000.0, 40))
    assert finite.half_space_ratio < 1e-3 and finite.validity_warning == ""
    a_hertz = solve(_case(_half_space(a_body), _half_space(b_body), 2000.0, 40)).mesh_half_width
    zone = 1.5 * finite.mesh_half_width / a_hertz
    half = solve(_case(_half_space(a_body), _half_space(b_body), 2000.0, 40, **{"discretization.zone": zone}))
    assert np.allclose(half.x, finite.x, rtol=0, atol=1e-9 * a_hertz)
    assert abs(finite.creep / half.creep - 1.0) <= 5e-3
    p0 = half.hertz_p0
    assert np.abs(finite.p_n - half.p_n).max() <= 5e-3 * p0
    assert np.abs(finite.p_t - half.p_t).max() <= 5e-3 * 0.3 * p0
    assert_contact_laws(finite)


def test_convergence_at_a_over_r_03():
    """A hollow roller R = 5, bore 2, on a rigid flat at a/R = 0.29 (mu = 0.3, Q/(mu P) = 0.5):
    100 and 200 contact elements (second-order slip derivative) agree within 0.2 % in creepage
    (measured 0.024 %) and contact half-width (measured 0.011 %), and no validity warning: the
    geometry is exact."""
    results = [
        solve(
            _case(
                _cylinder(5.0, 2.0, young=10.0),
                RIGID_FLAT,
                4.0,
                n,
                **{"discretization.slip_derivative": "element"},
            )
        )
        for n in (100, 200)
    ]
    coarse, fine = results
    assert abs(coarse.creep / fine.creep - 1.0) <= 2e-3
    assert abs(_edges_width(coarse) / _edges_width(fine) - 1.0) <= 2e-3
    assert fine.half_space_ratio > 0.25
    assert fine.validity_warning == ""
    for r in results:
        assert_contact_laws(r)


def test_effects_line(tmp_path):
    data = _case(_cylinder(5.0, 2.0, young=10.0), RIGID_FLAT, 0.5, 20)
    result = run_cli("check", write_case(tmp_path, data))
    assert result.exit_code == 0, result.output
    r = solve(data)
    assert "body shape: finite cylinder (A: R = 5, bore 2)" in r.effects_line


def test_twin_finite_cylinders_show_no_half_space_reference():
    """Twin finite cylinders are exactly decoupled, but Carter's creepage and Hertz's pressure are
    the half-space's (10 % off at a/R = 0.2, README's error map): not recorded as references."""
    twin = _cylinder(5.0, 2.0, young=10.0)
    r = solve(_case(twin, dict(twin), 0.5, 20))
    assert r.carter_creep is None and r.reference == {}


@pytest.mark.parametrize(
    ("body_a", "body_b", "key", "why"),
    [
        (_cylinder(5.0, 5.0), RIGID_FLAT, "bodies.A.inner_radius = 5", "not inside the body"),
        (_cylinder(5.0, 7.0), RIGID_FLAT, "bodies.A.inner_radius = 7", "not inside the body"),
        ({**_cylinder(5.0, 2.0), "inner_radius": None}, RIGID_FLAT, "bodies.A.inner_radius", "missing key"),
        (
            {**_cylinder(5.0, 2.0), "kind": "layered", "inner_radius": None, "layer_thickness": 5.0},
            RIGID_FLAT,
            "bodies.A.layer_thickness = 5",
            "not thinner than the body",
        ),
        (_cylinder(5.0, 2.0), {**RIGID_FLAT, "shape": "cylinder"}, "bodies.B.shape", "a rigid body has no"),
        (_cylinder(5.0, 2.0), {**RIGID_FLAT, "inner_radius": 1.0}, "bodies.B.inner_radius", "not used by"),
        (_cylinder(5.0, 2.0), _half_space(_cylinder(5.0, 2.0)), "bodies.B.shape", "against the finite cylinder"),
        ({**_cylinder(5.0, 2.0), "radius": float("inf")}, {"kind": "rigid", "radius": 5.0}, "bodies.A.radius", "flat"),
        (_half_space(_cylinder(5.0, 2.0)) | {"inner_radius": 2.0}, RIGID_FLAT, "bodies.A.inner_radius", "half-space"),
    ],
)
def test_bad_shapes_are_one_line_errors(tmp_path, body_a, body_b, key, why):
    body_a = {k: v for k, v in body_a.items() if v is not None}
    data = _case(body_a, body_b, 1.0, 20)
    result = run_cli("solve", write_case(tmp_path, data), "-o", tmp_path / "out.h5")
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and key in lines[0] and why in lines[0], result.output


@pytest.mark.parametrize(
    ("dotted", "why"),
    [
        ({"normal.load": 1e4}, "reaches half the circumference"),
    ],
)
def test_unsupported_finite_cases_are_one_line_errors(tmp_path, dotted, why):
    """A contact zone beyond the mesh's reach (the stresses of finite bodies: tests/test_stresses_finite.py)."""
    extra = dotted.pop("stresses", None)
    data = _case(_cylinder(5.0, 2.0, young=10.0), RIGID_FLAT, 1.0, 20, **dotted)
    if extra is not None:
        data["stresses"] = extra
    result = run_cli("solve", write_case(tmp_path, data), "-o", tmp_path / "out.h5")
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and why in lines[0], result.output


def test_half_space_warning_names_the_finite_model():
    """Above a/R = 0.1 the half-space warning points to shape = "cylinder" with the error map's
    estimate; a finite cylinder gets no warning at any a/R (its geometry is exact)."""
    from rolling_cli.case import load_case
    from rolling_cli.model.validity import half_space_check

    body = _cylinder(5.0, 2.0, young=10.0)
    half = load_case(_case(_half_space(body), RIGID_FLAT, 1.0, 20))
    warning = half_space_check(half, 1.5)["validity_warning"]
    assert 'shape = "cylinder" under [bodies.A]' in warning and "0.21 mu a/R" in warning
    finite = load_case(_case(body, RIGID_FLAT, 1.0, 20))
    assert half_space_check(finite, 1.5)["validity_warning"] == ""


@pytest.mark.parametrize(
    ("poisson", "load", "elements", "b_over_a"),
    [
        (0.3, 0.094, 80, (0.08, 0.13)),
        (0.5, 2.3, 80, (0.08, 0.13)),
        (0.3, 1e-4, 30, (0.7, 1.5)),
        (0.5, 1e-4, 30, (0.7, 1.5)),
    ],
)
def test_flat_layer_limit(poisson, load, elements, b_over_a):
    """A covered roller (cover b = 1 on a rigid core) of R/b = 10^4 on a rigid flat against today's
    flat layer (kind = "layered", the half-space shape), at b/a ~ 0.1 and ~ 1, nu = 0.3 and 0.5:
    creepage, peak pressure and contact half-width within 0.5 % (the issue's bounds). What differs is
    the curvature, O(a/R) <= 1e-3 (measured: creepage 0.15 % at b/a = 0.10 and 0.083, 0.02 % at
    b/a = 1.1 and 1.3; peak pressure and width at most 0.09 %). Before the bore was meshed as finely
    as a flat layer's bottom under the zone (at most b), thin covers were off by 1 % here."""
    cover = {"kind": "layered", "radius": 1e4, "young": 1.0, "poisson": poisson, "layer_thickness": 1.0}
    flat = solve(_case(cover, RIGID_FLAT, load, elements))
    finite = solve(_case({**cover, "shape": "cylinder"}, RIGID_FLAT, load, elements))
    width = _edges_width(flat)
    assert b_over_a[0] < 1.0 / width < b_over_a[1]
    assert abs(finite.creep / flat.creep - 1.0) <= 5e-3
    assert abs(finite.p_n.min() / flat.p_n.min() - 1.0) <= 5e-3
    assert abs(_edges_width(finite) / width - 1.0) <= 5e-3


def test_the_accuracy_line_says_the_estimate_covers_the_contact_only():
    """Issue 21 item 5: "adaptive tolerance (the estimate covers the body mesh or says it does not)".
    The estimate reads the contact tractions' kinks; a finite body's mesh away from the contact is
    fixed, so the result and the summary say that the estimate is of the contact discretisation only
    (a half-space body, whose far field is closed-form, does not carry the phrase)."""
    from rolling_cli.adapt.levels import FINITE_BODY_SCOPE
    from rolling_cli.report.summary import summary

    finite = solve(_case(_cylinder(10.0, 5.0), RIGID_FLAT, 500.0, 20, **{"discretization.tolerance": 5e-2}))
    assert str(finite.attributes["adaptive_method"]).endswith(FINITE_BODY_SCOPE)
    assert "contact discretisation only" in summary(finite)
    half = solve(_case(_half_space(_cylinder(10.0, 5.0)), RIGID_FLAT, 500.0, 20, **{"discretization.tolerance": 5e-2}))
    assert "accuracy       tolerance" in summary(half) and "contact discretisation only" not in summary(half)
