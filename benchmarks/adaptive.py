"""Accuracy on demand (issue #13): the adaptive mesh levels of ``rolling_cli.solve`` against references.

Half-plane model throughout (the BEM's graded levels: benchmarks/graded_bem.py and accuracy_cost.py).

1. **Graded meshes with an element edge on each exact kink** (Carter, Q/(mu P) =
   0.51): elements growing by 1.4 up to 0.05 a, smallest 1e-2 .. 1e-6 a, both
   slip derivatives ("fd" first order, "element" second order), uniform meshes
   alongside: what grading reaches, and how the two derivatives compare on it.
2. **The adaptive loop** (``[discretization] tolerance``, from the cases' 200
   uniform elements): tolerance requested -> elements, refinements, estimate,
   true maximum error, estimate / error, creepage error, Newton iterations,
   in-process time (fastest of 3, one BLAS thread). Cases: Carter (Q/(mu P) =
   0.51, both rolling directions, and 0.84), frictionless Hertz, aluminium on
   steel (Q/(mu P) = 0.04, 0.75, -0.83); fd and element.
3. **The estimate against the true error on every level** of every run of 2
   (each run replayed with ``max_refinements`` = 0, 1, ...: the loop is
   deterministic), with its two terms (traction jumps, kink motion).

True errors: max |p_t - p_t,ref| / (mu p0) over the nodes (|p_n - p_ref| / p0
when frictionless). References: Carter's and Hertz's closed forms; for the
dissimilar cases the same loop at tolerance 1e-4 (12 refinements at most),
interpolated with its element polynomials; its own estimate E_ref is printed,
and a dissimilar level enters the ratios of 3 only where its difference from
the reference exceeds 2 E_ref (below that the reference cannot tell).

    python benchmarks/adaptive.py [--quick]

Writes benchmarks/results/adaptive.md.
"""

from __future__ import annotations

import argparse
import datetime
import json
import logging
import math
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.adapt import transfer  # noqa: E402
from rolling_cli.adapt.accuracy import traction_estimate  # noqa: E402
from rolling_cli.adapt.grading import graded_grid  # noqa: E402
from rolling_cli.blas import single_threaded  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.model.grid import ContactGrid  # noqa: E402
from rolling_cli.pipeline.explicit import solve_on_grid  # noqa: E402
from rolling_cli.references import carter, hertz  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
CASES = ROOT / "cases"


class Reference:
    """True tractions: Carter's or Hertz's closed form, or a fine adaptive run interpolated."""

    def __init__(self, result=None):
        self.result = result
        self.grid = ContactGrid.graded(result.element_edges, result.element_order) if result is not None else None

    @property
    def resolution(self) -> float:
        """The reference's own error bound [-] (its estimate; 0 for a closed form)."""
        return 0.0 if self.result is None else float(self.result.adaptive_estimate)

    def error(self, r) -> dict:
        """Max and RMS traction error [-] (RMS over the contact) and the relative creepage error."""
        contact = r.p_n < 0.0
        if self.result is None and r.mu == 0.0:
            err = np.abs(-r.p_n - hertz.pressure(r.x, r.hertz_a, r.hertz_p0)) / r.hertz_p0
            creep = 0.0
        elif self.result is None:
            exact = carter.traction(r.x, r.q_over_mu_p, r.hertz_a, r.hertz_p0, r.mu, r.direction)
            err = np.abs(r.p_t - exact) / (r.mu * r.hertz_p0)
            creep = abs(r.creep / r.carter_creep - 1.0)
        else:
            p0 = float(np.max(-self.result.p_n))
            err = np.abs(r.p_t - transfer.interpolate(self.grid, self.result.p_t, r.x)) / (r.mu * p0)
            creep = abs(r.creep / self.result.creep - 1.0)
        return {"max": float(err.max()), "rms": float(np.sqrt(np.mean(err[contact] ** 2))), "creep": creep}


def adaptive_case(base, tolerance: float, scheme: str, refinements: int = 10):
    return with_overrides(
        base,
        {
            "discretization.tolerance": tolerance,
            "discretization.slip_derivative": scheme,
            "discretization.max_refinements": refinements,
        },
    )


def timed(case, repeats: int):
    """The result and the fastest in-process time of ``repeats`` solves (influence memo cleared)."""
    best, result = math.inf, None
    for _ in range(repeats):
        clear_memo()
        t = time.perf_counter()
        result = rolling_cli.solve(case)
        best = min(best, time.perf_counter() - t)
    return result, best


