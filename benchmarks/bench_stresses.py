"""Subsurface stress fields: time to compute them after a solve (issue #12 targets).

Targets: a 201 x 101 field for a 200-element half-plane case in <= 0.5 s; the
BEM layer field in <= 2 s. Each row solves the case once (not timed), then
times the stress stage alone, median of ``--repeat`` runs, BLAS
single-threaded; CPU seconds are given beside the wall seconds because the
machine may be shared.

    python benchmarks/bench_stresses.py [--repeat 5]

Rows: the half-plane field of one body (the integrals, then the invariants),
both bodies of the Carter case (they share the integrals), the BEM layer of the
paper's Fig. 11 case (boundary solve: H, G, one LU; then the Somigliana
field), and the BEM half-space block of the Carter case (200 elements).
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

import numpy as np

from rolling_cli import blas, pipeline
from rolling_cli.case import load_case
from rolling_cli.case.schema import Stresses
from rolling_cli.influence import build
from rolling_cli.model import materials
from rolling_cli.stresses import bem, compute, halfplane

CASES = Path(__file__).resolve().parents[1] / "cases"


def timed(repeat: int, function, *args) -> tuple[float, float, object]:
    """Median wall and CPU seconds of ``function(*args)`` and its last value."""
    walls, cpus = [], []
    value = None
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        value = function(*args)
        walls.append(time.perf_counter() - w0)
        cpus.append(time.process_time() - c0)
    return statistics.median(walls), statistics.median(cpus), value


def prepared(name: str, **discretization):
    case = load_case(CASES / name)
    if discretization:
        case = dataclasses.replace(case, discretization=dataclasses.replace(case.discretization, **discretization))
    case = dataclasses.replace(case, stresses=Stresses())
    result = pipeline.solve(dataclasses.replace(case, stresses=None))
    return case, pipeline.plan(case), result


def boundary_solve(case, the_plan, result):
    """Body B's boundary solution from the influence model, factorised anew (the memo cleared)."""
    build.clear_memo()
    return build.boundary_solution(case, the_plan, "B", result.p_n, result.p_t)


def rows(repeat: int) -> list[tuple]:
    out = []
    for elements in (100, 200, 400):
        case, the_plan, result = prepared("carter.toml", contact_elements=elements)
        x, z = compute.field_grid(case, the_plan, "A")
        wall, cpu, fields = timed(repeat, halfplane.field, the_plan.grid, result.p_n, result.p_t, x, z)
        out.append((f"half-plane, Carter, {elements} elements: integrals, one body", len(x), len(z), wall, cpu))
        if elements == 200:
            wall, cpu, _ = timed(repeat, compute.derived, *fields, 0.3)
            out.append(("half-plane: invariants of one body", len(x), len(z), wall, cpu))
            wall, cpu, _ = timed(repeat, compute.compute_stresses, case, the_plan, result.p_n, result.p_t)
            out.append(("half-plane, Carter, 200 elements: both bodies, all fields", len(x), len(z), wall, cpu))
    for name, label in (("tyred_fig11_q41.toml", "BEM layer, Fig. 11, 100 elements"), ("carter.toml", "BEM block")):
        extra = {"influence": "bem"} if label == "BEM block" else {}
        case, the_plan, result = prepared(name, **extra)
        if label == "BEM block":
            label = f"BEM block, Carter, {the_plan.grid.elements} elements"
        body = case.bodies.B
        wall, cpu, (mesh, u, t) = timed(repeat, boundary_solve, case, the_plan, result)
        out.append((f"{label}: boundary solve ({mesh.elements} BEM elements)", 0, 0, wall, cpu))
        x, z = compute.field_grid(case, the_plan, "B")
        X, Z = np.meshgrid(x, z)
        points = np.stack([X.ravel(), -Z.ravel()], axis=1)
        shear = materials.shear_modulus(body.young, body.poisson)
        wall, cpu, _ = timed(repeat, bem.stresses, mesh, u, t, shear, body.poisson, points)
        out.append((f"{label}: Somigliana field", len(x), len(z), wall, cpu))
        wall, cpu, _ = timed(repeat, compute.compute_stresses, case, the_plan, result.p_n, result.p_t)
        bodies = "both bodies" if label.startswith("BEM block") else "the layer"
        out.append((f"{label}: {bodies}, all fields (solve included)", len(x), len(z), wall, cpu))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    with blas.single_threaded():
        table = rows(args.repeat)
    print(f"| stage | nx | nz | wall [s] (median of {args.repeat}) | CPU [s] |")
    print("|---|---:|---:|---:|---:|")
    for label, nx, nz, wall, cpu in table:
        print(f"| {label} | {nx or '-'} | {nz or '-'} | {wall:.3f} | {cpu:.3f} |")


if __name__ == "__main__":
    main()
