"""The viscoelastic cover's cost with the old and the fast history kernels, interleaved in one process.

The cases of :mod:`bench_viscoelastic_layer` with the elastic BEM layer read from the disk cache:
solves of the elastic twin, of the cover with the kernels of main cffb703 (kept verbatim in
``tests/viscoelastic_reference.py``, swapped in for ``viscoelastic_layer.body_compliance``) and
of the cover with this tree's kernels follow each other, ``--repeat`` times, the in-process memos
cleared before every solve (a new process's state), so the shared machine's load hits all three
alike. Reported: median process CPU and wall times [ms], the ratios to the twin, and the time in
the cover's kernels alone (``body_compliance`` over all mesh levels). One BLAS thread.

    OMP_NUM_THREADS=1 python benchmarks/bench_cover_kernels.py [--repeat 15] [--sizes 60,120,240]
"""

from __future__ import annotations

import argparse
import copy
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import bench_viscoelastic_layer as bl  # noqa: E402
import viscoelastic_reference as old  # noqa: E402

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence import build, viscoelastic, viscoelastic_layer  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402

FAST = viscoelastic_layer.body_compliance
KERNEL_TIME = [0.0]


def _timed(kernels):
    def body_compliance(*args, **kwargs):
        t0 = time.process_time()
        try:
            return kernels(*args, **kwargs)
        finally:
            KERNEL_TIME[0] += time.process_time() - t0

    return body_compliance


def measure(data: dict, repeat: int) -> dict[str, dict[str, float]]:
    """Median CPU, wall and kernel times [s] of the twin, the old-kernel cover and the fast cover."""
    members = {"twin": (bl.twin(data), FAST), "old kernels": (data, old.body_compliance), "fast kernels": (data, FAST)}
    cases = {name: load_case(copy.deepcopy(d)) for name, (d, _) in members.items()}
    samples: dict[str, list[tuple[float, float, float]]] = {name: [] for name in members}
    for round_ in range(repeat + 1):
        for name, (_, kernels) in members.items():
            viscoelastic_layer.body_compliance = _timed(kernels)
            build.clear_memo()
            viscoelastic.clear_memo()
            KERNEL_TIME[0] = 0.0
            cpu, wall = time.process_time(), time.perf_counter()
            result = solve(cases[name])
            if round_:  # the first round warms up (imports, disk cache)
                samples[name].append((time.process_time() - cpu, time.perf_counter() - wall, KERNEL_TIME[0]))
            assert result.converged
    viscoelastic_layer.body_compliance = FAST
    return {
        name: {key: statistics.median(s[k] for s in rows) for k, key in enumerate(("cpu", "wall", "kernels"))}
        for name, rows in samples.items()
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--sizes", default="60,120,240")
    args = parser.parse_args()
    print(f"median of {args.repeat} interleaved solves each, CPU [ms] (wall [ms]); kernels: body_compliance CPU [ms]")
    print("| case | elements | elastic tyre | cover, old kernels | cover, fast kernels | ratio old | ratio fast |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, make in bl.CASES.items():
        for n in (int(s) for s in args.sizes.split(",")):
            data = make()
            data["discretization"]["contact_elements"] = n
            t = measure(data, args.repeat)

            def cell(m: dict[str, float], kernels: bool = True) -> str:
                extra = f", kernels {1e3 * m['kernels']:.1f}" if kernels else ""
                return f"{1e3 * m['cpu']:.1f} ({1e3 * m['wall']:.0f}{extra})"

            twin, slow, fast = t["twin"], t["old kernels"], t["fast kernels"]
            print(
                f"| {name.split(' (')[0]} | {n} | {cell(twin, False)} | {cell(slow)} | {cell(fast)} "
                f"| {slow['cpu'] / twin['cpu']:.2f} | {fast['cpu'] / twin['cpu']:.2f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
