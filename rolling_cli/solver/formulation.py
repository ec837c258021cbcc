"""The rolling contact problem as projection equations (paper eq. 28-39), in pure functions.

At a creepage xi and an overlap the contact laws are the projections

    F_n = p_n - min(0, p_n + r_n delta_n)                                    = 0   (eq. 28)
    F_t = p_t - Proj_[-g, g](p_t - r_t s_t),  g = -mu min(0, p_n + r_n delta_n) = 0   (eq. 31)

with the gap delta_n and the slip s_t the linear functions of
:class:`~rolling_cli.solver.system.ContactSystem` (eq. 33). A prescribed load P makes
the overlap unknown, with the equation sum w p_n + P = 0 (a finite cylinder's shaft load:
sum w (cos theta p_n - sin theta p_t) + P = 0, :meth:`ContactSystem.load`); a prescribed
tangential force makes the creepage unknown, with sum w p_t = Q_target.

The generalised Jacobian (eq. 36-39) depends on each node's state:
separation (p_n + r_n delta_n >= 0), adhesion (|p_t - r_t s_t| < g) or slip.
Because the elastic rows are linear, the Newton step with the Jacobian of the
current states is the exact solution of a linear system on the contact nodes
only (:func:`rolling_cli.solver.reduced.newton_point`):

* separation: p_n = p_t = 0;
* contact: delta_n = 0;
* adhesion: s_t = 0;  slip: p_t = sigma g = -mu sigma p_n, sigma = sgn(p_t - r_t s_t).

Nothing in this module iterates. The node-state rules are small named
functions (:func:`contact_by_projection`, :func:`contact_from_pressure`,
:func:`adhesion_by_projection`, :func:`reversal_through_adhesion`,
:func:`nearest_contact`, :func:`full_slip_safeguard`); the solver strategies
choose which apply.

Residuals are measured in units of the traction scales: the normal rows
against s_n = max(max|p_n|, P / zone length), the tangential rows against
s_t = mu s_n, so that a tolerance means the same for any penalty and any
friction coefficient (a prescribed Q is met to tolerance * mu P however small
mu is). The merit that the globalisation decreases weighs the tangential rows
against max(mu, 0.1) s_n instead (:func:`traction_scales`).
"""

from __future__ import annotations

import dataclasses
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .system import ContactSystem, abs_row_sum_max

if TYPE_CHECKING:
    from ..model.friction import SlipFriction

MODES = ("coupled", "normal", "tangential")


@dataclass
class State:
    """An iterate: tractions p_n, p_t [stress], overlap [length] and creepage xi [-]."""

    p_n: np.ndarray
    p_t: np.ndarray
    overlap: float
    creep: float

    def copy(self) -> State:
        """An independent copy."""
        return State(self.p_n.copy(), self.p_t.copy(), float(self.overlap), float(self.creep))

    def pack(self) -> np.ndarray:
        """The unknowns as one vector [p_n, p_t, overlap, creep] (mixed units)."""
        return np.concatenate([self.p_n, self.p_t, [self.overlap, self.creep]])

    @staticmethod
    def unpack(x: np.ndarray) -> State:
        """Inverse of :meth:`pack`."""
        n = (x.size - 2) // 2
        return State(x[:n].copy(), x[n : 2 * n].copy(), float(x[2 * n]), float(x[2 * n + 1]))


