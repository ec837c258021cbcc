"""Graded and adaptive contact meshes (issue #13, phase 1): what grading reaches, and at what cost.

Half-plane model throughout (the BEM takes no graded contact grids yet).

1. **Graded meshes on the exact kinks** (Carter, Q/(mu P) = 0.51): an element
   edge on each contact edge and on the stick/slip boundary, elements growing
   by 1.4 up to 0.05 a; smallest element 1e-2 .. 1e-6 a; both slip
   derivatives ("fd", first order; "element", second order); uniform meshes
   alongside.
2. **The adaptive loop prototype**, on the public :func:`rolling_cli.solve`
   with explicit grids (:func:`rolling_cli.adapt.explicit.solve_on_grid`):
   uniform 20 elements, then per level: indicator, kinks, next grid
   (:func:`rolling_cli.adapt.remesh.next_grid`), solve, until the estimate
   (the largest indicator) meets the tolerance, at most 10 refinements or
   3000 elements. Each level starts cold (Hertz/Carter) or warm (the previous
   level's solution transferred, :func:`rolling_cli.adapt.transfer.transfer_tractions`;
   when Newton fails from the warm start, the level is solved again cold and
   the run counts a fallback).
   Carter and the dissimilar case (aluminium on steel, Q/(mu P) = 0.04).
   Whole-process wall time (plan, influence, every level's solve), influence
   memo cleared before each run, one BLAS thread.
3. **The indicator against the true error**: ratio estimate / true maximum
   error over every mesh of 1-2 and uniform meshes of 10-320 elements.

True errors: Carter against the closed form; the dissimilar case against a
reference from the same loop at tolerance 1e-4 (its own estimate and its
difference from a 3e-4 run are printed), interpolated with the reference's
element polynomials. Errors are max |p_t - p_t,ref| / (mu p0) over the nodes.

    python benchmarks/adaptive.py [--quick]

Writes benchmarks/results/adaptive.md.
"""

from __future__ import annotations

import argparse
import datetime
import math
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.adapt import indicator, kinks, remesh, transfer  # noqa: E402
from rolling_cli.adapt.explicit import solve_on_grid  # noqa: E402
from rolling_cli.adapt.grading import graded_grid  # noqa: E402
from rolling_cli.blas import single_threaded  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.errors import ConvergenceError  # noqa: E402
from rolling_cli.grid import ContactGrid  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.references import carter  # noqa: E402
from rolling_cli.solver.formulation import State  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
MAX_LEVELS = 10
MAX_ELEMENTS = 3000
START_ELEMENTS = 20


@dataclass
class Level:
    """One mesh of an adaptive run: its grid, solution, estimate and the time so far."""

    grid: ContactGrid
    result: object
    estimate: float
    seconds: float


@dataclass
class Run:
    levels: list[Level] = field(default_factory=list)
    note: str = ""
    fallbacks: int = 0

    @property
    def final(self) -> Level:
        return self.levels[-1]


def peak_pressure(r) -> float:
    return float(np.max(-r.p_n))


def estimate_of(grid: ContactGrid, r) -> float:
    return float(indicator.element_indicator(grid, r.p_n, r.p_t, r.mu, peak_pressure(r)).max())


