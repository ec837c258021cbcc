"""Viscoelastic layer on a rigid core, the rubber cover (issue 22): transfer matrix, kernels, limits,
the thick-layer half-plane, the energy balance, the direction, bad input.

Independent references: the plane-strain layer's 4 x 4 boundary system solved numerically (the
closed-form transfer matrix), today's BEM layer (the Fourier layer's kernels; the elastic cover),
the elastic BEM layer with E_r and E_g (the speed limits), the viscoelastic half-plane's closed-form
kernels (the thick cover), and the Fourier-space loss of references.layer_fourier plus
references.hysteresis (the energy balance against the solved moment).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from helpers import case_dict, run_cli, write_case
from rolling_cli.case import load_case
from rolling_cli.influence import bem
from rolling_cli.influence import viscoelastic_layer as layer
from rolling_cli.influence.halfplane import _toeplitz_gather
from rolling_cli.model.grid import ContactGrid
from rolling_cli.pipeline import solve
from rolling_cli.references import hertz, layer_fourier

CASES = Path(__file__).resolve().parents[1] / "cases"


def _tyre(name: str) -> dict:
    with open(CASES / f"{name}.toml", "rb") as handle:
        return tomllib.load(handle)


def _cover(base: dict, relaxed: float, speed: float, **dotted) -> dict:
    """``base`` with its layer B viscoelastic: E_g = its young, E_r = ``relaxed``, tau_c = 1 s."""
    keys = {"bodies.B.viscoelastic": True, "bodies.B.relaxed_young": relaxed, "bodies.B.creep_time": 1.0}
    return case_dict(base, **{**keys, "rolling.speed": speed, **dotted})


# --- the transfer matrix and the kernels ----------------------------------------------------------


def _numerical_transfer(k: float, b: float, nu: float) -> np.ndarray:
    """[[H_nn, H_nt], [H_tn, H_tt]] at unit modulus from Airy's function (A + B z) e^(kz) +
    (C + D z) e^(-kz) in -b < z < 0: the tractions (sigma_xz, sigma_zz) given at z = 0, u = 0 at
    z = -b, solved as a 4 x 4 system (u_x = eps_xx / (ik), u_z = (gamma_xz - u_x') / (ik))."""

    def fields(z: float):
        e1, e2 = math.exp(k * z), math.exp(-k * z)
        f0 = np.array([e1, z * e1, e2, z * e2])
        f1 = np.array([k * e1, e1 + k * z * e1, -k * e2, e2 - k * z * e2])
        f2 = np.array([k * k * e1, 2 * k * e1 + k * k * z * e1, k * k * e2, -2 * k * e2 + k * k * z * e2])
        f3 = np.array([k**3 * e1, 3 * k * k * e1 + k**3 * z * e1, -(k**3) * e2, 3 * k * k * e2 - k**3 * z * e2])
        c = 1.0 + nu
        u = c * ((1 - nu) * f2 + nu * k * k * f0) / (1j * k)
        du = c * ((1 - nu) * f3 + nu * k * k * f1) / (1j * k)
        w = (2 * c * (-1j * k * f1) - du) / (1j * k)
        return -k * k * f0, -1j * k * f1, u, w

    s_zz, s_xz, u0, w0 = fields(0.0)
    _, _, ub, wb = fields(-b)
    system = np.array([s_xz, s_zz, ub, wb], dtype=complex)
    out = np.empty((2, 2), dtype=complex)
    for j, rhs in enumerate(([0, 1, 0, 0], [1, 0, 0, 0])):  # unit p_n, unit p_t
        coef = np.linalg.solve(system, np.array(rhs, dtype=complex))
        out[:, j] = [-(w0 @ coef), u0 @ coef]
    return out


@pytest.mark.parametrize("nu", [0.0, 0.3, 0.45, 0.5])
def test_transfer_matrix_is_the_layer_boundary_system_and_has_its_limits(nu):
    """The closed form against the numerical 4 x 4 solve (1e-12 of the entries: both are exact, the
    solve's conditioning ~e^(2kb) at kb <= 5 costs a few digits), the thin-layer springs at k b = 1e-4
    (H_nn -> -b (1 + nu)(1 - 2 nu)/(1 - nu), H_tt -> 2 (1 + nu) b, to O(k b) = 1e-4), and the
    half-plane's kernels at k b = 20 (the remainder ~ 4 t^2 e^(-2t) / kappa < 1e-11 of them)."""
    b = 0.7
    for k in (0.01, 0.3, 1.0, 3.0, 7.0):
        nn, tt, g = layer_fourier.transfer(np.array([k]), b, nu)
        closed = np.array([[nn[0], -1j * g[0]], [-1j * g[0], tt[0]]])
        exact = _numerical_transfer(k, b, nu)
        assert np.max(np.abs(closed - exact)) < 1e-12 * np.max(np.abs(exact)), k
    nn, tt, g = layer_fourier.transfer(np.array([1e-4 / b]), b, nu)
    assert nn[0] == pytest.approx(-b * (1 + nu) * (1 - 2 * nu) / (1 - nu), abs=2e-4 * b)
    assert tt[0] == pytest.approx(2.0 * (1 + nu) * b, rel=2e-4)
    k = 20.0 / b
    pairs = zip(layer_fourier.transfer(np.array([k]), b, nu), layer_fourier.halfplane(np.array([k]), nu), strict=True)
    for got, half in pairs:
        assert got[0] == pytest.approx(half[0], rel=1e-11)


@pytest.mark.parametrize(("nu", "band_tolerance"), [(0.5, (5e-3, 5e-3)), (0.3, (3e-3, 2e-2))])
def test_fourier_layer_kernels_match_the_bem_layer(nu, band_tolerance):
    """The infinite layer's element kernels (history_offsets at |b| -> inf is -K_F) against today's BEM
    layer (b = 1, 30 elements of 0.1, free ends 10 b beyond the zone), relative to each block's largest
    entry. nu = 0.5: everywhere within 0.1 % (direct) and 0.3 % (cross); measured 0.07 % and 0.2 %.
    nu = 0.3: off the three-element diagonal band within 0.3 % / 2 % (measured 0.08 % / 0.8 %); on
    the band the BEM's compressible element-level terms differ from the exact kernels by up to 15 % of
    the cross block, as the BEM half-space's from the closed-form half-plane do (the body_compliance
    docstring: the BEM's departure is carried along the history, so the limits stay exact)."""
    grid = ContactGrid(1.5, 30, 2)
    thickness = 1.0
    mesh = bem.body_mesh(grid, grid.half_width + 10.0 * thickness, thickness, largest=thickness, far_field=False)
    elastic = bem.condensed(mesh, grid, 1.0, nu)
    fast = layer.history_offsets(grid, thickness, nu, (layer.FAST * 3.0,))[0]
    index = np.arange(grid.size) // 3
    band = np.abs(index[:, None] - index[None, :]) <= 1
    direct_tol, cross_tol = (1e-3, 3e-3) if nu == 0.5 else band_tolerance
    for name, block, tol in (("S_nn", 0, direct_tol), ("S_tt", 1, direct_tol), ("S_nt", 2, cross_tol),
                             ("S_tn", 2, cross_tol)):  # fmt: skip
        bem_block = getattr(elastic, name)
        error = np.abs(bem_block + _toeplitz_gather(grid, fast[block])) / np.abs(bem_block).max()
        assert (error.max() if nu == 0.5 else error[~band].max()) < tol, name


def test_upstream_filter_is_the_exponential_average_on_the_cells():
    """Each row of the filter sums to the part of the exponential upstream of the node inside the zone
    (1 - exp(-d/|b|), d the distance to the zone's upstream edge), lies on one side, and tends to the
    identity as b -> 0 (1e-12: the cell's own share 1 - exp(-h/(2|b|)))."""
    grid = ContactGrid(1.0, 10, 2)
    x = grid.x
    for b in (0.05, -0.05, 2.0, -2.0):
        weights = layer.upstream_filter(x, b)
        edge = 1.0 if b > 0 else -1.0
        np.testing.assert_allclose(weights.sum(axis=1), -np.expm1(-np.abs(edge - x) / abs(b)), rtol=1e-12)
        upstream = (x[None, :] - x[:, None]) * b >= 0.0
        assert np.all(weights[~upstream] == 0.0)
    np.testing.assert_allclose(layer.upstream_filter(x, 1e-6), np.eye(grid.size), atol=1e-12)


# --- solutions ------------------------------------------------------------------------------------


def test_elastic_cover_is_todays_tyre_model():
    """E_r = E_g (no retardation term): the tyre case of Fig. 11 to 1e-6 mu p0 (it is the same BEM
    layer, scaled by E_g J_r = 1: equal to round-off)."""
    base = _tyre("tyred_fig11_q41")
    elastic = solve(load_case(base))
    cover = solve(load_case(_cover(base, 10.0, 1.0)))
    scale = 1e-6 * 0.1 * float(-elastic.p_n.min())
    np.testing.assert_allclose(cover.p_n, elastic.p_n, rtol=0.0, atol=scale)
    np.testing.assert_allclose(cover.p_t, elastic.p_t, rtol=0.0, atol=scale)
    assert cover.creep == pytest.approx(elastic.creep, rel=1e-9)
    assert "viscoelastic: simulated (B: SLS, V tau_c / a = " in cover.effects_line


@pytest.mark.parametrize("name", ["tyred_fig11_q41", "tyred_compressible_q41"])
def test_slow_and_fast_rolling_are_the_relaxed_and_glassy_elastic_covers(name):
    """V tau_c / a = 1e-8 gives the elastic cover with E_r, 1e8 with E_g, on the same grid (overlap
    control: the measured contact scale is the same), within 1e-4 mu p_max in both tractions (measured
    1e-7: the history terms left are of order b/h = 1e-8 and the exponential average's 1/|b|), the
    moment of the elastic cover and no hysteresis."""
    base = _tyre(name)
    young = float(base["bodies"]["B"]["young"])
    a = float(solve(load_case(base)).contact_half_width)
    for ratio, modulus in ((1e-8, 0.5 * young), (1e8, young)):
        elastic = solve(load_case(case_dict(base, **{"bodies.B.young": modulus})))
        cover = solve(load_case(_cover(base, 0.5 * young, ratio * a)))
        assert np.array_equal(cover.x, elastic.x)
        scale = 1e-4 * 0.1 * float(-elastic.p_n.min())
        assert np.max(np.abs(cover.p_n - elastic.p_n)) < scale, ratio
        assert np.max(np.abs(cover.p_t - elastic.p_t)) < scale, ratio
        moment = -float(elastic.x @ (elastic.weights * elastic.p_n))  # sgn(V) = -1
        assert cover.rolling_resistance_moment == pytest.approx(moment, rel=1e-4, abs=1e-6 * abs(moment) + 1e-12)
        assert abs(cover.hysteresis_power) < 1e-4 * float(elastic.frictional_power_total)


def _rigid_roller(nu: float, thickness_ratio: float, ratio: float, elements: int, **extra) -> tuple[dict, dict]:
    """(half-plane case, cover case): a rigid roller (R = 50) without friction on an SLS flat
    (E_g = 20, E_r = 10, tau_c = 0.01) or on a cover of it, b = thickness_ratio a_r, at V tau_c / a_r
    = ratio; both quadratic elements over 1.5 a_r."""
    a_r = hertz.half_width(1.0, 50.0, 10.0 / (1.0 - nu**2))
    material = {"radius": "inf", "young": 20.0, "relaxed_young": 10.0, "creep_time": 0.01, "poisson": nu}
    half = {
        "bodies": {"A": {"kind": "rigid", "radius": 50.0}, "B": {"kind": "viscoelastic", **material}},
        "friction": {"mu": 0.0},
        "normal": {"load": 1.0},
        "rolling": {"speed": ratio * a_r / 0.01, "direction": -1},
        "discretization": {"element": "quadratic", "contact_elements": elements, "zone": 1.5},
    }
    cover = {"kind": "layered", "viscoelastic": True, "layer_thickness": thickness_ratio * a_r, **material}
    return case_dict(half, **extra), case_dict(half, **{"bodies.B": cover, **extra})


@pytest.mark.parametrize(
    ("thickness_ratio", "ratio", "cells"), [(1.0, 0.3, 80), (1.0, 1.0, 80), (1.0, 3.0, 80), (0.1, 0.3, 160)]
)
def test_cover_rolling_resistance_against_the_fourier_reference(thickness_ratio, ratio, cells):
    """Hunter's roller on a cover (b = a_r and 0.1 a_r, E_g = 2 E_r, nu = 0.5, frictionless): M/(P R)
    against references.hunter with the layer's normal compliance (a different route: the complex
    modulus times the closed-form transfer matrix on a periodic FFT kernel, an active-set contact),
    within 1 % as Hunter's check. Measured: 0.006-0.07 % (b = a_r), 0.05 % (b = 0.1 a_r); the
    reference's own cell error (80 against 40 cells per a_r) is 0.1-0.2 %."""
    from rolling_cli.references import hunter

    _, cover = _rigid_roller(0.5, thickness_ratio, ratio, 60)
    result = solve(load_case(cover))
    a_r = hertz.half_width(1.0, 50.0, 10.0 / 0.75)
    reference = hunter.rolling_resistance(
        1.0, 50.0, 20.0, 10.0, 0.01, 0.5, ratio * a_r / 0.01, -1, cells, thickness=thickness_ratio * a_r
    )
    assert result.rolling_resistance_coefficient == pytest.approx(reference, rel=0.01)


@pytest.mark.parametrize(("thickness_ratio", "ratio"), [(30.0, 0.3), (30.0, 1.0), (100.0, 3.0)])
def test_thick_cover_is_the_viscoelastic_half_plane(thickness_ratio, ratio):
    """A cover with b/a_r >= 30 on Hunter's roller equals the viscoelastic half-plane within 0.5 % in the
    rolling resistance and the peak pressure (measured at b/a_r = 30: -0.07 %, -0.23 % at V tau_c / a_r
    = 0.3, 1, and 0.06 % in the peak; at 3, -1.0 % (b/a = 30) and -0.1 % (b/a = 100): the core is felt
    like (V tau_c / b)^2; at b/a_r = 10 already the elastic cover's own stiffening, 0.5 % in the peak,
    -1.9 % in M at 1)."""
    half, cover = _rigid_roller(0.5, thickness_ratio, ratio, 60)
    h, c = solve(load_case(half)), solve(load_case(cover))
    assert c.rolling_resistance_coefficient == pytest.approx(h.rolling_resistance_coefficient, rel=0.005)
    assert float(-c.p_n.min()) == pytest.approx(float(-h.p_n.min()), rel=0.005)


def _flat_layer_reference(thickness: float | None, ratio: float, period: float) -> tuple[float, float]:
    """(M/(P R), peak pressure) of Hunter's roller of :func:`_rigid_roller` (nu = 0.5) by the Fourier
    complex-modulus reference (references.hunter), on the half-plane (``thickness`` None) or the
    flat layer of that thickness on a rigid base, with a given ``period`` (both on the same one, so
    that they differ by the layer alone) and 40 cells per a_r."""
    from rolling_cli.references import hunter

    a_r = hertz.half_width(1.0, 50.0, 10.0 / 0.75)
    x, p = hunter.solve(1.0, 50.0, 1.0 / 20.0, [0.1 - 0.05], [ratio * a_r], 0.5, a_r / 40.0, period, thickness)
    return float(np.sum(p * x) * (a_r / 40.0) / 50.0), float(p.max())  # direction -1: x_c / R


def test_cover_of_ten_contact_widths_differs_from_the_half_plane_as_the_physics_does():
    """At b/a_r = 10 a cover is not the half-plane within 0.5 %, and no correct model makes it so: the
    flat-layer Fourier reference (a different route: the complex modulus times the closed-form
    transfer matrix, an active-set contact, period 40 b) puts the cover's M/(P R) 0.39 %, 1.94 % and
    7.5 % below the half-plane's at V tau_c / a_r = 0.3, 1, 3, and the elastic cover's (E_r = E_g,
    today's tyre model) peak pressure 0.51 % above the elastic half-plane's (benchmarks/RESULTS.md).
    So the check is relative to the model: the solved cover's difference from the solved
    viscoelastic half-plane equals (M) the reference's and (peak pressure) the elastic cover's own
    within 0.5 % of the cover's answer (measured: M 0.001 % at 1 and 0.10 % at 3, the peak 0.07 % and
    0.04 %; the reference's own cell error in its difference, 20 against 40 cells per a_r, is 0.08 %). The
    direct 0.5 % check holds from b/a_r = 30 (:func:`test_thick_cover_is_the_viscoelastic_half_plane`)."""
    a_r = hertz.half_width(1.0, 50.0, 10.0 / 0.75)
    elastic = {
        "bodies.B.relaxed_young": None,
        "bodies.B.creep_time": None,
        "bodies.B.young": 10.0,
        "rolling.speed": None,
    }
    half, cover = _rigid_roller(0.5, 10.0, 1.0, 60)  # with E_r: the same a_r, the same grid
    half_e = solve(load_case(case_dict(half, **{**elastic, "bodies.B.kind": "elastic"})))
    cover_e = solve(load_case(case_dict(cover, **{**elastic, "bodies.B.viscoelastic": None})))
    peak_e = float(cover_e.p_n.min() / half_e.p_n.min()) - 1.0  # the elastic cover's stiffening
    assert peak_e > 0.004  # it is there (0.51 %): the direct 0.5 % check could not hold at b/a_r = 10
    for ratio in (1.0, 3.0):
        half, cover = (solve(load_case(d)) for d in _rigid_roller(0.5, 10.0, ratio, 60))
        ref_cover, _ = _flat_layer_reference(10.0 * a_r, ratio, 400.0 * a_r)
        ref_half, _ = _flat_layer_reference(None, ratio, 400.0 * a_r)
        expected = half.rolling_resistance_coefficient * (ref_cover / ref_half)
        assert abs(ref_cover / ref_half - 1.0) > 0.005, ratio  # the physics' own difference exceeds 0.5 %
        assert cover.rolling_resistance_coefficient == pytest.approx(expected, rel=0.005), ratio
        peak = float(-cover.p_n.min())
        assert peak - float(-half.p_n.min()) * (1.0 + peak_e) == pytest.approx(0.0, abs=0.005 * peak), ratio


def test_two_thick_covers_creep_like_two_viscoelastic_cylinders():
    """Two identical covers (b = 30 a_r on R = 100, nu = 0.4, driven, Q/(mu P) = 0.5; the cross blocks
    cancel) against two identical SLS cylinders at V tau_c / a_r = 1: creepage, rolling resistance and
    peak pressure within 0.5 % (measured 0.06 %, 0.18 %, 0.05 % at 120 elements). A rigid roller on one
    cover creeps differently: the core couples the pressure into a tangential strain ~ P/(E b), so its
    creepage approaches the half-plane's only like a/b (35 %, 12 %, 4 % at b/a = 10, 30, 100, measured,
    in the elastic limit too)."""
    nu = 0.4
    a_r = hertz.half_width(1.0, 50.0, 0.5 * 10.0 / (1.0 - nu**2))
    material = {"radius": 100.0, "young": 20.0, "relaxed_young": 10.0, "creep_time": 0.01, "poisson": nu}
    pair = {
        "bodies": {"A": {"kind": "viscoelastic", **material}, "B": {"kind": "viscoelastic", **material}},
        "friction": {"mu": 0.3},
        "normal": {"load": 1.0},
        "tangential": {"q_over_mu_p": 0.5},
        "rolling": {"speed": a_r / 0.01, "direction": -1},
        "discretization": {"element": "quadratic", "contact_elements": 120, "zone": 1.5},
    }
    cover = {"kind": "layered", "viscoelastic": True, "layer_thickness": 30.0 * a_r, **material}
    h = solve(load_case(pair))
    c = solve(load_case(case_dict(pair, **{"bodies.A": cover, "bodies.B": dict(cover)})))
    assert "coupling: skipped" in c.effects_line
    assert c.creep == pytest.approx(h.creep, rel=0.005)
    assert c.rolling_resistance_coefficient == pytest.approx(h.rolling_resistance_coefficient, rel=0.005)
    assert float(-c.p_n.min()) == pytest.approx(float(-h.p_n.min()), rel=0.005)


@pytest.mark.parametrize(
    ("nu", "thickness_ratio", "ratio", "extra"),
    [
        (0.5, 1.0, 1.0, {}),  # frictionless: |V| M / R = hysteresis
        (0.5, 0.3, 10.0, {}),
        (0.3, 1.0, 0.1, {"friction.mu": 0.3, "tangential.q_over_mu_p": 0.0}),  # free rolling, coupled
    ],
)
def test_energy_balance(nu, thickness_ratio, ratio, extra):
    """|V| M / R* = hysteresis + frictional power + xi Q |V| within 0.5 %, the hysteresis from the
    layer's loss compliance in Fourier space (references.layer_fourier plus references.hysteresis),
    the moment from the solved pressure (measured 0.002-0.43 % at 60 elements; the second-order
    slip derivative keeps the frictional power's own error small)."""
    _, cover = _rigid_roller(nu, thickness_ratio, ratio, 60, **{"discretization.slip_derivative": "element", **extra})
    r = solve(load_case(cover))
    shafts = r.rolling_resistance_moment / 50.0
    losses = r.hysteresis_power + r.frictional_power_total + r.creep * r.tangential_load
    assert r.hysteresis_power > 0.0
    assert losses == pytest.approx(shafts, rel=0.005)


def test_reversed_rolling_mirrors_the_cover():
    """sgn(V) = +1 mirrors the frictionless cover's pressure (1e-9 p_max: the solver's tolerance) and
    keeps the rolling resistance; the pressure moves towards the leading edge."""
    _, forward = _rigid_roller(0.5, 1.0, 1.0, 40)
    backward = case_dict(forward, **{"rolling.direction": 1})
    f, b = solve(load_case(forward)), solve(load_case(backward))
    np.testing.assert_allclose(b.p_n, f.p_n[::-1], atol=1e-9 * float(-f.p_n.min()))
    assert b.rolling_resistance_coefficient == pytest.approx(f.rolling_resistance_coefficient, rel=1e-6)
    assert f.pressure_centroid > 0.0 > b.pressure_centroid


# --- bad input ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("dotted", "expected"),
    [
        ({"bodies.B.viscoelastic": None}, 'bodies.B.relaxed_young = 5.0: not used by kind = "layered"'),
        ({"bodies.B.creep_time": None}, "bodies.B.creep_time: missing key (viscoelastic = true)"),
        ({"bodies.B.relaxed_young": 20.0}, "bodies.B.relaxed_young = 20: above the glassy modulus young = 10"),
        ({"rolling.speed": None}, "rolling.speed: missing key (bodies.B.viscoelastic = true)"),
        ({"discretization.tolerance": 0.01}, "discretization.tolerance = 0.01: adaptive (graded) meshes"),
        ({"bodies.A": {"kind": "elastic", "radius": 100.0, "young": 5.0, "poisson": 0.3, "viscoelastic": True}},
         'bodies.A.viscoelastic = true: not used by kind = "elastic"'),
        ({"bodies.A": {"kind": "viscoelastic", "radius": 100.0, "young": 5.0, "poisson": 0.3,
                       "relaxed_young": 2.0, "creep_time": 1.0}},
         'bodies.B.kind = "layered": a layer with a viscoelastic half-space'),
    ],
)  # fmt: skip
def test_bad_input_is_one_line_exit_2(tmp_path, dotted, expected):
    data = _cover(_tyre("tyred_fig11_q41"), 5.0, 1.0)
    path = write_case(tmp_path, case_dict(data, **dotted))
    result = run_cli("check", path)
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and expected in lines[0], result.output
    assert "Traceback" not in result.output


@pytest.mark.parametrize("prony", [None, [[12.0, 0.0003], [8.0, 0.003]]])
def test_shipped_cover_and_a_prony_cover_balance_their_energy(prony):
    """cases/rubber_cover.toml (driven, Q/(mu P) = 0.3) and the same cover with a two-term Prony series
    (two history terms): the shafts' power equals hysteresis + friction + xi Q within 0.5 % (measured
    1e-4 and 1.3e-4), with a positive rolling resistance; the effects line names the model."""
    with open(CASES / "rubber_cover.toml", "rb") as handle:
        data = tomllib.load(handle)
    if prony is not None:
        data = case_dict(data, **{"bodies.B.relaxed_young": None, "bodies.B.creep_time": None, "bodies.B.prony": prony})
    r = solve(load_case(data))
    shafts = r.rolling_resistance_moment / 25.0
    losses = r.hysteresis_power + r.frictional_power_total + r.creep * r.tangential_load
    assert r.rolling_resistance_coefficient > 0.0
    assert losses == pytest.approx(shafts, rel=0.005)
    assert ("Prony (2 terms)" if prony else "B: SLS, V tau_c / a = 0.813") in r.effects_line


def test_fourier_offsets_do_not_depend_on_the_phase_blocks(monkeypatch):
    """The phases in blocks of wavenumbers (bounded memory) sum to the one-block result (round-off,
    1e-13 of the largest entry)."""
    grid = ContactGrid(1.5, 20, 2)
    whole = layer.fourier_offsets(grid, 0.1, 0.4, (0.5, -3.0))
    monkeypatch.setattr(layer, "_PHASES", 1000)
    blocks = layer.fourier_offsets(grid, 0.1, 0.4, (0.5, -3.0))
    assert np.max(np.abs(whole - blocks)) < 1e-13 * np.max(np.abs(whole))
