"""Figures in the style of the paper, from result and sweep files.

* One result: -p_n/p0 and p_t/(mu p0) against x/a, the slip velocity on a
  second axis, the node states as shaded bands (adhesion, slip; separation is
  left blank), and the Hertz/Carter references when the file has them. x is
  centred on the contact and scaled by its half-width a; p0 is the peak
  pressure (the curves of a tyred cylinder are centred as the paper does).
* A sweep: the traction curves of its cases (at most 12, evenly picked),
  labelled by the swept values (the paper's Fig. 4 and 8); when a tangential
  quantity is swept, also the creep-force curve Q/(mu P) against the creepage:
  one line per group of cases with equal values of the other swept keys (a
  family of curves, ``rollc sweep --curve creep --set friction.mu=...``),
  labelled ``key = value`` in its legend. With friction that falls with the
  slip speed the stable branch (dQ/dxi < 0) is drawn solid, the unstable one
  dashed, and the turning points (the peaks of |Q|) are marked.

Files of format 1 are converted to the current layout first
(:mod:`rolling_cli.files.legacy`), so one reader serves both.

Figures are built with matplotlib's object API on the Agg canvas (no screen
needed); :func:`plot_file` returns the Figure so tests can inspect it.
"""

from __future__ import annotations

import os

import h5py
import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..files import outputs
from ..files.legacy import converted
from ..files.reader import case_table, is_sweep, read_case, swept_names, version
from ..result import Result

COLOURS = {"adhesion": "#cfe3f5", "slip": "#fbe0c4"}
TANGENTIAL_KEYS = ("tangential.q_over_mu_p", "tangential.q_over_p", "tangential.load", "tangential.creep")


def _scales(result: Result) -> tuple[float, float, float]:
    """Centre, a [length] and p0 [stress] used to normalise the curves."""
    a = result.attributes.get("contact_half_width", np.nan)
    centre = result.attributes.get("contact_centre", 0.0)
    if not np.isfinite(a) or a <= 0:
        a, centre = float(result.attributes.get("hertz_a", 1.0)), 0.0
    p0 = float(np.max(-result.p_n)) if np.any(result.p_n < 0) else 1.0
    return float(centre), float(a), p0


def _bands(ax, result: Result, centre: float, a: float) -> None:
    """Shade each slip/adhesion zone; the first band of each kind is labelled for the legend."""
    labelled: set[str] = set()
    for name, start, end in result.zones():
        if name in COLOURS:
            label = f"{name} zone" if name not in labelled else None
            labelled.add(name)
            ax.axvspan(
                (start - centre) / a, (end - centre) / a, color=COLOURS[name], alpha=0.8, lw=0, zorder=0, label=label
            )


def draw_result(ax, result: Result, label: str | None = None, bands: bool = True, slip_axis=None):
    """Draw one result on ``ax``; returns the slip axis used (or None)."""
    centre, a, p0 = _scales(result)
    mu = float(result.attributes.get("mu", 0.0)) or 1.0
    xi = (result.x - centre) / a
    if bands:
        _bands(ax, result, centre, a)
    suffix = f" ({label})" if label else ""
    ax.plot(xi, -result.p_n / p0, color="0.35", lw=1.2, label=r"$-p_n/p_0$" + suffix)
    line = ax.plot(xi, result.p_t / (mu * p0), lw=1.8, label=r"$p_t/(\mu p_0)$" + suffix)[0]
    if result.reference:
        if "hertz_pressure" in result.reference:
            ax.plot(xi, result.reference["hertz_pressure"] / p0, "k:", lw=1, label="Hertz")
        if "carter_traction" in result.reference:
            ax.plot(xi, result.reference["carter_traction"] / (mu * p0), "k--", lw=1, label="Carter")
    if slip_axis is not None:
        contact = result.state > 0
        slip = np.where(result.state == 2, result.s_t, np.nan)
        slip_axis.plot(xi[contact], slip[contact], color=line.get_color(), ls="-.", lw=1, label=r"$s_t$" + suffix)
    return slip_axis


