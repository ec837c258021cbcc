"""Closed-form steady-rolling influence of viscoelastic half-planes (constant and quadratic elements).

A body with creep compliance J(t) = J_g + sum_i c_i (1 - exp(-t/lambda_i))
(:mod:`rolling_cli.model.viscoelastic`) and constant nu rolls at speed |V|:
the material moves through the contact towards sgn(V), so the point now at x
was at x - sgn(V) |V| t a time t ago (Kalker 1990, App. D; Hunter 1961).
Boltzmann superposition, integrated by parts, gives its surface displacement
as the elastic one (unit modulus, kernel k(x)) weighted by J over the load
history met upstream:

    u(x) = J_g k[p](x) + sum_i c_i C_i[k[p]](x),
    C_i[f](x) = int_0^inf exp(-s) f(x + b_i s) ds,   b_i = -sgn(V) |V| lambda_i,

so C_i averages f over the upstream length ell_i = |V| lambda_i. b_i -> 0
gives the relaxed elastic body (J_g + sum c_i = 1/E_r), |b_i| -> inf the
glassy one (C_i[f] tends to a rigid constant).

For a unit traction on an element of length h centred at offset y from the
target node, the elastic element integrals of the two half-plane kernels are
(G(u) = u ln|u| - u, L the log kernel's reference length)

    log:  E(y) = G(y + h/2) - G(y - h/2) - h ln L
    sign: S(y) = |y + h/2| - |y - h/2|

and C commutes with the x-derivative, with C[f] = f + b C[f'] (by parts), so

    C[E](y) = E(y) + b [Phi((y + h/2)/b) - Phi((y - h/2)/b)],
    Phi(a)  = ln|a| + gamma - e^a Ei(-a)          (Ei the exponential integral, principal value),
    C[S](y) = S(y) + 2|b| [expm1(min(a+, 0)) - expm1(min(a-, 0))],   a+- = (y +- h/2)/b,

exact (constants that cancel between the element's ends are dropped). Phi is
evaluated by its power series for |a| < 1/2, by scipy's ``expi`` up to
|a| = 40 and by the asymptotic series beyond, so neither limit loses digits.
Quadratic elements need the moments int xi^m Phi and int xi^m e^(...) over the
element (:func:`quadratic_offsets`): from the antiderivatives of t^j Phi(t)
near the element, by Gauss-Legendre farther.

The blocks keep the half-plane's structure: Toeplitz on a uniform grid (now not
symmetric: the history runs one way), S_tt = -S_nn and S_tn = S_nt, per body,
with the direct factor 2 (1 - nu^2)/pi and the cross factor (1 - 2 nu)(1 + nu)/2
times the J-weighted kernels. Each body is convolved with its own J, so the
normal-tangential coupling (beta) of dissimilar or differently relaxing bodies
varies along the history exactly as the materials do (with nu constant).
"""

from __future__ import annotations

import math

import numpy as np

from ..model.grid import ContactGrid
from ..model.viscoelastic import Material, Viscoelastic
from . import Block, Compliance
from .halfplane import _length_scale, _toeplitz_gather, use_operators

EULER_GAMMA = 0.5772156649015329

#: |a| below which Phi is summed by its power series, and above which by its asymptotic series.
SERIES_BELOW = 0.5
ASYMPTOTIC_ABOVE = 40.0


def _powers(a: np.ndarray, count: int) -> np.ndarray:
    """a^1 .. a^count [-], shape a.shape + (count,), by a running product."""
    return np.cumprod(np.broadcast_to(a[..., None], a.shape + (count,)), axis=-1)


#: S(a) = sum_k (-a)^k / (k k!) = sum_k _SERIES_S[k - 1] a^k, k = 1..24 (Phi's power series).
_SERIES_S = np.array([(-1.0) ** k / (k * math.factorial(k)) for k in range(1, 25)])
#: -e^a Ei(-a) ~ sum_k (-1)^k k! / a^(k+1) = sum_k _TAIL[k] a^-(k+1), k = 0..29 (the asymptotic series).
_TAIL = np.array([(-1.0) ** k * math.factorial(k) for k in range(30)])


