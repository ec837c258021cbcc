"""The viscoelastic kernels as they were before the fast paths (main cffb703), kept verbatim as
the reference of tests/test_viscoelastic_fast.py: the fast code must give the same blocks to 1e-12."""

# ruff: noqa
from __future__ import annotations

import math

import numpy as np

from rolling_cli.influence import Compliance
from rolling_cli.influence.halfplane import _length_scale, _toeplitz_gather, log_offsets, sign_offsets
from rolling_cli.influence.viscoelastic import history_lengths
from rolling_cli.model.grid import ContactGrid
from rolling_cli.model.viscoelastic import Material, Viscoelastic
from rolling_cli.references import layer_fourier

EULER_GAMMA = 0.5772156649015329
SERIES_BELOW = 0.5
ASYMPTOTIC_ABOVE = 40.0
_PHASES = 1 << 21


def phi(a) -> np.ndarray:
    """Phi(a) = ln|a| + gamma - e^a Ei(-a) [-], Phi(0) = 0; continuous, ~ -a (ln|a| + gamma - 1) near 0,
    ~ ln|a| + gamma + 1/a for large |a|."""
    from scipy.special import expi

    a = np.asarray(a, dtype=float)
    out = np.empty_like(a)
    small = np.abs(a) < SERIES_BELOW
    large = np.abs(a) > ASYMPTOTIC_ABOVE
    middle = ~(small | large)
    if middle.any():
        am = a[middle]
        out[middle] = np.log(np.abs(am)) + EULER_GAMMA - np.exp(am) * expi(-am)
    if small.any():
        # Ei(-a) = gamma + ln|a| + S(a), S = sum_k (-a)^k / (k k!):
        # Phi = -(e^a - 1)(ln|a| + gamma) - e^a S(a).
        a_s = a[small]
        term = np.ones_like(a_s)
        series = np.zeros_like(a_s)
        for k in range(1, 25):
            term = term * (-a_s) / k
            series += term / k
        with np.errstate(divide="ignore", invalid="ignore"):
            log_part = np.where(
                a_s == 0.0, 0.0, np.expm1(a_s) * (np.log(np.abs(np.where(a_s == 0.0, 1.0, a_s))) + EULER_GAMMA)
            )
        out[small] = -log_part - np.exp(a_s) * series
    if large.any():
        # -e^a Ei(-a) ~ sum_k (-1)^k k! / a^(k+1), the same series for either sign of a.
        a_l = a[large]
        term = 1.0 / a_l
        tail = term.copy()
        for k in range(1, 30):
            term = term * (-k) / a_l
            tail += term
        out[large] = np.log(np.abs(a_l)) + EULER_GAMMA + tail
    return out


def _g(u: np.ndarray) -> np.ndarray:
    """G(u) = u ln|u| - u [length], G(0) = 0."""
    absu = np.abs(u)
    return np.where(absu > 0.0, u * np.log(np.where(absu > 0.0, absu, 1.0)), 0.0) - u


def log_element(y, h: float, length_scale: float, b: float = 0.0) -> np.ndarray:
    """C_b[E](y): int over a unit-traction element of length h [length] at offset y [length] of
    ln(|x - s| / length_scale), averaged over the history with the length b [length] (0: elastic)."""
    y = np.asarray(y, dtype=float)
    out = _g(y + 0.5 * h) - _g(y - 0.5 * h) - h * math.log(length_scale)
    if b != 0.0:
        out = out + b * (phi((y + 0.5 * h) / b) - phi((y - 0.5 * h) / b))
    return out


def sign_element(y, h: float, b: float = 0.0) -> np.ndarray:
    """C_b[S](y): int over the element of sgn(x - s) [length], history-averaged with the length b [length]."""
    y = np.asarray(y, dtype=float)
    out = np.abs(y + 0.5 * h) - np.abs(y - 0.5 * h)
    if b != 0.0:
        hi = np.minimum((y + 0.5 * h) / b, 0.0)
        lo = np.minimum((y - 0.5 * h) / b, 0.0)
        out = out + 2.0 * abs(b) * (np.expm1(hi) - np.expm1(lo))
    return out


