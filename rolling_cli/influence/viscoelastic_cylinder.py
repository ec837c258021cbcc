"""Steady-rolling compliance of a viscoelastic finite cylinder: an annulus on a rigid shaft or core.

A finite cylinder (:mod:`.bem.cylinder`, :mod:`.finite`) of constant nu and creep
compliance J(t) = J_g + sum_i c_i (1 - exp(-t/lambda_i))
(:mod:`rolling_cli.model.viscoelastic`) turns about its shaft at the surface
speed |V|. Every material point goes round its circle at the same angular
speed, so the load history is along the circumference and periodic (period
L = 2 pi R in the arc length s of the outer circle). As for the half-plane
(:mod:`.viscoelastic`) the surface displacement is the unit-modulus elastic
response K of the annulus weighted by J over the history met upstream,

    u = J_g K[p] + sum_i c_i C_i[K[p]],   C_i[f](s) = int_0^inf exp(-t) f(s + b_i t) dt,

b_i = -sgn(V) |V| lambda_i, now on the periodic f. C_i is diagonal in the
circle's modes exp(i n s / R): C_i multiplies mode n by 1 / (1 - i n b_i / R).
The annulus is rotation-invariant, so its kernel is a Fourier series whose
coefficients K(n) are Michell's mode responses
(:func:`rolling_cli.references.annulus.mode_responses`; :func:`mode_kernels`).
The mean (n = 0) is steady for every material point, so it is always relaxed:
fast rolling is the glassy cylinder plus the relaxed mean mode (a uniform
radial displacement under the mean pressure P / (2 pi R) and a uniform twist
under Q / (2 pi R)), not the elastic cylinder with E_g.

As the layer (:mod:`.viscoelastic_layer`),

    u = J_r K_BEM + sum_i c_i [ (C_i - 1)[K_M] + (F_i - 1)[K_BEM - K_M] ],

K_BEM today's BEM annulus (built with E = E_g, :mod:`.bem.cylinder`), K_M the
exact (Michell) kernel integrated on the element shape functions
(:func:`exact_offsets`) and F_i the node filter of
:func:`.viscoelastic_layer.upstream_filter`, which carries the BEM's own
departure along the history, so that b_i -> 0 is the relaxed BEM cylinder and
|b_i| -> inf J_g K_BEM plus the relaxed mean mode of K_M, exactly.

K_M = (half-plane, periodic) + (remainder R(n) = K(n) - H(n / R)), H the
half-plane's transform: the periodic half-plane kernels are the line's plus
a smooth correction (the log kernel's ln|2 sin(s / 2R)| against ln|s / R|, the
sign kernel's sawtooth against sgn s), integrated by Gauss-Legendre on the
element; the remainder decays like 1/n^2 (the curvature), summed over
:data:`MODES` modes. The history (C_b - 1)[K_M] (:func:`history_offsets`):

* |b| <= :data:`SLOW` R: the line's closed form of
  :func:`.viscoelastic.quadratic_offsets` for the half-plane part (exact as
  b -> 0), the periodic correction's history by Gauss-Legendre in t (it is
  smooth over the |b| t < 0.75 L that count: the rest weighs e^-37), and the
  remainder's modes times i n beta / (1 - i n beta), beta = b / R;
* |b| > :data:`SLOW` R (the history wraps round the circle): the whole
  series K(n) / (1 - i n beta) minus K_M; its terms fall like 1/(beta n^3),
  so the cut costs ~ 1 / (2 pi beta MODES) < 1e-4 of the kernel.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..model.grid import ContactGrid, shape_coefficients
from ..model.viscoelastic import Viscoelastic
from ..references import annulus, layer_fourier
from . import Compliance
from .halfplane import _length_scale, _toeplitz_gather, log_offsets, sign_offsets
from .viscoelastic import quadratic_offsets
from .viscoelastic_layer import relaxed_body, upstream_filter

__all__ = ["mode_kernels", "offsets", "exact_offsets", "history_offsets", "body_compliance"]

#: Modes of the remainder's and the wrapped history's series.
MODES = 1 << 14
#: |b| / R below which the history uses the line's closed form (the periodic images weigh e^-37).
SLOW = 0.125
#: Complex phases formed at once by :func:`mode_offsets` (bounds a temporary to 32 MB).
_PHASES = 1 << 21
_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)
#: Gauss-Legendre points per panel in t of the periodic correction's history (smooth on |b| t ~ R).
_T_X, _T_W = np.polynomial.legendre.leggauss(8)


@functools.lru_cache(maxsize=4)
def mode_kernels(modes: int, radius: float, inner_radius: float, poisson: float) -> np.ndarray:
    """K(n), n = 0 .. ``modes``, shape (modes + 1, 3) complex, columns (nn, tt, nt) [length^2 at unit
    modulus]: the annulus's surface response to p_n, p_t = exp(i n s / R) in the arc frame of
    :mod:`.bem.cylinder` (w into the body, u_t along s; K_tn = K_nt by reciprocity), the kernel of a
    point load being (1/L) sum_n K(n) exp(i n s / R), K(-n) = conj K(n) (memoised, read-only). From
    Michell's modes:
    K_nn = -2 (1 + nu) R M_rr, K_tt = 2 (1 + nu) R M_tt, K_nt = -2i (1 + nu) R M_rt (R / G at E = 1)."""
    ratio = inner_radius / radius
    scale = 2.0 * (1.0 + poisson) * radius
    m = annulus.mode_responses(modes, ratio, poisson)
    radial, torsion = annulus._axisymmetric(ratio, poisson)
    out = np.zeros((modes + 1, 3), dtype=complex)
    out[0] = (-scale * radial, scale * torsion, 0.0)
    out[1:, 0] = -scale * m[:, 0, 0]
    out[1:, 1] = scale * m[:, 1, 1]
    out[1:, 2] = -1j * scale * m[:, 0, 1]
    out.flags.writeable = False  # memoised: every level and speed of a case shares it
    return out


def halfplane_modes(modes: int, radius: float, poisson: float) -> np.ndarray:
    """H(n / R) of the unit-modulus half-plane, n = 0 .. ``modes`` (0 at n = 0: the periodic kernels
    have zero mean), shape (modes + 1, 3), columns (nn, tt, nt) [length^2]."""
    n = np.arange(1, modes + 1, dtype=float)
    out = np.zeros((modes + 1, 3), dtype=complex)
    direct = 2.0 * (1.0 - poisson**2) * radius / n
    out[1:, 0], out[1:, 1] = -direct, direct
    out[1:, 2] = -1j * (1.0 + poisson) * (1.0 - 2.0 * poisson) * radius / n
    return out


def mode_offsets(grid: ContactGrid, radius: float, coefficients: np.ndarray) -> np.ndarray:
    """(1/L) sum_{n = -N}^{N} C(n) N~_k(n / R) exp(i n y / R) per element offset, C(-n) = conj C(n),
    for ``coefficients`` C (N + 1, B) [length^2]: shape (B, 2 N_e - 1, 3, 3) [length^2 per length],
    y the target node's offset from the source element's centre (the phases as the powers of
    exp(i n h / 3R), as :func:`.viscoelastic_layer.fourier_offsets`)."""
    count, blocks = coefficients.shape
    n = np.arange(count, dtype=float)
    shapes = layer_fourier.quadratic_spectra(n / radius, 0.5 * grid.element_length)  # (N + 1, 3)
    weight = np.where(n == 0.0, 1.0, 2.0)
    columns = (weight[:, None, None] * coefficients[:, :, None] * shapes[:, None, :]).reshape(count, 3 * blocks)
    step = grid.element_length / 3.0
    top = 3 * grid.elements - 2
    even = np.zeros((top + 1, columns.shape[1]))
    odd = np.zeros_like(even)
    chunk = max(1, _PHASES // (top + 1))
    for lo in range(0, count, chunk):
        part = slice(lo, lo + chunk)
        powers = np.empty((top + 1, n[part].size), dtype=complex)
        powers[0] = 1.0
        powers[1:] = np.exp(1j * n[part] * step / radius)[None, :]
        np.cumprod(powers, axis=0, out=powers)
        even += powers.real @ columns[part].real
        odd += powers.imag @ columns[part].imag
    ne = grid.elements
    j = 3 * np.arange(-(ne - 1), ne)[:, None] + np.arange(-1, 2)[None, :]  # (o, a)
    out = (even[np.abs(j)] - np.sign(j)[..., None] * odd[np.abs(j)]) / (2.0 * math.pi * radius)
    return out.reshape(2 * ne - 1, 3, blocks, 3).transpose(2, 0, 1, 3)


def _offsets_y(grid: ContactGrid) -> np.ndarray:
    """y[o, a] [length]: target node a of element e + o relative to the centre of element e."""
    ne = grid.elements
    return (3 * np.arange(-(ne - 1), ne)[:, None] + np.arange(-1, 2)[None, :]) * grid.element_length / 3.0


def _periodic_correction(v: np.ndarray, radius: float, poisson: float, scale: float) -> np.ndarray:
    """The periodic half-plane kernels minus the line's at separations v [length] (|v| < 2 pi R),
    (..., 3) for (nn, tt, nt) [length per stress at unit modulus]: kappa [ln(L_ref / R) +
    ln(sin x / x)], x = v / 2R, for nn (tt its negative), and -chi v / (pi R) for nt (the sawtooth),
    kappa = 2 (1 - nu^2) / pi, chi = (1 - 2 nu)(1 + nu) / 2."""
    x = v / (2.0 * radius)
    small = np.abs(x) < 1e-4
    safe = np.where(small, 1.0, x)
    sinc = np.where(small, 1.0 - x * x / 6.0, np.sin(safe) / safe)
    kappa = 2.0 * (1.0 - poisson**2) / math.pi
    chi = 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson)
    direct = kappa * (math.log(scale / radius) + np.log(sinc))
    return np.stack([direct, -direct, -chi * v / (math.pi * radius)], axis=-1)


def _element_correction(y: np.ndarray, grid: ContactGrid, radius: float, poisson: float, scale: float) -> np.ndarray:
    """int N_k(s) (periodic - line)(y - s) ds over an element centred at 0, at offsets ``y`` [length]:
    shape y.shape + (3 blocks, 3 k), by 12-point Gauss-Legendre (the integrand is analytic within
    pi R of the element)."""
    half = 0.5 * grid.element_length
    shapes = (shape_coefficients(2) @ np.vstack([np.ones_like(_GL_X), _GL_X, _GL_X**2])).T  # (g, k)
    values = _periodic_correction(y[..., None] - half * _GL_X, radius, poisson, scale)  # (..., g, blocks)
    return half * np.einsum("...gb,g,gk->...bk", values, _GL_W, shapes)


def _closed_exact(grid: ContactGrid, radius: float, poisson: float) -> np.ndarray:
    """The periodic half-plane part of K_M per element offset: the line's closed forms and the
    periodic correction, shape (3, 2 N_e - 1, 3, 3) [length^2 at unit modulus]."""
    scale = _length_scale(grid)
    kappa = 2.0 * (1.0 - poisson**2) / math.pi
    chi = 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson)
    direct = kappa * log_offsets(grid, scale)
    out = np.stack([direct, -direct, chi * sign_offsets(grid)])
    return out + np.moveaxis(_element_correction(_offsets_y(grid), grid, radius, poisson, scale), 2, 0)


def _closed_slow(grid: ContactGrid, radius: float, poisson: float, b: float) -> np.ndarray:
    """The periodic half-plane part of (C_b - 1)[K_M] for |b| <= SLOW R: the line's closed form and
    the periodic correction's history (Gauss-Legendre panels in t up to 0.75 L / |b| <= 45), shape
    (3, 2 N_e - 1, 3, 3)."""
    scale = _length_scale(grid)
    kappa = 2.0 * (1.0 - poisson**2) / math.pi
    chi = 0.5 * (1.0 - 2.0 * poisson) * (1.0 + poisson)
    log_b, sign_b = quadratic_offsets(grid, b, scale)
    direct = kappa * (log_b - log_offsets(grid, scale))
    out = np.stack([direct, -direct, chi * (sign_b - sign_offsets(grid))])
    top = min(45.0, 1.5 * math.pi * radius / abs(b))
    breaks = np.unique(np.clip([0.0, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, top], 0.0, top))
    lo, hi = breaks[:-1, None], breaks[1:, None]
    t = (0.5 * (lo + hi) + 0.5 * (hi - lo) * _T_X).ravel()
    wt = (0.5 * (hi - lo) * _T_W * np.exp(-0.5 * (lo + hi) - 0.5 * (hi - lo) * _T_X)).ravel()
    y = _offsets_y(grid)
    moved = _element_correction(y[..., None] + b * t, grid, radius, poisson, scale)  # (o, a, t, blocks, k)
    here = _element_correction(y, grid, radius, poisson, scale)  # (o, a, blocks, k)
    return out + np.einsum("oatbk,t->boak", moved, wt) - np.moveaxis(here, 2, 0) * float(np.sum(wt))


def offsets(
    grid: ContactGrid, radius: float, inner_radius: float, poisson: float, lengths, kernels=None
) -> tuple[np.ndarray, np.ndarray]:
    """(K_M, (C_b - 1)[K_M] for each b in ``lengths`` [length]) per element offset, shapes
    (3 blocks nn, tt, nt, 2 N_e - 1, 3, 3) and (b, 3, 2 N_e - 1, 3, 3) [length^2 at unit modulus]
    (module docstring); every mode series in one pass over the phases."""
    _check(grid)
    if kernels is None:
        kernels = mode_kernels(MODES, radius, inner_radius, poisson)
    remainder = kernels - halfplane_modes(kernels.shape[0] - 1, radius, poisson)
    n = np.arange(kernels.shape[0], dtype=float)
    lengths = [float(b) for b in lengths]
    series = [remainder]
    for b in lengths:
        beta = b / radius
        if abs(b) <= SLOW * radius:
            series.append(remainder * (1j * n * beta / (1.0 - 1j * n * beta))[:, None])
        else:
            series.append(kernels / (1.0 - 1j * n * beta)[:, None])
    summed = mode_offsets(grid, radius, np.concatenate(series, axis=1))
    exact = _closed_exact(grid, radius, poisson) + summed[0:3]
    history = []
    for k, b in enumerate(lengths, start=1):
        part = summed[3 * k : 3 * k + 3]
        history.append(part + _closed_slow(grid, radius, poisson, b) if abs(b) <= SLOW * radius else part - exact)
    return exact, np.stack(history) if history else np.zeros((0,) + exact.shape)


def exact_offsets(grid: ContactGrid, radius: float, inner_radius: float, poisson: float, kernels=None) -> np.ndarray:
    """K_M per element offset, shape (3 blocks nn, tt, nt, 2 N_e - 1, 3, 3) [length^2 at unit modulus]:
    the line half-plane's closed forms, the periodic correction and the remainder's modes."""
    return offsets(grid, radius, inner_radius, poisson, (), kernels)[0]


def history_offsets(grid: ContactGrid, radius: float, inner_radius: float, poisson: float, lengths) -> np.ndarray:
    """(C_b - 1)[K_M] per element offset for each history length b in ``lengths`` [length], shape
    (b, 3 blocks nn, tt, nt, 2 N_e - 1, 3, 3) [length^2 at unit modulus] (module docstring)."""
    return offsets(grid, radius, inner_radius, poisson, lengths)[1]


def _check(grid: ContactGrid) -> None:
    if grid.order != 2 or not grid.uniform:
        raise ValueError("the viscoelastic finite cylinder needs a uniform grid of quadratic elements")


def body_compliance(
    elastic: Compliance,
    grid: ContactGrid,
    model: Viscoelastic,
    radius: float,
    inner_radius: float,
    speed: float,
    direction: int,
) -> Compliance:
    """The viscoelastic annulus's compliance [length/stress] in the arc frame, from its elastic BEM
    annulus ``elastic`` (built with E = E_g) [length/stress]: ``radius`` R and ``inner_radius``
    (the shaft's or the core's) [length], ``speed`` |V| [length/time], ``direction`` sgn(V).
    J_r K_BEM + sum_i c_i [(C_i - 1)[K_M] + (F_i - 1)[E_g K_BEM - K_M]] (module docstring)."""
    blocks, out, terms = relaxed_body(elastic, model, speed, direction)
    if not terms:
        return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)
    exact, offsets_all = offsets(grid, radius, inner_radius, model.poisson, [b for _, b in terms])
    exact_blocks = [_toeplitz_gather(grid, exact[k]) for k in (0, 1, 2, 2)]
    departure = [model.glassy_young * block - f for block, f in zip(blocks, exact_blocks, strict=True)]
    n = grid.size
    stacked = np.concatenate(departure, axis=1)
    for (c, b), per_offset in zip(terms, offsets_all, strict=True):
        filtered = upstream_filter(np.asarray(elastic.x, dtype=float), b) @ stacked - stacked
        history = [_toeplitz_gather(grid, per_offset[block]) for block in (0, 1, 2)]
        for k, block in enumerate((0, 1, 2, 2)):
            out[k] = out[k] + c * (history[block] + filtered[:, k * n : (k + 1) * n])
    return Compliance(elastic.x, elastic.weights, out[0], out[1], out[2], out[3], definite_normal=True)
