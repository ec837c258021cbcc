"""Block-Toeplitz influence operators of a uniform contact grid, applied in O(n log n).

On a uniform grid of N_e elements with m nodes each (n = m N_e) the half-plane
influence of source node k of element e' at target node a of element e
depends only on the element offset e - e' (and on a, k): the matrix is
block-Toeplitz,

    M[m e + a, m e' + k] = values[e - e' + N_e - 1, a, k],

and :class:`BlockToeplitz` holds only its 2 N_e - 1 offset blocks: O(n)
memory where the dense matrix takes 8 n^2 bytes (800 MB at 10,000 nodes). A few
rows may be given explicitly instead (``rows``, ``row_values``): the slip
operator's gauge row and, for the second-order slip derivative, its neighbour
(:meth:`BlockToeplitz.upwind_derivative`).

It gives, without forming the matrix:

* ``M @ p``: FFT convolution of the offset blocks with the nodal vector
  (O(n log n)); :func:`apply_sum` adds several products with one inverse
  transform;
* exact entries (:meth:`~BlockToeplitz.entries`, :meth:`~BlockToeplitz.block`):
  the offset values gathered, so they equal the dense matrix's bit for bit;
* the row sums of |M| (:meth:`~BlockToeplitz.abs_row_sums`) and the largest
  |M_ij| over a set of rows (:meth:`~BlockToeplitz.abs_max`), in O(n).

Only the products differ from the dense ones, by round-off (tested).
Units are those of the values (the compliance blocks: length/stress).
"""

from __future__ import annotations

import numpy as np


