"""Cost of a viscoelastic finite cylinder against today's elastic finite cylinder (issue 22 item 2).

Each viscoelastic roller is paired with its elastic twin, the same finite cylinder with the
relaxed modulus E_r (the widest contact, the viscoelastic case's mesh scale) and no history, on the
same number of quadratic elements. Median wall times of ``--repeat`` in-process solves, in two
states: "cache" (the in-process memo cleared, the elastic BEM annulus read from the disk cache: a
re-run, a sweep) and "cold" (``use_cache=False``: the BEM annulus built). Split into the influence
build, the Newton solve and the rest (plan, result; for the roller the rolling-resistance outputs
and the annulus's modal hysteresis).

    python benchmarks/bench_viscoelastic_cylinder.py [--repeat 3] [--sizes 50,100,200]
"""

from __future__ import annotations

import argparse
import copy
import platform
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402


def _roller() -> dict:
    """A hollow roller R = 10, bore 5 (SLS, E_g = 2 E_r = 20, tau_c = 1, nu = 0.4) on a rigid flat,
    P = 1 (a/R ~ 0.1), mu = 0.3, Q/(mu P) = 0.5, V tau_c / a ~ 1."""
    body = {"kind": "viscoelastic", "radius": 10.0, "young": 20.0, "relaxed_young": 10.0, "creep_time": 1.0,
            "poisson": 0.4, "shape": "cylinder", "inner_radius": 5.0}  # fmt: skip
    return {
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
        "friction": {"mu": 0.3},
        "normal": {"load": 1.0},
        "tangential": {"q_over_mu_p": 0.5},
        "rolling": {"direction": -1, "speed": 1.0},
        "discretization": {"element": "quadratic", "contact_elements": 100, "zone": 1.5},
    }


def _covered() -> dict:
    """The same roller as a finite covered roller: an SLS cover 2 thick on a rigid core of radius 8."""
    data = _roller()
    body = data["bodies"]["A"]
    body.update(kind="layered", viscoelastic=True, layer_thickness=2.0)
    body.pop("inner_radius")
    return data


CASES = {
    "hollow roller R = 10, bore 5, nu = 0.4, load": _roller,
    "covered roller R = 10, cover 2, nu = 0.4, load": _covered,
}


def twin(data: dict) -> dict:
    """The elastic twin: the finite cylinder with E_r, not viscoelastic, no speed."""
    out = copy.deepcopy(data)
    body = out["bodies"]["A"]
    body.update(young=body.pop("relaxed_young"))
    body.pop("creep_time")
    if body.pop("viscoelastic", False) is False:
        body["kind"] = "elastic"
    out["rolling"].pop("speed")
    return out


def timed(data: dict, repeat: int, use_cache: bool) -> dict:
    """Median wall times [s]: total, influence, Newton, rest; and Newton iterations."""
    case = load_case(data)
    solve(case, use_cache=use_cache)  # the disk cache filled (for the "cache" rows)
    rows = []
    for _ in range(repeat):
        clear_memo()
        t0 = time.perf_counter()
        result = solve(case, use_cache=use_cache)
        total = time.perf_counter() - t0
        rows.append((total, result.time_influence, result.time_solve, int(result.iterations)))
    total, influence, newton = (statistics.median(r[k] for r in rows) for k in range(3))
    return {"total": total, "influence": influence, "newton": newton, "rest": total - influence - newton,
            "iterations": rows[0][3]}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--sizes", default="50,100,200")
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
