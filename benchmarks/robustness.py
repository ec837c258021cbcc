"""Robustness sweep: many random valid cases, biased to the extremes, solved cold.

Each case draws the moduli (1e2-1e6, log-uniform), Poisson ratios (0, 0.5 or
anything between), a rigid body A with probability 0.4, radii (5-1000 or a
flat), the friction (0.01, 1.5 or log-uniform between), the load, Q/(mu P)
(+-0.98 or uniform), the rolling direction, 8-60 contact elements and the
influence model (BEM one time in four). A case passes when it converges with
the default settings and satisfies the contact laws and the force balance
(tests/helpers.py). Failures are counted by type and by whether the case lies
in the strongly coupled, high-friction corner mu |beta_Dundurs| > 0.6.

    python benchmarks/robustness.py [--seeds 1,2,3,4,5,6,7] [--cases 400]
"""

from __future__ import annotations

import argparse
import collections
import math
import random
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

import helpers  # noqa: E402
from helpers import assert_contact_laws, assert_force_balance, solve  # noqa: E402


def random_case(rng: random.Random) -> tuple[dict, float]:
    def log_uniform(a, b):
        return math.exp(rng.uniform(math.log(a), math.log(b)))

    rigid = rng.random() < 0.4
    nu_a = rng.choice([0.0, 0.5, rng.uniform(0, 0.5)])
    nu_b = rng.choice([0.0, 0.5, rng.uniform(0, 0.5)])
    young_a, young_b = log_uniform(1e2, 1e6), log_uniform(1e2, 1e6)
    mu = rng.choice([0.01, 1.5, log_uniform(0.01, 1.5)])
    q = rng.choice([-0.98, 0.98, rng.uniform(-0.98, 0.98)])
    load = log_uniform(1, 1e3)
    radius_a = log_uniform(5, 1e3)  # the draws keep their order, so a seed gives the same cases
    radius_b = rng.choice([log_uniform(5, 1e3), math.inf])
    direction = rng.choice([-1, 1])
    elements = rng.randint(8, 60)
    influence = rng.choice(["half-plane"] * 3 + ["bem"])
    return helpers.random_case(
        young_a, young_b, rigid, nu_a, nu_b, radius_a, radius_b, mu, load, q, direction, elements, influence
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="1,2,3,4,5,6,7")
    parser.add_argument("--cases", type=int, default=400)
    args = parser.parse_args()
    print("| seed | cases | failed | failed with mu abs(beta) <= 0.6 | failure types | time [s] |")
    print("|---:|---:|---:|---:|---|---:|")
    totals = collections.Counter()
    for seed in (int(s) for s in args.seeds.split(",")):
        rng = random.Random(seed)
        kinds = collections.Counter()
        inside = 0
        t0 = time.perf_counter()
        for _ in range(args.cases):
            data, coupling = random_case(rng)
            try:
                with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
                    r = solve(data)
                    assert_contact_laws(r)
                    assert_force_balance(
                        r,
                        load=data["normal"]["load"],
                        q=data["tangential"]["q_over_mu_p"] * data["friction"]["mu"] * data["normal"]["load"],
                    )
            except Exception as err:  # every failure is counted, whatever its type
                kinds[type(err).__name__] += 1
                inside += coupling <= 0.6
        failed = sum(kinds.values())
        totals.update(kinds)
        shown = ", ".join(f"{k}: {v}" for k, v in kinds.items()) or "-"
        print(f"| {seed} | {args.cases} | {failed} | {inside} | {shown} | {time.perf_counter() - t0:.0f} |", flush=True)
    print(f"\ntotal failures by type: {dict(totals) or 'none'}")


if __name__ == "__main__":
    main()
