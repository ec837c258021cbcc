"""Sweep costs: a 100-value friction sweep of the Carter case against one solve,
with and without warm starts, serial against --workers 2.

Both are timed as a user runs them: the wall time of the ``rollc`` command
(process start and imports included), median of ``--repeat`` runs; the
in-process solve times are reported too. Also a heavier sweep (the paper's
dissimilar BEM model, 200 elements, 20 friction values) where the solves,
not the file writes, dominate, for the serial/parallel comparison.

    python benchmarks/bench_sweep.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import h5py

ROOT = Path(__file__).resolve().parents[1]


def wall(args: list[str], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "rolling_cli", "-q", *args], check=True, cwd=ROOT)
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def summary(path: str) -> tuple[int, float]:
    with h5py.File(path) as f:
        return int(f["summary/iterations"][()].sum()), float(f["summary/time"][()].sum())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    tmp = Path(tempfile.mkdtemp())
    carter = str(ROOT / "cases" / "carter.toml")
    one = wall(["solve", carter, "-o", str(tmp / "one.h5")], args.repeat)
    print("| study | workers | warm start | wall [s] | / one solve | Newton iterations | solve time in process [s] |")
    print("|---|---:|---|---:|---:|---:|---:|")
    print(f"| one solve, Carter (200 elements) | 1 | - | {one:.2f} | 1.0 | - | - |")
    rows = [
        ("100 friction values, Carter", carter, "friction.mu=0.01:1:100", 1, True),
        ("100 friction values, Carter", carter, "friction.mu=0.01:1:100", 1, False),
        ("100 friction values, Carter", carter, "friction.mu=0.01:1:100", 2, True),
    ]
    heavy = str(tmp / "heavy.toml")
    Path(heavy).write_text(
        (ROOT / "cases" / "paper_fig5_q075.toml").read_text().replace("contact_elements = 21", "contact_elements = 200")
    )
    subprocess.run(
        [sys.executable, "-m", "rolling_cli", "-q", "solve", heavy, "-o", str(tmp / "warm.h5")], check=True, cwd=ROOT
    )  # fill the influence cache first: the sweep then times solves only
    rows += [
        ("20 friction values, dissimilar BEM (200 elements)", heavy, "friction.mu=0.1:0.8:20", 1, True),
        ("20 friction values, dissimilar BEM (200 elements)", heavy, "friction.mu=0.1:0.8:20", 2, True),
    ]
    for name, case, values, workers, warm in rows:
        out = str(tmp / "s.h5")
        extra = [] if warm else ["--no-warm-start"]
        seconds = wall(["sweep", case, "--set", values, "-o", out, "--workers", str(workers), *extra], args.repeat)
        iterations, solve_time = summary(out)
        print(
            f"| {name} | {workers} | {'yes' if warm else 'no'} | {seconds:.2f} | {seconds / one:.1f} | "
            f"{iterations} | {solve_time:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
