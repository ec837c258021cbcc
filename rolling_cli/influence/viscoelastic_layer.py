"""Steady-rolling compliance of a viscoelastic layer bonded to a rigid core (the rubber cover).

A layer of thickness b, constant nu and creep compliance
J(t) = J_g + sum_i c_i (1 - exp(-t/lambda_i)) (:mod:`rolling_cli.model.viscoelastic`)
rolls at speed |V|. As for the half-plane (:mod:`.viscoelastic`), its surface
displacement is the unit-modulus elastic response K weighted by J over the
load history met upstream,

    u = J_g K[p] + sum_i c_i C_i[K[p]],   C_i[f](x) = int_0^inf exp(-s) f(x + b_i s) ds,

b_i = -sgn(V) |V| lambda_i. Written as

    u = J_r K[p] + sum_i c_i (C_i[K] - K)[p],   J_r = J_g + sum_i c_i = 1/E_r,

the first term is today's BEM layer (:mod:`.bem`, built with E = E_g and scaled
by E_g / E_r), so an elastic layer (no terms) is the tyre model to round-off and
slow rolling (b_i -> 0, C_i -> identity) is the relaxed BEM layer exactly. The
history term splits with the half-plane kernel K_hp (the layer's own nu) as

    C_i[K] - K = (C_i[K_hp] - K_hp) + F^-1[ R~(q) (i q b_i / (1 - i q b_i)) ],

R~ = K~ - K_hp~ the remainder of :func:`rolling_cli.references.layer_fourier.remainder`
(C_b multiplies a Fourier transform by 1/(1 - i q b)). The first bracket is the
closed form of :func:`.viscoelastic.quadratic_offsets` (the log constant
cancels); the second is bounded at q -> 0 (R~ ~ -K_hp~ ~ 1/|q| there times
q b) and decays like exp(-2 |q| b), so it is integrated on the element shape
functions in Fourier space, by Gauss-Legendre panels
(:func:`~rolling_cli.references.layer_fourier.wavenumbers`). On a uniform grid
both are block-Toeplitz: only the 2 N_e - 1 element offsets are integrated.

That alone would make fast rolling (|b_i| -> inf) J_g K_BEM + sum c_i (K_BEM - K_F),
K_F the infinite layer of the Fourier transfer matrix: the glassy layer up to the
BEM's own departure from the exact kernels (its compressible element-level
terms, up to 15 % of the cross block on the diagonal at nu = 0.3, as the BEM
half-space's; its truncation). So :func:`body_compliance` also carries that
departure E = K_BEM - K_F along the history, on the nodes
(:func:`upstream_filter`), which makes both limits exact; the filter is the only
approximation in between (tests/test_viscoelastic_layer.py, README).

Why this route: the BEM term keeps today's tyre model and its definite approach
(overlap control works), the history needs only the layer's closed-form transfer
matrix (no viscoelastic BEM, no complex-modulus BEM per speed), and everything
that depends on the speed is Toeplitz, so a speed sweep rebuilds only
O(N_e) integrals and the (n x n) filter products per row.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.grid import ContactGrid, shape_integrals
from ..model.viscoelastic import Viscoelastic
from ..references import layer_fourier
from . import Compliance
from .halfplane import _length_scale, _toeplitz_gather
from .viscoelastic import elastic_shape_offsets, history_lengths, quadratic_offsets

#: Complex phases formed at once by :func:`fourier_offsets` (bounds a temporary to 32 MB).
_PHASES = 1 << 21


def fourier_offsets(
    grid: ContactGrid, thickness: float, poisson: float, lengths, blocks: tuple[int, ...] = (0, 1, 2)
) -> np.ndarray:
    """F^-1[R~ (i q b / (1 - i q b)) N~_k](y_oa) per element offset for each history length b in
    ``lengths`` [length], shape (b, blocks, 2 N_e - 1, 3, 3) [length^2, at unit modulus]: (1/pi) Re
    int_0^inf ... exp(i q y) dq, y the target node's offset from the source element's centre
    (R_nt = -i g_R); ``blocks`` picks of 0 nn, 1 tt, 2 nt (all three by default).

    The offsets are the multiples y = j h/3 (h the element length, j = 3 o + a - 1), so the
    phases are the powers z^j of z = exp(i q h/3) (a running product, round-off ~ j eps), and
    -j takes the conjugates: two real matrix products for all rows and all lengths, on one set of
    wavenumbers."""
    lengths = tuple(float(b) for b in lengths)
    half = 0.5 * grid.element_length
    step = grid.element_length / 3.0
    top = 3 * grid.elements - 2  # the largest |j|
    q, w = layer_fourier.wavenumbers((top + 3) * step, thickness, lengths)
    r_nn, r_tt, g_r = layer_fourier.remainder(q, thickness, poisson)
    shapes = layer_fourier.quadratic_spectra(q, half)  # (q, 3)
    remainders = [(r_nn, r_tt, -1j * g_r)[k] for k in blocks]
    weighted = [w * (1j * q * b / (1.0 - 1j * q * b)) for b in lengths]  # the history's Lorentzian, per b
    columns = np.concatenate([(f * r)[:, None] * shapes for f in weighted for r in remainders], axis=1)
    low = q * (top * step) <= TAYLOR_PHASE  # |j q h/3| <= TAYLOR_PHASE for every j: the series
    even, odd = _taylor_phases(q[low], columns[low], top, step)
    high = ~low
    q, columns = q[high], columns[high]
    chunk = max(1, _PHASES // (top + 1))  # wavenumbers per block of phases (bounds the temporary)
    for lo in range(0, q.size, chunk):
        part = slice(lo, lo + chunk)
        powers = _phase_powers(q[part] * step, top)
        weights = np.zeros((powers.shape[1], 2, 2 * columns.shape[1]))  # (q, re/im, c): Re with Re, Im with Im
        weights[:, 0, : columns.shape[1]] = columns[part].real
        weights[:, 1, columns.shape[1] :] = columns[part].imag
        both = powers.view(float) @ weights.reshape(-1, weights.shape[2])  # one product on the interleaved phases
        even += both[:, : columns.shape[1]]
        odd += both[:, columns.shape[1] :]
    even = np.asarray(even / math.pi, dtype=float)  # from extended precision (:func:`_taylor_phases`)
    odd = np.asarray(odd / math.pi, dtype=float)
    ne = grid.elements
    j = 3 * np.arange(-(ne - 1), ne)[:, None] + np.arange(-1, 2)[None, :]  # (o, a)
    out = even[np.abs(j)] - np.sign(j)[..., None] * odd[np.abs(j)]  # (o, a, b 3 3)
    shape = (2 * ne - 1, 3, len(lengths), len(blocks), 3)
    return out.reshape(shape).transpose(2, 3, 0, 1, 4)  # (b, block, o, a, k)


def _phase_powers(theta: np.ndarray, top: int) -> np.ndarray:
    """exp(i j theta) for j = 0..``top``, shape (top + 1, theta.size) [-]: by doubling, rows m..2m-1
    are rows 0..m-1 times exp(i m theta) (each factor one complex exponential), log2(top) products
    where a running product takes top; row j carries the round-off of at most log2(j) + 1 factors
    (a running product's grows like sqrt(j), squaring's like j)."""
    powers = np.empty((top + 1, theta.size), dtype=complex)
    powers[0] = 1.0
    known = 1
    while known <= top:
        count = min(known, top + 1 - known)
        np.multiply(powers[:count], np.exp(1j * known * theta), out=powers[known : known + count])
        known += count
    return powers


#: Largest phase j q h/3 summed by :func:`_taylor_phases` (its series then need
#: :data:`TAYLOR_TERMS` terms: 1/20! < 1e-18).
TAYLOR_PHASE = 1.0
TAYLOR_TERMS = 10


def _taylor_phases(q: np.ndarray, columns: np.ndarray, top: int, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(sum_q cos(j q step) Re G_q, sum_q sin(j q step) Im G_q) for j = 0..``top``, shape (top + 1, c),
    for the low wavenumbers q [1/length] (q top step <= :data:`TAYLOR_PHASE`) and columns G (q, c):
    by the cosine's and sine's power series, whose coefficients are the moments sum_q (q/q_1)^k G_q
    (q_1 = the largest q), so the phases are never formed (~700 of the wavenumbers lie below the
    first uniform panel, :func:`~rolling_cli.references.layer_fourier.wavenumbers`).

    The moment k = 0 is shared by every j, so its round-off would shift all the entries alike (a
    rigid displacement, to which an overlap-controlled solve answers with a load change: 1e-12 of
    p_n, measured), where the direct sums' round-off differs from entry to entry: it is summed in
    extended precision (``np.longdouble``), and ``even`` is returned so."""
    even = np.zeros((top + 1, columns.shape[1]))
    odd = np.zeros_like(even)
    if q.size == 0:
        return even.astype(np.longdouble), odd
    scale = float(q.max())
    powers = np.vander(q / scale, 2 * TAYLOR_TERMS, increasing=True)  # (q, k): (q/q_1)^k
    moments_re = powers.T @ columns.real  # (k, c)
    moments_im = powers.T @ columns.imag
    x = np.arange(top + 1) * (step * scale)  # (j,) <= TAYLOR_PHASE
    k = np.arange(2 * TAYLOR_TERMS)
    factorial = np.array([math.factorial(int(i)) for i in k], dtype=float)
    series = x[:, None] ** k[None, :] / factorial * np.where(k % 4 < 2, 1.0, -1.0)  # (j, k): (-1)^(k//2) x^k / k!
    even += series[:, 2::2] @ moments_re[2::2]
    odd += series[:, 1::2] @ moments_im[1::2]
    constant = np.sum(columns.real.astype(np.longdouble), axis=0)  # the moment k = 0
    return even + constant[None, :], odd


