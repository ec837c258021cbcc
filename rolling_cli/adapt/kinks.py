"""Where the traction kinks: contact edges and stick/slip boundaries, to a fraction of a node spacing.

Near a contact edge x_e the pressure of a smooth (Hertzian) contact goes like
sqrt(x_e - x) inside and the gap like (x - x_e)^(3/2) outside; near a stick/slip
boundary x_b the friction reserve mu |p_n| - |p_t| goes like sqrt(|x - x_b|) on
the adhesion side and the slip velocity like sqrt(|x - x_b|) on the slip side.
So the squares p_n^2, gap^(4/3) and (mu |p_n| - |p_t|)^2 are locally LINEAR in
x and vanish at the kink: extrapolating the straight line through the two
nodes nearest the kink on one side gives its position, exactly for a pure
square root and to second order in the node spacing otherwise. Each kink is
bracketed by the two nodes whose states differ (the node states of the
converged projection equations), and the estimate must fall in that bracket
(else the next estimate, else the bracket's midpoint). Measured on Carter's
case (uniform meshes of 10 to 160 elements, zones 1.37 a to 1.6 a, Q/(mu P) =
0.3 to 0.8): contact edges within 0.04 node spacings from the gap and 0.15 from
the pressure, stick/slip boundaries within 0.35.

All functions are pure, on the node arrays of a solution.
"""

from __future__ import annotations

import numpy as np

#: Kink kinds, as reported by :func:`locate_kinks`.
CONTACT_EDGE, STICK_SLIP = "contact edge", "stick/slip"


