"""The Krylov preconditioner of the matrix-free Newton system: the LU of its near field.

For a :class:`~rolling_cli.solver.matrix_free.ReducedOperator` A with its
contact rows differenced (E, see :mod:`rolling_cli.solver.matrix_free`), the
unknowns of the tractions are ordered by node (p_n before p_t at each node):
the entries of E A between nodes at most ``width`` nodes apart then lie in a
band of half-width ``width`` (one traction) or 2 ``width`` + 1 (both), which
is assembled diagonal by diagonal from exact entries (O(N width) memory, no
sparse matrix) and factorised by LAPACK's banded LU with the overlap and
creepage unknowns as dense borders (:class:`~rolling_cli.solver.banded.BorderedBandLU`),
or, if that is singular, by SuperLU (:class:`~rolling_cli.solver.banded.SparseLU`).
:func:`preconditioner` returns v -> M^-1 E v.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .banded import BorderedBandLU, SparseLU, band_entries


def band_order(operator) -> tuple[np.ndarray, int]:
    """The traction unknowns in node order (p_n before p_t at each node), and the band
    half-width per node of distance (1 or 2)."""
    keys = np.concatenate([2 * operator.contact, 2 * operator.stick + 1])
    both = operator.contact.size and operator.stick.size
    return np.argsort(keys, kind="stable"), 2 if both else 1


#: The band is factorised in single precision (a preconditioner needs a few digits; the flexible
#: GMRES of :mod:`rolling_cli.solver.krylov` loses nothing by it): 3-5x faster LAPACK.
SINGLE = True


def preconditioner(operator, width: int) -> Callable[[np.ndarray], np.ndarray]:
    """v -> M^-1 E v for the near field M of E A (rows scaled), nodes up to ``width`` apart."""
    order, per_node = band_order(operator)
    size = order.size
    half = min(per_node * width + per_node - 1, max(size - 1, 0))
    border, columns, rows, corner = operator.borders()
    columns, rows = columns[order], rows[:, order]
    try:
        factor = BorderedBandLU(_band(operator, order, half), half, half, columns, rows, corner, single=SINGLE)

        def solve(v):
            core, edge = factor.solve(v[:size][order], v[size:])
            out = np.empty_like(v)
            out[order] = core
            out[size:] = edge
            return out

    except np.linalg.LinAlgError:  # (the factorisation overwrote the band: assemble it again)
        solve = _whole(_band(operator, order, half), half, columns, rows, corner, size, order).solve

    def apply(v: np.ndarray) -> np.ndarray:
        return solve(operator.difference(v))

    return apply


#: Band entries gathered per call (bounds the temporaries of the assembly: ~100 bytes each).
CHUNK = 1 << 17


def _band(operator, order: np.ndarray, half: int) -> np.ndarray:
    """E A's entries within ``half`` positions of the diagonal, in LAPACK band storage with room for the fill.

    Diagonal by diagonal, the operator's :meth:`entries` arithmetic on slices of per-position
    arrays (node, kind, slip coefficient, row scale): the influence values are gathered at one
    flat block-Toeplitz index per entry (a differenced contact row's next node is one block
    row further), without the index arrays of :meth:`entries`. Equal to :func:`_band_from_entries`.
    """
    size = order.size
    band = np.zeros((3 * half + 1, size), order="F")
    if not size:
        return band
    system = operator.problem.system
    contact, stick, coef = operator.contact, operator.stick, operator.coef
    nc = contact.size
    normal_at = order < nc  # the kind of each position's unknown
    node = np.empty(size, dtype=np.intp)
    node[normal_at] = contact[order[normal_at]]
    node[~normal_at] = stick[order[~normal_at] - nc]
    with_t = coef is not None and system.coupled
    slip = np.zeros(size)
    if coef is not None:
        slip[normal_at] = coef[order[normal_at]]
    shifted = np.zeros(size, dtype=bool)
    shifted[normal_at] = operator._differenced()[order[normal_at]]
    scale = operator.row_scale[order]
    first = system.S_nn if system.S_nn is not None else system.B_tt
    m, ne = first.block_size, first.elements
    # the flat index of gather(): m (i - j) + (m + 1) (j % m) + (N_e - 1) m^2, a row part and a column part
    base = m * node + (ne - 1) * m * m
    column = (m + 1) * (node % m) - m * node if m > 1 else -m * node

    def value(op, flat, row_nodes, col_nodes):
        """op[row node, column node] at their flat indices (explicit rows from their values)."""
        out = op.values.reshape(-1)[flat]
        if op.rows.size:
            slot = op._slots()[row_nodes]
            explicit = np.flatnonzero(slot >= 0)
            if explicit.size:
                out[explicit] = op.row_values[slot[explicit], col_nodes[explicit]]
        return out

    def normal(flat, row_nodes, col_nodes, cols_n, col_slip):
        """A contact row's entries before r_n (:meth:`entries`): S_nn (+ S_nt coef) or S_nt."""
        found = value(system.S_nn, flat, row_nodes, col_nodes)
        other = value(system.S_nt, flat, row_nodes, col_nodes) if system.coupled else 0.0
        out = np.where(cols_n, found, other)
        if with_t:
            out += np.where(cols_n, other * col_slip, 0.0)
        return out

    for d in range(-half, half + 1):
        lo, hi = max(0, -d), min(size, size - d)
        if lo >= hi:
            continue
        rows, cols = slice(lo, hi), slice(lo + d, hi + d)
        flat = base[rows] + column[cols]
        row_nodes, col_nodes, cols_n, col_slip = node[rows], node[cols], normal_at[cols], slip[cols]
        out = np.empty(hi - lo)
        at = np.flatnonzero(normal_at[rows])
        if at.size:
            f, rn, cn, n_, cs = flat[at], row_nodes[at], col_nodes[at], cols_n[at], col_slip[at]
            found = normal(f, rn, cn, n_, cs)
            sh = np.flatnonzero(shifted[rows][at])
            if sh.size:  # the next contact node's row: one node, m flat positions, further
                found[sh] -= normal(f[sh] + m, rn[sh] + 1, cn[sh], n_[sh], cs[sh])
            out[at] = system.penalty_n * found
        at = np.flatnonzero(~normal_at[rows])
        if at.size:
            f, rn, cn, n_, cs = flat[at], row_nodes[at], col_nodes[at], cols_n[at], col_slip[at]
            found = value(system.B_tt, f, rn, cn)
            if n_.any():
                found *= np.where(n_, cs, 1.0)
                if system.coupled:
                    found += np.where(n_, value(system.B_tn, f, rn, cn), 0.0)
            out[at] = system.penalty_t * found
        band[2 * half - d, cols] = out * scale[rows]
    return band


