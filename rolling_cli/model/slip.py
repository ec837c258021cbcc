"""The slip operator T of the paper (eq. 12, 19-21): slip = xi + T u.

In steady rolling the slip velocity (divided by |V|) is
s = xi + sgn(V) du/dx, u the relative tangential surface displacement. The
derivative is taken UPWIND, towards the side the material comes from
(x + Delta for V < 0), on the node grid: a uniform spacing Delta (a number)
or the n - 1 distances between neighbouring nodes (an array, graded grids):

* ``"fd"`` (the paper's eq. 12): first order, du/dx_i = (u_up - u_i) / (x_up - x_i).
* ``"element"``: the derivative of the quadratic interpolation of u through the
  node and its two upstream neighbours, second order on any spacing. With
  h1 = |x_up - x_i| and h2 = |x_upup - x_up|,

      sgn(V) du/dx_i = (2 h1 + h2) / (h1 (h1 + h2)) u_i - (h1 + h2) / (h1 h2) u_up
                       + h1 / (h2 (h1 + h2)) u_upup,

  which is (3 u_i - 4 u_up + u_upup) / (2 Delta) on a uniform grid.
  (The derivative of each element's own quadratic alone is not usable: it is
  linear per element, so its three nodal rows have rank 2 and the stick
  equations become singular. The upwind quadratic coincides with the element's
  own interpolation at the element's downstream node.)

The upstream end node has no upstream neighbour: its row is replaced by the gauge
u_gauge (eq. 20-21), which fixes the free constant of u; that node must lie
outside the contact. With the second-order stencil the node next to the gauge
falls back to first order.
"""

from __future__ import annotations

import numpy as np

SCHEMES = ("fd", "element")


def gauge_index(n: int, direction: int) -> int:
    """Index of the gauge node: the upstream (leading-edge) end of the zone."""
    return n - 1 if direction < 0 else 0


def creep_vector(n: int, direction: int) -> np.ndarray:
    """The vector e with slip = xi e + T u: ones, and 0 on the gauge row."""
    e = np.ones(n)
    e[gauge_index(n, direction)] = 0.0
    return e


def apply_t(matrix: np.ndarray, spacing, direction: int, scheme: str = "fd") -> np.ndarray:
    """T @ matrix for T of the given scheme [1/length on slip rows], without forming T.

    ``matrix`` has one row per node (a vector or an (n, m) array of
    displacements per unit load). ``spacing`` is the uniform node spacing
    [length] or the array of the n - 1 node distances x[i+1] - x[i] [length].
    Rows are combined by slicing, O(n m).
    """
    if scheme not in SCHEMES:
        raise ValueError(f"slip derivative must be one of {SCHEMES}, got {scheme!r}")
    u = np.asarray(matrix, dtype=float)
    if np.ndim(spacing) != 0:
        return _apply_t_graded(u, np.asarray(spacing, dtype=float), direction, scheme)
    n = u.shape[0]
    out = np.empty_like(u)
    # sgn(V) du/dx_i = (u_i - u_up) / Delta with up = i + 1 for V < 0 and i - 1 for
    # V > 0; rows are combined as contiguous slices in memory order.
    if direction < 0:
        here, up, gauge = slice(0, n - 1), slice(1, n), n - 1
    else:
        here, up, gauge = slice(1, n), slice(0, n - 1), 0
    np.subtract(u[here], u[up], out=out[here])
    out[here] /= spacing
    out[gauge] = u[gauge]
    if scheme == "element" and n > 2:
        if direction < 0:
            here2, up1, up2 = slice(0, n - 2), slice(1, n - 1), slice(2, n)
        else:
            here2, up1, up2 = slice(2, n), slice(1, n - 1), slice(0, n - 2)
        out[here2] = (3.0 * u[here2] - 4.0 * u[up1] + u[up2]) / (2.0 * spacing)
    return out


def _column(values: np.ndarray, ndim: int) -> np.ndarray:
    """Per-row coefficients shaped to broadcast against an array of ``ndim`` dimensions."""
    return values.reshape(values.shape + (1,) * (ndim - 1))


def _apply_t_graded(u: np.ndarray, gaps: np.ndarray, direction: int, scheme: str) -> np.ndarray:
    """:func:`apply_t` on the node distances ``gaps`` = x[i+1] - x[i] (n - 1,) [length]."""
    n = u.shape[0]
    if gaps.shape != (n - 1,) or not np.all(gaps > 0.0):
        raise ValueError("node distances must be n - 1 positive lengths")
    out = np.empty_like(u)
    # For both directions the distance from node i to its upstream neighbour is gaps[k]
    # for the k-th slip row in memory order (V < 0: rows 0..n-2; V > 0: rows 1..n-1).
    if direction < 0:
        here, up, gauge = slice(0, n - 1), slice(1, n), n - 1
    else:
        here, up, gauge = slice(1, n), slice(0, n - 1), 0
    out[here] = (u[here] - u[up]) / _column(gaps, u.ndim)
    out[gauge] = u[gauge]
    if scheme == "element" and n > 2:
        if direction < 0:
            here2, up1, up2 = slice(0, n - 2), slice(1, n - 1), slice(2, n)
            h1, h2 = gaps[:-1], gaps[1:]
        else:
            here2, up1, up2 = slice(2, n), slice(1, n - 1), slice(0, n - 2)
            h1, h2 = gaps[1:], gaps[:-1]
        c0 = (2.0 * h1 + h2) / (h1 * (h1 + h2))
        c1 = -(h1 + h2) / (h1 * h2)
        c2 = h1 / (h2 * (h1 + h2))
        d = u.ndim
        out[here2] = _column(c0, d) * u[here2] + _column(c1, d) * u[up1] + _column(c2, d) * u[up2]
    return out


def downwind_row(matrix: np.ndarray, spacing, direction: int) -> np.ndarray:
    """Slip row for the gauge node by the one-sided downstream difference (for reporting only).

    ``spacing``: the uniform node spacing or the n - 1 node distances [length].
    """
    u = np.asarray(matrix, dtype=float)
    g = gauge_index(u.shape[0], direction)
    inner = g - 1 if direction < 0 else g + 1
    if np.ndim(spacing) != 0:
        spacing = float(np.asarray(spacing)[-1 if direction < 0 else 0])
    return (u[inner] - u[g]) / spacing