def adapt(case, tolerance: float, warm: bool) -> Run:
    """The adaptive loop: uniform start, then graded refinements until the estimate meets the tolerance."""
    clear_memo()
    started = time.perf_counter()
    r = rolling_cli.solve(with_overrides(case, {"discretization.contact_elements": START_ELEMENTS}))
    grid = ContactGrid(case.discretization.zone * r.mesh_half_width, START_ELEMENTS, 2)
    run = Run()
    for _ in range(MAX_LEVELS + 1):
        eta = indicator.element_indicator(grid, r.p_n, r.p_t, r.mu, peak_pressure(r))
        run.levels.append(Level(grid, r, float(eta.max()), time.perf_counter() - started))
        if eta.max() <= tolerance:
            return run
        if len(run.levels) > MAX_LEVELS:
            break
        positions, kinds = kinks.locate_kinks(r, grid)
        new = remesh.next_grid(grid, eta, positions, kinds, tolerance)
        if new.elements > MAX_ELEMENTS:
            run.note = f"stopped: the next mesh would have {new.elements} elements"
            return run
        start = None
        if warm:
            edges = kinks.contact_edges(r.x, r.p_n, r.delta_n)
            p_n, p_t = transfer.transfer_tractions(grid, r.p_n, r.p_t, r.mu, new, edges)
            start = State(p_n, p_t, float(r.solved_overlap), float(r.creep))
        try:
            r = solve_on_grid(case, new, start)
        except ConvergenceError:
            if start is None:
                raise
            run.fallbacks += 1  # the warm start failed: this level again from Hertz/Carter
            r = solve_on_grid(case, new)
        grid = new
    run.note = f"stopped: {MAX_LEVELS} refinements"
    return run


class Reference:
    """True tractions and creepage: Carter's closed form, or a fine run interpolated."""

    def __init__(self, grid: ContactGrid | None = None, result=None):
        self.grid, self.result = grid, result

    def traction(self, r) -> np.ndarray:
        if self.result is None:
            return carter.traction(r.x, r.q_over_mu_p, r.hertz_a, r.hertz_p0, r.mu, r.direction)
        return transfer.interpolate(self.grid, self.result.p_t, r.x)

    def creep(self, r) -> float:
        return r.carter_creep if self.result is None else self.result.creep

    def scale(self, r) -> float:
        return r.mu * (r.hertz_p0 if self.result is None else peak_pressure(self.result))


def errors(r, ref: Reference) -> dict:
    err = np.abs(r.p_t - ref.traction(r)) / ref.scale(r)
    contact = r.p_n < 0.0
    return {
        "max": float(err.max()),
        "rms": float(np.sqrt(np.mean(err[contact] ** 2))),
        "creep": abs(r.creep / ref.creep(r) - 1.0),
    }


def study_graded(base, smallest_values, quick: bool) -> list[dict]:
    """Section 1: graded meshes with an edge on each exact kink, against uniform meshes."""
    rows = []
    ref = Reference()
    for scheme in ("fd", "element"):
        case = with_overrides(base, {"discretization.slip_derivative": scheme})
        a = rolling_cli.solve(with_overrides(case, {"discretization.contact_elements": 10})).hertz_a
        c = a * math.sqrt(1.0 - 0.51)
        zone = ContactGrid(case.discretization.zone * a, 10, 2)
        for smallest in smallest_values:
            grid = graded_grid(zone, [-a, a - 2 * c, a], smallest * a, 0.05 * a, 1.4)
            clear_memo()
            t = time.perf_counter()
            r = solve_on_grid(case, grid)
            seconds = time.perf_counter() - t
            rows.append(
                {
                    "scheme": scheme,
                    "mesh": f"graded, smallest {smallest:.0e} a",
                    "elements": grid.elements,
                    **errors(r, ref),
                    "estimate": estimate_of(grid, r),
                    "seconds": seconds,
                }
            )
        for n in (40, 160) if quick else (40, 80, 160, 320, 640):
            clear_memo()
            t = time.perf_counter()
            r = rolling_cli.solve(with_overrides(case, {"discretization.contact_elements": n}))
            seconds = time.perf_counter() - t
            grid = ContactGrid(case.discretization.zone * r.mesh_half_width, n, 2)
            rows.append(
                {
                    "scheme": scheme,
                    "mesh": "uniform",
                    "elements": n,
                    **errors(r, ref),
                    "estimate": estimate_of(grid, r),
                    "seconds": seconds,
                }
            )
        for row in rows[-len(smallest_values) - (2 if quick else 5) :]:
            print(
                f"  {row['scheme']:7s} {row['mesh']:26s} {row['elements']:4d}  max {row['max']:.2e} "
                f"rms {row['rms']:.2e} creep {row['creep']:.1e} est {row['estimate']:.2e} {row['seconds']:.3f} s",
                flush=True,
            )
    return rows