class BlockToeplitz:
    """An n x n block-Toeplitz matrix held by its offset blocks (see the module docstring).

    ``values`` (2 N_e - 1, m, m): the block of element offset o = e - e' at
    ``values[o + N_e - 1]``. ``rows`` (r,) and ``row_values`` (r, n): rows given
    explicitly, which replace the Toeplitz rows. Immutable by convention.
    """

    __array_ufunc__ = None  # numpy scalars and arrays defer to the operators below

    def __init__(self, values: np.ndarray, rows=(), row_values: np.ndarray | None = None) -> None:
        values = np.asarray(values, dtype=float)
        if values.ndim != 3 or values.shape[1] != values.shape[2] or values.shape[0] % 2 != 1:
            raise ValueError("offset blocks must have the shape (2 N_e - 1, m, m)")
        self.values = values
        self.elements = (values.shape[0] + 1) // 2
        self.block_size = values.shape[1]
        n = self.elements * self.block_size
        self.shape = (n, n)
        self.rows = np.asarray(rows, dtype=np.intp).reshape(-1)
        if row_values is None:
            row_values = np.zeros((0, n))
        self.row_values = np.asarray(row_values, dtype=float).reshape(self.rows.size, n)
        distinct = np.unique(self.rows).size == self.rows.size
        if self.rows.size and (self.rows.min() < 0 or self.rows.max() >= n or not distinct):
            raise ValueError("explicit rows must be distinct row indices")
        self._spectrum: np.ndarray | None = None
        self._slot_cache: np.ndarray | None = None
        self._row_cache: dict[bytes, np.ndarray] = {}
        self._corner_cache: np.ndarray | None = None

    # --- arithmetic --------------------------------------------------------------------------------

    def __mul__(self, factor) -> BlockToeplitz:
        factor = float(factor)
        return BlockToeplitz(self.values * factor, self.rows, self.row_values * factor)

    __rmul__ = __mul__

    def __neg__(self) -> BlockToeplitz:
        return BlockToeplitz(-self.values, self.rows, -self.row_values)

    def __matmul__(self, p) -> np.ndarray:
        """M @ p for p of shape (n,) or (n, k), by FFT convolution [units of M times p]."""
        return apply_sum([(self, p)])

    # --- the convolution ---------------------------------------------------------------------------

    @property
    def transform_length(self) -> int:
        """Length of the circular convolution that holds the linear one: >= 2 N_e - 1, FFT-friendly."""
        from scipy.fft import next_fast_len

        return next_fast_len(2 * self.elements - 1, real=True)

    def spectrum(self) -> np.ndarray:
        """Real FFT of the offset blocks over the offsets, (m, m, L/2 + 1) complex (computed once)."""
        if self._spectrum is None:
            from scipy.fft import rfft

            blocks = np.ascontiguousarray(np.moveaxis(self.values, 0, -1))  # (m, m, offsets)
            self._spectrum = rfft(blocks, n=self.transform_length, axis=-1)
        return self._spectrum

    # --- exact entries -----------------------------------------------------------------------------

    def _slots(self) -> np.ndarray:
        """Index into ``rows`` of every row, -1 for Toeplitz rows (computed once)."""
        if self._slot_cache is None:
            slots = np.full(self.shape[0], -1, dtype=np.intp)
            slots[self.rows] = np.arange(self.rows.size)
            self._slot_cache = slots
        return self._slot_cache

    def entries(self, i, j) -> np.ndarray:
        """M[i, j] for broadcastable integer index arrays ``i``, ``j`` (exact: gathered values)."""
        return gather([self], i, j)[0]

    def block(self, rows, cols=None) -> np.ndarray:
        """The dense block M[rows][:, cols] for index arrays (``cols=None``: all columns)."""
        rows = np.asarray(rows, dtype=np.intp).reshape(-1)
        cols = np.arange(self.shape[1]) if cols is None else np.asarray(cols, dtype=np.intp).reshape(-1)
        return self.entries(rows[:, None], cols[None, :])

    def row_block(self, rows: np.ndarray) -> np.ndarray:
        """The full rows M[rows] (a few rows; kept for the next call with the same rows)."""
        key = np.asarray(rows, dtype=np.intp).tobytes()
        cached = self._row_cache.get(key)
        if cached is None:
            if len(self._row_cache) > 4:
                self._row_cache.clear()
            cached = self._row_cache[key] = self.block(rows)
        return cached

    def toarray(self) -> np.ndarray:
        """The dense n x n matrix (small n: tests and comparisons)."""
        return self.block(np.arange(self.shape[0]))

    # --- sums over rectangles (the coarse grid of the Krylov preconditioner) -----------------------

    def corner_sums(self, x, y) -> np.ndarray:
        """G[k, l] = sum_{a < x_k, b < y_l} M[a, b] for node counts ``x`` (K,), ``y`` (L,) in 0..n:
        the sum of M over any rectangle of rows and columns is then four entries of G.

        Per pair of node positions (alpha, beta) in the element, the Toeplitz sum
        sum_{e < X, f < Y} v(e - f) of the offset values v is c2(X - 1) - c2(-1) - c2(X - 1 - Y)
        + c2(-1 - Y), c2 the twice cumulated v (O(N_e) once per operator, O(K L) per call); node
        counts at element boundaries (multiples of m) see the same X for every alpha, so their
        pairs take the values summed over the positions (one pair instead of m^2). Explicit rows
        add their differences from the Toeplitz rows. Round-off: ~eps N_e^2 max|v| absolute.
        """
        x = np.asarray(x, dtype=np.intp).reshape(-1)
        y = np.asarray(y, dtype=np.intp).reshape(-1)
        ne, m = self.elements, self.block_size
        c2 = self._twice_cumulated()  # (m + 1, m + 1, 2 N_e + 1): [alpha, beta], [m, m] the sum

        def toeplitz(c, big_x, big_y):
            """sum_{e < X, f < Y} v(e - f) from c = c2 (c2(t) at index t + N_e + 1)."""
            base = ne + 1
            found = c[(big_x[:, None] + base - 1) - big_y[None, :]]
            np.negative(found, out=found)
            found += c[big_x + base - 1][:, None]
            found += c[base - 1 - big_y][None, :] - c[base - 1]
            return found

        ax, ay = x % m == 0, y % m == 0
        if ax.all() and ay.all():
            out = toeplitz(c2[m, m], x // m, y // m)
        else:
            out = np.empty((x.size, y.size))
            out[np.ix_(ax, ay)] = toeplitz(c2[m, m], x[ax] // m, y[ay] // m)
        # the pairs with a node count inside an element: every position pair alone
        split_rows, split_cols = np.flatnonzero(~ax), np.flatnonzero(~ay)
        for rows, cols in ((split_rows, np.arange(y.size)), (np.flatnonzero(ax), split_cols)):
            if not rows.size or not cols.size:
                continue
            total = np.zeros((rows.size, cols.size))
            for alpha in range(m):
                big_x = -((alpha - x[rows]) // m)  # elements e with m e + alpha < x: ceil((x - alpha) / m)
                for beta in range(m):
                    big_y = -((beta - y[cols]) // m)
                    total += toeplitz(c2[alpha, beta], big_x, big_y)
            out[np.ix_(rows, cols)] = total
        if self.rows.size:  # explicit rows: their difference from the Toeplitz rows, cumulated
            i = self.rows
            j = np.arange(self.shape[1])
            flat = m * (i[:, None] - j[None, :]) + (ne - 1) * m * m + ((m + 1) * (j % m) if m > 1 else 0)
            delta = self.row_values - self.values.reshape(-1)[flat]
            cumulated = np.concatenate([np.zeros((i.size, 1)), np.cumsum(delta, axis=1)], axis=1)
            for r, row in zip(i, cumulated, strict=True):
                out[x > r] += row[y]
        return out

    def _twice_cumulated(self) -> np.ndarray:
        """c2 of :meth:`corner_sums` per position pair and summed, (m + 1, m + 1, 2 N_e + 1) (computed once)."""
        if self._corner_cache is None:
            ne, m = self.elements, self.block_size
            v = np.zeros((m + 1, m + 1, 2 * ne + 1))  # v(d) at index d + N_e + 1, d = -(N_e + 1) .. N_e - 1
            v[:m, :m, 2:] = np.moveaxis(self.values, 0, -1)
            v[m, :m] = v[:m, :m].sum(axis=0)
            v[:, m] = v[:, :m].sum(axis=1)
            self._corner_cache = np.cumsum(np.cumsum(v, axis=-1), axis=-1)
        return self._corner_cache

    # --- row norms ---------------------------------------------------------------------------------

    def abs_row_sums(self) -> np.ndarray:
        """sum_j |M_ij| for every row i, (n,) in O(n).

        Row m e + a sums |values[o, a, :]| over the offsets o + N_e - 1 = e .. e + N_e - 1:
        a difference of cumulative sums.
        """
        ne, m = self.elements, self.block_size
        per_offset = np.abs(self.values).sum(axis=2)  # (2 N_e - 1, m)
        cumulative = np.concatenate([np.zeros((1, m)), np.cumsum(per_offset, axis=0)])
        e = np.arange(ne)
        sums = (cumulative[e + ne] - cumulative[e]).reshape(-1)
        if self.rows.size:
            sums[self.rows] = np.abs(self.row_values).sum(axis=1)
        return sums

    def abs_max(self, rows=None) -> float:
        """max |M_ij| over the given rows (an index array or a boolean mask; None: all) and all columns.

        Row m e + a sees the offsets e .. e + N_e - 1 (shifted indices); the windows of
        any rows overlap, so rows of one a with e in [lo, hi] see exactly lo .. hi + N_e - 1.
        """
        n, ne, m = self.shape[0], self.elements, self.block_size
        chosen = np.zeros(n, dtype=bool)
        chosen[np.arange(n) if rows is None else rows] = True
        largest = 0.0
        if self.rows.size:
            picked = chosen[self.rows]
            if picked.any():
                largest = float(np.abs(self.row_values[picked]).max())
            chosen[self.rows] = False
        per_node = chosen.reshape(ne, m)
        for a in range(m):
            elements = np.flatnonzero(per_node[:, a])
            if elements.size:
                window = self.values[elements[0] : elements[-1] + ne, a, :]
                largest = max(largest, float(np.abs(window).max()))
        return largest

    # --- the slip operator ----------------------------------------------------------------------

    def upwind_derivative(self, spacing: float, direction: int, scheme: str) -> BlockToeplitz:
        """T @ M for the slip operator T of :func:`rolling_cli.model.slip.apply_t` [units of M / length].

        Row i = m e + a of M is the Toeplitz row of the shifted index q = i - m e' + m (N_e - 1)
        for each source element e', so the interior stencil of T (rows i, i +- 1, i +- 2) acts
        along q on the offset values themselves: :func:`~rolling_cli.model.slip.apply_t` applied to the
        (q, k) array gives every interior row's entries with the dense matrix's arithmetic (bit
        for bit). The stencil rows at the gauge end of the zone (the gauge row, and the
        first-order fallback of the second-order scheme) are computed from M's own end rows and
        kept explicitly.
        """
        from ..model import slip

        if self.rows.size:
            raise ValueError("the slip derivative needs a purely Toeplitz matrix")
        n, m = self.shape[0], self.block_size
        if n < 3 or np.ndim(spacing) != 0:
            raise ValueError("the Toeplitz slip derivative needs a uniform grid of at least 3 nodes")
        flat = self.values.reshape(-1, m)  # row q = m (o + N_e - 1) + a, column k
        derived = slip.apply_t(flat, spacing, direction, scheme).reshape(self.values.shape)
        ends = np.arange(n - 3, n) if direction < 0 else np.arange(3)
        end_rows = slip.apply_t(self.block(ends), spacing, direction, scheme)
        keep = slice(1, 3) if direction < 0 else slice(0, 2)
        return BlockToeplitz(derived, ends[keep], end_rows[keep])


def gather(operators: list[BlockToeplitz], i, j) -> list[np.ndarray]:
    """M[i, j] of each block-Toeplitz M of one grid, for broadcastable integer index arrays
    ``i``, ``j``: the offset values gathered (exact), the flat index computed once for all."""
    i, j = np.broadcast_arrays(np.asarray(i, dtype=np.intp), np.asarray(j, dtype=np.intp))
    first = operators[0]
    m, ne = first.block_size, first.elements
    # values[e_i - e_j + N_e - 1, a, k] for i = m e_i + a, j = m e_j + k, as one flat index:
    # m (i - j) + (m + 1) k + (N_e - 1) m^2
    flat = m * (i - j) + (ne - 1) * m * m
    if m > 1:
        flat += (m + 1) * (j % m)
    flat = flat.reshape(-1)
    found = []
    for op in operators:
        if op.shape != first.shape or op.block_size != m:
            raise ValueError("block-Toeplitz entries of different grids")
        out = op.values.reshape(-1)[flat].reshape(i.shape)
        if op.rows.size:
            slot = op._slots()[i]
            explicit = slot >= 0
            if explicit.any():
                out[explicit] = op.row_values[slot[explicit], j[explicit]]
        found.append(out)
    return found


def apply_sum(terms: list[tuple[BlockToeplitz, np.ndarray]]) -> np.ndarray:
    """sum_k M_k @ p_k for block-Toeplitz M_k of one grid, with one inverse FFT (:func:`products`)."""
    return products([terms])[0]


def products(sums: list[list[tuple[BlockToeplitz, np.ndarray]]]) -> list[np.ndarray]:
    """For each list of terms (M_k, p_k), sum_k M_k @ p_k; the M_k all of one grid.

    Each distinct vector p_k (by identity) is transformed once for all the sums,
    and the products are summed in the frequency domain: one forward transform
    of all the distinct operands together and one inverse transform of all the
    sums together when the operands have one shape (node components first,
    frequencies last: contiguous transforms); the explicit rows are then
    recomputed exactly from their row values and the other terms' entries in
    those rows. Returns (n,) or (n, k) arrays like the p_k.
    """
    from scipy.fft import irfft, rfft

    first = sums[0][0][0]
    ne, m = first.elements, first.block_size
    n = first.shape[0]
    length = first.transform_length
    slots: dict[int, int] = {}  # the operands stay alive in ``sums``: their ids are distinct
    arrays: list[np.ndarray] = []
    for terms in sums:
        for op, operand in terms:
            if op.shape != first.shape or op.block_size != m:
                raise ValueError("block-Toeplitz products of different grids")
            if id(operand) not in slots:
                p = np.asarray(operand, dtype=float)
                if p.shape[0] != n:
                    raise ValueError(f"operand has {p.shape[0]} rows, the operator {n} columns")
                slots[id(operand)] = len(arrays)
                arrays.append(p)
    transformed = _forward(arrays, ne, m, length, rfft)
    totals: list[np.ndarray] = []
    for terms in sums:
        total: np.ndarray | None = None
        for op, operand in terms:
            total = _accumulate(total, op.spectrum(), transformed[slots[id(operand)]])
        if total is None:
            raise ValueError("a sum of operator products needs one term at least")
        totals.append(total)
    if len({t.shape for t in totals}) == 1:
        found = list(irfft(np.stack(totals), n=length, axis=-1)[..., ne - 1 : 2 * ne - 1])
    else:
        found = [irfft(t, n=length, axis=-1)[..., ne - 1 : 2 * ne - 1] for t in totals]
    results = []
    for terms, out in zip(sums, found, strict=True):
        out = np.moveaxis(out, -1, 0)  # (ne, m, ...)
        out = np.ascontiguousarray(out).reshape((n,) + out.shape[2:])
        explicit = [op.rows for op, _ in terms if op.rows.size]
        if explicit:
            rows = np.unique(np.concatenate(explicit))
            out[rows] = sum(op.row_block(rows) @ arrays[slots[id(operand)]] for op, operand in terms)
        results.append(out)
    return results


def _forward(arrays: list[np.ndarray], ne: int, m: int, length: int, rfft) -> list[np.ndarray]:
    """Real FFTs of the operands over the elements, each (m, ..., frequencies): one call when
    they have one shape."""

    def components(p: np.ndarray) -> np.ndarray:  # (n, ...) -> (m, ..., ne)
        return np.moveaxis(p.reshape((ne, m) + p.shape[1:]), 0, -1)

    if len({p.shape for p in arrays}) == 1:
        stacked = np.ascontiguousarray(np.stack([components(p) for p in arrays]))
        return list(rfft(stacked, n=length, axis=-1))
    return [rfft(np.ascontiguousarray(components(p)), n=length, axis=-1) for p in arrays]


def _accumulate(total: np.ndarray | None, spectrum: np.ndarray, transformed: np.ndarray) -> np.ndarray:
    """total[a] += sum_k spectrum[a, k] P[k] for P = ``transformed`` (m, ..., frequencies)."""
    m, frequencies = spectrum.shape[0], spectrum.shape[-1]
    flat = transformed.reshape(m, -1, frequencies)
    out = total
    for k in range(m):
        term = spectrum[:, k, None, :] * flat[k]
        if out is None:
            out = term
        else:
            out += term.reshape(out.shape)
    if out is None:
        raise ValueError("an operator spectrum needs one component at least")
    return out.reshape((m,) + transformed.shape[1:])
