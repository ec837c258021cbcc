"""What accuracy costs in time: measured error against mesh size and run time.

Cases (all at their shipped settings otherwise):
* Carter (cases/carter.toml, similar, Q/(mu P) = 0.51): exact reference.
* Dissimilar (cases/dissimilar_q04.toml, beta_seed = 0.288, Q/(mu P) = 0.04):
  reference = the adaptive half-plane solution at tolerance 1e-4 (graded mesh,
  interpolated with its element polynomials; its own estimate and the uniform
  runs of 320-1280 elements against it are shown).
* Tyred cylinder (cases/tyred_fig11_q41.toml, incompressible layer, b/a = 0.1):
  reference = the finest BEM solution (the half-plane model cannot do layers).

Methods: influence BEM or half-plane x slip derivative "fd" or "element",
contact elements 5 to 640 (the layer needs at least 60: elements <= b/2).
Measures, on each run's own nodes: max and RMS traction error / (mu p0),
creepage error, stick/slip boundary positions / a, influence and Newton
times (cache off: cold builds), Newton iterations; and the half-mesh error
estimate of ``rollc solve --error-estimate`` against the true error.

The defaults are run as a user gets them (``influence = "auto"``: the closed
form for the two half-space cases, the BEM for the layer) and with the BEM
forced. A last table states the BEM's creepage error against the closed form
on the same grid (a model error: the discretisations are the same), before
issue #10 (the finite block, bottom fixed and sides free, W = D = 100 a) and
after (the half-space with the far-field truncation).

**Accuracy on demand** (issue #13): the adaptive mode (``[discretization]
tolerance``: graded meshes on the half-plane and on the BEM)
against the uniform default route (``influence = "auto"``, fd), both timed as
WHOLE processes (``rollc -q solve CASE --no-cache`` in a subprocess, fastest
of 3; start-up included), with the table "tolerance requested -> error
achieved -> time".

Writes benchmarks/results/accuracy_cost.md (tables) and accuracy_cost.png
(error against time, log-log, one line per method, Pareto front in grey; the
last row: adaptive and uniform against whole-process time).

    python benchmarks/accuracy_cost.py [--quick]
"""

from __future__ import annotations

import argparse
import datetime
import logging
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.adapt import transfer  # noqa: E402
from rolling_cli.case import case_to_toml, load_case, with_overrides  # noqa: E402
from rolling_cli.errors import RollingError  # noqa: E402
from rolling_cli.files.io_hdf5 import read_result  # noqa: E402
from rolling_cli.influence import bem, combine  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.model.grid import ContactGrid  # noqa: E402
from rolling_cli.pipeline import plan  # noqa: E402
from rolling_cli.pipeline.estimate import add_error_estimate  # noqa: E402
from rolling_cli.references import carter  # noqa: E402
from rolling_cli.solver.system import build_system  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
METHODS = [("half-plane", "fd"), ("half-plane", "element"), ("bem", "fd"), ("bem", "element")]


def run(case):
    clear_memo()
    t = time.perf_counter()
    r = rolling_cli.solve(case, use_cache=False)
    return r, time.perf_counter() - t


def boundaries(r) -> np.ndarray:
    """x of every adhesion/slip boundary (midway between the two nodes)."""
    s = r.state
    idx = np.flatnonzero((s[1:] != s[:-1]) & (s[1:] > 0) & (s[:-1] > 0))
    return 0.5 * (r.x[idx] + r.x[idx + 1])


