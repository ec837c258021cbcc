"""The short on-screen summary of a result."""

from __future__ import annotations

import json
import math
import textwrap

from ..result import Result
from ..stresses import power


def _fmt(value: float | None, digits: int = 6) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "undefined"
    return f"{value:.{digits}g}"


#: Summary lines are wrapped at this width, continued under the value column.
WIDTH = 160
_INDENT = " " * 17


def _wrap(line: str) -> list[str]:
    return textwrap.wrap(line, WIDTH, subsequent_indent=_INDENT, break_on_hyphens=False) or [line]


def _sensitivity_lines(attrs, length: str, stress: str, line: str) -> list[str]:
    """The derivatives of the solve (:mod:`rolling_cli.solver.sensitivity`), when recorded."""
    if "dQ_dxi" not in attrs and "da_dP" not in attrs:
        return []
    names = ("dQ_dxi", "dQ_dmu", "dQ_dP", "dxi_dQ", "dxi_dmu", "dxi_dP", "da_dP", "dp0_dP")
    if all(_fmt(attrs.get(name)) == "undefined" for name in names):
        return ["  sensitivity    not computed (a failed solve or a singular final matrix)"]
    per_load = f"1/({line})"
    lines = [
        f"  sensitivity    creep coefficient dQ/dxi = {_fmt(attrs.get('dQ_dxi'))} {line}, "
        f"dQ/dmu = {_fmt(attrs.get('dQ_dmu'))} {line}, dQ/dP = {_fmt(attrs.get('dQ_dP'))}",
        f"{_INDENT}dxi/dQ = {_fmt(attrs.get('dxi_dQ'))} {per_load}, dxi/dmu = {_fmt(attrs.get('dxi_dmu'))}, "
        f"dxi/dP = {_fmt(attrs.get('dxi_dP'))} {per_load}",
        f"{_INDENT}da/dP = {_fmt(attrs.get('da_dP'))} {length}/({line}), "
        f"dp0/dP = {_fmt(attrs.get('dp0_dP'))} {stress}/({line})",
    ]
    if "dQ_db" in attrs:
        lines.append(
            f"{_INDENT}layer: dQ/db = {_fmt(attrs['dQ_db'])} {stress}, dxi/db = {_fmt(attrs.get('dxi_db'))} 1/{length}"
        )
    if "dQ_dV" in attrs:  # a slip-speed friction law (its dmu: the law scaled as a whole)
        speed = f"{length}/{attrs.get('unit_time') or 'time'}"
        lines.append(
            f"{_INDENT}rolling speed: dQ/dV = {_fmt(attrs['dQ_dV'])} {line}/({speed}), "
            f"dxi/dV = {_fmt(attrs.get('dxi_dV'))} 1/({speed}) (dmu: the law scaled as a whole)"
        )
    return lines


def _resistance_lines(attrs, length: str, line: str) -> list[str]:
    """The viscoelastic outputs, one line each (:mod:`rolling_cli.model.resistance`)."""
    moments = f"M = {_fmt(attrs['rolling_resistance_moment'])} {line} {length}"
    for label in ("a", "b"):
        value = attrs.get(f"rolling_resistance_moment_{label}", math.nan)
        if not math.isnan(value):
            moments += f", M_{label.upper()} = {_fmt(value)} (shaft {label.upper()})"
    coefficient = f"M/(P R*) = {_fmt(attrs['rolling_resistance_coefficient'])}"
    force = attrs.get("rolling_resistance_force", math.nan)
    if force is not None and not math.isnan(force):  # a finite roller on a flat (model/power_balance.py)
        coefficient = (
            f"F_rr/P = {_fmt(attrs['rolling_resistance_coefficient'])}, F_rr = {_fmt(force)} {line} "
            f"(the power balance's force: losses / |V| + xi Q)"
        )
    return [
        f"  resistance     {moments}",
        f"  coefficient    {coefficient}",
        f"  pressure shift {_fmt(attrs['pressure_shift'])} {length} towards the leading edge "
        f"(centroid x = {_fmt(attrs['pressure_centroid'])} {length})",
        f"  hysteresis     {_fmt(attrs['hysteresis_power'])} {line} per unit rolling speed (loss in the bodies)",
    ]


def _effects_lines(attrs) -> list[str]:
    """One line per effect (what was simulated or skipped, and why), then the plan's warnings."""
    effects = json.loads(attrs.get("effects", "{}")) if attrs.get("effects") else {}
    notes = [f"{name}: {text}" for name, text in effects.get("notes", {}).items()]
    lines = [
        ("  effects        " if k == 0 else _INDENT) + note
        for k, note in enumerate(notes or [attrs.get("effects_line", "")])
    ]
    return lines + [f"  WARNING        {warning}" for warning in effects.get("warnings", [])]