def study_adaptive(name, base, tolerances, ref: Reference, repeats: int) -> tuple[list[dict], list[float]]:
    """Section 2: the adaptive loop; returns rows and every level's ratio estimate / true error."""
    rows, ratios = [], []
    for scheme in ("fd", "element"):
        case = with_overrides(base, {"discretization.slip_derivative": scheme})
        for warm in (False, True):
            for tol in tolerances:
                best = None
                for _ in range(repeats):  # timings on a shared machine: the fastest of the repeats
                    run = adapt(case, tol, warm)
                    if best is None or run.final.seconds < best.final.seconds:
                        best = run
                final = best.final
                e = errors(final.result, ref)
                for level in best.levels:
                    true = errors(level.result, ref)["max"]
                    if true > 0.0:
                        ratios.append(level.estimate / true)
                row = {
                    "case": name,
                    "scheme": scheme,
                    "start": "warm" if warm else "cold",
                    "tolerance": tol,
                    "elements": final.grid.elements,
                    "refinements": len(best.levels) - 1,
                    "smallest": final.grid.element_lengths.min() / final.result.mesh_half_width,
                    "estimate": final.estimate,
                    **e,
                    "seconds": final.seconds,
                    "note": best.note,
                    "iterations": sum(level.result.iterations for level in best.levels),
                    "fallbacks": best.fallbacks,
                }
                rows.append(row)
                print(
                    f"  {name:10s} {scheme:7s} {row['start']} tol {tol:.0e}: {row['elements']:4d} elements, "
                    f"{row['refinements']} refinements, est {row['estimate']:.2e}, true {row['max']:.2e} "
                    f"(ratio {row['estimate'] / row['max']:.1f}), creep {row['creep']:.1e}, "
                    f"{row['seconds']:.2f} s {best.note}",
                    flush=True,
                )
    return rows, ratios


