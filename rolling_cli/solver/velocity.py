"""The generalised Newton step with a velocity-dependent friction law mu(s_a).

With Coulomb friction the slip nodes' tractions are eliminated exactly,
p_t = -mu sigma p_n (:mod:`rolling_cli.solver.reduced`). With mu(s_a), s_a =
|V| |s_t|, the friction bound g = mu(s_a) |lambda_n| depends on the slip s_t,
which is a linear function of all tractions, so the slip rows of the
projection equation F_t = p_t - sigma g(lambda_n, s_t) = 0 are linearised at
the iterate k:

    p_t,i = sigma_i g_i^k + (-sigma_i mu_i^k) (lambda_n,i - lambda_n,i^k) + h_i (s_t,i - s_t,i^k),
    h_i = sigma_i |lambda_n,i^k| d mu / d s_t (s_t,i^k),  d mu / d s_t = |V| mu'(s_a) sgn(s_t)

(the d mu/d s_a term of the generalised Jacobian). sgn(s_t) is taken as -sigma_i, its value
at a solution (slip opposes the traction), so h_i = |lambda_n,i^k| |V| (-mu'(s_a)) >= 0 for a
falling law: the same at the solution, and a slip node whose slip still has the wrong sign at
an iterate (or is exactly 0, a node just released from adhesion) gets the law's slope, not
its mirror image or none (measured: the same iteration counts either way). On contact nodes the
linearised normal row makes lambda_n = p_n, so in the coupled mode
sigma g^k + (-sigma mu^k)(lambda_n - lambda_n^k) = -sigma mu^k p_n). The slip
tractions therefore stay unknowns: z = [p_n on contact | p_t on the adhesion and
slip nodes, in node order | r_n overlap? | r_t creep?], with the contact, adhesion,
load and force rows of :mod:`rolling_cli.solver.reduced` and the slip rows above (in
stress units, the identity on their own p_t). The matrix is assembled dense
(on a matrix-free system from the operators' exact entries) and solved by LU, or
by GMRES on the LU of an earlier step where that still serves
(:mod:`rolling_cli.solver.reuse`: the same step, at a fraction of the cost).

Only a Problem with ``friction`` set reaches this module; Coulomb friction
keeps :mod:`rolling_cli.solver.reduced`'s code path unchanged.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from . import reuse
from .formulation import Evaluation, Problem, State, node_sets
from .linalg import block as _dense_block


def _block(matrix, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """matrix[rows][:, cols] of a dense array (a view where it can be) or a block-Toeplitz operator
    (its entries gathered, kept for the next step: :func:`_gathered`)."""
    if isinstance(matrix, np.ndarray):
        return _dense_block(matrix, rows, cols)
    return _gathered(matrix, rows, cols)


#: Gathered blocks of block-Toeplitz operators kept between Newton steps, at most this many (the
#: coupled system's four: S_nn, S_nt, B_tt, B_tn).
KEPT_BLOCKS = 4
_kept_blocks: list[tuple[weakref.ref, bytes, bytes, np.ndarray]] = []


def _gathered(matrix, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """matrix[rows][:, cols] of a block-Toeplitz operator, kept for the next call with the same
    operator and index sets (read-only). The tangential stage holds p_n, so its traction nodes, and
    with them the B_tt block, are the same at every step: gathering its entries again cost more
    than the LU (800 traction nodes: 40 ms a step against 31 ms; 2-core x86_64)."""
    key_rows, key_cols = rows.tobytes(), cols.tobytes()
    for owner, kept_rows, kept_cols, values in _kept_blocks:
        if owner() is matrix and kept_rows == key_rows and kept_cols == key_cols:
            return values
    values = matrix.block(rows, cols)
    values.setflags(write=False)
    live = [entry for entry in _kept_blocks if entry[0]() is not None]  # none of a system that is gone
    _kept_blocks[:] = [(weakref.ref(matrix), key_rows, key_cols, values), *live][:KEPT_BLOCKS]
    return values


def _rows(matrix, rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(matrix @ values)[rows] [per unit of values]."""
    if isinstance(matrix, np.ndarray):
        return matrix[rows] @ values
    return (matrix @ values)[rows]


@dataclass
class VelocitySystem:
    """The linear system A z = rhs of one Newton step (module docstring) and its bookkeeping:
    ``contact`` (p_n unknowns), ``traction`` (p_t unknowns: the adhesion and slip nodes in node
    order), ``slip_rows`` (the rows of the slip nodes, in node order), the overlap and creep
    columns, and ``creep_column`` = d rhs / d xi when the creepage is held."""

    matrix: np.ndarray
    rhs: np.ndarray
    contact: np.ndarray
    traction: np.ndarray
    slip_rows: np.ndarray
    col_overlap: int | None
    col_creep: int | None
    creep_column: np.ndarray | None

    @property
    def key(self) -> tuple:
        """The layout of the unknowns (a kept factorisation is tried on the same layout only:
        :mod:`rolling_cli.solver.reuse`)."""
        return (self.contact.tobytes(), self.traction.tobytes(), self.col_overlap, self.col_creep)


