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

Part 3, small friction (``--small-mu N``, issue 26): half-spaces with mu from
1e-4 to 1e-2 (log-uniform) and a coupling (|beta_Dundurs| >= 0.02: moduli
1e1-1e6, Poisson ratios 0-0.5, a rigid body A with probability 0.3), near full
slip (Q/(mu P) = +-0.999 or +-0.95 to 0.999), both rolling directions, radii
100-2e4, 20-200 contact elements, BEM one time in two, loaded by force.

Part 4, thin incompressible layers near full slip (``--thin-layers``, issue
26): a rigid R = 100 on a layered R = 100 (E = 10, nu = 0.5), b = 0.05 a_H
(a_H = 1.545, Hertz's half-width of P = 0.5 on a half-space of the layer's
material), overlaps 0.0085-0.011 (a = 1.44-1.64), mu = 0.1, 200 elements, BEM,
Q/(mu P) = 0.7, 0.8, 0.9, 0.95 in both rolling directions (40 fixed cases).

Part 5, falling friction (``--laws N``, issue 23): similar steel cylinders or aluminium on steel
(R = 20-500), a law drawn from linear, rational, exponential and Polach's (mu_static 0.1-0.6,
mu_kinetic / mu_static 0.3-0.9, s_h 10-1000 mm/s; Polach: A 0.3-0.9, B 1e-3-0.1 s/mm) at |V| =
45000 mm/s (as cases/falling_exponential.toml), loaded by force (Q/(mu_static P) +-0.98 or uniform)
or by creepage (uniform within 1.5 times Carter's full-slip creepage), 20-100 elements, half-plane.

Part 6, the strongly coupled corner (``--corner N``, issue 23 item 4): issue 23's bodies (a stiff
roller on a soft, compressible flat, |beta_Dundurs| = 0.488) with mu for mu |beta| uniform in
0.6-1.5, loaded by force (Q/(mu P) uniform in +-0.98) or by creepage (uniform within 1.2 times the
corner's full-slip creepage, 0.04 mu / 2.2376), either rolling direction, 20-80 elements, half-plane.

In parts 5 and 6 a case also passes when a force-controlled solve fails with the message that the
creep-force curve turns before the force (no steady solution there): "converges or reports its
turning point". Velocity laws are checked with mu(s_a) at every node (tests/test_friction_laws.py).

    python benchmarks/robustness.py [--seeds 1,2,3,4,5,6,7] [--cases 400] [--layers 200] [--small-mu 20]
                                    [--thin-layers] [--laws 40] [--corner 10] [--skip-half-spaces]
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


def random_small_mu_case(rng: random.Random) -> tuple[dict, float]:
    """A small-friction, coupled half-space case near full slip (part 3) and its mu |beta_Dundurs|."""
    from rolling_cli.model import materials

    while True:  # a coupling: redraw the materials until |beta_Dundurs| >= 0.02
        rigid = rng.random() < 0.3
        nu_a, nu_b = rng.uniform(0.0, 0.5), rng.uniform(0.0, 0.5)
        young_a, young_b = _log_uniform(rng, 1e1, 1e6), _log_uniform(rng, 1e1, 1e6)
        beta = materials.dundurs_beta(math.inf if rigid else young_a, 0.0 if rigid else nu_a, young_b, nu_b)
        if abs(beta) >= 0.02:
            break
    mu = _log_uniform(rng, 1e-4, 1e-2)
    q = rng.choice([-1.0, 1.0]) * rng.choice([0.999, rng.uniform(0.95, 0.999)])
    load = _log_uniform(rng, 1, 1e3)
    radius_a, radius_b = _log_uniform(rng, 100, 2e4), _log_uniform(rng, 100, 2e4)
    direction = rng.choice([-1, 1])
    elements = rng.randint(20, 200)
    influence = rng.choice(["half-plane", "bem"])
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


#: Hertz's half-width of P = 0.5 for R = 100 on R = 100, E* = 10 / (1 - 0.25) (part 4).
THIN_A_HERTZ = math.sqrt(4.0 * 0.5 * 50.0 / (math.pi * 10.0 / 0.75))
#: Overlaps of part 4: 0.0085, 0.009 and 0.011 needed 137-154 iterations before issue 26.
THIN_OVERLAPS = (0.0085, 0.009, 0.0093, 0.01, 0.011)


def thin_layer_case(overlap: float, q: float, direction: int) -> dict:
    """Part 4's case: a rigid cylinder on a thin incompressible layer (b = 0.05 a_H), by overlap."""
    layer = {"kind": "layered", "radius": 100.0, "young": 10.0, "poisson": 0.5}
    return case_dict(
        **{
            "bodies.A": {"kind": "rigid", "radius": 100.0},
            "bodies.B": {**layer, "layer_thickness": 0.05 * THIN_A_HERTZ},
            "friction.mu": 0.1,
            "normal.overlap": overlap,
            "tangential.q_over_mu_p": q,
            "rolling.direction": direction,
            "discretization.influence": "bem",
            "discretization.contact_elements": 200,
        }
    )


def thin_layer_cases() -> list[dict]:
    """The 40 cases of part 4."""
    return [
        thin_layer_case(overlap, q, direction)
        for overlap in THIN_OVERLAPS
        for q in (0.7, 0.8, 0.9, 0.95)
        for direction in (1, -1)
    ]


#: Part 5's laws: the keys beyond mu_static, drawn by :func:`random_law_case`.
VELOCITY_LAWS = ("linear", "rational", "exponential", "polach")
#: Part 5's rolling speed |V| [mm/s] (cases/falling_exponential.toml).
LAW_SPEED = 45000.0


def _control(rng: random.Random, force: bool, full_slip: float) -> dict:
    """Force control (Q/(mu P) +-0.98 or uniform) or creepage control (uniform within ``full_slip``)."""
    if force:
        return {"q_over_mu_p": rng.choice([-0.98, 0.98, rng.uniform(-0.98, 0.98)])}
    return {"creep": rng.uniform(-full_slip, full_slip)}


def random_law_case(rng: random.Random) -> tuple[dict, float]:
    """A falling-friction case (part 5) and its mu_static |beta_Dundurs| (0 for similar bodies)."""
    from rolling_cli.model import materials

    law = rng.choice(VELOCITY_LAWS)
    mu_static = rng.uniform(0.1, 0.6)
    friction = {"law": law, "mu_static": mu_static}
    if law == "polach":
        friction |= {"polach_a": rng.uniform(0.3, 0.9), "polach_b": _log_uniform(rng, 1e-3, 0.1)}
    else:
        friction |= {"mu_kinetic": mu_static * rng.uniform(0.3, 0.9), "slip_velocity_half": _log_uniform(rng, 10, 1e3)}
    radius = _log_uniform(rng, 20.0, 500.0)
    similar = rng.random() < 0.5
    body_a = dict(helpers.CARTER["bodies"]["A"] if similar else helpers.ALUMINIUM, radius=radius)
    body_b = dict(helpers.CARTER["bodies"]["B"] if similar else helpers.STEEL, radius=radius)
    data = case_dict(**{"bodies.A": body_a, "bodies.B": body_b})
    data["friction"] = friction
    data["normal"] = {"load": _log_uniform(rng, 100.0, 3000.0)}
    estar = 1.0 / sum((1.0 - b["poisson"] ** 2) / b["young"] for b in (body_a, body_b))
    a = math.sqrt(4.0 * data["normal"]["load"] * (radius / 2.0) / (math.pi * estar))  # Hertz
    data["tangential"] = _control(rng, rng.random() < 0.5, 1.5 * mu_static * a / (radius / 2.0))
    data["rolling"] = {"direction": rng.choice([-1, 1]), "speed": LAW_SPEED}
    data["units"] = {"time": "s"}
    data["discretization"] |= {"contact_elements": rng.randint(20, 100), "influence": "half-plane"}
    beta = materials.dundurs_beta(body_a["young"], body_a["poisson"], body_b["young"], body_b["poisson"])
    return data, mu_static * abs(beta)


#: Issue 23's corner: its bodies, load and mu |beta_Dundurs| = 1.09 at mu = 2.2376 (part 6).
CORNER_BODIES = {
    "A": {"kind": "elastic", "radius": 485.0, "young": 991164.5, "poisson": 0.2730},
    "B": {"kind": "elastic", "radius": math.inf, "young": 396.505, "poisson": 0.02223},
}
CORNER_MU, CORNER_COUPLING = 2.2376, 1.09


def random_corner_case(rng: random.Random) -> tuple[dict, float]:
    """A strongly coupled case of issue 23's bodies (part 6) and its mu |beta_Dundurs|."""
    coupling = rng.uniform(0.6, 1.5)
    mu = CORNER_MU * coupling / CORNER_COUPLING
    force = rng.random() < 0.5
    data = case_dict(
        **{
            "bodies.A": dict(CORNER_BODIES["A"]),
            "bodies.B": dict(CORNER_BODIES["B"]),
            "friction.mu": mu,
            "normal.load": 43.863,
            "rolling.direction": rng.choice([-1, 1]),
            "discretization.contact_elements": rng.randint(20, 80),
            "discretization.influence": "half-plane",
        }
    )
    data["tangential"] = _control(rng, force, 1.2 * 0.04 * mu / CORNER_MU)
    return data, coupling


def turning_point_reported(data: dict, err: Exception) -> bool:
    """A force-controlled solve that failed saying the creep-force curve turns before the force."""
    return "q_over_mu_p" in data["tangential"] and "the creep-force curve turns at" in str(err)


def check(data: dict) -> int:
    """Solve ``data`` cold with the defaults, check the contact laws and the force balance at the
    tolerance the solve applied; returns the iterations (all mesh levels together)."""
    with np.errstate(divide="raise", over="raise", invalid="raise", under="ignore"):
        r = solve(data)
        if data["friction"].get("law", "constant") == "constant":
            assert_contact_laws(r, r.tolerance_applied)
        else:
            from test_friction_laws import assert_contact_laws_with_law

            assert_contact_laws_with_law(r, require_slip=False)  # a tiny creepage may stick everywhere
        load = data["normal"].get("load")
        ratio = data["tangential"].get("q_over_mu_p")
        mu = data["friction"].get("mu", data["friction"].get("mu_static"))
        q = None if ratio is None else ratio * mu * (load or r.normal_load)
        assert_force_balance(r, load=load, q=q, tolerance=r.tolerance_applied)
        return r.iterations_total


def run_fixed(cases: list[dict], label: str) -> collections.Counter:
    """Solve fixed cases; print one line per case (its iterations) and a summary row."""
    print(f"\n{label}\n")
    totals: collections.Counter = collections.Counter()
    iterations = []
    t0 = time.perf_counter()
    for data in cases:
        what = (
            f"overlap {data['normal'].get('overlap')}, Q/(mu P) {data['tangential']['q_over_mu_p']:+g}, "
            f"direction {data['rolling']['direction']:+d}"
        )
        try:
            its = check(data)
            iterations.append(its)
            print(f"- {what}: {its} iterations", flush=True)
        except Exception as err:  # every failure is counted and listed, whatever its type
            totals[type(err).__name__] += 1
            print(f"- {what}: FAILED {type(err).__name__}: {str(err)[:200]}", flush=True)
    its = np.array(iterations or [0])
    print("\n| cases | failed | median iterations | max | total | time [s] |\n|---:|---:|---:|---:|---:|---:|")
    print(
        f"| {len(cases)} | {sum(totals.values())} | {np.median(its):.0f} | {its.max()} | {its.sum()} "
        f"| {time.perf_counter() - t0:.0f} |"
    )
    print(f"\nfailures by type: {dict(totals) or 'none'}")
    return totals


def run(draw, seeds: list[int], cases: int, label: str) -> collections.Counter:
    """Solve ``cases`` draws per seed; print one table row per seed and every failure."""
    print(f"\n{label}\n")
    print("| seed | cases | failed | turning point reported | median iterations | p90 | max | total | time [s] |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    totals = collections.Counter()
    failures = []
    turning: list[tuple] = []
    for seed in seeds:
        rng = random.Random(seed)
        iterations = []
        failed = turned = 0
        t0 = time.perf_counter()
        for k in range(cases):
            data, coupling = draw(rng)
            try:
                iterations.append(check(data))
            except Exception as err:  # every failure is counted and listed, whatever its type
                if turning_point_reported(data, err):
                    totals["turning point reported"] += 1
                    turning.append((seed, k, coupling, str(err)[:160]))
                    turned += 1
                    continue
                failed += 1
                totals[type(err).__name__] += 1
                failures.append((seed, k, coupling, type(err).__name__, str(err)[:240]))
        its = np.array(iterations or [0])
        print(
            f"| {seed} | {cases} | {failed} | {turned} | {np.median(its):.0f} | {np.percentile(its, 90):.0f} "
            f"| {its.max()} | {its.sum()} | {time.perf_counter() - t0:.0f} |",
            flush=True,
        )
    for seed, k, coupling, kind, message in failures:
        print(f"- seed {seed}, case {k} (mu |beta_Dundurs| = {coupling:.3g}): {kind}: {message}")
    for seed, k, coupling, message in turning:
        print(f"- seed {seed}, case {k} (mu |beta_Dundurs| = {coupling:.3g}): turning point: {message}")
    print(f"\nfailures by type: {dict(totals) or 'none'}")
    return totals


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="1,2,3,4,5,6,7")
    parser.add_argument("--cases", type=int, default=400)
    parser.add_argument("--layers", type=int, default=0, help="layer cases per seed (part 2); 0 skips it")
    parser.add_argument("--small-mu", type=int, default=0, help="small-friction cases per seed (part 3); 0 skips it")
    parser.add_argument("--thin-layers", action="store_true", help="the thin-layer cases (part 4)")
    parser.add_argument("--laws", type=int, default=0, help="falling-friction cases per seed (part 5); 0 skips it")
    parser.add_argument("--corner", type=int, default=0, help="strongly coupled cases per seed (part 6); 0 skips it")
    parser.add_argument("--skip-half-spaces", action="store_true", help="skip part 1")
    args = parser.parse_args()
    logging.disable(logging.WARNING)  # zone enlargements are expected here; the table counts outcomes
    seeds = [int(s) for s in args.seeds.split(",")]
    if not args.skip_half_spaces:
        run(random_case, seeds, args.cases, "Part 1: half-spaces, loaded by force")
    if args.layers:
        run(random_layer_case, seeds, args.layers, "Part 2: a rigid cylinder on a layer, by overlap or force")
    if args.small_mu:
        run(random_small_mu_case, seeds, args.small_mu, "Part 3: small friction (1e-4 to 1e-2), coupled, near slip")
    if args.thin_layers:
        run_fixed(thin_layer_cases(), "Part 4: thin incompressible layer near full slip, by overlap")
    if args.laws:
        run(random_law_case, seeds, args.laws, "Part 5: falling friction laws, by force or creepage")
    if args.corner:
        run(random_corner_case, seeds, args.corner, "Part 6: the strongly coupled corner, mu |beta| 0.6-1.5")


if __name__ == "__main__":
    main()
