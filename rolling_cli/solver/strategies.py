"""Solution strategies: plain callables ``strategy(task, start, budget, cold=False) -> Solution``.

A strategy solves a :class:`Task` from a start state, taking its Newton
iterations from the shared :class:`~rolling_cli.solver.budget.Budget`. One that
fails raises :class:`StrategyFailed` with the best state it reached; it never
spends the budget silently. :func:`first_success` combines strategies: the
first that succeeds wins, and each next one starts from the best state so far.

* :func:`direct`: Newton on the task as it stands: the normal problem;
  decoupled (the normal problem, then the tangential one with p_n held); or the
  coupled system (eq. 33). Prescribed P and Q make the overlap and the
  creepage unknowns of the same Newton system.
* :func:`settled`: coupled, from a cold start: the normal problem with p_t = 0
  first (a guessed p_t would tilt the gap through the coupling and misplace the
  contact), then the coupled system.
* :func:`coupling_path`: continuation in the coupling scale kappa (the cross
  blocks S_nt, B_tn times kappa) from the exactly decoupled problem at
  kappa = 0 to kappa = 1 (:mod:`rolling_cli.solver.continuation`).
* :func:`creep_root`: force control as a scalar root of Q(xi) = Q_target, by a
  safeguarded Newton iteration on xi with dQ/dxi from the reduced Jacobian and
  creep-controlled inner solves; it stops on the force residual.

Each takes its Newton globalisation as a value (:class:`~rolling_cli.solver.newton.Watchdog`
or :class:`~rolling_cli.solver.newton.Armijo`); :func:`default` picks the
combination for a task.

One Newton run on one stage problem is :func:`~rolling_cli.solver.stage.run_newton`;
the creepage root's iteration is :mod:`rolling_cli.solver.creep_root`. What strategies are
given and return (:class:`Task`, :class:`Solution`, :class:`StrategyFailed`) lives in
:mod:`rolling_cli.solver.task`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..model.friction import SlipFriction
from . import continuation, formulation, predictor
from .budget import Budget
from .creep_root import solve as creep_root_solve
from .formulation import State
from .newton import Armijo, Watchdog
from .stage import clip_to_friction, run_newton
from .system import ContactSystem
from .task import TANGENTIAL_KINDS, Controls, Solution, Strategy, StrategyFailed, Task  # noqa: F401 (the strategies' names)

# --- strategies ------------------------------------------------------------------------------------


def direct(
    task: Task, start: State, budget: Budget, cold: bool = False, globalisation=None, name: str = "direct"
) -> Solution:
    """Newton on the task's own formulation (see the module docstring)."""
    state = task.prepared(start)
    tol = task.tolerance
    if task.formulation == "coupled":
        return run_newton(task.problem("coupled"), state, tol, budget, name, "coupled", cold, globalisation)
    held_p_t = state.p_t
    state.p_t = np.zeros_like(held_p_t)
    normal = run_newton(task.problem("normal"), state, tol, budget, name, "normal", cold, globalisation)
    if task.formulation == "normal" or task.controls.tangential[0] == "none":
        return normal
    state = clip_to_friction(normal.state, held_p_t, task.mu)
    return _tangential(task, state, budget, name, globalisation)


def _tangential(task: Task, state: State, budget: Budget, strategy: str, globalisation=None) -> Solution:
    """The tangential stage of a decoupled task (p_n held): Newton with the creepage unknown, and
    the scalar root on the creepage if that fails."""
    problem = task.problem("tangential")
    try:
        return run_newton(problem, state, task.tolerance, budget, strategy, "tangential", False, globalisation)
    except StrategyFailed as err:
        if problem.force is None or budget.exhausted:
            raise
        best = err.best if err.best is not None else state
        return creep_root_solve(problem, task, best, budget, globalisation)


def settled(
    task: Task, start: State, budget: Budget, cold: bool = False, globalisation=None, name: str = "settled"
) -> Solution:
    """Coupled: the normal problem with p_t = 0 first, then the coupled system (module docstring)."""
    state = task.prepared(start)
    guess = state.p_t
    state.p_t = np.zeros_like(guess)
    normal = run_newton(
        task.problem("normal"), state, task.tolerance, budget, name, "normal (p_t = 0)", cold, globalisation
    )
    state = clip_to_friction(normal.state, guess, task.mu)
    return run_newton(task.problem("coupled"), state, task.tolerance, budget, name, "coupled", False, globalisation)


def scaled_coupling(system: ContactSystem, kappa: float) -> ContactSystem:
    """The contact system with its normal-tangential cross blocks times ``kappa`` (None at 0), and
    the p_t term of a finite cylinder's shaft load (``load_t``) with them: the decoupled stages
    hold p_t = 0 while they meet the load."""
    if system.S_nt is None:
        return system
    if kappa == 0.0:
        return dataclasses.replace(system, S_nt=None, B_tn=None, gauge_tn=None, load_t=None)

    def scaled(block):
        return None if block is None else kappa * block

    return dataclasses.replace(
        system,
        S_nt=scaled(system.S_nt),
        B_tn=scaled(system.B_tn),
        gauge_tn=scaled(system.gauge_tn),
        load_t=scaled(system.load_t),
    )


