"""Force control: the combined Newton system against the scalar creepage root, strategy by strategy.

Each strategy of :mod:`rolling_cli.solver.strategies` is run alone (a budget
of 500 iterations, cold start, the case's own grid and zone 2.25 a so that
no zone enlargement interferes) on the random force-controlled cases of
``benchmarks/robustness.py`` (part 1, the given seeds): ``direct`` (the
combined system, overlap and creepage as Newton unknowns) with the watchdog
and with the monotone line search, ``creep_root`` (safeguarded Newton and
bisection on the scalar creepage, dQ/dxi from the reduced Jacobian, stopping on
the force residual), ``settled`` and ``coupling_path``. Reported per strategy:
failures, median / p90 Newton iterations (linear solves) of the successes,
and the solve time.

    python benchmarks/force_control.py [--seeds 1,2] [--cases 400]
"""

from __future__ import annotations

import argparse
import logging
import random
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from robustness import random_case  # noqa: E402

from rolling_cli import pipeline  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.solver import strategies  # noqa: E402
from rolling_cli.solver.budget import Budget  # noqa: E402

CHOICES = {
    "direct (watchdog)": strategies._with(strategies.direct, strategies.WATCHDOG),
    "direct (monotone)": strategies._with(strategies.direct, strategies.MONOTONE),
    "creep_root": strategies._with(strategies.creep_root, strategies.MONOTONE),
    "settled": strategies._with(strategies.settled, strategies.MONOTONE),
    "coupling_path": strategies._with(strategies.coupling_path, strategies.MONOTONE),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="1,2")
    parser.add_argument("--cases", type=int, default=400)
    args = parser.parse_args()
    logging.disable(logging.WARNING)
    tasks = []
    for seed in (int(s) for s in args.seeds.split(",")):
        rng = random.Random(seed)
        for _ in range(args.cases):
            data, coupling = random_case(rng)
            case = with_overrides(load_case(data), {"discretization.zone": 2.25})
            the_plan, system = pipeline.prepare(case)
            task = pipeline._task(case, the_plan, system)
            tasks.append((task, pipeline.initial_state(case, the_plan, system), coupling))
    print(f"{len(tasks)} force-controlled cases (seeds {args.seeds}), zone 2.25 a, each strategy alone\n")
    print("| strategy | coupled cases | failed | median iterations | p90 | time [s] |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, strategy in CHOICES.items():
        its, failed, coupled = [], 0, 0
        t0 = time.perf_counter()
        for task, start, _ in tasks:
            if task.formulation != "coupled":
                continue  # decoupled tasks solve the tangential stage alone: the same for every choice
            coupled += 1
            budget = Budget(500)
            try:
                strategy(task, start, budget, cold=True)
                its.append(budget.taken)
            except strategies.StrategyFailed:
                failed += 1
        its = np.array(its or [0])
        print(
            f"| {name} | {coupled} | {failed} | {np.median(its):.0f} | {np.percentile(its, 90):.0f} "
            f"| {time.perf_counter() - t0:.1f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