def study_graded(base, smallest_values, quick: bool) -> list[dict]:
    """Section 1: graded meshes with an edge on each exact kink, against uniform meshes."""
    rows = []
    ref = Reference()
    for scheme in ("fd", "element"):
        case = with_overrides(base, {"discretization.slip_derivative": scheme})
        a = rolling_cli.solve(with_overrides(case, {"discretization.contact_elements": 10})).hertz_a
        c = a * math.sqrt(1.0 - 0.51)
        zone = ContactGrid(case.discretization.zone * a, 10, 2)
        meshes = [("graded", s) for s in smallest_values] + [
            ("uniform", n) for n in ((40, 160) if quick else (40, 160, 640))
        ]
        for kind, size in meshes:
            clear_memo()
            t = time.perf_counter()
            if kind == "graded":
                grid = graded_grid(zone, [-a, a - 2 * c, a], size * a, 0.05 * a, 1.4)
                r = solve_on_grid(case, grid)
                label = f"graded, smallest {size:.0e} a"
            else:
                r = rolling_cli.solve(with_overrides(case, {"discretization.contact_elements": size}))
                grid = ContactGrid(case.discretization.zone * r.mesh_half_width, size, 2)
                label = "uniform"
            seconds = time.perf_counter() - t
            estimate = traction_estimate(grid, r.p_n, r.p_t, r.mu)[1]
            rows.append(
                {"scheme": scheme, "mesh": label, "elements": grid.elements, **ref.error(r), "estimate": estimate}
            )
            rows[-1]["seconds"] = seconds
            print(f"  {scheme:7s} {label:26s} {grid.elements:4d}  max {rows[-1]['max']:.2e}", flush=True)
    return rows


