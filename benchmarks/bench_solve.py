"""Solve time, memory and Newton iterations against problem size (half-plane model).

n is the number of contact nodes, i.e. the unknowns per traction component:
n = elements for constant elements, 3 x elements for the paper's quadratic
ones. Two columns of time:

* in-process: the median of ``--repeat`` runs of the whole pipeline after
  import (plan, influence, system, Newton), from a cold start (the in-process
  influence memo cleared);
* whole process: ``rollc -q solve case.toml -o result.h5`` as a subprocess
  (imports, solve and the result file), the median of ``--process-repeat`` runs,
  and the peak resident set of one more run (``os.wait4`` in a small launcher).

``path`` is the linear solver the Newton steps used (the ``linear_solver``
result attribute): "dense LU", or "Krylov" on the matrix-free path that uniform
grids from :data:`rolling_cli.influence.halfplane.OPERATOR_NODES` nodes get
(issue #14 item 2); ``Krylov it.`` the GMRES iterations of all Newton steps.
``--preconditioner band`` runs coupled systems with the near-field band alone
(without the coarse-grid correction, :mod:`rolling_cli.solver.coarse`), in
process only. ``--dense-up-to N`` adds, for sizes up to N nodes on the matrix-free path, the
same case forced onto the dense path (in-process time and the largest relative
difference of p_n and p_t; the threshold's crossover).

    python benchmarks/bench_solve.py [--repeat 3] [--process-repeat 5] [--sizes 50,100,...]
        [--fast-sizes 1000,3000,10000,30000,100000] [--dense-up-to 3200] [--cases "dissimilar q=0.75"]
        [--preconditioner two-level|band]
"""

from __future__ import annotations

import argparse
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402
import tomli_w  # noqa: E402

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.errors import ConvergenceError  # noqa: E402
from rolling_cli.influence import halfplane  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402
from rolling_cli.solver import matrix_free  # noqa: E402

CASES = Path(__file__).resolve().parents[1] / "cases"
FILES = {"Carter q=0.51": "carter.toml", "dissimilar q=0.04": "dissimilar_q04.toml"}
#: Cases named here are a shipped file with Q/(mu P) replaced (not in the default list).
VARIANTS = {"dissimilar q=0.75": ("dissimilar_q04.toml", 0.75)}


def run(case, repeat):
    """Median in-process time [s] of ``repeat`` cold solves, and the last result."""
    times, result = [], None
    for _ in range(repeat):
        clear_memo()  # every run builds its influence: no in-process reuse
        t = time.perf_counter()
        result = rolling_cli.solve(case)
        times.append(time.perf_counter() - t)
    return statistics.median(times), result


def dense_run(case, repeat):
    """As :func:`run` with the matrix-free path switched off."""
    saved = halfplane.OPERATOR_NODES
    halfplane.OPERATOR_NODES = 10**12
    try:
        return run(case, repeat)
    finally:
        halfplane.OPERATOR_NODES = saved
        clear_memo()


def rollc() -> list[str]:
    """The command of the installed ``rollc`` (beside this interpreter, else on PATH)."""
    beside = Path(sys.executable).with_name("rollc")
    found = str(beside) if beside.exists() else shutil.which("rollc")
    if found is None:
        raise SystemExit("rollc is not installed (pip install -e .)")
    return [found]


#: Runs a command and prints its peak resident set [kB]. The command is forked from this small
#: process, not from the benchmark (a child's high-water mark includes its parent's resident set
#: at the fork, and Linux keeps it across exec).
_PEAK = (
    "import os, subprocess, sys; p = subprocess.Popen(sys.argv[1:]); _, status, usage = os.wait4(p.pid, 0); "
    "print(usage.ru_maxrss if os.waitstatus_to_exitcode(status) == 0 else -1)"
)