def history_offsets(
    grid: ContactGrid, thickness: float, poisson: float, lengths, blocks: tuple[int, ...] = (0, 1, 2)
) -> np.ndarray:
    """(C_b[K] - K) of the unit-modulus layer per element offset for each history length b in
    ``lengths`` [length], shape (b, blocks, 2 N_e - 1, 3, 3) [length^2], ``blocks`` of 0 nn, 1 tt,
    2 nt (all three by default): the half-plane's closed form plus the remainder's Fourier part."""
    if grid.order != 2 or not grid.uniform:
        raise ValueError("the viscoelastic layer needs a uniform grid of quadratic elements")
    scale = _length_scale(grid)
    half = 0.5 * grid.element_length  # the half-plane's log_offsets and sign_offsets, their shapes memoised
    log_shape, sign_shape = elastic_shape_offsets(grid.elements)
    elastic_log = half * (log_shape + np.log(half / scale) * shape_integrals(2)[None, None, :])
    elastic_sign = half * sign_shape
    out = fourier_offsets(grid, thickness, poisson, lengths, blocks)
    for n, b in enumerate(lengths):
        log_b, sign_b = _halfplane_history(grid, float(b), scale)
        direct = 2.0 * (1.0 - poisson**2) / math.pi * (log_b - elastic_log)
        closed = (direct, -direct, 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson) * (sign_b - elastic_sign))
        out[n] += np.stack([closed[k] for k in blocks])
    return out