class Reference:
    """Reference tractions, creepage and boundaries; exact (Carter) or a fine run."""

    def __init__(self, result=None, exact=None):
        self.result, self.exact = result, exact

    def traction(self, r):
        if self.exact:
            return carter.traction(r.x, 0.51, r.hertz_a, r.hertz_p0, r.mu, -1)
        if "element_edges" in self.result.attributes:  # a graded reference: its element polynomials
            grid = ContactGrid.graded(self.result.element_edges, self.result.element_order)
            return transfer.interpolate(grid, self.result.p_t, r.x)
        return np.interp(r.x, self.result.x, self.result.p_t)

    def creep(self, r):
        return carter.creepage(0.51, r.hertz_a, 50.0, r.mu) if self.exact else self.result.creep

    def boundaries(self, r):
        if self.exact:
            return np.array([r.hertz_a * (1.0 - 2.0 * math.sqrt(1.0 - 0.51))])
        return boundaries(self.result)

    def scale(self, r):
        p0 = r.hertz_p0 if self.exact else float(np.max(-self.result.p_n))
        return r.mu * p0

    def half_width(self, r):
        return r.hertz_a if self.exact else self.result.contact_half_width

    def resolution(self) -> float:
        """The reference's own maximum error bound [-]: 0 for the closed form, its adaptive estimate,
        or NaN (a uniform reference: not estimated)."""
        if self.exact:
            return 0.0
        return float(self.result.attributes.get("adaptive_estimate", math.nan))


def measure(r, seconds, ref: Reference) -> dict:
    scale = ref.scale(r)
    err = np.abs(r.p_t - ref.traction(r)) / scale
    contact = r.p_n < 0
    b, b_ref = boundaries(r), ref.boundaries(r)
    boundary = float(np.max(np.abs(b - b_ref)) / ref.half_width(r)) if b.size == b_ref.size else math.nan
    return {
        "max": float(err.max()),
        "rms": float(np.sqrt(np.mean(err[contact] ** 2))),
        "creep": abs(r.creep / ref.creep(r) - 1.0),
        "boundary": boundary,
        "t_influence": r.time_influence,
        "t_newton": r.time_solve,
        "total": seconds,
        "iterations": r.iterations,
        "nodes": r.x.size,
    }


def study(name, base, methods, elements, ref, estimate_for="fd"):
    rows = []
    for influence, scheme in methods:
        for n in elements:
            case = with_overrides(
                base,
                {
                    "discretization.influence": influence,
                    "discretization.slip_derivative": scheme,
                    "discretization.contact_elements": n,
                },
            )
            try:
                r, seconds = run(case)
            except RollingError as err:
                print(f"  {name} {influence} {scheme} {n}: {err}", flush=True)
                continue
            row = {"case": name, "influence": influence, "scheme": scheme, "elements": n, **measure(r, seconds, ref)}
            if scheme == estimate_for and n >= 10:
                add_error_estimate(case, r, use_cache=False)
                row["est_max"] = r.error_estimate
                row["est_rms"] = r.error_estimate_rms
                row["est_creep"] = r.error_estimate_creep
            rows.append(row)
            print(
                f"  {name:10s} {influence:10s} {scheme:7s} {n:4d}  max {row['max']:.2e} rms {row['rms']:.2e} "
                f"creep {row['creep']:.1e}  {seconds:.2f} s",
                flush=True,
            )
    return rows


def order(rows, key, low=20):
    ns = np.array([r["elements"] for r in rows if r["elements"] >= low and r[key] > 0 and np.isfinite(r[key])])
    es = np.array([r[key] for r in rows if r["elements"] >= low and r[key] > 0 and np.isfinite(r[key])])
    if ns.size < 3:
        return math.nan
    return float(-np.polyfit(np.log(ns), np.log(es), 1)[0])