def coupling_path(task: Task, start: State, budget: Budget, cold: bool = False, globalisation=None) -> Solution:
    """Continuation in the coupling scale kappa from 0 (decoupled, solved exactly) to 1."""
    if task.system.S_nt is None:
        return direct(task, start, budget, cold, globalisation)
    decoupled = dataclasses.replace(task, system=scaled_coupling(task.system, 0.0), formulation="decoupled")
    try:
        first = direct(decoupled, start, budget, cold, globalisation, name="coupling path")
    except StrategyFailed as err:
        raise StrategyFailed("coupling path", "kappa = 0", err.reason, err.best, err.residual) from None

    def solve_at(kappa: float, guess: State) -> tuple[Solution, int]:
        scaled = dataclasses.replace(task, system=scaled_coupling(task.system, kappa))
        before = budget.taken
        solution = run_newton(
            scaled.problem("coupled"),
            task.prepared(guess),
            task.tolerance,
            budget,
            "coupling path",
            f"coupled, kappa = {kappa:.4g}",
            False,
            globalisation,
        )
        return solution, budget.taken - before

    return _follow("coupling path", "kappa", [1.0], solve_at, first, task, budget)


#: The strengths the law path walks through (each from the secant of the last two).
LAW_STEPS = (0.25, 0.5, 0.75, 1.0)


def law_path(task: Task, start: State, budget: Budget, cold: bool = False, globalisation=None) -> Solution:
    """A velocity-dependent law by continuation in its strength lambda: mu_s + lambda (mu(s_a) - mu_s)
    (:class:`~rolling_cli.model.friction.Blended`) from Coulomb friction with mu_static at lambda = 0
    to the law at 1, each step from the boundary-secant prediction of the last two. For laws that
    fall far (mu_k/mu_s = 0.4 on Carter's cylinders: direct Newton stagnates near the curve's peak,
    its stick/slip boundary moving a node an iteration from the Coulomb start)."""
    if task.friction is None:
        return direct(task, start, budget, cold, globalisation)
    from ..model.friction import Blended

    law, speed = task.friction.law, task.friction.speed
    coulomb = dataclasses.replace(task, friction=None)
    try:
        first = direct(coulomb, start, budget, cold, globalisation, name="law path")
    except StrategyFailed as err:
        raise StrategyFailed("law path", "lambda = 0", err.reason, err.best, err.residual) from None

    def solve_at(strength: float, guess: State) -> tuple[Solution, int]:
        blended = dataclasses.replace(task, friction=SlipFriction(Blended(law, strength), speed))
        before = budget.taken
        solution = run_newton(
            blended.problem(task.full_mode),
            task.prepared(guess),
            task.tolerance,
            budget,
            "law path",
            f"{task.full_mode}, lambda = {strength:.4g}",
            False,
            globalisation,
        )
        return solution, budget.taken - before

    return _follow("law path", "lambda", LAW_STEPS, solve_at, first, task, budget)


def _follow(name: str, symbol: str, targets, solve_at, first: Solution, task: Task, budget: Budget) -> Solution:
    """Continuation from ``first`` (the solution at parameter 0) through ``targets`` by ``solve_at``,
    each step from the boundary-secant prediction; a failure is the strategy ``name``'s, at
    ``symbol`` = the parameter it reached."""
    points = [(0.0, first)]
    try:
        continuation.follow(
            targets,
            solve_at,
            predictor.over_solutions(task.system.x, task.mu),
            points,
            failure=StrategyFailed,
            control=continuation.StepControl(),
            budget=budget,
        )
    except continuation.ContinuationFailed as err:
        best = err.best.state if err.best is not None else None
        raise StrategyFailed(name, f"{symbol} = {err.parameter:.4g}", err.reason, best, err.residual) from None
    return points[-1][1]


def creep_root(task: Task, start: State, budget: Budget, cold: bool = False, globalisation=None) -> Solution:
    """Force control by a safeguarded scalar root on the creepage (module docstring)."""
    mode = task.full_mode
    problem = task.problem(mode)
    if problem.force is None:
        return direct(task, start, budget, cold, globalisation)
    state = task.prepared(start)
    if mode == "tangential":
        state.p_t = np.zeros_like(state.p_t)
        normal = run_newton(
            task.problem("normal"), state, task.tolerance, budget, "creep root", "normal", cold, globalisation
        )
        state = clip_to_friction(normal.state, start.p_t, task.mu)
    return creep_root_solve(problem, task, state, budget, globalisation)