#: |b| / (zone width) of the history length that stands for b -> inf: C_b[K_F] ~ K~(0) / |b| is then
#: ~1e-12 of K, and the log constants (ln |b| ~ 28) cancel to ~1e-14.
FAST = 1e12
#: |b| / (zone width) beyond which the half-plane's history kernels take their limit form.
HUGE = 1e10


def _halfplane_history(grid: ContactGrid, b: float, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(C_b[log], C_b[sign]) element offsets of :func:`.viscoelastic.quadratic_offsets` [length]; for
    |b| > HUGE zone widths their limits: C_b[ln(|u|/L)] -> ln|b| - gamma - ln L and C_b[sgn u] ->
    sgn(b), times the shape integrals (the omitted Phi(u/b) ~ |u/b| ln|b/u| < 3e-9 of them)."""
    if abs(b) <= HUGE * 2.0 * grid.half_width:
        return quadratic_offsets(grid, b, scale)
    from ..model.grid import shape_integrals
    from .viscoelastic import EULER_GAMMA

    half = 0.5 * grid.element_length
    integrals = np.broadcast_to(half * shape_integrals(2), (2 * grid.elements - 1, 3, 3))
    constant = math.log(abs(b)) - EULER_GAMMA - math.log(scale)
    return constant * integrals, math.copysign(1.0, b) * integrals


def upstream_filter(x: np.ndarray, b: float) -> np.ndarray:
    """F[i, m] [-]: the weight of node m's cell in C_b at node i, int over the cell of the upstream
    density exp(-(s - x_i)/b) / |b| (s on the side of x_i that b points to), for node positions x
    [length] (cells of :func:`~rolling_cli.model.grid.node_cell_edges`): C_b of a function known
    only at the nodes, taken piecewise constant on the cells, and zero beyond the zone."""
    from ..model.grid import node_cell_edges

    edges = node_cell_edges(x)
    lo, hi = edges[:-1][None, :] - x[:, None], edges[1:][None, :] - x[:, None]  # (i, m) relative
    if b > 0.0:
        lo, hi = np.maximum(lo, 0.0), np.maximum(hi, 0.0)
    else:
        lo, hi = np.minimum(lo, 0.0), np.minimum(hi, 0.0)
    return np.abs(np.expm1(-hi / b) - np.expm1(-lo / b))


#: Rows of F formed at once by :func:`apply_upstream_filter` (dense within a band, one carried
#: row between bands).
FILTER_BAND = 32


def apply_upstream_filter(x: np.ndarray, b: float, values: np.ndarray) -> np.ndarray:
    """F @ ``values`` for F = :func:`upstream_filter` (x, b) [same units as ``values``, shape (n, c)],
    without forming F: beyond a node's own cell F is separable, F[i, m] = exp(-(x_r - x_i)/b) F[r, m]
    for every node r between i and m (b > 0: m > r >= i; the exponential density is memoryless), so
    the rows are taken in bands of :data:`FILTER_BAND` from the upstream end, each band's own
    (band x band) block of F dense and the rest carried in as one row: O(n^2 c) work against the
    dense product's O(n^3). b < 0 is the mirror image (x -> -x reversed, b -> -b)."""
    x = np.asarray(x, dtype=float)
    values = np.asarray(values, dtype=float)
    if x.size <= 4 * FILTER_BAND:  # a few bands: the dense product is as cheap (and the old one exactly)
        return upstream_filter(x, b) @ values
    if b < 0.0:
        return apply_upstream_filter(-x[::-1], -b, values[::-1])[::-1]
    from ..model.grid import node_cell_edges

    edges = node_cell_edges(x)
    n = x.size
    out = np.empty_like(values)
    carry = np.zeros(values.shape[1:])  # sum_{m >= end} F[end - 1, m] values[m]
    end = n
    while end > 0:
        start = max(0, end - FILTER_BAND)
        rows = np.arange(max(0, start - 1), end)  # the band and the row above it (the next carry)
        lo = np.maximum(edges[start:end][None, :] - x[rows, None], 0.0)
        hi = np.maximum(edges[start + 1 : end + 1][None, :] - x[rows, None], 0.0)
        block = np.abs(np.expm1(-hi / b) - np.expm1(-lo / b))  # F[rows, start:end]
        part = block @ values[start:end] + np.exp(-(x[end - 1] - x[rows]) / b)[:, None] * carry
        out[start:end] = part[rows.size - (end - start) :]
        carry = part[0]
        end = start
    return out


def body_compliance(
    elastic: Compliance,
    grid: ContactGrid,
    model: Viscoelastic,
    thickness: float,
    speed: float,
    direction: int,
    normal_only: bool = False,
) -> Compliance:
    """The viscoelastic layer's compliance [length/stress] on ``grid`` from its elastic BEM layer
    ``elastic`` (built with E = E_g, the body's ``young``) [length/stress]: ``thickness`` b [length],
    ``speed`` |V| [length/time], ``direction`` sgn(V). ``normal_only``: the history on S_nn alone,
    the other three blocks the relaxed layer's (J_r K_BEM), for a frictionless normal solve that
    never reads them (the a-estimate levels: a third of the work).

    J_r K_BEM + sum_i c_i (C_i[K] - K) with C_i[K] - K = (C_i[K_F] - K_F) + (C_i[E] - E): the
    first from :func:`history_offsets`, the second the BEM's own departure E = K_BEM - K_F from
    the Fourier layer K_F (its element-level discretisation, the truncated layer) convolved on
    the nodes by :func:`upstream_filter`. K_F is :func:`history_offsets` at |b| = :data:`FAST`
    (C_b[K_F] -> 0), so both limits are exact: b_i -> 0 the relaxed BEM layer, |b_i| -> inf
    J_g K_BEM. The filter is the only approximation in between (E is known at the nodes only)."""
    blocks, out, terms = relaxed_body(elastic, model, speed, direction)
    if not terms:
        return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)
    fast = math.copysign(FAST * 2.0 * grid.half_width, terms[0][1])
    kinds = (0,) if normal_only else (0, 1, 2)  # the Fourier blocks nn, tt, nt
    targets = (0,) if normal_only else (0, 1, 2, 2)  # the output blocks' Fourier block: S_tn takes nt's
    offsets_all = history_offsets(grid, thickness, model.poisson, (fast, *(b for _, b in terms)), kinds)
    minus_f = [_toeplitz_gather(grid, offsets_all[0, k]) for k in range(len(kinds))]  # -K_F, unit modulus
    n = grid.size
    stacked = np.empty((n, len(targets) * n))  # the departures E_g K_BEM - K_F side by side: one filter
    for k, f in enumerate(targets):
        np.add(model.glassy_young * blocks[k], minus_f[f], out=stacked[:, k * n : (k + 1) * n])
    for (c, b), offsets in zip(terms, offsets_all[1:], strict=True):
        filtered = apply_upstream_filter(np.asarray(elastic.x, dtype=float), b, stacked)
        filtered -= stacked
        history = [_toeplitz_gather(grid, offsets[block]) for block in range(len(kinds))]
        for k, block in enumerate(targets):
            term = history[block] + filtered[:, k * n : (k + 1) * n]
            term *= c
            out[k] += term
    return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)


def relaxed_body(
    elastic: Compliance, model: Viscoelastic, speed: float, direction: int
) -> tuple[list, list, list[tuple[float, float]]]:
    """The slow-rolling part of a viscoelastic BEM body (layer or finite cylinder) built at E = E_g:
    its four blocks [S_nn, S_tt, S_nt, S_tn] [length/stress], those times J_r E_g, and the history terms
    (c_i [1/stress], b_i [length]) that act (none: E_r = E_g, or at rest). Raises ValueError when the
    BEM body lacks its coupling blocks."""
    if elastic.S_nt is None or elastic.S_tn is None:
        raise ValueError("the viscoelastic BEM body carries its coupling blocks")
    factor = model.relaxed / model.glassy  # J_r E_g
    blocks = [elastic.S_nn, elastic.S_tt, elastic.S_nt, elastic.S_tn]
    out = [factor * block for block in blocks]
    terms = [
        (c, b)
        for c, b in zip(model.compliances, history_lengths(model, speed, direction), strict=True)
        if c != 0.0 and b != 0.0
    ]
    return blocks, out, terms
