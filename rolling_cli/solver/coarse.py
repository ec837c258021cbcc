"""The coarse-grid correction of the matrix-free Newton system's preconditioner (two levels).

The near-field band (:mod:`rolling_cli.solver.near_field`) captures node pairs
a few nodes apart; the half-plane kernel is logarithmic (long range), and the
smooth part of the error that the band leaves grows with the grid, so do the
GMRES iterations. The coarse correction removes that part: the traction
unknowns of a :class:`~rolling_cli.solver.matrix_free.ReducedOperator` A
(rows scaled) are grouped into aggregates of consecutive nodes (one traction,
one slip coefficient: runs of the contact and adhesion sets cut at multiples
of :func:`aggregate_nodes`), P the piecewise-constant prolongation (the
overlap and creepage unknowns are coarse unknowns of their own), and the
Galerkin coarse matrix A_c = P^T A P is built exactly, without products by A:
its entry between two aggregates is the sum of an influence operator over a
rectangle of nodes, four corner sums of
:meth:`~rolling_cli.influence.toeplitz.BlockToeplitz.corner_sums` (O(N_c^2)
per operator); the border columns are A applied to unit vectors. A_c is
factorised by a dense LU once per Newton step.

:func:`two_level` combines the two multiplicatively, the band first:

    y = M^-1 E v,   y <- y + P A_c^-1 P^T (v - A y)

(one more product by A per iteration). With one coarse unknown per ~24 fine
ones (at most :data:`COARSE_LIMIT`) a Newton step of the coupled dissimilar
case takes ~6 GMRES iterations at 10,000 nodes (the band alone ~60) and ~17 at
100,000, where the band alone stalls (benchmarks/RESULTS.md). The coarse
matrix is exact (tested against P^T A P from products); the preconditioner
only changes the iterations, not what GMRES converges to.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

#: Fine traction unknowns per coarse unknown (the aggregate length in nodes), and the largest
#: coarse system (a dense LU of COARSE_LIMIT^2 entries per Newton step: 32 MB, ~0.3 s).
AGGREGATE = 24
COARSE_LIMIT = 2000


def aggregate_nodes(unknowns: int, block: int) -> int:
    """Nodes per aggregate for ``unknowns`` traction unknowns on elements of ``block`` nodes: a
    multiple of ``block`` (aggregates start at element boundaries: cheaper corner sums) near
    :data:`AGGREGATE`, larger when the coarse system would exceed :data:`COARSE_LIMIT`."""
    per = max(AGGREGATE, -(-unknowns // COARSE_LIMIT))
    return block * max(1, -(-per // block))


class CoarseCorrection:
    """P A_c^-1 P^T for the :class:`~rolling_cli.solver.matrix_free.ReducedOperator` ``operator``
    (see the module docstring); ``apply`` is its scaled product z -> row_scale (A z).

    Raises numpy.linalg.LinAlgError when A_c is singular.
    """

    def __init__(self, operator, apply: Callable[[np.ndarray], np.ndarray]) -> None:
        import scipy.linalg

        from .. import blas

        blas.settle()  # scipy's BLAS, perhaps loaded just now, on the command's threads

        self.starts, self.traction, self.border, matrix = galerkin(operator, apply)
        self.size = matrix.shape[0]
        self.lu, self.pivots = scipy.linalg.lu_factor(matrix, overwrite_a=True, check_finite=False)
        diagonal = np.abs(np.diag(self.lu))
        if not diagonal.size or not diagonal.min() > 1e-13 * diagonal.max():  # (and NaN)
            raise np.linalg.LinAlgError("singular coarse system")

    def restrict(self, r: np.ndarray) -> np.ndarray:
        """P^T r (:func:`restrict`)."""
        return restrict(r, self.starts, self.traction, self.border)

    def prolong(self, c: np.ndarray) -> np.ndarray:
        """P c (:func:`prolong`)."""
        return prolong(c, self.starts, self.traction)

    def __call__(self, r: np.ndarray) -> np.ndarray:
        """P A_c^-1 P^T r."""
        import scipy.linalg

        return self.prolong(scipy.linalg.lu_solve((self.lu, self.pivots), self.restrict(r), check_finite=False))


def galerkin(operator, apply: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, int, np.ndarray, np.ndarray]:
    """The aggregates and A_c = P^T A P of the module docstring: (first unknown of each
    aggregate, the number of traction unknowns, the border unknowns, A_c) with the coarse unknowns
    ordered as the aggregates (contact, then adhesion), then the borders; ``apply`` is z ->
    row_scale (A z). Units: the unknowns are stresses (tractions, r_n overlap, r_t creepage)
    and the scaled rows dimensionless, so A_c is in 1/stress and P A_c^-1 P^T maps a scaled
    residual to a correction in stress."""
    system = operator.problem.system
    first = system.S_nn if system.S_nn is not None else system.B_tt
    nc, ns = operator.contact.size, operator.stick.size
    length = aggregate_nodes(nc + ns, first.block_size)
    labels = None  # contact runs are cut where the slip coefficient or the adhesion set changes
    if operator.coef is not None or ns:
        coef = np.zeros(nc) if operator.coef is None else operator.coef
        labels = np.stack([coef, np.isin(operator.contact, operator.stick)])
    normal = _aggregates(operator.contact, labels, length, 0)
    tangential = _aggregates(operator.stick, None, length, nc)
    starts = np.concatenate([normal[0], tangential[0]])
    border = np.array([k for k in (operator.col_overlap, operator.col_creep) if k is not None], dtype=np.intp)
    core = starts.size
    matrix = np.zeros((core + border.size,) * 2, order="F")  # (LAPACK's order: factorised in place)
    _traction_block(operator, normal, tangential, matrix)
    if border.size:  # border columns: A e_b restricted; border rows: V summed per aggregate
        _, _, rows, _ = operator.borders()
        for b, k in enumerate(border):
            unit = np.zeros(operator.shape[0])
            unit[k] = 1.0
            matrix[:, core + b] = restrict(apply(unit), starts, nc + ns, border)
            if core:
                matrix[core + b, :core] = np.add.reduceat(rows[b], starts)
    return starts, nc + ns, border, matrix


def restrict(r: np.ndarray, starts: np.ndarray, traction: int, border: np.ndarray) -> np.ndarray:
    """P^T r: the sums of a fine vector over the aggregates (first unknowns ``starts``, the
    ``traction`` unknowns), then its ``border`` entries."""
    core = np.add.reduceat(r[:traction], starts) if starts.size else np.zeros(0)
    return np.concatenate([core, r[border]])


def prolong(c: np.ndarray, starts: np.ndarray, traction: int) -> np.ndarray:
    """P c: each aggregate's value repeated over its unknowns, then the border values."""
    counts = np.diff(np.append(starts, traction))
    out = np.empty(traction + c.size - starts.size)
    out[:traction] = np.repeat(c[: starts.size], counts)
    out[traction:] = c[starts.size :]
    return out


