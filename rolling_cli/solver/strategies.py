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

Over 500 lines for a reason: the strategies call each other (:func:`direct` ->
the tangential stage -> the creepage root -> creepage-controlled inner solves;
the paths and :func:`default` compose them by name), so splitting them would
make modules import each other in a circle; what they are given and return
(:class:`Task`, :class:`Solution`, :class:`StrategyFailed`) lives in
:mod:`rolling_cli.solver.task`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..model.friction import SlipFriction
from . import continuation, formulation, predictor, reduced
from .budget import Budget, BudgetExhausted
from .formulation import Evaluation, Problem, State
from .newton import Armijo, NewtonFailure, NonlinearSystem, Watchdog, newton
from .system import ContactSystem
from .task import TANGENTIAL_KINDS, Controls, Solution, Strategy, StrategyFailed, Task  # noqa: F401 (the strategies' names)

# --- one Newton run on one problem ---------------------------------------------------------------


def _nonlinear(problem: Problem, scales: formulation.Scales) -> NonlinearSystem:
    def evaluate(x):
        return formulation.evaluate(problem, State.unpack(x), scales)

    linear: dict = {}

    def step(x, ev):
        linear.clear()
        return reduced.newton_point(problem, State.unpack(x), ev, linear).pack()

    def describe(x, ev):
        return {
            "creep": float(x[-1]),
            "overlap": float(x[-2]),
            "contact": int(ev.contact.sum()),
            "stick": int(ev.stick.sum()),
            "edge": bool(ev.contact[0] or ev.contact[-1]),
            "linear_solver": "dense LU"
            if problem.friction is not None and problem.tangential
            else problem.system.linear_solver,
        }

    return NonlinearSystem(evaluate, step, describe, lambda: dict(linear))


def run_newton(
    problem: Problem,
    start: State,
    tolerance: float,
    budget: Budget,
    strategy: str,
    stage: str,
    cold: bool = False,
    globalisation=None,
) -> Solution:
    """Newton on one stage problem to the tolerance, or to :data:`~rolling_cli.solver.formulation.FLOOR_FACTOR`
    times the round-off floor where that is larger (the history's "tolerance" column says which);
    raises :class:`StrategyFailed` with the best state."""
    scales = formulation.traction_scales(problem, start)
    system = _nonlinear(problem, scales)
    first = formulation.evaluate(problem, start, scales, cold=True) if cold else None
    applied = max(tolerance, formulation.FLOOR_FACTOR * formulation.roundoff_floor(problem, scales))
    label = {"strategy": strategy, "stage": stage, "tolerance": applied}
    try:
        x, ev = newton(
            system,
            start.pack(),
            tolerance=applied,
            budget=budget,
            globalisation=globalisation or Watchdog(),
            first=first,
            label=label,
        )
    except NewtonFailure as err:
        raise StrategyFailed(strategy, stage, err.reason, State.unpack(err.best_x), err.best.residual) from None
    return Solution(State.unpack(x), ev, problem)


def _clip_to_friction(state: State, p_t: np.ndarray, mu: float) -> State:
    out = state.copy()
    out.p_t = np.clip(p_t, mu * state.p_n, -mu * state.p_n)
    return out


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
    state = _clip_to_friction(normal.state, held_p_t, task.mu)
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
        return _creep_root(problem, task, best, budget, globalisation)


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
    state = _clip_to_friction(normal.state, guess, task.mu)
    return run_newton(task.problem("coupled"), state, task.tolerance, budget, name, "coupled", False, globalisation)


def scaled_coupling(system: ContactSystem, kappa: float) -> ContactSystem:
    """The contact system with its normal-tangential cross blocks times ``kappa`` (None at 0)."""
    if system.S_nt is None:
        return system
    if kappa == 0.0:
        return dataclasses.replace(system, S_nt=None, B_tn=None, gauge_tn=None)

    def scaled(block):
        return None if block is None else kappa * block

    return dataclasses.replace(
        system, S_nt=scaled(system.S_nt), B_tn=scaled(system.B_tn), gauge_tn=scaled(system.gauge_tn)
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
            _predict(task.system.x, task.mu),
            points,
            failure=StrategyFailed,
            control=continuation.StepControl(),
            budget=budget,
        )
    except continuation.ContinuationFailed as err:
        best = err.best.state if err.best is not None else None
        raise StrategyFailed(name, f"{symbol} = {err.parameter:.4g}", err.reason, best, err.residual) from None
    return points[-1][1]


def _predict(x: np.ndarray, mu: float):
    """The boundary-secant predictor over points [(s, Solution)] (a copy from one point)."""

    def predict(points, s):
        return predictor.secant(x, [(sk, sol.state, sol.zones()) for sk, sol in points[-2:]], s, mu)

    return predict


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
        state = _clip_to_friction(normal.state, start.p_t, task.mu)
    return _creep_root(problem, task, state, budget, globalisation)


#: The creep root does not look beyond this creepage (100 %: the bodies no longer roll on each other).
MAX_CREEP = 1.0


def _creep_root(problem: Problem, task: Task, state: State, budget: Budget, globalisation=None) -> Solution:
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
    starts (:func:`_full_slip_onset`) when that lies beyond the root, the others expand
    geometrically in the direction of the root.
    A solution in full slip (one way or, with a coupling, both) holds unchanged up to
    the creepage where the first node's slip reaches zero (:func:`_full_slip_edge`), so the bracket end
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
    predict = _predict(system.x, task.mu)
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
        target, _ = problem.force_target(current.p_n)
        q = float(system.weights @ current.p_t)
        scale = formulation.traction_scales(problem, current).tangential
        f = (q - target) / (lz * scale)
        budget.history[-1]["force_residual"] = f
        xi = current.creep
        if abs(f) <= budget.history[-1]["tolerance"]:
            ev = formulation.evaluate(problem, current, formulation.traction_scales(problem, current))
            return Solution(current, ev, problem)
        edge = _full_slip_edge(system, current, inner.evaluation, upward=f > 0.0)
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
                d_q, dp_n = reduced.creep_derivatives(held, current, inner.evaluation)
                _, d_target = problem.force_target(current.p_n)
                if d_target is not None:  # overlap control: Q_target = (Q/P) P moves with P(xi)
                    d_q -= float(d_target @ dp_n)
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
            target, _ = problem.force_target(current.p_n)
            if not jumped and (f > 0.0) == (target < 0.0):  # the target's full slip lies beyond the root
                jumped = True
                sigma = 1.0 if target > 0.0 else -1.0
                proposal = _full_slip_onset(system, current, task.mu, sigma)
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


def _full_slip_onset(system: ContactSystem, state: State, mu: float, sigma: float) -> float | None:
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


def _full_slip_edge(system: ContactSystem, state: State, ev: Evaluation, upward: bool) -> float | None:
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
