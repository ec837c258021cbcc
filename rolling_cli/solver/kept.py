"""The converged solve's reduced system from the Newton's last LU (issue 24: sensitivities at <= 10 %).

:func:`rolling_cli.solver.reduced.newton_point` keeps the last dense Newton
matrix with its LU (:class:`~rolling_cli.solver.linalg.Factor`: the same
numbers as the LU it would have made and dropped). The sensitivities need the
reduced system of the converged node states (:mod:`rolling_cli.solver.sensitivity`),
which is usually that matrix:

* **the same matrix**: same contact system, mode, node sets, slip coefficients
  (mu sigma), force row and unknowns (what fixes A): its LU serves as it is (no
  assembly, no factorisation);
* **bordered**: an overlap-controlled solve (overlap held) is differentiated
  as the load-controlled problem at its own load, whose matrix is the Newton's
  bordered by the overlap column (-1 on the contact rows) and the load row
  (w/L on the contact columns; a finite cylinder's shaft load: its own weights,
  on the adhesion columns too), its force row (a target Q/P or Q/(mu P) that
  moved with p_n) changed by a row of rank one. With the old matrix A, the
  border B = [e_force, u], C = [d; g] (d the force row's change, u the overlap
  column, g the load row) and E = [[-1, 0], [0, 0]], the new system is solved
  by block elimination through A's LU: X = A^-1 B, S = E - C X (2 x 2),
  t = S^-1 (f_extra - C A^-1 f), x = A^-1 f - X t: two more triangular solves.

Anything else is assembled and factorised afresh
(:func:`~rolling_cli.solver.reduced.reduced_system`). The store holds one LU
for the process: solves in threads (a Dask worker's) may take each other's,
which the checks above refuse (the contact system is compared by identity),
so a sensitivity then assembles its own; never a wrong one.
"""

from __future__ import annotations

import numpy as np

from . import reduced
from .formulation import Evaluation, Layout, NodeSets, Problem, State
from .linalg import Solver
from .reduced import ReducedSystem


def kept_system(problem: Problem, state: State, sets: NodeSets, ev: Evaluation) -> ReducedSystem:
    """The reduced system of ``sets`` (:func:`~rolling_cli.solver.reduced.reduced_system`) with
    ``factor`` from the last Newton step's LU where the module docstring's cases apply (then
    ``matrix`` is the kept A, or None for a bordered one: only ``factor`` solves it), else
    assembled (``factor`` None). The kept LU is released: taken once, it does not outlive its use."""
    kept = reduced.take_kept()
    lay = reduced.layout(problem, state, sets, ev)
    if kept is None or kept[0]() is not problem.system or kept[1] != problem.mode:
        return reduced.reduced_system(problem, state, sets, ev)
    old: ReducedSystem = kept[2]
    common = (
        _equal(old.sets.contact, sets.contact) and _equal(old.sets.stick, sets.stick)
        and _equal(old.coef, lay.coef) and (old.col_creep is None) == (lay.col_creep is None)
        and (old.force_row_n is None) == (lay.force_row_n is None) and old.factor is not None
    )  # fmt: skip
    if not common:
        return reduced.reduced_system(problem, state, sets, ev)
    same_t = _equal(old.force_row_t, lay.force_row_t)
    if old.col_overlap == lay.col_overlap and _equal(old.force_row_n, lay.force_row_n) and same_t:
        return _system(lay, sets, old.matrix, old.factor)
    if old.col_overlap is None and lay.col_overlap is not None and problem.normal:
        assert old.factor is not None
        return _system(lay, sets, None, Bordered(problem, old, lay, old.factor))
    return reduced.reduced_system(problem, state, sets, ev)


def _system(lay: Layout, sets: NodeSets, matrix, factor: Solver | None) -> ReducedSystem:
    return ReducedSystem(
        matrix, lay.rhs, sets, lay.coef, lay.p_t_slip, lay.col_overlap, lay.col_creep, lay.creep_column,
        lay.force_row_n, factor, lay.force_row_t,
    )  # fmt: skip


class Bordered:
    """Solves of the load-controlled matrix from the overlap-controlled one's LU (module docstring).
    ``old`` the kept system (overlap held), ``lay`` the new layout (overlap unknown at column
    nc + ns, before the creepage's)."""

    def __init__(self, problem: Problem, old: ReducedSystem, lay: Layout, factor: Solver) -> None:
        system = problem.system
        nc, m = lay.nc, old.rhs.size
        self.factor, self.overlap = factor, lay.nc + lay.ns
        self.old_rows = np.r_[np.arange(self.overlap), np.arange(self.overlap + 1, m + 1)]  # old unknowns
        u = np.zeros(m)
        u[:nc] = -1.0  # the overlap column on the contact rows
        g = np.zeros(m)
        g[:nc] = (system.weights[lay.contact] if lay.load_row_n is None else lay.load_row_n) / system.zone_length
        if lay.load_row_t is not None:  # the load row (a finite cylinder's shaft load holds p_t)
            g[nc : lay.nc + lay.ns] = lay.load_row_t / system.zone_length
        border, rows, corner = [u], [g], [0.0]
        if old.col_creep is not None and old.force_row_n is not None and lay.force_row_n is not None:
            d = np.zeros(m)
            d[:nc] = (lay.force_row_n - old.force_row_n) / system.zone_length
            if lay.force_row_t is not None or old.force_row_t is not None:  # a ratio target's p_t part
                w_stick = system.weights[lay.stick]
                new_t = w_stick if lay.force_row_t is None else lay.force_row_t
                old_t = w_stick if old.force_row_t is None else old.force_row_t
                d[nc : lay.nc + lay.ns] = (new_t - old_t) / system.zone_length
            e = np.zeros(m)
            e[old.col_creep] = 1.0
            border, rows, corner = [e, u], [d, g], [-1.0, 0.0]  # y = d.x a new unknown: d.x - y = 0
        self.rows = np.array(rows)
        self.columns = factor.solve(np.column_stack(border)).reshape(m, -1)  # A^-1 B
        self.schur = np.diag(corner) - self.rows @ self.columns
        self.extra = len(corner)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """z with M z = rhs [rhs's units / M's] (a vector or columns, new layout's order)."""
        f = rhs.reshape(rhs.shape[0], -1)
        x0 = self.factor.solve(f[self.old_rows]).reshape(self.old_rows.size, -1)
        right = np.zeros((self.extra, f.shape[1]))
        right[-1] = f[self.overlap]  # the load row's right-hand side (the force row's y-row is 0)
        t = np.linalg.solve(self.schur, right - self.rows @ x0)
        out = np.empty_like(f)
        out[self.old_rows] = x0 - self.columns @ t
        out[self.overlap] = t[-1]
        return out.reshape(rhs.shape)


def _equal(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    """Both None, or equal arrays (bit for bit)."""
    if a is None or b is None:
        return a is None and b is None
    return a.shape == b.shape and bool(np.array_equal(a, b))
