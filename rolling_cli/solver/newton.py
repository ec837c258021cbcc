"""Generalised Newton method for the projection equations (paper eq. 28-39).

At a fixed creepage xi the contact laws are the projections

    F_n = p_n - min(0, p_n + r_n delta_n)                       = 0   (eq. 28)
    F_t = p_t - Proj_[-g, g](p_t - r_t s_t),  g = -mu min(0, p_n + r_n delta_n)   (eq. 31)

with delta_n and s_t the linear functions of :class:`~rolling_cli.system.ContactSystem`
(eq. 33). When the load P is prescribed, the overlap is an extra unknown with
the extra equation sum w p_n + P = 0.

The generalised Jacobian (eq. 36-39) depends on each node's state: separation
(p + r delta >= 0), adhesion (|p_t - r_t s_t| < g) or slip. Because the elastic
rows are linear, a Newton step with the Jacobian of the current states is the
exact solution of a linear system on the contact nodes only:

* separation: p_n = p_t = 0;
* contact: delta_n = 0;
* adhesion: s_t = 0;  slip: p_t = sigma g = -mu sigma p_n, sigma = sgn(p_t - r_t s_t).

That reduced system (contact + adhesion unknowns, plus the overlap) is solved
by one LU factorisation; the step to the Newton point is then damped by a
backtracking line search on the merit 0.5 |F|^2 (PHYSICS.md: without it the
iteration cycles). ``mode`` selects which tractions are unknown: "coupled"
(both, eq. 33), "normal" (eq. 30, p_t held) or "tangential" (eq. 32, p_n held).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError
from ..system import ContactSystem
from .linalg import solve_dense

MODES = ("coupled", "normal", "tangential")


@dataclass
class State:
    """An iterate: tractions [stress], overlap [length] and creepage [-]."""

    p_n: np.ndarray
    p_t: np.ndarray
    overlap: float
    creep: float

    def copy(self) -> State:
        return State(self.p_n.copy(), self.p_t.copy(), float(self.overlap), float(self.creep))


@dataclass(frozen=True)
class Problem:
    """What is unknown in one inner solve.

    ``mode``: one of :data:`MODES`; ``mu``: friction coefficient; ``load``: the
    prescribed P [force/length] (the overlap is then unknown) or ``None`` (the
    overlap is held at the state's value); ``force``: (kind, value) with kind
    "load" (Q [force/length]), "q_over_p" or "q_over_mu_p" makes the creepage
    unknown with the equation sum w p_t = Q_target, or ``None`` (creepage held).
    """

    system: ContactSystem
    mode: str
    mu: float
    load: float | None = None
    force: tuple[str, float] | None = None

    @property
    def creep_unknown(self) -> bool:
        return self.force is not None and self.tangential

    def force_target(self, p_n: np.ndarray) -> tuple[float, np.ndarray | None]:
        """Q_target [force/length] and, when it depends on p_n, its gradient d Q_target / d p_n."""
        kind, value = self.force
        if kind == "load":
            return value, None
        factor = value if kind == "q_over_p" else value * self.mu
        if self.load is not None:
            return factor * self.load, None
        w = self.system.weights
        return factor * float(-(w @ p_n)), -factor * w

    @property
    def normal(self) -> bool:
        return self.mode in ("coupled", "normal")

    @property
    def tangential(self) -> bool:
        return self.mode in ("coupled", "tangential")


@dataclass
class Evaluation:
    """Residual and node states at one iterate."""

    F_n: np.ndarray
    F_t: np.ndarray
    F_load: float
    F_force: float
    contact: np.ndarray
    stick: np.ndarray
    sigma: np.ndarray
    friction_bound: np.ndarray
    gap: np.ndarray
    slip: np.ndarray
    scale: float
    slip_margin: np.ndarray | None = None

    @property
    def merit(self) -> float:
        """0.5 |F|^2 [stress^2]."""
        return 0.5 * (float(self.F_n @ self.F_n) + float(self.F_t @ self.F_t) + self.F_load**2 + self.F_force**2)

    @property
    def relative_residual(self) -> float:
        """max |F| / traction scale [-]."""
        worst = max(
            float(np.max(np.abs(self.F_n))),
            float(np.max(np.abs(self.F_t))),
            abs(self.F_load),
            abs(self.F_force),
        )
        return worst / self.scale


@dataclass
class InnerResult:
    """Outcome of one inner solve."""

    state: State
    evaluation: Evaluation
    iterations: int
    history: list[dict] = field(default_factory=list)


def traction_scale(problem: Problem, state: State) -> float:
    """Reference traction for relative residuals [stress]: max(|p_n|, P / zone length)."""
    sys = problem.system
    ref = float(np.max(np.abs(state.p_n)))
    if problem.load is not None:
        ref = max(ref, problem.load / sys.zone_length)
    return ref if ref > 0.0 else 1.0


def evaluate(problem: Problem, state: State, scale: float, by_traction: bool = False) -> Evaluation:
    """Residual F and the node states at ``state`` (eq. 33 with delta, s eliminated).

    ``by_traction=True`` reads the contact states from the pressure alone (the
    limit r_n -> 0): used for the first iterate, whose gap comes from a guessed
    overlap and, with coupling, is tilted by the guessed tangential traction;
    the pressure guess is the more reliable of the two. (The adhesion states
    keep r_t: a Carter guess sits exactly on the friction bound in the slip
    zone, where the traction alone cannot tell adhesion from slip.)
    """
    sys = problem.system
    mu = problem.mu
    r_n = 0.0 if by_traction else sys.penalty_n
    r_t = sys.penalty_t
    gap = sys.gap(state.p_n, state.p_t, state.overlap)
    slip_t = sys.slip(state.p_n, state.p_t, state.creep)
    # Node states (the Jacobian) use the solver's penalties; the residual and the
    # merit use the automatic ones, so the tolerance means the same whatever r.
    if problem.normal:
        lam_n = state.p_n + r_n * gap
        contact = lam_n < 0.0
        bound = -mu * np.minimum(0.0, lam_n)
        lam_ref = state.p_n + sys.reference_penalty_n * gap
        F_n = state.p_n - np.minimum(0.0, lam_ref)
        bound_ref = -mu * np.minimum(0.0, lam_ref)
    else:
        contact = state.p_n < 0.0
        F_n = np.zeros_like(state.p_n)
        bound = bound_ref = -mu * np.minimum(0.0, state.p_n)
    if problem.tangential:
        lam_t = state.p_t - r_t * slip_t
        # A traction that would reverse passes through adhesion: with a large r_t a
        # slip node with wrong-way slip would otherwise jump to the opposite slip
        # state and the iteration oscillates. At a solution the slip opposes the
        # traction, so this changes no fixed point.
        reversal = state.p_t * lam_t < 0.0
        stick = contact & ((np.abs(lam_t) < bound) | reversal)
        sigma = np.where(contact & ~stick, np.sign(lam_t), 0.0)
        margin = np.abs(lam_t) - bound
        F_t = state.p_t - np.clip(state.p_t - sys.reference_penalty_t * slip_t, -bound_ref, bound_ref)
    else:
        stick = np.zeros_like(contact)
        sigma = np.zeros_like(state.p_t)
        F_t = np.zeros_like(state.p_t)
        margin = None
    F_load = 0.0
    if problem.load is not None and problem.normal:
        F_load = (float(sys.weights @ state.p_n) + problem.load) / sys.zone_length
    F_force = 0.0
    if problem.creep_unknown:
        target, _ = problem.force_target(state.p_n)
        F_force = (float(sys.weights @ state.p_t) - target) / sys.zone_length
    return Evaluation(F_n, F_t, F_load, F_force, contact, stick, sigma, bound, gap, slip_t, scale, margin)


def _node_sets(problem: Problem, state: State, ev: Evaluation):
    """Contact, adhesion and slip index sets for the Jacobian, with safeguards.

    * No contact node while the normal problem is solved: the node closest to
      contact is taken as in contact (else the system has no pressure unknown).
    * Creepage unknown and no adhesion node (a full-slip iterate): without an
      adhesion row the creepage column vanishes and the force-controlled system
      is singular (PHYSICS.md trap). The slip nodes closest to adhesion are
      taken as adhering (the generalised Jacobian at nearby kinks), as many as
      it takes for their friction capacity, sum 2 w g, to cover the gap between
      the prescribed force and the full-slip force; one node alone may be
      unable to, and the iteration would return to the same state.
    """
    sys = problem.system
    contact = ev.contact.copy()
    if problem.normal and not contact.any():
        contact[int(np.argmin(state.p_n + sys.penalty_n * ev.gap))] = True
    stick = ev.stick & contact
    if problem.creep_unknown and contact.any() and not stick.any():
        order = np.argsort(np.where(contact, ev.slip_margin, np.inf))[: int(contact.sum())]
        w = sys.weights
        target, _ = problem.force_target(state.p_n)
        full_slip = float(w @ (ev.sigma * ev.friction_bound))
        capacity = np.cumsum(2.0 * w[order] * ev.friction_bound[order])
        count = int(np.searchsorted(capacity, abs(target - full_slip))) + 1
        stick[order[: min(count, order.size)]] = True
    slipping = contact & ~stick if problem.tangential else np.zeros_like(contact)
    sigma = np.where(slipping, ev.sigma, 0.0)
    return np.flatnonzero(contact), np.flatnonzero(stick), np.flatnonzero(slipping), sigma


def _newton_point(problem: Problem, state: State, ev: Evaluation) -> State:
    """Solve the reduced linear system of the current node states for the Newton point.

    Unknowns z = [p_n on contact | p_t on adhesion | r_n overlap? | r_t creep?], all
    in stress units; rows
    r_n delta_n = 0 (contact), r_t s_t = 0 (adhesion), the load equation and
    the tangential force equation, both divided by the zone length so that
    every row is in stress units.
    """
    sys = problem.system
    mu = problem.mu
    c_idx, st_idx, sl_idx, sigma = _node_sets(problem, state, ev)
    r_n, r_t = sys.penalty_n, sys.penalty_t
    lz = sys.zone_length
    w = sys.weights
    overlap_unknown = problem.normal and problem.load is not None
    creep_unknown = problem.creep_unknown
    nc = c_idx.size if problem.normal else 0
    ns = st_idx.size if problem.tangential else 0
    size = nc + ns + overlap_unknown + creep_unknown
    A = np.zeros((size, size), order="F")  # LAPACK layout: no copy before the LU
    rhs = np.zeros(size)
    rows_n = slice(0, nc)
    rows_t = slice(nc, nc + ns)
    k = nc + ns
    col_overlap = k if overlap_unknown else None
    k += overlap_unknown
    col_creep = k if creep_unknown else None

    # p_t on slip nodes: coupled -> coef * p_n (unknown); tangential -> sigma g (known)
    coef = -mu * sigma[c_idx] if problem.mode == "coupled" else None
    p_t_slip = sigma[sl_idx] * ev.friction_bound[sl_idx] if problem.mode == "tangential" else None

    if problem.normal:
        a_nn = sys.S_nn[np.ix_(c_idx, c_idx)]
        if sys.S_nt is not None and coef is not None:
            a_nn = a_nn + sys.S_nt[np.ix_(c_idx, c_idx)] * coef[None, :]
        A[rows_n, :nc] = r_n * a_nn
        fixed = sys.gap0[c_idx] - (0.0 if overlap_unknown else state.overlap)
        if sys.S_nt is not None:
            if problem.tangential:
                A[rows_n, nc : nc + ns] = r_n * sys.S_nt[np.ix_(c_idx, st_idx)]
            else:
                fixed = fixed + sys.S_nt[c_idx] @ state.p_t
        rhs[rows_n] = -r_n * fixed
        if overlap_unknown:  # unknown r_n * overlap, in stress units like the tractions
            A[rows_n, col_overlap] = -1.0
            A[col_overlap, :nc] = w[c_idx] / lz
            rhs[col_overlap] = -problem.load / lz
    if problem.tangential:
        A[rows_t, nc : nc + ns] = r_t * sys.B_tt[np.ix_(st_idx, st_idx)]
        e = sys.creep_vector[st_idx]
        fixed = np.zeros(ns) if creep_unknown else state.creep * e
        if problem.normal:
            a_tn = sys.B_tt[np.ix_(st_idx, c_idx)] * coef[None, :]
            if sys.B_tn is not None:
                a_tn = a_tn + sys.B_tn[np.ix_(st_idx, c_idx)]
            A[rows_t, :nc] = r_t * a_tn
        else:
            fixed = fixed + sys.B_tt[np.ix_(st_idx, sl_idx)] @ p_t_slip
            if sys.B_tn is not None:
                fixed = fixed + sys.B_tn[st_idx] @ state.p_n
        rhs[rows_t] = -r_t * fixed
        if creep_unknown:  # unknown r_t * creep, in stress units like the tractions
            A[rows_t, col_creep] = e
            target, d_target = problem.force_target(state.p_n)
            A[col_creep, nc : nc + ns] = w[st_idx] / lz
            if problem.normal:
                row = w[c_idx] * coef
                if d_target is not None:
                    row = row - d_target[c_idx]
                A[col_creep, :nc] = row / lz
                rhs[col_creep] = target / lz if d_target is None else 0.0
            else:
                rhs[col_creep] = (target - float(w[sl_idx] @ p_t_slip)) / lz

    solution = solve_dense(A, rhs)

    new = state.copy()
    if problem.normal:
        new.p_n = np.zeros_like(state.p_n)
        new.p_n[c_idx] = solution[:nc]
    if problem.tangential:
        new.p_t = np.zeros_like(state.p_t)
        new.p_t[st_idx] = solution[nc : nc + ns]
        new.p_t[sl_idx] = coef[np.searchsorted(c_idx, sl_idx)] * new.p_n[sl_idx] if coef is not None else p_t_slip
    if overlap_unknown:
        new.overlap = float(solution[col_overlap]) / r_n
    if creep_unknown:
        new.creep = float(solution[col_creep]) / r_t
    return new


def _blend(a: State, b: State, alpha: float) -> State:
    return State(
        a.p_n + alpha * (b.p_n - a.p_n),
        a.p_t + alpha * (b.p_t - a.p_t),
        a.overlap + alpha * (b.overlap - a.overlap),
        a.creep + alpha * (b.creep - a.creep),
    )


def solve_inner(
    problem: Problem,
    state: State,
    tolerance: float,
    max_iterations: int,
    label: str = "",
    patience: int | None = None,
) -> InnerResult:
    """Generalised Newton with a backtracking line search, at the state's controls.

    Each iteration computes the Newton point of the current node states and
    takes the full step when it decreases the merit 0.5 |F|^2 (Armijo), else
    backtracks along the step. (An earlier variant also accepted non-decreasing
    full steps into unvisited node states; after the first-iterate and
    reversal rules of :func:`evaluate` it gained nothing on the test cases and
    made strongly coupled, high-friction cases wander: 105 iterations against
    18 for a rigid cylinder on a nu = 0 body with mu = 1.5.)

    Returns the converged state; raises :class:`ConvergenceError` (with the
    residual history and the last iterate) when ``max_iterations`` Newton steps
    do not bring the relative residual below ``tolerance``, or, with
    ``patience``, as soon as that many steps pass without a new lowest merit or
    a step fails to lower the merit at all.
    """
    if problem.mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}")
    scale = traction_scale(problem, state)
    ev = evaluate(problem, state, scale, by_traction=True)
    history: list[dict] = []
    best, best_at = ev.merit, 0
    for iteration in range(max_iterations + 1):
        res = ev.relative_residual
        history.append(
            {
                "stage": label,
                "iteration": iteration,
                "residual": res,
                "creep": state.creep,
                "overlap": state.overlap,
                "contact": int(ev.contact.sum()),
                "stick": int(ev.stick.sum()),
            }
        )
        if res <= tolerance:
            return InnerResult(state, ev, iteration, history)
        if ev.merit < (1.0 - 1e-4) * best:
            best, best_at = ev.merit, iteration
        if iteration == max_iterations or (patience is not None and iteration - best_at >= patience):
            break
        target = _newton_point(problem, state, ev)
        target_ev = evaluate(problem, target, scale)
        if target_ev.merit <= (1.0 - 1e-4) * ev.merit:
            state, ev, alpha = target, target_ev, 1.0
        else:
            previous = ev.merit
            state, ev, alpha = _backtrack(problem, state, ev, target, target_ev, scale)
            if patience is not None and ev.merit >= previous:
                history[-1]["step"] = alpha
                break  # a fixed point of the iteration: waiting will not help
        history[-1]["step"] = alpha
    raise ConvergenceError(
        f"Newton did not converge in {iteration} iterations",
        residual=ev.relative_residual,
        iterations=iteration,
        history=history,
        cause="the contact and adhesion sets keep changing; raise solver.max_iterations, "
        "refine the mesh or keep the automatic penalty",
        partial=state,
    )


def _backtrack(
    problem: Problem, state: State, ev: Evaluation, target: State, target_ev: Evaluation, scale: float
) -> tuple[State, Evaluation, float]:
    """Backtracking (Armijo) on the merit along state -> Newton point."""
    m0 = ev.merit
    best = (target, target_ev, 1.0)
    alpha = 0.5
    for _ in range(12):
        trial = _blend(state, target, alpha)
        trial_ev = evaluate(problem, trial, scale)
        if trial_ev.merit <= (1.0 - 1e-4 * alpha) * m0:
            return trial, trial_ev, alpha
        if trial_ev.merit < best[1].merit:
            best = (trial, trial_ev, alpha)
        alpha *= 0.5
    # No sufficient decrease: keep the best point tried (the full Newton step
    # if nothing was better) and let the iteration cap catch a cycle.
    return best