def _figure(show: bool, **kwargs) -> Figure:
    """A Figure on the Agg canvas, or through pyplot (interactive backend) when it is to be shown."""
    if show:
        import matplotlib.pyplot as plt

        return plt.figure(**kwargs)
    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def result_figure(result: Result, show: bool = False) -> Figure:
    """The single-result figure."""
    fig = _figure(show, figsize=(8, 5), layout="constrained")
    ax = fig.add_subplot()
    slip_axis = ax.twinx()
    draw_result(ax, result, slip_axis=slip_axis)
    ax.set_xlabel(r"$(x - x_c)/a$ [-]")
    ax.set_ylabel(r"$-p_n/p_0$, $p_t/(\mu p_0)$ [-]")
    slip_axis.set_ylabel(r"slip velocity $s_t = \dot{s}/|V|$ [-] (slip zones)")
    attrs = result.attributes
    ax.set_title(
        f"{attrs.get('title') or 'rolling_cli result'}\n"
        f"Q/(mu P) = {attrs.get('q_over_mu_p', np.nan):.3f}, creepage = {attrs.get('creep', np.nan):.3e}, "
        f"a = {_scales(result)[1]:.4g} {attrs.get('unit_length', '')}",
        fontsize=9,
    )
    handles, labels = ax.get_legend_handles_labels()
    h2, l2 = slip_axis.get_legend_handles_labels()
    ax.legend(handles + h2, labels + l2, fontsize=8, loc="upper left")
    ax.grid(True, alpha=0.3)
    return fig


def sweep_figure(handle, show: bool = False) -> Figure:
    """The sweep figure of an open format-2 file: the tractions of (at most 12 of) its converged
    cases, and the creep-force curve when a tangential key is swept."""
    names = swept_names(handle)
    keys = list(names)
    table = case_table(handle, ["converged", "creep", "q_over_mu_p", "creep_slope", *names.values()])
    rows = np.flatnonzero(table["converged"]) if "converged" in table else np.array([], dtype=int)
    step = int(np.ceil(len(rows) / 12)) if len(rows) > 12 else 1  # at most 12 curves stay readable
    results = [read_case(handle, int(row)) for row in rows[::step]]
    labels = [", ".join(f"{k.split('.')[-1]} = {_fmt(table[names[k]][row])}" for k in keys) for row in rows[::step]]
    curve = any(k in TANGENTIAL_KEYS for k in keys)
    fig = _figure(show, figsize=(12 if curve else 8, 5), layout="constrained")
    ax = fig.add_subplot(1, 2 if curve else 1, 1)
    shown = list(zip(results, labels, strict=True))
    colours = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, max(len(shown), 1)))
    for (result, label), colour in zip(shown, colours, strict=False):
        centre, a, p0 = _scales(result)
        mu = float(result.attributes.get("mu", 0.0)) or 1.0
        ax.plot((result.x - centre) / a, result.p_t / (mu * p0), lw=1.4, color=colour, label=label)
    ax.set_xlabel(r"$(x - x_c)/a$ [-]")
    ax.set_ylabel(r"$p_t/(\mu p_0)$ [-]")
    ax.set_title(f"{len(rows)} cases, swept: {', '.join(keys)}", fontsize=9)
    if shown:
        ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    if curve:
        ax2 = fig.add_subplot(1, 2, 2)
        others = [k for k in keys if k not in TANGENTIAL_KEYS]  # the keys not on the x axis: one line each
        groups = curve_groups([table[names[k]][rows] for k in others], len(rows))
        colours = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, max(len(groups), 1)))
        slopes = table.get("creep_slope")
        for members, colour in zip(groups, colours, strict=True):
            creep, q = table["creep"][rows[members]], table["q_over_mu_p"][rows[members]]
            slope = slopes[rows[members]] if slopes is not None else np.full(len(members), np.nan)
            legend = ", ".join(f"{k} = {_fmt(table[names[k]][rows[members[0]]])}" for k in others) or None
            _draw_curve(ax2, creep, q, slope, colour, legend)
        ax2.set_xlabel(r"creepage $\xi = (V_A - V_B)/|V|$ [-]")
        ax2.set_ylabel(r"$Q/(\mu P)$ [-]")
        ax2.set_title("creep-force curve" + ("s" if len(groups) > 1 else ""), fontsize=9)
        if ax2.get_legend_handles_labels()[0]:
            ax2.legend(fontsize=7)
        ax2.axhline(0, color="0.6", lw=0.8)
        ax2.axvline(0, color="0.6", lw=0.8)
        ax2.grid(True, alpha=0.3)
    return fig


