"""Sweeps at scale: a half-plane friction x creepage lookup table (the cases a vehicle-dynamics
or roller-drive model consumes), solved and written as one file.

Each run is a fresh process (``sweep.run`` as ``rollc sweep`` calls it) that reports:

* wall time, the solve time summed over cases, and the writer's time (rows,
  commits, rebuilds, the final trim), so the writer overhead = writer / solve;
* the peak memory (RSS) of the process that writes: it must not grow with
  the number of cases;
* bytes per case of the file.

Rows: the study at N/10 and N cases serially (overhead, memory flat in N), then
the N-case study on ``--workers 2`` and on a 2-worker Dask LocalCluster
(``--scheduler local:2``). Last, an estimate of the 1,000,000-case table on a
64-worker cluster from the measured per-case costs.

    python benchmarks/bench_sweep.py [--cases 10000] [--elements 200] [--skip-parallel]
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

RUN = """
import json, os, resource, sys, time
from rolling_cli.study import sweep
from rolling_cli.case import load_case
args = json.loads(sys.argv[1])
base = load_case(args["case"])
spec = sweep.spec_from_options(args["settings"], False)
start = time.perf_counter()
report = sweep.run(base, spec, args["output"], workers=args["workers"], scheduler=args["scheduler"])
wall = time.perf_counter() - start
print(json.dumps({
    "cases": spec.size,
    "failed": int(report.failed_mask.sum()),
    "wall": wall,
    "solve": report.solve_seconds,
    "write": report.write_seconds,
    "bytes": os.path.getsize(args["output"]),
    "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
}))
"""


def study(cases: int) -> list[str]:
    """Friction values x creepages, as square as the count allows (the creepage varies fastest)."""
    mus = max(1, round(math.sqrt(cases / 10)))
    creeps = max(1, cases // mus)
    return [f"friction.mu=0.05:0.6:{mus}", f"tangential.creep=-0.004:0.004:{creeps}"]


def run(case: dict, settings: list[str], output: str, workers: int = 1, scheduler: str | None = None) -> dict:
    args = {"case": case, "settings": settings, "output": output, "workers": workers, "scheduler": scheduler}
    done = subprocess.run(
        [sys.executable, "-c", RUN, json.dumps(args)], capture_output=True, text=True, cwd=ROOT, check=True
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def whole_process(args: list[str], repeat: int = 3) -> float:
    """Median wall time of a ``rollc`` command, process start and imports included."""
    import statistics
    import time

    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "rolling_cli", "-q", *args], check=True, cwd=ROOT)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", type=int, default=10_000)
    parser.add_argument("--elements", type=int, default=200, help="contact elements (the shipped Carter case: 200)")
    parser.add_argument("--skip-parallel", action="store_true")
    args = parser.parse_args()
    import tomllib

    case = tomllib.loads((ROOT / "cases" / "carter.toml").read_text())
    case["discretization"].update(influence="half-plane", contact_elements=args.elements)
    case.pop("tangential", None)
    case["tangential"] = {"creep": 0.0}
    tmp = Path(tempfile.mkdtemp())
    print(f"Half-plane Carter pair, {args.elements} contact elements, mu x creepage table")
    print()
    print("| cases | how | wall [s] | solve [s] | writer [s] | writer / solve | peak RSS [MB] | bytes/case | failed |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    rows = []
    plan = [(max(10, args.cases // 10), 1, None), (args.cases, 1, None)]
    if not args.skip_parallel:
        plan += [(args.cases, 2, None), (args.cases, 1, "local:2")]
    for count, workers, scheduler in plan:
        out = str(tmp / f"s_{count}_{workers}_{scheduler or 'local'}.h5".replace(":", ""))
        r = run(case, study(count), out, workers, scheduler)
        how = f"Dask {scheduler}" if scheduler else f"--workers {workers}"
        rows.append((count, how, r))
        print(
            f"| {r['cases']} | {how} | {r['wall']:.1f} | {r['solve']:.1f} | {r['write']:.2f} | "
            f"{100 * r['write'] / r['solve']:.1f} % | {r['rss_mb']:.0f} | {r['bytes'] / r['cases']:.0f} | "
            f"{r['failed']} |",
            flush=True,
        )
    carter = str(ROOT / "cases" / "carter.toml")
    one = whole_process(["solve", carter, "-o", str(tmp / "one.h5"), "--overwrite"])
    hundred = whole_process(
        ["sweep", carter, "--set", "friction.mu=0.01:1:100", "-o", str(tmp / "100.h5"), "--workers", "1", "--overwrite"]
    )
    print()
    print(
        f"Whole process (median of 3): one Carter solve {one:.2f} s, a 100-value friction sweep of it "
        f"{hundred:.2f} s ({hundred / one:.1f} times one solve)."
    )
    serial = rows[1][2]
    per_solve = serial["solve"] / serial["cases"]
    per_write = serial["write"] / serial["cases"]
    per_transfer = transfer_seconds(case)
    per_client = per_write + per_transfer
    million, workers = 1_000_000, 64
    solve_hours = million * per_solve / workers / 3600
    client_hours = million * per_client / 3600
    size_gb = million * serial["bytes"] / serial["cases"] / 1e9
    print()
    print(
        f"Estimate, {million} cases on {workers} workers: the solves take {solve_hours:.2f} h of wall time "
        f"({per_solve * 1e3:.2f} ms per case, measured serially); the one client takes {client_hours:.2f} h "
        f"({per_client * 1e3:.2f} ms per case: the writer {per_write * 1e3:.2f} ms, a record's pickle round "
        f"trip {per_transfer * 1e3:.2f} ms); the run takes the larger, ~{max(solve_hours, client_hours):.2f} h, "
        f"and writes {size_gb:.1f} GB."
    )


def transfer_seconds(case: dict) -> float:
    """Seconds per case to serialise a chunk's records on a worker and read them in the client."""
    import pickle
    import time

    from rolling_cli.case import load_case
    from rolling_cli.study import sweep

    spec = sweep.spec_from_options(study(80), False)
    items = [(i, spec.combination(i)) for i in range(sweep.CHUNK)]
    records = list(sweep.solve_items(load_case(case), items, True, True))
    start = time.perf_counter()
    for _ in range(20):
        pickle.loads(pickle.dumps(records))
    return (time.perf_counter() - start) / 20 / len(records)


if __name__ == "__main__":
    main()
