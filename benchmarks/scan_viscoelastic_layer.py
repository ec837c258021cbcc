"""Robustness scan of viscoelastic covers (issue 22): random SLS covers on the paper's Fig. 11 tyre.

E_g / E_r in 1..100, V tau_c / a in 0.01..100, nu in {0.3, 0.45, 0.5}, Q/(mu P) in -0.9..0.9,
b in 0.05..2 (a ~ 1), load control (P = 0.5), 80 quadratic elements: convergence, Newton iterations
and the energy balance (shafts' power against hysteresis + friction + xi Q, relative to the largest
of the four terms).

    python benchmarks/scan_viscoelastic_layer.py [--seed 1] [--cases 30]
"""

from __future__ import annotations

import argparse
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.case.io import with_overrides  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cases", type=int, default=30)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    with open(ROOT / "cases" / "tyred_fig11_q41.toml", "rb") as handle:
        data = tomllib.load(handle)
    data["normal"] = {"load": 0.5}
    base = load_case(data)
    failed, iterations = 0, []
    for n in range(args.cases):
        ratio, speed = 10 ** rng.uniform(0, 2), 10 ** rng.uniform(-2, 2)
        nu, q, b = float(rng.choice([0.3, 0.45, 0.5])), rng.uniform(-0.9, 0.9), 10 ** rng.uniform(-1.3, 0.3)
        case = with_overrides(base, {
            "bodies.B.viscoelastic": True, "bodies.B.young": 10.0 * ratio, "bodies.B.relaxed_young": 10.0,
            "bodies.B.creep_time": 1.0, "bodies.B.poisson": nu, "bodies.B.layer_thickness": float(b),
            "rolling.speed": float(speed), "tangential.q_over_mu_p": float(q),
            "discretization.contact_elements": 80,
        })  # fmt: skip
        t0 = time.perf_counter()
        r = solve(case, keep_failed=True)
        shafts = r.rolling_resistance_moment / 50.0
        terms = (r.hysteresis_power, r.frictional_power_total, r.creep * r.tangential_load)
        balance = (sum(terms) - shafts) / max(abs(shafts), *(abs(t) for t in terms))
        failed += not r.converged
        iterations.append(int(r.iterations))
        seconds = time.perf_counter() - t0
        print(f"{n} E_g/E_r={ratio:.3g} V tau/a={speed:.3g} nu={nu} Q/(mu P)={q:.2f} b={b:.3g}: "
              f"converged={r.converged} it={r.iterations} balance={balance:.1e} {seconds:.2f} s")  # fmt: skip
    print(f"failed {failed} of {args.cases}; iterations median {np.median(iterations):g}, max {max(iterations)}")


if __name__ == "__main__":
    main()