@dataclass(frozen=True)
class Problem:
    """What is unknown in one solve.

    ``mode``: one of :data:`MODES` (which tractions are unknown: both, p_n with
    p_t held, p_t with p_n held); ``mu``: friction coefficient; ``load``: the
    prescribed P [force/length] (the overlap is then unknown) or ``None`` (the
    overlap is held at the state's value); ``force``: (kind, value) with kind
    "load" (Q [force/length]), "q_over_p" or "q_over_mu_p" makes the creepage
    unknown with the equation sum w p_t = Q_target, or ``None`` (creepage held);
    ``friction``: a velocity-dependent law (the friction bound is then mu(s_a) |p_n| and ``mu``
    its mu_static, the scale of the residuals and of Q/(mu P); :mod:`rolling_cli.solver.velocity`),
    or ``None`` for Coulomb friction with ``mu``.
    """

    system: ContactSystem
    mode: str
    mu: float
    load: float | None = None
    force: tuple[str, float] | None = None
    friction: SlipFriction | None = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"mode must be one of {MODES}, got {self.mode!r}")

    @property
    def normal(self) -> bool:
        """True when p_n is unknown."""
        return self.mode in ("coupled", "normal")

    @property
    def tangential(self) -> bool:
        """True when p_t is unknown."""
        return self.mode in ("coupled", "tangential")

    @property
    def overlap_unknown(self) -> bool:
        """True when the overlap is an unknown (P prescribed and the normal problem solved)."""
        return self.normal and self.load is not None

    @property
    def creep_unknown(self) -> bool:
        """True when the creepage is an unknown (a tangential force prescribed)."""
        return self.force is not None and self.tangential

    def force_target(self, p_n: np.ndarray, p_t: np.ndarray) -> tuple[float, np.ndarray | None]:
        """Q_target [force/length] and, when it depends on p_n, its gradient d Q_target / d p_n (a ratio
        Q/P or Q/(mu P) under overlap control: P = :meth:`ContactSystem.load`, which for a finite
        cylinder moves with p_t too: :meth:`target_gradient_t`)."""
        if self.force is None:
            raise ValueError("no tangential force is prescribed")
        kind, value = self.force
        if kind == "load":
            return value, None
        factor = value if kind == "q_over_p" else value * self.mu
        if self.load is not None:
            return factor * self.load, None
        return factor * self.system.load(p_n, p_t), -factor * self.system.load_weights

    def target_gradient_t(self) -> np.ndarray | None:
        """d Q_target / d p_t [length]: a ratio target under overlap control on a system whose load
        holds p_t (a finite cylinder's shaft load), else None (Q_target does not move with p_t)."""
        if self.force is None or self.force[0] == "load" or self.load is not None or self.system.load_t is None:
            return None
        factor = self.force[1] if self.force[0] == "q_over_p" else self.force[1] * self.mu
        return -factor * self.system.load_t

    def held(self, **changes) -> Problem:
        """A copy with fields replaced (for example ``force=None`` to hold the creepage)."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True)
class Scales:
    """Traction scales of the residual rows [stress]: normal s_n and tangential s_t."""

    normal: float
    tangential: float
    merit_tangential: float = 0.0

    @property
    def weight_tangential(self) -> float:
        """The scale that weighs the tangential rows in the merit [stress]: :data:`MERIT_FRICTION` s_n
        at least (see :func:`traction_scales`)."""
        return max(self.tangential, self.merit_tangential)


#: The tangential rows weigh in the merit as if mu were at least this (see :func:`traction_scales`).
MERIT_FRICTION = 0.1


def traction_scales(problem: Problem, state: State) -> Scales:
    """s_n = max(max|p_n|, P / zone length) and s_t = mu s_n (s_n when frictionless) [stress].

    The convergence test (:attr:`Evaluation.relative_residual`) divides the tangential rows by
    s_t; the merit that the globalisation decreases (:attr:`Evaluation.merit`) by
    max(mu, :data:`MERIT_FRICTION`) s_n. With s_t alone the tangential rows outweigh the normal
    ones by 1/mu^2 (1e5 at mu = 0.003): with a coupling a step that settles the pressure, and
    with it the friction bound, raises the merit through the tangential rows and is refused,
    and small-friction cases near full slip ran out of iterations (issue 26: 100+ iterations
    against 24 with the weight floored, benchmarks/RESULTS.md). Where mu >= 0.1 nothing changes.
    """
    system = problem.system
    s_n = float(np.max(np.abs(state.p_n))) if state.p_n.size else 0.0
    if problem.load is not None:
        s_n = max(s_n, problem.load / system.zone_length)
    if not s_n > 0.0:
        s_n = 1.0
    s_t = problem.mu * s_n if problem.mu > 0.0 else s_n
    return Scales(s_n, s_t, MERIT_FRICTION * s_n)


@dataclass
class Evaluation:
    """Residual rows [stress] and node states at one iterate (``gap`` only when p_n is unknown,
    ``slip`` only when p_t is; ``capacity`` -min(0, p_n + r_n delta_n) [stress], of which the friction
    bound is mu(s_a) times, only with a velocity-dependent law)."""

    F_n: np.ndarray
    F_t: np.ndarray
    F_load: float
    F_force: float
    contact: np.ndarray
    stick: np.ndarray
    sigma: np.ndarray
    friction_bound: np.ndarray
    gap: np.ndarray | None
    slip: np.ndarray | None
    scales: Scales
    slip_margin: np.ndarray | None = None
    capacity: np.ndarray | None = None

    @property
    def merit(self) -> float:
        """0.5 |F / s|^2, every row divided by its traction scale, the tangential ones by
        :attr:`Scales.weight_tangential` (see :func:`traction_scales`) [-]."""
        s_n, s_t = self.scales.normal, self.scales.weight_tangential
        return 0.5 * (
            (float(self.F_n @ self.F_n) + self.F_load**2) / s_n**2
            + (float(self.F_t @ self.F_t) + self.F_force**2) / s_t**2
        )

    @property
    def relative_residual(self) -> float:
        """max |F| / s over all rows [-]."""
        s_n, s_t = self.scales.normal, self.scales.tangential
        normal = max(float(np.max(np.abs(self.F_n), initial=0.0)), abs(self.F_load)) / s_n
        tangential = max(float(np.max(np.abs(self.F_t), initial=0.0)), abs(self.F_force)) / s_t
        return max(normal, tangential)

    @property
    def residual(self) -> float:
        """The convergence measure of the generic Newton: :attr:`relative_residual`."""
        return self.relative_residual


#: A converged residual need not be below this multiple of the round-off floor.
FLOOR_FACTOR = 10.0


def roundoff_floor(problem: Problem, scales: Scales) -> float:
    """The relative residual that round-off alone leaves [-]; a property of the system, not of an iterate.

    A residual row is a penalty times a gap or a slip, each a sum over all nodes
    (the log kernel does not decay), so its rounding error is about eps times
    the row sum of the magnitudes: eps r_n (max_i sum_j |S_nn,ij| s_n + ... + max
    gap0) / s_n for the normal rows, and likewise with B_tt, B_tn for the
    tangential ones. (At a solution the overlap and the creepage balance these
    terms, so they add nothing; taking them from an iterate would let a wild
    iterate raise the floor.) It grows with the number of nodes (2e-14 at 60
    nodes, 1e-11 at 3000 for the log kernel), so a tolerance below it cannot be
    met however well Newton does.
    """
    system = problem.system
    eps = np.finfo(float).eps
    s_n, s_t = scales.normal, scales.tangential
    nn, nt, tt, tn, gap0 = _row_sums(system)
    floor = 0.0
    if problem.normal:
        floor = eps * system.reference_penalty_n * (nn * s_n + nt * s_t + gap0) / s_n
    if problem.tangential:
        floor = max(floor, eps * system.reference_penalty_t * (tt * s_t + tn * s_n) / s_t)
    return floor


_ROW_SUMS: dict[int, tuple] = {}


def _row_sums(system: ContactSystem) -> tuple[float, float, float, float, float]:
    """max_i sum_j |M_ij| of S_nn, S_nt and of B_tt, B_tn over the slip rows, and max |gap0|; cached per
    system (a property of its matrices: sweeps and strategies solve many problems on one system)."""
    key = id(system)
    cached = _ROW_SUMS.get(key)
    if cached is not None and cached[0]() is system:
        return cached[1]

    def row_sum(matrix, rows=None):
        return abs_row_sum_max(matrix, rows) if matrix is not None else 0.0

    rows = np.ones(system.size, dtype=bool)
    rows[system.gauge] = False
    values = (
        row_sum(system.S_nn),
        row_sum(system.S_nt),
        row_sum(system.B_tt, rows),
        row_sum(system.B_tn, rows),
        float(np.abs(system.gap0).max()),
    )
    if len(_ROW_SUMS) > 32:
        _ROW_SUMS.clear()
    _ROW_SUMS[key] = (weakref.ref(system), values)
    return values


# --- node-state rules -------------------------------------------------------------------------------


def contact_by_projection(p_n: np.ndarray, gap: np.ndarray, r_n: float) -> np.ndarray:
    """Contact where p_n + r_n delta_n < 0 (eq. 38-39)."""
    return p_n + r_n * gap < 0.0


def contact_from_pressure(p_n: np.ndarray) -> np.ndarray:
    """Contact where p_n < 0: the limit r_n -> 0, for a first iterate whose gap comes from a
    guessed overlap (and, with coupling, a guessed tangential traction): the pressure guess is
    the more reliable of the two."""
    return p_n < 0.0


def adhesion_by_projection(lam_t: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """Adhesion where |p_t - r_t s_t| < g (eq. 39)."""
    return np.abs(lam_t) < bound


def reversal_through_adhesion(p_t: np.ndarray, lam_t: np.ndarray) -> np.ndarray:
    """Nodes whose traction would reverse (p_t and p_t - r_t s_t of opposite signs) pass through
    adhesion: with a large r_t such a node would otherwise jump to the opposite slip state and the
    iteration oscillates. At a solution the slip opposes the traction, so no fixed point changes."""
    return p_t * lam_t < 0.0


def nearest_contact(p_n: np.ndarray, gap: np.ndarray, r_n: float) -> int:
    """The node closest to contact (smallest p_n + r_n delta_n): taken as in contact when no node is,
    else the normal system has no pressure unknown."""
    return int(np.argmin(p_n + r_n * gap))


def full_slip_safeguard(
    contact: np.ndarray, margin: np.ndarray, bound: np.ndarray, weights: np.ndarray, force_gap: float
) -> np.ndarray:
    """Adhesion nodes for a full-slip iterate under force control.

    Without an adhesion row the creepage column vanishes and the force-controlled
    system is singular (PHYSICS.md trap). The slip nodes closest to adhesion
    (smallest ``margin`` = |p_t - r_t s_t| - g) are taken as adhering, as many as
    it takes for their friction capacity, sum 2 w g, to cover ``force_gap`` = |Q_target
    - Q_full_slip| [force/length]; one node alone may be unable to, and the iteration
    would return to the same state. Returns the boolean adhesion mask.
    """
    stick = np.zeros_like(contact)
    count_contact = int(contact.sum())
    if count_contact == 0:
        return stick
    order = np.argsort(np.where(contact, margin, np.inf))[:count_contact]
    capacity = np.cumsum(2.0 * weights[order] * bound[order])
    count = int(np.searchsorted(capacity, force_gap)) + 1
    stick[order[: min(count, order.size)]] = True
    return stick


# --- residual and node states -----------------------------------------------------------------------


def evaluate(problem: Problem, state: State, scales: Scales, cold: bool = False) -> Evaluation:
    """Residual F and the node states at ``state`` (eq. 33 with delta and s eliminated).

    ``cold=True`` reads the contact states from the pressure
    (:func:`contact_from_pressure`), for a first iterate built from closed forms,
    whose gap comes from a guessed overlap tilted through the coupling by a
    guessed p_t. (The adhesion states keep r_t: a Carter guess sits exactly on
    the friction bound in the slip zone, where the traction alone cannot tell
    adhesion from slip; measured, reading them from the traction made 11 more of
    838 strongly coupled random cases fail.) Node states (the Jacobian) use the
    solver's penalties; the residual uses the automatic reference ones, so the
    tolerance means the same whatever r.
    """
    system = problem.system
    mu = problem.mu
    gap = slip_t = None
    if problem.normal:
        gap = system.gap(state.p_n, state.p_t, state.overlap)
        lam_n = state.p_n + system.penalty_n * gap
        contact = contact_from_pressure(state.p_n) if cold else lam_n < 0.0
        bound = -mu * np.minimum(0.0, state.p_n if cold else lam_n)
        lam_ref = state.p_n + system.reference_penalty_n * gap
        F_n = state.p_n - np.minimum(0.0, lam_ref)
        bound_ref = -mu * np.minimum(0.0, lam_ref)
        lam_bound = state.p_n if cold else lam_n
    else:
        contact = contact_from_pressure(state.p_n)
        F_n = np.zeros_like(state.p_n)
        bound = bound_ref = -mu * np.minimum(0.0, state.p_n)
        lam_bound = lam_ref = state.p_n
    capacity = None
    if problem.tangential:
        slip_t = system.slip(state.p_n, state.p_t, state.creep)
        if problem.friction is not None:  # the bound mu(s_a) |lambda_n| at this iterate's slip
            mu_nodes = problem.friction.at(slip_t)[0]
            capacity = -np.minimum(0.0, lam_bound)
            bound = mu_nodes * capacity
            bound_ref = -mu_nodes * np.minimum(0.0, lam_ref)
        lam_t = state.p_t - system.penalty_t * slip_t
        stick = contact & (adhesion_by_projection(lam_t, bound) | reversal_through_adhesion(state.p_t, lam_t))
        sigma = np.where(contact & ~stick, np.sign(lam_t), 0.0)
        margin = np.abs(lam_t) - bound
        F_t = state.p_t - np.clip(state.p_t - system.reference_penalty_t * slip_t, -bound_ref, bound_ref)
    else:
        stick = np.zeros_like(contact)
        sigma = np.zeros_like(state.p_t)
        F_t = np.zeros_like(state.p_t)
        margin = None
    F_load = 0.0
    if problem.overlap_unknown and problem.load is not None:
        F_load = (problem.load - system.load(state.p_n, state.p_t)) / system.zone_length
    F_force = 0.0
    if problem.creep_unknown:
        target, _ = problem.force_target(state.p_n, state.p_t)
        F_force = (float(system.weights @ state.p_t) - target) / system.zone_length
    return Evaluation(F_n, F_t, F_load, F_force, contact, stick, sigma, bound, gap, slip_t, scales, margin, capacity)


@dataclass(frozen=True)
class NodeSets:
    """Index sets of the Newton system: contact, adhesion and slip nodes, and sigma on slip nodes."""

    contact: np.ndarray
    stick: np.ndarray
    slip: np.ndarray
    sigma: np.ndarray


def node_sets(problem: Problem, state: State, ev: Evaluation) -> NodeSets:
    """Contact, adhesion and slip sets for the Jacobian, with :func:`nearest_contact` and
    :func:`full_slip_safeguard` applied."""
    system = problem.system
    contact = ev.contact.copy()
    if problem.normal and ev.gap is not None and not contact.any():
        contact[nearest_contact(state.p_n, ev.gap, system.penalty_n)] = True
    stick = ev.stick & contact
    # (a velocity-dependent law keeps the creepage in the full-slip rows through d mu/d s: no safeguard)
    if (
        problem.creep_unknown
        and problem.friction is None
        and ev.slip_margin is not None
        and contact.any()
        and not stick.any()
    ):
        target, _ = problem.force_target(state.p_n, state.p_t)
        full_slip = float(system.weights @ (ev.sigma * ev.friction_bound))
        stick = full_slip_safeguard(contact, ev.slip_margin, ev.friction_bound, system.weights, abs(target - full_slip))
    slipping = contact & ~stick if problem.tangential else np.zeros_like(contact)
    sigma = np.where(slipping, ev.sigma, 0.0)
    return NodeSets(np.flatnonzero(contact), np.flatnonzero(stick), np.flatnonzero(slipping), sigma)


@dataclass
class Layout:
    """The unknowns, right-hand side and bookkeeping of one reduced system (see
    :class:`~rolling_cli.solver.reduced.ReducedSystem`): ``nc``, ``ns`` unknowns of p_n on ``contact`` and p_t on
    ``stick`` (none where that traction is held), the overlap and creepage columns,
    ``coef`` (p_t = coef p_n on the slip nodes, coupled mode), ``p_t_slip`` (the known
    slip tractions, tangential mode), ``creep_vector`` on the adhesion rows, ``force_row_n``
    (the force row's entries on the p_n unknowns, coupled force control); ``load_row_n``,
    ``load_row_t`` the load row's entries on the p_n and p_t unknowns (None: w on p_n, none on
    p_t) and ``force_row_t`` the force row's on p_t (None: w), other than the arc sums where the
    load is a finite cylinder's shaft load (:meth:`ContactSystem.load`)."""

    contact: np.ndarray
    stick: np.ndarray
    size: int
    col_overlap: int | None
    col_creep: int | None
    coef: np.ndarray | None
    p_t_slip: np.ndarray | None
    creep_vector: np.ndarray | None
    force_row_n: np.ndarray | None
    rhs: np.ndarray
    creep_column: np.ndarray | None
    load_row_n: np.ndarray | None = None
    load_row_t: np.ndarray | None = None
    force_row_t: np.ndarray | None = None

    @property
    def nc(self) -> int:
        return int(self.contact.size)

    @property
    def ns(self) -> int:
        return int(self.stick.size)
