"""Whole-process timings of a finite cylinder (issue 21): a rubber-covered roller at a/R = 0.2.

A cover (E = 10, nu = 0.45) of thickness 1 on a rigid core, outer radius 5, on a rigid flat,
P = 3.3 (a/R = 0.194), mu = 0.5, Q/(mu P) = 0.5, 200 contact elements, cache off, one BLAS
thread: ``rollc solve`` (BEM build and solve, with the coarse pre-solve that measures a) and
``rollc sweep --curve load`` (a 41-point creep-force curve: one BEM build, warm starts), each
as a fresh process; wall time and the peak resident memory of the child (median of --repeat).

    python benchmarks/finite_roller.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CASE = """title = "Rubber-covered roller on a rigid flat, a/R = 0.2"
[bodies.A]
kind = "layered"
radius = 5.0
young = 10.0
poisson = 0.45
layer_thickness = 1.0
shape = "cylinder"
[bodies.B]
kind = "rigid"
radius = inf
[friction]
mu = 0.5
[normal]
load = 3.3
[tangential]
q_over_mu_p = 0.5
[rolling]
direction = -1
[discretization]
contact_elements = 200
"""


def _run(args: list[str], cwd: Path) -> tuple[float, float, float]:
    """Wall time [s], CPU time (user + system) [s] and peak RSS [MB] of one child process (the CPU
    time is the steadier figure on a machine loaded by other jobs). Compiled bytecode is allowed
    (PYTHONDONTWRITEBYTECODE unset), as in an installed package."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", ROLLC_NO_CACHE="1")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rolling_cli", *args], cwd=cwd, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return wall, cpu, max(after.ru_maxrss, before.ru_maxrss) / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        (work / "roller.toml").write_text(CASE)
        rows = {
            "solve (build + solve)": ["solve", "roller.toml", "-o", "r.h5", "--overwrite"],
            "41-point creep-force curve": [
                "sweep",
                "roller.toml",
                "--curve",
                "load",
                "-o",
                "c.h5",
                "--overwrite",
                "--workers",
                "1",
            ],  # fmt: skip
        }
        print("| run | wall [s] (median) | runs [s] | CPU [s] (median) | peak RSS [MB] |")
        print("|---|---:|---|---:|---:|")
        for name, command in rows.items():
            runs = [_run(command, work) for _ in range(args.repeat)]
            walls = [w for w, _, _ in runs]
            text = ", ".join(f"{w:.2f}" for w in walls)
            cpu = statistics.median(c for _, c, _ in runs)
            peak = max(m for _, _, m in runs)
            print(f"| {name} | {statistics.median(walls):.2f} | {text} | {cpu:.2f} | {peak:.0f} |", flush=True)


if __name__ == "__main__":
    main()
