"""The creep-force curve's turning points with friction that falls with the slip speed (issue 23
item 3): found by the slope's sign change, used to bracket the high-slip branch, to explain a force
beyond the peak, and to trace `--curve load` through both turns."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from test_friction_laws import EXPONENTIAL, SMALL, law_case, solve

import rolling_cli
from helpers import CARTER, case_dict, run_cli, write_case
from rolling_cli import pipeline
from rolling_cli.pipeline import branches
from rolling_cli.study import sweep


def test_the_turning_point_is_a_local_maximum_of_q():
    """The peak found by the regula falsi on dQ/dxi is checked on Q alone (another route): |Q| at the
    peak's creepage is no smaller than at 0.98 and 1.02 times it. Within the bracket tolerance
    (1e-3 of xi) |Q| is 1e-6 of the peak's below the true peak, while the curvature drops |Q| by
    ~(1/2)(0.02)^2 ~ 2e-4 of it at +-2 %: the margin 1e-5 |Q| separates the two by 20x."""
    case = rolling_cli.load_case(law_case(CARTER, EXPONENTIAL, **SMALL, **{"tangential.creep": -0.002}))
    peak = branches.peak_on_side(case, -1.0, pipeline.solve, pipeline.prepare)
    assert peak is not None and peak.branch in ("rising", "falling")
    q_peak = abs(peak.tangential_load)
    for factor in (0.98, 1.02):
        near = solve(case_dict(law_case(CARTER, EXPONENTIAL, **SMALL), **{"tangential.creep": factor * peak.creep}))
        assert abs(near.tangential_load) <= q_peak * (1.0 + 1e-5)
    assert 0.6 < peak.q_over_mu_p < 0.8  # Q/(mu_s P) peaks between mu_k/mu_s = 0.6 and 0.8 (README: 0.71)
    other = branches.peak_on_side(case, 1.0, pipeline.solve, pipeline.prepare)  # similar bodies: antisymmetric
    assert other.creep == pytest.approx(-peak.creep, rel=1e-9)
    assert other.q_over_mu_p == pytest.approx(-peak.q_over_mu_p, rel=1e-9)


def test_high_slip_next_to_the_peak_brackets_from_the_peak():
    """Q/(mu_s P) = 0.70, 1.5 % below the peak: the walk from the low-slip solution steps over the peak
    in one step; the bracket must start at the peak (before: it started from the low-slip solution,
    and the force-controlled solve fell back to it: an error). Both solutions hold Q."""
    data = law_case(CARTER, EXPONENTIAL, **SMALL, **{"tangential.q_over_mu_p": 0.70})
    high = solve(case_dict(data, **{"solver.branch": "high-slip"}))
    low = solve(case_dict(data, **{"solver.branch": "low-slip"}))
    assert high.branch == "falling" and low.branch == "rising"
    assert abs(high.creep) > abs(low.creep)
    for result in (high, low):
        bound = result.tolerance_applied * result.traction_scale * float(result.weights.sum())
        assert abs(result.tangential_load - 0.70 * 0.30 * result.normal_load) <= bound


def test_a_force_beyond_the_peak_is_explained(tmp_path):
    """Q/(mu_s P) = 0.792 exceeds the peak (0.71): no steady solution on either branch. The solve
    exits non-zero naming the turning point, not 'Newton did not converge', and writes nothing."""
    data = law_case(CARTER, EXPONENTIAL, **SMALL, **{"tangential.q_over_mu_p": 0.792})
    path = write_case(tmp_path, data)
    out = tmp_path / "over.h5"
    result = run_cli("solve", path, "-o", out)
    assert result.exit_code == 1
    assert "no steady solution with tangential.q_over_mu_p = 0.792: the creep-force curve turns at" in result.output
    assert "Traceback" not in result.output and not out.exists()


def test_load_curve_runs_through_both_turning_points(tmp_path):
    """`--curve load` on a falling law: the points follow the curve in creepage order (high-slip,
    low-slip across Q = 0, high-slip), every one converges on the branch it asked for, and each
    turn is met from both sides at the same force (two solutions, the high-slip one farther out)."""
    case = rolling_cli.load_case(law_case(CARTER, EXPONENTIAL, **SMALL, **{"tangential.q_over_mu_p": 0.5}))
    spec = sweep.curve_spec(case, "load", 11)
    assert spec.keys == ("tangential.q_over_mu_p", "solver.branch") and spec.size == 11
    out = tmp_path / "load.h5"
    report = sweep.run(case, spec, str(out), workers=1)
    assert report.failed == []
    with h5py.File(out, "r") as handle:
        creep, q = handle["creep"][:], handle["q_over_mu_p"][:]
        branch = [b.decode() for b in handle["branch"][:]]
        assert handle["converged"][:].all()
    asked = [spec.combination(i)["solver.branch"] for i in range(spec.size)]
    assert np.all(np.diff(creep) > 0.0)  # in creepage order through the turns
    for got, wanted, xi in zip(branch, asked, creep, strict=True):
        assert got == branches.BRANCHES[wanted] or (xi == 0.0 and got == "")
    turns = [i for i in range(1, spec.size) if asked[i] != asked[i - 1]]
    assert len(turns) == 2
    for i in turns:
        assert q[i] == pytest.approx(q[i - 1], rel=1e-6)
        outer = i - 1 if asked[i - 1] == "high-slip" else i
        inner = i if outer == i - 1 else i - 1
        assert abs(creep[outer]) > abs(creep[inner])
