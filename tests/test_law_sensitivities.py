"""Sensitivities with a slip-speed friction law (:mod:`rolling_cli.solver.law_sensitivity`).

Every recorded derivative against a central difference of re-solves (relative step
:data:`sensitivity_checks.STEP` = 1e-6 on the same grid, as tests/sensitivity_checks.py does),
on Carter's cylinders with the exponential law (cases/falling_exponential.toml at 100
elements), under creepage and force control, on the rising and the falling branch of
the creep-force curve. The law's scale is differenced by scaling mu_static and mu_kinetic
together (mu(s) -> (1 + e) mu(s)); the load by whole re-solves (rollc's grid follows
the Hertz a, the derivative recorded is that of ``rollc solve``'s result).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from sensitivity_checks import STEP, TOLERANCE, _outcome_of, _resolve

import rolling_cli
from helpers import case_dict, dissimilar
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.report.summary import summary
from rolling_cli.solver.formulation import State

CASE = Path(__file__).resolve().parent.parent / "cases" / "falling_exponential.toml"
SMALL = {"discretization.contact_elements": 100, "solver.tolerance": 1e-13}


#: Q/(mu_s P) of each branch's point: the case's 0.5 on the rising branch; the falling branch
#: levels off at mu_k/mu_s = 0.6 (full sliding), so its point is taken at 0.65, between that and
#: the curve's peak.
RATIOS = {"low-slip": 0.5, "high-slip": 0.65}


def _base(branch: str) -> dict:
    data = tomllib.loads(CASE.read_text())
    return case_dict(data, **SMALL, **{"solver.branch": branch, "tangential.q_over_mu_p": RATIOS[branch]})


def _dissimilar() -> dict:
    """The case's law on aluminium against steel (coupled normal and tangential problems)."""
    data = _base("low-slip")
    data["bodies"] = dissimilar()["bodies"]
    return data


def _scaled_law(data: dict, factor: float) -> dict:
    """``data`` with the law scaled as a whole: mu(s) -> factor mu(s)."""
    law = data["friction"]
    if "mu_kinetic" not in law:  # Polach: mu_kinetic = A mu_static scales with mu_static
        return case_dict(data, **{"friction.mu_static": law["mu_static"] * factor})
    return case_dict(
        data, **{"friction.mu_static": law["mu_static"] * factor, "friction.mu_kinetic": law["mu_kinetic"] * factor}
    )


def _differences(data: dict, force_control: bool):
    """(base result, {name: (recorded, central difference, scale, node states changed)})."""
    case = load_case(data)
    the_plan, system = pipeline.prepare(case)
    base = pipeline.solve(case, system=system)
    assert base.converged and not base.zone_note
    if force_control:
        data = case_dict(data, **{"tangential.load": base.tangential_load})
    else:
        data = case_dict(data, **{"tangential.creep": base.creep, "solver.branch": None})  # no branch choice
    base = pipeline.solve(load_case(data), system=system)
    if case.normal.load is None:  # the derivatives hold P: re-solved under load control at the solved P
        data = case_dict(data, **{"normal.load": base.normal_load})
    start = State(base.p_n, base.p_t, base.solved_overlap, base.creep)
    reference = _outcome_of(base)
    load, q, xi, speed = base.normal_load, base.tangential_load, base.creep, base.rolling_speed
    out_name = "creep" if force_control else "force"

    def central(moved, whole: bool = False):
        runs = [
            _outcome_of(pipeline.solve(load_case(moved(sign)))) if whole else _resolve(moved(sign), system, start)
            for sign in (1.0, -1.0)
        ]
        changed = not all(np.array_equal(run.states, reference.states) for run in runs)
        return getattr(runs[0], out_name) - getattr(runs[1], out_name), runs, changed

    force_scale = base.mu * load
    creep_scale = max(abs(xi), base.mu * base.hertz_a / the_plan.radius)
    out_scale = creep_scale if force_control else force_scale
    prefix = "dxi" if force_control else "dQ"
    found = {}
    d, _, changed = central(lambda s: _scaled_law(data, 1.0 + s * STEP))  # d/d mu_static, the law scaled with it
    found[f"{prefix}_dmu"] = (d / (2 * STEP * base.mu), out_scale / base.mu, changed)
    d, _, changed = central(lambda s: case_dict(data, **{"rolling.speed": speed * (1.0 + s * STEP)}))
    found[f"{prefix}_dV"] = (d / (2 * STEP * speed), out_scale / speed, changed)
    if pipeline.hertz_applies(case):  # else no P-derivatives with a law (law_sensitivity's docstring)
        d, runs, changed = central(lambda s: case_dict(data, **{"normal.load": load * (1.0 + s * STEP)}), whole=True)
        found[f"{prefix}_dP"] = (d / (runs[0].load - runs[1].load), out_scale / load, changed)
        d_peak = (runs[0].peak - runs[1].peak) / (runs[0].load - runs[1].load)
        found["dp0_dP"] = (d_peak, reference.peak / load, changed)
    if force_control:
        d, runs, changed = central(lambda s: case_dict(data, **{"tangential.load": q * (1.0 + s * STEP)}))
        found["dxi_dQ"] = (d / (runs[0].force - runs[1].force), creep_scale / force_scale, changed)
    else:
        d, runs, changed = central(lambda s: case_dict(data, **{"tangential.creep": xi * (1.0 + s * STEP)}))
        found["dQ_dxi"] = (d / (runs[0].creep - runs[1].creep), force_scale / creep_scale, changed)
    return base, found


