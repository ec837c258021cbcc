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
  vanishes at both ends and has the closed-form Cauchy integral :func:`edge_kernel`);
* at a located stick/slip boundary b (a knot for q): the slip law
  q = tau mu |p_n| up to b, then the adhesion node's friction reserve
  opening like a square root, the correction -tau r_k (sqrt(v) - v) between b
  and that node (:func:`representation`).

The density is continuous, so sigma_xx is finite and continuous everywhere
(the linear pieces' kinks give bounded (x - knot) log|x - knot| terms), equals
p_n and -q at the nodes, and at a kink it is the square-root cusp's peak
value. Carter's case at 200 elements: the trailing-edge tension within 0.6 %
of the closed form (:func:`rolling_cli.references.carter_surface.sigma_xx`;
the element interpolation at the nodes reads 6 % low), von Mises and Tresca
at the stick/slip boundary (mu = 0.3, Q/(mu P) = 0.95) within 0.01 % (2 %
low on the nodes and the field grid).
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid
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


def _kinks_between_nodes(x: np.ndarray, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The positions strictly between two nodes (not on one), unique, and the node right of each."""
    positions = np.asarray(positions, dtype=float)
    positions = np.unique(positions[(positions > x[0]) & (positions < x[-1]) & ~np.isin(positions, x)])
    return positions, np.searchsorted(x, positions)


def representation(grid: ContactGrid, p_n: np.ndarray, q: np.ndarray, edges: np.ndarray, boundaries=()):
    """The continuous surface traction (module docstring) as knots and square-root corrections.

    Returns ``knots`` (K,) [length], ``values`` (2, K) [stress] (p_n and q at the
    knots: linear between them) and ``corrections``: (e, s, amplitude (2,)) per
    square root, which adds amplitude (sqrt(v) - v), v = |x - knots[e]| /
    |knots[s] - knots[e]|, between knots e and s (neighbours). Contact
    ``edges``: value 0 at the edge, amplitude the contact node's values.
    Stick/slip ``boundaries`` [length]: q keeps the slip law up to the
    boundary, q(b) = tau mu |p_n(b)| (tau, mu = |q|/|p_n| of the slip node,
    the one of the pair with the larger |q|/|p_n|), and the friction reserve
    r_k = mu |p_n,k| - |q_k| of the adhesion node opens like a square root:
    amplitude (0, -tau r_k).
    """
    x = grid.x
    edges, right = _kinks_between_nodes(x, edges)
    contact_right = p_n[right] < 0.0
    keep = contact_right != (p_n[right - 1] < 0.0)  # a contact edge lies between contact and separation
    edges, contact_right = edges[keep], contact_right[keep]
    boundaries, b_right = _kinks_between_nodes(x, boundaries)
    ratio = np.abs(q) / np.where(p_n < 0.0, -p_n, np.inf)  # |q|/|p_n|, 0 off contact
    in_contact = (p_n[b_right] < 0.0) & (p_n[b_right - 1] < 0.0)
    boundaries, b_right = boundaries[in_contact], b_right[in_contact]
    slip_right = ratio[b_right] > ratio[b_right - 1]
    knots = np.unique(np.concatenate([[grid.edges[0]], x, edges, boundaries, [grid.edges[-1]]]))
    values = np.zeros((2, knots.size))
    node_knot = np.searchsorted(knots, x)
    values[0, node_knot], values[1, node_knot] = p_n, q
    corrections = []
    for e, on_right in zip(np.searchsorted(knots, edges), contact_right, strict=True):  # a handful
        side = e + 1 if on_right else e - 1  # the contact node next to the edge
        corrections.append((e, side, values[:, side].copy()))
    for b, right_node, on_right in zip(np.searchsorted(knots, boundaries), b_right, slip_right, strict=True):
        slip, stick = (right_node, right_node - 1) if on_right else (right_node - 1, right_node)
        mu, tau = ratio[slip], np.sign(q[slip])
        w = (knots[b] - x[right_node - 1]) / (x[right_node] - x[right_node - 1])
        values[0, b] = (1.0 - w) * p_n[right_node - 1] + w * p_n[right_node]
        values[1, b] = -tau * mu * values[0, b]
        reserve = max(mu * -p_n[stick] - abs(q[stick]), 0.0)
        corrections.append((b, node_knot[stick], np.array([0.0, -tau * reserve])))
    return knots, values, corrections


def both_signs(
    grid: ContactGrid,
    p_n: np.ndarray,
    q: np.ndarray,
    x: np.ndarray,
    edges: np.ndarray,
    signs=(1.0, -1.0),
    boundaries=(),
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(sigma_xx, sigma_zz, tau_xz) [stress] at surface points ``x`` [length] for the traction sign * q, per sign.

    ``p_n`` (<= 0 in compression) and ``q`` (on the body along +x) [stress] are
    the nodal values on ``grid``; ``edges`` [length] the located contact edges
    (:func:`rolling_cli.adapt.kinks.contact_edges`; each between a contact node
    and a separated one), ``boundaries`` [length] the stick/slip boundaries
    (:func:`rolling_cli.adapt.kinks.stick_slip_boundaries`). Outputs have the
    shape of ``x``.
    """
    x = np.asarray(x, dtype=float)
    flat = x.ravel() - grid.centre
    p_n, q = np.asarray(p_n, dtype=float), np.asarray(q, dtype=float)
    knots, values, corrections = representation(grid, p_n, q, edges, boundaries)
    k = knots - grid.centre
    starts, ends = k[:-1], k[1:]
    coeff = np.zeros((1, starts.size, 3))
    coeff[0, :, 0] = 0.5 * (values[1, :-1] + values[1, 1:])
    coeff[0, :, 1] = (values[1, 1:] - values[1, :-1]) / (ends - starts)
    hilbert = line_integrals(flat, np.zeros_like(flat), starts, ends, coeff)[0][:, 0].real
    local = np.stack([np.interp(flat, k, values[0]), np.interp(flat, k, values[1])])
    for e, s, amplitude in corrections:  # a handful of kinks
        orient = 1.0 if s > e else -1.0  # +1: the square root right of the kink
        eta = orient * (flat - k[e]) / abs(k[s] - k[e])
        v = np.clip(eta, 0.0, 1.0)
        local += amplitude[:, None] * (np.sqrt(v) - v)
        hilbert += orient * amplitude[1] * edge_kernel(eta)
    sigma_zz = local[0].reshape(x.shape)
    out = []
    for sign in signs:
        sigma_xx = (local[0] - sign * (2.0 / np.pi) * hilbert).reshape(x.shape)
        out.append((sigma_xx, sigma_zz, (-sign * local[1]).reshape(x.shape)))
    return out
