"""Sensitivities of a converged solve (issue 24 item 1; rolling_cli/solver/sensitivity.py).

References: Carter's closed-form creep-force law and its derivatives
(rolling_cli/references/carter.py), Hertz's a and p0 proportional to sqrt(P),
and central differences of re-solved cases (tests/sensitivity_checks.py) on
random cases of benchmarks/robustness.py's domain.
"""

from __future__ import annotations

import logging
import random
import sys
from pathlib import Path

import numpy as np
import pytest
from sensitivity_checks import TOLERANCE, check_case, is_finite

from helpers import case_dict, dissimilar, run_cli, write_case
from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.files.layout import units_of
from rolling_cli.references import carter
from rolling_cli.solver import reduced, sensitivity
from rolling_cli.solver.formulation import Problem, State, evaluate, node_sets, traction_scales

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import robustness  # noqa: E402


def _solved(data: dict):
    case = load_case(data)
    the_plan, system = pipeline.prepare(case)
    result = pipeline.solve(case, system=system)
    return the_plan, system, result


def _state(result) -> State:
    return State(result.p_n, result.p_t, result.solved_overlap, result.creep)


def _carter_bounds(result, the_plan):
    """Node spacing Delta, Carter's a, c and s = 1 - c/a at the solved Q/(mu P)."""
    spacing = result.node_spacing
    a = result.hertz_a
    c = carter.stick_half_width(result.q_over_mu_p, a)
    return spacing, a, c, 1.0 - c / a


@pytest.mark.parametrize("elements, direction, q", [(100, -1, 0.51), (300, 1, -0.3)])
def test_carter_closed_form(elements, direction, q):
    """dQ/dxi = -(2 P R*/a) c/a, dQ/dmu = sgn(Q) P s^2, dQ/dP = sgn(Q) mu s (s = 1 - c/a), da/dP = a/(2P).

    The grid's error: Carter's dQ/dxi is proportional to the adhesion half-width c, and the
    discrete adhesion zone ends at a node, so c is known to half a node spacing each side:
    relative error <= Delta / (2c) (Delta/(2c) = 5.4e-3 at 100 elements, measured errors 4e-4 at
    100 and 1e-4 at 400; the issue's 1e-6 is below what any of these grids can give). dQ/dmu =
    P s^2 with s = 1 - c/a: a shift of c by Delta/2 moves s by Delta/(2a), 2 s relative:
    Delta/(a s). dQ/dP comes from the homogeneity (module docstring of the sensitivity module),
    Q/P - xi/(2P) dQ/dxi, whose error is xi/(2P) times dQ/dxi's error plus the discrete
    creepage's own error |xi_h - xi_Carter| times |dQ/dxi| / (2P). da/dP = (cell half-width)/(2P):
    the cells end within one node spacing of a, Delta/a.
    """
    data = case_dict(**{"discretization.contact_elements": elements, "rolling.direction": direction})
    data = case_dict(data, **{"tangential.q_over_mu_p": q})
    the_plan, _, r = _solved(data)
    spacing, a, c, s = _carter_bounds(r, the_plan)
    P, R, mu = r.normal_load, the_plan.radius, r.mu
    expected = carter.creep_coefficient(r.q_over_mu_p, P, a, R)
    assert abs(r.dQ_dxi / expected - 1.0) <= spacing / (2.0 * c)
    assert abs(r.dQ_dmu / carter.friction_derivative(r.q_over_mu_p, P) - 1.0) <= spacing / (a * s)
    creep_error = abs(r.creep - carter.creepage(r.q_over_mu_p, a, R, mu))
    bound = (abs(r.creep) * spacing / (2.0 * c) + creep_error) * abs(r.dQ_dxi) / (2.0 * P)
    assert abs(r.dQ_dP - carter.load_derivative(r.q_over_mu_p, mu)) <= bound
    assert abs(r.da_dP / (a / (2.0 * P)) - 1.0) <= spacing / a
    # the two sets are one linearisation: dxi/dQ dQ/dxi = 1 and so on (to rounding)
    assert r.dxi_dQ * r.dQ_dxi == pytest.approx(1.0, rel=1e-12)
    assert r.dxi_dmu == pytest.approx(-r.dQ_dmu / r.dQ_dxi, rel=1e-12)
    assert r.dxi_dP == pytest.approx(-r.dQ_dP / r.dQ_dxi, rel=1e-12)


