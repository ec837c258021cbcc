"""The a-estimate levels of thin layers with and without the skip of a repeating level (issue 22).

Random covers on the paper's Fig. 11 tyre (R = 100 rigid on R = 100 layered; b in 0.03..0.4 with
a ~ 0.5..1.5, nu in {0.3, 0.45, 0.5}, overlap or load control, elastic or SLS with E_g / E_r in
1.5..10 and V tau_c / a in 0.1..10): the measured half-width with the skip
(:func:`rolling_cli.pipeline.planning.repeats_estimate`: the first level's width kept) against the
path that runs the second level; where the two differ,
the per-case outputs (creepage, peak pressure, load, overlap, rolling resistance: the largest
relative change) against each other and against the discretisation error (the same outputs against
the same case on twice the elements). Cases on 60 elements, or on the fewest the layer rule allows
on either path. CPU: the median of 3 solves, the BEM layer from the disk cache.

    python benchmarks/scan_estimate_skip.py [--seed 1] [--cases 40]
"""

from __future__ import annotations

import argparse
import copy
import re
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.errors import CaseError  # noqa: E402
from rolling_cli.influence import build, viscoelastic  # noqa: E402
from rolling_cli.pipeline import mesh_path, solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _random_case(rng: np.random.Generator) -> dict:
    with open(ROOT / "cases" / "tyred_fig11_q41.toml", "rb") as handle:
        data = tomllib.load(handle)
    body = data["bodies"]["B"]
    body["layer_thickness"] = float(np.exp(rng.uniform(np.log(0.03), np.log(0.4))))
    body["poisson"] = float(rng.choice([0.3, 0.45, 0.5]))
    if rng.random() < 0.5:
        data["normal"] = {"overlap": float(np.exp(rng.uniform(np.log(0.001), np.log(0.01))))}
    else:
        data["normal"] = {"load": float(np.exp(rng.uniform(np.log(0.05), np.log(1.0))))}
    if rng.random() < 0.7:
        ratio = float(np.exp(rng.uniform(np.log(1.5), np.log(10.0))))
        body.update(viscoelastic=True, relaxed_young=body["young"], young=ratio * body["young"], creep_time=1.0)
        data["rolling"]["speed"] = float(np.exp(rng.uniform(np.log(0.1), np.log(10.0))))
    data["discretization"]["contact_elements"] = 60
    return data


def _solve(data: dict, skip: bool, repeat: int = 3):
    """(result, a-estimate levels, median CPU [s] of ``repeat`` solves with the influence memos
    cleared and the BEM layers from the disk cache, after one solve that fills it)."""
    original, presolve = mesh_path.repeats_estimate, mesh_path.presolve_case
    levels = []

    def counted(*args):
        levels.append(args)
        return presolve(*args)

    if not skip:
        mesh_path.repeats_estimate = lambda *args: False
    mesh_path.presolve_case = counted
    try:
        times = []
        for _ in range(repeat + 1):
            build.clear_memo()
            viscoelastic.clear_memo()
            mesh_path._estimates.clear()
            levels.clear()
            t0 = time.process_time()
            result = solve(load_case(copy.deepcopy(data)))
            times.append(time.process_time() - t0)
        return result, len(levels), float(np.median(times[1:]))
    finally:
        mesh_path.repeats_estimate, mesh_path.presolve_case = original, presolve


def _scalars(a, b) -> float:
    """Largest relative difference of the per-case outputs: creepage, peak pressure, load and overlap,
    the rolling resistance (a cover) [-]."""
    pairs = [(a.creep, b.creep), (-a.p_n.min(), -b.p_n.min()), (a.normal_load, b.normal_load)]
    pairs += [(a.overlap, b.overlap)]
    if getattr(b, "rolling_resistance_coefficient", None):
        pairs.append((a.rolling_resistance_coefficient, b.rolling_resistance_coefficient))
    return max(abs(float(u) / float(v) - 1.0) for u, v in pairs)


def _allowed(data: dict) -> dict:
    """``data`` with at least the contact elements the layer rule asks for, on either path (the
    thin-layer estimate first, then each path's measured contact scale)."""
    original = mesh_path.repeats_estimate
    for skip in (True, False, True, False):
        if not skip:
            mesh_path.repeats_estimate = lambda *args: False
        try:
            mesh_path._estimates.clear()
            mesh_path.measured_plan(load_case(copy.deepcopy(data)))
        except CaseError as err:
            found = re.search(r">= (\d+) elements", str(err))
            if found is None:
                raise
            data["discretization"]["contact_elements"] = int(found.group(1))
        finally:
            mesh_path.repeats_estimate = original
    return data


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cases", type=int, default=40)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print("| b | nu | control | visco | a (skip) | a (2 levels) | levels | output change | disc. error | CPU ratio |")
    print("|---:|---:|---|---|---:|---:|---:|---:|---:|---:|")
    for _ in range(args.cases):
        data = _random_case(rng)
        try:
            data = _allowed(data)
            old, levels_old, t_old = _solve(data, False)
            new, levels_new, t_new = _solve(data, True)
        except Exception as err:  # noqa: BLE001 - a scan reports every failure
            print(f"| failed: {err} |")
            continue
        body = data["bodies"]["B"]
        same = np.array_equal(new.x, old.x)
        diff = _scalars(new, old)
        error = ""
        if not same:
            fine_data = copy.deepcopy(data)
            fine_data["discretization"]["contact_elements"] *= 2
            error = f"{_scalars(old, _solve(fine_data, False, repeat=0)[0]):.1e}"
        print(
            f"| {body['layer_thickness']:.3f} | {body['poisson']} | {next(iter(data['normal']))} "
            f"| {'SLS' if body.get('viscoelastic') else '-'} | {new.x[-1] / 1.5:.5f} | {old.x[-1] / 1.5:.5f} "
            f"| {levels_old} -> {levels_new}, {'same grid' if same else 'other grid'} | {diff:.1e} | {error} "
            f"| {t_new / t_old:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
