"""Solution strategies and load control around the generalised Newton solve.

Strategies (chosen by :mod:`rolling_cli.effects`):

* ``"coupled"``: normal and tangential tractions in one generalised Newton
  system (eq. 33).
* ``"decoupled"``: exact when the coupling blocks vanish (beta = 0): the normal
  problem (eq. 30), then the tangential one (eq. 32) with p_n held.
* ``"normal"``: frictionless, or no tangential problem: the normal one only.

Controls become extra unknowns of the same Newton system: a prescribed load P
makes the overlap unknown (equation sum w p_n + P = 0); a prescribed
tangential force (Q, Q/P or Q/(mu P)) makes the creepage unknown (equation
sum w p_t = Q_target). Full-slip iterates, where Q stops depending on the
creepage, are handled inside the Newton step (see
:func:`rolling_cli.solver.newton._node_sets`). If that combined system has not
converged within half the iteration budget, or stagnates for
:data:`COMBINED_PATIENCE` iterations, the force is matched instead by a
bracketed root on the creepage with creep-controlled inner solves
(:func:`_bracketed_creepage`). All inner solves share one iteration budget,
``max_iterations``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.optimize

from ..errors import ConvergenceError, GrossSlidingError
from ..system import ContactSystem
from .newton import Evaluation, Problem, State, evaluate, solve_inner, traction_scale

STRATEGIES = ("coupled", "decoupled", "normal")
TANGENTIAL_KINDS = ("creep", "load", "q_over_p", "q_over_mu_p", "none")


@dataclass(frozen=True)
class Controls:
    """What is prescribed.

    ``load`` P [force/length] or ``overlap`` [length] (exactly one);
    ``tangential`` is (kind, value) with kind in :data:`TANGENTIAL_KINDS`:
    creepage xi [-], Q [force/length], Q/P [-], Q/(mu P) [-], or "none" (p_t = 0).
    """

    load: float | None
    overlap: float | None
    tangential: tuple[str, float]


@dataclass
class Outcome:
    """A converged solve: the final state, its evaluation and the record."""

    state: State
    evaluation: Evaluation
    iterations: int
    residual: float
    history: list[dict] = field(default_factory=list)


def solve_rolling(
    system: ContactSystem,
    mu: float,
    controls: Controls,
    start: State,
    strategy: str,
    tolerance: float,
    max_iterations: int,
    warm: bool = False,
) -> Outcome:
    """Solve the steady rolling problem with the given strategy and controls.

    ``start`` is the initial state; its creepage is the first guess when a
    force is prescribed. ``warm=True`` says it is a converged neighbouring
    solution (sweeps, grid sequencing), which skips the cold-start pressure
    settling. Raises :class:`ConvergenceError` or :class:`GrossSlidingError`.
    """
    if strategy not in STRATEGIES:
        raise ValueError(f"strategy must be one of {STRATEGIES}")
    kind, value = controls.tangential
    state = start.copy()
    if controls.overlap is not None:
        state.overlap = controls.overlap
    if kind == "creep":
        state.creep = value
    elif kind == "none":
        state.creep = 0.0
    force = None if kind in ("creep", "none") else (kind, value)
    history: list[dict] = []
    used = 0

    def run(problem: Problem, state: State, label: str, limit: int | None = None, patience: int | None = None):
        nonlocal used
        budget = max_iterations - used if limit is None else min(limit, max_iterations - used)
        try:
            result = solve_inner(problem, state, tolerance, budget, label, patience)
        except ConvergenceError as err:
            history.extend(err.history)
            used += err.iterations or 0
            if problem.creep_unknown and err.partial is not None:
                _saturated(problem, err.partial)
            raise ConvergenceError(
                "Newton did not converge",
                residual=err.residual,
                iterations=used,
                history=history,
                cause=err.cause,
                partial=err.partial,
            ) from None
        history.extend(result.history)
        used += result.iterations
        return result

    if strategy in ("decoupled", "normal"):
        held_p_t = state.p_t
        state.p_t = np.zeros_like(state.p_t)
        result = run(Problem(system, "normal", mu, controls.load), state, "normal")
        if strategy == "normal" or kind == "none":
            return Outcome(result.state, result.evaluation, used, result.evaluation.relative_residual, history)
        state = result.state
        state.p_t = np.clip(held_p_t, mu * state.p_n, -mu * state.p_n)
        problem = Problem(system, "tangential", mu, controls.load, force)
    elif not warm:
        # Settle the pressure first (Hertz-like, p_t = 0): a tangential guess
        # tilts the gap through the coupling and misplaces the contact.
        guess_p_t = state.p_t
        state.p_t = np.zeros_like(state.p_t)
        state = run(Problem(system, "normal", mu, controls.load), state, "normal (p_t = 0)").state
        state.p_t = np.clip(guess_p_t, mu * state.p_n, -mu * state.p_n)
        problem = Problem(system, "coupled", mu, controls.load, force)
    else:
        problem = Problem(system, "coupled", mu, controls.load, force)
    if force is None:
        result = run(problem, state, problem.mode)
        return Outcome(result.state, result.evaluation, used, result.evaluation.relative_residual, history)
    try:
        result = run(problem, state, problem.mode, limit=max(1, max_iterations // 2), patience=COMBINED_PATIENCE)
        return Outcome(result.state, result.evaluation, used, result.evaluation.relative_residual, history)
    except ConvergenceError as err:
        start_state = err.partial if err.partial is not None else state
    final, evaluation = _bracketed_creepage(problem, start_state, run, tolerance)
    return Outcome(final, evaluation, used, evaluation.relative_residual, history)


#: The combined force-controlled Newton hands over to the creepage bracket after
#: this many iterations without a new lowest merit (or half the budget).
COMBINED_PATIENCE = 10


def _bracketed_creepage(problem: Problem, state: State, run, tolerance: float) -> tuple[State, Evaluation]:
    """Fallback force control: a bracketed root of f(xi) = (Q(xi) - Q_target) / (mu P).

    Used when the combined Newton system (creepage unknown) does not converge,
    as in strongly coupled, low-friction cases near full slip, whose adhesion
    zones shrink to the points where the slip changes sign. At a fixed
    creepage the problem has no such singularity; f is continuous and
    non-increasing, so a bracket [lo, hi] with f(lo) > 0 > f(hi) is found by
    expanding steps and closed by Brent's method, each evaluation an inner
    solve warm-started from the previous one.
    """
    sys = problem.system
    held = dataclasses.replace(problem, force=None)
    w = sys.weights
    current = state.copy()
    solved: list[State] = []

    def f(xi: float) -> float:
        nonlocal current
        # start from the solved creepage nearest to xi: Brent's points close in
        nearest = min(solved, key=lambda s: abs(s.creep - xi)) if solved else current
        start = nearest.copy()
        start.creep = float(xi)
        current = run(held, start, "creepage bracket").state
        solved.append(current)
        load = float(-(w @ current.p_n))
        target, _ = problem.force_target(current.p_n)
        return (float(w @ current.p_t) - target) / (problem.mu * max(load, 1e-300))

    xi0 = float(state.creep)
    elastic = np.abs(sys.slip(state.p_n, state.p_t, 0.0)[state.p_n < 0.0])
    # The stagnated creepage is usually near the root: small first steps, growing fast.
    step = 1e-3 * max(abs(xi0), float(elastic.max()) if elastic.size else 0.0, 1e-9)
    f0 = f(xi0)
    lo = hi = xi0
    f_lo = f_hi = f0
    for _ in range(40):
        if f_lo > 0.0 > f_hi or abs(f_lo) <= tolerance or abs(f_hi) <= tolerance:
            break
        if f0 > 0.0:  # Q too large: raise the creepage (Q falls as xi rises)
            lo, f_lo = hi, f_hi
            hi = hi + step
            f_hi = f(hi)
        else:
            hi, f_hi = lo, f_lo
            lo = lo - step
            f_lo = f(lo)
        step *= 4.0
    else:
        _saturated(problem, current)
        raise ConvergenceError(
            "no creepage carries the prescribed tangential force",
            cause="Q(xi) did not cross the target over a creepage range of "
            f"{lo:.3e} .. {hi:.3e}; the force may be at the friction limit",
            partial=current,
        )
    if abs(f_lo) <= tolerance or abs(f_hi) <= tolerance:
        root = lo if abs(f_lo) <= abs(f_hi) else hi
    else:
        root = scipy.optimize.brentq(f, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=200)
    residual = f(root)
    ev = evaluate(problem, current, traction_scale(problem, current))
    if ev.relative_residual > tolerance:
        raise ConvergenceError(
            "the creepage iteration did not match the tangential force",
            residual=ev.relative_residual,
            cause=f"Q(xi) jumps near xi = {root:.6e} (force mismatch {abs(residual):.2e} of mu P); refine the mesh",
            partial=current,
        )
    return current, ev


def _saturated(problem: Problem, state: State) -> None:
    """A target beyond the friction limit: gross sliding (raised), else nothing."""
    sys = problem.system
    load = float(-(sys.weights @ state.p_n))
    target, _ = problem.force_target(state.p_n)
    if load > 0.0 and abs(target) >= problem.mu * load * (1.0 - 1e-9):
        raise GrossSlidingError(
            f"gross sliding: the prescribed tangential force |Q| = {abs(target):.6g} reaches "
            f"mu P = {problem.mu * load:.6g}; the cylinders slide, they do not roll"
        )