def _accuracy_lines(attrs) -> list[str]:
    """The adaptive mesh's accuracy line and note, and the a-posteriori error estimate, when recorded."""
    from ..adapt.levels import summary_line  # imported when a summary is printed (not by rollc -q)

    lines = []
    accuracy = summary_line(attrs)
    if accuracy:
        lines.append(accuracy)
        if attrs.get("adaptive_note"):
            lines.append(f"  WARNING        {attrs['adaptive_note']}")
    if attrs.get("error_estimate_note"):
        lines.append(f"  error estimate {attrs['error_estimate_note']}")
    elif "error_estimate" in attrs:
        lines.append(
            f"  error estimate against {attrs.get('error_estimate_elements')} elements "
            f"({attrs.get('error_estimate_method', 'half mesh')}): "
            f"traction max {_fmt(attrs['error_estimate'], 3)}, RMS {_fmt(attrs.get('error_estimate_rms'), 3)} "
            f"(of mu p0); creepage {_fmt(attrs.get('error_estimate_creep'), 3)}, load "
            f"{_fmt(attrs.get('error_estimate_load'), 3)} (relative)"
        )
    return lines


def summary(result: Result, output: str | None = None) -> str:
    """Multi-line text: convergence, loads, creepage, zones, effects and times."""
    u = result.units
    length, stress, line = u["length"], u["stress"], u["force/length"]
    attrs = result.attributes
    lines = []
    title = attrs.get("title") or "rolling_cli result"
    lines.append(title)
    status = "yes" if attrs.get("converged") else "NO"
    lines.append(
        f"  converged      {status}, {attrs.get('iterations')} Newton iterations, "
        f"relative residual {attrs.get('residual', math.nan):.2e}"
    )
    lines.extend(_effects_lines(attrs))
    lines.append(
        f"  loads          P = {_fmt(attrs['normal_load'])} {line}, Q = {_fmt(attrs['tangential_load'])} {line}, "
        f"Q/(mu P) = {_fmt(attrs.get('q_over_mu_p'), 5)} "
        + (
            f"(mu = mu_static = {_fmt(attrs['mu'])}, {attrs['friction_law']} law)"
            if attrs.get("friction_law")
            else f"(mu = {_fmt(attrs['mu'])})"
        )
    )
    arc = attrs.get("arc_load")
    if arc is not None and math.isfinite(arc):  # a finite cylinder: P is the load on its shaft
        lines.append(
            f"  shaft          P is the load on the shaft (arc sum -sum w p_n = {_fmt(arc)} {line}), "
            f"Q = torque / R; bearing force across {_fmt(attrs.get('shaft_tangential_load'))} {line}"
        )
    creep = f"  creepage       xi = {_fmt(attrs['creep'])}"
    if "carter_creep" in attrs:
        creep += f" (Carter{' with mu_static' if attrs.get('friction_law') else ''}: {_fmt(attrs['carter_creep'])})"
    if attrs.get("branch"):
        creep += f", {attrs['branch']} branch (dQ/dxi = {_fmt(attrs.get('creep_slope'))} {line})"
    lines.append(creep)
    lines.extend(_sensitivity_lines(attrs, length, stress, line))

    if attrs.get("branch_note"):
        lines.append(f"  branches       {attrs['branch_note']}")
    overlap = attrs.get("overlap", math.nan)
    if not math.isnan(overlap):
        lines.append(f"  overlap        {_fmt(overlap)} {length}")
    lines.append(
        f"  Hertz          a = {_fmt(attrs['hertz_a'])} {length}, p0 = {_fmt(attrs['hertz_p0'])} {stress}, "
        f"beta (Dundurs) = {_fmt(attrs['beta_dundurs'], 4)}"
        + (" (relaxed moduli)" if "rolling_resistance_moment" in attrs else "")
    )
    lines.append(
        f"  contact        half-width {_fmt(attrs.get('contact_half_width'))} {length}, "
        f"centre {_fmt(attrs.get('contact_centre'), 4)} {length}"
    )
    if attrs.get("validity_warning"):
        lines.append(f"  WARNING        {attrs['validity_warning']}")
    if attrs.get("zone_note"):
        lines.append(f"  NOTE           {attrs['zone_note']}")
    for name, start, end in result.zones():
        if name == "separation":
            continue
        lines.append(f"  {name:<14} x = {start:.5g} .. {end:.5g} {length}")
    lines.extend(_accuracy_lines(attrs))
    if "rolling_resistance_moment" in attrs:  # a viscoelastic body
        lines.extend(_resistance_lines(attrs, length, line))
    power_line = power.summary_line(attrs, line)
    if power_line:
        lines.append(power_line)
    if "stress_bodies" in attrs:
        from ..stresses.report import summary_lines

        lines.extend(summary_lines(attrs, u))
    lines.append(
        f"  time           influence {attrs.get('time_influence', 0.0):.3f} s, "
        f"Newton {attrs.get('time_solve', 0.0):.3f} s"
        + (f", stresses {attrs['time_stresses']:.3f} s" if "time_stresses" in attrs else "")
    )
    if attrs.get("message"):
        lines.append(f"  failure        {attrs['message']}")
    if output:
        lines.append(f"  written        {output}")
    return "\n".join(wrapped for line in lines for wrapped in _wrap(line))
