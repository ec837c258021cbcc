"""P as the load on the shaft (issue 21 item 3): what prescribing the shaft load instead of the arc
sum changes, and what it costs.

For finite cylinders ``normal.load`` prescribes the bearing force along the line of centres,
sum w (-p_n cos theta + p_t sin theta) (:func:`rolling_cli.influence.finite.shaft_load_weights`).
Each case is solved twice on one contact system: with that load row ("shaft") and with the arc
sum's (the model before: the same system with ``load_n = load_t = None``). Printed per case: a/R,
the arc sum against P in the shaft solve, the creepage difference (in units of mu a/R, its scale:
the cover's creepage is small and changes sign near a/R = 0.2), contact half-width and peak
pressure of the shaft solve against the arc solve, and both solves' Newton iterations and times (best of
``--repeat``), as a Markdown table.

    python benchmarks/bench_shaft_load.py [--elements 100] [--repeat 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np

from rolling_cli import pipeline
from rolling_cli.case import load_case

R = 5.0


def _case(body: dict, load: float, ratio: float, elements: int) -> dict:
    return {
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
        "friction": {"mu": 0.3},
        "normal": {"load": load},
        "tangential": {"q_over_mu_p": ratio},
        "rolling": {"direction": -1},
        "discretization": {"contact_elements": elements},
    }


BODIES = {
    "hollow roller (bore 2, nu 0.3)": {
        "kind": "elastic", "radius": R, "young": 10.0, "poisson": 0.3, "shape": "cylinder", "inner_radius": 2.0,
    },
    "cover (b = 1, nu 0.45)": {
        "kind": "layered", "radius": R, "young": 10.0, "poisson": 0.45, "shape": "cylinder", "layer_thickness": 1.0,
    },
}  # fmt: skip
#: Loads [force/length] giving a/R ~ 0.2 and ~ 0.3 on each body.
LOADS = {"hollow roller (bore 2, nu 0.3)": (2.0, 4.0), "cover (b = 1, nu 0.45)": (4.0, 8.0)}


def _width(result) -> float:
    """Contact half-width [length] from p_n^2 linear at the edges (benchmarks/finite_error_map.py)."""
    x, p = result.x, result.p_n
    inside = np.flatnonzero(p < 0.0)

    def edge(i, j):
        return x[i] + (x[i] - x[j]) * p[i] ** 2 / (p[j] ** 2 - p[i] ** 2)

    return 0.5 * (edge(inside[-1], inside[-2]) - edge(inside[0], inside[1]))


def _best(case, system, repeat: int):
    """The result of the fastest of ``repeat`` solves of ``case`` on ``system`` and its time [s]."""
    best, result = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = pipeline.solve(case, system=system)
        best = min(best, time.perf_counter() - t0)
    return result, best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=100)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(
        "| body | Q/(mu P) | a/R | arc sum / P - 1 | creepage shaft - arc, / (mu a/R) | half-width | peak pressure "
        "| iterations shaft / arc | solve [ms] shaft / arc |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, body in BODIES.items():
        for load in LOADS[name]:
            for ratio in (0.0, 0.5):
                case = load_case(_case(body, load, ratio, args.elements))
                _, system = pipeline.prepare(case)
                shaft, t_shaft = _best(case, system, args.repeat)
                arc, t_arc = _best(case, dataclasses.replace(system, load_n=None, load_t=None), args.repeat)
                creep = (shaft.creep - arc.creep) / (0.3 * _width(arc) / R)  # in units of mu a/R
                if shaft.x.size != arc.x.size:  # a zone enlarged in one solve only: not one grid
                    raise SystemExit(f"{name}, P = {load}: the two solves ran on different grids")
                print(
                    f"| {name} | {ratio:g} | {_width(shaft) / R:.3f} "
                    f"| {shaft.arc_load / shaft.normal_load - 1.0:+.2%} | {creep:+.4f} "
                    f"| {_width(shaft) / _width(arc) - 1.0:+.3%} "
                    f"| {shaft.p_n.min() / arc.p_n.min() - 1.0:+.2%} "
                    f"| {shaft.iterations} / {arc.iterations} | {1e3 * t_shaft:.0f} / {1e3 * t_arc:.0f} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