def needed(rows, key, target):
    """The fewest elements from which every finer mesh meets the target (alignment luck excluded)."""
    ordered = sorted(rows, key=lambda r: r["elements"])
    for k, row in enumerate(ordered):
        if all(r[key] <= target for r in ordered[k:]):
            return row
    return None


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer meshes (for a smoke run)")
    args = parser.parse_args()
    logging.getLogger("rolling_cli").setLevel(logging.ERROR)  # the capped adaptive runs warn
    OUT.mkdir(parents=True, exist_ok=True)
    full = [5, 10, 20, 40, 80, 160, 320, 640]
    elements = [5, 20, 80] if args.quick else full
    started = time.perf_counter()

    rows = []
    print("Carter", flush=True)
    rows += study("Carter", load_case(ROOT / "cases" / "carter.toml"), METHODS, elements, Reference(exact=True))

    print("dissimilar: reference", flush=True)
    dis = load_case(ROOT / "cases" / "dissimilar_q04.toml")
    finest = run(adaptive_case(dis, 1e-4, refinements=12))[0]
    ref_levels = [160, 320] if args.quick else [320, 640, 1280]
    self_conv = []
    for n in ref_levels:
        m = measure(run(with_overrides(dis, {"discretization.contact_elements": n}))[0], 0.0, Reference(finest))
        self_conv.append((n, m["max"], m["rms"], m["creep"]))
    rows += study("dissimilar", dis, METHODS, elements, Reference(finest))

    print("tyred: reference", flush=True)
    tyre = load_case(ROOT / "cases" / "tyred_fig11_q41.toml")
    tyre_ref_n = 320 if args.quick else 640
    tyre_ref = run(with_overrides(tyre, {"discretization.contact_elements": tyre_ref_n}))[0]
    tyre_elements = [60, 120] if args.quick else [60, 80, 120, 160, 240, 320]
    rows += study("tyred", tyre, [("bem", "fd"), ("bem", "element")], tyre_elements, Reference(tyre_ref))

    print("defaults", flush=True)
    defaults = []
    for name, base, ref in (
        ("Carter", load_case(ROOT / "cases" / "carter.toml"), Reference(exact=True)),
        ("dissimilar", dis, Reference(finest)),
        ("tyred", tyre, Reference(tyre_ref)),
    ):
        for influence in ("auto", "bem") if name != "tyred" else ("auto",):
            case = with_overrides(base, {"discretization.influence": influence, "discretization.slip_derivative": "fd"})
            if name != "tyred":  # the schema defaults (the tyred case keeps its shipped 100 elements)
                case = with_overrides(case, {"discretization.contact_elements": 200})
            r, seconds = run(case)
            label = f"{influence} ({r.influence})" if influence == "auto" else "bem (forced)"
            defaults.append({"case": name, "model": label, "elements": case.discretization.contact_elements})
            defaults[-1].update(measure(r, seconds, ref))
    print("BEM creepage model error, before and after issue #10", flush=True)
    model = model_error(200 if not args.quick else 60)
    print("accuracy on demand: adaptive and uniform, whole process", flush=True)
    references = {"Carter": Reference(exact=True), "dissimilar": Reference(finest), "tyred": Reference(tyre_ref)}
    whole = whole_process_study(
        {"Carter": load_case(ROOT / "cases" / "carter.toml"), "dissimilar": dis, "tyred": tyre},
        references,
        args.quick,
    )
    startup = startup_time()
    write_markdown(rows, self_conv, finest, tyre_ref_n, time.perf_counter() - started, defaults, model)
    write_adaptive_markdown(whole, startup)
    write_plot(rows, whole)
    print(f"written {OUT / 'accuracy_cost.md'} and {OUT / 'accuracy_cost.png'}")


#: Tolerances of the adaptive runs (graded levels on both models; benchmarks/graded_bem.py for the tyred case).
TOLERANCES = {
    "Carter": [1e-2, 3e-3, 1e-3, 3e-4, 1e-4],
    "dissimilar": [1e-2, 3e-3, 1e-3, 3e-4],
    "tyred": [0.1, 0.05, 0.03, 0.02],
}
#: Uniform meshes of the default route timed the same way.
UNIFORM = {
    "Carter": [20, 40, 80, 160, 320, 640],
    "dissimilar": [20, 40, 80, 160, 320, 640],
    "tyred": [60, 80, 120, 160, 240, 320],
}


def adaptive_case(base, tolerance: float, refinements: int = 10):
    """``base`` in the adaptive mode at ``tolerance`` (fd, its own starting mesh)."""
    return with_overrides(base, {"discretization.tolerance": tolerance, "discretization.max_refinements": refinements})


def rollc(case, repeats: int):
    """``rollc -q solve`` of ``case`` in a subprocess (cache off): the result and the fastest wall time."""
    exe = Path(sys.executable).with_name("rollc")
    command = [str(exe)] if exe.exists() else [sys.executable, "-m", "rolling_cli"]
    best, result = math.inf, None
    with tempfile.TemporaryDirectory() as tmp:
        path, out = Path(tmp) / "case.toml", Path(tmp) / "case.h5"
        path.write_text(case_to_toml(case))
        for _ in range(repeats):
            t = time.perf_counter()
            subprocess.run(
                [*command, "-q", "solve", str(path), "-o", str(out), "--no-cache", "--overwrite"],
                check=True,
                env=os.environ,
            )
            best = min(best, time.perf_counter() - t)
        result = read_result(out)
    return result, best


