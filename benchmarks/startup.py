"""Start-up and whole-process speed (issue #14 item 1).

Every time here is a WHOLE process (a subprocess, Python's start-up and the
imports included), the median of ``--repeats`` runs (default 5), the commands
interleaved round by round so that a shared machine's load hits them alike,
with one BLAS thread (:data:`rolling_cli.blas.SINGLE_THREAD_ENV`) and bytecode
caching on (``PYTHONDONTWRITEBYTECODE`` removed; a warm-up run of each command
writes the .pyc files first).

Tables printed:

1. ``rollc --version``, the shipped half-plane case ``cases/carter.toml``
   (``rollc -q solve ... -o``) and a BEM case (``cases/paper_fig3_q051.toml``,
   21 elements) with its influence read from a warm disk cache and with
   ``--no-cache``: median and fastest wall time and the peak resident memory.
   With ``--tree NAME=DIR`` (repeatable; DIR a source tree of the package, for
   example ``git archive <commit> rolling_cli | tar -x -C DIR``) the same
   commands also run on that tree (``PYTHONPATH=DIR``), interleaved with the
   current one.
2. The ten largest import costs of the Carter solve (``python -X importtime``,
   median self time over the runs), and the total per top-level package.
3. rollc against CONTACT at equal Carter error: uniform half-plane meshes and
   the adaptive mode (``[discretization] tolerance``), each run through
   :func:`accuracy_cost.rollc` (``rollc -q solve CASE --no-cache``) and
   measured with :func:`accuracy_cost.measure` (max and RMS traction error /
   (mu p0) against Carter on the run's own nodes). CONTACT's time at the same
   error is interpolated log-log in its published grid-refinement table
   (:data:`CONTACT`); beyond the table's errors nothing is extrapolated: below
   its finest error CONTACT's time is more than its 1600-element time (">",
   the ratio a lower bound).

    python benchmarks/startup.py [--repeats 5] [--tree NAME=DIR ...] [--quick] [--only-startup]
"""

from __future__ import annotations

import argparse
import collections
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import accuracy_cost  # noqa: E402  (its whole-process runner and error measure are reused)

from rolling_cli.blas import SINGLE_THREAD_ENV  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402