def phi(a) -> np.ndarray:
    """Phi(a) = ln|a| + gamma - e^a Ei(-a) [-], Phi(0) = 0; continuous, ~ -a (ln|a| + gamma - 1) near 0,
    ~ ln|a| + gamma + 1/a for large |a|. The two series as products with their coefficient vectors."""
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
        series = _powers(a_s, _SERIES_S.size) @ _SERIES_S
        with np.errstate(divide="ignore", invalid="ignore"):
            log_part = np.where(
                a_s == 0.0, 0.0, np.expm1(a_s) * (np.log(np.abs(np.where(a_s == 0.0, 1.0, a_s))) + EULER_GAMMA)
            )
        out[small] = -log_part - np.exp(a_s) * series
    if large.any():
        # -e^a Ei(-a) ~ sum_k (-1)^k k! / a^(k+1), the same series for either sign of a.
        a_l = a[large]
        out[large] = np.log(np.abs(a_l)) + EULER_GAMMA + _powers(1.0 / a_l, _TAIL.size) @ _TAIL
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


def _psi_series(top: int) -> tuple[np.ndarray, np.ndarray]:
    """(A, B), shape (PHI_TERMS + top + 1, top + 1): the power series of :func:`psi_moments`,
    Psi_j(a) = sum_m (A[m - 1, j] ln|a| + B[m - 1, j]) a^m, from Phi's (p_n, q_n): the term
    a^n of Phi gives m = n + j + 1, A = p_n / m, B = q_n / m - p_n / m^2."""
    a = np.zeros((PHI_TERMS + top + 1, top + 1))
    b = np.zeros_like(a)
    for j in range(top + 1):
        m = np.arange(PHI_TERMS) + j + 2
        a[m - 1, j] = _PHI_P / m
        b[m - 1, j] = _PHI_Q / m - _PHI_P / m**2
    return a, b


def psi_moments(a, top: int = 2) -> np.ndarray:
    """Psi_j(a) = int_0^a t^j Phi(t) dt [-], j = 0..top, shape a.shape + (top + 1,): the power series
    for |a| < 1/2 (:func:`_psi_series`), else the recursion Psi_j = a^j Phi - j Psi_(j-1) + a^(j+1)
    ((ln|a| + gamma)/(j + 1) - 1/(j + 1)^2) (by parts with Phi' = Phi - ln|a| - gamma), which cancels
    only near 0."""
    a = np.asarray(a, dtype=float)
    out = np.zeros(a.shape + (top + 1,))
    small = np.abs(a) < SERIES_BELOW
    if small.any():
        s = a[small]
        log = np.log(np.abs(np.where(s == 0.0, 1.0, s)))
        coeff_log, coeff = _psi_series(top)
        powers = _powers(s, coeff.shape[0])
        out[small] = log[:, None] * (powers @ coeff_log) + powers @ coeff
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


