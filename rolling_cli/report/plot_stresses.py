"""Contour maps of the subsurface stresses of a result file (``rollc plot FILE --stresses``).

For each body with a stress field: the von Mises stress and the shear stress
tau_xz, in units of p0 (the peak contact pressure), against x/a and z/a (a the
contact scale of the mesh), depth downwards, equal aspect (a thin layer's
depth stretched by a stated factor). Above the surface a strip marks the node
states (adhesion and slip as in the traction figure), a dot the maximum von
Mises stress; a layer's bond line is dashed.
"""

from __future__ import annotations

import h5py
import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ..errors import CaseError
from ..files.io_hdf5 import read_result
from ..files.reader import is_sweep
from ..result import Result
from .plot import COLOURS, _figure, deliver

#: Filled contour levels per map (at most; rounded to nice values).
LEVELS = 20
#: A field shallower than this fraction of its width is drawn with its depth stretched.
THIN = 0.2


def stress_figure(result: Result, show: bool = False) -> Figure:
    """The figure of ``result.stresses`` (ValueError when the result has none)."""
    if not result.stresses:
        raise ValueError("the file holds no stresses; allowed: a result solved with a [stresses] table")
    bodies = list(result.stresses.values())
    first = bodies[0].attributes
    a, p0 = float(first["length_scale"]), float(first["pressure_scale"])
    x = bodies[0].arrays["x"] / a
    width = float(x[-1] - x[0])
    depth = max(float(b.arrays["z"][-1]) for b in bodies) / a
    stretch = 1.0 if depth >= THIN * width else float(np.ceil(0.3 * width / depth))
    thin = stretch > 1.0
    rows, cols = (2 * len(bodies), 1) if thin else (len(bodies), 2)
    panel_width = 10.0 if thin else 5.0
    panel_height = panel_width * stretch * depth / width + 1.2
    fig = _figure(show, figsize=(cols * panel_width + 1.5, min(rows * panel_height + 0.8, 11.0)), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).reshape(len(bodies), 2)
    for pair, stresses in zip(axes, bodies, strict=True):
        _body_maps(pair, result, stresses, a, p0, stretch)
    fig.suptitle(
        f"{result.attributes.get('title') or 'rolling_cli result'}: subsurface stresses, "
        f"p0 = {p0:.4g} {result.units['stress']}, a = {a:.4g} {result.units['length']}",
        fontsize=10,
    )
    return fig


def _body_maps(pair, result: Result, stresses, a: float, p0: float, stretch: float) -> None:
    arrays, attrs = stresses.arrays, stresses.attributes
    x, z = arrays["x"] / a, arrays["z"] / a
    label = f"body {stresses.label} ({attrs.get('model', '')})"
    tau = arrays["tau_xz"] / p0
    bound = float(np.abs(tau).max()) or 1.0
    mises = arrays["von_mises"] / p0
    maps = (
        (mises, "viridis", MaxNLocator(LEVELS).tick_values(0.0, float(mises.max()) or 1.0), "von Mises / p0"),
        (tau, "RdBu_r", MaxNLocator(LEVELS, symmetric=True).tick_values(-bound, bound), r"$\tau_{xz}$ / p0"),
    )
    for ax, (values, cmap, levels, name) in zip(pair, maps, strict=True):
        filled = ax.contourf(x, z, values, levels=levels, cmap=cmap)
        ax.contour(x, z, values, levels=levels[::4], colors="k", linewidths=0.3, alpha=0.5)
        ax.figure.colorbar(filled, ax=ax, label=name, shrink=0.9)
        _surface_states(ax, result, a, float(z[-1]))
        if "bond_depth" in attrs and attrs["bond_depth"] / a <= z[-1] * (1 + 1e-9):
            ax.axhline(attrs["bond_depth"] / a, color="k", lw=1.2, ls="--")
        ax.set_xlim(x[0], x[-1])
        ax.set_ylim(z[-1], -0.06 * z[-1])  # depth downwards, the state strip above the surface
        ax.set_aspect(stretch)
        ax.set_xlabel("x/a")
        ax.set_ylabel("z/a (depth)" + (f", stretched x{stretch:g}" if stretch > 1.0 else ""))
        ax.set_title(f"{label}: {name}" + (", bond line dashed" if "bond_depth" in attrs else ""), fontsize=9)
    if "max_von_mises" in attrs:
        pair[0].plot(attrs["max_von_mises_x"] / a, attrs["max_von_mises_z"] / a, "w.", ms=8, mec="k")


def _surface_states(ax, result: Result, a: float, depth: float) -> None:
    """Adhesion and slip as coloured bands just above the surface z = 0."""
    strip = 0.06 * depth
    for name, start, end in result.zones():
        if name in COLOURS:
            ax.fill_between([start / a, end / a], -strip, 0.0, color=COLOURS[name], lw=0, zorder=3)
            ax.fill_between([start / a, end / a], -strip, 0.0, facecolor="none", edgecolor="0.4", lw=0.4, zorder=3)
    ax.axhline(0.0, color="k", lw=0.8)


def plot_stress_file(path: str, output: str | None = None, show: bool = False) -> Figure:
    """Plot the stresses of a single result file; write ``output`` (.png, .pdf or .svg) and/or show it.

    Raises :class:`~rolling_cli.errors.CaseError` for a sweep file or a result without stresses.
    """
    with h5py.File(path, "r") as handle:
        if is_sweep(handle):
            raise CaseError("--stresses: not a single result; allowed: a file written by rollc solve", file=path)
    result = read_result(path)
    if not result.stresses:
        raise CaseError("--stresses: the result holds no stresses; allowed: a case with a [stresses] table", file=path)
    return deliver(stress_figure(result, show), output, show)
