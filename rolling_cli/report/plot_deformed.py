"""The deformed contact region to scale (``rollc plot FILE --deformed [--magnify K]``).

Both bodies near the contact, in the case's length unit, equal axis scales:
their undeformed outlines (dashed) and their deformed surfaces (solid),
undeformed + K x displacement (K = 1: to scale), the contact nodes marked by
state (adhesion, slip). Body A is above, B below; x is the solver's frame
(a finite cylinder's: arc length s at the angle theta = s / R).

Geometry, the model's own (so the drawn gap is the solver's gap):

* a half-space body (closed form or BEM block or layer): its profile is the
  model's parabola x^2 / (2 R) (the circle of radius R to O(x^4 / R^3); a flat
  for R = inf), and a node moves by (u, w) with w into the body (up for A,
  down for B) and u along +x;
* a finite cylinder: the node at arc length s sits at theta = s / R on its
  circle (A: (R sin theta, R (1 - cos theta)), B the mirror image), and moves
  by -w n + u tau along its outward normal n and arc tangent tau
  (:mod:`rolling_cli.influence.finite`);
* the approach: the solved overlap d (``solved_overlap``) is split between
  the bodies as rigid shifts: B is shifted by c_B = w_B at the node nearest the
  contact centre (its surface point there stays in place; 0 for a rigid B),
  A by d - c_B. For a half-space d and w are relative to the model's datum
  (the log kernel's reference length, a rigid shift in 2D); the drawn
  w_X - c_X are not (they are fixed by the gap). The vertical
  distance of the surfaces at a node is then the solver's gap
  g0 - d + w_A + w_B (for a finite cylinder on a flat, its linearised
  g0 - d + cos(theta) w + sin(theta) u): zero over the contact.

With K > 1 the displacements and the approach are magnified, the profiles
not: the surfaces then overlap by (K - 1) times the undeformed gap over the
contact (stated in the title).
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass

import h5py
import numpy as np
from matplotlib.figure import Figure

from ..errors import CaseError
from ..files.io_hdf5 import read_result
from ..files.reader import is_sweep
from ..result import Result
from .plot import _figure, deliver

#: Half-width of the drawn window in contact half-widths a (the brief's "about 2-3 a").
WINDOW = 2.5
#: Points of each undeformed outline across the window.
OUTLINE_POINTS = 400
STATE_COLOURS = {1: "#1f77b4", 2: "#ff7f0e"}  # adhesion, slip (node markers)


@dataclass(frozen=True)
class Body:
    """One body's drawing: ``outline`` (2, m) undeformed and ``surface`` (2, n) deformed at the
    contact nodes [length]; ``label`` says what it is."""

    label: str
    outline: np.ndarray
    surface: np.ndarray


def _radius(value) -> float:
    return math.inf if value is None else float(value)


def body_geometry(
    x: np.ndarray,
    w: np.ndarray | None,
    u: np.ndarray | None,
    radius: float,
    finite: bool,
    upper: bool,
    approach: float,
    window: tuple[float, float],
    magnify: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(undeformed outline (2, m), deformed surface at the nodes (2, n)) [length] of one body.

    ``x`` (n,) node positions (a finite cylinder's arc lengths) [length]; ``w``, ``u`` (n,) its
    surface displacements [length] (None: rigid, zero); ``radius`` R [length] (inf: a flat);
    ``finite``: a finite cylinder (arc frame) rather than a half-space (parabola); ``upper``: body A
    (above, w upwards); ``approach``: the rigid shift of this body towards the other [length];
    ``window`` (lo, hi): the outline's x range [length]; ``magnify`` K scales displacements and
    approach."""
    w = np.zeros_like(x) if w is None else np.asarray(w, dtype=float)
    u = np.zeros_like(x) if u is None else np.asarray(u, dtype=float)
    side = 1.0 if upper else -1.0
    shift = -side * magnify * approach
    xs = np.linspace(window[0], window[1], OUTLINE_POINTS)
    if finite:
        theta = x / radius
        sin, cos = np.sin(theta), np.cos(theta)
        span = np.clip(xs / radius, -math.pi, math.pi)
        outline = np.array([radius * np.sin(span), side * radius * (1.0 - np.cos(span)) + shift])
        base = np.array([radius * sin, side * radius * (1.0 - cos) + shift])
        move = np.array([-w * sin + u * cos, side * (w * cos + u * sin)])  # A: -w n + u tau; B: its mirror
        return outline, base + magnify * move
    curvature = 0.0 if math.isinf(radius) else 1.0 / radius
    outline = np.array([xs, side * 0.5 * curvature * xs**2 + shift])
    base = np.array([x, side * 0.5 * curvature * x**2 + shift])
    return outline, base + magnify * np.array([u, side * w])


def case_bodies(result: Result) -> dict:
    """The case's bodies (from the file's case text): {label: (kind, radius, finite)}."""
    from ..case.io import case_from_dict

    case = case_from_dict(tomllib.loads(result.case_toml or ""), None)
    out = {}
    for label in ("A", "B"):
        body = getattr(case.bodies, label)
        out[label] = (body.kind, _radius(body.radius), bool(body.finite))
    return out


