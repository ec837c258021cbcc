"""The half-space error map (issue 21): how far the half-space model is from the finite cylinder.

A roller of radius R = 10 on a rigid flat, mu = 0.3, Q/(mu P) = 0.5, 100 contact elements
(second-order slip derivative), for a/R = 0.01 .. 0.5:

* **solid**: an elastic roller (E = 1, nu = 0.3) on an axle of radius 0.1 R (the bore), against
  today's half-space model of the same material;
* **covered**: a cover (E = 1, nu = 0.45) of thickness 0.2 R on a rigid core, against today's
  flat-layer model (a layer of the same thickness on a rigid core).

The load is the one that gives the half-space model the wanted a/R. Printed: a/R of each
model, both creepages and their difference in units of mu a/R (the creepage's scale: a
relative difference means little where the creepage changes sign), and the half-space model's
peak pressure and contact half-width relative to the finite cylinder's (half-space / finite - 1),
as a Markdown table.

    python benchmarks/finite_error_map.py [--ratios 0.01,0.02,0.05,0.1,0.2,0.3,0.5] [--elements 100]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import rolling_cli
from rolling_cli.case import load_case
from rolling_cli.references import hertz

R = 10.0


def _case(body: dict, load: float, elements: int) -> dict:
    return {
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
        "friction": {"mu": 0.3},
        "normal": {"load": load},
        "tangential": {"q_over_mu_p": 0.5},
        "rolling": {"direction": -1},
        "discretization": {"contact_elements": elements, "slip_derivative": "element"},
    }


def _bodies(kind: str) -> tuple[dict, dict]:
    """(finite, half-space) body tables."""
    if kind == "solid":
        half = {"kind": "elastic", "radius": R, "young": 1.0, "poisson": 0.3}
        return {**half, "shape": "cylinder", "inner_radius": 0.1 * R}, half
    half = {"kind": "layered", "radius": R, "young": 1.0, "poisson": 0.45, "layer_thickness": 0.2 * R}
    return {**half, "shape": "cylinder"}, half


def _width(result) -> float:
    """Contact half-width from p_n^2 linear at the edges (two outermost contact nodes each side)."""
    x, p = result.x, result.p_n
    inside = np.flatnonzero(p < 0.0)

    def edge(i, j):
        return x[i] + (x[i] - x[j]) * p[i] ** 2 / (p[j] ** 2 - p[i] ** 2)

    return 0.5 * (edge(inside[-1], inside[-2]) - edge(inside[0], inside[1]))


def _load_for(kind: str, ratio: float, elements: int) -> float:
    """The load giving the half-space model a/R = ``ratio`` (Hertz for the solid; two secant steps on
    the layer model's measured a for the cover, a ~ P^k)."""
    finite, half = _bodies(kind)
    e_star = 1.0 / (1.0 - half["poisson"] ** 2)
    load = hertz.load_for_half_width(ratio * R, R, e_star)
    if kind == "solid":
        return load
    for _ in range(3):
        a = _width(rolling_cli.solve(load_case(_case(half, load, elements))))
        load *= (ratio * R / a) ** 2.5  # a ~ P^0.4 between the thin layer (1/3, 1/5) and Hertz (1/2)
    return load


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ratios", default="0.01,0.02,0.05,0.1,0.2,0.3,0.5")
    parser.add_argument("--elements", type=int, default=100)
    args = parser.parse_args()
    ratios = [float(r) for r in args.ratios.split(",")]
    print(
        "| roller | a/R (half-space) | a/R (finite) | xi finite / (mu a/R) | xi half-space / (mu a/R) "
        "| creepage difference / (mu a/R) | peak pressure | half-width | time [s] |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for kind in ("solid", "covered"):
        finite_body, half_body = _bodies(kind)
        for ratio in ratios:
            start = time.perf_counter()
            load = _load_for(kind, ratio, args.elements)
            half = rolling_cli.solve(load_case(_case(half_body, load, args.elements)))
            try:
                finite = rolling_cli.solve(load_case(_case(finite_body, load, args.elements)))
            except Exception:  # a zone beyond the mesh's reach (half the circumference): say so
                print(f"| {kind} | {_width(half) / R:.3g} | zone beyond R pi/2 | | | | | | |")
                continue
            scale = 0.3 * _width(half) / R  # mu a / R: the creepage's natural scale
            creep = (half.creep - finite.creep) / scale
            peak = half.p_n.min() / finite.p_n.min() - 1.0
            width = _width(half) / _width(finite) - 1.0
            seconds = time.perf_counter() - start
            print(
                f"| {kind} | {_width(half) / R:.3g} | {_width(finite) / R:.3g} | {finite.creep / scale:.4f} "
                f"| {half.creep / scale:.4f} | {creep:+.4f} | {peak:+.2%} "
                f"| {width:+.2%} | {seconds:.1f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
