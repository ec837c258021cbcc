"""Predictors for continuation: a start for the next point of a path from converged neighbours.

* :func:`secant`: the boundary-tracking secant predictor. A plain secant
  (x1 + t (x1 - x0)) of two traction profiles keeps both profiles' kinks (the
  contact edges and the stick/slip boundaries, where the traction has a
  square-root kink) at their old places, so Newton then moves each boundary a
  node or two per iteration. Here the zone boundaries themselves are
  extrapolated (located to a small fraction of a node by :func:`zones`), both
  profiles are mapped piecewise-linearly onto the predicted boundaries, and the
  secant is taken of the mapped profiles. The overlap and the creepage are
  extrapolated linearly.
* :func:`with_traction`: a state with another's tangential traction and
  creepage (a neighbour's pressure with a closed-form traction).
* :func:`transfer`: a state moved onto another grid (a larger zone, a finer
  mesh): tractions interpolated, zero outside the old zone.

Node labels: 0 separation, 1 adhesion, 2 slip with p_t > 0, 3 slip with p_t < 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .formulation import State


@dataclass(frozen=True)
class Zones:
    """The zone pattern of a solution: the label of each run of nodes (left to right),
    the boundary positions between runs [length], and which boundaries are contact edges."""

    pattern: tuple[int, ...]
    boundaries: np.ndarray
    edges: np.ndarray


def node_labels(p_n: np.ndarray, p_t: np.ndarray, stick: np.ndarray) -> np.ndarray:
    """0 separation, 1 adhesion, 2 slip with p_t >= 0, 3 slip with p_t < 0."""
    labels = np.zeros(p_n.shape, dtype=np.int8)
    contact = p_n < 0.0
    labels[contact & stick] = 1
    labels[contact & ~stick & (p_t >= 0.0)] = 2
    labels[contact & ~stick & (p_t < 0.0)] = 3
    return labels


def zones(x: np.ndarray, labels: np.ndarray, p_n: np.ndarray, p_t: np.ndarray, bound: np.ndarray) -> Zones:
    """Zone boundaries located to a small fraction of a node spacing.

    Near a contact edge the pressure vanishes like a square root, and so does the
    friction margin g - |p_t| (g = mu |p_n|) at the edge of an adhesion zone; the
    squares of both are then linear in x, so each boundary is where the line
    through the squares at the two nodes inside the zone (the contact side, or the
    adhesion side) reaches zero. Between two slip runs of opposite direction it is
    where p_t changes sign (linear interpolation). A boundary the fit cannot place
    between its two nodes falls back to their midpoint.
    """
    cut = np.flatnonzero(np.diff(labels))
    n = labels.size
    boundaries = np.empty(cut.size)
    edges = np.empty(cut.size, dtype=bool)
    margin = np.clip(bound - np.abs(p_t), 0.0, None)
    for k, i in enumerate(cut):  # one per zone boundary: a handful per solution
        left, right = labels[i], labels[i + 1]
        edges[k] = (left == 0) != (right == 0)
        if edges[k]:
            field, inside = -np.minimum(p_n, 0.0), int(i if right == 0 else i + 1)
        elif 1 in (left, right):
            field, inside = margin, int(i if left == 1 else i + 1)
        else:
            field, inside = None, -1  # no field: the zero crossing of p_t places the boundary
        lo, hi = x[i], x[i + 1]
        position = 0.5 * (lo + hi)
        if field is None:
            f0, f1 = p_t[i], p_t[i + 1]
            if f0 * f1 < 0.0:
                position = lo + f0 / (f0 - f1) * (hi - lo)
        else:
            step = -1 if inside == i else 1
            deeper = inside + step
            if 0 <= deeper < n and labels[deeper] == labels[inside]:
                s0, s1 = field[inside] ** 2, field[deeper] ** 2
                if s1 > s0 > 0.0:
                    candidate = x[inside] - s0 * (x[deeper] - x[inside]) / (s1 - s0)
                    if lo <= candidate <= hi:
                        position = candidate
        boundaries[k] = position
    pattern = tuple(int(v) for v in labels[np.concatenate([[0], cut + 1])])
    return Zones(pattern, boundaries, edges)


def _warp(x: np.ndarray, values: np.ndarray, source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``values`` (on x) mapped so that the knots ``source`` move to ``target`` (ends fixed)."""
    if source.size == 0:
        return values
    knots_to = np.concatenate([[x[0]], target, [x[-1]]])
    knots_from = np.concatenate([[x[0]], source, [x[-1]]])
    return np.interp(np.interp(x, knots_to, knots_from), x, values)


