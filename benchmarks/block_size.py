"""The BEM half-space's truncation: which far-field condition, and how the answer depends on W.

Part 1, the choice (issue #10). One elastic body, 42 contact elements, meshes of
size W = D = 20, 50, 100, 200 a, five truncations:

* ``block``: the old model, bottom fixed and sides free (no far field);
* ``strain-correction``: the block, plus a correction of its uniform strain and
  rotation: the block's response to a unit resultant minus the closed-form
  half-plane's, fitted by a + b x over the zone and removed (rank 2);
* ``traction``: Flamant's tractions of the resultant on the sides, its
  displacement on the bottom;
* ``semicircle``: a semicircular truncation of radius W (straight chords),
  Flamant's displacement on it;
* ``displacement``: Flamant's displacement of the resultant on the sides and
  the bottom (the one rolling_cli uses).

Columns: max |d/dx (BEM - half-plane)| of the surface displacements under a
Hertz pressure p (S_nn p, S_tn p) and a shear q = -p (S_tt q, S_nt q) over the
contact, / max |d/dx S_nn p|; and the mean strain offsets over the contact: from
P (S_tn p, the creepage offset) and from Q (S_tt q), and the tilt from Q (S_nt q).

Part 2, full solves against the half-plane model on the same grid, W = D = 20 to
200 a: aluminium on steel (Q/(mu P) = 0.04 and 0.75, 100 and 400 elements) and
the issue's rigid cylinder on an incompressible flat (mu = 0.01 and 0.001,
Q/(mu P) = 0.5, 200 elements, coupling forced on so that the far field's
residual shows).

    python benchmarks/block_size.py [--part 1|2] [--sizes 20,50,100,200]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import rolling_cli  # noqa: E402
from rolling_cli.case import load_case, with_overrides  # noqa: E402
from rolling_cli.influence import bem, halfplane  # noqa: E402
from rolling_cli.influence.bem import farfield  # noqa: E402
from rolling_cli.influence.bem.mesh import BoundaryMesh, _Builder, _frozen, graded_edges  # noqa: E402
from rolling_cli.model.grid import ContactGrid  # noqa: E402
from rolling_cli.references import flamant, hertz  # noqa: E402

CASES = Path(__file__).resolve().parents[1] / "cases"
E = 2.0e5
VARIANTS = ("block", "strain-correction", "traction", "semicircle", "displacement")


def semicircle(radius: float, zone_edges: np.ndarray, growth: float = 1.4) -> BoundaryMesh:
    """The half-disc of ``radius`` below y = 0: the top face as the rectangle's, the arc as
    straight chords graded from the corners (each chord its own discontinuous element)."""
    h = float(zone_edges[1] - zone_edges[0])
    big = radius / 4.0
    b = _Builder([], [], [], [], [])
    top_corner = graded_edges(float(zone_edges[-1]), radius, h, growth, big)
    corner = float(top_corner[-1] - top_corner[-2])
    half = graded_edges(0.0, np.pi / 2, corner / radius, growth, big / radius)
    angles = np.concatenate([np.pi + half, 2 * np.pi - half[::-1][1:]])
    arc = []
    for a0, a1 in zip(angles[:-1], angles[1:], strict=True):
        arc += b.segment(radius * np.array([[np.cos(a0), np.sin(a0)], [np.cos(a1), np.sin(a1)]]), fixed=True)
    b.segment(np.column_stack([top_corner[::-1], np.zeros(top_corner.size)]), fixed=False)
    first = len(b.nodes)
    b.segment(np.column_stack([zone_edges[::-1], np.zeros(zone_edges.size)]), fixed=False, discontinuous=True)
    contact = np.arange(first, len(b.nodes))
    left = graded_edges(float(zone_edges[0]), -radius, h, growth, big)
    b.segment(np.column_stack([left, np.zeros(left.size)]), fixed=False)
    far = np.zeros(len(b.nodes), dtype=bool)
    far[arc] = True
    return b.mesh(far, contact)


def half_space_traction(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Flamant's traction per unit resultant, (n, 2 components, 2 force axes), block frame."""
    s = flamant.stress(points[:, 0], -points[:, 1])  # (n, (xx, zz, xz), (F_x, F_z))
    sxx, syy, sxy = s[:, 0], s[:, 1], -s[:, 2]
    t = np.stack(
        [sxx * normals[:, 0, None] + sxy * normals[:, 1, None], sxy * normals[:, 0, None] + syy * normals[:, 1, None]],
        1,
    )
    t[:, :, 1] *= -1.0  # force axis y = -z
    return t


def _compliance(mesh, grid, nu, values):
    return bem.condensed(mesh, grid, E, nu, far_values=values)


