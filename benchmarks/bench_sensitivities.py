"""Sensitivities (issue 24 item 1): their accuracy against finite differences and their cost.

Part 1, finite differences: ``--cases`` random cases of benchmarks/robustness.py's
domain (its half-space draw, and its layer draw one time in four), each under force
control (as drawn) and under creepage control (at the solved creepage); every
recorded sensitivity against a central difference of re-solved cases, relative step
1e-6 (tests/sensitivity_checks.py). Reports the cases compared, the largest relative
error, and every point where the zone pattern changed within the step (not compared).

Part 2, cost: the shipped cases, each solved ``--repeat`` times; the time of the
sensitivities (``time_sensitivities``: the extra linear solves) against the rest of
the solve (``time_total_solve`` minus it), with the influence rebuilt (cache off)
and memoised (a sweep's later cases), and against the wall time of the whole
``rollc solve`` command (a fresh process, cache off). Medians.

    python benchmarks/bench_sensitivities.py [--cases 100] [--seed 1] [--repeat 3]
"""

from __future__ import annotations

import argparse
import logging
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import robustness  # noqa: E402
from sensitivity_checks import TOLERANCE, check_case  # noqa: E402

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402


def finite_differences(cases: int, seed: int) -> None:
    rng = random.Random(seed)
    compared = left_out = 0
    worst = (0.0, "")
    changes, failures, resolve_failures = [], [], []
    t0 = time.perf_counter()
    for k in range(cases):
        layer = rng.random() < 0.25
        data = (robustness.random_layer_case if layer else robustness.random_case)(rng)[0]
        for force in (True, False):
            label = f"case {k} ({'layer' if layer else 'half-space'}, {'force' if force else 'creepage'} control)"
            try:
                with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
                    checks = check_case(data, force)
            except Exception as err:  # a re-solve that fails is listed
                resolve_failures.append(f"{label}: {type(err).__name__}: {str(err)[:160]}")
                continue
            if isinstance(checks, str):
                left_out += 1
                continue
            compared += 1
            for check in checks:
                if check.pattern_changed:
                    changes.append(f"{label}: {check.name}")
                elif check.error > worst[0]:
                    worst = (check.error, f"{label}: {check.name}")
                if not check.pattern_changed and check.error > TOLERANCE:
                    failures.append(f"{label}: {check.name} error {check.error:.2e}")
    print(f"\nPart 1: {cases} random cases x 2 controls, {time.perf_counter() - t0:.0f} s")
    print(f"- compared: {compared} (case, control) pairs; left out (not solved or zone enlarged): {left_out}")
    print(f"- largest relative error where the pattern held: {worst[0]:.2e} ({worst[1]})")
    print(f"- above {TOLERANCE:g}: {len(failures)}")
    for line in failures:
        print(f"  - {line}")
    print(f"- a re-solve of the difference failed (not compared): {len(resolve_failures)}")
    for line in resolve_failures:
        print(f"  - {line}")
    print(f"- zone pattern changed within the step (reported, not compared): {len(changes)}")
    for line in changes:
        print(f"  - {line}")


def cost(repeat: int) -> None:
    print("\nPart 2: cost of the sensitivities (medians)\n")
    print(
        "| case | nodes | sensitivities [ms] | rest, influence rebuilt [ms] | share | rest, memoised [ms] | share "
        "| rollc solve [ms] | share |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for path in sorted((ROOT / "cases").glob("*.toml")):
        case = load_case(path)
        if getattr(case, "sweep", None) is not None:  # a sweep's file: its base case is another's
            continue
        cold, warm, sens = [], [], []
        for _ in range(repeat):
            clear_memo()
            r = rolling_cli.solve(case, use_cache=False)
            cold.append(r.time_total_solve - r.time_sensitivities)
            sens.append(r.time_sensitivities)
            r = rolling_cli.solve(case, use_cache=False)
            warm.append(r.time_total_solve - r.time_sensitivities)
            sens.append(r.time_sensitivities)
        command = []
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(repeat):
                t = time.perf_counter()
                subprocess.run(
                    [sys.executable, "-m", "rolling_cli", "solve", str(path), "-o", f"{tmp}/r.h5", "-q",
                     "--overwrite", "--no-cache"],
                    check=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
                )  # fmt: skip
                command.append(time.perf_counter() - t)
        s, c, w, e = (statistics.median(v) for v in (sens, cold, warm, command))
        print(
            f"| {path.stem} | {r.x.size} | {1e3 * s:.1f} | {1e3 * c:.0f} | {100 * s / c:.1f} % "
            f"| {1e3 * w:.0f} | {100 * s / w:.1f} % | {1e3 * e:.0f} | {100 * s / e:.1f} % |",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--skip-differences", action="store_true")
    args = parser.parse_args()
    logging.disable(logging.WARNING)
    if not args.skip_differences:
        finite_differences(args.cases, args.seed)
    cost(args.repeat)


if __name__ == "__main__":
    main()
