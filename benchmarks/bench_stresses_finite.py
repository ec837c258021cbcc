"""Subsurface stresses of finite cylinders (issue 21 item 5): cost of the stress stage, and the
convergence of the curved-element Somigliana identity against Michell's series.

Part 1, cost: each row solves a finite case once (not timed), then times the stress stage alone
(:func:`rolling_cli.stresses.compute.compute_stresses`: the annulus' boundary solve, factorised anew,
and the 201 x 101 field with the surface samples), median of ``--repeat`` runs, BLAS single-threaded;
CPU seconds beside the wall seconds (the machine may be shared).

Part 2, convergence: exact boundary data of Michell's series (a smooth load, modes 0-8) on uniform
curved meshes of n elements per circle (R = 1, r_i = 0.6), the largest error of the identity over 200
interior points and points 1e-2, 1e-4 and 1e-6 element lengths inside the mesh's boundary.

    python benchmarks/bench_stresses_finite.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from rolling_cli import blas, pipeline  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence import build  # noqa: E402
from rolling_cli.stresses import compute  # noqa: E402

ROLLERS = {
    "covered roller (R 5, cover 1, nu 0.45), a/R ~ 0.2": {
        "kind": "layered", "radius": 5.0, "young": 10.0, "poisson": 0.45, "layer_thickness": 1.0, "shape": "cylinder",
    },
    "hollow roller (R 10, bore 4, nu 0.3), a/R ~ 0.1": {
        "kind": "elastic", "radius": 10.0, "young": 1000.0, "poisson": 0.3, "shape": "cylinder", "inner_radius": 4.0,
    },
}  # fmt: skip
LOADS = {
    "covered roller (R 5, cover 1, nu 0.45), a/R ~ 0.2": 3.3,
    "hollow roller (R 10, bore 4, nu 0.3), a/R ~ 0.1": 20.0,
}


def timed(repeat: int, function, *args) -> tuple[float, float]:
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        function(*args)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus)


def cost_rows(repeat: int) -> list[tuple]:
    out = []
    for label, body in ROLLERS.items():
        for elements in (100, 200):
            data = {
                "title": label,
                "bodies": {"A": body, "B": {"kind": "rigid", "radius": float("inf")}},
                "friction": {"mu": 0.5},
                "normal": {"load": LOADS[label]},
                "tangential": {"q_over_mu_p": 0.5},
                "rolling": {"direction": -1},
                "discretization": {"contact_elements": elements},
                "stresses": {},
            }
            case = load_case(data)
            result = pipeline.solve(case)
            the_plan = pipeline.plan(case, half_width=result.mesh_half_width)

            def stage(case=case, the_plan=the_plan, result=result):
                build.clear_memo()
                compute.compute_stresses(case, the_plan, result.p_n, result.p_t)

            wall, cpu = timed(repeat, stage)
            out.append((f"{label}, {elements} elements", wall, cpu))
    return out


def convergence_rows() -> list[tuple]:
    from test_stresses_bem import node_normals
    from test_stresses_finite import NU, G, _michell_state, _uniform_annulus

    from rolling_cli.influence.bem.elements import map_points
    from rolling_cli.stresses import curved

    radius, inner = 1.0, 0.6
    n = np.arange(9)
    S, T = np.exp(0.3j * n) / (1.0 + n) ** 2, 0.5 * np.exp(-0.7j * n) / (1.0 + n) ** 2
    state = _michell_state(S, T, radius, inner)
    rng = np.random.default_rng(1)
    r, theta = inner + (radius - inner) * rng.random(200), 2.0 * np.pi * rng.random(200)
    inside = np.column_stack([r * np.sin(theta), -radius + r * np.cos(theta)])
    out = []
    for count in (16, 32, 64, 128, 256):
        mesh = _uniform_annulus(radius, inner, count)
        h = 2.0 * np.pi * radius / count
        on, normal, _ = map_points(mesh.geometry[::3], np.array([0.37]))
        near = np.concatenate([on[:, 0] - d * h * normal[:, 0] for d in (1e-2, 1e-4, 1e-6)])
        sigma, u = state(mesh.nodes)
        normals = node_normals(mesh)
        t = np.stack(
            [sigma[0] * normals[:, 0] + sigma[2] * normals[:, 1], sigma[2] * normals[:, 0] + sigma[1] * normals[:, 1]],
            1,
        )
        errors = [np.abs(curved.stresses(mesh, u, t, G, NU, p) - state(p)[0]).max() for p in (inside, near)]
        out.append((count, *errors))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    blas.settle()
    print("| finite cylinder, 201 x 101 field | wall s | CPU s |")
    print("|---|---|---|")
    for label, wall, cpu in cost_rows(args.repeat):
        print(f"| {label} | {wall:.3f} | {cpu:.3f} |")
    print()
    print("| elements per circle | error inside / load | error near the boundary / load |")
    print("|---|---|---|")
    for count, inside, near in convergence_rows():
        print(f"| {count} | {inside:.2e} | {near:.2e} |")


if __name__ == "__main__":
    main()