def startup_time(repeats: int = 5) -> float:
    """Whole-process time of ``rollc --version`` plus the imports a solve needs [s] (fastest)."""
    code = "import rolling_cli.cli, rolling_cli.pipeline, rolling_cli.files.io_hdf5"
    best = math.inf
    for _ in range(repeats):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], check=True)
        best = min(best, time.perf_counter() - t)
    return best


def whole_process_study(bases: dict, references: dict, quick: bool) -> list[dict]:
    """Adaptive runs at each tolerance and uniform runs of the default route, whole process."""
    repeats = 1 if quick else 3
    rows = []
    for name, base in bases.items():
        base = with_overrides(base, {"discretization.influence": "auto", "discretization.slip_derivative": "fd"})
        tolerances = TOLERANCES[name][:2] if quick else TOLERANCES[name]
        sizes = UNIFORM[name][:3] if quick else UNIFORM[name]
        runs = [("adaptive", tol, adaptive_case(base, tol)) for tol in tolerances]
        runs += [("uniform", n, with_overrides(base, {"discretization.contact_elements": n})) for n in sizes]
        for mode, value, case in runs:
            r, seconds = rollc(case, repeats)
            row = {"case": name, "mode": mode, "value": value, **measure(r, seconds, references[name])}
            row.update(
                elements=r.contact_elements,
                in_process=float(r.time_total_solve),
                influence_model=r.influence,
                estimate=float(r.attributes.get("adaptive_estimate", math.nan)),
                met=bool(r.attributes.get("adaptive_met", False)),
                refinements=int(r.attributes.get("adaptive_refinements", 0)),
                note=str(r.attributes.get("adaptive_note", "")),
                resolution=references[name].resolution(),
            )
            rows.append(row)
            print(
                f"  {name:10s} {mode:8s} {value:g}: {row['elements']} elements, max {row['max']:.2e}, "
                f"creep {row['creep']:.1e}, {seconds:.2f} s whole process, {row['in_process']:.3f} s in process",
                flush=True,
            )
    return rows


def block_system(case):
    """The contact system of the old BEM model (finite blocks, bottom fixed, sides free) for ``case``."""
    the_plan = plan(case)
    grid, disc = the_plan.grid, case.discretization
    bodies = []
    for body in (case.bodies.A, case.bodies.B):
        if body.rigid:
            bodies.append(None)
            continue
        size = disc.block_width * the_plan.half_width
        mesh = bem.body_mesh(grid, size, disc.block_depth * the_plan.half_width)  # no far field
        bodies.append(bem.condensed(mesh, grid, float(body.young), float(body.poisson)))
    pair = combine(bodies[0], bodies[1], coupling=True)
    return build_system(pair, the_plan.radius, case.rolling.direction, grid.spacing, disc.slip_derivative)


def model_error(elements: int) -> list[dict]:
    """BEM creepage / half-plane creepage - 1 on the same grid: the old block and the half-space."""
    carter_case = load_case(ROOT / "cases" / "carter.toml")
    rigid = {
        "bodies.A": {"kind": "rigid", "radius": 50.0},
        "bodies.B": {"kind": "elastic", "radius": float("inf"), "young": 1.0e4, "poisson": 0.5},
        "normal.load": 100.0,
        "tangential.q_over_mu_p": 0.5,
    }
    studies = [
        (f"rigid on nu = 0.5 (Carter exact), mu = {mu}", with_overrides(carter_case, {**rigid, "friction.mu": mu}))
        for mu in (0.1, 0.01, 0.001)
    ]
    dis = load_case(ROOT / "cases" / "dissimilar_q04.toml")
    studies += [
        (f"aluminium on steel, Q/(mu P) = {q}", with_overrides(dis, {"tangential.q_over_mu_p": q}))
        for q in (0.04, 0.75, -0.83)
    ]
    out = []
    for label, base in studies:
        case = with_overrides(base, {"discretization.contact_elements": elements, "effects.coupling": "on"})
        hp = rolling_cli.solve(with_overrides(case, {"discretization.influence": "half-plane"}))
        bem_case = with_overrides(case, {"discretization.influence": "bem"})
        new = rolling_cli.solve(bem_case, use_cache=False)
        old = rolling_cli.solve(bem_case, system=block_system(bem_case), use_cache=False)
        row = {"case": label, "elements": elements, "half-plane": hp.creep, "block": old.creep, "half-space": new.creep}
        row["carter"] = getattr(hp, "carter_creep", math.nan) if "Carter" in label else math.nan
        out.append(row)
        print(f"  {label}: half-plane {hp.creep:.4e} block {old.creep:.4e} half-space {new.creep:.4e}", flush=True)
    return out


