"""Closed-form plane-strain half-plane influence (Johnson, Contact Mechanics, 2.2).

For one half-plane (E, nu) under the nodal tractions of the contact grid, in the
body's own frame (z into the body), with k = 2 (1 - nu^2) / (pi E) and
c = (1 - 2 nu)(1 + nu) / (2 E):

    w(x) =  k int p_n(s) ln(|x - s|/L) ds + c int p_t(s) sgn(x - s) ds
    u(x) =  c int p_n(s) sgn(x - s) ds   - k int p_t(s) ln(|x - s|/L) ds

(p_n <= 0 in compression). The log kernel leaves a free rigid constant: the
reference length L only shifts w and u by constants, so the normal approach
(overlap) of a half-plane is undefined and this model must be loaded by force.
Element integrals are exact (:mod:`rolling_cli.model.kernels`) for any element
length. On a uniform grid each matrix is block-Toeplitz: only the 2 N_e - 1
element offsets are integrated and the matrix is gathered from them, or, on
large grids (:func:`use_operators`), kept as a
:class:`~rolling_cli.influence.toeplitz.BlockToeplitz` operator (O(n) memory,
FFT products) with the same entries. On a
graded grid every (target node, source element) pair is integrated in its own
element's local coordinate (:func:`graded_log_matrix`, :func:`graded_sign_matrix`),
O(n N_e) work, the size of the matrix itself.
"""

from __future__ import annotations

import math

import numpy as np

from ..model import materials
from ..model.grid import NODE_COORDINATES, ContactGrid, shape_coefficients, shape_integrals
from ..model.kernels import log_moments, sign_moments
from ..model.viscoelastic import Material
from . import Compliance


def _toeplitz_gather(grid: ContactGrid, per_offset: np.ndarray) -> np.ndarray:
    """Full (n, n) matrix from values per (element offset, target node, source node).

    ``per_offset[o + N_e - 1, a, k]`` is the entry for target node a of element
    e_i and source node k of element e_j = e_i - o. Reversing the offsets and
    flattening (offset, k) makes every matrix row a contiguous window of one
    vector per a, so the matrix is written row by row from sliding windows.
    """
    ne, m = grid.elements, grid.nodes_per_element
    n = ne * m
    out = np.empty((ne, m, n))
    for a in range(m):
        flat = np.ascontiguousarray(per_offset[::-1, a, :]).reshape(-1)
        windows = np.lib.stride_tricks.sliding_window_view(flat, n)[::m]  # row t starts at t * m
        out[:, a, :] = windows[ne - 1 :: -1]
    return out.reshape(n, n)


def _local_coordinates(grid: ContactGrid) -> np.ndarray:
    """c[o, a]: local coordinate of target node a of element e_j + o in element e_j."""
    ne = grid.elements
    offsets = np.arange(-(ne - 1), ne)
    return 2.0 * offsets[:, None] + NODE_COORDINATES[grid.order][None, :]


#: Target rows per block of the graded integration (bounds the (rows, N_e, 3) moment arrays).
GRADED_BLOCK_PAIRS = 1 << 20


