"""Where a falling-law solve spends its time against the Coulomb one, stage by stage (issue 23).

Carter's cylinders of ``bench_friction`` (half-plane, 200 elements by default), Coulomb mu = 0.30
against the exponential law, one control (``--creep`` or ``--q``). The pipeline's stage functions
are wrapped by timers (process CPU time, so a loaded machine's waits are not counted) and each
wrapped call is charged to the mesh level running at the time (coarse grid, case grid, or "post":
the result and its sensitivities). Printed: the mean CPU time per solve of each stage and its
calls, and the median CPU time of the whole solve, for both laws. The linear algebra's share
(``reuse._factor``: a fresh LU of the velocity system; ``reuse._refined``: GMRES on a kept LU;
``linalg.solve_dense``: LU solves) against the assembly and evaluation around it is the floor of
the falling solve: its case grid needs a Newton step per factor of ~r^2 in the residual, each a
system over all contact nodes, where the Coulomb step solves the adhesion nodes once.

    OMP_NUM_THREADS=1 python benchmarks/bench_law_floor.py [--creep -0.002 | --q 0.7] [--repeat 20]
"""

from __future__ import annotations

import argparse
import collections
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_friction  # noqa: E402

import rolling_cli  # noqa: E402
from rolling_cli.influence.build import clear_memo  # noqa: E402

SPENT: dict[str, float] = collections.defaultdict(float)
CALLS: collections.Counter = collections.Counter()
LEVEL = ["pre"]

#: (module, function): the stages timed; the modules that imported a function by name get the wrapper too.
STAGES = [
    ("rolling_cli.solver.velocity", "velocity_system"),
    ("rolling_cli.solver.reuse", "_refined"),
    ("rolling_cli.solver.reuse", "_factor"),
    ("rolling_cli.solver.formulation", "evaluate"),
    ("rolling_cli.solver.formulation", "roundoff_floor"),
    ("rolling_cli.solver.reduced", "newton_point"),
    ("rolling_cli.solver.linalg", "solve_dense"),
    ("rolling_cli.pipeline.assemble", "_sensitivities"),
    ("rolling_cli.pipeline.planning", "build_contact_system_with_origin"),
]
IMPORTERS = {
    "solve_dense": ["rolling_cli.solver.reuse", "rolling_cli.solver.law_sensitivity"],
    "build_contact_system_with_origin": ["rolling_cli.pipeline.mesh_path"],
}


def _timed(key: str, function):
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            name = f"[{LEVEL[0]}] {key}"
            SPENT[name] += time.process_time() - start
            CALLS[name] += 1

    return wrapper


def install() -> None:
    """Wrap the stages (and mark each mesh level's solve)."""
    import importlib

    from rolling_cli.pipeline import mesh_path

    for module_name, name in STAGES:
        module = importlib.import_module(module_name)
        wrapped = _timed(f"{module_name.split('.')[-1]}.{name}", getattr(module, name))
        setattr(module, name, wrapped)
        for importer in IMPORTERS.get(name, []):
            setattr(importlib.import_module(importer), name, wrapped)
    attempt = mesh_path.MeshPath._attempt

    def level_attempt(self, level, *args, **kwargs):
        LEVEL[0] = level.kind
        try:
            return _timed("level solve", attempt)(self, level, *args, **kwargs)
        finally:
            LEVEL[0] = "post"

    mesh_path.MeshPath._attempt = level_attempt


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--creep", type=float, default=None)
    parser.add_argument("--q", type=float, default=None, help="Q/(mu_s P)")
    parser.add_argument("--elements", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    tangential = (
        {"q_over_mu_p": args.q} if args.q is not None else {"creep": -0.002 if args.creep is None else args.creep}
    )
    install()
    for falling in (False, True):
        case = rolling_cli.load_case(bench_friction.case(args.elements, tangential, falling))
        rolling_cli.solve(case)  # warm-up
        SPENT.clear()
        CALLS.clear()
        totals = []
        for _ in range(args.repeat):
            clear_memo()
            LEVEL[0] = "pre"
            start = time.process_time()
            result = rolling_cli.solve(case)
            totals.append(time.process_time() - start)
        label = "falling" if falling else "Coulomb"
        its = result.attributes.get("iterations_total")
        print(f"{label}: {tangential}, median CPU {1e3 * statistics.median(totals):.1f} ms, Newton iterations {its}")
        for key in sorted(SPENT):
            print(f"   {key:52s} {1e3 * SPENT[key] / args.repeat:7.2f} ms  x{CALLS[key] / args.repeat:.1f}")


if __name__ == "__main__":
    main()