def has_displacements(result: Result, bodies: dict) -> bool:
    """True when the result holds the surface displacements of each deformable body."""
    return all(
        getattr(result, f"surface_w_{label}") is not None for label, (kind, _, _) in bodies.items() if kind != "rigid"
    )


def deformed_bodies(result: Result, magnify: float = 1.0) -> tuple[list[Body], tuple[float, float]]:
    """Both bodies' drawings and the window (lo, hi) [length] (ValueError without displacements)."""
    bodies = case_bodies(result)
    if not has_displacements(result, bodies):
        raise ValueError("the file has no surface displacements (written by an older rollc)")
    a = result.contact_half_width
    if a is None or not math.isfinite(a) or a <= 0.0:
        a = float(np.ptp(result.x)) / 4.0
    centre = result.contact_centre if result.contact_centre is not None and math.isfinite(result.contact_centre) else 0
    window = (centre - WINDOW * a, centre + WINDOW * a)
    overlap = float(result.solved_overlap or 0.0)
    w_b = result.surface_w_B
    centre_node = int(np.argmin(np.abs(result.x - centre)))
    c_b = 0.0 if w_b is None else float(w_b[centre_node])
    drawn = []
    for label, (kind, radius, finite) in bodies.items():
        upper = label == "A"
        w, u = getattr(result, f"surface_w_{label}"), getattr(result, f"surface_u_{label}")
        approach = overlap - c_b if upper else c_b
        outline, surface = body_geometry(result.x, w, u, radius, finite, upper, approach, window, magnify)
        what = "flat" if math.isinf(radius) else f"R = {radius:g}"
        shape = "finite cylinder" if finite else ("rigid" if kind == "rigid" else "half-space")
        drawn.append(Body(f"{label} ({shape}, {what})", outline, surface))
    return drawn, window


def _height(drawn: list[Body], window: tuple[float, float]) -> tuple[float, float]:
    """The y range [length]: the drawn curves inside the window, at least 0.3 of its width."""
    ys = []
    for body in drawn:
        for curve in (body.outline, body.surface):
            inside = (curve[0] >= window[0]) & (curve[0] <= window[1])
            ys.append(curve[1, inside])
    values = np.concatenate(ys)
    lo, hi = float(values.min()), float(values.max())
    half = max(0.55 * (hi - lo), 0.15 * (window[1] - window[0]))
    mid = 0.5 * (lo + hi)
    return mid - half, mid + half


def deformed_figure(result: Result, magnify: float = 1.0, show: bool = False) -> Figure:
    """The figure of the deformed contact region of ``result`` (equal axis scales)."""
    drawn, window = deformed_bodies(result, magnify)
    unit = result.units["length"]
    fig = _figure(show, figsize=(9.0, 4.5), layout="constrained")
    ax = fig.subplots()
    contact = result.state > 0
    for body, colour in zip(drawn, ("k", "0.35"), strict=True):
        ax.plot(*body.outline, color=colour, lw=0.8, ls="--", label=f"body {body.label}, undeformed")
        ax.plot(*body.surface, color=colour, lw=1.4, label=f"body {body.label}, deformed")
        for state, name in ((1, "adhesion"), (2, "slip")):
            on = result.state == state
            if on.any() and body is drawn[0]:
                ax.plot(*body.surface[:, on], ".", color=STATE_COLOURS[state], ms=4, label=f"{name} nodes")
    if contact.any():
        ends = drawn[0].surface[0, contact]
        ax.axvspan(float(ends.min()), float(ends.max()), color="0.92", zorder=0, label="contact")
    ax.set_xlim(*window)
    ax.set_ylim(*_height(drawn, window))
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(f"x [{unit}]")
    ax.set_ylabel(f"y [{unit}]")
    fig.legend(fontsize=7, loc="outside lower center", ncols=4)
    scale = "to scale" if magnify == 1.0 else f"displacements x{magnify:g} (surfaces overlap by (K-1) g0 in contact)"
    ax.set_title(f"{result.title or 'rolling_cli result'}\ndeformed contact region, {scale}", fontsize=9)
    return fig


def plot_deformed_file(path: str, output: str | None = None, show: bool = False, magnify: float = 1.0) -> Figure:
    """Plot the deformed contact region of a single result file; write ``output`` and/or show it.

    Raises :class:`~rolling_cli.errors.CaseError` for a sweep file or a file without displacements."""
    with h5py.File(path, "r") as handle:
        if is_sweep(handle):
            raise CaseError("--deformed: not a single result; allowed: a file written by rollc solve", file=path)
    result = read_result(path)
    if not has_displacements(result, case_bodies(result)):
        raise CaseError(
            "--deformed: the file has no surface displacements; allowed: a result written by this rollc", file=path
        )
    if not (math.isfinite(magnify) and magnify > 0.0):
        raise CaseError(f"--magnify {magnify}: allowed: a finite number > 0")
    return deliver(deformed_figure(result, magnify, show), output, show)