def _graded_matrix(grid: ContactGrid, moments_of, log_length: float | None) -> np.ndarray:
    """M[i, j] = half_e sum_m moments(c_ie)[m] A[k, m] (+ half_e ln(half_e / L) int N_k) for node j = (e, k).

    c_ie is node i's local coordinate in element e; rows are integrated in
    blocks of at most :data:`GRADED_BLOCK_PAIRS` (node, element) pairs.
    """
    half = 0.5 * grid.element_lengths
    coeff = shape_coefficients(grid.order)
    deg = coeff.shape[1]
    constant = None
    if log_length is not None:
        constant = np.log(half / log_length)[:, None] * shape_integrals(grid.order)[None, :]  # (e, k)
    n = grid.size
    out = np.empty((n, grid.elements, deg))
    rows = max(1, GRADED_BLOCK_PAIRS // grid.elements)
    for lo in range(0, n, rows):
        c = (grid.x[lo : lo + rows, None] - grid.element_centres[None, :]) / half[None, :]
        block = np.einsum("iem,km->iek", moments_of(c)[..., :deg], coeff)
        if constant is not None:
            block += constant[None]
        out[lo : lo + rows] = block
    out *= half[None, :, None]
    return out.reshape(n, n)


def graded_log_matrix(grid: ContactGrid, length_scale: float) -> np.ndarray:
    """L[i, j] = int N_j(s) ln(|x_i - s| / length_scale) ds [length], any grid (no Toeplitz structure)."""
    return _graded_matrix(grid, log_moments, length_scale)


def graded_sign_matrix(grid: ContactGrid) -> np.ndarray:
    """Sg[i, j] = int N_j(s) sgn(x_i - s) ds [length], any grid (no Toeplitz structure)."""
    return _graded_matrix(grid, sign_moments, None)


def log_offsets(grid: ContactGrid, length_scale: float) -> np.ndarray:
    """The log kernel's blocks per element offset on a uniform grid [length], (2 N_e - 1, m, m):
    ``[o + N_e - 1, a, k]`` = int N_k(s) ln(|x - s| / length_scale) ds for target node a of
    element e + o and source node k of element e."""
    half = 0.5 * grid.element_length
    coeff = shape_coefficients(grid.order)
    moments = log_moments(_local_coordinates(grid))  # (o, a, power)
    deg = coeff.shape[1]
    return half * (
        np.einsum("oam,km->oak", moments[..., :deg], coeff)
        + np.log(half / length_scale) * shape_integrals(grid.order)[None, None, :]
    )


def sign_offsets(grid: ContactGrid) -> np.ndarray:
    """The sign kernel's blocks per element offset on a uniform grid [length] (as :func:`log_offsets`)."""
    half = 0.5 * grid.element_length
    coeff = shape_coefficients(grid.order)
    moments = sign_moments(_local_coordinates(grid))
    deg = coeff.shape[1]
    return half * np.einsum("oam,km->oak", moments[..., :deg], coeff)


def log_matrix(grid: ContactGrid, length_scale: float) -> np.ndarray:
    """L[i, j] = int N_j(s) ln(|x_i - s| / length_scale) ds [length] (block-Toeplitz path when uniform)."""
    if not grid.uniform:
        return graded_log_matrix(grid, length_scale)
    return _toeplitz_gather(grid, log_offsets(grid, length_scale))


def sign_matrix(grid: ContactGrid) -> np.ndarray:
    """Sg[i, j] = int N_j(s) sgn(x_i - s) ds [length] (block-Toeplitz path when uniform)."""
    if not grid.uniform:
        return graded_sign_matrix(grid)
    return _toeplitz_gather(grid, sign_offsets(grid))


def _length_scale(grid: ContactGrid) -> float:
    """Reference length of the log kernel: e * (zone width), so ln(|x - s|/L) < 0 on the zone."""
    return float(math.e * 2.0 * grid.half_width)


#: Uniform grids with at least this many contact nodes get :class:`~rolling_cli.influence.toeplitz.BlockToeplitz`
#: operators instead of dense matrices, and so the matrix-free Newton solve
#: (:mod:`rolling_cli.solver.matrix_free`); below it the dense LU is faster (``benchmarks/bench_solve.py``).
OPERATOR_NODES = 900


def use_operators(grid: ContactGrid) -> bool:
    """True when the compliance of ``grid`` is held as block-Toeplitz operators: a uniform grid of
    at least :data:`OPERATOR_NODES` nodes (a graded grid has no Toeplitz structure: dense)."""
    return grid.uniform and grid.size >= OPERATOR_NODES


def body_compliance(
    grid: ContactGrid, young: float, poisson: float, coupling: bool = True, operators: bool | None = None
) -> Compliance:
    """Compliance of one elastic half-plane on the contact grid [length/stress] (``operators``: see
    :func:`pair_compliance`)."""
    return _compliance(
        grid,
        direct=2.0 * materials.plane_strain_compliance(young, poisson) / np.pi,
        cross=materials.coupling_compliance(young, poisson),
        coupling=coupling,
        operators=operators,
    )


def pair_compliance(
    grid: ContactGrid,
    young_a: float,
    poisson_a: float,
    young_b: float,
    poisson_b: float,
    coupling: bool = True,
    operators: bool | None = None,
) -> Compliance:
    """Compliance of the half-plane pair (``young = inf`` for a rigid body) [length/stress].

    Direct terms add (2 / (pi E*)); cross terms subtract (Kalker's K/G). With
    ``coupling=False`` the cross blocks are neither integrated nor stored. The
    blocks are dense arrays, or block-Toeplitz operators with the same entries
    (``operators=True``; ``None``: :func:`use_operators` decides by size).
    """
    e_star = materials.effective_modulus(young_a, poisson_a, young_b, poisson_b)
    cross = materials.kalker_k_over_g(young_a, poisson_a, young_b, poisson_b)
    return _compliance(grid, direct=2.0 / (np.pi * e_star), cross=cross, coupling=coupling, operators=operators)


def materials_pair(
    grid: ContactGrid,
    material_a: Material | None,
    material_b: Material | None,
    coupling: bool = True,
    operators: bool | None = None,
) -> Compliance:
    """:func:`pair_compliance` of two elastic :class:`~rolling_cli.model.viscoelastic.Material`
    values (None: a rigid body) [length/stress]. A material with retardation terms is refused
    (its steady-rolling kernels are :mod:`.viscoelastic`'s)."""
    constants = [elastic_constants(m) for m in (material_a, material_b)]
    return pair_compliance(grid, *constants[0], *constants[1], coupling=coupling, operators=operators)


def elastic_constants(material: Material | None) -> tuple[float, float]:
    """(E [stress], nu [-]) of an elastic material; (inf, 0) for None, a rigid body (its compliance
    1/inf = 0 drops out of every formula)."""
    if material is None:
        return math.inf, 0.0
    if not material.elastic:
        raise ValueError(f"a {material.label} material has no elastic half-plane kernel")
    return material.young, material.poisson


def _compliance(grid: ContactGrid, direct: float, cross: float, coupling: bool, operators: bool | None) -> Compliance:
    if operators is None:
        operators = use_operators(grid)
    if operators:
        return _operator_compliance(grid, direct, cross, coupling)
    s_nn = log_matrix(grid, _length_scale(grid))
    s_nn *= direct
    s_nt = s_tn = None
    if coupling:
        s_nt = sign_matrix(grid)
        s_nt *= cross
        s_tn = s_nt  # identical kernels: share the array (read-only use)
    return Compliance(
        x=grid.x,
        weights=grid.weights,
        S_nn=s_nn,
        S_tt=np.negative(s_nn),
        S_nt=s_nt,
        S_tn=s_tn,
        definite_normal=False,
    )


def _operator_compliance(grid: ContactGrid, direct: float, cross: float, coupling: bool) -> Compliance:
    """As the dense compliance, the blocks held as block-Toeplitz operators (the same entries, bit for bit)."""
    from .toeplitz import BlockToeplitz

    if not grid.uniform:
        raise ValueError("block-Toeplitz operators need a uniform grid")
    offsets = log_offsets(grid, _length_scale(grid))
    offsets *= direct
    s_nn = BlockToeplitz(offsets)
    s_nt = None
    if coupling:
        offsets = sign_offsets(grid)
        offsets *= cross
        s_nt = BlockToeplitz(offsets)
    return Compliance(
        x=grid.x, weights=grid.weights, S_nn=s_nn, S_tt=-s_nn, S_nt=s_nt, S_tn=s_nt, definite_normal=False
    )