def test_fixed_states_on_carter():
    """Without the homogeneity (the path of layers and overlap control), on Carter's 200 elements:
    da/dP by the active-set change argument against Hertz's a/(2P) within 10 % (it counts the
    nodes the edge passes: measured within 6 % over a load cycle at 100 elements, the error of one
    node in the span), and d max|p_n|/dP at fixed states against Hertz's p0/(2P) within 5e-3
    (measured 7e-3 at 50 elements, 2e-3 at 200, 5e-4 at 800: the discrete punch mode at the
    edges). dQ/dP at fixed states misses the motion of the contact edge that ends the adhesion
    zone (the module docstring): it is the saw-tooth's slope between node changes, about half of
    the closed form's, which is why load-controlled half-spaces take it from the homogeneity."""
    the_plan, system, r = _solved(case_dict())
    found = sensitivity.sensitivities(system, r.mu, _state(r), force_control=True, self_similar=False)
    P, a, p0 = r.normal_load, r.hertz_a, r.hertz_p0
    assert abs(found.da_dP / (a / (2.0 * P)) - 1.0) <= 0.10
    assert abs(found.dp0_dP / (p0 / (2.0 * P)) - 1.0) <= 5e-3
    assert found.dQ_dP < 0.7 * carter.load_derivative(r.q_over_mu_p, r.mu)
    assert found.dQ_dxi == pytest.approx(r.dQ_dxi, rel=1e-12)  # xi and mu need no homogeneity
    assert found.dQ_dmu == pytest.approx(r.dQ_dmu, rel=1e-12)


def _draws() -> list[tuple[str, dict]]:
    """20 cases of benchmarks/robustness.py's domain: half-spaces (similar and dissimilar, half-plane
    and BEM), layers (load and overlap), plus Carter's and the aluminium/steel pair."""
    rng = random.Random(11)
    cases = [("half-space", robustness.random_case(rng)[0]) for _ in range(12)]
    cases += [("layer", robustness.random_layer_case(rng)[0]) for _ in range(6)]
    cases += [("similar", case_dict(**{"discretization.contact_elements": 40}))]
    cases += [("dissimilar", dissimilar(**{"discretization.contact_elements": 40}))]
    return cases


def test_finite_differences(capsys):
    """Every sensitivity equals a central difference (relative step 1e-6, re-solved) within 1e-5
    (TOLERANCE: tests/sensitivity_checks.py), both controls, except where the zone pattern changes
    within the step: those are reported, not compared. Cases the solver refuses or whose zone
    had to be enlarged are left out; at least 30 of the 40 (case, control) pairs must be
    compared, so that the test cannot pass by leaving everything out."""
    logging.disable(logging.WARNING)  # zone enlargements and warnings of the random draw are expected
    try:
        compared, changes, left_out = 0, [], []
        for k, (kind, data) in enumerate(_draws()):
            for force in (True, False):
                checks = check_case(data, force)
                if isinstance(checks, str):
                    left_out.append(f"{k} {kind}: {checks}")
                    continue
                assert is_finite(checks), (k, kind, force, checks)
                held = 0  # the checks of this case actually compared (not skipped for a zone change)
                for check in checks:
                    if check.pattern_changed:
                        changes.append(f"{k} {kind} {'force' if force else 'creep'} {check.name}")
                        continue
                    assert check.error <= TOLERANCE, (k, kind, force, check)
                    held += 1
                compared += held > 0
    finally:
        logging.disable(logging.NOTSET)
    with capsys.disabled():
        print(f"\nsensitivities: {compared} solves compared; zone pattern changed within the step: {changes or 'none'}")
        print(f"left out: {left_out or 'none'}")
    assert compared >= 30