def _assert_matches(base, found: dict) -> None:
    """Each recorded derivative within :data:`TOLERANCE` of its difference (relative to
    max(|value|, scale/10)), the node states the same at both ends of every difference (else the
    difference is no fair reference and the test says so)."""
    for name, (difference, scale, changed) in found.items():
        assert not changed, f"{name}: the node states change within the step"
        recorded = getattr(base, name)
        error = abs(recorded - difference) / max(abs(recorded), 0.1 * scale)
        assert error <= TOLERANCE, f"{name}: recorded {recorded:.10g}, difference {difference:.10g} ({error:.2e})"


@pytest.mark.parametrize("force_control", [False, True], ids=["creep", "force"])
@pytest.mark.parametrize("branch", ["low-slip", "high-slip"])
def test_law_sensitivities_match_central_differences(branch, force_control):
    """Each recorded derivative within :data:`TOLERANCE` (1e-5, relative to max(|value|, scale/10):
    the differences' truncation ~1e-12 and the re-solves' residual 1e-13 mu P over the step 1e-6,
    ~1e-7 of the scale, both far below) of its central difference; the node states the same at
    both ends of every difference (else the difference is no fair reference and the test says so)."""
    base, found = _differences(_base(branch), force_control)
    assert base.branch == ("rising" if branch == "low-slip" else "falling")
    _assert_matches(base, found)


@pytest.mark.parametrize("force_control", [False, True], ids=["creep", "force"])
def test_coupled_law_sensitivities_match_central_differences(force_control):
    """Dissimilar bodies (the pressure moves with the tangential problem: the coupled velocity
    system, and the homogeneity's dp0/dP takes the peak's own derivatives along xi or Q and |V|):
    every derivative within :data:`TOLERANCE` of its difference (as above)."""
    base, found = _differences(_dissimilar(), force_control)
    names = {"dxi_dmu", "dxi_dV", "dxi_dQ", "dxi_dP"} if force_control else {"dQ_dmu", "dQ_dV", "dQ_dxi", "dQ_dP"}
    assert set(found) == names | {"dp0_dP"}
    _assert_matches(base, found)
    assert math.isfinite(base.da_dP)


def test_coulomb_friction_records_no_speed_derivative():
    """A constant law: the Coulomb sensitivities as before, and no dQ_dV/dxi_dV (not recorded, None),
    nor their summary line; dQ/dxi equals the law case's at mu_kinetic = mu_static (the same
    friction everywhere: the velocity Newton and the Coulomb elimination solve one problem)."""
    data = _base("low-slip")
    coulomb = case_dict(data, **{"solver.branch": None})
    coulomb["friction"] = {"mu": data["friction"]["mu_static"]}
    result = rolling_cli.solve(load_case(coulomb))
    assert result.dQ_dV is None and result.dxi_dV is None
    assert "rolling speed:" not in summary(result)
    flat = case_dict(data, **{"solver.branch": None, "friction.mu_kinetic": data["friction"]["mu_static"]})
    law = rolling_cli.solve(load_case(flat))
    assert law.dQ_dV == 0.0 or abs(law.dQ_dV) <= 1e-12 * abs(law.dQ_dxi)
    # the same problem solved two ways: the two Newtons' last LUs, round-off ~1e-10 relative
    assert law.dQ_dxi == pytest.approx(result.dQ_dxi, rel=1e-8)
    assert law.dxi_dmu == pytest.approx(result.dxi_dmu, rel=1e-8)


def test_overlap_controlled_law_sensitivities_hold_the_load():
    """Overlap control (dissimilar bodies, creepage control): differentiated as the load-controlled
    problem at its own load, so dQ/dxi, dQ/dmu and dQ/dV match differences of re-solves with P held
    (as above); no P-derivatives (NaN: no homogeneity, module docstring)."""
    data = case_dict(_dissimilar(), **{"normal.overlap": 0.01, "solver.branch": None, "tangential.creep": -0.002})
    base, found = _differences(data, False)
    assert set(found) == {"dQ_dmu", "dQ_dV", "dQ_dxi"}
    _assert_matches(base, found)
    assert all(math.isnan(getattr(base, name)) for name in ("dQ_dP", "dxi_dP", "da_dP", "dp0_dP"))


def test_viscoelastic_law_case_records_no_speed_or_load_derivative():
    """A viscoelastic body: |V| enters its influence (V tau / a) as well as the law's s_a, and the
    load homogeneity does not hold: dQ/dV, dxi/dV and the P-derivatives are NaN, the derivatives
    in xi, Q and the law's scale recorded (finite)."""
    data = tomllib.loads((CASE.parent / "rubber_roller.toml").read_text())
    data = case_dict(data, **{"discretization.contact_elements": 100})
    data["friction"] = {"law": "exponential", "mu_static": 0.5, "mu_kinetic": 0.3, "slip_velocity_half": 100.0}
    result = rolling_cli.solve(load_case(data))
    assert result.converged
    assert all(math.isnan(getattr(result, name)) for name in ("dQ_dV", "dxi_dV", "dQ_dP", "dxi_dP", "da_dP"))
    assert all(math.isfinite(getattr(result, name)) for name in ("dQ_dxi", "dQ_dmu", "dxi_dQ", "dxi_dmu"))


@pytest.mark.parametrize("force_control", [False, True], ids=["creep", "force"])
def test_polach_law_sensitivities_match_central_differences(force_control):
    """Polach's law (mu_s = 0.3, A = 0.6, B = 0.01 s/mm: s_a ~ 90 mm/s here, mu well down its
    fall), another mu(s_a) and d mu/d s_a through the same columns: as above."""
    data = _base("low-slip")
    data["friction"] = {"law": "polach", "mu_static": 0.3, "polach_a": 0.6, "polach_b": 0.01}
    base, found = _differences(data, force_control)
    assert len(found) == 5
    _assert_matches(base, found)