def whole_process(data: dict, repeat: int, folder: Path) -> tuple[float, float]:
    """Median wall time [s] of ``rollc -q solve`` on ``data`` (``repeat`` runs) and the peak
    resident set of one more run [MB]."""
    case_file = folder / "case.toml"
    case_file.write_text(tomli_w.dumps(data))
    out = folder / "result.h5"
    command = rollc() + ["-q", "solve", str(case_file), "-o", str(out)]
    times = []
    for _ in range(repeat):
        out.unlink(missing_ok=True)
        t = time.perf_counter()
        subprocess.run(command, check=True)
        times.append(time.perf_counter() - t)
    out.unlink(missing_ok=True)
    found = subprocess.run([sys.executable, "-c", _PEAK, *command], capture_output=True, text=True, check=True)
    peak = int(found.stdout.strip())
    if peak < 0:
        raise SystemExit(f"rollc failed on {case_file}")
    return statistics.median(times), peak / 1024.0  # kB on Linux


def case_data(file: str, element: str, elements: int) -> dict:
    """The shipped case ``file`` (or a name of :data:`VARIANTS`) with its element type and count
    replaced (a plain dict)."""
    q = None
    if file in VARIANTS:
        file, q = VARIANTS[file]
    data = tomllib.loads((CASES / file).read_text())
    data["discretization"]["element"] = element
    data["discretization"]["contact_elements"] = elements
    if q is not None:
        data["tangential"]["q_over_mu_p"] = q
    return data


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--process-repeat", type=int, default=5, help="whole-process runs (0: no column)")
    parser.add_argument("--sizes", default="50,100,200,400,800,1600,3200")
    parser.add_argument("--fast-sizes", default="1000,3000,10000,30000,100000", help="quadratic elements only")
    parser.add_argument("--dense-up-to", type=int, default=0, help="compare with the dense path up to n nodes")
    parser.add_argument("--cases", default=",".join(FILES), help=f"of {', '.join([*FILES, *VARIANTS])}")
    parser.add_argument(
        "--preconditioner",
        choices=("two-level", "band"),
        default="two-level",
        help="coupled systems' Krylov preconditioner in process (band: the near field alone, as before "
        "the coarse correction; the process column always runs the default)",
    )
    args = parser.parse_args()
    matrix_free.TWO_LEVEL = args.preconditioner == "two-level"
    sizes = [int(s) for s in args.sizes.split(",") if s]
    fast = [int(s) for s in args.fast_sizes.split(",") if s]
    print(
        f"# bench_solve: {platform.node()}, {platform.processor() or platform.machine()}, "
        f"python {platform.python_version()}, rolling_cli {rolling_cli.__version__}"
    )
    print(
        "| case | element | n nodes | elements | path | time [s] | process [s] | process peak [MB] | "
        "influence [s] | Newton [s] | iterations | Krylov it. | dense [s] | max rel. diff. |"
    )
    print("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.cases.split(","):
            runs = [(e, n) for e in ("constant", "quadratic") for n in sizes] + [("quadratic", n) for n in fast]
            for element, n in runs:
                per = 1 if element == "constant" else 3
                elements = max(2, round(n / per))
                data = case_data(FILES.get(name, name), element, elements)
                case = load_case(data)
                try:
                    wall, r = run(case, args.repeat)
                except ConvergenceError as err:
                    print(f"| {name} | {element} | {elements * per} | {elements} | failed: {str(err)[:120]} |")
                    continue
                process, peak = whole_process(data, args.process_repeat, Path(tmp)) if args.process_repeat else (0, 0)
                path = r.attributes["linear_solver"]
                dense = diff = "-"
                if path == "Krylov" and elements * per <= args.dense_up_to:
                    seconds, d = dense_run(case, args.repeat)
                    scale = np.abs(d.p_n).max()
                    change = max(np.abs(r.p_n - d.p_n).max(), np.abs(r.p_t - d.p_t).max()) / scale
                    dense, diff = f"{seconds:.3f}", f"{change:.1e}"
                print(
                    f"| {name} | {element} | {elements * per} | {elements} | {path} | {wall:.3f} | "
                    f"{process:.3f} | {peak:.0f} | {r.time_influence:.3f} | {r.time_solve:.3f} | {r.iterations} | "
                    f"{r.attributes.get('krylov_iterations', '-')} | {dense} | {diff} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