def first_success(*strategies: Strategy, name: str = "first success") -> Strategy:
    """The first strategy that succeeds; each next one starts from the best state so far
    (least merit of the task's own residual)."""

    def combined(task: Task, start: State, budget: Budget, cold: bool = False) -> Solution:
        best, best_merit = start, None  # best_merit: computed on the first failure
        failures: list[StrategyFailed] = []
        for strategy in strategies:
            try:
                return strategy(task, best, budget, cold=cold)
            except StrategyFailed as err:
                failures.append(err)
                if budget.exhausted:
                    break
                if err.best is not None:
                    reached = merit(task, err.best)
                    if best_merit is None:
                        best_merit = merit(task, best)
                    if reached < best_merit:
                        best, best_merit, cold = err.best, reached, False
        worst = failures[-1]
        raise StrategyFailed(
            name,
            worst.stage,
            "; ".join(str(f) for f in failures),
            best,
            min(f.residual for f in failures),
            causes=failures,
        )

    return combined


def merit(task: Task, state: State) -> float:
    """The merit of ``state`` for the whole task (its scaled residual norm), to rank starts."""
    problem = task.problem(task.full_mode)
    prepared = task.prepared(state)
    return formulation.evaluate(problem, prepared, formulation.traction_scales(problem, prepared)).merit


#: Globalisations as values: the watchdog for first attempts (it lets an active-set step raise the
#: merit, which warm starts and layers need), the monotone line search for the fallbacks (robust
#: where the normal-tangential coupling is strong: benchmarks/RESULTS.md, robustness). A settled
#: start gets a longer patience: on a thin incompressible layer near full slip the watchdog needed
#: three of its cycles (33 iterations) to find its way, where 20 stopped it; its cycles restart from
#: a backtrack of less than 1/16 of the step, so it keeps them (``retrace=0``: tests/test_paths.py,
#: the thin layer at Q/(mu P) = 0.7 fails within 100 iterations without them).
WATCHDOG = Watchdog()
PATIENT_WATCHDOG = Watchdog(patience=40, retrace=0.0)
MONOTONE = Armijo()


def _with(strategy, globalisation, name: str | None = None) -> Strategy:
    """``strategy`` with a fixed globalisation (and history name)."""
    kwargs = {"globalisation": globalisation}
    if name is not None:
        kwargs["name"] = name

    def bound(task: Task, start: State, budget: Budget, cold: bool = False) -> Solution:
        return strategy(task, start, budget, cold=cold, **kwargs)

    return bound


def restarted(strategy: Strategy, start: State) -> Strategy:
    """``strategy`` from the fixed cold ``start`` (its node states read from the pressure),
    whatever state the chain hands on: a warm start that failed, retried from the closed form."""

    def bound(task: Task, _handed_on: State, budget: Budget, cold: bool = False) -> Solution:
        return strategy(task, start, budget, cold=True)

    return bound


def default(task: Task, settle: bool = False, restart: State | None = None, restart_settle: bool = False) -> Strategy:
    """The strategy for a task.

    Newton on the task's own formulation with the watchdog first (for a coupled
    task whose start has only an approximate pressure, ``settle``, :func:`settled`
    instead: a pressure interpolated from a coarse pre-solve is settled on the
    task's grid before friction enters); then, with the monotone line search, the
    same again, and for coupled tasks (force control) :func:`creep_root`,
    :func:`settled` and :func:`coupling_path`. Decoupled tasks fall back to the
    creepage root inside their tangential stage. A warm start (a neighbour's
    prediction) that fails is first retried from the closed-form ``restart``
    (settled first when ``restart_settle``, as a cold start of that case would
    be): a neighbour near full slip can hold a stick zone far from the case's,
    and the watchdog then cycles through the same raised steps (dissimilar_q04's
    load curve, 21 points, the second: 73 iterations through three strategies;
    12 with the retry and the watchdog's retrace stop). The order is measured
    (benchmarks/RESULTS.md, robustness): the creepage root is what strongly
    coupled low-friction cases near full slip need, the monotone line search what
    the strongly coupled high-friction corner needs.
    """
    first = _with(settled, PATIENT_WATCHDOG) if settle and task.formulation == "coupled" else _with(direct, WATCHDOG)
    chain = [first]
    if restart is not None:  # a warm start: its failure is retried from the closed form first
        if restart_settle and task.formulation == "coupled":
            retry = _with(settled, PATIENT_WATCHDOG, "settled, closed-form start")
        else:
            retry = _with(direct, WATCHDOG, "direct, closed-form start")
        chain.append(restarted(retry, restart))
    if task.friction is not None:  # a velocity-dependent law: continuation in its strength next
        chain.append(_with(law_path, WATCHDOG))
    chain.append(_with(direct, MONOTONE, "direct, monotone"))
    if task.formulation == "coupled":
        if task.controls.force is not None:
            chain.append(_with(creep_root, MONOTONE))
        chain += [_with(settled, MONOTONE), _with(coupling_path, MONOTONE)]
    return first_success(*chain, name=task.formulation)
