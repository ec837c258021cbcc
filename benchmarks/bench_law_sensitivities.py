"""Sensitivities with a slip-speed friction law (issue 24 item 1): accuracy and cost.

Part 1, accuracy: cases/falling_exponential.toml at 100 elements on both branches of its
creep-force curve (Q/(mu_s P) = 0.5 rising, 0.65 falling), its law on dissimilar bodies, and
an overlap-controlled dissimilar case, each under creepage and force control: every recorded
derivative against a central difference of re-solves (relative step 1e-6,
tests/test_law_sensitivities.py's helpers). Prints the largest relative error per case.

Part 2, cost: ``time_sensitivities`` (assembly of the velocity system and one dense LU for the
three columns) against ``time_solve``, medians of ``--repeat`` in-process solves, at 100 to 800
elements, both controls.

    python benchmarks/bench_law_sensitivities.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from test_law_sensitivities import CASE, _base, _differences, _dissimilar  # noqa: E402

import rolling_cli  # noqa: E402
from helpers import case_dict  # noqa: E402
from rolling_cli.case import load_case  # noqa: E402


def accuracy() -> None:
    """Part 1 (module docstring)."""
    overlap = case_dict(_dissimilar(), **{"normal.overlap": 0.01, "solver.branch": None, "tangential.creep": -0.002})
    cases = [
        ("rising", _base("low-slip")),
        ("falling", _base("high-slip")),
        ("dissimilar", _dissimilar()),
    ]
    print("| case | control | derivatives | largest relative error | node states changed |")
    print("|---|---|---|---:|---|")
    runs = [(name, data, force) for name, data in cases for force in (False, True)] + [("overlap", overlap, False)]
    for name, data, force in runs:
        base, found = _differences(data, force)
        errors = {
            key: abs(getattr(base, key) - d) / max(abs(getattr(base, key)), 0.1 * scale)
            for key, (d, scale, _) in found.items()
        }
        changed = any(c for _, _, c in found.values())
        control = "force" if force else "creep"
        print(f"| {name} | {control} | {', '.join(sorted(found))} | {max(errors.values()):.1e} | {changed} |")


def cost(repeat: int) -> None:
    """Part 2 (module docstring)."""
    data = tomllib.loads(CASE.read_text())
    print("| elements | control | sensitivities [ms] | solve [ms] | share |")
    print("|---:|---|---:|---:|---:|")
    for n in (100, 200, 400, 800):
        for control in ({}, {"tangential.creep": -0.0019}):
            case = load_case(case_dict(data, **{"discretization.contact_elements": n}, **control))
            results = [rolling_cli.solve(case) for _ in range(repeat)]
            sens = statistics.median(r.time_sensitivities for r in results)
            solve = statistics.median(r.time_solve for r in results)
            name = "creep" if control else "force"
            print(f"| {n} | {name} | {1e3 * sens:.1f} | {1e3 * solve:.1f} | {100 * sens / solve:.0f} % |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    logging.disable(logging.WARNING)
    accuracy()
    cost(args.repeat)


if __name__ == "__main__":
    main()
