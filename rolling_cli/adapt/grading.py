"""Contact grids graded geometrically towards given points (the kinks of the traction).

At a contact edge or a stick/slip boundary the traction has a square-root
kink, which a uniform mesh averages over a node cell: the maximum error then
falls only like sqrt(h). A grid with an element edge ON each kink and elements
growing geometrically away from it resolves the square root where it matters
and stays coarse elsewhere. The element size at distance d from the nearest
kink (anchor) is

    h(d) = min(largest, smallest + (growth - 1) d),

so the k-th element from a kink is about smallest * growth^k long. Between two
anchors each half is meshed from its own anchor; a zone end that is not an
anchor gets no refinement. The element count of a piece is the integral of
1/h rounded up, and the edges are placed at equal steps of that integral
(closed form both ways), so every element is at most h long.
"""

from __future__ import annotations

import numpy as np

from ..model.grid import ContactGrid


def _size_integral(d: np.ndarray, smallest: float, largest: float, rate: float) -> np.ndarray:
    """Phi(d) = int_0^d dt / h(t) [-] for h(t) = min(largest, smallest + rate t)."""
    d = np.asarray(d, dtype=float)
    if rate <= 0.0:
        return d / smallest
    knee = max(largest - smallest, 0.0) / rate
    inner = np.log1p(rate * np.minimum(d, knee) / smallest) / rate
    return inner + np.maximum(d - knee, 0.0) / largest


def _size_integral_inverse(phi: np.ndarray, smallest: float, largest: float, rate: float) -> np.ndarray:
    """The distance d [length] with Phi(d) = phi (inverse of :func:`_size_integral`)."""
    phi = np.asarray(phi, dtype=float)
    if rate <= 0.0:
        return phi * smallest
    knee = max(largest - smallest, 0.0) / rate
    phi_knee = np.log1p(rate * knee / smallest) / rate
    inner = smallest * np.expm1(rate * np.minimum(phi, phi_knee)) / rate
    return np.where(phi <= phi_knee, inner, knee + (phi - phi_knee) * largest)


def _graded_piece(length: float, smallest: float, largest: float, rate: float) -> np.ndarray:
    """Distances [length] of the element edges from the anchor over a piece of ``length``, 0 .. length."""
    total = float(_size_integral(np.asarray(length, dtype=float), smallest, largest, rate))
    count = max(1, int(np.ceil(total - 1e-9)))
    distances = _size_integral_inverse(np.linspace(0.0, total, count + 1), smallest, largest, rate)
    distances[-1] = length
    return distances


def graded_edges(lower: float, upper: float, anchors, smallest, largest: float, growth: float = 1.3) -> np.ndarray:
    """Element edges [length] over [lower, upper], graded towards each anchor (an edge on each).

    ``anchors`` [length] outside (lower, upper) are ignored; ``smallest`` [length]
    is the element length at the anchors, one value or one per anchor; anchors
    closer together than their smallest element are merged into their mean (with
    the smaller length). ``largest`` bounds the element length [length];
    ``growth`` >= 1 is the ratio of neighbouring element lengths away from an
    anchor (1: uniform ``smallest``).
    """
    anchors = np.atleast_1d(np.asarray(anchors, dtype=float))
    sizes = np.broadcast_to(np.asarray(smallest, dtype=float), anchors.shape).copy() if anchors.size else anchors
    if not upper > lower or np.any(sizes <= 0.0) or np.any(sizes > largest) or growth < 1.0:
        raise ValueError("graded edges need lower < upper, 0 < smallest <= largest and growth >= 1")
    if anchors.size == 0 and not 0.0 < float(np.min(smallest)) <= largest:
        raise ValueError("graded edges need 0 < smallest <= largest")
    rate = growth - 1.0
    keep = (anchors > lower) & (anchors < upper)
    order = np.argsort(anchors[keep], kind="stable")
    inside, sizes = anchors[keep][order], sizes[keep][order]
    if inside.size > 1:  # anchors closer than their smallest element are one anchor (their mean)
        group = np.concatenate([[0], np.cumsum(np.diff(inside) >= np.minimum(sizes[1:], sizes[:-1]))])
        inside = np.bincount(group, weights=inside) / np.bincount(group)
        sizes = np.array([sizes[group == g].min() for g in range(inside.size)])  # a handful of anchors
    points = np.concatenate([[lower], inside, [upper]])
    size_at = np.concatenate([[largest], sizes, [largest]])
    is_anchor = np.concatenate([[False], np.ones(inside.size, dtype=bool), [False]])
    pieces = [np.array([lower])]
    for k in range(points.size - 1):  # one piece per gap between anchors (a handful)
        a, b = points[k], points[k + 1]
        left, right = is_anchor[k], is_anchor[k + 1]
        if left and right:
            mid = 0.5 * (a + b)
            first = a + _graded_piece(mid - a, size_at[k], largest, rate)
            second = b - _graded_piece(b - mid, size_at[k + 1], largest, rate)[::-1]
            pieces += [first[1:], second[1:]]
        elif left:
            pieces.append((a + _graded_piece(b - a, size_at[k], largest, rate))[1:])
        elif right:
            pieces.append((b - _graded_piece(b - a, size_at[k + 1], largest, rate)[::-1])[1:])
        else:
            count = max(1, int(np.ceil((b - a) / largest - 1e-9)))
            pieces.append(np.linspace(a, b, count + 1)[1:])
    return np.concatenate(pieces)


def graded_grid(zone: ContactGrid, anchors, smallest, largest: float, growth: float = 1.3) -> ContactGrid:
    """A grid over ``zone``'s potential contact zone and of its element order, graded towards ``anchors``.

    See :func:`graded_edges` for the arguments [length].
    """
    lower, upper = zone.centre - zone.half_width, zone.centre + zone.half_width
    edges = graded_edges(lower, upper, anchors, smallest, largest, growth)
    return ContactGrid.graded(edges, zone.order)
