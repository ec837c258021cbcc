"""Stress indicators of a result: :func:`attach` (one call after a solve), maxima, notes, summary lines.

Indicators (:data:`INDICATORS`), each with its maximum over the requested
bodies, where (x/a, z/a) and which body:

* ``von_mises``: the von Mises stress;
* ``tresca``: sigma_1 - sigma_3 (twice the maximum shear);
* ``tau_xz_range``: the orthogonal shear range over a rolling pass at a depth
  (its x is undefined: NaN);
* ``sigma_1``: the largest principal stress (tension where > 0);
* ``surface_tension``: the largest surface sigma_xx (tension where > 0), on
  the surface samples;
* ``bond_shear`` and ``bond_tension``: the largest |tau_xz| and sigma_zz on a
  layer's bond line.

Where the maxima are looked for: the field grid, and the surface samples
(``surface_x``: the contact nodes and the located contact edges and stick/slip
boundaries, :func:`rolling_cli.adapt.kinks.locate_kinks`), where the surface
stresses peak in square-root cusps that a grid would miss by the square root
of its distance (the trailing-edge tension of Carter's case read 6 % low at
0.0025 a). The field-grid indicators (von Mises, Tresca, sigma_1) take the
larger of both; the surface tension is the samples'. Half-plane surface
values come from a continuous traction with square-root contact edges and
stick/slip boundaries (:mod:`.surface`), so they do not depend on where the
samples fall.

Scales: a is the mesh's contact scale (the plan's half-width) and p0 the peak
contact pressure max(-p_n).
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

#: name -> (description, dataset, how): "max" of a (z, x) field, "depth" for a (z,) profile,
#: "surface" / "bond" for the surface or bond-line arrays, "abs" for the largest magnitude.
INDICATORS = {
    "von_mises": ("von Mises stress", "von_mises", "max"),
    "tresca": ("Tresca stress sigma_1 - sigma_3", "tresca", "max"),
    "tau_xz_range": ("orthogonal shear range over a rolling pass", "tau_xz_range", "depth"),
    "sigma_1": ("largest principal stress (tension > 0)", "sigma_1", "max"),
    "surface_tension": ("largest surface sigma_xx (tension > 0)", "surface_sigma_xx", "surface"),
    "bond_shear": ("largest |tau_xz| on the bond line", "bond_tau_xz", "bond_abs"),
    "bond_tension": ("largest sigma_zz on the bond line (tension > 0)", "bond_sigma_zz", "bond"),
}


def attach(case, the_plan, result):
    """Compute the requested stress fields of a solved ``result`` and store them in it; returns it.

    Does nothing without a [stresses] table; a result that did not converge
    gets no fields and an effects note saying so. Sets ``result.stresses``
    (label -> :class:`~rolling_cli.stresses.compute.BodyStresses`), the root
    attributes ``stress_max_<indicator>`` [stress] with ``_x_over_a``,
    ``_z_over_a`` and ``_body``, and ``time_stresses`` [s].
    """
    if case.stresses is None:
        return result
    if not result.attributes.get("converged", False):
        set_note(result, "skipped: the solve did not converge")
        return result
    from ..adapt.kinks import locate_kinks
    from .compute import compute_stresses  # the stress machinery is imported only when it runs

    start = time.perf_counter()
    kinks = locate_kinks(result, the_plan.grid)
    bodies = compute_stresses(case, the_plan, result.p_n, result.p_t, kinks)
    if not bodies:  # only rigid bodies requested (the effects note says so)
        return result
    a = float(the_plan.half_width)
    p0 = float(np.max(-result.p_n)) if np.any(result.p_n < 0.0) else math.nan
    for stresses in bodies.values():
        stresses.attributes.update({"length_scale": a, "pressure_scale": p0, **maxima(stresses)})
        stresses.attributes.update({"unit_length": case.units.length, "unit_stress": case.units.stress})
    result.stresses = bodies
    result.attributes.update(root_attributes(bodies, a, p0))
    result.attributes["time_stresses"] = time.perf_counter() - start
    return result


def maxima(stresses) -> dict:
    """Per-body indicator maxima: ``max_<name>`` [stress], ``max_<name>_x``, ``max_<name>_z`` [length].

    A field indicator's maximum is the larger of the field grid's and the
    surface samples' (module docstring).
    """
    arrays = stresses.arrays
    on_surface = surface_invariants(stresses)
    out = {}
    for name, (_, dataset, how) in INDICATORS.items():
        if dataset not in arrays:
            continue
        values = arrays[dataset]
        if how == "max":
            iz, ix = np.unravel_index(np.argmax(values), values.shape)
            found = (values[iz, ix], arrays["x"][ix], arrays["z"][iz])
            if dataset in on_surface:
                i = int(np.argmax(on_surface[dataset]))
                if on_surface[dataset][i] > found[0]:
                    found = (on_surface[dataset][i], arrays["surface_x"][i], 0.0)
        elif how == "depth":
            iz = np.argmax(values)
            found = (values[iz], math.nan, arrays["z"][iz])
        elif how == "surface":
            i = int(np.argmax(values))
            found = (values[i], arrays["surface_x"][i], 0.0)
        else:
            magnitude = np.abs(values) if how == "bond_abs" else values
            i = int(np.argmax(magnitude))
            found = (magnitude[i], arrays["bond_x"][i], stresses.attributes.get("bond_depth", math.nan))
        out[f"max_{name}"], out[f"max_{name}_x"], out[f"max_{name}_z"] = (float(v) for v in found)
    return out


def surface_invariants(stresses) -> dict[str, np.ndarray]:
    """The derived stresses (:func:`~rolling_cli.stresses.compute.derived`) at the surface samples ({} without them)."""
    arrays = stresses.arrays
    if "surface_sigma_zz" not in arrays:
        return {}
    from .compute import derived

    poisson = float(stresses.attributes["poisson"])
    sxx, szz, txz = (arrays[f"surface_{name}"][None, :] for name in ("sigma_xx", "sigma_zz", "tau_xz"))
    return {name: values[0] for name, values in derived(sxx, szz, txz, poisson).items() if values.ndim == 2}


def root_attributes(bodies: dict, a: float, p0: float) -> dict:
    """The largest value of every indicator over the bodies, with (x/a, z/a) and the body."""
    out = {"stress_bodies": ", ".join(bodies), "stress_length_scale": a, "stress_pressure_scale": p0}
    for name in INDICATORS:
        found = [(s.attributes[f"max_{name}"], label) for label, s in bodies.items() if f"max_{name}" in s.attributes]
        if not found:
            continue
        value, label = max(found)
        attrs = bodies[label].attributes
        out[f"stress_max_{name}"] = value
        out[f"stress_max_{name}_x_over_a"] = attrs[f"max_{name}_x"] / a
        out[f"stress_max_{name}_z_over_a"] = attrs[f"max_{name}_z"] / a
        out[f"stress_max_{name}_body"] = label
    return out


def planned_note(case) -> str:
    """The effects note of a case with a [stresses] table: which bodies get which model."""
    from .compute import model_name

    parts, skipped = [], []
    for label in case.stresses.bodies:
        model = model_name(case, label)
        if model == "rigid":
            skipped.append(label)
        else:
            parts.append(f"{label} ({model})")
    nx, nz = case.stresses.points
    text = f"simulated: {', '.join(parts)}, {nx} x {nz} points" if parts else "skipped: no deformable body requested"
    if skipped:
        text += f"; {', '.join(skipped)} skipped (rigid: no stress field)"
    return text


def set_note(result, text: str) -> None:
    """Replace the ``stresses`` effects note of a result (its JSON and its summary line)."""
    effects = json.loads(result.attributes.get("effects") or "{}")
    notes = effects.setdefault("notes", {})
    notes["stresses"] = text
    result.attributes["effects"] = json.dumps(effects)
    result.attributes["effects_line"] = "; ".join(f"{name}: {note}" for name, note in notes.items())


def summary_lines(attributes: Mapping[str, Any], units: dict) -> list[str]:
    """Screen lines for the stress maxima in a result's attributes ([] when there are none)."""
    if "stress_bodies" not in attributes:
        return []
    stress = units["stress"]
    p0 = attributes.get("stress_pressure_scale", math.nan)
    lines = [f"  stresses       bodies {attributes['stress_bodies']}; p0 = {p0:.6g} {stress} (peak pressure)"]
    labels = {
        "von_mises": "von Mises",
        "tresca": "Tresca",
        "tau_xz_range": "orth. shear",
        "sigma_1": "principal max",
        "surface_tension": "surface sxx",
        "bond_shear": "bond |txz|",
        "bond_tension": "bond szz",
    }
    for name, label in labels.items():
        key = f"stress_max_{name}"
        if key not in attributes:
            continue
        value = attributes[key]
        x, z = attributes[f"{key}_x_over_a"], attributes[f"{key}_z_over_a"]
        where = f"z/a = {z:.3f}" if math.isnan(x) else f"x/a = {x:.3f}, z/a = {z:.3f}"
        what = "range" if name == "tau_xz_range" else "max"
        body = attributes[key + "_body"]
        lines.append(f"  {label:<14} {what} {value / p0:.4g} p0 = {value:.5g} {stress} at {where} (body {body})")
    return lines
