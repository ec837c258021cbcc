"""Convergence of the BEM half-space block with its size (W = D = k a).

Two checks against the closed-form half-plane, 100 contact elements:
* Carter (similar, P prescribed): traction error / (mu p0) and creepage error
  against Carter's formulas;
* aluminium on steel (Q/(mu P) = 0.75): BEM minus half-plane model, same grid.

    python benchmarks/block_size.py [--sizes 5,10,20,40,80,100,160]
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
from rolling_cli.influence.bem import body_mesh  # noqa: E402
from rolling_cli.influence.build import bem_inputs  # noqa: E402
from rolling_cli.pipeline import plan  # noqa: E402
from rolling_cli.references import carter  # noqa: E402

CASES = Path(__file__).resolve().parents[1] / "cases"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="5,10,20,40,80,100,160")
    parser.add_argument("--elements", type=int, default=100)
    args = parser.parse_args()
    common = {"discretization.contact_elements": args.elements}
    similar = with_overrides(load_case(CASES / "carter.toml"), common)
    dissimilar = with_overrides(load_case(CASES / "dissimilar_q75.toml"), common)
    reference = rolling_cli.solve(dissimilar)
    print(f"# block_size: {args.elements} contact elements, rolling_cli {rolling_cli.__version__}")
    print(
        "| W/a = D/a | BEM elements | Carter: max traction error / (mu p0) | Carter: creepage error | "
        "dissimilar: max |p_t(BEM) - p_t(half-plane)| / (mu p0) | dissimilar: creepage difference | time [s] |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for k in (float(v) for v in args.sizes.split(",")):
        block = {"discretization.influence": "bem", "discretization.block_width": k, "discretization.block_depth": k}
        t = time.perf_counter()
        r = rolling_cli.solve(with_overrides(similar, block), use_cache=False)
        exact = carter.traction(r.x, 0.51, r.hertz_a, r.hertz_p0, r.mu, -1)
        e_carter = np.max(np.abs(r.p_t - exact)) / (r.mu * r.hertz_p0)
        c_carter = r.creep / r.carter_creep - 1.0
        d = rolling_cli.solve(with_overrides(dissimilar, block), use_cache=False)
        e_dis = np.max(np.abs(d.p_t - reference.p_t)) / (d.mu * d.hertz_p0)
        c_dis = d.creep / reference.creep - 1.0
        the_plan = plan(with_overrides(similar, block))
        inputs = bem_inputs(with_overrides(similar, block), the_plan, similar.bodies.A)
        mesh = body_mesh(the_plan.grid, inputs["half_width"], inputs["depth"])
        print(
            f"| {k:g} | {mesh.elements} | {e_carter:.4f} | {c_carter:+.2e} | {e_dis:.4f} | {c_dis:+.2e} | "
            f"{time.perf_counter() - t:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