def uniform_ratios(name, base, ref: Reference, elements) -> list[float]:
    """Section 3: estimate / true error on uniform meshes."""
    out = []
    for scheme in ("fd", "element"):
        for n in elements:
            case = with_overrides(
                base, {"discretization.slip_derivative": scheme, "discretization.contact_elements": n}
            )
            r = rolling_cli.solve(case)
            grid = ContactGrid(case.discretization.zone * r.mesh_half_width, n, 2)
            out.append(estimate_of(grid, r) / errors(r, ref)["max"])
    print(f"  {name}: uniform estimate / true in [{min(out):.2f}, {max(out):.2f}]", flush=True)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer meshes and tolerances (a smoke run)")
    args = parser.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    carter_case = with_overrides(load_case(ROOT / "cases" / "carter.toml"), {"discretization.influence": "half-plane"})
    dissimilar_case = load_case(ROOT / "cases" / "dissimilar_q04.toml")
    repeats = 1 if args.quick else 3
    with single_threaded():
        print("1. graded meshes on the exact kinks (Carter)", flush=True)
        graded = study_graded(carter_case, [1e-2, 1e-4] if args.quick else [1e-2, 1e-3, 1e-4, 1e-5, 1e-6], args.quick)

        print("2. adaptive loop", flush=True)
        carter_tols = [1e-2, 1e-3] if args.quick else [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
        carter_rows, carter_ratios = study_adaptive("Carter", carter_case, carter_tols, Reference(), repeats)

        print("   dissimilar reference", flush=True)
        ref_tol, check_tol = 1e-4, 3e-4
        ref_run = adapt(dissimilar_case, ref_tol, warm=True)
        check_run = adapt(dissimilar_case, check_tol, warm=True)
        reference = Reference(ref_run.final.grid, ref_run.final.result)
        ref_info = {
            "tolerance": ref_tol,
            "elements": ref_run.final.grid.elements,
            "estimate": ref_run.final.estimate,
            "seconds": ref_run.final.seconds,
            "check_tolerance": check_tol,
            "check_difference": errors(check_run.final.result, reference)["max"],
            "note": ref_run.note,
        }
        print(f"   {ref_info}", flush=True)
        dis_tols = [1e-2, 1e-3] if args.quick else [1e-2, 3e-3, 1e-3]
        dis_rows, dis_ratios = study_adaptive("dissimilar", dissimilar_case, dis_tols, reference, repeats)

        print("3. indicator against the true error on uniform meshes", flush=True)
        sizes = [10, 40] if args.quick else [10, 20, 40, 80, 160, 320]
        carter_ratios_uniform = uniform_ratios("Carter", carter_case, Reference(), sizes)
        dis_ratios_uniform = uniform_ratios("dissimilar", dissimilar_case, reference, sizes[:-1])
    ratios = {
        "Carter": (carter_ratios_uniform, [r["estimate"] / r["max"] for r in graded], carter_ratios),
        "dissimilar": (dis_ratios_uniform, [], dis_ratios),
    }
    write_markdown(graded, carter_rows + dis_rows, ref_info, ratios, time.perf_counter() - started)
    print(f"written {OUT / 'adaptive.md'}")


def _range(values) -> str:
    values = [v for v in values if np.isfinite(v)]
    if not values:
        return "-"
    return f"{min(values):.2f} / {float(np.median(values)):.2f} / {max(values):.2f} ({len(values)})"


def write_markdown(graded, adaptive, ref_info, ratios, seconds) -> None:
    lines = [
        "# Graded and adaptive contact meshes (half-plane model)",
        "",
        f"Generated by `benchmarks/adaptive.py` on {datetime.date.today().isoformat()}, {platform.machine()}, "
        f"2 cores shared with other jobs, one BLAS thread, Python {platform.python_version()}; the study took "
        f"{seconds / 60:.1f} min. Errors: max and RMS |p_t - p_t,ref| / (mu p0) over the nodes (RMS over the "
        "contact), creepage relative. Estimate: the largest element indicator (traction jumps). Times: whole "
        "process, wall clock (shared machine: noisy, fastest of 3 runs for the adaptive loop).",
        "",
        "## 1. Graded meshes with an element edge on each exact kink (Carter, Q/(mu P) = 0.51)",
        "",
        "Growth 1.4 per element away from each kink, largest element 0.05 a; uniform meshes below them.",
        "",
        "| slip derivative | mesh | elements | max error | RMS error | creepage error | estimate | time [s] |",
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
        f"Dissimilar reference: the same loop at tolerance {ref_info['tolerance']:.0e} ({ref_info['elements']} "
        f"elements, its own estimate {ref_info['estimate']:.1e}, {ref_info['seconds']:.1f} s); the run at "
        f"{ref_info['check_tolerance']:.0e} differs from it by {ref_info['check_difference']:.1e} mu p0. "
        f"{ref_info['note']}",
        "",
        "| case | slip derivative | start | tolerance | elements | refinements | smallest / a | estimate | "
        "max error | estimate / error | RMS error | creepage error | Newton iterations | warm-start failures | "
        "time [s] |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in adaptive:
        lines.append(
            f"| {r['case']} | {r['scheme']} | {r['start']} | {r['tolerance']:.0e} | {r['elements']} | "
            f"{r['refinements']} | {r['smallest']:.1e} | {r['estimate']:.2e} | {r['max']:.2e} | "
            f"{r['estimate'] / r['max']:.1f} | {r['rms']:.1e} | {r['creep']:.1e} | {r['iterations']} | "
            f"{r['fallbacks']} | {r['seconds']:.2f} |" + (f" {r['note']}" if r["note"] else "")
        )
    lines += [
        "",
        "## 3. The indicator against the true error",
        "",
        "Ratio estimate / true maximum error: min / median / max (count). Below 1 would be an underestimate.",
        "",
        "| case | uniform meshes | graded on exact kinks | every level of the adaptive runs |",
        "|---|---|---|---|",
    ]
    for name, (uniform, graded_ratios, levels) in ratios.items():
        lines.append(f"| {name} | {_range(uniform)} | {_range(graded_ratios)} | {_range(levels)} |")
    (OUT / "adaptive.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
