"""Creep-force tables (issue 24 items 2-3): solves, time, accuracy and the interpolant's speed.

For each case (default: Carter's and the aluminium/steel pair of cases/): the whole
``rollc table CASE --tolerance 1e-3`` process (wall time, solves, nodes, error
estimate), then ``--points`` direct creepage-controlled solves at random creepages
inside the table's domain against the table (largest |Delta Q/(mu P)|), and the
interpolant's time per query in one vectorised call of 10^4 points (median of 20).

    python benchmarks/bench_table.py [--points 1000] [--cases carter,dissimilar_q75]

With ``--mu LO:HI`` the tables are two-axis (creepage x mu; ``--workers N`` passes on), and the
random points are drawn in (u, mu).

    python benchmarks/bench_table.py --mu 0.1:0.3 --points 200 --cases dissimilar_q75 [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rolling_cli import pipeline, table  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", type=int, default=1000)
    parser.add_argument("--cases", default="carter,dissimilar_q75")
    parser.add_argument("--tolerance", type=float, default=1e-3)
    parser.add_argument("--mu", default=None, help="LO:HI: two-axis tables (creepage x mu)")
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args()
    if args.mu is not None:
        two_axes(args)
        return
    logging.disable(logging.WARNING)
    print("| case | solves | nodes | error estimate | rollc table [s] | points | max abs error | query [us] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name in args.cases.split(","):
        path = ROOT / "cases" / f"{name}.toml"
        with tempfile.TemporaryDirectory() as tmp:
            out = f"{tmp}/t.h5"
            t0 = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "rolling_cli", "table", str(path), "-o", out, "-q", "--no-cache",
                 "--tolerance", str(args.tolerance)],
                check=True, env={**os.environ, "PYTHONPATH": str(ROOT)},
            )  # fmt: skip
            wall = time.perf_counter() - t0
            made = table.load(out)
        case = load_case(path)
        the_plan, system = pipeline.prepare(case)
        scale = made.attributes["creep_scale"]
        lo, hi = made.domain
        worst = 0.0
        for u in np.random.default_rng(1).uniform(lo, hi, args.points):
            point = dataclasses.replace(case, tangential=type(case.tangential)(creep=float(u * scale)))
            direct = pipeline.solve(point, system=system).q_over_mu_p
            worst = max(worst, abs(float(made(u)) - direct))
        queries = np.random.default_rng(2).uniform(lo, hi, 10_000)
        times = []
        for _ in range(20):
            t0 = time.perf_counter()
            made(queries)
            times.append(time.perf_counter() - t0)
        per_query = statistics.median(times) / queries.size * 1e6
        print(
            f"| {name} | {made.attributes['cases']} | {made.nodes.size} | {made.error_bound:.2e} | {wall:.2f} "
            f"| {args.points} | {worst:.2e} | {per_query:.2f} |",
            flush=True,
        )


def two_axes(args) -> None:
    """Two-axis tables: the whole ``rollc table --mu`` process, then direct solves at random (u, mu)."""
    print("| case | rows | solves | workers | error estimate | met | rollc table [s] | points | max abs error |")
    print("|---|---:|---:|---:|---:|---|---:|---:|---:|")
    for name in args.cases.split(","):
        path = ROOT / "cases" / f"{name}.toml"
        with tempfile.TemporaryDirectory() as tmp:
            out = f"{tmp}/t.h5"
            t0 = time.perf_counter()
            done = subprocess.run(
                [sys.executable, "-m", "rolling_cli", "table", str(path), "-o", out, "-q", "--no-cache",
                 "--tolerance", str(args.tolerance), "--mu", args.mu, "--workers", str(args.workers)],
                env={**os.environ, "PYTHONPATH": str(ROOT)},
            )  # fmt: skip
            wall = time.perf_counter() - t0
            if done.returncode not in (0, 1):  # 1: written, the estimate not met
                raise SystemExit(f"rollc table failed ({done.returncode})")
            made = table.load(out)
        case = load_case(path)
        the_plan, system = pipeline.prepare(case)
        (lo, hi), (mu_lo, mu_hi) = made.domain
        rng = np.random.default_rng(1)
        worst = 0.0
        for u, mu in zip(rng.uniform(lo, hi, args.points), rng.uniform(mu_lo, mu_hi, args.points), strict=True):
            creep = float(u * mu * the_plan.half_width / the_plan.radius)
            point = dataclasses.replace(
                case, friction=dataclasses.replace(case.friction, mu=float(mu)),
                tangential=type(case.tangential)(creep=creep),
            )  # fmt: skip
            direct = pipeline.solve(point, system=system).q_over_mu_p
            worst = max(worst, abs(float(made(u, mu)) - direct))
        attrs = made.attributes
        print(
            f"| {name} | {len(made.rows)} | {attrs['cases']} | {args.workers} | {made.error_bound:.2e} "
            f"| {attrs['met']} | {wall:.1f} | {args.points} | {worst:.2e} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