def _zero_of_line(x1: np.ndarray, q1: np.ndarray, x2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """x where the straight line through (x1, q1), (x2, q2) vanishes (NaN when it is flat)."""
    slope = q2 - q1
    out = np.full(np.shape(x1), np.nan)
    ok = slope != 0.0
    out[ok] = x1[ok] - q1[ok] * (x2[ok] - x1[ok]) / slope[ok]
    return out


def _side_estimate(x: np.ndarray, q: np.ndarray, inner: np.ndarray, step: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Kinks from the square-root quantity ``q`` (squared here) at nodes ``inner`` and ``inner + step``.

    ``step`` points away from each kink (+1 or -1); ``valid`` says where the second
    node exists and shares the state. NaN where no estimate is possible.
    """
    out = np.full(inner.shape, np.nan)
    if not valid.any():
        return out
    i1 = inner[valid]
    i2 = i1 + step[valid]
    out[valid] = _zero_of_line(x[i1], q[i1] ** 2, x[i2], q[i2] ** 2)
    return out


def _first_inside(lower_x: np.ndarray, upper_x: np.ndarray, *estimates: np.ndarray) -> np.ndarray:
    """The first estimate inside each bracket [lower_x, upper_x]; the bracket midpoint if none is."""
    out = 0.5 * (lower_x + upper_x)
    for estimate in reversed(estimates):  # earlier estimates overwrite later ones
        ok = np.isfinite(estimate) & (estimate >= lower_x) & (estimate <= upper_x)
        out = np.where(ok, estimate, out)
    return out


def _brackets(mask: np.ndarray, other: np.ndarray) -> np.ndarray:
    """Indices i with mask[i] and other[i + 1], or other[i] and mask[i + 1]: (i, side) pairs.

    Returns an (m, 2) array: the left node of each bracket and +1 when ``mask``
    lies on the left, -1 when on the right.
    """
    left = np.flatnonzero(mask[:-1] & other[1:])
    right = np.flatnonzero(other[:-1] & mask[1:])
    out = np.concatenate([np.column_stack([left, np.ones_like(left)]), np.column_stack([right, -np.ones_like(right)])])
    return out[np.argsort(out[:, 0], kind="stable")]


def contact_edges(
    x: np.ndarray, p_n: np.ndarray, gap: np.ndarray | None = None, element: np.ndarray | None = None
) -> np.ndarray:
    """Positions [length] of the contact edges, one per change between contact and separation.

    Two estimates: from p_n^2 through the two outermost contact nodes, and
    (``gap`` given) from gap^(4/3) through the two innermost separated nodes (a
    gap growing like (x - x_e)^(3/2) makes gap^(2/3) linear). The gap's is the
    more accurate one (0.04 against 0.12 node spacings on uniform meshes), but
    not where the bracketing nodes lie in different elements (``element``: the
    element index of each node): the discrete pressure's support then ends on
    that element edge and the gap of the discrete pressure vanishes there,
    wherever the true contact edge lies, so on a grid graded towards an earlier
    estimate it would never move it. Without ``element`` the pressure's
    estimate comes first.
    """
    contact = p_n < 0.0
    pairs = _brackets(contact, ~contact)
    if pairs.size == 0:
        return np.empty(0)
    i, contact_left = pairs[:, 0], pairs[:, 1] > 0
    n = x.size
    inner = np.where(contact_left, i, i + 1)  # the outermost contact node
    step = np.where(contact_left, -1, 1)  # towards the contact's interior
    second = np.clip(inner + step, 0, n - 1)
    valid = contact[second] & (second != inner)
    from_pressure = _side_estimate(x, -p_n, inner, step, valid)
    if gap is None:
        return _first_inside(x[i], x[i + 1], from_pressure)
    outer = np.where(contact_left, i + 1, i)  # the first separated node
    second = np.clip(outer - step, 0, n - 1)
    valid = ~contact[second] & (second != outer)
    root = np.cbrt(np.maximum(gap, 0.0))  # gap^(1/3): its square is linear
    from_gap = _side_estimate(x, root, outer, -step, valid)
    if element is None:
        return _first_inside(x[i], x[i + 1], from_pressure, from_gap)
    from_gap[element[i] != element[i + 1]] = np.nan
    return _first_inside(x[i], x[i + 1], from_gap, from_pressure)


def stick_slip_boundaries(x: np.ndarray, p_n: np.ndarray, p_t: np.ndarray, state: np.ndarray, mu: float) -> np.ndarray:
    """Positions [length] of every boundary between adhesion (state 1) and slip (state 2).

    From the friction reserve mu |p_n| - |p_t| through the two adhesion nodes
    nearest the boundary. (The slip velocity on the slip side is not used: the
    discrete one is not square-root-like at the boundary, it puts the estimate
    about half a node spacing off on Carter's case.)
    """
    stick, slipping = state == 1, state == 2
    pairs = _brackets(stick, slipping)
    if pairs.size == 0:
        return np.empty(0)
    i, stick_left = pairs[:, 0], pairs[:, 1] > 0
    inner = np.where(stick_left, i, i + 1)  # the adhesion node at the boundary
    step = np.where(stick_left, -1, 1)  # into the adhesion zone
    second = np.clip(inner + step, 0, x.size - 1)
    valid = stick[second] & (second != inner)
    reserve = np.maximum(mu * np.abs(p_n) - np.abs(p_t), 0.0)
    return _first_inside(x[i], x[i + 1], _side_estimate(x, reserve, inner, step, valid))


def locate_kinks(result, grid=None) -> tuple[np.ndarray, np.ndarray]:
    """Every contact edge and stick/slip boundary of a solved :class:`~rolling_cli.result.Result`.

    ``grid`` (its :class:`~rolling_cli.model.grid.ContactGrid`) lets the contact edges
    use the gap where that is reliable (:func:`contact_edges`). Returns
    (positions [length], kinds), sorted by position; kinds are
    :data:`CONTACT_EDGE` or :data:`STICK_SLIP`.
    """
    return locate(result.x, result.p_n, result.p_t, result.delta_n, result.state, result.mu, grid)


def locate(
    x: np.ndarray,
    p_n: np.ndarray,
    p_t: np.ndarray,
    gap: np.ndarray,
    state: np.ndarray,
    mu: float,
    grid=None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`locate_kinks` on plain arrays: node positions ``x`` and ``gap`` [length], tractions
    [stress], node ``state`` (0 separation, 1 adhesion, 2 slip), friction coefficient ``mu``."""
    element = None
    if grid is not None:
        element = np.repeat(np.arange(grid.elements), grid.nodes_per_element)
    edges = contact_edges(x, p_n, gap, element)
    boundaries = np.empty(0)
    if mu > 0.0:
        boundaries = stick_slip_boundaries(x, p_n, p_t, state, mu)
    positions = np.concatenate([edges, boundaries])
    kinds = np.array([CONTACT_EDGE] * edges.size + [STICK_SLIP] * boundaries.size)
    order = np.argsort(positions, kind="stable")
    return positions[order], kinds[order]


def displacement_change(
    x: np.ndarray,
    p_n: np.ndarray,
    p_t: np.ndarray,
    state: np.ndarray,
    mu: float,
    positions: np.ndarray,
    kinds: np.ndarray,
    p0: float,
    shifts: np.ndarray,
) -> np.ndarray:
    """The traction change [-] that moving each kink by ``shifts`` [length] makes next to it.

    On the kink's square-root side the traction vanishes at the kink and grows
    like sqrt(d); moved by Delta, the traction at distance Delta from the kink
    goes from (about) zero to its value there, so the change is the value at
    d = Delta: the pressure |p_n| / p0 beside a contact edge (p_t = mu p_n in
    slip makes it the tangential change in units of mu p0; beside an adhering
    edge Carter's traction grows more slowly), the friction reserve
    (mu |p_n| - |p_t|) / (mu p0) beside a stick/slip boundary. Interpolated
    between the nodes of the side's run, and below the first node d_1 as the
    square root v_1 sqrt(Delta / d_1).
    """
    out = np.zeros(positions.shape)
    if not p0 > 0.0:
        return out
    contact, stick = p_n < 0.0, state == 1
    reserve = np.maximum(mu * np.abs(p_n) - np.abs(p_t), 0.0) / (mu * p0) if mu > 0.0 else np.zeros_like(p_n)
    for k, (position, kind, shift) in enumerate(zip(positions, kinds, shifts, strict=True)):  # a handful
        side = contact if kind == CONTACT_EDGE else stick
        values = -p_n / p0 if kind == CONTACT_EDGE else reserve
        if not side.any() or not shift > 0.0:
            continue
        candidates = np.flatnonzero(side)
        first = candidates[np.argmin(np.abs(x[candidates] - position))]
        step = 1 if x[first] >= position else -1
        run = first + step * np.arange(x.size)  # the side's nodes from the kink inwards, while they last
        run = run[(run >= 0) & (run < x.size)]
        outside = np.flatnonzero(~side[run])
        run = run[: outside[0]] if outside.size else run
        distance = np.abs(x[run] - position)
        if shift <= distance[0]:
            out[k] = float(values[first]) * np.sqrt(shift / distance[0]) if distance[0] > 0.0 else 0.0
        else:
            out[k] = float(np.interp(shift, distance, values[run]))
    return out
