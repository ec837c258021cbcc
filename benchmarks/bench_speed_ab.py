"""The cost ratios of issues 22 and 23 on two source trees, interleaved (before/after a change).

Two pairs of in-process solves, each the median of cold solves (the influence memo
cleared) with the pair's two members alternated solve by solve, so that a shared
machine's load hits both alike:

* ``friction``: Carter's cylinders (half-plane, ``--elements``, 200 by default), Coulomb
  mu = 0.30 against the exponential law of issue 23 (mu_s 0.30, mu_k 0.18,
  s_h 100 mm/s at |V| = 45000 mm/s), creep and force control
  (:mod:`bench_friction`'s cases; on further grids of ``--elements`` three of them);
* ``visco``: a rigid roller and a steel roller on an SLS flat against their
  elastic twins with E_r (:mod:`bench_viscoelastic`'s cases), 200 and 800 elements.

Each tree (``--tree NAME=DIR``, repeatable; DIR a source tree of the package, for
example ``git archive <commit> rolling_cli | tar -x -C DIR``; the current tree is
always measured as "current") runs in its own subprocess (``PYTHONPATH=DIR``), the
trees alternated round by round (``--rounds``). Reported per case and tree: the median
wall time [ms] and process CPU time [ms] of each member, their ratio, and the Newton
iterations of all mesh levels. One BLAS thread.

    python benchmarks/bench_speed_ab.py [--rounds 5] [--repeat 5] [--suite friction,visco] [--elements 200,400]
                                        [--tree NAME=DIR ...]
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


def _pairs(suite: str, elements: list[int]) -> dict[str, tuple[dict, dict]]:
    """name -> (reference case dict, case dict) of a suite (friction: on each grid of ``elements``)."""
    sys.path.insert(0, str(HERE))
    if suite == "friction":
        import bench_friction as bf

        controls = [{"creep": xi} for xi in (-0.0005, -0.001, -0.002, -0.004)]
        controls += [{"q_over_mu_p": q} for q in (0.3, 0.5, 0.7)]
        out = {}
        for n in elements:
            for tangential in controls if n == elements[0] else controls[2::3]:
                ((kind, value),) = tangential.items()
                out[f"{kind} = {value:g}, {n} el."] = (bf.case(n, tangential, False), bf.case(n, tangential, True))
        return out
    import bench_viscoelastic as bv

    out = {}
    for name, data in bv.CASES.items():
        for n in (200, 800):
            visco = copy.deepcopy(data)
            visco["discretization"]["contact_elements"] = n
            out[f"{name.split(',')[0]}, {n} el."] = (bv.twin(visco), visco)
    return out


def worker(suite: str, repeat: int, elements: list[int]) -> None:
    """Measure a suite in this process (the tree on ``sys.path`` first); print JSON."""
    import rolling_cli
    from rolling_cli.influence import viscoelastic
    from rolling_cli.influence.build import clear_memo

    results = {}
    for name, pair in _pairs(suite, elements).items():
        cases = [rolling_cli.load_case(copy.deepcopy(data)) for data in pair]
        for case in cases:
            rolling_cli.solve(case)  # warm-up (imports, process caches)
        samples: list[list[tuple[float, float]]] = [[], []]
        iterations = [0, 0]
        for _ in range(repeat):
            for member, case in enumerate(cases):
                clear_memo()
                getattr(viscoelastic, "clear_memo", lambda: None)()  # the kernels' memo (not in older trees)
                wall, cpu = time.perf_counter(), time.process_time()
                result = rolling_cli.solve(case)
                samples[member].append((time.perf_counter() - wall, time.process_time() - cpu))
                assert result.converged
                iterations[member] = int(result.attributes.get("iterations_total") or result.iterations)
        results[name] = {
            "wall": [statistics.median(s[0] for s in member) for member in samples],
            "cpu": [statistics.median(s[1] for s in member) for member in samples],
            "iterations": iterations,
        }
    print(json.dumps(results))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--suite", default="friction,visco")
    parser.add_argument("--elements", default="200", help="friction grids (the first: all controls)")
    parser.add_argument("--tree", action="append", default=[], help="NAME=DIR: a source tree to compare with")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.worker, args.repeat, [int(n) for n in args.elements.split(",")])
        return
    trees = {**dict(item.split("=", 1) for item in args.tree), "current": str(ROOT)}
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    for suite in args.suite.split(","):
        runs: dict[str, list[dict]] = {tree: [] for tree in trees}
        for _ in range(args.rounds):
            for tree, path in trees.items():
                command = [sys.executable, str(Path(__file__)), "--worker", suite, "--repeat", str(args.repeat)]
                command += ["--elements", args.elements]
                out = subprocess.run(
                    command, env={**env, "PYTHONPATH": path}, capture_output=True, text=True, check=True
                ).stdout
                runs[tree].append(json.loads(out.strip().splitlines()[-1]))
        print(f"\n{suite}: median over {args.rounds} rounds x {args.repeat} solves, wall [ms] (CPU [ms])")
        print("| case | tree | reference | case | ratio wall | ratio CPU | iterations ref. / case |")
        print("|---|---|---:|---:|---:|---:|---:|")
        for name in runs["current"][0]:
            for tree in trees:
                rows = [run[name] for run in runs[tree]]
                wall = [statistics.median(r["wall"][m] for r in rows) for m in (0, 1)]
                cpu = [statistics.median(r["cpu"][m] for r in rows) for m in (0, 1)]
                its = rows[0]["iterations"]
                print(
                    f"| {name} | {tree} | {1e3 * wall[0]:.1f} ({1e3 * cpu[0]:.1f}) | {1e3 * wall[1]:.1f} "
                    f"({1e3 * cpu[1]:.1f}) | {wall[1] / wall[0]:.2f} | {cpu[1] / cpu[0]:.2f} | {its[0]} / {its[1]} |"
                )


if __name__ == "__main__":
    if "--worker" in sys.argv:
        tree = os.environ.get("PYTHONPATH", "").split(os.pathsep)[0]
        if tree:
            sys.path.insert(0, tree)
    main()
