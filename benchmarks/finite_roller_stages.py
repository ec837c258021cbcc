"""Where the finite roller's whole process goes (issue 21, "Numbers to reach"): CPU time per stage.

The covered roller of ``benchmarks/finite_roller.py`` (a/R = 0.2, 200 contact elements, cache
off, one BLAS thread), ``rollc solve`` run in fresh processes; in each, the stages are timed by
wrapping their functions (process CPU time, so the figures hold on a loaded machine): the three
BEM builds (two a-estimate levels of 16 elements, the case grid) split into mesh, element
integrals and systems (``mixed_systems``), LU solves, contact blocks and the arc rotation; the
Newton solves; the file; the rest of the command. The imports are timed apart, in a fresh process
importing every module the solve had loaded (so their CPU is the start-up's). Also the page faults
(minor) and the wall time of the process. Medians over --repeat processes.

    python benchmarks/finite_roller_stages.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from finite_roller import CASE  # noqa: E402

CHILD = r"""
import json, resource, sys, time
wall0, cpu0 = time.perf_counter(), time.process_time()
from rolling_cli import cli, process
process.reuse_freed_memory()
import rolling_cli.influence.bem.cylinder as cyl
import rolling_cli.solver.newton as newton
import rolling_cli.files.io_hdf5 as io
times, builds = {}, []

def wrap(module, name, key):
    inner = getattr(module, name, None)
    if inner is None:
        return
    def timed(*args, **kwargs):
        start = time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            times[key] = times.get(key, 0.0) + time.process_time() - start
    setattr(module, name, timed)

for name, key in (("annulus_mesh", "mesh"), ("mixed_systems", "integrals and systems"),
                  ("solve_all", "LU solves"), ("contact_blocks", "contact blocks"),
                  ("_arc_blocks", "arc rotation"), ("rotate", "arc rotation")):
    wrap(cyl, name, "  " + key)
if not hasattr(cyl, "solve_all"):
    wrap(cyl, "solve_small", "  LU solves")
wrap(cyl, "condensed", "BEM builds")
wrap(newton, "newton", "Newton")
wrap(io, "write_result", "file")
sys.argv = ["rollc", "solve", "roller.toml", "-o", "r.h5", "--overwrite"]
cpu1 = time.process_time()
try:
    cli.main()
except SystemExit:
    pass
usage = resource.getrusage(resource.RUSAGE_SELF)
times["command (all)"] = time.process_time() - cpu1
times["process CPU"] = time.process_time() - cpu0
times["wall"] = time.perf_counter() - wall0
times["page faults"] = usage.ru_minflt
modules = sorted(m for m in sys.modules if "." not in m or m.startswith("rolling_cli"))
print(json.dumps({"times": times, "modules": modules}))
"""

IMPORTS = r"""
import importlib, json, sys, time
names = json.loads(sys.argv[1])
start = time.process_time()
for name in names:
    try:
        importlib.import_module(name)
    except Exception:
        pass
print(time.process_time() - start)
"""


def _env() -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", ROLLC_NO_CACHE="1")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    rows: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "roller.toml").write_text(CASE)
        for _ in range(args.repeat):
            run = subprocess.run(
                [sys.executable, "-c", CHILD], cwd=tmp, env=_env(), check=True, capture_output=True, text=True
            )
            found = json.loads(run.stdout.strip().splitlines()[-1])
            for key, value in found["times"].items():
                rows.setdefault(key, []).append(value)
            imported = subprocess.run(
                [sys.executable, "-c", IMPORTS, json.dumps(found["modules"])],
                env=_env(),
                check=True,
                capture_output=True,
                text=True,
            )
            rows.setdefault("imports (apart)", []).append(float(imported.stdout))
    print("| stage | CPU [s] (median) | min |")
    print("|---|---:|---:|")
    for key, values in rows.items():
        if key == "page faults":
            print(f"| {key} | {statistics.median(values):.0f} | {min(values):.0f} |")
        else:
            print(f"| {key} | {statistics.median(values):.3f} | {min(values):.3f} |")
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
