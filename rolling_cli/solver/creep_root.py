"""Force control as a scalar root of Q(xi) = Q_target: a safeguarded Newton iteration on the
creepage xi with dQ/dxi from the reduced Jacobian and creepage-controlled inner solves
(:func:`~rolling_cli.solver.stage.run_newton`); it stops on the force residual. Used by the
strategies (:func:`rolling_cli.solver.strategies.creep_root`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from . import formulation, predictor, reduced
from .budget import Budget, BudgetExhausted
from .formulation import Evaluation, Problem, State
from .stage import run_newton
from .system import ContactSystem
from .task import Solution, StrategyFailed, Task

#: The creep root does not look beyond this creepage (100 %: the bodies no longer roll on each other).
MAX_CREEP = 1.0


def solve(problem: Problem, task: Task, state: State, budget: Budget, globalisation=None) -> Solution:
    """Safeguarded Newton on f(xi) = (Q(xi) - Q_target) / (L s_t), Q(xi) from creep-controlled solves.

    Under overlap control a target given as Q/P or Q/(mu P) moves with the load P(xi), and
    the slope is that of Q - Q_target (:func:`~rolling_cli.solver.reduced.creep_derivatives`):
    with dQ/dxi alone the Newton steps left the bracket and the root bisected (a thin
    incompressible layer near full slip: 148 iterations against 84, issue 26).

    Q is continuous and non-increasing in xi. A bracket [lo, hi] with f(lo) > 0 >
    f(hi) is kept once found; a Newton step (dQ/dxi from the reduced Jacobian of
    the converged inner solve) that leaves it, or a derivative that does not
    decrease, is replaced by regula falsi between the ends (Illinois: an end kept
    k >= 2 times in a row counts 2^(1-k)), and by bisection when |f| did not fall. Before a
    bracket exists, the first step without a slope goes to where the target's full slip
    starts (:func:`full_slip_onset`) when that lies beyond the root, the others expand
    geometrically in the direction of the root.
    A solution in full slip (one way or, with a coupling, both) holds unchanged up to
    the creepage where the first node's slip reaches zero (:func:`full_slip_edge`), so the bracket end
    moves there at no cost. Near full slip the root lies just short of that edge,
    where Q - Q_target falls steeply: Newton steps from the other side overshoot it
    and bisection took a dozen solves more (issue 26: 40 cases of the small-friction
    coupled family took 2638 iterations, 8 of them over 100; now 1233, at most 66:
    benchmarks/RESULTS.md). Stops when the force
    residual is below the tolerance (the inner solve converged too); raises when the
    bracket closes to round-off without that (Q jumps) or the budget is spent.

    Over 80 lines for a reason: the bracket, the Newton step and the bisection update one
    loop state (bracket ends, their residuals, the last converged state), which helpers would
    have to pass back and forth whole.
    """
    held = problem.held(force=None)
    system = problem.system
    lz = system.zone_length
    name = "creep root"
    lo = hi = None
    f_lo = f_hi = 0.0
    kept = 0  # +1 / -1: the low / high end kept by the last regula falsi step, once or more (Illinois)
    current = state.copy()
    step = None
    jumped = False
    fallback = None  # after a jump: the state and expansion step to retry if its solve fails
    last_f = None
    solved: list[tuple[float, Solution]] = []
    predict = predictor.over_solutions(system.x, task.mu)
    for _ in range(200):
        xi = current.creep
        if solved and fallback is None:  # start from the boundary secant of the two solved creepages nearest to xi
            near = sorted(solved, key=lambda point: abs(point[0] - xi))[:2]
            near.sort(key=lambda point: abs(point[0] - xi), reverse=True)
            if len(near) == 2 and near[0][0] == near[1][0]:
                near = near[1:]
            current = predict(near, xi)
            current.creep = xi
        try:
            inner = run_newton(
                held, current, task.tolerance, budget, name, f"creepage held, xi = {xi:.6e}", False, globalisation
            )
        except StrategyFailed:
            if fallback is None or budget.exhausted:
                raise
            current, fallback = fallback, None  # the jump failed: expand from the last solution instead
            continue
        fallback = None
        solved.append((xi, inner))
        current = inner.state
        target, _ = problem.force_target(current.p_n, current.p_t)
        q = float(system.weights @ current.p_t)
        scale = formulation.traction_scales(problem, current).tangential
        f = (q - target) / (lz * scale)
        budget.history[-1]["force_residual"] = f
        xi = current.creep
        if abs(f) <= budget.history[-1]["tolerance"]:
            ev = formulation.evaluate(problem, current, formulation.traction_scales(problem, current))
            return Solution(current, ev, problem)
        edge = full_slip_edge(system, current, inner.evaluation, upward=f > 0.0)
        if edge is not None:  # the same solution holds from xi to the edge: go there
            moved = current.copy()
            moved.creep = xi = edge
            solved.append((edge, dataclasses.replace(inner, state=moved)))
        if f > 0.0:
            if lo is None or xi > lo:
                lo, f_lo = xi, f
                kept = min(kept, 0) - 1 if hi is not None else 0
        elif hi is None or xi < hi:
            hi, f_hi = xi, f
            kept = max(kept, 0) + 1 if lo is not None else 0
        if edge is not None:  # Q does not move with xi here
            d_q = 0.0
        else:
            try:
                budget.take()
                d_q, dp_n, dp_t = reduced.creep_derivatives(held, current, inner.evaluation)
                _, d_target = problem.force_target(current.p_n, current.p_t)
                if d_target is not None:  # overlap control: Q_target = (Q/P) P moves with P(xi)
                    d_q -= float(d_target @ dp_n)
                d_target_t = problem.target_gradient_t()
                if d_target_t is not None:  # and a finite cylinder's shaft load P with p_t
                    d_q -= float(d_target_t @ dp_t)
            except BudgetExhausted:
                raise StrategyFailed(name, "budget", "budget", current, abs(f)) from None
            except np.linalg.LinAlgError:  # a singular sensitivity system: bracketing alone
                d_q = 0.0
        derivative = d_q / (lz * scale)
        proposal = xi - f / derivative if derivative < 0.0 else None
        if lo is not None and hi is not None:
            if hi - lo <= 4.0 * np.finfo(float).eps * max(abs(lo), abs(hi)):
                raise StrategyFailed(
                    name,
                    f"xi = {xi:.6e}",
                    "Q(xi) jumps across the target: the force cannot be matched on this mesh (refine it)",
                    current,
                    abs(f),
                )
            if proposal is None or not lo < proposal < hi:
                # regula falsi between the ends, an end kept k >= 2 times in a row weighed 2^(1-k) (Illinois)
                weight_lo = 0.5 ** max(kept - 1, 0)
                weight_hi = 0.5 ** max(-kept - 1, 0)
                proposal = lo + (hi - lo) * weight_lo * f_lo / (weight_lo * f_lo - weight_hi * f_hi)
            if proposal is None or not lo < proposal < hi:
                proposal = 0.5 * (lo + hi)
            if last_f is not None and abs(f) >= abs(last_f) and f * last_f > 0.0:
                proposal = 0.5 * (lo + hi)  # no progress: bisect
        elif proposal is None:
            target, _ = problem.force_target(current.p_n, current.p_t)
            if not jumped and (f > 0.0) == (target < 0.0):  # the target's full slip lies beyond the root
                jumped = True
                sigma = 1.0 if target > 0.0 else -1.0
                proposal = full_slip_onset(system, current, task.mu, sigma)
                if proposal is not None and (proposal - xi) * f > 0.0:
                    elastic = np.abs(system.slip(current.p_n, current.p_t, 0.0)[current.p_n < 0.0])
                    step = 1e-3 * max(abs(xi), float(elastic.max()) if elastic.size else 0.0, 1e-12)
                    fallback = current.copy()
                    fallback.creep = xi + step if f > 0.0 else xi - step
                    jump = current.copy()  # started from that full slip, the solution if the estimate holds
                    jump.p_t = np.where(current.p_n < 0.0, -sigma * task.mu * current.p_n, 0.0)
                    jump.creep = proposal
                    current = jump
                    last_f = f
                    continue
                proposal = None
            if proposal is None:
                elastic = np.abs(system.slip(current.p_n, current.p_t, 0.0)[current.p_n < 0.0])
                scale_xi = max(abs(xi), float(elastic.max()) if elastic.size else 0.0, 1e-12)
                step = step * 4.0 if step else 1e-3 * scale_xi
                proposal = xi + step if f > 0.0 else xi - step
        if abs(proposal) > MAX_CREEP:
            raise StrategyFailed(
                name,
                f"xi = {xi:.6e}",
                f"no creepage up to |xi| = {MAX_CREEP:g} carries the force (full slip below the target)",
                current,
                abs(f),
            )
        last_f = f
        current = current.copy()
        current.creep = float(proposal)
    raise StrategyFailed(name, "root", "no convergence in 200 creepage updates", current, abs(last_f or np.inf))


def full_slip_onset(system: ContactSystem, state: State, mu: float, sigma: float) -> float | None:
    """The creepage [-] from which every contact node slips one way, p_t = sigma mu |p_n|, estimated
    with ``state``'s pressure: there the slip s_i = xi + e_i (e the elastic slip of the full-slip
    tractions) opposes the traction at every node, sigma s_i <= 0, from xi = -sigma max(sigma e)."""
    contact = state.p_n < 0.0
    contact[system.gauge] = False
    if not contact.any():
        return None
    p_t = np.where(state.p_n < 0.0, -sigma * mu * state.p_n, 0.0)
    elastic = system.slip(state.p_n, p_t, 0.0)[contact]
    return float(-sigma * np.max(sigma * elastic))


def full_slip_edge(system: ContactSystem, state: State, ev: Evaluation, upward: bool) -> float | None:
    """For a state in full slip (no adhesion node), the creepage up to which it stays the solution
    [-], upward (larger xi) or downward; None when not in full slip or when it stays the solution
    without end that way.

    In full slip p_t = sigma_i mu |p_n| at every contact node whatever the creepage (sigma_i = +-1,
    of both signs with a coupling), and the slip s = xi + (B p)(x) moves with xi alone (the creep
    vector is 1 off the gauge row); it opposes the traction, sigma_i s_i <= 0, until the creepage
    where the first node's slip reaches 0: upward xi + min(-s_i) over the nodes of sigma_i = +1,
    downward xi + max(-s_i) over those of sigma_i = -1. In between the force is the same.
    """
    contact = state.p_n < 0.0
    contact[system.gauge] = False
    if not contact.any() or (ev.stick & contact).any():
        return None
    signs = np.sign(state.p_t[contact])
    if not np.all(signs != 0.0):
        return None
    slip = system.slip(state.p_n, state.p_t, state.creep)[contact]
    ends = -slip[signs > 0.0] if upward else -slip[signs < 0.0]
    if not ends.size:
        return None
    return float(state.creep + (ends.min() if upward else ends.max()))
