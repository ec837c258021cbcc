"""Warm paths as well as cold ones: creep-force curves and hard layers through the real sweep.

* ``rollc sweep --curve load|creep`` (41 points, warm starts on, the default) on
  the shipped Carter, dissimilar and tyred cases: every case converges and obeys
  the contact laws, and the median Newton iterations of the warm-started cases is
  no larger than that of cold starts of the same cases (every fourth point solved
  cold again, to keep the test short).
* A thin incompressible layer (b/a = 0.05, nu = 0.5) under overlap control, with
  Q of the sign of V, both rolling directions: converged within the default
  solver.max_iterations (it took 125-152 iterations before the solver layer was
  rebuilt, and failed within 100).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from helpers import assert_contact_laws, case_dict, solve
from rolling_cli import pipeline
from rolling_cli.case import load_case, with_overrides
from rolling_cli.pipeline import solve as solve_case
from rolling_cli.solver import strategies
from rolling_cli.study import sweep
from rolling_cli.study.path import result_state

CASES = Path(__file__).resolve().parents[1] / "cases"


@pytest.mark.parametrize("kind", ["load", "creep"])
@pytest.mark.parametrize("name", ["carter", "dissimilar_q75", "dissimilar_qm83", "tyred_fig11_q41"])
def test_creep_force_curve_converges_and_warm_starts_pay(tmp_path, name, kind):
    base = load_case(CASES / f"{name}.toml")
    spec = sweep.curve_spec(base, kind, 41)
    report = sweep.run(base, spec, str(tmp_path / "curve.h5"), workers=1)
    assert len(report.records) == 41 and not report.failed, [r.message for r in report.failed]
    warm = []
    for record in report.records.values():
        assert_contact_laws(record.result, tolerance=record.result.tolerance_applied)
        if record.result.start == "warm":
            warm.append(record.result.iterations)
    assert len(warm) >= 25  # all but the first case or two of each chunk
    key = spec.keys[0]
    cold = [solve_case(with_overrides(base, {key: value})).iterations for value in spec.values[0][::4]]
    assert np.median(warm) <= np.median(cold)


def test_carter_load_curve_takes_one_iteration_per_warm_case(tmp_path):
    """On a load curve of similar cylinders P stays fixed, so a warm case's pressure is already the
    converged one (its normal stage takes no iteration, where a cold case needs one from Hertz), and
    the better of the neighbours' secant and Carter's closed-form traction has the discrete stick and
    slip nodes but for a node or two: one tangential iteration. The closed form must be chosen where
    it is better (near full slip, where the stick/slip boundary moves like sqrt(1 - Q/(mu P)) and a
    secant misplaces it: 84 iterations for the 41 cases with the neighbours' traction alone, 56 with
    the better of the two, 87 all cold)."""
    base = load_case(CASES / "carter.toml")
    report = sweep.run(base, sweep.curve_spec(base, "load", 41), str(tmp_path / "curve.h5"), workers=1)
    warm = [r.result for r in report.records.values() if r.result.start == "warm"]
    assert np.median([r.iterations for r in warm]) == 1
    assert {r.start_traction for r in warm} == {"neighbours", "closed form"}


@pytest.mark.parametrize("direction", [-1, 1])
@pytest.mark.parametrize("q", [0.5, 0.7, 0.95])
def test_thin_incompressible_layer_under_overlap_control(q, direction):
    layer = {"kind": "layered", "radius": 100.0, "young": 10.0, "poisson": 0.5, "layer_thickness": 0.05}
    data = case_dict(
        **{
            "bodies.A": {"kind": "rigid", "radius": 100.0},
            "bodies.B": layer,
            "normal.overlap": 0.004,
            "tangential.q_over_mu_p": q * direction,  # Q of the sign of V
            "rolling.direction": direction,
            "discretization.influence": "bem",
            "discretization.contact_elements": 140,
        }
    )
    r = solve(data)
    assert r.converged and r.iterations <= 100
    assert_contact_laws(r)
    assert r.q_over_mu_p == pytest.approx(q * direction, abs=1e-9)
    assert 0.04 <= 0.05 / r.contact_half_width <= 0.06  # b/a = 0.05


def test_cold_cases_of_a_layer_under_creepage_control_settle_the_pressure_first(tmp_path):
    """--no-warm-start on a prebuilt system has no pre-solve levels: on a layer under creepage control
    the closed-form start (Hertz pressure, Carter's full-slip traction) is settled (normal problem with
    p_t = 0 first) before the coupled Newton, which from the raw start cycled for 45 iterations a case
    near full slip; under load control the start stays direct."""
    base = load_case(CASES / "tyred_fig11_q41.toml")
    spec = sweep.curve_spec(base, "creep", 41)
    items = [(i, spec.combination(i)) for i in (33, 35)]
    records = list(sweep.solve_items(base, items, False, True))
    for record in records:
        assert record.converged, record.message
        assert_contact_laws(record.result, tolerance=record.result.tolerance_applied)
        assert record.result.strategies.startswith("case grid: settled")
        assert record.result.iterations <= 12  # settled: 7-8 here; from the raw start 45
    loaded = list(sweep.solve_items(base, [(0, {"tangential.q_over_mu_p": 0.5})], False, True))
    assert loaded[0].converged and loaded[0].result.strategies.startswith("case grid: direct")


@pytest.mark.parametrize(
    "name, kind, retry",
    [
        ("dissimilar_q04", "load", "direct, closed-form start"),
        ("tyred_fig11_q41", "creep", "settled, closed-form start"),
    ],
)
def test_a_failed_warm_start_is_retried_from_the_closed_form_start(monkeypatch, name, kind, retry):
    """Through the pipeline: a warm start (a converged neighbour) whose first strategy fails is solved
    next from the closed-form start, with the strategy a cold start of the case gets (settled on a
    layer under creepage control). The failing first attempt here takes no iteration, so the case
    then takes exactly the iterations of its cold solve on the same system."""
    base = load_case(CASES / f"{name}.toml")
    spec = sweep.curve_spec(base, kind, 21)
    case = with_overrides(base, spec.combination(15))
    _, system = pipeline.prepare(case)
    neighbour = solve_case(with_overrides(base, spec.combination(14)), system=system)
    cold = solve_case(case, system=system)
    real_direct = strategies.direct

    def first_fails(task, start, budget, cold=False, globalisation=None, name="direct"):
        if name == "direct":
            raise strategies.StrategyFailed(name, "stage", "stagnation", start, 1.0)
        return real_direct(task, start, budget, cold=cold, globalisation=globalisation, name=name)

    monkeypatch.setattr(strategies, "direct", first_fails)
    r = solve_case(case, start=result_state(neighbour), system=system)
    assert r.converged and r.start == "warm" and retry in r.strategies
    assert_contact_laws(r, tolerance=r.tolerance_applied)
    assert r.iterations == cold.iterations
    assert np.max(np.abs(r.p_t - cold.p_t)) <= 1e-8 * case.friction.mu * float(np.max(-cold.p_n))
