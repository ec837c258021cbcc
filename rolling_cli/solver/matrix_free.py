"""The reduced Newton system without its matrix (large uniform half-plane grids).

The system is :func:`rolling_cli.solver.reduced.reduced_system`'s, row for
row: contact rows r_n delta_n = 0, adhesion rows r_t s_t = 0, the load and
force rows, unknowns z = [p_n on contact | p_t on adhesion | r_n overlap? |
r_t creep?]. Its dense matrix would hold (2 n_c)^2 entries; here it is an
operator (:class:`ReducedOperator`): z is scattered into full-length
tractions, the influence operators are applied by FFT
(:func:`rolling_cli.influence.toeplitz.apply_sum`, O(n log n)) and the rows
gathered.

It is solved by flexible GMRES (:mod:`rolling_cli.solver.krylov`) with the LU
of the near field as preconditioner (:mod:`rolling_cli.solver.near_field`):

* rows are scaled by their traction scale (s_n normal and load rows, s_t
  tangential and force rows), so the residual is the Newton's own measure;
* the contact rows carry the log kernel, which does not decay: a banded
  approximation misses all its smooth part. Differencing neighbouring contact
  rows (E, a bidiagonal matrix; the last row of each run of contact nodes kept
  whole: it carries the overlap) turns them into the Cauchy kernel of the
  slip rows (the slip operator T does the same to the tangential block, paper
  eq. 19-25), whose far field is smaller and smooth;
* the preconditioner is the LU of E A restricted to node pairs at most
  :data:`NEAR_FIELD` nodes apart (a band in node order, LAPACK's band LU in
  single precision), bordered by the dense load and force rows and creep
  column (SuperLU of the whole if the band is singular); it is applied as
  M^-1 E.

The far field the band leaves out grows (slowly) with the grid, and so do the
Krylov iterations per Newton step: ~60 at 10,000 nodes, a few hundred at
30,000, and at 100,000 nodes a coupled system no longer converges in
GMRES(100) with the band alone. The preconditioner (:data:`TWO_LEVEL`)
therefore adds a coarse-grid correction after the band
(:mod:`rolling_cli.solver.coarse`: aggregates of ~24 unknowns, the exact
Galerkin coarse matrix from corner sums of the influence operators, a dense LU
per Newton step): the coupled dissimilar case takes ~6 iterations per step at
10,000 nodes and ~17 at 100,000; Carter's decoupled stages 10 and 12 (44 and
134 with the band alone), 0.34 -> 0.15 s and 7.1 -> 2.5 s (benchmarks/RESULTS.md).

GMRES stops when the largest scaled residual component is at most the
round-off floor of the system (:func:`~rolling_cli.solver.formulation.roundoff_floor`,
the accuracy a dense LU reaches) or :data:`KRYLOV_TOLERANCE`, whichever is
larger. It starts from the current iterate, so late Newton steps need few
iterations.
"""

from __future__ import annotations

import contextlib
import contextvars
import logging
from dataclasses import dataclass

import numpy as np

from ..influence.toeplitz import gather, products
from . import coarse, krylov, near_field
from .formulation import Evaluation, Layout, Problem, State, roundoff_floor

log = logging.getLogger(__name__)

#: Node distance of the near field kept in the preconditioner: Krylov iterations fall slowly
#: with it, the sparse LU grows linearly (benchmarks/bench_solve.py).
NEAR_FIELD = 16
#: The Krylov solve stops at max |residual| / traction scale <= max(this, round-off floor).
KRYLOV_TOLERANCE = 1e-13
#: Inexact Newton (matrix-free systems only): a Newton step from an iterate of relative residual
#: r >= FORCING_FROM is solved to FORCING r (two to three digits), a step from a closer iterate to the
#: round-off floor. The steps far from the solution mostly move the node states, where a few digits do
#: as well as thirteen; the last steps are exact, so the converged result is the dense path's to
#: round-off, and a case whose first node states are right still converges in one step. (1e-2 took
#: two more Newton steps on the dissimilar case at 10,000 nodes, 1e-3 and 1e-4 more GMRES
#: iterations: 792, 622 and 644 against 590.)
FORCING = 3e-3
FORCING_FROM = 1e-2
#: A solve that stagnates is accepted up to this multiple of its target (round-off); else, up to
#: DENSE_FALLBACK unknowns (a dense matrix of 128 MB), it is solved by a dense LU instead
#: (:meth:`ReducedOperator.solve_dense`), and above it fails (numpy.linalg.LinAlgError).
STAGNATION_ALLOWANCE = 10.0
DENSE_FALLBACK = 4000
#: The coarse-grid correction of :mod:`rolling_cli.solver.coarse` after the near-field band (False:
#: the band alone, ``benchmarks/bench_solve.py --preconditioner band``).
TWO_LEVEL = True


