"""The reduced Newton system of the current node states, A z = rhs, written once.

:func:`layout` fixes the unknowns, the right-hand side and the bookkeeping of
the system (which the dense and the matrix-free paths share); its matrix is
assembled dense from the compliance blocks (:func:`dense_matrix`), or is a
:class:`~rolling_cli.solver.matrix_free.ReducedOperator` on a matrix-free
system. :func:`solve_reduced` solves either; :func:`newton_point` is the
generalised Newton step of :mod:`rolling_cli.solver.formulation`, and
:func:`creep_sensitivity` the derivative dQ/dxi at fixed node states
(:mod:`rolling_cli.solver.sensitivity` all the derivatives of a converged solve).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..influence.toeplitz import apply_sum
from .formulation import Evaluation, Layout, NodeSets, Problem, State, node_sets
from .linalg import Solver, block, factorise, solve_dense

if TYPE_CHECKING:  # the matrix-free path is imported only when a system uses it (start-up time)
    from .matrix_free import ReducedOperator


@dataclass
class ReducedSystem:
    """The linear system of the current node states, A z = rhs, and how z maps back to a state.

    Unknowns z = [p_n on contact | p_t on adhesion | r_n overlap? | r_t creep?], all in
    stress units; rows r_n delta_n = 0 (contact), r_t s_t = 0 (adhesion), the load and
    the tangential force equations divided by the zone length. ``creep_column`` is
    d rhs / d xi when the creepage is held (the sensitivity of the solution to xi).
    ``matrix`` is dense, or a :class:`~rolling_cli.solver.matrix_free.ReducedOperator`
    on a matrix-free system, or None where only ``factor`` solves it; ``factor`` its kept LU when it
    has one (:mod:`rolling_cli.solver.kept`),
    ``force_row_n`` the force row's entries on p_n (coupled force control with a target
    that moves with p_n), part of what fixes the matrix, as is ``force_row_t``, its entries on
    p_t where they are not w (:class:`~rolling_cli.solver.formulation.Layout`).
    """

    matrix: np.ndarray | ReducedOperator | None
    rhs: np.ndarray
    sets: NodeSets
    coef: np.ndarray | None
    p_t_slip: np.ndarray | None
    col_overlap: int | None
    col_creep: int | None
    creep_column: np.ndarray | None = None
    force_row_n: np.ndarray | None = None
    factor: Solver | None = None
    force_row_t: np.ndarray | None = None


def layout(problem: Problem, state: State, sets: NodeSets, ev: Evaluation) -> Layout:
    """The unknowns and the right-hand side [stress] of the reduced system of ``sets``."""
    system = problem.system
    c_idx, st_idx, sl_idx, sigma = sets.contact, sets.stick, sets.slip, sets.sigma
    r_n, r_t = system.penalty_n, system.penalty_t
    lz = system.zone_length
    w = system.weights
    overlap_unknown, creep_unknown = problem.overlap_unknown, problem.creep_unknown
    contact = c_idx if problem.normal else c_idx[:0]
    stick = st_idx if problem.tangential else st_idx[:0]
    nc, ns = contact.size, stick.size
    size = nc + ns + overlap_unknown + creep_unknown
    col_overlap = nc + ns if overlap_unknown else None
    col_creep = nc + ns + overlap_unknown if creep_unknown else None
    # p_t on slip nodes: coupled -> coef * p_n (unknown); tangential -> sigma g (known)
    coef = -problem.mu * sigma[c_idx] if problem.mode == "coupled" else None
    p_t_slip = sigma[sl_idx] * ev.friction_bound[sl_idx] if problem.mode == "tangential" else None
    rhs = np.zeros(size)
    creep_column = force_row_n = e = None
    load_rows: tuple = (None, None)
    force_row_t = None
    if problem.normal:
        fixed = system.gap0[contact] - (0.0 if overlap_unknown else state.overlap)
        if system.S_nt is not None and not problem.tangential:
            fixed = fixed + _rows_times(system, system.S_nt, contact, state.p_t)
        rhs[:nc] = -r_n * fixed
        if col_overlap is not None and problem.load is not None:
            rhs[col_overlap] = -problem.load / lz
            if system.load_n is not None or system.load_t is not None:  # a finite cylinder's shaft load
                load_rows, held = _load_rows(problem, state, contact, stick, coef)
                rhs[col_overlap] = -(problem.load + held) / lz
    if problem.tangential:
        e = system.creep_vector[stick]
        fixed = np.zeros(ns) if creep_unknown else state.creep * e
        if not problem.normal:
            fixed = fixed + _slip_terms(system, stick, sl_idx, p_t_slip, state.p_n)
        rhs[nc : nc + ns] = -r_t * fixed
        if creep_unknown:
            target, d_target = problem.force_target(state.p_n, state.p_t)
            d_target_t = problem.target_gradient_t()  # a ratio target moving with a shaft load's p_t
            if d_target_t is not None:
                force_row_t = w[stick] - d_target_t[stick]
            if problem.normal:
                force_row_n = w[contact] * coef
                if d_target is not None:
                    force_row_n = force_row_n - d_target[contact]
                if d_target_t is not None:
                    force_row_n = force_row_n - d_target_t[contact] * coef
                rhs[col_creep] = target / lz if d_target is None else 0.0
            elif d_target_t is not None:  # Q - Q_target(p_n held, p_t) = 0: the p_t terms on the left
                target = problem.force_target(state.p_n, np.zeros_like(state.p_t))[0]
                rhs[col_creep] = (target - float((w[sl_idx] - d_target_t[sl_idx]) @ p_t_slip)) / lz
            else:
                rhs[col_creep] = (target - float(w[sl_idx] @ p_t_slip)) / lz
        else:
            creep_column = np.zeros(size)
            creep_column[nc : nc + ns] = -r_t * e
    return Layout(
        contact, stick, size, col_overlap, col_creep, coef, p_t_slip, e, force_row_n, rhs, creep_column,
        load_rows[0], load_rows[1], force_row_t,
    )  # fmt: skip


def _load_rows(problem: Problem, state: State, contact: np.ndarray, stick: np.ndarray, coef) -> tuple:
    """((the load row's entries on the p_n unknowns, on the p_t unknowns or None) [length], the held
    p_t's part of the load row [force/length]) for a load P = -(load_n p_n + load_t p_t)
    (:meth:`~rolling_cli.solver.system.ContactSystem.load`): coupled, p_t = coef p_n on the slip
    nodes and unknown on the adhesion ones; p_t held otherwise (its term joins the right-hand side)."""
    system = problem.system
    row_n = system.load_weights[contact]
    load_t = system.load_t
    if load_t is None:
        return (row_n, None), 0.0
    if not problem.tangential:
        return (row_n, None), float(load_t @ state.p_t)
    if coef is not None:
        row_n = row_n + load_t[contact] * coef
    return (row_n, load_t[stick]), 0.0


def _rows_times(system, block, rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(block @ values)[rows]: the rows' products with a dense block, or one operator product."""
    if system.matrix_free:
        return (block @ values)[rows]
    return block[rows] @ values


def _slip_terms(system, stick: np.ndarray, slip: np.ndarray, p_t_slip, p_n: np.ndarray) -> np.ndarray:
    """The adhesion rows' slip from the known slip tractions and the held pressure (tangential mode)."""
    if system.matrix_free:
        p_t = np.zeros(system.size)
        p_t[slip] = p_t_slip
        terms = [(system.B_tt, p_t)]
        if system.B_tn is not None:
            terms.append((system.B_tn, p_n))
        return apply_sum(terms)[stick]
    out = block(system.B_tt, stick, slip) @ p_t_slip
    if system.B_tn is not None:
        out = out + system.B_tn[stick] @ p_n
    return out


def dense_matrix(problem: Problem, lay: Layout) -> np.ndarray:
    """The reduced matrix A [stress/stress] of a layout, from the dense compliance blocks."""
    system = problem.system
    r_n, r_t, lz, w = system.penalty_n, system.penalty_t, system.zone_length, system.weights
    c_idx, st_idx, coef = lay.contact, lay.stick, lay.coef
    nc, ns = lay.nc, lay.ns
    A = np.zeros((lay.size, lay.size), order="F")  # LAPACK layout: no copy before the LU
    rows_n, rows_t = slice(0, nc), slice(nc, nc + ns)
    if problem.normal:
        a_nn = block(system.S_nn, c_idx, c_idx)
        if system.S_nt is not None and coef is not None:
            a_nn = a_nn + block(system.S_nt, c_idx, c_idx) * coef[None, :]
        A[rows_n, :nc] = r_n * a_nn
        if system.S_nt is not None and problem.tangential:
            A[rows_n, nc : nc + ns] = r_n * block(system.S_nt, c_idx, st_idx)
        if lay.col_overlap is not None:  # unknown r_n * overlap, in stress units like the tractions
            A[rows_n, lay.col_overlap] = -1.0
            A[lay.col_overlap, :nc] = (w[c_idx] if lay.load_row_n is None else lay.load_row_n) / lz
            if lay.load_row_t is not None:  # a finite cylinder's shaft load holds p_t
                A[lay.col_overlap, nc : nc + ns] = lay.load_row_t / lz
    if problem.tangential:
        A[rows_t, nc : nc + ns] = r_t * block(system.B_tt, st_idx, st_idx)
        if problem.normal and coef is not None:  # the coupled mode
            a_tn = block(system.B_tt, st_idx, c_idx) * coef[None, :]
            if system.B_tn is not None:
                a_tn = a_tn + block(system.B_tn, st_idx, c_idx)
            A[rows_t, :nc] = r_t * a_tn
        if lay.col_creep is not None:  # unknown r_t * creep, in stress units like the tractions
            A[rows_t, lay.col_creep] = lay.creep_vector
            A[lay.col_creep, nc : nc + ns] = (w[st_idx] if lay.force_row_t is None else lay.force_row_t) / lz
            if lay.force_row_n is not None:
                A[lay.col_creep, :nc] = lay.force_row_n / lz
    return A


def reduced_system(problem: Problem, state: State, sets: NodeSets, ev: Evaluation) -> ReducedSystem:
    """The reduced Newton system of the node sets (see :class:`ReducedSystem`): its matrix dense,
    or on a matrix-free system (:attr:`~rolling_cli.solver.system.ContactSystem.matrix_free`) the
    operator :class:`~rolling_cli.solver.matrix_free.ReducedOperator`, with the same rows."""
    lay = layout(problem, state, sets, ev)
    matrix: np.ndarray | ReducedOperator
    if problem.system.matrix_free:
        from . import matrix_free

        matrix = matrix_free.operator(problem, state, lay, ev)
    else:
        matrix = dense_matrix(problem, lay)
    return ReducedSystem(
        matrix, lay.rhs, sets, lay.coef, lay.p_t_slip, lay.col_overlap, lay.col_creep, lay.creep_column,
        lay.force_row_n, force_row_t=lay.force_row_t,
    )  # fmt: skip


def state_from_solution(problem: Problem, state: State, reduced: ReducedSystem, z: np.ndarray) -> State:
    """The state whose unknowns are the reduced solution ``z`` (the others from ``state``)."""
    sets = reduced.sets
    nc = sets.contact.size if problem.normal else 0
    ns = sets.stick.size if problem.tangential else 0
    new = state.copy()
    if problem.normal:
        new.p_n = np.zeros_like(state.p_n)
        new.p_n[sets.contact] = z[:nc]
    if problem.tangential:
        new.p_t = np.zeros_like(state.p_t)
        new.p_t[sets.stick] = z[nc : nc + ns]
        if reduced.coef is not None:
            new.p_t[sets.slip] = reduced.coef[np.searchsorted(sets.contact, sets.slip)] * new.p_n[sets.slip]
        else:
            new.p_t[sets.slip] = reduced.p_t_slip
    if reduced.col_overlap is not None:
        new.overlap = float(z[reduced.col_overlap]) / problem.system.penalty_n
    if reduced.col_creep is not None:
        new.creep = float(z[reduced.col_creep]) / problem.system.penalty_t
    return new


def unknowns(problem: Problem, state: State, reduced: ReducedSystem) -> np.ndarray:
    """The reduced unknowns z [stress] of ``state`` (the inverse of :func:`state_from_solution` on them)."""
    sets = reduced.sets
    parts = []
    if problem.normal:
        parts.append(state.p_n[sets.contact])
    if problem.tangential:
        parts.append(state.p_t[sets.stick])
    if reduced.col_overlap is not None:
        parts.append([problem.system.penalty_n * state.overlap])
    if reduced.col_creep is not None:
        parts.append([problem.system.penalty_t * state.creep])
    return np.concatenate(parts) if parts else np.zeros(0)


def friction_rows(problem: Problem, reduced: ReducedSystem, state: State) -> np.ndarray:
    """d(A z - rhs)/d mu [stress] at fixed unknowns z = the state's and fixed node states.

    mu enters only through the slip tractions p_t = sigma g = -mu sigma p_n, so this is the
    response of the system's rows to their change dp_t/dmu = -sigma p_n on the slip nodes: the
    contact rows r_n S_nt dp_t (coupled mode), the adhesion rows r_t B_tt dp_t and the force row
    sum w dp_t / L (the load row does not change, but for a finite cylinder's shaft load, which
    holds p_t: sum load_t dp_t / L; and a ratio target's with it)."""
    system, sets = problem.system, reduced.sets
    out = np.zeros(reduced.rhs.size)
    if not problem.tangential or sets.slip.size == 0:
        return out
    dp_t = np.zeros(system.size)
    dp_t[sets.slip] = -sets.sigma[sets.slip] * state.p_n[sets.slip]
    nc = sets.contact.size if problem.normal else 0
    ns = sets.stick.size
    slip = sets.slip
    if system.matrix_free:
        if problem.normal and system.S_nt is not None:
            out[:nc] = system.penalty_n * (system.S_nt @ dp_t)[sets.contact]
        out[nc : nc + ns] = system.penalty_t * (system.B_tt @ dp_t)[sets.stick]
    else:  # dense blocks: only the slip columns (dp_t vanishes elsewhere)
        if problem.normal and system.S_nt is not None:
            out[:nc] = system.penalty_n * (block(system.S_nt, sets.contact, slip) @ dp_t[slip])
        out[nc : nc + ns] = system.penalty_t * (block(system.B_tt, sets.stick, slip) @ dp_t[slip])
    if reduced.col_creep is not None:
        out[reduced.col_creep] = float(system.weights @ dp_t) / system.zone_length
        d_target_t = problem.target_gradient_t()
        if d_target_t is not None:
            out[reduced.col_creep] -= float(d_target_t @ dp_t) / system.zone_length
    if reduced.col_overlap is not None and system.load_t is not None:
        out[reduced.col_overlap] = float(system.load_t @ dp_t) / system.zone_length
    return out


def solve_reduced(
    reduced: ReducedSystem, rhs: np.ndarray, residual: float | None = None, record: dict | None = None
) -> np.ndarray:
    """The solution z of ``reduced.matrix`` z = ``rhs``.

    A dense matrix: LU (:func:`~rolling_cli.solver.linalg.solve_dense`). A matrix-free
    system: the preconditioned Krylov solve (:meth:`~rolling_cli.solver.matrix_free.ReducedOperator.solve`)
    to the accuracy a dense LU reaches or, for a Newton step from an iterate of relative
    residual ``residual``, to the forcing target of an inexact Newton method
    (:func:`~rolling_cli.solver.matrix_free.forcing_target`), starting from that iterate.
    ``record`` (optional dict) receives a Krylov solve's counts (history columns).
    """
    if reduced.factor is not None:
        return reduced.factor.solve(rhs)
    if isinstance(reduced.matrix, np.ndarray):
        return solve_dense(reduced.matrix, rhs)
    if reduced.matrix is None:
        raise ValueError("a reduced system without its matrix solves only through its factor")
    if residual is None:
        return reduced.matrix.solve(rhs, record=record)
    from .matrix_free import forcing_target

    return reduced.matrix.solve(rhs, reduced.matrix.guess, forcing_target(residual), record=record)


def newton_point(problem: Problem, state: State, ev: Evaluation, record: dict | None = None) -> State:
    """The Newton point: the solution of the linear system of the current node states (exact, or
    on a matrix-free system to the forcing target of :func:`solve_reduced`). ``record`` receives
    the linear solve's counts (Krylov only), for the step's history row. With a velocity-dependent
    friction law: :func:`rolling_cli.solver.velocity.newton_point`. A dense matrix's LU is kept
    (the last one only) for :func:`rolling_cli.solver.kept.kept_system`: the same numbers as an LU made and dropped."""
    global _KEPT
    if problem.friction is not None and problem.tangential:
        from . import velocity

        return velocity.newton_point(problem, state, ev, record)
    _KEPT = None  # the previous step's matrix and LU go before this one is built (peak memory)
    reduced = reduced_system(problem, state, node_sets(problem, state, ev), ev)
    if isinstance(reduced.matrix, np.ndarray):
        reduced.factor = factorise(reduced.matrix)
        if reduced.factor is not None:
            _KEPT = (weakref.ref(problem.system), problem.mode, reduced)
    dz = solve_reduced(reduced, reduced.rhs, ev.relative_residual, record)
    return state_from_solution(problem, state, reduced, dz)


#: The last dense Newton matrix with its LU: (weak reference to its system, the mode, the system);
#: taken by :func:`rolling_cli.solver.kept.kept_system`.
_KEPT: tuple | None = None


def take_kept() -> tuple | None:
    """The kept (system reference, mode, :class:`ReducedSystem` with its ``factor``), released."""
    global _KEPT
    kept, _KEPT = _KEPT, None
    return kept


def release() -> None:
    """Drop the kept matrix and LU without using them."""
    global _KEPT
    _KEPT = None


def creep_sensitivity(problem: Problem, state: State, ev: Evaluation) -> float:
    """dQ/dxi [force/length] at fixed node states, from the reduced Jacobian (creepage held).

    The reduced system is linear in xi with d rhs / d xi = ``creep_column``; the
    derivative of the solution gives dp_t/dxi on the adhesion nodes, and on slip
    nodes through p_n (coupled mode). Returns sum w dp_t/dxi.
    """
    return creep_derivatives(problem, state, ev)[0]


def creep_derivatives(problem: Problem, state: State, ev: Evaluation) -> tuple[float, np.ndarray, np.ndarray]:
    """dQ/dxi [force/length], dp_n/dxi and dp_t/dxi [stress] (zero where p_n is held) at fixed node
    states (see :func:`creep_sensitivity`): under overlap control the load, and with it a target Q
    given as Q/P or Q/(mu P), moves with the creepage through the coupling (and, a finite
    cylinder's shaft load, through p_t)."""
    if problem.friction is not None and problem.tangential:  # the creepage held or, there, unknown
        from . import velocity

        return velocity.creep_derivatives(problem, state, ev)
    if problem.creep_unknown or not problem.tangential:
        raise ValueError("the creep sensitivity needs a tangential problem with the creepage held")
    sets = node_sets(problem, state, ev)
    reduced = reduced_system(problem, state, sets, ev)
    if reduced.creep_column is None:
        raise ValueError("the creep sensitivity needs the creepage held")
    dz = solve_reduced(reduced, reduced.creep_column)
    nc = sets.contact.size if problem.normal else 0
    ns = sets.stick.size
    w = problem.system.weights
    d_q = float(w[sets.stick] @ dz[nc : nc + ns])
    dp_n = np.zeros_like(state.p_n)
    if problem.normal:
        dp_n[sets.contact] = dz[:nc]
    dp_t = np.zeros_like(state.p_t)
    dp_t[sets.stick] = dz[nc : nc + ns]
    if reduced.coef is not None:
        dp_t[sets.slip] = reduced.coef[np.searchsorted(sets.contact, sets.slip)] * dp_n[sets.slip]
        d_q += float(w[sets.slip] @ dp_t[sets.slip])
    return d_q, dp_n, dp_t