def two_level(
    apply: Callable[[np.ndarray], np.ndarray],
    band: Callable[[np.ndarray], np.ndarray],
    coarse: CoarseCorrection,
) -> Callable[[np.ndarray], np.ndarray]:
    """v -> y + Q (v - A y), y = band(v), Q the coarse correction (the module docstring)."""

    def precondition(v: np.ndarray) -> np.ndarray:
        y = band(v)
        return y + coarse(v - apply(y))

    return precondition


def _aggregates(nodes: np.ndarray, labels: np.ndarray | None, length: int, offset: int):
    """(first unknown, first node, end node, slip coefficient) per aggregate of the unknowns at
    ``nodes`` (ascending; unknown k + ``offset`` at ``nodes[k]``): runs of adjacent nodes with one
    column of ``labels`` (slip coefficient first), cut where the node is a multiple of ``length``."""
    if not nodes.size:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty, empty, np.zeros(0)
    cut = np.ones(nodes.size, dtype=bool)
    cut[1:] = (np.diff(nodes) != 1) | (nodes[1:] % length == 0)
    if labels is not None:
        cut[1:] |= np.any(labels[:, 1:] != labels[:, :-1], axis=0)
    first = np.flatnonzero(cut)
    last = np.append(first[1:], nodes.size) - 1
    values = labels[0, first] if labels is not None else np.zeros(first.size)
    return first + offset, nodes[first], nodes[last] + 1, values


def _traction_block(operator, normal, tangential, out: np.ndarray) -> None:
    """P^T A P between the traction aggregates into ``out`` (contact aggregates first): rectangle
    sums of the influence operators, one operator at a time (its cells are N_c^2 doubles).

    An adhesion aggregate's nodes are a contact aggregate's (both are cut at the adhesion zone's
    ends and at the same multiples), so every aggregate spans one interval between consecutive
    breaks: the rectangle sums are the cells of the corner sums' second difference.
    """
    system = operator.problem.system
    problem = operator.problem
    _, lo_n, hi_n, coef_n = normal
    _, lo_t, hi_t, _ = tangential
    breaks = np.unique(np.concatenate([lo_n, hi_n, lo_t, hi_t]))
    rn, rt = np.searchsorted(breaks, lo_n), np.searchsorted(breaks, lo_t)
    if not (np.array_equal(breaks[rn + 1], hi_n) and np.array_equal(breaks[rt + 1], hi_t)):
        raise np.linalg.LinAlgError("an aggregate spans several intervals")  # not by _aggregates
    na, nt = lo_n.size, lo_t.size
    normal_rows, tangential_rows = slice(0, na), slice(na, na + nt)
    coupled = system.coupled
    with_t = operator.coef is not None and problem.tangential
    s_n = system.penalty_n * operator.row_scale[0] if na else 0.0  # contact rows: r_n (S_nn p_n + S_nt p_t)
    s_t = system.penalty_t * operator.row_scale[operator.contact.size] if nt else 0.0  # r_t (B_tt p_t + B_tn p_n)
    # (operator, [(fine rows, fine columns, block rows, block columns, factor)])
    terms = []
    if na:
        terms.append((system.S_nn, [(rn, rn, normal_rows, normal_rows, s_n)]))
        if coupled:
            parts = [(rn, rn, normal_rows, normal_rows, s_n * coef_n[None, :])] if with_t else []
            if nt:
                parts.append((rn, rt, normal_rows, tangential_rows, s_n))
            terms.append((system.S_nt, parts))
    if nt:
        parts = [(rt, rt, tangential_rows, tangential_rows, s_t)]
        if with_t and na:
            parts.append((rt, rn, tangential_rows, normal_rows, s_t * coef_n[None, :]))
        terms.append((system.B_tt, parts))
        if na and coupled and problem.normal:
            terms.append((system.B_tn, [(rt, rn, tangential_rows, normal_rows, s_t)]))
    for op, parts in terms:
        if not parts:
            continue
        corners = op.corner_sums(breaks, breaks)
        corners[1:] -= corners[:-1].copy()
        cells = np.diff(corners[1:], axis=1)
        del corners
        for rows, cols, block_rows, block_cols, factor in parts:
            out[block_rows, block_cols] += factor * cells[np.ix_(rows, cols)]
