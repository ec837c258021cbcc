"""Finite-difference checks of the recorded sensitivities (tests/test_sensitivities.py and
benchmarks/bench_sensitivities.py share them).

Each sensitivity of a converged solve is compared with a central difference of
re-solved cases, relative step 1e-6 of the parameter, the other parameters held
as the derivative holds them (creepage control: xi, mu, P; force control: the
force Q, mu, P). The re-solves are independent Newton solves (from the base
solution, which only saves iterations) on the base case's own contact system,
except the load of a load-controlled case on two half-spaces: rollc's grid
scales with the Hertz a there, so that difference re-solves the whole pipeline
at P +- h (the derivative recorded is that of ``rollc solve``'s result). The
sensitivities hold P: an overlap-controlled case is re-solved under load
control at its solved P.

A difference is not a fair reference where the node states (the zone pattern)
change within the step (PHYSICS.md): those are detected, by comparing the
states of the three solves, and reported instead of compared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.result import node_states
from rolling_cli.solver import control
from rolling_cli.solver.budget import Budget
from rolling_cli.solver.formulation import State

#: Relative step of the central differences.
STEP = 1e-6
#: The difference's error: truncation (h^2 ~ 1e-12 relative) and the re-solves' residual
#: (tolerance 1e-13 of the force scale mu P, divided by the step 1e-6: ~1e-7 of the scale) are
#: both far below it; 1e-5 is the issue's figure.
TOLERANCE = 1e-5


@dataclass
class Check:
    """One compared sensitivity: its name, the recorded value, the difference, the natural scale
    of the derivative and whether the zone pattern changed within the step (not compared)."""

    name: str
    recorded: float
    difference: float
    scale: float
    pattern_changed: bool

    @property
    def error(self) -> float:
        """|recorded - difference| relative to max(|recorded|, scale / 10): a derivative much smaller
        than its scale is a cancellation, compared on the scale."""
        return abs(self.recorded - self.difference) / max(abs(self.recorded), 0.1 * self.scale)


@dataclass
class Outcome:
    """A solved point: P, Q, xi, max|p_n| and the node states."""

    load: float
    force: float
    creep: float
    peak: float
    states: np.ndarray


def _outcome_of(result) -> Outcome:
    return Outcome(result.normal_load, result.tangential_load, result.creep, float(-result.p_n.min()), result.state)


def _resolve(data: dict, system, start: State) -> Outcome:
    """An independent Newton solve of ``data`` on ``system`` (the base grid), from ``start``."""
    case = load_case(data)
    the_plan = pipeline.plan(case, check=False)
    task = pipeline._task(case, the_plan, system)
    solution = control.solve(task, start, Budget(case.solver.max_iterations))
    s = solution.state
    w = system.weights
    stick = solution.stick
    load = system.load(s.p_n, s.p_t)  # P as normal.load prescribes it (a finite cylinder's: on its shaft)
    return Outcome(load, float(w @ s.p_t), s.creep, float(-s.p_n.min()), node_states(s.p_n, stick))


def _with(data: dict, **dotted) -> dict:
    from helpers import case_dict

    return case_dict(data, **dotted)


def check_case(data: dict, force_control: bool) -> list[Check] | str:
    """Solve ``data`` (its tangential control replaced by the solved creepage unless ``force_control``,
    by the solved force Q when it is) and compare every sensitivity with its difference. Returns the
    checks, or a string saying why the case was left out (not converged, zone enlarged)."""
    data = _with(data, **{"solver.tolerance": 1e-13})
    case = load_case(data)
    try:
        the_plan, system = pipeline.prepare(case)
        base = pipeline.solve(case, system=system)
    except Exception as err:  # a case the solver refuses is not a sensitivity question
        return f"not solved: {type(err).__name__}"
    if base.zone_note:
        return "zone enlarged"
    if not force_control:  # the creepage-controlled case through the solved point
        data = _with(data, **{"tangential.creep": base.creep})
        base = pipeline.solve(load_case(data), system=system)
    start = State(base.p_n, base.p_t, base.solved_overlap, base.creep)
    mu, load, q, xi = base.mu, base.normal_load, base.tangential_load, base.creep
    if case.normal.load is None:  # the sensitivities hold P: re-solve under load control at the solved P
        data = _with(data, **{"normal.load": load})
    held = {"tangential.load": q} if force_control else {"tangential.creep": xi}
    similar = pipeline.hertz_applies(case)
    outcome = _outcome_of(base)

    def pair(key: str, value: float, extra: dict, whole: bool = False) -> tuple[Outcome, Outcome, float]:
        h = STEP * abs(value)
        runs = []
        for sign in (1.0, -1.0):
            moved = _with(data, **{**extra, key: value + sign * h})
            runs.append(_outcome_of(pipeline.solve(load_case(moved))) if whole else _resolve(moved, system, start))
        return runs[0], runs[1], 2.0 * h

    def changed(plus: Outcome, minus: Outcome) -> bool:
        return not (np.array_equal(plus.states, outcome.states) and np.array_equal(minus.states, outcome.states))

    force_scale = mu * load
    creep_scale = max(abs(xi), mu * base.hertz_a / the_plan.radius)
    checks = []
    plus, minus, _ = pair("normal.load", load, held, whole=similar)
    d_load = plus.load - minus.load
    pattern = changed(plus, minus)
    if force_control:
        checks.append(Check("dxi_dP", base.dxi_dP, (plus.creep - minus.creep) / d_load, creep_scale / load, pattern))
    else:
        checks.append(Check("dQ_dP", base.dQ_dP, (plus.force - minus.force) / d_load, force_scale / load, pattern))
    peak_scale = outcome.peak / load
    checks.append(Check("dp0_dP", base.dp0_dP, (plus.peak - minus.peak) / d_load, peak_scale, pattern))
    # friction
    plus, minus, h2 = pair("friction.mu", mu, held)
    pattern = changed(plus, minus)
    if force_control:
        checks.append(Check("dxi_dmu", base.dxi_dmu, (plus.creep - minus.creep) / h2, creep_scale / mu, pattern))
    else:
        checks.append(Check("dQ_dmu", base.dQ_dmu, (plus.force - minus.force) / h2, force_scale / mu, pattern))
    # the tangential control itself
    if force_control:
        plus, minus, h2 = pair("tangential.load", q if q != 0.0 else force_scale, {})
        d = (plus.creep - minus.creep) / (plus.force - minus.force)
        checks.append(Check("dxi_dQ", base.dxi_dQ, d, creep_scale / force_scale, changed(plus, minus)))
    else:
        plus, minus, h2 = pair("tangential.creep", xi if xi != 0.0 else creep_scale, {})
        d = (plus.force - minus.force) / (plus.creep - minus.creep)
        checks.append(Check("dQ_dxi", base.dQ_dxi, d, force_scale / creep_scale, changed(plus, minus)))
    return checks


def is_finite(checks: list[Check]) -> bool:
    """Every recorded sensitivity and difference is a number."""
    return all(math.isfinite(c.recorded) and math.isfinite(c.difference) for c in checks)
