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
:func:`rolling_cli.solver.newton._node_sets`). All inner solves share one
iteration budget, ``max_iterations``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError, GrossSlidingError
from ..system import ContactSystem
from .newton import Evaluation, Problem, State, solve_inner

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

    def run(problem: Problem, state: State, label: str):
        nonlocal used
        try:
            result = solve_inner(problem, state, tolerance, max_iterations - used, label)
        except ConvergenceError as err:
            history.extend(err.history)
            used += err.iterations or 0
            _raise_gross_sliding(problem, err)
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
    result = run(problem, state, problem.mode)
    return Outcome(result.state, result.evaluation, used, result.evaluation.relative_residual, history)


def _raise_gross_sliding(problem: Problem, err: ConvergenceError) -> None:
    """After a failure under force control: say so when the force exceeds friction."""
    if not problem.creep_unknown or err.partial is None:
        return
    state = err.partial
    sys = problem.system
    load = float(-(sys.weights @ state.p_n))
    target, _ = problem.force_target(state.p_n)
    if load > 0.0 and abs(target) >= problem.mu * load * (1.0 - 1e-9):
        raise GrossSlidingError(
            f"gross sliding: the prescribed tangential force |Q| = {abs(target):.6g} reaches "
            f"mu P = {problem.mu * load:.6g}; the cylinders slide, they do not roll"
        )