def _draw_curve(ax, creep: np.ndarray, q: np.ndarray, slope: np.ndarray, colour, legend: str | None) -> None:
    """One creep-force curve: stable runs solid, unstable ones dashed, turning points marked."""
    segments, turns = branch_segments(creep, q, slope)
    unstable_named = legend is not None  # a family's legend names the curves, not the line styles
    for k, (xs, qs, stable) in enumerate(segments):
        label = legend if k == 0 else None
        if not stable and not unstable_named:
            label, unstable_named = "unstable (dQ/dxi > 0)", True
        ax.plot(xs, qs, "o-" if stable else "o--", ms=3, color=colour, label=label)
    if turns:
        turn_x, turn_q = zip(*turns, strict=True)
        ax.plot(turn_x, turn_q, "D", ms=6, mfc="none", color=colour, label="turning point" if legend is None else None)


def branch_segments(creep, q, slope) -> tuple[list[tuple[np.ndarray, np.ndarray, bool]], list[tuple[float, float]]]:
    """The creep-force curve's points ``creep`` xi [-], ``q`` Q/(mu P) [-] with their slopes
    dQ/dxi [force/length] (NaN: not recorded) split into runs of one stability, in creepage order.

    A point is stable where Q falls as xi rises, dQ/dxi < 0 (the "rising" branch: |Q| grows with
    |xi| in the project's sign convention, Q > 0 for xi < 0; Vollebregt & Schuttelaars 2012); a
    NaN slope counts as stable (Coulomb friction has no falling branch). Neighbouring runs share
    their boundary point so the drawn line is continuous. The turning points (xi, Q) are where the
    slope changes sign, by linear interpolation of the slope between the two points around it.
    Returns ([(xi, Q, stable), ...], [(xi_turn, Q_turn), ...]).
    """
    order = np.argsort(np.asarray(creep, dtype=float), kind="stable")
    x, y, s = (np.asarray(v, dtype=float)[order] for v in (creep, q, slope))
    stable = ~(s >= 0.0)  # NaN -> stable
    if not len(x):
        return [], []
    cuts = np.flatnonzero(stable[1:] != stable[:-1]) + 1
    segments, start = [], 0
    for cut in [*cuts, len(x)]:
        stop = min(cut + 1, len(x))  # share the boundary point with the next run
        segments.append((x[start:stop], y[start:stop], bool(stable[start])))
        start = cut
    turns = []
    for cut in cuts:
        i, j = cut - 1, cut
        if np.isfinite(s[i]) and np.isfinite(s[j]) and s[i] != s[j]:
            t = s[i] / (s[i] - s[j])  # the slope's zero between the two points
            turns.append((float(x[i] + t * (x[j] - x[i])), float(max(y[i], y[j], key=abs))))
    return segments, turns


def curve_groups(columns: list[np.ndarray], count: int) -> list[np.ndarray]:
    """Positions of ``count`` cases grouped by equal values in every column (the swept keys not on a
    panel's x axis), groups in order of first appearance; one group of all when there are no columns."""
    if not columns or not count:
        return [np.arange(count)]
    codes = np.stack([np.unique(np.asarray(c), return_inverse=True)[1].ravel() for c in columns], axis=1)
    _, first, inverse = np.unique(codes, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    return [np.flatnonzero(inverse == g) for g in np.argsort(first, kind="stable")]


def _fmt(value) -> str:
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, (float, np.floating)):
        return f"{value:.4g}"
    return str(value)


def plot_file(path: str, output: str | None = None, show: bool = False) -> Figure:
    """Plot a result or sweep file (any format version); write ``output`` (.png, .pdf or .svg,
    under a temporary name, then renamed) and/or show it."""
    ext = os.path.splitext(output)[1].lower() if output else ""
    if output and ext not in FORMATS:
        raise ValueError(f"{output}: unsupported figure format; allowed: {', '.join(FORMATS)}")
    with converted(path) as source, h5py.File(source, "r") as handle:
        version(handle)
        fig = sweep_figure(handle, show) if is_sweep(handle) else result_figure(read_case(handle, 0), show)
    return deliver(fig, output, show)


def deliver(fig: Figure, output: str | None, show: bool) -> Figure:
    """Write ``fig`` to ``output`` (.png, .pdf or .svg; under a temporary name, then renamed, so no
    partial figure is left) and/or show it; ValueError for another format. Returns ``fig``."""
    if output:
        ext = os.path.splitext(output)[1].lower()
        if ext not in FORMATS:
            raise ValueError(f"{output}: unsupported figure format; allowed: {', '.join(FORMATS)}")
        with outputs.atomic_file(output, replace=True) as tmp:
            fig.savefig(tmp, format=ext[1:], dpi=150)
    if show:
        import matplotlib.pyplot as plt

        plt.show()
    return fig


FORMATS = (".png", ".pdf", ".svg")
