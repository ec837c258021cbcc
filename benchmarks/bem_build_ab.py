"""Before/after timing of the BEM build: this checkout against another one (issue #10).

Times the stages of one BEM body of the paper's similar case (mesh + assembly,
factorisation with the load right-hand sides, condensation) in CPU seconds,
with the code of the checkout given by ``--root`` (for example an export of
the commit before issue #10: ``git archive f9479a3 | tar -x -C /tmp/before``).
Run it for both roots, alternately, with BLAS single-threaded
(``OPENBLAS_NUM_THREADS=1``) so that a shared machine's load distorts less:

    python benchmarks/bem_build_ab.py --root /tmp/before
    python benchmarks/bem_build_ab.py --root .
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=str(Path(__file__).resolve().parents[1]))
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--elements", default="21,80,160,320")
    args = parser.parse_args()
    sys.path.insert(0, str(Path(args.root).resolve()))
    from rolling_cli import pipeline
    from rolling_cli.case import load_case, with_overrides
    from rolling_cli.influence import bem
    from rolling_cli.influence.bem import condense
    from rolling_cli.influence.bem.assembly import assemble
    from rolling_cli.influence.build import bem_inputs

    def plan(case, use_cache):  # the measured plan: pipeline.measured_plan after issue #9
        measured = getattr(pipeline, "measured_plan", None)
        return measured(case, use_cache) if measured else pipeline.plan(case, use_cache=use_cache)

    half_space = hasattr(bem, "prepare_body")  # after issue #10: the far-field half-space
    base = load_case(Path(args.root) / "cases" / "paper_fig3_q051.toml")
    print(f"# bem_build_ab: {Path(args.root).resolve()} ({'half-space' if half_space else 'block'})")
    print("| contact elements | BEM nodes | mesh + assembly [s] | factorisation [s] | condensation [s] | total [s] |")
    print("|---:|---:|---:|---:|---:|---:|")
    for n in (int(v) for v in args.elements.split(",")):
        case = with_overrides(base, {"discretization.contact_elements": n})
        the_plan = plan(case, use_cache=False)
        body = case.bodies.A
        inputs = bem_inputs(case, the_plan, body)
        grid = the_plan.grid
        shear = body.young / (2 * (1 + body.poisson))
        runs = []
        for _ in range(args.repeat):
            t0 = time.process_time()
            if half_space:
                from rolling_cli.influence.bem.farfield import far_field_values

                mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"], far_field=True)
                H, G = assemble(mesh, shear, body.poisson)
                t1 = time.process_time()
                far = far_field_values(mesh, body.young, body.poisson, inputs["depth"])
                prepared = condense.prepare(mesh, H, G, grid.weights, far)
                t2 = time.process_time()
                condense.contact_compliance(prepared, consume=True)
            else:
                mesh = bem.body_mesh(grid, inputs["half_width"], inputs["depth"])
                H, G = assemble(mesh, shear, body.poisson)
                t1 = time.process_time()
                A, B = condense.boundary_system(mesh, H, G)
                lu = condense.factorise(A)
                t2 = time.process_time()
                condense.unit_load_responses(lu, B, condense.contact_dofs(mesh))
            t3 = time.process_time()
            runs.append((t1 - t0, t2 - t1, t3 - t2, t3 - t0))
        med = [statistics.median(r[k] for r in runs) for k in range(4)]
        print(f"| {n} | {mesh.size} | {med[0]:.3f} | {med[1]:.3f} | {med[2]:.3f} | {med[3]:.3f} |", flush=True)


if __name__ == "__main__":
    main()
