"""Closed-form steady-rolling influence of viscoelastic half-planes (piecewise-constant tractions).

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

from ..grid import ContactGrid
from ..model.viscoelastic import Viscoelastic
from . import Block, Compliance
from .halfplane import _length_scale, _toeplitz_gather, use_operators

EULER_GAMMA = 0.5772156649015329

#: |a| below which Phi is summed by its power series, and above which by its asymptotic series.
SERIES_BELOW = 0.5
ASYMPTOTIC_ABOVE = 40.0


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


def history_lengths(model: Viscoelastic, speed: float, direction: int) -> tuple[float, ...]:
    """b_i = -sgn(V) |V| lambda_i [length]: the signed upstream lengths of the terms."""
    return tuple(-float(direction) * ell for ell in model.lengths(speed))


def body_offsets(
    grid: ContactGrid, model: Viscoelastic | None, young: float, poisson: float, speed: float, direction: int
) -> tuple[np.ndarray, np.ndarray]:
    """(direct, cross) element-offset values [length/stress] of one half-plane body, shape (2 N_e - 1,):
    entry o + N_e - 1 is the response at a node of element e + o to a unit traction on element e.

    ``model`` None is an elastic body of ``young`` [stress]; a viscoelastic one is J-weighted.
    """
    if grid.order != 0 or not grid.uniform:
        raise ValueError("the viscoelastic kernel needs a uniform grid of constant elements")
    ne, h = grid.elements, grid.element_length
    y = np.arange(-(ne - 1), ne) * h
    scale = _length_scale(grid)
    if model is None:
        log_k = log_element(y, h, scale) / young
        sign_k = sign_element(y, h) / young
        nu = poisson
    else:
        log_k = model.glassy * log_element(y, h, scale)
        sign_k = model.glassy * sign_element(y, h)
        for c, b in zip(model.compliances, history_lengths(model, speed, direction), strict=True):
            log_k = log_k + c * log_element(y, h, scale, b)
            sign_k = sign_k + c * sign_element(y, h, b)
        nu = model.poisson
    return 2.0 * (1.0 - nu**2) / np.pi * log_k, 0.5 * (1.0 - 2.0 * nu) * (1.0 + nu) * sign_k


def pair_compliance(
    grid: ContactGrid,
    bodies: list[tuple[Viscoelastic | None, float, float] | None],
    speed: float,
    direction: int,
    coupling: bool = True,
    operators: bool | None = None,
) -> Compliance:
    """Compliance of a half-plane pair with viscoelastic bodies [length/stress].

    ``bodies``: for A and B, ``None`` (rigid) or (model, young, poisson), model None for an elastic
    body. ``speed`` |V| [length/time], ``direction`` sgn(V). Direct blocks add, cross blocks
    subtract (as :func:`rolling_cli.influence.combine`); the blocks are dense, or block-Toeplitz
    operators with the same entries (``operators``; None: :func:`~.halfplane.use_operators`).
    """
    direct = np.zeros(2 * grid.elements - 1)
    cross = np.zeros_like(direct)
    for sign, body in zip((1.0, -1.0), bodies, strict=True):
        if body is None:
            continue
        d, c = body_offsets(grid, body[0], body[1], body[2], speed, direction)
        direct += d
        cross += sign * c
    direct = direct[:, None, None]
    cross = cross[:, None, None]
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