def secant(x: np.ndarray, points: list[tuple[float, State, Zones]], s: float, mu: float) -> State:
    """Predicted state at path parameter ``s`` from the last converged points [(s_k, state_k, zones_k)].

    The zone boundaries are extrapolated linearly when the last two points share
    a zone pattern and the prediction keeps them ordered inside the zone;
    otherwise they stay where the last solution has them. (A quadratic through
    three points was measured worse: it amplifies the error of the located
    boundaries about 4.4 times, a line 2.2 times, and mid-curve that error
    outweighs the curvature of the boundary's path.) The last two profiles are mapped onto the predicted
    boundaries and extrapolated linearly, as are the overlap and the creepage.
    The result is projected onto p_n <= 0 and |p_t| <= mu |p_n|. With one
    point the prediction is a copy.
    """
    if len(points) == 1:
        return points[0][1].copy()
    (s0, state0, zones0), (s1, state1, zones1) = points[-2], points[-1]
    t = (s - s1) / (s1 - s0)
    b1 = zones1.boundaries
    target, b0 = b1, None
    if zones0.pattern == zones1.pattern:
        predicted = b1 + t * (b1 - zones0.boundaries)
        inside = predicted.size == 0 or (predicted[0] > x[0] and predicted[-1] < x[-1])
        if inside and np.all(np.diff(predicted) > 0.0):
            target, b0 = predicted, zones0.boundaries
    edges = zones1.edges
    pn1 = _warp(x, state1.p_n, b1[edges], target[edges])
    pt1 = _warp(x, state1.p_t, b1, target)
    if b0 is None:
        pn0, pt0 = state0.p_n, state0.p_t
    else:
        pn0 = _warp(x, state0.p_n, b0[edges], target[edges])
        pt0 = _warp(x, state0.p_t, b0, target)
    p_n = np.minimum(pn1 + t * (pn1 - pn0), 0.0)
    p_n[~_inside_contact(x, zones1, target)] = 0.0  # no stray pressure beyond the predicted edges
    p_t = np.clip(pt1 + t * (pt1 - pt0), mu * p_n, -mu * p_n)
    return State(
        p_n,
        p_t,
        state1.overlap + t * (state1.overlap - state0.overlap),
        state1.creep + t * (state1.creep - state0.creep),
    )


def with_traction(state: State, other: State, mu: float) -> State:
    """``state`` with the tangential traction and creepage of ``other`` (the traction clipped to
    ``state``'s friction bound mu |p_n|); its pressure and overlap are kept."""
    out = state.copy()
    out.p_t = np.clip(other.p_t, mu * state.p_n, -mu * state.p_n)
    out.creep = float(other.creep)
    return out


def _inside_contact(x: np.ndarray, zones: Zones, boundaries: np.ndarray) -> np.ndarray:
    """Nodes inside the runs of ``zones``' pattern that are in contact, with its boundaries moved to
    ``boundaries``."""
    knots = np.concatenate([[-np.inf], boundaries, [np.inf]])
    run = np.searchsorted(knots, x, side="right") - 1  # the run each node falls in
    return np.array(zones.pattern)[np.clip(run, 0, len(zones.pattern) - 1)] != 0


def transfer(state: State, x_from: np.ndarray, x_to: np.ndarray, mu: float) -> State:
    """``state`` on the grid ``x_from`` interpolated onto ``x_to`` (zero beyond the old nodes).

    The contact set is kept on the small side: a node of the new grid outside
    the old contact gets no pressure (a contact set too large is shed one node
    per Newton iteration, one too small gains all its missing nodes at once).
    """
    p_n = np.minimum(np.interp(x_to, x_from, state.p_n, left=0.0, right=0.0), 0.0)
    inside = x_from[state.p_n < 0.0]
    if inside.size:
        p_n[(x_to < inside.min()) | (x_to > inside.max())] = 0.0
    p_t = np.interp(x_to, x_from, state.p_t, left=0.0, right=0.0)
    p_t = np.clip(p_t, mu * p_n, -mu * p_n)
    return State(p_n, p_t, float(state.overlap), float(state.creep))


def over_solutions(x: np.ndarray, mu: float):
    """The boundary-secant predictor over path points [(s, solution)] (objects with ``state`` and
    ``zones()``; a copy of the state from one point): ``predict(points, s) -> State`` for
    :func:`rolling_cli.solver.continuation.follow`. ``x`` the nodes [length], ``mu`` [-]."""

    def predict(points, s):
        return secant(x, [(sk, sol.state, sol.zones()) for sk, sol in points[-2:]], s, mu)

    return predict
