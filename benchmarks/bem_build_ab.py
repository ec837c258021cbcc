"""Before/after cost of the BEM build: checkouts side by side, interleaved (issues #10 and #14).

Every measurement runs in a fresh process with the code of one checkout
(``--roots``, comma-separated, e.g. an export of the branch point:
``git archive 21d1604 | tar -x -C /tmp/before``), and the runs alternate
between the roots, so that a shared machine's load falls on all of them
alike; each cell is the median of ``--repeat`` runs.

* ``--mode stages`` (default): one BEM body (``--case similar``: the paper's
  similar case, R = 100 mm, a half-space of 100 a with its far field;
  ``--case layer``: the paper's Fig. 11 layer, b/a = 0.1), mesh + assembly,
  factorisation, condensation (the solves and the compliance blocks), their
  total, in wall and CPU seconds, and the peak resident memory of the build
  over the process's state before it (``ru_maxrss``).
* ``--mode whole``: ``python -m rolling_cli -q solve --no-cache`` of the case
  (overlap control: it includes the coarse pre-solves that measure a, the
  Newton solve and the result file), wall seconds and peak resident memory
  of the whole process.

``--case`` takes ``similar`` (cases/paper_fig3_q051.toml, one BEM body),
``dissimilar`` (cases/dissimilar_q04.toml with ``influence = "bem"``: two
bodies, whole mode only) or ``layer`` (cases/tyred_fig11_q41.toml). BLAS
threads are left as the environment sets them.

    python benchmarks/bem_build_ab.py --roots /tmp/before,. --elements 100,400,1600
    python benchmarks/bem_build_ab.py --roots /tmp/before,. --mode whole --elements 400
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve()
CASES = {"similar": "paper_fig3_q051.toml", "dissimilar": "dissimilar_q04.toml", "layer": "tyred_fig11_q41.toml"}
#: The measured contact half-width a [mm] of the similar and the layer case (the build only scales with it).
HALF_WIDTH = {"similar": 0.5443, "layer": 0.9999}


def stages(root: str, elements: int, case_name: str) -> dict:
    """The build stages of the case's first meshed body in this process, with the code under ``root`` (child mode)."""
    sys.path.insert(0, str(Path(root).resolve()))
    from rolling_cli.case import load_case, with_overrides
    from rolling_cli.influence import bem
    from rolling_cli.influence.bem import condense
    from rolling_cli.influence.build import bem_inputs
    from rolling_cli.pipeline import plan

    base = load_case(Path(root) / "cases" / CASES[case_name])
    case = with_overrides(base, {"discretization.contact_elements": elements})
    the_plan = plan(case, half_width=HALF_WIDTH[case_name])
    body = case.bodies.A if not case.bodies.A.rigid else case.bodies.B
    inputs = bem_inputs(case, the_plan, body)
    grid = the_plan.grid
    shear = body.young / (2 * (1 + body.poisson))
    layer = body.kind == "layered"
    base_rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    clocks = [(time.perf_counter(), time.process_time())]
    largest = inputs["depth"] if layer else None
    mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"], largest=largest, far_field=not layer)
    from rolling_cli.influence.bem.farfield import far_field_values

    far = far_field_values(mesh, body.young, body.poisson, inputs["depth"])
    if hasattr(condense, "contact_blocks"):  # issue #14: systems assembled straight, mirror halves, LU in place
        from rolling_cli.influence.bem.symmetry import reductions
        from rolling_cli.influence.bem.system import mixed_systems

        parts = reductions(mesh, far, grid.weights)
        systems = mixed_systems(mesh, shear, body.poisson, far, parts)
        clocks.append((time.perf_counter(), time.process_time()))
        factors = [condense.factorise(system.matrix) for system in systems]
        clocks.append((time.perf_counter(), time.process_time()))
        solutions = [condense.solve(f, system.rhs, overwrite=True) for f, system in zip(factors, systems, strict=True)]
        del factors, systems
        condense.contact_blocks(solutions, parts, mesh, grid.weights)
    else:  # issue #10: dense H and G, then A, B, the LU of a copy
        from rolling_cli.influence.bem.assembly import assemble

        H, G = assemble(mesh, shear, body.poisson)
        clocks.append((time.perf_counter(), time.process_time()))
        prepared = condense.prepare(mesh, H, G, grid.weights, far)
        del H, G
        clocks.append((time.perf_counter(), time.process_time()))
        condense.contact_compliance(prepared, consume=True)
    clocks.append((time.perf_counter(), time.process_time()))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base_rss
    names = ("assembly", "factorisation", "condensation")
    out = {f"{name} wall": clocks[k + 1][0] - clocks[k][0] for k, name in enumerate(names)}
    out |= {f"{name} cpu": clocks[k + 1][1] - clocks[k][1] for k, name in enumerate(names)}
    out |= {"nodes": mesh.size, "peak MB": peak / 1024.0}
    return out


