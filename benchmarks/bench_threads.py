"""BLAS threads of a single ``rollc solve``: one against two, on an idle machine and beside busy processes.

Each case is solved as a subprocess, ``rollc -q solve CASE -o OUT --overwrite --no-cache`` (so
the BEM cases compute their influence: the LAPACK condensation), with

* ``default``: none of the thread variables set (what ``rollc solve`` chooses:
  :data:`rolling_cli.blas.DEFAULT_THREADS`);
* ``1`` / ``2``: OPENBLAS_NUM_THREADS, OMP_NUM_THREADS and MKL_NUM_THREADS set to that count
  (a user's setting, which rollc respects);

under three loads: as the machine is (``--busy 0``), and beside one and two busy-loop processes
(pure Python ``while True: pass``, each keeping one core busy). Wall times are the median of
``--repeat`` runs, the settings alternated within each repetition so that a drift of the
machine's load falls on all alike. The load average before each load level is printed.

    python benchmarks/bench_threads.py [--repeat 3] [--busy 0,1,2] [--cases carter,fig5_200,tyred]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import tomli_w

ROOT = Path(__file__).resolve().parents[1]
CASES = ROOT / "cases"
THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
SETTINGS = ("default", "1", "2")


def case_files(directory: Path) -> dict[str, Path]:
    """The benchmark's cases, written to ``directory``: name -> case file."""
    out = {"carter": CASES / "carter.toml", "dissimilar": CASES / "dissimilar_q75.toml"}
    fig5 = tomllib.loads((CASES / "paper_fig5_q075.toml").read_text())
    fig5["discretization"]["contact_elements"] = 200  # 600 contact nodes, a BEM of ~900 nodes a body
    out["fig5_200"] = directory / "fig5_200.toml"
    out["fig5_200"].write_text(tomli_w.dumps(fig5))
    out["tyred"] = CASES / "tyred_fig11_q41.toml"
    return out


def environment(setting: str) -> dict[str, str]:
    """The subprocess environment of a thread setting (see the module docstring)."""
    env = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    if setting != "default":
        env.update({name: setting for name in THREAD_VARIABLES[:3]})
    return env


def solve_time(case: Path, output: Path, setting: str) -> float:
    """Wall time [s] of one ``rollc -q solve`` subprocess."""
    command = [sys.executable, "-m", "rolling_cli", "-q", "solve", str(case), "-o", str(output)]
    start = time.perf_counter()
    subprocess.run([*command, "--overwrite", "--no-cache"], check=True, env=environment(setting))
    return time.perf_counter() - start


def busy(count: int) -> list[subprocess.Popen]:
    """``count`` busy-loop processes (stopped by the caller)."""
    return [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(count)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--busy", default="0,1,2")
    parser.add_argument("--cases", default="carter,dissimilar,fig5_200,tyred")
    args = parser.parse_args()
    print(f"CPUs usable: {len(os.sched_getaffinity(0))}")
    print("| busy loops | load avg (1 min) before | case | default [s] | 1 thread [s] | 2 threads [s] | 2 / 1 |")
    print("|---:|---:|---|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        files = case_files(Path(tmp))
        for level in (int(b) for b in args.busy.split(",")):
            loops = busy(level)
            try:
                time.sleep(1.0)
                load = os.getloadavg()[0]
                for name in args.cases.split(","):
                    times: dict[str, list[float]] = {s: [] for s in SETTINGS}
                    solve_time(files[name], Path(tmp) / "warm.h5", "1")  # page cache, .pyc files
                    for _ in range(args.repeat):
                        for setting in SETTINGS:
                            times[setting].append(solve_time(files[name], Path(tmp) / "out.h5", setting))
                    med = {s: statistics.median(t) for s, t in times.items()}
                    print(
                        f"| {level} | {load:.1f} | {name} | {med['default']:.2f} | {med['1']:.2f} | {med['2']:.2f} "
                        f"| {med['2'] / med['1']:.2f} |",
                        flush=True,
                    )
            finally:
                for loop in loops:
                    loop.kill()
                    loop.wait()


if __name__ == "__main__":
    main()
