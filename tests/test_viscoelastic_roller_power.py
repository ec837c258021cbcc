"""Power balance of a viscoelastic finite roller on a rigid flat (issue 22, Checks "Energy balance").

Two routes (rolling_cli/model/power_balance.py): the rolling-resistance force F_rr from the contact
tractions, the geometry of the flat and the solver's surface displacements (its real-space history),
against the losses L = hysteresis (Michell's loss compliance summed mode by mode,
references.annulus.hysteresis_power) + frictional power (the solver's slip, nodal weights) + xi Q.
Tolerance 0.5 % (the issue's): the two routes differ by the modal against the real-space history
(0.05 %, tests/test_viscoelastic_cylinder.py::test_body_power_is_the_modal_loss) and by the nodal
rule of the frictional power on a slip with kinks at the stick/slip boundary (0.1-0.3 % of L at 60
elements, halving with the element size: benchmarks/RESULTS.md).
"""

from __future__ import annotations

import math

import pytest

from helpers import case_dict
from rolling_cli.case import load_case
from rolling_cli.pipeline import solve


def _losses(r) -> float:
    """hysteresis + frictional power + xi Q per unit |V| [force/length]."""
    return r.hysteresis_power + r.frictional_power_total + r.creep * r.tangential_load


def _hollow(load: float, speed: float) -> dict:
    """A solid-material hollow roller (R = 10, bore 5, SLS E_g = 2 E_r = 20, tau_c = 1, nu = 0.4) on
    a rigid flat, driven at Q/(mu P) = 0.3 (mu = 0.5), 60 quadratic elements over 1.5 a."""
    body = {"kind": "viscoelastic", "radius": 10.0, "young": 20.0, "relaxed_young": 10.0, "creep_time": 1.0,
            "poisson": 0.4, "shape": "cylinder", "inner_radius": 5.0}  # fmt: skip
    return case_dict({
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
        "friction": {"mu": 0.5},
        "normal": {"load": load},
        "tangential": {"q_over_mu_p": 0.3},
        "rolling": {"direction": -1, "speed": speed},
        "discretization": {"element": "quadratic", "contact_elements": 60, "zone": 1.5},
    })  # fmt: skip


def test_shipped_rubber_roller_balances():
    """cases/rubber_roller_finite.toml (a/R = 0.12, driven, nu = 0.49 cover): F_rr = L within 0.5 %
    (measured 0.19 %), and F_rr / P is the coefficient written out. The half-space's |V| M / R misses
    the displaced points' torque T_u: more than 10 % of L here (measured 16.9 %), so the correction is
    what closes the balance (it is T_u / R to within the same 0.5 %)."""
    r = solve(load_case("cases/rubber_roller_finite.toml"))
    losses = _losses(r)
    assert r.hysteresis_power > 0.0 and r.frictional_power_total > 0.0
    assert r.rolling_resistance_force == pytest.approx(losses, rel=5e-3)
    assert r.rolling_resistance_coefficient == pytest.approx(r.rolling_resistance_force / r.normal_load, rel=1e-12)
    naive = r.rolling_resistance_moment / 25.0
    assert abs(naive / losses - 1.0) > 0.1
    sign = -1.0  # sgn(V) of the case
    assert naive - sign * r.shaft_torque_displacement / 25.0 == pytest.approx(losses, rel=5e-3)


@pytest.mark.parametrize(("load", "speed", "ratio"), [(0.35, 0.5, 0.05), (17.0, 3.0, 0.30)])
def test_driven_roller_balances_at_small_and_large_a_over_r(load, speed, ratio):
    """The hollow roller at a/R = 0.05 and 0.3 (V tau_c / a ~ 1): F_rr = L within 0.5 % (measured
    0.17 % and 0.32 %), while M / R is off by O(a/R) (measured 6.0 % and 64 %)."""
    r = solve(load_case(_hollow(load, speed)))
    assert r.contact_half_width / 10.0 == pytest.approx(ratio, rel=0.05)
    losses = _losses(r)
    assert r.rolling_resistance_force == pytest.approx(losses, rel=5e-3)
    assert abs(r.rolling_resistance_moment / 10.0 / losses - 1.0) > 0.5 * ratio


@pytest.mark.parametrize("direction", [-1, 1])
def test_free_rolling_balances_both_directions(direction):
    """Frictionless (Q = 0) at a/R ~ 0.26, both rolling directions: F_rr equals the modal hysteresis
    within 0.5 % (measured 0.04 % both ways: without friction only the modal against the real-space
    history is left)."""
    data = case_dict(_hollow(12.0, 2.6), **{"friction.mu": 0.0, "tangential.q_over_mu_p": None,
                                             "rolling.direction": direction})  # fmt: skip
    r = solve(load_case(data))
    assert r.rolling_resistance_force == pytest.approx(r.hysteresis_power, rel=5e-3)
    assert r.rolling_resistance_force > 0.0


def test_only_a_finite_roller_on_a_flat_has_the_force():
    """A viscoelastic half-plane case writes NaN for F_rr and keeps M / (P R*) as its coefficient."""
    data = case_dict(_hollow(1.0, 1.0), **{"bodies.A.shape": None, "bodies.A.inner_radius": None})
    r = solve(load_case(data))
    assert math.isnan(r.rolling_resistance_force) and math.isnan(r.shaft_torque_displacement)
    expected = r.rolling_resistance_moment / (r.normal_load * 10.0)
    assert r.rolling_resistance_coefficient == pytest.approx(expected, rel=1e-12)