def whole(root: str, elements: int, case_name: str) -> dict:
    """``python -m rolling_cli -q solve --no-cache`` in a child process: wall seconds and peak RSS."""
    text = (Path(root) / "cases" / CASES[case_name]).read_text()
    text = text.replace('influence = "half-plane"', 'influence = "bem"')
    lines = text.split("\n")
    lines = [f"contact_elements = {elements}" if line.startswith("contact_elements") else line for line in lines]
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "case.toml"
        case.write_text("\n".join(lines) + "\n")
        env = dict(os.environ, PYTHONPATH=str(Path(root).resolve()))
        command = [sys.executable, "-m", "rolling_cli", "-q", "solve", "--no-cache", str(case)]
        command += ["-o", str(Path(tmp) / "r.h5")]
        start = time.perf_counter()
        child = subprocess.Popen(command, env=env, cwd=tmp)
        _, status, usage = os.wait4(child.pid, 0)
        seconds = time.perf_counter() - start
        if status != 0:
            raise RuntimeError(f"{command} failed with status {status}")
    return {"wall": seconds, "peak MB": usage.ru_maxrss / 1024.0}


def child(args) -> dict:
    command = [sys.executable, str(HERE), "--child", args.mode, "--roots", args.roots, "--elements", args.elements]
    command += ["--case", args.case]
    run = subprocess.run(command, capture_output=True, text=True, check=True)
    return json.loads(run.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--roots", default=str(HERE.parents[1]))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--elements", default="100,400")
    parser.add_argument("--mode", choices=("stages", "whole"), default="stages")
    parser.add_argument("--case", choices=tuple(CASES), default="similar")
    parser.add_argument("--child", choices=("stages", "whole"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child == "stages":
        print(json.dumps(stages(args.roots, int(args.elements), args.case)))
        return
    if args.child == "whole":
        print(json.dumps(whole(args.roots, int(args.elements), args.case)))
        return
    roots = args.roots.split(",")
    print(f"# bem_build_ab --mode {args.mode} --case {args.case}: roots {', '.join(roots)}; median of {args.repeat}")
    for n in (int(v) for v in args.elements.split(",")):
        runs = {root: [] for root in roots}
        for _ in range(args.repeat):
            for root in roots:  # interleaved
                one = argparse.Namespace(**{**vars(args), "roots": root, "elements": str(n)})
                runs[root].append(child(one))
        for root in roots:
            med = {key: statistics.median(r[key] for r in runs[root]) for key in runs[root][0]}
            if args.mode == "stages":
                names = ("assembly", "factorisation", "condensation")
                wall = sum(med[f"{name} wall"] for name in names)
                cpu = sum(med[f"{name} cpu"] for name in names)
                stage = " | ".join(f"{med[f'{name} wall']:.3f}" for name in names)
                print(
                    f"| {n} | {root} | {int(med['nodes'])} | {stage} | {wall:.3f} | {cpu:.3f} | {med['peak MB']:.0f} |",
                    flush=True,
                )
            else:
                print(f"| {n} | {root} | {med['wall']:.2f} | {med['peak MB']:.0f} |", flush=True)


if __name__ == "__main__":
    main()