def test_friction_rows_are_the_matrix_difference():
    """reduced.friction_rows (d(A z - b)/dmu, written from the slip tractions) equals the difference of
    the assembled reduced systems at mu and 2 mu (A is affine in mu at fixed node states), on the
    coupled aluminium/steel case under force control (every row kind present). Rounding: eps times
    the rows' size, relative 1e-9 with margin."""
    the_plan, system, r = _solved(dissimilar())
    state = _state(r)
    w = system.weights
    problem = Problem(system, "coupled", r.mu, load=r.normal_load, force=("load", float(w @ state.p_t)))
    ev = evaluate(problem, state, traction_scales(problem, state))
    sets = node_sets(problem, state, ev)
    base = reduced.reduced_system(problem, state, sets, ev)
    doubled = reduced.reduced_system(problem.held(mu=2.0 * r.mu), state, sets, ev)
    z = reduced.unknowns(problem, state, base)
    difference = ((doubled.matrix @ z - doubled.rhs) - (base.matrix @ z - base.rhs)) / r.mu
    rows = reduced.friction_rows(problem, base, state)
    assert np.abs(rows - difference).max() <= 1e-9 * np.abs(difference).max()
    assert np.abs(difference).max() > 0.0


def test_matrix_free_matches_dense(monkeypatch):
    """On a grid large enough for the matrix-free path (900+ nodes), the Krylov solves give the
    dense LU's sensitivities for the same state: the same linear systems, the Krylov ones solved
    to its target (1e-12 of the scaled residual), so agreement to 1e-7 relative."""
    from rolling_cli.influence import halfplane
    from rolling_cli.influence.build import clear_memo

    data = dissimilar(**{"discretization.contact_elements": 460})
    the_plan, system, r = _solved(data)
    assert system.matrix_free
    monkeypatch.setattr(halfplane, "OPERATOR_NODES", 10**9)
    clear_memo()
    try:
        dense = pipeline.build_contact_system(load_case(data), the_plan, use_cache=False)
    finally:
        clear_memo()
    assert not dense.matrix_free
    expected = sensitivity.sensitivities(dense, r.mu, _state(r), force_control=True, self_similar=True)
    for name, value in expected.as_dict().items():
        assert r.attributes[name] == pytest.approx(value, rel=1e-7), name


def test_outputs(tmp_path):
    """The summary prints the creep coefficient, the file declares units, ``rollc export`` writes them."""
    case = write_case(tmp_path, case_dict(**{"discretization.contact_elements": 40}))
    out = tmp_path / "c.h5"
    result = run_cli("solve", case, "-o", out)
    assert result.exit_code == 0, result.output
    assert "creep coefficient dQ/dxi = " in result.output
    import h5py

    with h5py.File(out, "r") as handle:
        assert handle["dQ_dxi"].attrs["units"] == "N/mm"
        assert handle["dxi_dQ"].attrs["units"] == "1/(N/mm)"
        assert handle["da_dP"].attrs["units"] == "mm/(N/mm)"
        value = float(handle["dQ_dxi"][0])
    csv = tmp_path / "c.csv"
    assert run_cli("export", out, "-o", csv).exit_code == 0
    import csv as csv_module

    with csv.open() as stream:
        row = next(csv_module.DictReader(stream))
    for name in ("dQ_dxi", "dQ_dmu", "dQ_dP", "dxi_dQ", "dxi_dmu", "dxi_dP", "da_dP", "dp0_dP"):
        assert row[name] != "", name
    assert float(row["dQ_dxi"]) == value


def test_units_of_quotients():
    """The quotient unit keys of the derivatives, in a case's units."""
    units = {"length": "mm", "stress": "MPa", "force/length": "N/mm", "1": "1"}
    assert units_of("1/(force/length)", units) == "1/(N/mm)"
    assert units_of("stress/(force/length)", units) == "MPa/(N/mm)"


