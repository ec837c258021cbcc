"""Simulate only the effects a case calls for: every skip is exact, and says so."""

import json
import logging

import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, dissimilar, solve

RIGID = {"kind": "rigid", "radius": 100.0}


def _effects(result) -> dict:
    return json.loads(result.effects)


@pytest.mark.parametrize(
    "label,data",
    [
        ("similar half-planes", case_dict()),
        ("rigid on incompressible half-plane", case_dict(**{"bodies.A": RIGID, "bodies.B.poisson": 0.5})),
        (
            "identical BEM bodies",
            case_dict(**{"discretization.influence": "bem", "discretization.contact_elements": 60}),
        ),
    ],
)
def test_decoupled_equals_coupled_when_beta_is_zero(label, data):
    """beta = 0: the normal-then-tangential solve equals the coupled Newton solve
    (forced with effects.coupling = "on", whose cross blocks are then exactly zero)
    to 1e-10 of the traction scale, and the default never forms the cross blocks."""
    auto = solve(data)
    forced = solve(case_dict(data, **{"effects.coupling": "on"}))
    assert _effects(auto)["strategy"] == "decoupled" and not _effects(auto)["coupling"]
    assert _effects(forced)["strategy"] == "coupled"
    scale = auto.hertz_p0
    assert np.max(np.abs(auto.p_n - forced.p_n)) <= 1e-10 * scale, label
    assert np.max(np.abs(auto.p_t - forced.p_t)) <= 1e-10 * scale, label
    assert auto.creep == pytest.approx(forced.creep, rel=1e-10, abs=1e-16)
    assert "coupling: skipped" in auto.effects_line


def test_no_tangential_load_with_beta_zero_skips_the_tangential_problem():
    r = solve(case_dict(**{"tangential.q_over_mu_p": None}))
    effects = _effects(r)
    assert not effects["tangential"] and effects["strategy"] == "normal"
    assert "tangential: skipped" in r.effects_line
    assert np.all(r.p_t == 0.0) and r.creep == 0.0
    assert np.all(r.state[r.p_n < 0] == 1)  # no slip anywhere: all contact nodes adhere
    # the same case with the tangential problem solved gives p_t = 0 too
    forced = solve(case_dict(**{"tangential.q_over_mu_p": None, "effects.coupling": "on"}))
    assert np.max(np.abs(forced.p_t)) <= 1e-10 * r.hertz_p0


def test_frictionless_has_no_tangential_unknowns():
    r = solve(case_dict(**{"friction.mu": 0.0, "tangential.creep": 1e-3}))
    assert "skipped: frictionless" in r.effects_line
    assert np.all(r.p_t == 0.0)
    assert np.all(r.state[r.p_n < 0] == 2)  # everything slips freely
    assert_contact_laws(r)


def test_free_rolling_of_dissimilar_bodies_is_not_skipped():
    r = solve(dissimilar(**{"tangential.q_over_mu_p": None}))
    assert _effects(r)["tangential"] and _effects(r)["coupling"]
    assert "coupling: simulated: dissimilar materials" in r.effects_line


def test_forcing_coupling_off_warns_about_a_real_effect(caplog):
    with caplog.at_level(logging.WARNING, logger="rolling_cli"):
        r = solve(dissimilar(**{"effects.coupling": "off"}))
    assert any("drops a real effect" in rec.message for rec in caplog.records)
    assert _effects(r)["warnings"] and "beta" in _effects(r)["warnings"][0]
    assert _effects(r)["strategy"] == "decoupled"


def test_rigid_body_and_identical_bodies_need_no_extra_influence():
    r = solve(
        case_dict(**{"bodies.A": RIGID, "discretization.influence": "bem", "discretization.contact_elements": 30})
    )
    notes = _effects(r)["notes"]
    assert notes["influence A"] == "skipped: rigid body, no mesh"
    same = solve(case_dict(**{"discretization.influence": "bem", "discretization.contact_elements": 30}))
    assert _effects(same)["notes"]["influence B"] == "reused: identical to body A"


LAYER = {"kind": "layered", "radius": 100.0, "young": 10.0, "poisson": 0.5, "layer_thickness": 0.1}


@pytest.mark.parametrize(
    "label,dotted,model,why",
    [
        ("half-spaces, load", {}, "half-plane", "auto: two half-spaces under load control"),
        ("rigid on elastic, load", {"bodies.A": RIGID}, "half-plane", "auto: two half-spaces under load control"),
        ("overlap", {"normal.overlap": 0.015}, "bem", "auto: overlap control"),
        ("layer", {"bodies.A": RIGID, "bodies.B": LAYER, "normal.overlap": 0.0042}, "bem", "auto: body B is layered"),
        ("forced bem", {"discretization.influence": "bem"}, "bem", 'discretization.influence = "bem"'),
        ("forced half-plane", {"discretization.influence": "half-plane"}, "half-plane", 'influence = "half-plane"'),
    ],
)
def test_auto_influence_picks_the_closed_form_where_it_is_exact(label, dotted, model, why):
    """discretization.influence defaults to "auto": the closed-form half-plane for two
    half-spaces under load control, the BEM for an overlap or a layer; "bem" and
    "half-plane" force a model. The choice and its reason are in the effects (JSON and the
    summary line), and the result's ``influence`` attribute is the resolved model."""
    from rolling_cli import load_case
    from rolling_cli.pipeline.effects import decide

    data = case_dict(**{"discretization.influence": None, **dotted})
    effects = decide(load_case(data))
    assert effects.influence == model, label
    assert why in effects.notes["influence"], label
    assert json.loads(effects.to_json())["influence"] == model
    if label in ("half-spaces, load", "overlap"):
        r = solve(case_dict(data, **{"discretization.contact_elements": 30}))
        assert r.influence == model and why in r.effects_line


def test_constant_elements_with_an_automatic_bem_are_rejected_naming_the_reason():
    from rolling_cli import load_case
    from rolling_cli.errors import CaseError

    with pytest.raises(CaseError, match=r"discretization.element.*auto: overlap control"):
        load_case(
            case_dict(
                **{"discretization.influence": "auto", "discretization.element": "constant", "normal.overlap": 0.015}
            )
        )
    assert load_case(case_dict(**{"discretization.influence": "auto", "discretization.element": "constant"}))


def test_bem_half_spaces_with_beta_zero_are_decoupled():
    """The BEM now models half-spaces, so a rigid body on an incompressible one has exactly zero
    cross compliance (Carter is exact for it): the coupling is skipped, as for the closed form."""
    r = solve(
        case_dict(
            **{
                "bodies.A": RIGID,
                "bodies.B.poisson": 0.5,
                "discretization.influence": "bem",
                "discretization.contact_elements": 30,
            }
        )
    )
    assert "coupling: skipped: beta (Dundurs) = 0, exactly decoupled (the BEM models half-spaces)" in r.effects_line
    assert "influence B: simulated: BEM half-space" in r.effects_line


def test_error_estimate_reports_nan_and_why_when_no_comparison_mesh_solves(monkeypatch):
    from rolling_cli import load_case
    from rolling_cli.errors import ConvergenceError
    from rolling_cli.pipeline import estimate

    case = load_case(case_dict(**{"discretization.contact_elements": 20}))
    result = solve(case_dict(**{"discretization.contact_elements": 20}))

    def fail(*args, **kwargs):
        raise ConvergenceError("Newton did not converge", cause="test")

    monkeypatch.setattr(estimate, "solve", fail)
    estimate.add_error_estimate(case, result)
    assert np.isnan(result.error_estimate) and result.error_estimate_note.startswith("no estimate: the half mesh")
