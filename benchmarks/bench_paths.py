"""Warm against cold paths: 41-point creep-force curves, in-process and as whole ``rollc sweep`` processes.

For each shipped case and curve kind (``--curve load``: Q/(mu P) from -0.99 to
0.99; ``--curve creep``: the creepage over 1.5 times full slip), the sweep runs
with warm starts (the default: each case started from the boundary-tracking
secant of its two predecessors) and with ``--no-warm-start``. Reported: the
failures, the median and mean Newton iterations of the warm-started and of the
cold-started cases, the in-process time (``sweep.run``, one worker, one BLAS
thread) and the whole-process time of ``rollc -q sweep ... --workers 1``
(median of ``--repeat``), which includes start-up and writing. In-process times are medians
of ``--repeat`` interleaved warm/cold runs after a warm-up; "Newton" sums the results'
``time_solve`` (the solver strategies alone, without case building, results and file).

    python benchmarks/bench_paths.py [--cases carter,dissimilar_q75,...] [--repeat 3]
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from rolling_cli import blas  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.study import sweep  # noqa: E402

CASES = "carter,dissimilar_q75,dissimilar_qm83,tyred_fig11_q41"


def in_process(name: str, kind: str, warm: bool, work: Path) -> tuple[float, float, list, list, int]:
    """One in-process sweep: (seconds, Newton seconds summed over the cases (the results'
    ``time_solve``), warm-started iterations, cold-started iterations, failures)."""
    base = load_case(ROOT / "cases" / f"{name}.toml")
    spec = sweep.curve_spec(base, kind, 41)
    out = work / f"{name}_{kind}_{warm}.h5"
    if out.exists():
        out.unlink()
    t0 = time.perf_counter()
    report = sweep.run(base, spec, str(out), workers=1, warm=warm)
    seconds = time.perf_counter() - t0
    records = [r for r in report.records.values() if r.converged]
    newton = sum(float(r.result.time_solve) for r in records)
    warm_its = [r.result.iterations for r in records if r.result.start == "warm"]
    cold_its = [r.result.iterations for r in records if r.result.start == "cold"]
    return seconds, newton, warm_its, cold_its, len(report.failed)


def whole_process(name: str, kind: str, warm: bool, work: Path, repeat: int) -> float:
    rollc = shutil.which("rollc") or f"{sys.executable} -m rolling_cli"
    times = []
    for k in range(repeat):
        out = work / f"p_{name}_{kind}_{warm}_{k}.h5"
        cmd = [*rollc.split(), "-q", "sweep", str(ROOT / "cases" / f"{name}.toml"), "--curve", kind]
        cmd += ["--workers", "1", "-o", str(out)] + ([] if warm else ["--no-warm-start"])
        t0 = time.perf_counter()
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # bytecode cached, as installed
        subprocess.run(cmd, check=False, capture_output=True, env={**env, **blas.SINGLE_THREAD_ENV})
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", default=CASES)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(
        "| case | curve | failed (warm / cold) | iterations warm-started: median (mean) | cold: median (mean) "
        "| in-process warm / cold [s] | speed-up | Newton warm / cold [s] | speed-up | whole process warm / cold [s] "
        "| speed-up |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp, blas.single_threaded():
        work = Path(tmp)
        for name in args.cases.split(","):
            for kind in ("load", "creep"):
                in_process(name, kind, True, work)  # warm-up: imports, influence memo
                runs = {True: [], False: []}
                for _ in range(max(1, args.repeat)):  # interleaved
                    for warm in (True, False):
                        runs[warm].append(in_process(name, kind, warm, work))
                tw, nw = (statistics.median(r[i] for r in runs[True]) for i in (0, 1))
                tc, nc = (statistics.median(r[i] for r in runs[False]) for i in (0, 1))
                _, _, warm_its, _, fw = runs[True][0]
                _, _, _, cold_its, fc = runs[False][0]
                pw = whole_process(name, kind, True, work, args.repeat)
                pc = whole_process(name, kind, False, work, args.repeat)
                print(
                    f"| {name} | {kind} | {fw} / {fc} | {np.median(warm_its):.0f} ({np.mean(warm_its):.2f}) "
                    f"| {np.median(cold_its):.0f} ({np.mean(cold_its):.2f}) | {tw:.3f} / {tc:.3f} | {tc / tw:.2f} "
                    f"| {nw:.3f} / {nc:.3f} | {nc / nw:.2f} | {pw:.2f} / {pc:.2f} | {pc / pw:.2f} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