def _rule(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes on [-1, 1] and the moment weights w_g xi_g^m, shape (gauss, 3)."""
    x, w = np.polynomial.legendre.leggauss(points)
    return x, w[:, None] * x[:, None] ** np.arange(3)


#: (upper |c|, rule) of :func:`phi_moments` beyond the element: n points where rho^(-2n) < 1e-17
#: (rho >= 11.9 beyond |c| = 6: 8 points; >= 40 beyond 20: 6; >= 200 beyond 100: 4).
_GL_TIERS = ((6.0, _rule(12)), (20.0, _rule(8)), (100.0, _rule(6)), (math.inf, _rule(4)))
#: Breakpoints of the Gauss-Legendre panels of the exponential moments (e^-60 ~ 1e-26 beyond).
_TAU_BREAKS = np.array([0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 60.0])


def phi_moments(c, beta: float) -> np.ndarray:
    """M_m(c) = int_{-1}^{1} xi^m Phi((c - xi) / beta) d xi [-], m = 0, 1, 2, for local coordinates c
    (shape c.shape + (3,)); beta = b / (half the element length). Near the element (|c| <= 2) by
    the antiderivatives (:func:`psi_moments`): M_m = beta sum_j C(m, j) c^(m-j) (-beta)^j
    [Psi_j((c + 1)/beta) - Psi_j((c - 1)/beta)]; farther by Gauss-Legendre on the integrand,
    analytic on the element: its branch point xi = c lies outside the Bernstein ellipse of parameter
    rho = |c| + sqrt(c^2 - 1), so n points err by ~rho^(-2n): 12 points for 2 < |c| < 6 (rho 3.7:
    < 1e-14, as :mod:`rolling_cli.model.kernels`), fewer farther (:data:`_GL_TIERS`, each < 1e-17)."""
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
        distance = np.abs(c)
        inner = 2.0
        for outer, (x, moments) in _GL_TIERS:
            tier = (distance > inner) & (distance <= outer)
            inner = outer
            if tier.any():
                out[tier] = phi((c[tier][:, None] - x[None, :]) / beta) @ moments  # (points, gauss) @ (gauss, m)
    return out


def exp_moments(c, beta: float) -> np.ndarray:
    """X_m(c) = int xi^m exp((c - xi) / beta) d xi over the part of [-1, 1] where (c - xi) / beta < 0
    (upstream of the target) [-], m = 0, 1, 2, shape c.shape + (3,). With tau = (xi - c) / beta >= 0,
    X_m = |beta| int (c + beta tau)^m e^-tau d tau, by 12-point Gauss-Legendre on the panels between
    :data:`_TAU_BREAKS` (each panel's integrand is a polynomial times e^-tau: error < 1e-13). The
    element spans 2 / |beta| in tau, so only the panels it meets are integrated (one or two for a
    history much longer than the elements), all points at once."""
    c = np.asarray(c, dtype=float)
    t1, t2 = (-1.0 - c) / beta, (1.0 - c) / beta
    lo = np.maximum(0.0, np.minimum(t1, t2))[..., None]
    hi = np.maximum(0.0, np.maximum(t1, t2))[..., None]
    last = _TAU_BREAKS.size - 2
    first = np.clip(np.searchsorted(_TAU_BREAKS, lo, side="right") - 1, 0, last)  # the panel holding lo
    slots = int(np.max(np.clip(np.searchsorted(_TAU_BREAKS, hi, side="left") - 1, 0, last) - first, initial=0)) + 1
    panel = np.minimum(first + np.arange(slots), last)  # (..., slot); repeats of the last one are empty
    a = np.clip(_TAU_BREAKS[panel], lo, hi)
    b = np.clip(_TAU_BREAKS[panel + 1], lo, hi)
    b = np.where(np.arange(slots) > last - first, a, b)  # a repeated last panel counts once
    half = 0.5 * (b - a)
    tau = (0.5 * (a + b))[..., None] + half[..., None] * _GL_X  # (..., slot, gauss)
    xi = c[..., None, None] + beta * tau
    weight = half[..., None] * _GL_W * np.exp(-tau)
    panels = np.stack([np.sum(weight, axis=-1), np.sum(weight * xi, axis=-1), np.sum(weight * xi * xi, axis=-1)])
    return abs(beta) * np.moveaxis(panels.sum(axis=-1), 0, -1)


def quadratic_offsets(grid: ContactGrid, b: float, length_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """(C_b[log], C_b[sign]) element-offset blocks of a uniform quadratic-element grid, shape
    (2 N_e - 1, 3, 3) [length] (indexed as :func:`~.halfplane.log_offsets`): for shape function
    N_k, with s = centre + h xi (h half the element) and beta = b / h,

        C_b[int N_k ln(|x - s|/L) ds] = h [sum_m A_km M_m(c) + (ln|b| - gamma - ln L) int N_k],
        C_b[int N_k sgn(x - s) ds]    = h sum_m A_km [G_m(c) + 2 sgn(b) X_m(c)],

    since C_b[ln|u|] = Phi(u/b) + ln|b| - gamma and C_b[sgn u] = sgn u - 2 sgn(u) e^(u/b) for u/b < 0
    (M: :func:`phi_moments`, X: :func:`exp_moments`, G: :func:`~rolling_cli.model.kernels.sign_moments`)."""
    from ..model.grid import shape_integrals

    half = 0.5 * grid.element_length
    log_shape, sign_shape = _shape_offsets(grid.elements, b / half)
    constant = math.log(abs(b)) - EULER_GAMMA - math.log(length_scale)
    return half * (log_shape + constant * shape_integrals(grid.order)), half * sign_shape


#: Relative difference of beta = b / h below which :func:`_shape_offsets` reuses an earlier level's
#: blocks (the a-estimate levels of a layer share h = 2 b_layer to a few ulps): the kernels change
#: by ~1e-14 relative, far below the solver's tolerance.
SAME_BETA = 1e-14
#: Entries kept by :func:`_shape_offsets` (the history and the elastic blocks of two levels).
MEMO_ENTRIES = 4
#: Element-offset blocks kept by :func:`_shape_offsets`: (beta, elements, log part, sign part).
_shape_memo: list[tuple[float, int, np.ndarray, np.ndarray]] = []


def _shape_offsets(elements: int, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """The dimensionless parts of :func:`quadratic_offsets`, sum_m A_km M_m(c) and
    sum_m A_km [G_m(c) + 2 sgn(beta) X_m(c)], shape (2 N_e - 1, 3, 3), for N_e = ``elements``;
    memoised on beta (:data:`SAME_BETA`): a coarser level with the same beta takes the middle
    offsets of a finer one's (the offsets are the same integers, so the same numbers)."""
    from ..model.grid import NODE_COORDINATES, shape_coefficients
    from ..model.kernels import sign_moments

    for known, count, log_shape, sign_shape in _shape_memo:
        if count >= elements and abs(known - beta) <= SAME_BETA * abs(beta):
            middle = slice(count - elements, count + elements - 1)
            return log_shape[middle], sign_shape[middle]
    offsets = np.arange(-(elements - 1), elements)
    c = 2.0 * offsets[:, None] + NODE_COORDINATES[2][None, :]  # (o, a), as halfplane._local_coordinates
    coeff = shape_coefficients(2)
    log_shape = np.einsum("oam,km->oak", phi_moments(c, beta), coeff)
    signs = sign_moments(c)[..., :3] + 2.0 * math.copysign(1.0, beta) * exp_moments(c, beta)
    sign_shape = np.einsum("oam,km->oak", signs, coeff)
    _shape_memo.insert(0, (beta, elements, log_shape, sign_shape))
    del _shape_memo[MEMO_ENTRIES:]
    return log_shape, sign_shape


def elastic_shape_offsets(elements: int) -> tuple[np.ndarray, np.ndarray]:
    """The dimensionless parts of :func:`~.halfplane.log_offsets` and :func:`~.halfplane.sign_offsets`
    on quadratic elements, sum_m A_km A_m(c) and sum_m A_km G_m(c), shape (2 N_e - 1, 3, 3), the
    same numbers as theirs; memoised with :func:`_shape_offsets` (as beta = 0)."""
    from ..model.grid import NODE_COORDINATES, shape_coefficients
    from ..model.kernels import log_moments, sign_moments

    for known, count, log_shape, sign_shape in _shape_memo:
        if count >= elements and known == 0.0:
            middle = slice(count - elements, count + elements - 1)
            return log_shape[middle], sign_shape[middle]
    offsets = np.arange(-(elements - 1), elements)
    c = 2.0 * offsets[:, None] + NODE_COORDINATES[2][None, :]
    coeff = shape_coefficients(2)
    log_shape = np.einsum("oam,km->oak", log_moments(c)[..., :3], coeff)
    sign_shape = np.einsum("oam,km->oak", sign_moments(c)[..., :3], coeff)
    _shape_memo.insert(0, (0.0, elements, log_shape, sign_shape))
    del _shape_memo[MEMO_ENTRIES:]
    return log_shape, sign_shape


def clear_memo() -> None:
    """Forget the memoised kernel blocks (:func:`_shape_offsets`; benchmarks time cold builds)."""
    _shape_memo.clear()


def history_lengths(model: Viscoelastic, speed: float, direction: int) -> tuple[float, ...]:
    """b_i = -sgn(V) |V| lambda_i [length]: the signed upstream lengths of the terms."""
    return tuple(-float(direction) * ell for ell in model.lengths(speed))


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
        from .halfplane import log_offsets, sign_offsets

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


def pair_compliance(
    grid: ContactGrid,
    bodies: list[Material | None],
    speed: float,
    direction: int,
    coupling: bool = True,
    operators: bool | None = None,
) -> Compliance:
    """Compliance of a half-plane pair with viscoelastic bodies [length/stress].

    ``bodies``: the materials of A and B, ``None`` for a rigid body (an elastic material has no
    retardation terms). ``speed`` |V| [length/time], ``direction`` sgn(V). Direct blocks add, cross blocks
    subtract (as :func:`rolling_cli.influence.combine`); the blocks are dense, or block-Toeplitz
    operators with the same entries (``operators``; None: :func:`~.halfplane.use_operators`).
    """
    m = grid.nodes_per_element
    direct = np.zeros((2 * grid.elements - 1, m, m))
    cross = np.zeros_like(direct)
    for sign, body in zip((1.0, -1.0), bodies, strict=True):
        if body is None:
            continue
        d, c = body_offsets(grid, body, speed, direction)
        direct += d
        cross += sign * c
    if operators is None:
        operators = use_operators(grid)
    s_nn: Block
    s_nt: Block | None
    s_tt: Block
    if operators:
        from .toeplitz import BlockToeplitz

        s_nn = BlockToeplitz(direct)
        s_nt = BlockToeplitz(cross) if coupling else None
        s_tt = -s_nn
    else:
        s_nn = _toeplitz_gather(grid, direct)
        s_nt = _toeplitz_gather(grid, cross) if coupling else None
        s_tt = np.negative(s_nn)
    return Compliance(x=grid.x, weights=grid.weights, S_nn=s_nn, S_tt=s_tt, S_nt=s_nt, S_tn=s_nt)