def variant(name: str, grid: ContactGrid, size: float, nu: float, hp):
    """The condensed compliance of one truncation variant, and its mesh."""
    zeros = lambda m: np.zeros((2 * m.size, 2))  # noqa: E731
    if name in ("block", "strain-correction"):
        mesh = bem.body_mesh(grid, size, size)
        c = _compliance(mesh, grid, nu, zeros(mesh))
        if name == "block":
            return c, mesh
        f = -hertz.pressure(grid.x, 1.0, 1.0)
        f = f / (grid.weights @ f)  # a unit resultant
        basis = np.vander(grid.x, 2)
        fixed = {}
        for block in ("S_nn", "S_tn", "S_nt", "S_tt"):
            diff = getattr(c, block) @ f - getattr(hp, block) @ f
            fit = basis @ np.linalg.lstsq(basis, diff, rcond=None)[0]
            fixed[block] = getattr(c, block) - np.outer(fit, grid.weights)
        return dataclasses.replace(c, **fixed), mesh
    if name == "traction":
        base = bem.body_mesh(grid, size, size)
        sides = np.abs(base.nodes[:, 0]) > size * (1 - 1e-9)
        mesh = dataclasses.replace(base, far=_frozen(sides | base.fixed))
        values = np.zeros((mesh.size, 2, 2))
        values[mesh.fixed] = farfield.half_space_displacement(mesh.nodes[mesh.fixed], E, nu, size)
        normals = np.column_stack([np.sign(mesh.nodes[sides, 0]), np.zeros(int(sides.sum()))])
        values[sides] = half_space_traction(mesh.nodes[sides], normals)
        return _compliance(mesh, grid, nu, values.reshape(-1, 2)), mesh
    mesh = semicircle(size, grid.edges) if name == "semicircle" else bem.body_mesh(grid, size, size, far_field=True)
    return _compliance(mesh, grid, nu, farfield.far_field_values(mesh, E, nu, size)), mesh


def part1(sizes):
    grid = ContactGrid(1.5, 42, 2)
    x = grid.x
    p = -hertz.pressure(x, 1.0, 1.0)
    q = -p
    inner = np.abs(x[:-1]) < 1.0

    def d(values):
        return (values[1:] - values[:-1]) / grid.spacing

    print(
        "| nu | truncation | W/a | BEM elements | S_nn p | S_tt q | S_tn p | S_nt q | "
        "strain offset from P | from Q | tilt from Q | time [s] |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for nu in (0.3, 0.5):
        hp = halfplane.body_compliance(grid, E, nu)
        scale = np.abs(d(hp.S_nn @ p)).max()
        for name in VARIANTS:
            for size in sizes:
                t = time.perf_counter()
                c, mesh = variant(name, grid, size, nu, hp)
                t = time.perf_counter() - t
                diff = {
                    b: (d(getattr(c, b) @ f) - d(getattr(hp, b) @ f))[inner] / scale
                    for b, f in (("S_nn", p), ("S_tt", q), ("S_tn", p), ("S_nt", q))
                }
                cells = " | ".join(f"{np.abs(diff[b]).max():.1e}" for b in ("S_nn", "S_tt", "S_tn", "S_nt"))
                print(
                    f"| {nu} | {name} | {size:g} | {mesh.elements} | {cells} | {diff['S_tn'].mean():+.1e} | "
                    f"{diff['S_tt'].mean():+.1e} | {diff['S_nt'].mean():+.1e} | {t:.2f} |",
                    flush=True,
                )


def part2(sizes):
    dissimilar = load_case(CASES / "dissimilar_q04.toml")
    rigid = with_overrides(
        load_case(CASES / "carter.toml"),
        {
            "bodies.A": {"kind": "rigid", "radius": 50.0},
            "bodies.B": {"kind": "elastic", "radius": float("inf"), "young": 1.0e4, "poisson": 0.5},
            "normal.load": 100.0,
            "tangential.q_over_mu_p": 0.5,
            "effects.coupling": "on",
        },
    )
    studies = [
        (
            f"aluminium on steel, Q/(mu P) = {q}, {n} el.",
            with_overrides(dissimilar, {"tangential.q_over_mu_p": q, "discretization.contact_elements": n}),
        )
        for n in (100, 400)
        for q in (0.04, 0.75)
    ] + [
        (f"rigid on nu = 0.5, mu = {mu}, coupling on", with_overrides(rigid, {"friction.mu": mu}))
        for mu in (0.01, 0.001)
    ]
    print("| case | W/a = D/a | creepage | / half-plane - 1 | max abs(p_t - p_t(half-plane)) / (mu p0) | time [s] |")
    print("|---|---:|---:|---:|---:|---:|")
    for label, case in studies:
        hp = rolling_cli.solve(with_overrides(case, {"discretization.influence": "half-plane"}))
        for size in sizes:
            block = {
                "discretization.influence": "bem",
                "discretization.block_width": size,
                "discretization.block_depth": size,
            }
            t = time.perf_counter()
            r = rolling_cli.solve(with_overrides(case, block), use_cache=False)
            dt = np.abs(r.p_t - hp.p_t).max() / (hp.mu * hp.hertz_p0)
            print(
                f"| {label} | {size:g} | {r.creep:.6e} | {r.creep / hp.creep - 1:+.1e} | {dt:.1e} | "
                f"{time.perf_counter() - t:.2f} |",
                flush=True,
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default="20,50,100,200")
    parser.add_argument("--part", default="1,2")
    args = parser.parse_args()
    sizes = [float(v) for v in args.sizes.split(",")]
    print(f"# block_size (truncation study), rolling_cli {rolling_cli.__version__}")
    if "1" in args.part:
        part1(sizes)
    if "2" in args.part:
        part2(sizes)


if __name__ == "__main__":
    main()
