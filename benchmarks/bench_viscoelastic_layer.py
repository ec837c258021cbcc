"""Cost of a viscoelastic cover (layer on a rigid core) against today's elastic tyre case (issue 22).

Each viscoelastic cover is paired with its elastic twin, the same layer with the relaxed modulus
E_r (the widest contact, the viscoelastic case's mesh scale) and no history, on the same number of
quadratic elements. Median wall times of ``--repeat`` in-process solves, in two states: "cache"
(the in-process memo cleared, the elastic BEM layer read from the disk cache: a re-run, a sweep)
and "cold" (``use_cache=False``: the BEM layer built). Split into the influence build, the Newton
solve and the rest (plan, coarse levels' systems, result; for the cover the rolling-resistance
outputs and the Fourier-space hysteresis).

    python benchmarks/bench_viscoelastic_layer.py [--repeat 5] [--sizes 60,120,240]
"""

from __future__ import annotations

import argparse
import copy
import platform
import statistics
import sys
import time
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence import viscoelastic  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _file(name: str) -> dict:
    with open(ROOT / "cases" / f"{name}.toml", "rb") as handle:
        return tomllib.load(handle)


def _paper_cover() -> dict:
    """The paper's Fig. 11 tyre (nu = 0.5, b/a = 0.1, overlap control) as an SLS cover, E_g = 2 E_r,
    V tau_c / a ~ 1."""
    data = _file("tyred_fig11_q41")
    body = data["bodies"]["B"]
    body.update(viscoelastic=True, young=2.0 * body["young"], relaxed_young=body["young"], creep_time=1.0)
    data["rolling"]["speed"] = 1.0
    return data


CASES = {
    "paper Fig. 11 tyre as an SLS cover (nu = 0.5, b/a = 0.1, overlap)": _paper_cover,
    "cases/rubber_cover.toml (nu = 0.49, b/a ~ 1.7, load)": lambda: _file("rubber_cover"),
}


def twin(data: dict) -> dict:
    """The elastic twin: the layer with E_r, not viscoelastic, no speed."""
    out = copy.deepcopy(data)
    body = out["bodies"]["B"]
    body.update(young=body.pop("relaxed_young"))
    for key in ("viscoelastic", "creep_time"):
        body.pop(key)
    out["rolling"].pop("speed")
    return out


def timed(data: dict, repeat: int, use_cache: bool) -> dict:
    """Median wall times [s]: total, influence, Newton, rest; and Newton iterations."""
    case = load_case(data)
    solve(case, use_cache=use_cache)  # the disk cache filled (for the "cache" rows)
    rows = []
    for _ in range(repeat):
        clear_memo()
        viscoelastic.clear_memo()  # the kernels' memo on b/h too: every solve cold
        t0 = time.perf_counter()
        result = solve(case, use_cache=use_cache)
        total = time.perf_counter() - t0
        rows.append((total, result.time_influence, result.time_solve, int(result.iterations)))
    total, influence, newton = (statistics.median(r[k] for r in rows) for k in range(3))
    return {"total": total, "influence": influence, "newton": newton, "rest": total - influence - newton,
            "iterations": rows[0][3]}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", default="60,120,240")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    print(f"# {platform.machine()}, Python {platform.python_version()}, repeat {args.repeat}")
    print("| case | elements | BEM | elastic total [ms] (infl. / Newton / rest, it.) | viscoelastic total [ms] "
          "(infl. / Newton / rest, it.) | ratio |")  # fmt: skip
    print("|---|---:|---|---|---|---:|")
    for name, make in CASES.items():
        for n in sizes:
            visco = make()
            visco["discretization"]["contact_elements"] = n
            for state, use_cache in (("cache", True), ("cold", False)):
                e = timed(twin(visco), args.repeat, use_cache)
                v = timed(visco, args.repeat, use_cache)

                def cell(t):
                    return (f"{1e3 * t['total']:.0f} ({1e3 * t['influence']:.0f} / {1e3 * t['newton']:.0f} / "
                            f"{1e3 * t['rest']:.0f}, {t['iterations']})")  # fmt: skip

                print(f"| {name} | {n} | {state} | {cell(e)} | {cell(v)} | {v['total'] / e['total']:.2f} |")


if __name__ == "__main__":
    main()
