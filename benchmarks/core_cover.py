"""A cover on an elastic core (issue 21 item 1): the core's effect and the influence build's cost.

A rubber-like cover (E = 10, nu = 0.45) of thickness 5 on a core of radius 20 (bore 5, a steel shaft's; nu = 0.3),
outer radius 25, on a rigid flat, P = 10, mu = 0.5, Q/(mu P) = 0.3, 100 contact elements: the
creepage, the approach of the shaft (overlap), the contact half-width and the peak pressure against
the core's modulus E_c / E = 1 .. 1e6, the rigid core (today's model)
and the homogeneous roller (kind = "elastic", bore 5: E_c = E); then the compliance
build's time (core.condensed against cylinder.condensed, warm imports, median of --repeat) at
60, 100 and 200 contact elements.

    python benchmarks/core_cover.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import time

from rolling_cli import pipeline
from rolling_cli.influence import build
from rolling_cli.influence.bem import core, cylinder
from rolling_cli.model.grid import ContactGrid

COVER = {"kind": "layered", "shape": "cylinder", "radius": 25.0, "layer_thickness": 5.0, "young": 10.0, "poisson": 0.45}


def _case(body: dict) -> dict:
    return {
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
        "friction": {"mu": 0.5},
        "normal": {"load": 10.0},
        "tangential": {"q_over_mu_p": 0.3},
        "discretization": {"contact_elements": 100, "zone": 1.5},
    }


def physics() -> None:
    print("| E_core / E, nu_core | creepage xi | overlap | half-width | peak pressure | influence build [s] |")
    print("|---:|---:|---:|---:|---:|---:|")
    homogeneous = {k: v for k, v in COVER.items() if k != "layer_thickness"} | {"kind": "elastic", "inner_radius": 5.0}
    rows: list = [(1.0, 0.45), "homogeneous", (1.0, 0.3), (3.0, 0.3), (10.0, 0.3), (100.0, 0.3), (1e4, 0.3)]
    for ratio in [*rows, (1e6, 0.3), None]:
        body = dict(COVER) if ratio != "homogeneous" else homogeneous
        if isinstance(ratio, tuple):
            body |= {"core_young": 10.0 * ratio[0], "core_poisson": ratio[1], "inner_radius": 5.0}
        build.clear_memo()
        r = pipeline.solve(_case(body), use_cache=False)
        label = "rigid" if ratio is None else f"{ratio[0]:g}, {ratio[1]:g}" if isinstance(ratio, tuple) else str(ratio)
        print(
            f"| {label} | {r.creep:.6g} | {r.overlap:.6g} | {r.contact_half_width:.5g} | {-r.p_n.min():.5g} |"
            f" {r.time_influence:.3g} |"
        )


def cost(repeat: int) -> None:
    print("| contact elements | rigid core [s] | elastic core [s] | ratio |")
    print("|---:|---:|---:|---:|")
    for elements in (60, 100, 200):
        grid = ContactGrid(4.5, elements, 2)
        rigid, elastic = [], []
        for _ in range(repeat):
            t = time.perf_counter()
            cylinder.condensed(grid, 25.0, 20.0, 10.0, 0.45)
            rigid.append(time.perf_counter() - t)
            t = time.perf_counter()
            core.condensed(grid, 25.0, 20.0, 5.0, 10.0, 0.45, 50.0, 0.3)
            elastic.append(time.perf_counter() - t)
        a, b = statistics.median(rigid), statistics.median(elastic)
        print(f"| {elements} | {a:.3f} | {b:.3f} | {b / a:.2f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    physics()
    cost(args.repeat)


if __name__ == "__main__":
    main()
