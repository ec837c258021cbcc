"""The linear part of the rolling contact problem (paper eq. 14, 19-26).

    delta_n = gap0 - overlap + S_nn p_n + S_nt p_t        (normal gap, eq. 14)
    s_t     = xi e + B_tn p_n + B_tt p_t,  B = T S         (slip, eq. 22-25)

gap0 = x^2 / (2 R*) is the undeformed profile (eq. 7), ``overlap`` the imposed
rigid approach, xi the creepage, e the creep vector (0 on the gauge row) and T
the upwind slip operator of :mod:`rolling_cli.model.slip`. The contact laws and the
Newton solver in :mod:`rolling_cli.solver` only see these plain arrays, or, for
large uniform half-plane grids, block-Toeplitz operators with the same entries
(:class:`~rolling_cli.influence.toeplitz.BlockToeplitz`: ``@``, exact entries,
row sums); :attr:`ContactSystem.matrix_free` says which, and the Newton
system is then solved matrix-free (:mod:`rolling_cli.solver.matrix_free`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..influence import Block, Compliance
from ..model import slip
from ..model.grid import ContactGrid, node_cell_edges


@dataclass(frozen=True)
class ContactSystem:
    """Arrays of the discrete rolling problem.

    Units: ``x``, ``weights`` [length]; ``spacing`` [length] the node spacing
    (on a graded grid the largest one); ``gap0`` [length];
    ``S_nn``, ``S_nt`` [length/stress]; ``B_tn``, ``B_tt`` [1/stress] on slip rows
    (the gauge row holds displacements, [length/stress]); ``penalty_n``
    [stress/length], ``penalty_t`` [stress] are the solver's penalties, which
    choose the node states of the Newton Jacobian; ``reference_penalty_*`` are
    the automatic ones, which measure the residual. ``S_nt``/``B_tn`` are ``None`` when
    the coupling is not simulated. ``gauge_tn``/``gauge_tt`` are the slip rows of
    the gauge node by a downwind difference, for reporting only. ``load_n``, ``load_t``
    [length]: the weights of the load P = -(load_n p_n + load_t p_t) that ``normal.load``
    prescribes (:meth:`load`); None: the quadrature weights and no p_t term (P the arc
    sum; a finite cylinder's shaft load otherwise, :mod:`rolling_cli.influence.finite`). The four blocks
    are dense arrays, or all :class:`~rolling_cli.influence.toeplitz.BlockToeplitz`
    operators (:attr:`matrix_free`).
    """

    x: np.ndarray
    weights: np.ndarray
    spacing: float
    gap0: np.ndarray
    S_nn: Block
    B_tt: Block
    creep_vector: np.ndarray
    gauge: int
    direction: int
    penalty_n: float
    penalty_t: float
    S_nt: Block | None = None
    B_tn: Block | None = None
    gauge_tn: np.ndarray | None = None
    gauge_tt: np.ndarray | None = None
    definite_normal: bool = False
    reference_penalty_n: float = 0.0
    reference_penalty_t: float = 0.0
    load_n: np.ndarray | None = None
    load_t: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Number of contact nodes n."""
        return self.x.shape[0]

    @property
    def coupled(self) -> bool:
        """True when the normal-tangential coupling blocks are present."""
        return self.S_nt is not None

    @property
    def matrix_free(self) -> bool:
        """True when the blocks are block-Toeplitz operators: the Newton system is then applied
        matrix-free and solved by a preconditioned Krylov method instead of a dense LU."""
        return _is_operator(self.S_nn)

    @property
    def linear_solver(self) -> str:
        """The linear solver of the Newton steps on this system: "dense LU" or "Krylov" (the
        history column and result attribute ``linear_solver``)."""
        return "Krylov" if self.matrix_free else "dense LU"

    def node_cells(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper edges of every node's cell [length] (:func:`~rolling_cli.model.grid.node_cell_edges`)."""
        edges = node_cell_edges(self.x)
        return edges[:-1], edges[1:]

    def extent(self, nodes: np.ndarray) -> tuple[float, float]:
        """Smallest and largest x [length] of the cells of the selected ``nodes`` (a mask or indices)."""
        lo, hi = self.node_cells()
        return float(lo[nodes].min()), float(hi[nodes].max())

    @property
    def load_weights(self) -> np.ndarray:
        """The weights of p_n in the load P [length]: ``load_n``, or the quadrature weights."""
        return self.weights if self.load_n is None else self.load_n

    def load(self, p_n: np.ndarray, p_t: np.ndarray) -> float:
        """The load P = -(load_n p_n + load_t p_t) [force/length] that ``normal.load`` prescribes: the
        arc sum -sum w p_n, or a finite cylinder's shaft load (class docstring)."""
        out = -float(self.load_weights @ p_n)
        if self.load_t is not None:
            out -= float(self.load_t @ p_t)
        return out

    @property
    def zone_length(self) -> float:
        """Length of the potential contact zone, sum of the weights [length]."""
        return float(self.weights.sum())

    def gap(self, p_n: np.ndarray, p_t: np.ndarray, overlap: float) -> np.ndarray:
        """Normal gap delta_n [length] (eq. 14)."""
        out = self.gap0 - overlap + self.S_nn @ p_n
        if self.S_nt is not None:
            out += self.S_nt @ p_t
        return out

    def slip(self, p_n: np.ndarray, p_t: np.ndarray, creep: float) -> np.ndarray:
        """Slip s_t [-] (eq. 22); the gauge row holds the gauge displacement."""
        out = creep * self.creep_vector + self.B_tt @ p_t
        if self.B_tn is not None:
            out += self.B_tn @ p_n
        return out

    def reported_slip(self, p_n: np.ndarray, p_t: np.ndarray, creep: float) -> np.ndarray:
        """Slip velocity at every node [-], the gauge node by a downwind difference."""
        out = self.slip(p_n, p_t, creep)
        g = self.gauge
        value = creep + self.gauge_tt @ p_t
        if self.gauge_tn is not None:
            value += self.gauge_tn @ p_n
        out[g] = value
        return out


def automatic_penalties(S_nn: np.ndarray, B_tt: np.ndarray, direction: int) -> tuple[float, float]:
    """Penalties scaled to the influence blocks: (r_n [stress/length], r_t [stress]).

    r_t = 1 / max|B_tt| over the slip rows (PHYSICS.md: this choice converged in
    6 Newton steps where 1000x smaller took 120). r_n = 1 / max|S_nn[i] - S_nn[up(i)]|:
    the largest change of the normal approach between neighbouring nodes per
    unit nodal pressure (on a uniform grid Delta max|D S_nn|, D the first-order
    difference; the form needs no spacing, so graded grids get it too). Both
    are free of the rigid constant of the log kernel, so the half-plane and BEM
    models get the same scale. The kernels peak at the diagonal, so the maxima
    are taken over the band |i - j| <= :data:`PENALTY_BAND` (O(n) work instead
    of O(n^2)).
    """
    n = B_tt.shape[0]
    g = slip.gauge_index(n, direction)
    rows = np.delete(np.arange(n), g)
    offsets = np.arange(-PENALTY_BAND, PENALTY_BAND + 1)
    cols = np.clip(rows[:, None] + offsets[None, :], 0, n - 1)
    r_t = 1.0 / float(np.max(np.abs(entries(B_tt, rows[:, None], cols))))
    up = rows - direction  # the upstream neighbour of every slip row
    r_n = 1.0 / float(np.max(np.abs(entries(S_nn, rows[:, None], cols) - entries(S_nn, up[:, None], cols))))
    return r_n, r_t


def _is_operator(matrix) -> bool:
    """True for a block-Toeplitz operator, False for a dense array (the module is not imported for it)."""
    return matrix is not None and not isinstance(matrix, np.ndarray)


def entries(matrix, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """matrix[rows, cols] (broadcast index arrays) of a dense block or a block-Toeplitz operator."""
    if _is_operator(matrix):
        return matrix.entries(rows, cols)
    return matrix[rows, cols]


def abs_max(matrix, rows: np.ndarray) -> float:
    """max |matrix_ij| over the given rows (an index array or a boolean mask), dense or block-Toeplitz."""
    if _is_operator(matrix):
        return matrix.abs_max(rows)
    return float(np.abs(matrix[rows]).max())


def abs_row_sum_max(matrix, rows: np.ndarray | None = None) -> float:
    """max_i sum_j |matrix_ij| over the given rows (None: all), dense or block-Toeplitz."""
    if _is_operator(matrix):
        sums = matrix.abs_row_sums()
        return float((sums if rows is None else sums[rows]).max())
    return float(np.abs(matrix if rows is None else matrix[rows]).sum(axis=1).max())


#: Half-width of the diagonal band searched for the penalty scales.
PENALTY_BAND = 6


def build_system(
    compliance: Compliance,
    radius: float,
    direction: int,
    grid: ContactGrid | float,
    scheme: str = "fd",
    penalty: float | None = None,
) -> ContactSystem:
    """Assemble the contact system from a pair compliance.

    ``radius`` is R* [length], ``direction`` the sign of V, ``grid`` the contact
    grid of the compliance (or, on a uniform grid, just its node spacing
    [length]), ``scheme`` the slip derivative, ``penalty`` r_t [stress] or
    ``None`` for automatic (r_n then keeps the automatic ratio r_n/r_t). On a
    uniform grid the slip operator uses the one spacing, on a graded grid the
    distances between neighbouring nodes.
    """
    x = compliance.x
    n = x.shape[0]
    spacing, largest = _slip_spacing(x, grid)
    g = slip.gauge_index(n, direction)
    b_tt = _slip_block(compliance.S_tt, spacing, direction, scheme)
    b_tn = None
    gauge_tn = None
    if compliance.S_tn is not None:
        b_tn = _slip_block(compliance.S_tn, spacing, direction, scheme)
        gauge_tn = _downwind_row(compliance.S_tn, spacing, direction)
    if compliance.hoop_t is not None:  # a finite body's hoop strain on the slip rows (not the gauge row)
        b_tt, b_tn = _with_hoop(b_tt, b_tn, compliance, g, direction)
    ref_n, ref_t = automatic_penalties(compliance.S_nn, b_tt, direction)
    r_n, r_t = ref_n, ref_t
    if penalty is not None:
        r_n, r_t = ref_n * penalty / ref_t, float(penalty)
    return ContactSystem(
        x=x,
        weights=compliance.weights,
        spacing=largest,
        gap0=0.5 * x**2 / radius if compliance.gap0 is None else compliance.gap0,
        S_nn=compliance.S_nn,
        S_nt=compliance.S_nt,
        B_tn=b_tn,
        B_tt=b_tt,
        creep_vector=slip.creep_vector(n, direction),
        gauge=g,
        direction=direction,
        penalty_n=r_n,
        penalty_t=r_t,
        reference_penalty_n=ref_n,
        reference_penalty_t=ref_t,
        gauge_tn=gauge_tn,
        gauge_tt=_downwind_row(compliance.S_tt, spacing, direction),
        definite_normal=compliance.definite_normal,
        load_n=compliance.load_n,
        load_t=compliance.load_t,
    )


def _with_hoop(b_tt, b_tn, compliance: Compliance, gauge: int, direction: int):
    """B_tt and B_tn plus sgn(V) times the hoop strain blocks, except on the gauge row (dense)."""
    rows = np.ones((compliance.x.shape[0], 1))
    rows[gauge] = 0.0
    hoop_t, hoop_n = compliance.hoop_t, compliance.hoop_n
    if hoop_t is not None:
        b_tt = b_tt + direction * rows * hoop_t
    if b_tn is not None and hoop_n is not None:
        b_tn = b_tn + direction * rows * hoop_n
    return b_tt, b_tn


def _slip_block(matrix, spacing, direction: int, scheme: str):
    """T @ matrix (:func:`rolling_cli.model.slip.apply_t`), for a dense block or a block-Toeplitz operator."""
    if _is_operator(matrix):
        return matrix.upwind_derivative(spacing, direction, scheme)
    return slip.apply_t(matrix, spacing, direction, scheme)


def _downwind_row(matrix, spacing, direction: int) -> np.ndarray:
    """The gauge node's downwind slip row (:func:`rolling_cli.model.slip.downwind_row`), dense or block-Toeplitz."""
    if _is_operator(matrix):
        n = matrix.shape[0]
        g = slip.gauge_index(n, direction)
        inner = g - 1 if direction < 0 else g + 1
        end = matrix.block(np.array([inner, g]))
        return (end[0] - end[1]) / spacing
    return slip.downwind_row(matrix, spacing, direction)


#: Node distances may differ from a uniform spacing by this fraction (round-off of the node positions).
UNIFORM_TOLERANCE = 1e-9


def _slip_spacing(x: np.ndarray, grid: ContactGrid | float) -> tuple[float | np.ndarray, float]:
    """The spacing argument of :func:`rolling_cli.model.slip.apply_t` and the largest node distance [length]."""
    gaps = np.diff(x)
    if isinstance(grid, ContactGrid):
        if grid.size != x.size or not np.allclose(grid.x, x, rtol=0.0, atol=UNIFORM_TOLERANCE * grid.half_width):
            raise ValueError("the compliance is not on the nodes of this contact grid")
        if not grid.uniform:
            return gaps, float(gaps.max())
        grid = grid.spacing
    spacing = float(grid)
    if gaps.size and not np.allclose(gaps, spacing, rtol=UNIFORM_TOLERANCE, atol=0.0):
        raise ValueError("a single node spacing was given for a graded grid: pass the ContactGrid")
    return spacing, spacing