def body_offsets(grid: ContactGrid, model: Material, speed: float, direction: int) -> tuple[np.ndarray, np.ndarray]:
    """(direct, cross) element-offset blocks [length/stress] of one half-plane body, shape
    (2 N_e - 1, m, m) (m nodes per element; indexed as :func:`~.halfplane.log_offsets`): the response
    at node a of element e + o to a unit traction at node k of element e.

    An elastic ``model`` (no retardation terms) gives the elastic kernels over its E; a viscoelastic one
    is J-weighted.
    Constant elements use the closed forms :func:`log_element` and :func:`sign_element`, quadratic
    ones :func:`quadratic_offsets`.
    """
    if not grid.uniform:
        raise ValueError("the viscoelastic kernel needs a uniform grid")
    scale = _length_scale(grid)
    if grid.order == 0:
        ne, h = grid.elements, grid.element_length
        y = np.arange(-(ne - 1), ne) * h

        def kernels(b: float) -> tuple[np.ndarray, np.ndarray]:
            return log_element(y, h, scale, b)[:, None, None], sign_element(y, h, b)[:, None, None]
    else:
        from rolling_cli.influence.halfplane import log_offsets, sign_offsets

        def kernels(b: float) -> tuple[np.ndarray, np.ndarray]:
            if b == 0.0:
                return log_offsets(grid, scale), sign_offsets(grid)
            return quadratic_offsets(grid, b, scale)

    log_k, sign_k = kernels(0.0)
    if model.elastic:
        log_k, sign_k, nu = log_k / model.young, sign_k / model.young, model.poisson
    else:
        log_k, sign_k, nu = model.glassy * log_k, model.glassy * sign_k, model.poisson
        for c, b in zip(model.compliances, history_lengths(model, speed, direction), strict=True):
            log_b, sign_b = kernels(b)
            log_k = log_k + c * log_b
            sign_k = sign_k + c * sign_b
    return 2.0 * (1.0 - nu**2) / np.pi * log_k, 0.5 * (1.0 - 2.0 * nu) * (1.0 + nu) * sign_k


def _phi_series() -> tuple[np.ndarray, np.ndarray]:
    """(p_n, q_n), n = 1..:data:`PHI_TERMS`: Phi(a) = sum_n (p_n ln|a| + q_n) a^n near 0, from
    Phi = -(e^a - 1)(ln|a| + gamma) - e^a S(a), S(a) = sum_k (-a)^k / (k k!)."""
    n = np.arange(1, PHI_TERMS + 1)
    fact = np.array([math.factorial(int(k)) for k in range(PHI_TERMS + 1)], dtype=float)
    p = -1.0 / fact[n]
    q = -EULER_GAMMA / fact[n]
    for i, order in enumerate(n):
        k = np.arange(1, order + 1)
        q[i] -= float(np.sum((-1.0) ** k / (k * fact[k] * fact[order - k])))
    return p, q


PHI_TERMS = 25
_PHI_P, _PHI_Q = _phi_series()


def psi_moments(a, top: int = 2) -> np.ndarray:
    """Psi_j(a) = int_0^a t^j Phi(t) dt [-], j = 0..top, shape a.shape + (top + 1,): the power series
    for |a| < 1/2, else the recursion Psi_j = a^j Phi - j Psi_(j-1) + a^(j+1) ((ln|a| + gamma)/(j + 1)
    - 1/(j + 1)^2) (by parts with Phi' = Phi - ln|a| - gamma), which cancels only near 0."""
    a = np.asarray(a, dtype=float)
    out = np.zeros(a.shape + (top + 1,))
    small = np.abs(a) < SERIES_BELOW
    if small.any():
        s = a[small]
        log = np.log(np.abs(np.where(s == 0.0, 1.0, s)))
        for j in range(top + 1):
            total = np.zeros_like(s)
            for i in range(PHI_TERMS):
                m = i + 1 + j + 1  # power of a after integrating t^(n + j), n = i + 1
                total += (_PHI_P[i] * (log / m - 1.0 / m**2) + _PHI_Q[i] / m) * s**m
            out[small, j] = total
    big = ~small
    if big.any():
        b = a[big]
        f = phi(b)
        log = np.log(np.abs(b))
        prev = np.zeros_like(b)
        for j in range(top + 1):
            prev = b**j * f - j * prev + b ** (j + 1) * ((log + EULER_GAMMA) / (j + 1) - 1.0 / (j + 1) ** 2)
            out[big, j] = prev
    return out


