"""Surface stresses of a half-plane from a continuous traction with square-root contact edges.

On the surface z = 0 of a half-plane (:mod:`.halfplane` for the frame and
signs) the stresses are local but for one principal value:

    sigma_xx(x, 0) = p_n(x) - (2/pi) pv int q(s)/(x - s) ds,   sigma_zz = p_n(x),   tau_xz = -q(x).

The solver's element interpolation is discontinuous: at an element end where
it jumps by J, sigma_xx has the singularity (2 J/pi) log|x - end|, so surface
values between the nodes depend on where they fall (at an element end only a
finite part, which depends on the length unit, is defined). Here the surface
uses instead one continuous density through the nodal values:

* piecewise linear between neighbouring knots: the zone's ends (value 0),
  every contact node and the located contact edges (value 0);
* between a contact edge e and its nearest contact node x_1 (value f_1), the
  square root f_1 sqrt(|s - e| / |x_1 - e|), the shape of a smooth contact's
  pressure and of its slip traction there (it is stored as the linear chord
  plus the correction f_1 (sqrt(v) - v), v = |s - e| / |x_1 - e|, which
  vanishes at both ends and has the closed-form Cauchy integral :func:`edge_kernel`).

The density is continuous, so sigma_xx is finite and continuous everywhere
(the linear pieces' kinks give bounded (x - knot) log|x - knot| terms), equals
p_n and -q at the nodes, and at a contact edge it is the square-root cusp's
peak value: for Carter's traction (200 elements) within 0.6 % of the exact
trailing-edge tension (:func:`rolling_cli.references.carter_surface.sigma_xx`),
where the element interpolation sampled at the nodes reads 6 % low.
"""

from __future__ import annotations

import numpy as np

from ..grid import ContactGrid
from .cauchy import line_integrals


def edge_kernel(eta: np.ndarray) -> np.ndarray:
    """G(eta) = pv int_0^1 (sqrt(v) - v) / (eta - v) dv [-], for real eta (finite everywhere).

    Closed form: for eta > 0, (sqrt(eta) + eta) log(1 + sqrt(eta))
    + (eta - sqrt(eta)) log|sqrt(eta) - 1| - eta log(eta) - 1 (log 4 - 1 at
    eta = 1); for eta = -m < 0, 2 sqrt(m) atan(1/sqrt(m)) + m log(m/(1 + m)) - 1;
    G(0) = -1. Far away G ~ 1/(6 eta) (the correction's integral is 1/6).
    """
    eta = np.asarray(eta, dtype=float)
    out = np.full(eta.shape, -1.0)
    pos, neg = eta > 0.0, eta < 0.0
    e = eta[pos]
    r = np.sqrt(e)
    off = r != 1.0
    near_one = np.zeros_like(e)
    near_one[off] = (e[off] - r[off]) * np.log(np.abs(r[off] - 1.0))
    out[pos] = (r + e) * np.log1p(r) + near_one - e * np.log(e) - 1.0
    m = -eta[neg]
    root = np.sqrt(m)
    out[neg] = 2.0 * root * np.arctan(1.0 / root) + m * np.log(m / (1.0 + m)) - 1.0
    return out


def _knots(grid: ContactGrid, p_n: np.ndarray, edges: np.ndarray):
    """Knot positions, the knot index of each nodal value, and each kept edge's (knot, contact-side knot)."""
    x = grid.x
    edges = np.asarray(edges, dtype=float)
    inside = (edges > x[0]) & (edges < x[-1]) & ~np.isin(edges, x)
    edges = np.unique(edges[inside])
    right = np.searchsorted(x, edges)  # the node right of each edge
    contact_right = p_n[right] < 0.0
    between = contact_right != (p_n[right - 1] < 0.0)  # a contact edge lies between contact and separation
    edges, contact_right = edges[between], contact_right[between]
    knots = np.concatenate([[grid.edges[0]], x, edges, [grid.edges[-1]]])
    knots = np.unique(knots)  # the zone's ends are never nodes
    node_knot = np.searchsorted(knots, x)
    edge_knot = np.searchsorted(knots, edges)
    side = np.where(contact_right, edge_knot + 1, edge_knot - 1)  # the contact node next to the edge
    return knots, node_knot, edge_knot, side


def both_signs(
    grid: ContactGrid, p_n: np.ndarray, q: np.ndarray, x: np.ndarray, edges: np.ndarray, signs=(1.0, -1.0)
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] at surface points ``x`` [length] for the traction sign * q, per sign.

    ``p_n`` (<= 0 in compression) and ``q`` (on the body along +x) [stress] are
    the nodal values on ``grid``; ``edges`` [length] the located contact edges
    (:func:`rolling_cli.adapt.kinks.contact_edges`; each between a contact node
    and a separated one). Outputs have the shape of ``x``.
    """
    x = np.asarray(x, dtype=float)
    flat = x.ravel() - grid.centre
    p_n, q = np.asarray(p_n, dtype=float), np.asarray(q, dtype=float)
    knots, node_knot, edge_knot, side = _knots(grid, p_n, edges)
    values = np.zeros((2, knots.size))
    values[0, node_knot], values[1, node_knot] = p_n, q
    k = knots - grid.centre
    starts, ends = k[:-1], k[1:]
    coeff = np.zeros((1, starts.size, 3))
    coeff[0, :, 0] = 0.5 * (values[1, :-1] + values[1, 1:])
    coeff[0, :, 1] = (values[1, 1:] - values[1, :-1]) / (ends - starts)
    hilbert = line_integrals(flat, np.zeros_like(flat), starts, ends, coeff)[0][:, 0].real
    local = np.stack([np.interp(flat, k, values[0]), np.interp(flat, k, values[1])])
    for e, s in zip(edge_knot, side, strict=True):  # a handful of contact edges
        length = abs(k[s] - k[e])
        orient = 1.0 if s > e else -1.0  # +1: contact right of the edge
        eta = orient * (flat - k[e]) / length
        v = np.clip(eta, 0.0, 1.0)
        local += values[:, s, None] * (np.sqrt(v) - v)
        hilbert += orient * values[1, s] * edge_kernel(eta)
    sigma_zz = local[0].reshape(x.shape)
    out = []
    for sign in signs:
        sigma_xx = (local[0] - sign * (2.0 / np.pi) * hilbert).reshape(x.shape)
        out.append((sigma_xx, sigma_zz, (-sign * local[1]).reshape(x.shape)))
    return out
