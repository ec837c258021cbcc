"""Robustness sweep: many random valid cases, biased to the extremes, solved cold with the defaults.

Part 1, half-spaces (the draw of every earlier measurement, so seeds give the
same cases): the moduli (1e2-1e6, log-uniform), Poisson ratios (0, 0.5 or
anything between), a rigid body A with probability 0.4, radii (5-1000 or a
flat), the friction (0.01, 1.5 or log-uniform between), the load, Q/(mu P)
(+-0.98 or uniform), the rolling direction, 8-60 contact elements and the
influence model (BEM one time in four), loaded by force.

Part 2, layers (``--layers N``): a rigid cylinder on a layered body (a layer of
thickness b bonded to a rigid core), b/a from 0.05 to 2 (log-uniform), the
layer's nu (0.3, 0.45, 0.5 or anything between), mu (0.05-1), Q/(mu P), the
rolling direction, loaded by overlap or by force, with the fewest contact
elements the layer allows (at most b/2 long) times 1-2.

A case passes when it converges and satisfies the contact laws and the force
balance (tests/helpers.py) at the tolerance the solve applied. Every failure is
listed with its reason and mu |beta_Dundurs|.

    python benchmarks/robustness.py [--seeds 1,2,3,4,5,6,7] [--cases 400] [--layers 200]
"""

from __future__ import annotations

import argparse
import collections
import logging
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
from helpers import assert_contact_laws, assert_force_balance, case_dict, solve  # noqa: E402


def _log_uniform(rng: random.Random, a: float, b: float) -> float:
    return math.exp(rng.uniform(math.log(a), math.log(b)))


def random_case(rng: random.Random) -> tuple[dict, float]:
    """A half-space case (part 1) and its mu |beta_Dundurs|."""
    rigid = rng.random() < 0.4
    nu_a = rng.choice([0.0, 0.5, rng.uniform(0, 0.5)])
    nu_b = rng.choice([0.0, 0.5, rng.uniform(0, 0.5)])
    young_a, young_b = _log_uniform(rng, 1e2, 1e6), _log_uniform(rng, 1e2, 1e6)
    mu = rng.choice([0.01, 1.5, _log_uniform(rng, 0.01, 1.5)])
    q = rng.choice([-0.98, 0.98, rng.uniform(-0.98, 0.98)])
    load = _log_uniform(rng, 1, 1e3)
    radius_a = _log_uniform(rng, 5, 1e3)  # the draws keep their order, so a seed gives the same cases
    radius_b = rng.choice([_log_uniform(rng, 5, 1e3), math.inf])
    direction = rng.choice([-1, 1])
    elements = rng.randint(8, 60)
    influence = rng.choice(["half-plane"] * 3 + ["bem"])
    return helpers.random_case(
        young_a, young_b, rigid, nu_a, nu_b, radius_a, radius_b, mu, load, q, direction, elements, influence
    )


def random_layer_case(rng: random.Random) -> tuple[dict, float]:
    """A rigid cylinder on a layer (part 2); returns the case and 0 (no Dundurs beta for a layer).

    The load or overlap is drawn for an intended half-width a; the contact
    elements follow from the half-width the solver measures (its frictionless
    pre-solve), so that they are at most b/2 long as the layer model requires.
    """
    from rolling_cli import pipeline
    from rolling_cli.case import load_case

    radius = _log_uniform(rng, 20.0, 500.0)
    young = _log_uniform(rng, 1.0, 1e4)
    nu = rng.choice([0.3, 0.45, 0.5, rng.uniform(0.0, 0.5)])
    a = _log_uniform(rng, 0.2, 5.0)  # the intended contact half-width [length]
    thickness = _log_uniform(rng, 0.05, 2.0) * a  # b / a from 0.05 to 2
    mu = _log_uniform(rng, 0.05, 1.0)
    q = rng.choice([-0.98, 0.98, rng.uniform(-0.98, 0.98)])
    direction = rng.choice([-1, 1])
    if rng.random() < 0.5:  # interference of a rigid cylinder: a^2 / 2R, a third of it on a bulging layer
        normal = {"normal.overlap": a * a / (2.0 * radius) / (3.0 if nu >= 0.45 else 1.0)}
    else:  # Hertz's load for a on a half-space of the layer's material (a layer is stiffer)
        normal = {"normal.load": math.pi * a * a * young / (1.0 - nu * nu) / (4.0 * radius)}
    layer = {"kind": "layered", "radius": radius, "young": young, "poisson": nu, "layer_thickness": thickness}
    data = case_dict(
        **{
            "bodies.A": {"kind": "rigid", "radius": radius},
            "bodies.B": layer,
            "friction.mu": mu,
            "tangential.q_over_mu_p": q,
            "rolling.direction": direction,
            "discretization.influence": "bem",
            **normal,
        }
    )
    measured = pipeline.estimate_half_width(load_case(data))
    fewest = 2.0 * data["discretization"]["zone"] * measured / (0.5 * thickness)
    data["discretization"]["contact_elements"] = int(min(max(math.ceil(fewest * rng.uniform(1.0, 2.0)), 20), 600))
    return data, 0.0


def run(draw, seeds: list[int], cases: int, label: str) -> collections.Counter:
    """Solve ``cases`` draws per seed; print one table row per seed and every failure."""
    print(f"\n{label}\n")
    print("| seed | cases | failed | median iterations | p90 | max | total | time [s] |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    totals = collections.Counter()
    failures = []
    for seed in seeds:
        rng = random.Random(seed)
        iterations = []
        failed = 0
        t0 = time.perf_counter()
        for k in range(cases):
            data, coupling = draw(rng)
            try:
                with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
                    r = solve(data)
                    assert_contact_laws(r, r.tolerance_applied)
                    load = data["normal"].get("load")
                    q = data["tangential"]["q_over_mu_p"] * data["friction"]["mu"] * (load or r.normal_load)
                    assert_force_balance(r, load=load, q=q, tolerance=r.tolerance_applied)
                    iterations.append(r.iterations_total)
            except Exception as err:  # every failure is counted and listed, whatever its type
                failed += 1
                totals[type(err).__name__] += 1
                failures.append((seed, k, coupling, type(err).__name__, str(err)[:240]))
        its = np.array(iterations or [0])
        print(
            f"| {seed} | {cases} | {failed} | {np.median(its):.0f} | {np.percentile(its, 90):.0f} | {its.max()} "
            f"| {its.sum()} | {time.perf_counter() - t0:.0f} |",
            flush=True,
        )
    for seed, k, coupling, kind, message in failures:
        print(f"- seed {seed}, case {k} (mu |beta_Dundurs| = {coupling:.3f}): {kind}: {message}")
    print(f"\nfailures by type: {dict(totals) or 'none'}")
    return totals


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="1,2,3,4,5,6,7")
    parser.add_argument("--cases", type=int, default=400)
    parser.add_argument("--layers", type=int, default=0, help="layer cases per seed (part 2); 0 skips it")
    args = parser.parse_args()
    logging.disable(logging.WARNING)  # zone enlargements are expected here; the table counts outcomes
    seeds = [int(s) for s in args.seeds.split(",")]
    run(random_case, seeds, args.cases, "Part 1: half-spaces, loaded by force")
    if args.layers:
        run(random_layer_case, seeds, args.layers, "Part 2: a rigid cylinder on a layer, by overlap or force")


if __name__ == "__main__":
    main()