def _band_from_entries(operator, order: np.ndarray, half: int) -> np.ndarray:
    """:func:`_band` from :meth:`entries`, :data:`CHUNK` entries per call (the reference of the tests)."""
    size = order.size
    band = np.zeros((3 * half + 1, size), order="F")
    per_call = max(1, CHUNK // max(size, 1))
    offsets = np.arange(-half, half + 1)
    for lo in range(0, offsets.size, per_call):
        d = offsets[lo : lo + per_call]
        p = np.arange(size)[None, :].repeat(d.size, axis=0)
        q = p + d[:, None]
        valid = (q >= 0) & (q < size)
        rows = np.broadcast_to((2 * half - d)[:, None], p.shape)[valid]
        p, q = p[valid], q[valid]
        band[rows, q] = operator.entries(order[p], order[q])
    return band


def _whole(band, half: int, columns, rows, corner, size: int, order: np.ndarray) -> SparseLU:
    """SuperLU of the bordered near field in the operator's own numbering (the border unknowns last)."""
    r, c, v = band_entries(band, half, half)
    r, c = order[r], order[c]
    nb = corner.shape[0]
    ur, uc = np.nonzero(columns)
    vr, vc = np.nonzero(rows)
    dr, dc = np.nonzero(corner)
    all_rows = np.concatenate([r, order[ur], size + vr, size + dr])
    all_cols = np.concatenate([c, size + uc, order[vc], size + dc])
    values = np.concatenate([v, columns[ur, uc], rows[vr, vc], corner[dr, dc]])
    return SparseLU(all_rows, all_cols, values, size + nb)
