"""Solve time and Newton iterations against problem size (half-plane model).

n is the number of contact nodes, i.e. the unknowns per traction component:
n = elements for constant elements, 3 x elements for the paper's quadratic
ones. Each time is the median of ``--repeat`` runs of the whole pipeline
after import (plan, influence, system, Newton), from a cold start.

    python benchmarks/bench_solve.py [--repeat 3] [--sizes 50,100,...]
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402

CASES = Path(__file__).resolve().parents[1] / "cases"


def run(case, repeat):
    times, result = [], None
    for _ in range(repeat):
        clear_memo()  # every run builds its influence: no in-process reuse
        t = time.perf_counter()
        result = rolling_cli.solve(case)
        times.append(time.perf_counter() - t)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--sizes", default="50,100,200,400,800,1600,3200")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    print(
        f"# bench_solve: {platform.node()}, {platform.processor() or platform.machine()}, "
        f"python {platform.python_version()}, rolling_cli {rolling_cli.__version__}"
    )
    print("| case | element | n nodes | elements | time [s] | influence [s] | Newton [s] | iterations |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name, file in (("Carter q=0.51", "carter.toml"), ("dissimilar q=0.04", "dissimilar_q04.toml")):
        base = load_case(CASES / file)
        for element in ("constant", "quadratic"):
            for n in sizes:
                per = 1 if element == "constant" else 3
                elements = max(2, round(n / per))
                case = with_overrides(
                    base, {"discretization.element": element, "discretization.contact_elements": elements}
                )
                wall, r = run(case, args.repeat)
                print(
                    f"| {name} | {element} | {elements * per} | {elements} | {wall:.3f} | "
                    f"{r.time_influence:.3f} | {r.time_solve:.3f} | {r.iterations} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
