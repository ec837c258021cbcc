"""A viscoelastic cover against today's tyre case on two source trees, interleaved (issue 22 cost target).

The cases of :mod:`bench_viscoelastic_layer` (the paper's Fig. 11 tyre as an SLS cover,
``cases/rubber_cover.toml``), each against its elastic twin (the layer with E_r, no history), on
``--sizes`` quadratic elements, with the elastic BEM layer read from the disk cache (a re-run, a
sweep; the in-process memos cleared before every solve, as a new process). In one process the
twin and the cover are solved alternately, ``--repeat`` times (median wall and process CPU time);
each tree (``--tree NAME=DIR``, DIR a source tree of the package, e.g. ``git archive <commit>
rolling_cli | tar -x -C DIR``; the current tree is always "current") runs in its own subprocess,
the trees alternated round by round (``--rounds``), so the shared machine's load hits all alike.
Also reported: the largest difference of the cover's p_n, p_t and rolling-resistance outputs
between each tree and the current one, relative to their largest magnitude. One BLAS thread.

    python benchmarks/bench_cover_ab.py [--rounds 3] [--repeat 5] [--sizes 60,120,240] [--tree NAME=DIR ...]
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: The cover's outputs compared between the trees (besides p_n and p_t).
OUTPUTS = ("rolling_resistance_coefficient", "hysteresis_power", "pressure_shift", "creep", "overlap")


def _pairs(sizes: list[int]) -> dict[str, tuple[dict, dict]]:
    """name -> (twin case dict, cover case dict)."""
    sys.path.insert(0, str(HERE))
    import bench_viscoelastic_layer as bl

    out = {}
    for name, make in bl.CASES.items():
        for n in sizes:
            cover = make()
            cover["discretization"]["contact_elements"] = n
            out[f"{name.split(' (')[0]}, {n} el."] = (bl.twin(cover), cover)
    return out


def _clear() -> None:
    """Every in-process memo of the influence (a new process's state; the disk cache stays)."""
    from rolling_cli.influence import build, viscoelastic

    build.clear_memo()
    if hasattr(viscoelastic, "clear_memo"):  # the fast tree's kernel memo
        viscoelastic.clear_memo()


def worker(repeat: int, sizes: list[int]) -> None:
    """Measure in this process (the tree on ``sys.path`` first); print JSON."""
    import rolling_cli

    results = {}
    for name, pair in _pairs(sizes).items():
        cases = [rolling_cli.load_case(copy.deepcopy(data)) for data in pair]
        for case in cases:
            rolling_cli.solve(case)  # warm-up (imports, the disk cache filled)
        samples: list[list[tuple[float, float]]] = [[], []]
        iterations = [0, 0]
        for _ in range(repeat):
            for member, case in enumerate(cases):
                _clear()
                wall, cpu = time.perf_counter(), time.process_time()
                result = rolling_cli.solve(case)
                samples[member].append((time.perf_counter() - wall, time.process_time() - cpu))
                assert result.converged
                iterations[member] = int(result.attributes.get("iterations_total") or result.iterations)
        answer = {"p_n": [float(v) for v in result.p_n], "p_t": [float(v) for v in result.p_t]}
        answer.update({key: float(result.attributes.get(key, getattr(result, key, float("nan")))) for key in OUTPUTS})
        results[name] = {
            "wall": [statistics.median(s[0] for s in member) for member in samples],
            "cpu": [statistics.median(s[1] for s in member) for member in samples],
            "iterations": iterations,
            "answer": answer,
        }
    print(json.dumps(results))


def _difference(a: dict, b: dict) -> float:
    """Largest relative difference of two answers (arrays relative to their largest magnitude)."""
    worst = 0.0
    for key in a:
        x, y = a[key], b[key]
        x, y = (x, y) if isinstance(x, list) else ([x], [y])
        if len(x) != len(y):
            return float("inf")
        scale = max(max(abs(v) for v in y), 1e-300)
        worst = max(worst, max(abs(u - v) for u, v in zip(x, y, strict=True)) / scale)
    return worst


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", default="60,120,240")
    parser.add_argument("--tree", action="append", default=[], help="NAME=DIR: a source tree to compare with")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    sizes = [int(n) for n in args.sizes.split(",")]
    if args.worker:
        worker(args.repeat, sizes)
        return
    trees = {**dict(item.split("=", 1) for item in args.tree), "current": str(ROOT)}
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    runs: dict[str, list[dict]] = {tree: [] for tree in trees}
    for _ in range(args.rounds):
        for tree, path in trees.items():
            command = [sys.executable, str(Path(__file__)), "--worker", "--repeat", str(args.repeat)]
            command += ["--sizes", args.sizes]
            out = subprocess.run(
                command, env={**env, "PYTHONPATH": path}, capture_output=True, text=True, check=True
            ).stdout
            runs[tree].append(json.loads(out.strip().splitlines()[-1]))
    print(f"median over {args.rounds} rounds x {args.repeat} solves, wall [ms] (CPU [ms]), BEM from the disk cache")
    print("| case | tree | elastic tyre | viscoelastic cover | ratio wall | ratio CPU | iterations |", end=" ")
    print("answer vs current |")
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for name in runs["current"][0]:
        for tree in trees:
            rows = [run[name] for run in runs[tree]]
            wall = [statistics.median(r["wall"][m] for r in rows) for m in (0, 1)]
            cpu = [statistics.median(r["cpu"][m] for r in rows) for m in (0, 1)]
            its = rows[0]["iterations"]
            diff = _difference(rows[0]["answer"], runs["current"][0][name]["answer"])
            print(
                f"| {name} | {tree} | {1e3 * wall[0]:.0f} ({1e3 * cpu[0]:.0f}) "
                f"| {1e3 * wall[1]:.0f} ({1e3 * cpu[1]:.0f}) | {wall[1] / wall[0]:.2f} | {cpu[1] / cpu[0]:.2f} "
                f"| {its[0]} / {its[1]} | {diff:.1e} |"
            )


if __name__ == "__main__":
    if "--worker" in sys.argv:
        tree = os.environ.get("PYTHONPATH", "").split(os.pathsep)[0]
        if tree:
            sys.path.insert(0, tree)
    main()