_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)
_TAU_BREAKS = np.array([0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 60.0])


def phi_moments(c, beta: float) -> np.ndarray:
    """M_m(c) = int_{-1}^{1} xi^m Phi((c - xi) / beta) d xi [-], m = 0, 1, 2, for local coordinates c
    (shape c.shape + (3,)); beta = b / (half the element length). Near the element (|c| <= 2) by
    the antiderivatives (:func:`psi_moments`): M_m = beta sum_j C(m, j) c^(m-j) (-beta)^j
    [Psi_j((c + 1)/beta) - Psi_j((c - 1)/beta)]; farther by 12-point Gauss-Legendre on the integrand,
    analytic on the element (its branch point xi = c lies outside the Bernstein ellipse of parameter
    3.7: error < 1e-14, as :mod:`rolling_cli.model.kernels`)."""
    c = np.asarray(c, dtype=float)
    out = np.empty(c.shape + (3,))
    near = np.abs(c) <= 2.0
    if near.any():
        cn = c[near]
        upper = psi_moments((cn + 1.0) / beta)
        lower = psi_moments((cn - 1.0) / beta)
        diff = upper - lower
        for m in range(3):
            total = np.zeros_like(cn)
            for j in range(m + 1):
                total += math.comb(m, j) * cn ** (m - j) * (-beta) ** j * diff[:, j]
            out[near, m] = beta * total
    far = ~near
    if far.any():
        cf = c[far]
        values = phi((cf[:, None] - _GL_X[None, :]) / beta)  # (points, gauss)
        for m in range(3):
            out[far, m] = values @ (_GL_W * _GL_X**m)
    return out


def exp_moments(c, beta: float) -> np.ndarray:
    """X_m(c) = int xi^m exp((c - xi) / beta) d xi over the part of [-1, 1] where (c - xi) / beta < 0
    (upstream of the target) [-], m = 0, 1, 2, shape c.shape + (3,). With tau = (xi - c) / beta >= 0,
    X_m = |beta| int (c + beta tau)^m e^-tau d tau, by 12-point Gauss-Legendre on the panels between
    :data:`_TAU_BREAKS` (each panel's integrand is a polynomial times e^-tau: error < 1e-13)."""
    c = np.asarray(c, dtype=float)
    t1, t2 = (-1.0 - c) / beta, (1.0 - c) / beta
    lo = np.maximum(0.0, np.minimum(t1, t2))
    hi = np.maximum(0.0, np.maximum(t1, t2))
    out = np.zeros(c.shape + (3,))
    for left, right in zip(_TAU_BREAKS[:-1], _TAU_BREAKS[1:], strict=True):
        a = np.clip(left, lo, hi)
        b = np.clip(right, lo, hi)
        half = 0.5 * (b - a)
        tau = (0.5 * (a + b))[..., None] + half[..., None] * _GL_X  # (..., gauss)
        xi = c[..., None] + beta * tau
        weight = half[..., None] * _GL_W * np.exp(-tau)
        for m in range(3):
            out[..., m] += np.sum(weight * xi**m, axis=-1)
    return abs(beta) * out


