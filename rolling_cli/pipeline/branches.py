"""The branch of a force-controlled solve with friction that falls with the slip speed.

With a falling law the creep-force curve Q(xi) rises to a peak and falls, so
a prescribed Q below the peak has two steady solutions: a low-slip one on the
rising branch (dQ/dxi < 0 for Q > 0: stable) and a high-slip one on the
falling branch (Vollebregt & Schuttelaars 2012). Newton finds one of them.
``[solver] branch = "low-slip" | "high-slip"`` asks for one: when the solve
found the other, :func:`on_branch` walks the curve under creepage control from
the solution found (away from zero for the high-slip branch, towards it for
the low-slip one) until Q(xi) crosses the target on the requested branch,
closes the bracket by the Illinois variant of regula falsi, and solves the
force-controlled case from the bracketed solution. The result then records the
other solution's creepage (``other_branch_creep``) and says so
(``branch_note``); a target that the requested branch does not reach is an
error naming the curve's extreme. Every solve reuses the case's contact
system and starts from its neighbour.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

from ..case import Case, with_overrides
from ..errors import ConvergenceError
from ..result import Result, recorded
from ..solver.formulation import State

#: ``solver.branch`` -> the ``branch`` a result on it records.
BRANCHES = {"low-slip": "rising", "high-slip": "falling"}
#: Creepage factor of the walk along the curve, per step.
WALK = 1.5
#: Walk steps at most (1.5^30: 5 decades of creepage).
STEPS = 30
#: Regula falsi steps at most; the bracket is closed to this fraction of mu P.
FALSI_STEPS = 40
FALSI_TOLERANCE = 1e-6


def result_state(result: Result) -> State:
    """The solver state of a converged result (its tractions [stress], overlap [length], creepage)."""
    return State(
        result.p_n, result.p_t, recorded(result.solved_overlap, "solved_overlap"), recorded(result.creep, "creep")
    )


def on_branch(case: Case, result: Result, solve: Callable[..., Result], prepare: Callable) -> Result:
    """``result`` if it lies on the branch ``case.solver.branch`` asks for, else the solution of the
    same force on that branch (module docstring), by ``solve(case, start=, system=)`` on the
    system that ``prepare(case)`` builds (the pipeline's own, passed in: this module runs below it).
    Raises ConvergenceError when that branch does not carry the force."""
    wanted = BRANCHES[case.solver.branch]
    if result.branch == wanted:
        return result
    auto = dataclasses.replace(case, solver=dataclasses.replace(case.solver, branch="auto"))
    the_plan, system = prepare(auto)
    target = abs(recorded(result.tangential_load, "tangential_load"))
    scale = recorded(result.mu, "mu") * recorded(result.normal_load, "normal_load")
    found_creep = float(recorded(result.creep, "creep"))

    def at(creep: float, start) -> Result:
        creep_case = with_overrides(auto, {"tangential.creep": creep})
        return solve(creep_case, start=start, system=system)

    factor = WALK if wanted == "falling" else 1.0 / WALK
    previous, xi = result, found_creep
    crossing = None
    lowest = (math.inf, found_creep)  # the smallest |Q| seen on the wanted branch, and where
    for _ in range(STEPS):
        xi_next = xi * factor
        if abs(xi_next) > 1.0:
            break
        current = at(xi_next, result_state(previous))
        q = abs(recorded(current.tangential_load, "tangential_load"))
        if current.branch == wanted:
            lowest = min(lowest, (q, xi_next))
            if q <= target:
                crossing = (previous, current)
                break
        previous, xi = current, xi_next
    if crossing is None:
        raise ConvergenceError(
            f"no steady solution with |Q| = {target:.6g} on the {case.solver.branch} branch: along the creep-force "
            f"curve from xi = {found_creep:.6g} (the {result.branch} branch's solution) to xi = {xi:.6g}, |Q| on "
            f"that branch stays above it (smallest {lowest[0]:.6g} at xi = {lowest[1]:.6g})"
        )
    bracketed = _falsi(crossing, target, scale, at)
    solved = solve(auto, start=result_state(bracketed), system=system)
    if solved.branch != wanted:
        raise ConvergenceError(
            f"the force-controlled solve from the {case.solver.branch} branch's bracket (xi = "
            f"{float(recorded(bracketed.creep, 'creep')):.6g}) returned to the {solved.branch} branch"
        )
    solved.attributes["other_branch_creep"] = found_creep
    solved.attributes["branch_note"] = (
        f"two steady solutions for Q = {target:.6g}: xi = {float(recorded(solved.creep, 'creep')):.6g} "
        f"({case.solver.branch}, chosen) and {found_creep:.6g}"
    )
    return solved


def _falsi(crossing: tuple[Result, Result], target: float, scale: float, at) -> Result:
    """Close the bracket of |Q(xi)| - target by the Illinois regula falsi on creepage-controlled solves."""
    (left, right) = crossing
    f_left = abs(recorded(left.tangential_load, "tangential_load")) - target
    f_right = abs(recorded(right.tangential_load, "tangential_load")) - target
    x_left, x_right = float(recorded(left.creep, "creep")), float(recorded(right.creep, "creep"))
    best, best_f = (left, f_left) if abs(f_left) < abs(f_right) else (right, f_right)
    side = 0
    for _ in range(FALSI_STEPS):
        if abs(best_f) <= FALSI_TOLERANCE * scale:
            break
        xi = (x_left * f_right - x_right * f_left) / (f_right - f_left)
        if not math.isfinite(xi):
            xi = 0.5 * (x_left + x_right)
        current = at(xi, result_state(best))
        f = abs(recorded(current.tangential_load, "tangential_load")) - target
        if abs(f) < abs(best_f):
            best, best_f = current, f
        if (f > 0.0) == (f_left > 0.0):
            x_left, f_left = xi, f
            if side == -1:
                f_right *= 0.5
            side = -1
        else:
            x_right, f_right = xi, f
            if side == 1:
                f_left *= 0.5
            side = 1
    return best
