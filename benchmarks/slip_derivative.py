"""Slip derivative: the paper's first-order upwind difference ("fd") against the
second-order upwind quadratic ("element"), for Carter (Q/(mu P) = 0.51), both
influence models. Errors against Carter's closed form; time of the full solve
with the influence cache off.

    python benchmarks/slip_derivative.py [--elements 10,20,40,80,160,320]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.references import carter  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "cases" / "carter.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--elements", default="10,20,40,80,160,320")
    args = parser.parse_args()
    base = load_case(CASE)
    print("| influence | elements | scheme | max error / (mu p0) | RMS error / (mu p0) | creepage error | time [s] |")
    print("|---|---:|---|---:|---:|---:|---:|")
    for influence in ("half-plane", "bem"):
        for n in (int(v) for v in args.elements.split(",")):
            for scheme in ("fd", "element"):
                case = with_overrides(
                    base,
                    {
                        "discretization.influence": influence,
                        "discretization.contact_elements": n,
                        "discretization.slip_derivative": scheme,
                    },
                )
                clear_memo()
                t = time.perf_counter()
                r = rolling_cli.solve(case, use_cache=False)
                wall = time.perf_counter() - t
                err = np.abs(r.p_t - carter.traction(r.x, 0.51, r.hertz_a, r.hertz_p0, r.mu, -1)) / (r.mu * r.hertz_p0)
                print(
                    f"| {influence} | {n} | {scheme} | {err.max():.4f} | {np.sqrt(np.mean(err**2)):.5f} | "
                    f"{r.creep / r.carter_creep - 1:+.2e} | {wall:.3f} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