def test_full_slip_free_rolling_and_frictionless():
    """The branches without a partial-slip linearisation, against exact values.

    Full slip (creepage twice Carter's onset): Q = -sgn(xi) mu P exactly, so dQ/dxi = 0,
    dQ/dmu = -sgn(xi) P and dQ/dP = -sgn(xi) mu (to rounding), and the creepage derivatives are
    undefined (NaN: dxi/dQ would be infinite). Free rolling of similar bodies (no tangential
    problem solved): every contact node adheres, and Carter's creep coefficient at Q = 0 is
    -(2 P R*/a) (c = a), met within the grid's resolution of the contact, Delta/(2a).
    Frictionless: the tangential derivatives are NaN, the normal ones Hertz's (a and p0 proportional
    to sqrt(P), exact by homogeneity: a/(2P) to the recorded half-width, p0/(2P) to max|p_n|)."""
    the_plan, _, base = _solved(case_dict())
    onset = carter.full_slip_creepage(base.hertz_a, the_plan.radius, base.mu)
    _, _, slip = _solved(case_dict(**{"tangential.creep": 2.0 * onset}))
    P, mu = slip.normal_load, slip.mu
    assert slip.q_over_mu_p == pytest.approx(-1.0, rel=1e-12)
    assert slip.dQ_dxi == 0.0
    assert slip.dQ_dmu == pytest.approx(-P, rel=1e-12)
    assert slip.dQ_dP == pytest.approx(-mu, rel=1e-9)
    assert all(np.isnan(getattr(slip, name)) for name in ("dxi_dQ", "dxi_dmu", "dxi_dP"))
    free = pipeline.solve(load_case(case_dict(**{"tangential.q_over_mu_p": None})))
    expected = carter.creep_coefficient(0.0, free.normal_load, free.hertz_a, the_plan.radius)
    assert abs(free.dQ_dxi / expected - 1.0) <= free.node_spacing / (2.0 * free.hertz_a)
    frictionless = pipeline.solve(load_case(case_dict(**{"friction.mu": 0.0, "tangential.q_over_mu_p": None})))
    assert np.isnan(frictionless.dQ_dxi) and np.isnan(frictionless.dxi_dQ)
    assert frictionless.da_dP == pytest.approx(frictionless.contact_half_width / (2.0 * frictionless.normal_load))
    assert frictionless.dp0_dP == pytest.approx(frictionless.traction_scale / (2.0 * frictionless.normal_load))
    # another route than the formula: central differences of whole re-solves at P (1 +- 1e-4); the
    # half-space's grid scales with the Hertz a, so the recorded width moves smoothly with P: the
    # difference's truncation is (h^2/6) a'''/a' = 1e-8 relative (a ~ P^1/2, h = 1e-4), rounding 1e-12/1e-4
    load = frictionless.normal_load
    widths = []
    for factor in (1.0 + 1e-4, 1.0 - 1e-4):
        data = case_dict(**{"friction.mu": 0.0, "tangential.q_over_mu_p": None, "normal.load": factor * load})
        widths.append(pipeline.solve(load_case(data)).contact_half_width)
    assert frictionless.da_dP == pytest.approx((widths[0] - widths[1]) / (2e-4 * load), rel=1e-6)


def test_a_zone_change_within_the_step_is_reported():
    """At a creepage where an adhesion node turns to slip within the difference's step, the check
    reports the pattern change instead of comparing: found by bisection between two creepages
    1e-3 apart whose zone patterns differ, down to a bracket of 1e-7 relative (inside the step
    of 1e-6), on Carter's 40 elements under creepage control."""
    data = case_dict(**{"discretization.contact_elements": 40})
    xi = pipeline.solve(load_case(data)).creep

    def states(value):
        return pipeline.solve(load_case(case_dict(data, **{"tangential.creep": value}))).state

    lo, hi = xi, xi * 1.001
    while np.array_equal(states(lo), states(hi)):  # move on until the pattern differs across the bracket
        lo, hi = hi, hi * 1.001
    first = states(lo)
    while abs(hi - lo) > 1e-7 * abs(xi):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.array_equal(states(mid), first) else (lo, mid)
    checks = check_case(case_dict(data, **{"tangential.creep": 0.5 * (lo + hi)}), force_control=False)
    assert not isinstance(checks, str)
    assert {c.name: c.pattern_changed for c in checks}["dQ_dxi"]
