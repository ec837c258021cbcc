"""Random falling-law and viscoelastic cases on two source trees: convergence, answers, iterations.

A check of the cost work of issues 22 and 23 against a tree without it: ``--cases``
random cases (seed ``--seed``), each either Carter's or the dissimilar pair with a
random slip-speed law (exponential, linear, rational; mu_k/mu_s 0.5-0.95, s_h 20-300
mm/s, |V| 5000-60000 mm/s) under creep or force control, or the rigid roller / steel
on polymer of :mod:`bench_viscoelastic` at a random speed (x 10^(+-1.5)) and
Q/(mu P) 0-0.9; 100-300 elements. Each tree solves them in its own process
(``PYTHONPATH``); printed: the cases that fail in either tree, the largest relative
difference of p_n and p_t between the trees, and the Newton iterations of each kind.

    python benchmarks/speed_random_cases.py --tree before=DIR [--seed 11] [--cases 40]
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def cases(seed: int, count: int) -> list[tuple[str, dict]]:
    """(kind, case dict) of the random draw."""
    sys.path[1:1] = [str(HERE), str(ROOT / "tests")]
    import bench_viscoelastic as bv

    from helpers import CARTER, case_dict, dissimilar

    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        kind = str(rng.choice(["law", "visco"]))
        n = int(rng.choice([100, 150, 200, 300]))
        if kind == "law":
            data = case_dict(CARTER if rng.random() < 0.5 else dissimilar(), **{"discretization.contact_elements": n})
            law = str(rng.choice(["exponential", "linear", "rational"]))
            mu_s = float(rng.uniform(0.2, 0.5))
            mu_k = mu_s * float(rng.uniform(0.5, 0.95))
            data["friction"] = {"law": law, "mu_static": mu_s, "mu_kinetic": mu_k}
            data["friction"]["slip_velocity_half"] = float(rng.uniform(20, 300))
            data.setdefault("rolling", {})["speed"] = float(rng.uniform(5000, 60000))
            if rng.random() < 0.5:
                data["tangential"] = {"creep": -float(rng.uniform(1e-4, 5e-3))}
            else:
                data["tangential"] = {"q_over_mu_p": float(rng.uniform(0.1, 0.85))}
        else:
            data = copy.deepcopy(bv.ROLLER if rng.random() < 0.5 else bv.POLYMER)
            data["discretization"]["contact_elements"] = n
            data["rolling"]["speed"] = float(data["rolling"]["speed"] * 10 ** rng.uniform(-1.5, 1.5))
            data["tangential"] = {"q_over_mu_p": float(rng.uniform(0.0, 0.9))}
        out.append((kind, data))
    return out


def worker(seed: int, count: int) -> None:
    """Solve the draw with the tree on ``PYTHONPATH``; print JSON rows."""
    import rolling_cli

    rows = []
    for kind, data in cases(seed, count):
        try:
            r = rolling_cli.solve(rolling_cli.load_case(data))
            rows.append({"kind": kind, "ok": bool(r.converged), "it": int(r.attributes.get("iterations_total") or 0),
                         "p_n": np.asarray(r.p_n).tolist(), "p_t": np.asarray(r.p_t).tolist()})  # fmt: skip
        except Exception as err:  # a failure is a result here
            rows.append({"kind": kind, "ok": False, "error": str(err)[:120]})
    print(json.dumps(rows))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=11)
    parser.add_argument("--cases", type=int, default=40)
    parser.add_argument("--tree", default="", help="NAME=DIR: the source tree to compare with (required)")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args.seed, args.cases)
        return
    if "=" not in args.tree:
        parser.error("--tree NAME=DIR is required")
    name, other = args.tree.split("=", 1)
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    found = {}
    for tree, path in (("current", str(ROOT)), (name, other)):
        command = [sys.executable, __file__, "--worker", "--seed", str(args.seed), "--cases", str(args.cases)]
        out = subprocess.run(command, env={**env, "PYTHONPATH": path}, capture_output=True, text=True, check=True)
        found[tree] = json.loads(out.stdout.strip().splitlines()[-1])
    worst, iterations = 0.0, {}
    for i, (a, b) in enumerate(zip(found["current"], found[name], strict=True)):
        if not (a["ok"] and b["ok"]):
            print(f"case {i} ({a['kind']}): current {a.get('error', 'ok')}; {name} {b.get('error', 'ok')}")
            continue
        for key in ("p_n", "p_t"):
            x, y = np.array(a[key]), np.array(b[key])
            worst = max(worst, float(np.abs(x - y).max() / max(np.abs(y).max(), 1e-300)))
        its = iterations.setdefault(a["kind"], [0, 0, 0])
        its[0], its[1], its[2] = its[0] + 1, its[1] + a["it"], its[2] + b["it"]
    print(f"largest relative difference of p_n, p_t: {worst:.1e}")
    for kind, (count, now, then) in iterations.items():
        print(f"{kind}: {count} cases converged in both, Newton iterations current {now}, {name} {then}")


if __name__ == "__main__":
    if "--worker" in sys.argv:
        tree = os.environ.get("PYTHONPATH", "").split(os.pathsep)[0]
        if tree:
            sys.path.insert(0, tree)
    main()
