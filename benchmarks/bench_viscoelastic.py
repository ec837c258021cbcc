"""Cost of a viscoelastic half-plane solve against the elastic one on the same grid (issue 22).

Each viscoelastic case is paired with its elastic twin: body B elastic with the
relaxed modulus E_r, whose Hertz half-width is the viscoelastic case's mesh
scale, so both have the same constant-element grid. The in-process median of
``--repeat`` cold solves (the influence memo cleared) is split into the
influence build, the Newton solve and the rest (plan, system, result; for the
viscoelastic case the rolling-resistance outputs and the Fourier-space
hysteresis).

    python benchmarks/bench_viscoelastic.py [--repeat 5] [--sizes 100,200,400,800]
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
from rolling_cli.influence import viscoelastic  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402

ROLLER = {
    "bodies": {
        "A": {"kind": "rigid", "radius": 50.0},
        "B": {
            "kind": "viscoelastic",
            "radius": "inf",
            "young": 20.0,
            "relaxed_young": 10.0,
            "creep_time": 0.01,
            "poisson": 0.5,
        },
    },
    "friction": {"mu": 0.3},
    "normal": {"load": 1.0},
    "tangential": {"q_over_mu_p": 0.5},
    "rolling": {"speed": 200.0},
    "discretization": {"element": "constant", "contact_elements": 200, "zone": 1.5},
}
POLYMER = {
    "bodies": {
        "A": {"kind": "elastic", "radius": 50.0, "young": 210000.0, "poisson": 0.3},
        "B": {
            "kind": "viscoelastic",
            "radius": 100.0,
            "young": 3200.0,
            "relaxed_young": 1600.0,
            "creep_time": 0.002,
            "poisson": 0.35,
        },
    },
    "friction": {"mu": 0.3},
    "normal": {"load": 300.0},
    "tangential": {"q_over_mu_p": 0.5},
    "rolling": {"speed": 1000.0},
    "discretization": {"element": "constant", "contact_elements": 200, "zone": 1.5},
}
CASES = {"rigid on SLS flat, nu = 0.5 (decoupled)": ROLLER, "steel on SLS polymer, nu = 0.35 (coupled)": POLYMER}


def twin(data: dict) -> dict:
    """The elastic twin: body B elastic with E_r (the same mesh scale, so the same grid)."""
    out = copy.deepcopy(data)
    body = out["bodies"]["B"]
    body.update(kind="elastic", young=body.pop("relaxed_young"))
    body.pop("creep_time")
    out["rolling"].pop("speed")
    return out


def timed(data: dict, repeat: int) -> dict:
    """Median wall times [s] of cold solves: total, influence, Newton, rest; and Newton iterations."""
    case = load_case(data)
    rows = []
    for _ in range(repeat):
        clear_memo()
        viscoelastic.clear_memo()  # the kernels' memo on b/h too: every solve cold
        t0 = time.perf_counter()
        result = solve(case)
        total = time.perf_counter() - t0
        rows.append((total, result.time_influence, result.time_solve, int(result.iterations)))
    total, influence, newton = (statistics.median(r[k] for r in rows) for k in range(3))
    return {"total": total, "influence": influence, "newton": newton, "rest": total - influence - newton,
            "iterations": rows[0][3]}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", default="100,200,400,800")
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    solve(load_case(ROLLER))  # imports (scipy.special, ...) out of the timings
    print(f"# {platform.machine()}, Python {platform.python_version()}, repeat {args.repeat}")
    print("| case | elements | elastic total [ms] (infl. / Newton / rest, it.) | viscoelastic total [ms] "
          "(infl. / Newton / rest, it.) | ratio |")  # fmt: skip
    print("|---|---:|---|---|---:|")
    for name, data in CASES.items():
        for n in sizes:
            visco = copy.deepcopy(data)
            visco["discretization"]["contact_elements"] = n
            e = timed(twin(visco), args.repeat)
            v = timed(visco, args.repeat)

            def cell(t):
                return (f"{1e3 * t['total']:.1f} ({1e3 * t['influence']:.1f} / {1e3 * t['newton']:.1f} / "
                        f"{1e3 * t['rest']:.1f}, {t['iterations']})")  # fmt: skip

            print(f"| {name} | {n} | {cell(e)} | {cell(v)} | {v['total'] / e['total']:.2f} |")


if __name__ == "__main__":
    main()
