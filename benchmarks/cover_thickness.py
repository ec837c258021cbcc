"""A thick cover against the half-plane: model error or physics? (issue 22, the b/a >= 10 check).

Hunter's roller (rigid, R = 50, P = 1, frictionless; E_g = 20, E_r = 10, tau_c = 0.01, nu = 0.5,
quadratic elements over 1.5 a_r, a_r the relaxed Hertz half-width) on a cover of thickness b bonded to
a rigid core, against the same material as a half-plane, at b/a_r = 10, 30, 100, on the same grid:

* elastic (E_r = E_g = 10, today's tyre model, no history) against the elastic half-plane;
* viscoelastic (the SLS) at V tau_c / a_r = 0.3, 1, 3 against the viscoelastic half-plane;
* the flat-layer Fourier reference (:mod:`rolling_cli.references.hunter` with
  :mod:`rolling_cli.references.layer_fourier`'s transfer, a period of 40 max(a_r, b) so that the
  layer's small wavenumbers |k| b < 1 are sampled) with and without the layer: the physics' own
  layer-minus-half-plane difference by a route that shares nothing with the BEM;
* with ``--friction``: the same roller driven (mu = 0.3, Q/(mu P) = 0.5): the creepage.

Printed: relative differences cover / half-plane - 1 of the peak pressure, the contact half-width
(where p^2, linear through the outermost two loaded points, vanishes), the rolling resistance M/(P R) and the creepage.

    python benchmarks/cover_thickness.py [--elements 60] [--ratios 10,30,100] [--friction]
"""

from __future__ import annotations

import argparse
import copy
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402
from rolling_cli.references import hertz, hunter  # noqa: E402

R, P, EG, ER, TAU, NU = 50.0, 1.0, 20.0, 10.0, 0.01, 0.5


def a_relaxed() -> float:
    """The relaxed Hertz half-width a_r [length]."""
    return hertz.half_width(P, R, ER / (1.0 - NU**2))


def cases(thickness_ratio: float, ratio: float | None, elements: int, friction: bool) -> tuple[dict, dict]:
    """(half-plane, cover) case dicts; ``ratio`` = V tau_c / a_r, None for the elastic pair (E = E_r)."""
    a_r = a_relaxed()
    if ratio is None:
        material = {"radius": "inf", "young": ER, "poisson": NU}
        half_body = {"kind": "elastic", **material}
        cover_body = {"kind": "layered", "layer_thickness": thickness_ratio * a_r, **material}
    else:
        material = {"radius": "inf", "young": EG, "relaxed_young": ER, "creep_time": TAU, "poisson": NU}
        half_body = {"kind": "viscoelastic", **material}
        cover_body = {"kind": "layered", "viscoelastic": True, "layer_thickness": thickness_ratio * a_r, **material}
    half = {
        "bodies": {"A": {"kind": "rigid", "radius": R}, "B": half_body},
        "friction": {"mu": 0.3 if friction else 0.0},
        "normal": {"load": P},
        "rolling": {"direction": -1},
        "discretization": {"element": "quadratic", "contact_elements": elements, "zone": 1.5},
    }
    if friction:
        half["tangential"] = {"q_over_mu_p": 0.5}
    if ratio is not None:
        half["rolling"]["speed"] = ratio * a_r / TAU
    cover = copy.deepcopy(half)
    cover["bodies"]["B"] = cover_body
    return half, cover


def edge_width(x: np.ndarray, p: np.ndarray) -> float:
    """The contact half-width [length] between the edges where p^2, linear through the two outermost
    loaded points at each end, vanishes (p ~ sqrt(distance) at a smooth edge): not quantised to cells."""
    loaded = np.flatnonzero(p > 0.0)
    lo, hi = loaded[0], loaded[-1]
    ends = []
    for i, j in ((lo, lo + 1), (hi, hi - 1)):
        s = p[i] ** 2 / (p[j] ** 2 - p[i] ** 2)  # p^2 zero at x_i - s (x_j - x_i)
        ends.append(x[i] - s * (x[j] - x[i]))
    return 0.5 * abs(ends[1] - ends[0])


def outputs(data: dict) -> dict:
    """peak pressure, contact half-width, M/(P R), creepage of one solved case."""
    r = solve(load_case(data))
    return {
        "peak": float(-r.p_n.min()),
        "width": edge_width(r.x, -r.p_n),
        "rr": float(getattr(r, "rolling_resistance_coefficient", None) or 0.0),
        "creep": float(r.creep),
    }


def reference(thickness_ratio: float, ratio: float | None, layer: bool, cells_per_a: int = 40) -> dict:
    """The Fourier reference's peak pressure, half-width and x_c / R: the cover (``layer``) or the
    half-plane on the cover's period (40 b: the two differ by the layer alone, not by the period)."""
    a_r = a_relaxed()
    b = thickness_ratio * a_r
    ell = 0.0 if ratio is None else ratio * a_r
    glassy, extra = (1.0 / ER, []) if ratio is None else (1.0 / EG, [1.0 / ER - 1.0 / EG])
    h = a_r / cells_per_a
    period = max(40.0 * a_r, 40.0 * b, 30.0 * ell)
    x, p = hunter.solve(P, R, glassy, extra, [ell] * len(extra), NU, h, period, b if layer else None)
    return {
        "peak": float(p.max()),
        "width": edge_width(x, p),
        "rr": float(np.sum(p * x) * h / P / R),
    }


def rel(a: float, b: float) -> float:
    """a / b - 1 in per cent (NaN when b = 0)."""
    return 100.0 * (a / b - 1.0) if b else math.nan


def _cell(value: float) -> str:
    """A table cell: the value in per cent, blank when undefined (no friction: no creepage)."""
    return "" if math.isnan(value) else f"{value:+.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--elements", type=int, default=60)
    parser.add_argument("--ratios", default="10,30,100")
    parser.add_argument("--speeds", default="0.3,1,3")
    parser.add_argument("--friction", action="store_true")
    parser.add_argument("--no-reference", action="store_true")
    args = parser.parse_args()
    ratios = [float(v) for v in args.ratios.split(",")]
    speeds: list[float | None] = [None, *(float(v) for v in args.speeds.split(","))]
    print(f"# {args.elements} quadratic elements, cover / half-plane - 1 [%]" + (", driven" if args.friction else ""))
    print("| b/a_r | V tau_c/a_r | peak | width | M/(P R) | creepage | ref. peak | ref. width | ref. M/(P R) |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    halves = {s: outputs(cases(10.0, s, args.elements, args.friction)[0]) for s in speeds}
    for ratio in ratios:
        for speed in speeds:
            c = outputs(cases(ratio, speed, args.elements, args.friction)[1])
            h = halves[speed]
            keys = ("peak", "width", "creep") if speed is None else ("peak", "width", "rr", "creep")  # elastic: M = 0
            cells = [_cell(rel(c[k], h[k])) if k in keys else "" for k in ("peak", "width", "rr", "creep")]
            if args.no_reference:
                cells += ["", "", ""]
            else:
                f, g = reference(ratio, speed, True), reference(ratio, speed, False)
                cells += [_cell(rel(f[k], g[k])) if k in keys else "" for k in ("peak", "width", "rr")]
            label = "elastic" if speed is None else f"{speed:g}"
            print(f"| {ratio:g} | {label} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