def write_markdown(rows, self_conv, finest, tyre_ref_n, seconds, defaults, model):
    lines = [
        "# What accuracy costs",
        "",
        f"Generated by `benchmarks/accuracy_cost.py` on {datetime.date.today().isoformat()}, "
        f"{platform.machine()} VM with 2 cores, Python {platform.python_version()}, rolling_cli "
        f"{rolling_cli.__version__}; the study took {seconds / 60:.1f} min. Errors on each run's own nodes: "
        "traction / (mu p0), creepage relative, stick/slip boundaries / a. Times: influence (cold, cache off; "
        "for overlap and layer cases including the coarse pre-solves) and Newton, seconds. "
        "Each run's error estimate (`--error-estimate`: half the elements; twice as many, differences x 3.41, "
        "where the half mesh breaks the layer's b/2 rule: tyred 60 and 80) is shown for the fd scheme. "
        "The maximum error is set by the node next to a square-root kink (contact edge, stick/slip boundary) "
        "and depends on where the kink falls within a node cell, so it is not monotone in the mesh; "
        "the RMS error is. Errors within a factor 2 of the numerical references' resolution are "
        "underestimated (their own errors are shown).",
        "",
        "## The defaults (influence auto, fd slip derivative, zone 1.5 a, 200 contact elements)",
        "",
        "| case | influence | elements | max | RMS | creepage | influence [s] | Newton [s] | total [s] |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for d in defaults:
        lines.append(
            f"| {d['case']} | {d['model']} | {d['elements']} | {d['max']:.2e} | {d['rms']:.2e} | {d['creep']:.1e} | "
            f"{d['t_influence']:.2f} | {d['t_newton']:.3f} | {d['total']:.2f} |"
        )
    lines += [
        "",
        "## BEM creepage against the closed form on the same grid (model error), before and after issue #10",
        "",
        "Coupling forced on (so that a pair with beta = 0 also shows its cross blocks). Before: the finite "
        "block (bottom fixed, sides free, W = D = 100 a), whose uniform lateral strain from P and Q shifts the "
        "creepage by a fixed amount, so that its relative error grows without bound as mu or Q/(mu P) go to 0. "
        "After: the half-space (far-field truncation).",
        "",
        "| case | elements | half-plane creepage | Carter | block: / half-plane - 1 | half-space: / half-plane - 1 |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for m in model:
        carter_cell = f"{m['carter']:.4e}" if math.isfinite(m["carter"]) else "-"
        lines.append(
            f"| {m['case']} | {m['elements']} | {m['half-plane']:.4e} | {carter_cell} | "
            f"{m['block'] / m['half-plane'] - 1:+.2e} | {m['half-space'] / m['half-plane'] - 1:+.2e} |"
        )
    lines += [""]
    for name in ("Carter", "dissimilar", "tyred"):
        subset = [r for r in rows if r["case"] == name]
        lines += [f"## {name}", ""]
        if name == "dissimilar":
            lines += [
                f"Reference: the adaptive half-plane solution at tolerance 1e-4 ({finest.contact_elements} "
                f"graded elements, its own estimate {finest.adaptive_estimate:.1e} mu p0"
                + ("" if finest.adaptive_met else ", the tolerance not met")
                + "). The uniform half-plane runs of 320-1280 elements against it:",
                "",
                "| elements | max | RMS | creepage |",
                "|---:|---:|---:|---:|",
            ]
            lines += [f"| {n} | {a:.2e} | {b:.2e} | {c:.1e} |" for n, a, b, c in self_conv]
            lines += [""]
        if name == "tyred":
            lines += [f"Reference: BEM, fd, {tyre_ref_n} elements.", ""]
        lines += [
            "| influence | slip derivative | elements | nodes | max | RMS | creepage | boundary | "
            "influence [s] | Newton [s] | iterations | estimate max / true | estimate RMS / true | "
            "estimate creep / true |",
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for r in subset:
            ratios = [
                f"{r[f'est_{k}'] / r[k]:.1f}" if f"est_{k}" in r and r[k] > 0 else "" for k in ("max", "rms", "creep")
            ]
            lines.append(
                f"| {r['influence']} | {r['scheme']} | {r['elements']} | {r['nodes']} | {r['max']:.2e} | "
                f"{r['rms']:.2e} | {r['creep']:.1e} | {r['boundary']:.1e} | {r['t_influence']:.3f} | "
                f"{r['t_newton']:.3f} | {r['iterations']} | {' | '.join(ratios)} |"
            )
        lines += ["", "Observed orders (slope of log error against log elements, elements >= 20):", ""]
        lines += ["| influence | slip derivative | max | RMS | creepage |", "|---|---|---:|---:|---:|"]
        for influence, scheme in sorted({(r["influence"], r["scheme"]) for r in subset}):
            part = [r for r in subset if r["influence"] == influence and r["scheme"] == scheme]
            lines.append(
                f"| {influence} | {scheme} | {order(part, 'max'):.2f} | {order(part, 'rms'):.2f} | "
                f"{order(part, 'creep'):.2f} |"
            )
        lines += [
            "",
            "Fewest elements from which every finer mesh meets the target (max traction / RMS "
            "traction / creepage), with that run's time:",
            "",
        ]
        lines += ["| influence | slip derivative | target | max | RMS | creepage |", "|---|---|---:|---|---|---|"]
        for influence, scheme in sorted({(r["influence"], r["scheme"]) for r in subset}):
            part = [r for r in subset if r["influence"] == influence and r["scheme"] == scheme]
            for target in (1e-2, 1e-3):
                cells = []
                for key in ("max", "rms", "creep"):
                    hit = needed(part, key, target)
                    cells.append(f"{hit['elements']} ({hit['total']:.2f} s)" if hit else "not reached")
                lines.append(f"| {influence} | {scheme} | {target:.0e} | {' | '.join(cells)} |")
        lines += [""]
    (OUT / "accuracy_cost.md").write_text("\n".join(lines) + "\n")


def write_adaptive_markdown(whole: list[dict], startup: float) -> None:
    """Append the accuracy-on-demand section to accuracy_cost.md."""
    lines = [
        "## Accuracy on demand: the adaptive mode against uniform meshes, whole process",
        "",
        "Every run is a whole process, `rollc -q solve CASE --no-cache` (fastest of 3; shared machine, "
        f"default BLAS threads), so Python's start-up and the imports are in: about {startup:.2f} s here "
        "(the imports a solve needs, measured alone). In process: the solve alone (`time_total_solve`). "
        "Adaptive: `[discretization] tolerance` from the case's own mesh (Carter and dissimilar: 200 "
        "elements, graded half-plane levels; tyred: 100 elements, graded BEM levels). "
        'Uniform: the default route (`influence = "auto"`, fd) at N elements. Errors '
        "against the references above (dissimilar: the adaptive run at 1e-4, whose own estimate bounds "
        "what it can resolve; tyred: the 640-element BEM run, so errors near its own, ~1e-3, are not "
        "resolved).",
        "",
        "### Tolerance requested -> error achieved -> time",
        "",
        "| case | model | tolerance | met | elements | refinements | estimate | max error | estimate / error | "
        "creepage error | whole process [s] | in process [s] |",
        "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in (r for r in whole if r["mode"] == "adaptive"):
        lines.append(
            f"| {r['case']} | {r['influence_model']} | {r['value']:g} | {'yes' if r['met'] else 'no'} | "
            f"{r['elements']} | {r['refinements']} | {r['estimate']:.2e} | {r['max']:.2e} | "
            f"{r['estimate'] / r['max']:.1f} | {r['creep']:.1e} | {r['total']:.2f} | {r['in_process']:.3f} |"
        )
    notes = sorted({r["note"] for r in whole if r["mode"] == "adaptive" and r["note"]})
    if notes:
        lines += ["", "Not met:", ""] + [f"* {n}" for n in notes]
    lines += [
        "",
        "### Uniform meshes of the default route, the same way",
        "",
        "| case | model | elements | max error | RMS error | creepage error | whole process [s] | in process [s] |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in (r for r in whole if r["mode"] == "uniform"):
        lines.append(
            f"| {r['case']} | {r['influence_model']} | {r['elements']} | {r['max']:.2e} | {r['rms']:.2e} | "
            f"{r['creep']:.1e} | {r['total']:.2f} | {r['in_process']:.3f} |"
        )
    with open(OUT / "accuracy_cost.md", "a") as handle:
        handle.write("\n".join(lines) + "\n")


def write_plot(rows, whole):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    names = ("Carter", "dissimilar", "tyred")
    fig = Figure(figsize=(15, 13), layout="constrained")
    FigureCanvasAgg(fig)
    for row, (key, label) in enumerate(
        (("rms", r"RMS traction error / $(\mu p_0)$ [-]"), ("max", r"max traction error / $(\mu p_0)$ [-]"))
    ):
        for k, name in enumerate(names):
            ax = fig.add_subplot(3, 3, 3 * row + k + 1)
            subset = [r for r in rows if r["case"] == name]
            for influence, scheme in sorted({(r["influence"], r["scheme"]) for r in subset}):
                part = sorted(
                    (r for r in subset if r["influence"] == influence and r["scheme"] == scheme),
                    key=lambda r: r["elements"],
                )
                times, errors = [r["total"] for r in part], [r[key] for r in part]
                ax.loglog(times, errors, "o-", ms=4, label=f"{influence}, {scheme}")
                for r in part:
                    ax.annotate(
                        str(r["elements"]), (r["total"], r[key]), fontsize=6, xytext=(2, 2), textcoords="offset points"
                    )
            front, best = [], math.inf
            for r in sorted(subset, key=lambda r: r["total"]):
                if r[key] < best:
                    best = r[key]
                    front.append((r["total"], r[key]))
            if front:
                ax.step(*zip(*front, strict=True), where="post", color="0.5", lw=4, alpha=0.35, label="Pareto front")
            ax.set_xlabel("wall time per solve [s] (influence + Newton, cold)")
            ax.set_ylabel(label)
            ax.set_title(f"{name}: {key} error against time (labels: contact elements)", fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    for k, name in enumerate(names):
        ax = fig.add_subplot(3, 3, 7 + k)
        for mode, style in (("uniform", "s-"), ("adaptive", "o-")):
            part = [r for r in whole if r["case"] == name and r["mode"] == mode]
            if not part:
                continue
            ax.loglog([r["total"] for r in part], [r["max"] for r in part], style, ms=4, label=mode)
            for r in part:
                text = f"{r['value']:g}" if mode == "adaptive" else str(r["value"])
                ax.annotate(text, (r["total"], r["max"]), fontsize=6, xytext=(2, 2), textcoords="offset points")
        adaptive = [r for r in whole if r["case"] == name and r["mode"] == "adaptive"]
        if adaptive:
            ax.loglog([r["total"] for r in adaptive], [r["value"] for r in adaptive], "k:", lw=1, label="tolerance")
        ax.set_xlabel("whole process [s] (rollc -q solve, start-up included)")
        ax.set_ylabel(r"max traction error / $(\mu p_0)$ [-]")
        ax.set_title(f"{name}: adaptive (labels: tolerance) and uniform (labels: elements)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.savefig(OUT / "accuracy_cost.png", dpi=120)


if __name__ == "__main__":
    main()