def quadratic_offsets(grid: ContactGrid, b: float, length_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(C_b[log], C_b[sign]) element-offset blocks of a uniform quadratic-element grid, shape
    (2 N_e - 1, 3, 3) [length] (indexed as :func:`~.halfplane.log_offsets`): for shape function
    N_k, with s = centre + h xi (h half the element) and beta = b / h,

        C_b[int N_k ln(|x - s|/L) ds] = h [sum_m A_km M_m(c) + (ln|b| - gamma - ln L) int N_k],
        C_b[int N_k sgn(x - s) ds]    = h sum_m A_km [G_m(c) + 2 sgn(b) X_m(c)],

    since C_b[ln|u|] = Phi(u/b) + ln|b| - gamma and C_b[sgn u] = sgn u - 2 sgn(u) e^(u/b) for u/b < 0
    (M: :func:`phi_moments`, X: :func:`exp_moments`, G: :func:`~rolling_cli.model.kernels.sign_moments`)."""
    from rolling_cli.model.grid import shape_coefficients, shape_integrals
    from rolling_cli.model.kernels import sign_moments
    from rolling_cli.influence.halfplane import _local_coordinates

    half = 0.5 * grid.element_length
    beta = b / half
    c = _local_coordinates(grid)  # (o, a)
    coeff = shape_coefficients(grid.order)
    constant = math.log(abs(b)) - EULER_GAMMA - math.log(length_scale)
    log_k = half * (np.einsum("oam,km->oak", phi_moments(c, beta), coeff) + constant * shape_integrals(grid.order))
    signs = sign_moments(c)[..., :3] + 2.0 * math.copysign(1.0, b) * exp_moments(c, beta)
    sign_k = half * np.einsum("oam,km->oak", signs, coeff)
    return log_k, sign_k


def fourier_offsets(grid: ContactGrid, thickness: float, poisson: float, lengths) -> np.ndarray:
    """F^-1[R~ (i q b / (1 - i q b)) N~_k](y_oa) per element offset for each history length b in
    ``lengths`` [length], shape (b, 3 blocks nn, tt, nt, 2 N_e - 1, 3, 3) [length^2, at unit
    modulus]: (1/pi) Re int_0^inf ... exp(i q y) dq, y the target node's offset from the source
    element's centre (R_nt = -i g_R).

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
    columns = np.concatenate(
        [
            (w * (1j * q * b / (1.0 - 1j * q * b)) * r)[:, None] * shapes
            for b in lengths
            for r in (r_nn, r_tt, -1j * g_r)
        ],
        axis=1,
    )
    even = np.zeros((top + 1, columns.shape[1]))  # Re(z^j G) = even -+ odd for +-j
    odd = np.zeros_like(even)
    chunk = max(1, _PHASES // (top + 1))  # wavenumbers per block of phases (bounds the temporary)
    for lo in range(0, q.size, chunk):
        part = slice(lo, lo + chunk)
        powers = np.empty((top + 1, q[part].size), dtype=complex)
        powers[0] = 1.0
        powers[1:] = np.exp(1j * q[part] * step)[None, :]
        np.cumprod(powers, axis=0, out=powers)
        even += powers.real @ columns[part].real
        odd += powers.imag @ columns[part].imag
    even /= math.pi
    odd /= math.pi
    ne = grid.elements
    j = 3 * np.arange(-(ne - 1), ne)[:, None] + np.arange(-1, 2)[None, :]  # (o, a)
    out = even[np.abs(j)] - np.sign(j)[..., None] * odd[np.abs(j)]  # (o, a, b 3 3)
    return out.reshape(2 * ne - 1, 3, len(lengths), 3, 3).transpose(2, 3, 0, 1, 4)  # (b, block, o, a, k)


def history_offsets(grid: ContactGrid, thickness: float, poisson: float, lengths) -> np.ndarray:
    """(C_b[K] - K) of the unit-modulus layer per element offset for each history length b in
    ``lengths`` [length], shape (b, 3 blocks nn, tt, nt, 2 N_e - 1, 3, 3) [length^2]: the
    half-plane's closed form plus the remainder's Fourier part."""
    if grid.order != 2 or not grid.uniform:
        raise ValueError("the viscoelastic layer needs a uniform grid of quadratic elements")
    scale = _length_scale(grid)
    elastic_log, elastic_sign = log_offsets(grid, scale), sign_offsets(grid)
    out = fourier_offsets(grid, thickness, poisson, lengths)
    for n, b in enumerate(lengths):
        log_b, sign_b = _halfplane_history(grid, float(b), scale)
        direct = 2.0 * (1.0 - poisson**2) / math.pi * (log_b - elastic_log)
        out[n] += np.stack([direct, -direct, 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson) * (sign_b - elastic_sign)])
    return out


FAST = 1e12
HUGE = 1e10


def _halfplane_history(grid: ContactGrid, b: float, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(C_b[log], C_b[sign]) element offsets of :func:`.viscoelastic.quadratic_offsets` [length]; for
    |b| > HUGE zone widths their limits: C_b[ln(|u|/L)] -> ln|b| - gamma - ln L and C_b[sgn u] ->
    sgn(b), times the shape integrals (the omitted Phi(u/b) ~ |u/b| ln|b/u| < 3e-9 of them)."""
    if abs(b) <= HUGE * 2.0 * grid.half_width:
        return quadratic_offsets(grid, b, scale)
    from rolling_cli.model.grid import shape_integrals

    half = 0.5 * grid.element_length
    integrals = np.broadcast_to(half * shape_integrals(2), (2 * grid.elements - 1, 3, 3))
    constant = math.log(abs(b)) - EULER_GAMMA - math.log(scale)
    return constant * integrals, math.copysign(1.0, b) * integrals


def upstream_filter(x: np.ndarray, b: float) -> np.ndarray:
    """F[i, m] [-]: the weight of node m's cell in C_b at node i, int over the cell of the upstream
    density exp(-(s - x_i)/b) / |b| (s on the side of x_i that b points to), for node positions x
    [length] (cells of :func:`~rolling_cli.model.grid.node_cell_edges`): C_b of a function known
    only at the nodes, taken piecewise constant on the cells, and zero beyond the zone."""
    from rolling_cli.model.grid import node_cell_edges

    edges = node_cell_edges(x)
    lo, hi = edges[:-1][None, :] - x[:, None], edges[1:][None, :] - x[:, None]  # (i, m) relative
    if b > 0.0:
        lo, hi = np.maximum(lo, 0.0), np.maximum(hi, 0.0)
    else:
        lo, hi = np.minimum(lo, 0.0), np.minimum(hi, 0.0)
    return np.abs(np.expm1(-hi / b) - np.expm1(-lo / b))


def body_compliance(
    elastic: Compliance,
    grid: ContactGrid,
    model: Viscoelastic,
    thickness: float,
    speed: float,
    direction: int,
) -> Compliance:
    """The viscoelastic layer's compliance [length/stress] on ``grid`` from its elastic BEM layer
    ``elastic`` (built with E = E_g, the body's ``young``) [length/stress]: ``thickness`` b [length],
    ``speed`` |V| [length/time], ``direction`` sgn(V).

    J_r K_BEM + sum_i c_i (C_i[K] - K) with C_i[K] - K = (C_i[K_F] - K_F) + (C_i[E] - E): the
    first from :func:`history_offsets`, the second the BEM's own departure E = K_BEM - K_F from
    the Fourier layer K_F (its element-level discretisation, the truncated layer) convolved on
    the nodes by :func:`upstream_filter`. K_F is :func:`history_offsets` at |b| = :data:`FAST`
    (C_b[K_F] -> 0), so both limits are exact: b_i -> 0 the relaxed BEM layer, |b_i| -> inf
    J_g K_BEM. The filter is the only approximation in between (E is known at the nodes only)."""
    if elastic.S_nt is None or elastic.S_tn is None:
        raise ValueError("the BEM layer carries its coupling blocks")
    factor = model.relaxed / model.glassy  # J_r E_g
    blocks = [elastic.S_nn, elastic.S_tt, elastic.S_nt, elastic.S_tn]
    out = [factor * block for block in blocks]
    terms = [
        (c, b)
        for c, b in zip(model.compliances, history_lengths(model, speed, direction), strict=True)
        if c != 0.0 and b != 0.0  # no history: E_r = E_g, or at rest
    ]
    if not terms:
        return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)
    fast = math.copysign(FAST * 2.0 * grid.half_width, terms[0][1])
    offsets_all = history_offsets(grid, thickness, model.poisson, (fast, *(b for _, b in terms)))
    layer_f = [-_toeplitz_gather(grid, offsets_all[0, k]) for k in (0, 1, 2, 2)]  # K_F, unit modulus
    departure = [model.glassy_young * block - f for block, f in zip(blocks, layer_f, strict=True)]
    n = grid.size
    stacked = np.concatenate(departure, axis=1)  # (n, 4n): one product per term
    for (c, b), offsets in zip(terms, offsets_all[1:], strict=True):
        filtered = upstream_filter(np.asarray(elastic.x, dtype=float), b) @ stacked - stacked
        history = [_toeplitz_gather(grid, offsets[block]) for block in (0, 1, 2)]
        for k, block in enumerate((0, 1, 2, 2)):
            out[k] = out[k] + c * (history[block] + filtered[:, k * n : (k + 1) * n])
    return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)