def study_adaptive(name, base, tolerances, ref: Reference, repeats: int, schemes=("fd", "element")):
    """Sections 2 and 3: the loop at each tolerance, and every level of it against the reference."""
    rows, levels = [], []
    for scheme in schemes:
        for tol in tolerances:
            case = adaptive_case(base, tol, scheme)
            r, seconds = timed(case, repeats)
            e = ref.error(r)
            history = json.loads(r.adaptive_history)
            rows.append(
                {
                    "case": name,
                    "scheme": scheme,
                    "tolerance": tol,
                    "elements": r.contact_elements,
                    "refinements": r.adaptive_refinements,
                    "smallest": float(np.diff(r.element_edges).min() / r.mesh_half_width),
                    "estimate": r.adaptive_estimate,
                    "met": bool(r.adaptive_met),
                    **e,
                    "iterations": r.iterations_total,
                    "seconds": seconds,
                    "note": r.adaptive_note,
                }
            )
            print(
                f"  {name:12s} {scheme:7s} tol {tol:.0e}: {r.contact_elements:4d} elements, {r.adaptive_refinements} "
                f"refinements, est {r.adaptive_estimate:.2e}, true {e['max']:.2e}, creep {e['creep']:.1e}, "
                f"{seconds:.3f} s {r.adaptive_note}",
                flush=True,
            )
            for k, row in enumerate(history):  # every level: replay the run up to it
                level = r if k == len(history) - 1 else rolling_cli.solve(adaptive_case(base, tol, scheme, k))
                true = ref.error(level)["max"]
                levels.append(
                    {
                        "case": name,
                        "true": true,
                        "estimate": row["estimate"],
                        "jumps": row.get("jumps", row["estimate"]),
                        "motion": row.get("kink_motion", 0.0),
                        "resolved": true > 2.0 * ref.resolution,
                    }
                )
    return rows, levels


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer meshes, cases and tolerances (a smoke run)")
    args = parser.parse_args()
    logging.getLogger("rolling_cli").setLevel(logging.ERROR)  # replays of capped runs warn
    OUT.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    carter_case = load_case(CASES / "carter.toml")
    repeats = 1 if args.quick else 3
    tolerances = [1e-2, 1e-3] if args.quick else [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
    frictionless = rolling_cli.case.case_to_dict(carter_case)
    frictionless.pop("tangential")
    frictionless["friction"]["mu"] = 0.0
    closed = [
        ("Carter 0.51", carter_case),
        ("Carter 0.51, V > 0", with_overrides(carter_case, {"rolling.direction": 1})),
        ("Carter 0.84", load_case(CASES / "carter_q084.toml")),
        ("Hertz (mu = 0)", load_case(frictionless)),
    ]
    dissimilar = [(f"dissimilar {q}", load_case(CASES / f"dissimilar_{q}.toml")) for q in ("q04", "q75", "qm83")]
    if args.quick:
        closed, dissimilar = closed[:1], dissimilar[:1]
    with single_threaded():
        print("1. graded meshes on the exact kinks (Carter)", flush=True)
        smallest = [1e-2, 1e-4] if args.quick else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
        graded = study_graded(carter_case, smallest, args.quick)
        print("2-3. the adaptive loop and its levels", flush=True)
        rows, level_rows, references = [], [], []
        for name, base in closed:
            r, lv = study_adaptive(name, base, tolerances, Reference(), repeats)
            rows += r
            level_rows += lv
        for name, base in dissimilar:
            t = time.perf_counter()
            reference = rolling_cli.solve(adaptive_case(base, 1e-4, "fd", 12))
            ref = Reference(reference)
            references.append((name, reference, time.perf_counter() - t))
            print(
                f"   {name} reference: {reference.contact_elements} elements, estimate {ref.resolution:.2e}", flush=True
            )
            dis_tols = [t for t in tolerances if t >= 1e-3]
            r, lv = study_adaptive(name, base, dis_tols, ref, repeats)
            rows += r
            level_rows += lv
    write_markdown(graded, rows, level_rows, references, time.perf_counter() - started)
    print(f"written {OUT / 'adaptive.md'}")


def _range(values) -> str:
    values = [v for v in values if np.isfinite(v)]
    if not values:
        return "-"
    return f"{min(values):.2f} / {float(np.median(values)):.2f} / {max(values):.2f} ({len(values)})"


def write_markdown(graded, rows, level_rows, references, seconds) -> None:
    lines = [
        "# Accuracy on demand: graded and adaptive contact meshes (half-plane model)",
        "",
        f"Generated by `benchmarks/adaptive.py` on {datetime.date.today().isoformat()}, {platform.machine()}, "
        f"2 cores shared with other jobs, one BLAS thread, Python {platform.python_version()}; the study took "
        f"{seconds / 60:.1f} min. Errors: max and RMS traction error / (mu p0) over the nodes (pressure / p0 "
        "when frictionless; RMS over the contact), creepage relative. Estimate: the adaptive loop's (the "
        "larger of the traction jumps and the kink motion). Times: in-process `rolling_cli.solve`, wall "
        "clock, fastest of 3 (shared machine: noisy; whole-process times in accuracy_cost.md).",
        "",
        "## 1. Graded meshes with an element edge on each exact kink (Carter, Q/(mu P) = 0.51)",
        "",
        "Growth 1.4 per element away from each kink, largest element 0.05 a; uniform meshes below them. "
        "Estimate here: the traction jumps alone (the kinks do not move).",
        "",
        "| slip derivative | mesh | elements | max error | RMS error | creepage error | jumps | time [s] |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for r in graded:
        lines.append(
            f"| {r['scheme']} | {r['mesh']} | {r['elements']} | {r['max']:.2e} | {r['rms']:.2e} | {r['creep']:.1e} "
            f"| {r['estimate']:.2e} | {r['seconds']:.3f} |"
        )
    lines += [
        "",
        "## 2. The adaptive loop: tolerance requested -> error achieved -> time",
        "",
        "From the cases' 200 uniform elements. Dissimilar references: the loop at tolerance 1e-4 "
        "(at most 12 refinements): "
        + "; ".join(
            f"{name}: {r.contact_elements} elements, its estimate {r.adaptive_estimate:.1e}"
            + ("" if r.adaptive_met else " (1e-4 not met)")
            + f", {s:.1f} s"
            for name, r, s in references
        )
        + ". A dissimilar error below twice its reference's estimate is not resolved by the reference.",
        "",
        "| case | slip derivative | tolerance | met | elements | refinements | smallest / a | estimate | "
        "max error | estimate / error | RMS error | creepage error | Newton iterations | time [s] |",
        "|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['scheme']} | {r['tolerance']:.0e} | {'yes' if r['met'] else 'no'} | {r['elements']} | "
            f"{r['refinements']} | {r['smallest']:.1e} | {r['estimate']:.2e} | {r['max']:.2e} | "
            f"{r['estimate'] / r['max']:.1f} | {r['rms']:.1e} | {r['creep']:.1e} | {r['iterations']} | "
            f"{r['seconds']:.3f} |"
        )
    notes = sorted({r["note"] for r in rows if r["note"]})
    if notes:
        lines += ["", "Runs that did not meet their tolerance said:", ""] + [f"* {n}" for n in notes]
    lines += [
        "",
        "## 3. The estimate against the true error on every level",
        "",
        "Ratio estimate / true maximum error over every level of every run of section 2: min / median / max "
        "(count). Below 1 would be an underestimate. Also the ratio of the traction jumps alone (without the "
        "kink-motion term). Dissimilar levels only where the reference resolves them.",
        "",
        "| case | estimate / error | jumps alone / error | levels where the kink motion is the larger term |",
        "|---|---|---|---:|",
    ]
    for name in dict.fromkeys(row["case"] for row in level_rows):
        part = [row for row in level_rows if row["case"] == name and row["resolved"] and row["true"] > 0.0]
        ratios = [row["estimate"] / row["true"] for row in part]
        jumps = [row["jumps"] / row["true"] for row in part]
        motion = sum(row["motion"] > row["jumps"] for row in part)
        lines.append(f"| {name} | {_range(ratios)} | {_range(jumps)} | {motion} of {len(part)} |")
    part = [row for row in level_rows if row["resolved"] and row["true"] > 0.0]
    lines.append(
        f"| **all** | {_range([row['estimate'] / row['true'] for row in part])} | "
        f"{_range([row['jumps'] / row['true'] for row in part])} | "
        f"{sum(row['motion'] > row['jumps'] for row in part)} of {len(part)} |"
    )
    (OUT / "adaptive.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