@dataclass
class ReducedOperator:
    """The reduced Newton matrix A of one set of node states, applied matrix-free (``A @ z``).

    ``contact``, ``stick``: node indices of the normal and tangential unknowns
    (empty when that traction is held); ``coef``: p_t = coef p_n on the contact
    nodes (slip nodes of the coupled mode, 0 elsewhere) or None; ``force_row_n``:
    the force row's entries on the p_n unknowns (coupled force control);
    ``row_scale``: 1 / traction scale per row; ``target``: the scaled residual
    the solve must reach; ``guess``: the unknowns of the current iterate.
    """

    problem: Problem
    contact: np.ndarray
    stick: np.ndarray
    coef: np.ndarray | None
    col_overlap: int | None
    col_creep: int | None
    force_row_n: np.ndarray | None
    row_scale: np.ndarray
    target: float
    guess: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        """(size, size) of the reduced system."""
        return (self.row_scale.size, self.row_scale.size)

    @property
    def _sizes(self) -> tuple[int, int]:
        return self.contact.size, self.stick.size

    def tractions(self, z: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Full-length p_n and p_t of the unknowns ``z`` (None where that traction is held)."""
        n = self.problem.system.size
        nc, ns = self._sizes
        p_n = p_t = None
        if self.problem.normal:
            p_n = np.zeros(n)
            p_n[self.contact] = z[:nc]
        if self.problem.tangential:
            p_t = np.zeros(n)
            p_t[self.stick] = z[nc : nc + ns]
            if self.coef is not None:
                p_t[self.contact] += self.coef * z[:nc]
        return p_n, p_t

    def __matmul__(self, z: np.ndarray) -> np.ndarray:
        """A z [stress]: scatter, block-Toeplitz products (one transform per traction), gather."""
        system = self.problem.system
        nc, ns = self._sizes
        r_n, r_t, lz, w = system.penalty_n, system.penalty_t, system.zone_length, system.weights
        p_n, p_t = self.tractions(z)
        sums = []
        if self.problem.normal:
            sums.append([(system.S_nn, p_n)] + ([(system.S_nt, p_t)] if p_t is not None and system.coupled else []))
        if self.problem.tangential:
            sums.append([(system.B_tt, p_t)] + ([(system.B_tn, p_n)] if p_n is not None and system.coupled else []))
        found = products(sums)
        out = np.zeros(self.shape[0])
        if self.problem.normal:
            out[:nc] = r_n * found[0][self.contact]
            if self.col_overlap is not None:
                out[:nc] -= z[self.col_overlap]
                out[self.col_overlap] = w[self.contact] @ z[:nc] / lz
        if self.problem.tangential:
            out[nc : nc + ns] = r_t * found[-1][self.stick]
            if self.col_creep is not None:
                out[nc : nc + ns] += system.creep_vector[self.stick] * z[self.col_creep]
                row = w[self.stick] @ z[nc : nc + ns]
                if self.force_row_n is not None:
                    row += self.force_row_n @ z[:nc]
                out[self.col_creep] = row / lz
        return out

    # --- the preconditioner --------------------------------------------------------------------

    def _differenced(self) -> np.ndarray:
        """Contact rows k replaced by row k - row k+1 (E): those whose next contact node is adjacent."""
        c = self.contact
        out = np.zeros(c.size, dtype=bool)
        out[:-1] = np.diff(c) == 1
        return out

    def difference(self, v: np.ndarray) -> np.ndarray:
        """E v: the differenced contact rows of a row vector ``v``."""
        out = v.copy()
        rows = np.flatnonzero(self._differenced())
        out[rows] -= v[rows + 1]
        return out

    def entries(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """(E A)[i, j] with the rows scaled, for arrays of unknowns ``i``, ``j`` of the tractions
        (not the overlap or creepage): exact entries of the influence operators, gathered."""
        system = self.problem.system
        nc = self.contact.size
        c, st, coef = self.contact, self.stick, self.coef
        row_n, col_n = i < nc, j < nc
        node_j = np.where(col_n, c[np.minimum(j, max(nc - 1, 0))] if nc else 0, 0)
        if st.size:
            node_j = np.where(col_n, node_j, st[np.clip(j - nc, 0, st.size - 1)])
        out = np.zeros(np.shape(i))
        if self.problem.normal:
            diff = self._differenced()
            normal_ops = [system.S_nn, system.S_nt] if system.coupled else [system.S_nn]
            col_coef = (
                np.where(col_n, coef[np.minimum(j, nc - 1)], 0.0) if coef is not None and system.coupled else None
            )

            def normal(rows_at, pick):
                """Contact rows at nodes ``rows_at`` (before r_n), for the entries ``pick``."""
                found = gather(normal_ops, rows_at, node_j[pick])
                cols_n = col_n[pick]
                value = np.where(cols_n, found[0], found[1] if system.coupled else 0.0)  # p_t columns: S_nt
                if col_coef is not None:
                    value += np.where(cols_n, found[1] * col_coef[pick], 0.0)
                return value

            rows = np.flatnonzero(row_n)
            value = normal(c[i[rows]], rows)
            shifted = diff[i[rows]]
            if shifted.any():
                pick = rows[shifted]
                value[shifted] -= normal(c[i[pick] + 1], pick)
            out[rows] = system.penalty_n * value
        if self.problem.tangential:
            rows = np.flatnonzero(~row_n)
            at = st[i[rows] - nc]
            cols_n, nodes = col_n[rows], node_j[rows]
            if cols_n.any():
                ops = [system.B_tt, system.B_tn] if system.coupled else [system.B_tt]
                found = gather(ops, at, nodes)
                value = found[0]
                if coef is not None:  # p_n columns of adhesion rows: the coupled mode's slip nodes
                    value *= np.where(cols_n, coef[np.minimum(j[rows], nc - 1)], 1.0)
                if system.coupled:
                    value += np.where(cols_n, found[1], 0.0)
            else:
                value = system.B_tt.entries(at, nodes)
            out[rows] = system.penalty_t * value
        return out * self.row_scale[i]

    def borders(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The border unknowns (overlap, creepage) and, rows scaled and E applied, their columns
        U (tractions x borders), rows V (borders x tractions) and crossing D."""
        system = self.problem.system
        nc, ns = self._sizes
        lz, w = system.zone_length, system.weights
        border = np.array([k for k in (self.col_overlap, self.col_creep) if k is not None], dtype=np.intp)
        columns = np.zeros((nc + ns, border.size))
        rows = np.zeros((border.size, nc + ns))
        for b, k in enumerate(border):
            if k == self.col_overlap:  # -1 on the contact rows; E leaves it on the last of each run
                columns[np.flatnonzero(~self._differenced()), b] = -1.0
                rows[b, :nc] = w[self.contact] / lz
            else:  # e on the adhesion rows; the force row
                columns[nc:, b] = system.creep_vector[self.stick]
                rows[b, nc:] = w[self.stick] / lz
                if self.force_row_n is not None:
                    rows[b, :nc] = self.force_row_n / lz
            rows[b] *= self.row_scale[k]
        columns *= self.row_scale[: nc + ns, None]
        return border, columns, rows, np.zeros((border.size, border.size))

    def preconditioner(self, apply):
        """The right preconditioner of GMRES for the scaled product ``apply``: the near-field band
        (:mod:`~rolling_cli.solver.near_field`) and, when :data:`TWO_LEVEL`, the coarse-grid
        correction after it (:func:`rolling_cli.solver.coarse.two_level`; the band
        alone if the coarse system is singular)."""
        band = near_field.preconditioner(self, NEAR_FIELD)
        if not TWO_LEVEL:
            return band
        try:
            return coarse.two_level(apply, band, coarse.CoarseCorrection(self, apply))
        except np.linalg.LinAlgError:
            log.debug("singular coarse system: the near-field preconditioner alone")
            return band

    # --- the solve ------------------------------------------------------------------------------

    def solve(
        self,
        rhs: np.ndarray,
        start: np.ndarray | None = None,
        target: float | None = None,
        record: dict | None = None,
    ) -> np.ndarray:
        """z with A z = rhs to ``target`` (default :attr:`target`; module docstring); raises
        LinAlgError when GMRES fails. ``record`` (a dict, optional) receives this solve's
        counts, ``krylov_iterations`` and ``krylov_dense_fallbacks`` (1 when the stalled
        GMRES was redone by dense LU): the Newton step's history columns."""
        if self.shape[0] == 0:
            return np.zeros(0)
        target = self.target if target is None else max(self.target, target)
        scale = self.row_scale
        record = {} if record is None else record

        def apply(z):
            return scale * (self @ z)

        result = krylov.gmres(apply, scale * rhs, self.preconditioner(apply), target, start=start)
        record.update(krylov_iterations=result.iterations, krylov_dense_fallbacks=0)
        if not result.residual <= STAGNATION_ALLOWANCE * target:
            if self.shape[0] <= DENSE_FALLBACK:
                log.debug("Krylov stalled at %.2e: dense LU of the %d unknowns", result.residual, self.shape[0])
                record["krylov_dense_fallbacks"] = 1
                return self.solve_dense(rhs)
            raise np.linalg.LinAlgError(
                f"the Krylov solve of the Newton system stalled at a relative residual {result.residual:.2e} "
                f"(target {target:.1e}) after {result.iterations} iterations"
            )
        log.debug("Krylov: %d iterations, residual %.2e", result.iterations, result.residual)
        return result.x

    def solve_dense(self, rhs: np.ndarray) -> np.ndarray:
        """z with A z = rhs by a dense LU of E D A z = E D rhs (D the row scales, E the row
        differences: both regular), assembled from exact entries row block by row block
        (O(size^2) memory: the fallback of :meth:`solve` up to :data:`DENSE_FALLBACK` unknowns)."""
        from .linalg import solve_dense

        border, columns, rows, corner = self.borders()
        core = self.shape[0] - border.size
        matrix = np.empty(self.shape, order="F")
        step = max(1, near_field.CHUNK // max(core, 1))
        cols = np.arange(core)
        for lo in range(0, core, step):
            block = np.arange(lo, min(lo + step, core))
            i, j = np.broadcast_arrays(block[:, None], cols[None, :])
            matrix[lo : lo + block.size, :core] = self.entries(i.ravel(), j.ravel()).reshape(block.size, core)
        matrix[:core, core:] = columns
        matrix[core:, :core] = rows
        matrix[core:, core:] = corner
        return solve_dense(matrix, self.difference(self.row_scale * rhs))


#: Inside :func:`exact_steps`: every Newton step is solved to the round-off floor.
_EXACT: contextvars.ContextVar[bool] = contextvars.ContextVar("exact_steps", default=False)


@contextlib.contextmanager
def exact_steps():
    """Solve every Newton step to the round-off floor within this block (the strongly coupled corner:
    issue 23's case at xi = 0.006 on 1251 nodes failed with the inexact far steps, from the same start
    converged in 110 iterations with exact ones, as the dense LU does: benchmarks/RESULTS.md)."""
    token = _EXACT.set(True)
    try:
        yield
    finally:
        _EXACT.reset(token)


def forcing_target(residual: float) -> float:
    """The Krylov target of a Newton step from an iterate of relative residual ``residual`` [-]
    (see :data:`FORCING`); 0 asks for the round-off floor, which the solve never goes below."""
    return FORCING * residual if residual >= FORCING_FROM and not _EXACT.get() else 0.0


def operator(problem: Problem, state: State, lay: Layout, ev: Evaluation) -> ReducedOperator:
    """The reduced matrix of a layout (:func:`~rolling_cli.solver.reduced.layout`) as a
    :class:`ReducedOperator`: rows scaled by the traction scales, the iterate's unknowns as the
    Krylov guess, the solve's target no lower than the round-off floor."""
    system = problem.system
    if lay.load_row_n is not None or lay.load_row_t is not None or lay.force_row_t is not None:
        raise ValueError("a load other than the arc sum (a finite cylinder's) is not matrix-free")
    nc, ns = lay.nc, lay.ns
    s_n, s_t = ev.scales.normal, ev.scales.tangential
    row_scale = np.empty(lay.size)
    guess = np.zeros(lay.size)
    if problem.normal:
        row_scale[:nc] = 1.0 / s_n
        guess[:nc] = state.p_n[lay.contact]
        if lay.col_overlap is not None:
            row_scale[lay.col_overlap] = 1.0 / s_n
            guess[lay.col_overlap] = system.penalty_n * state.overlap
    if problem.tangential:
        row_scale[nc : nc + ns] = 1.0 / s_t
        guess[nc : nc + ns] = state.p_t[lay.stick]
        if lay.col_creep is not None:
            row_scale[lay.col_creep] = 1.0 / s_t
            guess[lay.col_creep] = system.penalty_t * state.creep
    floor = roundoff_floor(problem, ev.scales)
    return ReducedOperator(
        problem,
        lay.contact,
        lay.stick,
        lay.coef,
        lay.col_overlap,
        lay.col_creep,
        lay.force_row_n,
        row_scale,
        max(KRYLOV_TOLERANCE, floor),
        guess,
    )


def result_attributes(system, history: list[dict]) -> dict:
    """Result attributes of the linear solver: ``linear_solver`` ("dense LU" or "Krylov") and, for
    Krylov, ``krylov_solves`` (Newton steps solved by GMRES), ``krylov_iterations`` (their GMRES
    iterations) and ``krylov_dense_fallbacks`` (stalled solves redone by dense LU), summed over
    the Newton history of this solve (the columns :meth:`ReducedOperator.solve` records)."""
    attrs: dict = {"linear_solver": system.linear_solver}
    if system.matrix_free:
        steps = [row for row in history if "krylov_iterations" in row]
        attrs.update(
            krylov_solves=len(steps),
            krylov_iterations=int(sum(row["krylov_iterations"] for row in steps)),
            krylov_dense_fallbacks=int(sum(row.get("krylov_dense_fallbacks", 0) for row in steps)),
        )
    return attrs