def slip_gain(problem: Problem, ev: Evaluation, slip_nodes: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """h_i = |lambda_n,i| |V| (-mu'(s_a,i)) on the slip nodes [stress]: d p_t / d s_t of a slipping node,
    sigma_i |lambda_n,i| d mu/d s_t with sgn(s_t) = -sigma_i (module docstring)."""
    assert problem.friction is not None and ev.slip is not None and ev.capacity is not None
    law, speed = problem.friction.law, problem.friction.speed
    dmu_ds = law.dmu_ds(speed * np.abs(ev.slip[slip_nodes]))
    return -ev.capacity[slip_nodes] * speed * dmu_ds


def velocity_system(problem: Problem, state: State, ev: Evaluation) -> VelocitySystem:
    """The Newton system of the current node states with mu(s_a) (module docstring).

    The traction rows and columns are in node order: an adhesion row is r_t s_t = 0, a slip row
    p_t - h s_t = ..., so both are a row factor (r_t, or -h) times the same rows of B_tt (and B_tn)
    over the traction columns, plus the identity on the slip rows: one scaled copy of a block
    (a view where the contact is one run of nodes), not two gathers.

    Over 80 lines for a reason: the rows of one matrix, block by block, each next to its
    right-hand side; split up, the column bookkeeping would be passed around whole.
    """
    system = problem.system
    assert problem.friction is not None and ev.slip is not None and ev.capacity is not None
    sets = node_sets(problem, state, ev)
    r_n, r_t, lz, w = system.penalty_n, system.penalty_t, system.zone_length, system.weights
    coupled = problem.mode == "coupled"
    contact = sets.contact if problem.normal else sets.contact[:0]
    slip = sets.slip
    slipping = np.zeros(system.size, dtype=bool)
    slipping[slip] = True
    member = slipping.copy()
    member[sets.stick] = True
    traction = np.flatnonzero(member)  # the adhesion and slip nodes in node order
    slipping = slipping[traction]
    nc, nt = contact.size, traction.size
    overlap_unknown, creep_unknown = problem.overlap_unknown, problem.creep_unknown
    size = nc + nt + overlap_unknown + creep_unknown
    col_overlap = nc + nt if overlap_unknown else None
    col_creep = nc + nt + overlap_unknown if creep_unknown else None
    A = np.zeros((size, size))  # row order: the rows are scaled copies of rows of the blocks
    rhs = np.zeros(size)
    cols_n, traction_rows = slice(0, nc), slice(nc, nc + nt)
    slip_rows = nc + np.flatnonzero(slipping)
    e = system.creep_vector[traction]
    h = np.zeros(nt)
    h[slipping] = slip_gain(problem, ev, slip, sets.sigma)
    factor = np.where(slipping, -h, r_t)  # the row factor of s_t: r_t (adhesion) or -h (slip)
    held_n = state.p_n  # the held p_n (tangential mode)
    if problem.normal:  # contact rows: r_n delta_n = 0
        A[:nc, cols_n] = r_n * _block(system.S_nn, contact, contact)
        if system.S_nt is not None:
            A[:nc, traction_rows] = r_n * _block(system.S_nt, contact, traction)
        rhs[:nc] = -r_n * (system.gap0[contact] - (0.0 if overlap_unknown else state.overlap))
        if col_overlap is not None and problem.load is not None:
            A[:nc, col_overlap] = -1.0
            A[col_overlap, cols_n] = system.load_weights[contact] / lz
            rhs[col_overlap] = -problem.load / lz
            if system.load_t is not None:  # a finite cylinder's shaft load holds p_t
                if coupled:
                    A[col_overlap, traction_rows] = system.load_t[traction] / lz
                else:
                    rhs[col_overlap] -= float(system.load_t @ state.p_t) / lz
    # adhesion rows r_t s_t = 0 and the slip rows p_t - h s_t, s_t = xi e + B_tt p_t + B_tn p_n
    # (einsum: the block is a strided view; a broadcast multiply into A's view took 1.7x as long)
    np.einsum("i,ij->ij", factor, _block(system.B_tt, traction, traction), out=A[traction_rows, traction_rows])
    A[slip_rows, slip_rows] += 1.0  # the slip rows' own p_t
    rhs[slip_rows] = -h[slipping] * ev.slip[slip]
    if system.B_tn is not None:
        if coupled:
            A[traction_rows, cols_n] = factor[:, None] * _block(system.B_tn, traction, contact)
        else:
            rhs[traction_rows] -= factor * _rows(system.B_tn, traction, held_n)
    if coupled:  # the bound's own term: p_t = -sigma mu^k p_n + ...
        mu_k = problem.friction.at(ev.slip[slip])[0]
        A[slip_rows, np.searchsorted(contact, slip)] += sets.sigma[slip] * mu_k
    else:
        rhs[slip_rows] += sets.sigma[slip] * ev.friction_bound[slip]
    creep_column = None
    if creep_unknown:  # the unknown is r_t xi
        A[traction_rows, col_creep] = factor * e / r_t
        A[col_creep, traction_rows] = w[traction] / lz
        target, d_target = problem.force_target(state.p_n, state.p_t)
        d_target_t = problem.target_gradient_t()  # a ratio target moving with a shaft load's p_t
        if d_target_t is not None:
            A[col_creep, traction_rows] -= d_target_t[traction] / lz
            target = problem.force_target(state.p_n, np.zeros_like(state.p_t))[0]
        if coupled and d_target is not None:
            A[col_creep, cols_n] = -d_target[contact] / lz
            rhs[col_creep] = 0.0
        else:
            rhs[col_creep] = target / lz
    else:
        rhs[traction_rows] -= factor * state.creep * e
        creep_column = np.zeros(size)
        creep_column[traction_rows] = -factor * e
    return VelocitySystem(A, rhs, contact, traction, slip_rows, col_overlap, col_creep, creep_column)


def state_from(problem: Problem, state: State, reduced: VelocitySystem, z: np.ndarray) -> State:
    """The state whose unknowns are ``z`` (the others from ``state``)."""
    nc, nt = reduced.contact.size, reduced.traction.size
    new = state.copy()
    if problem.normal:
        new.p_n = np.zeros_like(state.p_n)
        new.p_n[reduced.contact] = z[:nc]
    new.p_t = np.zeros_like(state.p_t)
    new.p_t[reduced.traction] = z[nc : nc + nt]
    if reduced.col_overlap is not None:
        new.overlap = float(z[reduced.col_overlap]) / problem.system.penalty_n
    if reduced.col_creep is not None:
        new.creep = float(z[reduced.col_creep]) / problem.system.penalty_t
    return new


def newton_point(problem: Problem, state: State, ev: Evaluation, record: dict | None = None) -> State:
    """The Newton point of the current node states with mu(s_a) (the LU of an earlier step reused
    where it still serves: :mod:`rolling_cli.solver.reuse`). ``record`` receives the linear
    solve's history columns."""
    reduced = velocity_system(problem, state, ev)
    z = reuse.solve(reduced.matrix, reduced.rhs, problem.system, reduced.key, record)
    return state_from(problem, state, reduced, z)


def creep_sensitivity(problem: Problem, state: State, ev: Evaluation) -> float:
    """dQ/dxi [force/length] at fixed node states (creepage held), d mu/d s_a included."""
    return creep_derivatives(problem, state, ev)[0]


def creep_derivatives(problem: Problem, state: State, ev: Evaluation) -> tuple[float, np.ndarray, np.ndarray]:
    """dQ/dxi [force/length], dp_n/dxi and dp_t/dxi [stress] (zero where p_n is held) at fixed node
    states (creepage held), d mu/d s_a included (see :func:`rolling_cli.solver.reduced.creep_derivatives`).

    ``problem`` may hold the creepage or have it unknown (a prescribed force: the problem a
    force-controlled solve converged on). In the second case its Newton matrix J is the held one,
    A, bordered by the creepage column c (d rows / d(r_t xi)) and the force row, the creepage
    last; with [u; s] = J^-1 e_last, A u + c s = 0, so A^-1 c = -u/s and the held derivative
    A^-1 (d rhs/d xi) = A^-1 (-r_t c) = r_t u / s: one solve with the matrix of the last Newton
    steps (whose factorisation :mod:`rolling_cli.solver.reuse` keeps), not a fresh LU of A."""
    reduced = velocity_system(problem, state, ev)
    nc, nt = reduced.contact.size, reduced.traction.size
    if reduced.col_creep is not None:
        unit = np.zeros(reduced.rhs.size)
        unit[reduced.col_creep] = 1.0
        bordered = reuse.solve(reduced.matrix, unit, problem.system, reduced.key)
        dz = problem.system.penalty_t * bordered[: reduced.col_creep] / bordered[reduced.col_creep]
    elif reduced.creep_column is not None:
        dz = reuse.solve(reduced.matrix, reduced.creep_column, problem.system, reduced.key)
    else:
        raise ValueError("the creep sensitivity needs a tangential problem")
    dp_n = np.zeros_like(state.p_n)
    if problem.normal:
        dp_n[reduced.contact] = dz[:nc]
    dp_t = np.zeros_like(state.p_t)
    dp_t[reduced.traction] = dz[nc : nc + nt]
    return float(problem.system.weights[reduced.traction] @ dz[nc : nc + nt]), dp_n, dp_t
