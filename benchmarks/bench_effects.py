"""Time saved by simulating only the effects a case needs.

For beta = 0 cases: the automatic choice (normal problem, then tangential with
p_n held; coupling blocks never formed) against the coupled solve forced with
``effects.coupling = "on"``; and free rolling of similar cylinders, where the
tangential problem is skipped, against solving it. Median of ``--repeat`` runs,
influence rebuilt every time (cache off).

    python benchmarks/bench_effects.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402

CASES = Path(__file__).resolve().parents[1] / "cases"


def timed(case, repeat):
    times, result = [], None
    for _ in range(repeat):
        clear_memo()
        t = time.perf_counter()
        result = rolling_cli.solve(case, use_cache=False)
        times.append(time.perf_counter() - t)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    carter = load_case(CASES / "carter.toml")
    studies = []
    for elements in (200, 800, 1600):
        studies.append(
            (
                f"Carter, half-plane, {elements} elements",
                with_overrides(carter, {"discretization.contact_elements": elements}),
            )
        )
    studies.append(("Carter, BEM, 200 elements", with_overrides(carter, {"discretization.influence": "bem"})))
    print("| case | automatic [s] | effects | forced [s] | forced | saved |")
    print("|---|---:|---|---:|---|---:|")
    for name, case in studies:
        compare(name, case, "decoupled", "coupled", args.repeat)
    for elements in (200, 1600):
        free = with_overrides(carter, {"discretization.contact_elements": elements, "tangential.q_over_mu_p": 0.0})
        name = f"free rolling (Q = 0), similar, {elements} elements"
        compare(name, free, "tangential skipped", "coupled, tangential solved", repeat=args.repeat)


def compare(name, case, automatic, forced_label, repeat):
    """One table row: the automatic effects against effects.coupling = "on"."""
    auto, r_auto = timed(case, repeat)
    forced, _ = timed(with_overrides(case, {"effects.coupling": "on"}), repeat)
    print(
        f"| {name} | {auto:.3f} | {automatic} ({r_auto.iterations} it.) | {forced:.3f} | {forced_label} | "
        f"{100 * (1 - auto / forced):.0f} % |",
        flush=True,
    )


if __name__ == "__main__":
    main()