CASES = ROOT / "cases"
#: CONTACT's published grid refinement on Carter's case: elements, time [s], max and RMS traction error [-].
CONTACT = [
    (50, 0.04, 1.8e-2, 3.6e-3),
    (200, 0.24, 9.1e-3, 1.0e-3),
    (800, 5.96, 4.7e-3, 2.8e-4),
    (1600, 31.1, 3.5e-3, 1.5e-4),
]
#: Uniform meshes and adaptive tolerances of the comparison (Carter, half-plane).
UNIFORM = [40, 80, 160, 200, 320, 640]
TOLERANCES = [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
#: The target: rollc at least 20x faster than CONTACT at equal error, max and RMS, from 1 % to 0.05 %.
TARGETS = [1e-2, 7e-3, 5e-3, 3.5e-3, 2e-3, 1e-3, 5e-4]
TARGET_RATIO = 20.0


#: The console script's body (``rollc``: ``from rolling_cli.cli import entry; sys.exit(entry())``), run
#: with ``-c`` so that every tree runs its own entry point: ``entry`` where the tree has one (the quick
#: exit), else the click group ``main`` (the trees before it).
LAUNCHER = (
    "import re, sys; sys.argv[0] = 'rollc'; import rolling_cli.cli as cli; sys.exit(getattr(cli, 'entry', cli.main)())"
)


def rollc_command() -> list[str]:
    """``rollc`` as the console script runs it, for whichever tree ``PYTHONPATH`` selects."""
    return [sys.executable, "-c", LAUNCHER]


def child_environment() -> dict:
    """The environment of the timed processes: one BLAS thread, and bytecode caching on (as in a user's
    shell: PYTHONDONTWRITEBYTECODE would recompile the package's sources at every start)."""
    env = {**os.environ, **SINGLE_THREAD_ENV}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def whole_process(args: list[str], cwd: str, env: dict) -> tuple[float, float]:
    """Wall time [s] and peak resident memory [MB] of one command (``os.wait4``: this child only)."""
    t = time.perf_counter()
    child = subprocess.Popen(args, cwd=cwd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    seconds = time.perf_counter() - t
    stderr = child.stderr.read().decode()
    child.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{' '.join(args)} failed: {stderr}")
    return seconds, usage.ru_maxrss / 1024.0  # Linux: kB


def startup_table(repeats: int, others: dict[str, str]) -> list[dict]:
    """Table 1: the commands, interleaved, on the current tree (and on the ``others``: name -> tree)."""
    rollc = rollc_command()
    trees = {"current": None, **others}
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "cache"
        commands = {
            "rollc --version": ["--version"],
            "carter.toml (half-plane, 200 elements)": ["-q", "solve", str(CASES / "carter.toml"), "-o", "c.h5"],
            "paper_fig3_q051.toml (BEM, 21 elements), cached": [
                "-q",
                "solve",
                str(CASES / "paper_fig3_q051.toml"),
                "-o",
                "b.h5",
            ],
            "paper_fig3_q051.toml (BEM, 21 elements), --no-cache": [
                "-q",
                "solve",
                str(CASES / "paper_fig3_q051.toml"),
                "-o",
                "n.h5",
                "--no-cache",
            ],
        }
        envs = {}
        for tree, path in trees.items():
            env = {**child_environment(), "ROLLC_CACHE_DIR": str(cache / tree)}
            if path:
                env["PYTHONPATH"] = os.path.abspath(path)
            envs[tree] = env
            for args in commands.values():  # warm-up: the .pyc files written, the BEM cache filled
                whole_process([*rollc, *args, *(["--overwrite"] if args[0] == "-q" else [])], tmp, env)
        samples = collections.defaultdict(list)
        for _ in range(repeats):
            for name, args in commands.items():
                for tree in trees:
                    extra = ["--overwrite"] if args[0] == "-q" else []
                    samples[name, tree].append(whole_process([*rollc, *args, *extra], tmp, envs[tree]))
    rows = []
    for (name, tree), values in samples.items():
        times = [v[0] for v in values]
        rows.append(
            {
                "command": name,
                "tree": tree,
                "median": statistics.median(times),
                "fastest": min(times),
                "rss": statistics.median(v[1] for v in values),
            }
        )
    return rows


def import_costs(repeats: int) -> tuple[list, list, float]:
    """Table 2: (module, median self ms, median cumulative ms) of the 10 largest self times in the Carter
    solve, the self time per top-level package, and the median total [ms]."""
    own = collections.defaultdict(list)
    cumulative = collections.defaultdict(list)
    totals = []
    env = child_environment()
    pattern = re.compile(r"import time:\s+(\d+) \|\s+(\d+) \| (\s*)(\S+)")
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            args = [sys.executable, "-X", "importtime", "-m", "rolling_cli", "-q", "solve"]
            args += [str(CASES / "carter.toml"), "-o", "c.h5", "--overwrite"]
            done = subprocess.run(args, cwd=tmp, env=env, capture_output=True, text=True, check=True)
            total = 0
            for line in done.stderr.splitlines():
                match = pattern.match(line)
                if match:
                    own[match.group(4)].append(int(match.group(1)) / 1e3)
                    cumulative[match.group(4)].append(int(match.group(2)) / 1e3)
                    if not match.group(3):  # a top-level import: its cumulative time counts once
                        total += int(match.group(2)) / 1e3
            totals.append(total)
    medians = {name: statistics.median(v) for name, v in own.items()}
    top = sorted(medians, key=medians.get, reverse=True)[:10]
    rows = [(name, medians[name], statistics.median(cumulative[name])) for name in top]
    packages = collections.defaultdict(float)
    for name, value in medians.items():
        packages[name.split(".")[0]] += value
    grouped = sorted(packages.items(), key=lambda kv: kv[1], reverse=True)[:10]
    return rows, grouped, statistics.median(totals)


def contact_time(error: float, column: int) -> tuple[float, str]:
    """CONTACT's time [s] at ``error`` (column 2: max, 3: RMS), log-log piecewise linear in its table,
    and "" inside the table's errors; beyond them no extrapolation: the finest row's time as a lower
    bound (">": CONTACT needs more than 1600 elements) or the coarsest row's as an upper bound ("<")."""
    points = sorted((row[column], row[1]) for row in CONTACT)
    log_e = np.log([p[0] for p in points])
    log_t = np.log([p[1] for p in points])
    x = math.log(error)
    if x < log_e[0]:
        return points[0][1], ">"
    if x > log_e[-1]:
        return points[-1][1], "<"
    return float(np.exp(np.interp(x, log_e, log_t))), ""


def comparison(repeats: int, quick: bool) -> list[dict]:
    """Table 3: uniform and adaptive Carter runs, whole process (interleaved), errors and CONTACT's times."""
    base = with_overrides(
        load_case(CASES / "carter.toml"),
        {"discretization.influence": "auto", "discretization.slip_derivative": "fd"},
    )
    sizes = UNIFORM[:3] if quick else UNIFORM
    tolerances = TOLERANCES[:2] if quick else TOLERANCES
    runs = [("uniform", n, with_overrides(base, {"discretization.contact_elements": n})) for n in sizes]
    runs += [("adaptive", tol, accuracy_cost.adaptive_case(base, tol)) for tol in tolerances]
    times = collections.defaultdict(list)
    results = {}
    for _ in range(repeats):
        for mode, value, case in runs:
            result, seconds = accuracy_cost.rollc(case, 1)
            times[mode, value].append(seconds)
            results[mode, value] = result
    reference = accuracy_cost.Reference(exact=True)
    rows = []
    for mode, value, _ in runs:
        r = results[mode, value]
        m = accuracy_cost.measure(r, 0.0, reference)
        seconds = statistics.median(times[mode, value])
        row = {"mode": mode, "value": value, "elements": r.contact_elements, "max": m["max"], "rms": m["rms"]}
        row["seconds"] = seconds
        for key, column in (("max", 2), ("rms", 3)):
            t, bound = contact_time(m[key], column)
            row[f"contact_{key}"], row[f"bound_{key}"] = t, bound
            row[f"ratio_{key}"] = t / seconds
        rows.append(row)
    return rows


def print_tables(startup: list[dict], imports: tuple | None, compare: list[dict] | None, repeats: int) -> None:
    print(f"\n## Whole process, median of {repeats} (interleaved), OPENBLAS_NUM_THREADS=1\n")
    print("| command | tree | median [s] | fastest [s] | peak RSS [MB] |")
    print("|---|---|---:|---:|---:|")
    for r in startup:
        print(f"| {r['command']} | {r['tree']} | {r['median']:.3f} | {r['fastest']:.3f} | {r['rss']:.0f} |")
    if imports is None:
        return
    top, grouped, total = imports
    print(f"\n## Imports of the Carter solve (-X importtime, median of {repeats}): total {total:.0f} ms\n")
    print("| module | self [ms] | cumulative [ms] |")
    print("|---|---:|---:|")
    for name, own, cumulative in top:
        print(f"| {name} | {own:.1f} | {cumulative:.1f} |")
    print("\n| top-level package | self time summed [ms] |")
    print("|---|---:|")
    for name, value in grouped:
        print(f"| {name} | {value:.1f} |")
    print("\n## rollc whole process against CONTACT at equal Carter error\n")
    print(
        "| run | elements | max error | RMS error | rollc whole process [s] | CONTACT at equal max [s] | ratio "
        "| CONTACT at equal RMS [s] | ratio |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in compare:
        run = f"uniform {r['value']}" if r["mode"] == "uniform" else f"adaptive, tolerance {r['value']:g}"
        cells = []
        for key in ("max", "rms"):
            bound = r[f"bound_{key}"]
            cells.append(f"{bound}{r[f'contact_{key}']:.2f} | {bound}{r[f'ratio_{key}']:.1f}x")
        print(
            f"| {run} | {r['elements']} | {100 * r['max']:.3f} % | {100 * r['rms']:.4f} % | {r['seconds']:.3f} | "
            + " | ".join(cells)
            + " |"
        )
    for key, label in (("max", "max"), ("rms", "RMS")):
        print(f"\n### Cost of reaching a {label} error: the fastest rollc run at or below it, CONTACT interpolated\n")
        print(f"| {label} error at most | fastest rollc run | rollc [s] | CONTACT [s] | ratio | {TARGET_RATIO:.0f}x |")
        print("|---:|---|---:|---:|---:|---|")
        for target, run, seconds, contact, bound in reach(compare, key):
            if run is None:
                print(f"| {100 * target:g} % | none | | {bound}{contact:.2f} | | |")
                continue
            ratio = contact / seconds
            met = ratio >= TARGET_RATIO and bound != "<"
            missed = ratio < TARGET_RATIO and bound != ">"
            verdict = "met" if met else "missed" if missed else "open"
            cells = f"{seconds:.3f} | {bound}{contact:.2f} | {bound}{ratio:.1f}x | {verdict}"
            print(f"| {100 * target:g} % | {run} | {cells} |")


def reach(compare: list[dict], key: str) -> list[tuple]:
    """Per target error of :data:`TARGETS`: (target, the fastest run meeting it, its time [s], CONTACT's
    time at the target [s], bound mark)."""
    column = 2 if key == "max" else 3
    rows = []
    for target in TARGETS:
        ok = [r for r in compare if r[key] <= target]
        best = min(ok, key=lambda r: r["seconds"]) if ok else None
        contact, bound = contact_time(target, column)
        if best is None:
            rows.append((target, None, math.nan, contact, bound))
            continue
        run = f"uniform {best['value']}" if best["mode"] == "uniform" else f"adaptive {best['value']:g}"
        rows.append((target, run, best["seconds"], contact, bound))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5, help="runs per command (median)")
    parser.add_argument(
        "--tree", action="append", default=[], help="NAME=DIR: a source tree of the package to compare with"
    )
    parser.add_argument("--quick", action="store_true", help="fewer meshes in the comparison (a smoke run)")
    parser.add_argument("--only-startup", action="store_true", help="table 1 only (the whole-process times)")
    args = parser.parse_args()
    os.environ.update(SINGLE_THREAD_ENV)  # accuracy_cost.rollc passes this environment on
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    startup = startup_table(args.repeats, dict(item.split("=", 1) for item in args.tree))
    if args.only_startup:
        print_tables(startup, None, None, args.repeats)
        return
    imports = import_costs(args.repeats)
    compare = comparison(args.repeats, args.quick)
    print_tables(startup, imports, compare, args.repeats)


if __name__ == "__main__":
    main()
