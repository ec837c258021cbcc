"""BEM timings: mesh, assembly, factorisation, condensation and the Newton solve.

For the paper's similar case (R = 100 mm, overlap 0.015 mm, Q/(mu P) = 0.51,
half-spaces truncated at the default 100 a with the far-field condition), 21
to 320 contact elements. The influence cache is off, so every stage is really
computed; each time is the median of ``--repeat`` runs. "assembly" is the
far-field values and the boundary systems with their right-hand sides
(the body's two mirror halves), "factorisation" their LUs, "condensation"
the solves and the compliance blocks.

    python benchmarks/bench_bem.py [--repeat 3] [--elements 21,40,80,160,320]
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
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence import bem  # noqa: E402
from rolling_cli.influence.bem.condense import contact_blocks, factorise, solve  # noqa: E402
from rolling_cli.influence.bem.farfield import far_field_values  # noqa: E402
from rolling_cli.influence.bem.symmetry import reductions  # noqa: E402
from rolling_cli.influence.bem.system import mixed_systems  # noqa: E402
from rolling_cli.influence.build import bem_inputs, clear_memo  # noqa: E402
from rolling_cli.pipeline import measured_plan  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "cases" / "paper_fig3_q051.toml"


def stages(case):
    """Seconds per stage for one BEM body, then the full solve."""
    the_plan = measured_plan(case, use_cache=False)
    body = case.bodies.A if not case.bodies.A.rigid else case.bodies.B  # the first meshed body
    inputs = bem_inputs(case, the_plan, body)
    grid = the_plan.grid
    out = {}
    t = time.perf_counter()
    layer = body.kind == "layered"
    largest = inputs["depth"] if layer else None
    mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"], largest=largest, far_field=not layer)
    out["mesh"] = time.perf_counter() - t
    shear = body.young / (2 * (1 + body.poisson))
    t = time.perf_counter()
    far = far_field_values(mesh, body.young, body.poisson, inputs["depth"])  # zero on a layer (no far nodes)
    parts = reductions(mesh, far, grid.weights)
    systems = mixed_systems(mesh, shear, body.poisson, far, parts)
    out["assembly"] = time.perf_counter() - t
    t = time.perf_counter()
    factors = [factorise(system.matrix) for system in systems]
    out["factorisation"] = time.perf_counter() - t
    t = time.perf_counter()
    solutions = [solve(f, system.rhs, overwrite=True) for f, system in zip(factors, systems, strict=True)]
    del factors, systems
    contact_blocks(solutions, parts, mesh, grid.weights)
    out["condensation"] = time.perf_counter() - t
    clear_memo()
    t = time.perf_counter()
    result = rolling_cli.solve(case, use_cache=False)
    out["full solve"] = time.perf_counter() - t
    out["newton"] = result.time_solve
    return mesh, out, result


def main(case_file: Path = CASE, elements: str = "21,40,80,160,320", name: str = "bench_bem") -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--elements", default=elements)
    args = parser.parse_args()
    base = load_case(case_file)
    print(f"# {name}: {platform.node()}, python {platform.python_version()}, rolling_cli {rolling_cli.__version__}")
    print(
        "| contact elements | BEM elements | BEM nodes | mesh [s] | assembly [s] | factorisation [s] | "
        "condensation [s] | assembly + condensation [s] | Newton [s] | iterations | full solve [s] |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in (int(v) for v in args.elements.split(",")):
        case = with_overrides(base, {"discretization.contact_elements": n})
        runs = [stages(case) for _ in range(args.repeat)]
        mesh, result = runs[-1][0], runs[-1][2]
        med = {k: statistics.median(r[1][k] for r in runs) for k in runs[0][1]}
        build = med["assembly"] + med["factorisation"] + med["condensation"]
        print(
            f"| {n} | {mesh.elements} | {mesh.size} | {med['mesh']:.3f} | {med['assembly']:.3f} | "
            f"{med['factorisation']:.3f} | {med['condensation']:.3f} | {build:.3f} | {med['newton']:.3f} | "
            f"{result.iterations} | {med['full solve']:.3f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
