"""Cost of friction that falls with the slip speed against Coulomb friction on the same grid.

Carter's similar cylinders (half-plane, 200 elements by default) with
mu_static = 0.30 under creep control (xi = -0.0005 ... -0.004) and force control
(Q/(mu_s P) = 0.3 ... 0.7): the Coulomb case with mu = mu_static and the issue's
exponential law (mu_k = 0.18, s_h = 100 mm/s, |V| = 45000 mm/s). Columns: the
in-process wall time of ``rolling_cli.solve`` (plan, influence, system, Newton,
result; the median of ``--repeat`` runs after one warm-up, the influence memo
cleared every run), the Newton time alone (``time_solve``) and the Newton
iterations. Target (issue 23): the falling-law solve at most 1.5x the Coulomb one.

    OMP_NUM_THREADS=1 python benchmarks/bench_friction.py [--repeat 5] [--elements 200]
"""

from __future__ import annotations

import argparse
import platform
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402

BODY = {"kind": "elastic", "radius": 100.0, "young": 210000.0, "poisson": 0.3}
LAW = {"law": "exponential", "mu_static": 0.30, "mu_kinetic": 0.18, "slip_velocity_half": 100.0}
SPEED = 45000.0


def case(elements: int, tangential: dict, falling: bool) -> dict:
    """A Carter case dict with Coulomb mu = 0.30 or the exponential law."""
    return {
        "bodies": {"A": dict(BODY), "B": dict(BODY)},
        "friction": dict(LAW) if falling else {"mu": 0.30},
        "normal": {"load": 1812.5},
        "tangential": tangential,
        "rolling": {"direction": -1, **({"speed": SPEED} if falling else {})},
        "discretization": {"influence": "half-plane", "contact_elements": elements},
    }


def measure(data: dict, repeat: int) -> tuple[float, float, int]:
    """(median wall time of solve [s], median Newton time [s], Newton iterations of every grid)."""
    loaded = rolling_cli.load_case(data)
    rolling_cli.solve(loaded)  # warm-up (imports, caches of the process)
    walls, newton = [], []
    result = None
    for _ in range(repeat):
        clear_memo()
        start = time.perf_counter()
        result = rolling_cli.solve(loaded)
        walls.append(time.perf_counter() - start)
        newton.append(float(result.time_solve))
    assert result is not None and result.converged
    return statistics.median(walls), statistics.median(newton), int(result.iterations_total or result.iterations)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--elements", type=int, default=200)
    args = parser.parse_args()
    controls = [{"creep": xi} for xi in (-0.0005, -0.001, -0.002, -0.004)]
    controls += [{"q_over_mu_p": q} for q in (0.3, 0.5, 0.7)]
    print(
        f"# {platform.machine()}, Python {platform.python_version()}, {args.elements} elements, median of {args.repeat}"
    )
    print(
        "| control | Coulomb solve [s] | falling solve [s] | ratio | Coulomb Newton [s] | falling Newton [s] "
        "| ratio | iterations Coulomb / falling (all grids) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    ratios = []
    for tangential in controls:
        ((kind, value),) = tangential.items()
        c_wall, c_newton, c_it = measure(case(args.elements, tangential, False), args.repeat)
        f_wall, f_newton, f_it = measure(case(args.elements, tangential, True), args.repeat)
        ratios.append(f_wall / c_wall)
        print(
            f"| {kind} = {value:g} | {c_wall:.3f} | {f_wall:.3f} | {f_wall / c_wall:.2f} | {c_newton:.3f} "
            f"| {f_newton:.3f} | {f_newton / c_newton:.1f} | {c_it} / {f_it} |"
        )
    print(f"median solve ratio {statistics.median(ratios):.2f}, largest {max(ratios):.2f}")


if __name__ == "__main__":
    main()
