"""Q(xi) of the strongly coupled corner (issue 23 item 4), point by point under creepage control.

The issue's case: a stiff roller (R = 485, E = 991164.5, nu = 0.273) on a soft, nearly
incompressible-free flat (E = 396.505, nu = 0.02223), mu = 2.2376 (mu |beta_Dundurs| = 1.09), P = 43.863,
half-plane, 250 elements. Each creepage xi in 0 .. 0.04 (41 points) is solved cold and alone
(no path, no warm start), so a point's failure is the solver's on that case, not a path's. Prints
xi, Q/(mu P) and the Newton iterations, or the failure. Does Q(xi) fold (which would leave force
control without a solution), or is it monotone where it converges?

    python benchmarks/corner_curve.py [--points 41] [--xi-max 0.04] [--mu 2.2376] [--force -0.7897,-0.85,-0.95]
                                      [--elements 250]

``--mu`` moves the case along mu |beta_Dundurs| (|beta| = 0.488: mu 1.229 .. 3.072 for 0.6 .. 1.5; the
creepage range then scales with mu, 0.04 mu / 2.2376 unless ``--xi-max``); ``--force`` also solves
under force control at those Q/(mu P), each cold and alone.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.errors import RollingError  # noqa: E402

CASE = {
    "bodies": {
        "A": {"kind": "elastic", "radius": 485.0, "young": 991164.5, "poisson": 0.2730},
        "B": {"kind": "elastic", "radius": math.inf, "young": 396.505, "poisson": 0.02223},
    },
    "friction": {"mu": 2.2376},
    "normal": {"load": 43.863},
    "tangential": {"creep": 0.0},
    "rolling": {"direction": 1},
    "discretization": {"influence": "half-plane", "contact_elements": 250},
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=41)
    parser.add_argument("--xi-max", type=float, default=None)
    parser.add_argument("--mu", type=float, default=2.2376)
    parser.add_argument("--force", default="")
    parser.add_argument("--elements", type=int, default=250, help="contact elements on the 1.5 a zone")
    args = parser.parse_args()
    xi_max = args.xi_max if args.xi_max is not None else 0.04 * args.mu / 2.2376
    base = with_overrides(load_case(CASE), {"friction.mu": args.mu, "discretization.contact_elements": args.elements})
    t0 = time.perf_counter()
    converged = []
    iterations = 0
    print("| xi | Q/(mu P) | Newton iterations (all levels) |\n|---:|---:|---:|")
    for xi in np.linspace(0.0, xi_max, args.points):
        case = with_overrides(base, {"tangential.creep": float(xi)})
        try:
            result = rolling_cli.solve(case)
        except RollingError as err:
            print(f"| {xi:.4f} | failed | {str(err).split(';')[0][:70]} |")
            continue
        converged.append((xi, result.q_over_mu_p))
        iterations += result.iterations_total
        print(f"| {xi:.4f} | {result.q_over_mu_p:+.5f} | {result.iterations_total} |")
    q = np.array([c[1] for c in converged])
    monotone = bool(np.all(np.diff(q) < 0.0))
    print(
        f"\n{len(converged)} of {args.points} converged; Q/(mu P) monotone over them: {monotone}; "
        f"{iterations} Newton iterations; {time.perf_counter() - t0:.0f} s"
    )
    for q in [float(v) for v in args.force.split(",") if v]:
        case = with_overrides(base, {"tangential.q_over_mu_p": q})
        try:
            result = rolling_cli.solve(case)
            print(f"force control Q/(mu P) = {q}: xi = {result.creep:.6g}, {result.iterations_total} iterations")
        except RollingError as err:
            print(f"force control Q/(mu P) = {q}: failed: {str(err).split(';')[0][:90]}")


if __name__ == "__main__":
    main()
