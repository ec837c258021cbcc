"""README figure of viscoelastic rolling (issue 22): rolling resistance and overfeed against speed.

Left: the rolling-resistance coefficient M / (P R) of a rigid roller on a standard-linear-solid
half-plane (Hunter's problem, E_g = 2 E_r, nu = 0.5, frictionless) against V tau_c / a_r, the
solver's points over the Fourier-space complex-modulus reference curve
(:mod:`rolling_cli.references.hunter`). Right: the shipped driven rubber roller
(``cases/rubber_roller.toml``, Q/(mu P) = 0.3): its rolling-resistance coefficient and its
creepage (overfeed) against the rolling speed.

    python benchmarks/fig_viscoelastic.py     # writes benchmarks/results/viscoelastic.png
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.case.io import with_overrides  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402
from rolling_cli.references import hertz, hunter  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
ROLLER = {
    "bodies": {
        "A": {"kind": "rigid", "radius": 50.0},
        "B": {"kind": "viscoelastic", "radius": "inf", "young": 20.0, "relaxed_young": 10.0,
              "creep_time": 0.01, "poisson": 0.5},
    },
    "friction": {"mu": 0.0},
    "normal": {"load": 1.0},
    "rolling": {"speed": 100.0},
    "discretization": {"element": "constant", "contact_elements": 200, "zone": 1.5},
}  # fmt: skip


def hunter_curve():
    """(V tau / a_r, solver M/(PR), reference M/(PR)) of Hunter's problem."""
    a = hertz.half_width(1.0, 50.0, 10.0 / 0.75)
    ratios = np.logspace(-2, 2, 17)
    fine = np.logspace(-2, 2, 61)
    solver = []
    for ratio in ratios:
        data = copy.deepcopy(ROLLER)
        data["rolling"]["speed"] = float(ratio * a / 0.01)
        solver.append(float(solve(load_case(data)).rolling_resistance_coefficient))
    reference = [hunter.rolling_resistance(1.0, 50.0, 20.0, 10.0, 0.01, 0.5, r * a / 0.01, -1, 40) for r in fine]
    return ratios, np.array(solver), fine, np.array(reference)


def roller_speed_curve():
    """(speeds, M/(P R*), creepage) of the shipped rubber roller."""
    base = load_case(ROOT / "cases" / "rubber_roller.toml")
    speeds = np.logspace(2, 5, 16)
    coefficient, creep = [], []
    for speed in speeds:
        r = solve(with_overrides(base, {"rolling.speed": float(speed)}))
        coefficient.append(float(r.rolling_resistance_coefficient))
        creep.append(float(r.creep))
    return speeds, np.array(coefficient), np.array(creep)


def main() -> None:
    ratios, solver, fine, reference = hunter_curve()
    speeds, coefficient, creep = roller_speed_curve()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    left.semilogx(fine, reference, "-", color="0.5", label="Fourier complex-modulus reference")
    left.semilogx(ratios, solver, "o", label="rollc (200 constant elements)")
    left.set_xlabel("V tau_c / a_r")
    left.set_ylabel("M / (P R)")
    left.set_title("Rigid roller on an SLS half-plane (E_g = 2 E_r)")
    left.legend(loc="upper left", fontsize="small")
    right.semilogx(speeds, coefficient, "o-", label="M / (P R*)")
    right.set_xlabel("rolling speed |V| [mm/s]")
    right.set_ylabel("M / (P R*)")
    twin = right.twinx()
    twin.semilogx(speeds, -creep * 1e3, "s--", color="C1", label="overfeed -xi [1e-3]")
    twin.set_ylabel("overfeed -xi [1e-3]")
    right.set_title("cases/rubber_roller.toml (Q/(mu P) = 0.3)")
    lines = right.get_legend_handles_labels()
    extra = twin.get_legend_handles_labels()
    right.legend(lines[0] + extra[0], lines[1] + extra[1], loc="upper left")
    fig.tight_layout()
    out = ROOT / "benchmarks" / "results" / "viscoelastic.png"
    fig.savefig(out, dpi=110)
    print(f"written {out}")


if __name__ == "__main__":
    main()
