"""README figure of the viscoelastic cover (issue 22): rolling resistance against speed for covers.

Hunter's roller (a rigid cylinder, R = 50, P = 1, frictionless) on a standard linear solid
(E_g = 2 E_r = 20, nu = 0.5, tau_c = 0.01) that is a half-plane or a cover of thickness
b = 0.1 a_r and 1 a_r bonded to a rigid core (a_r the relaxed Hertz half-width of the half-plane):
the rolling-resistance coefficient M / (P R) against V tau_c / a_r, the solver's points (60
quadratic elements) over the Fourier-space complex-modulus references
(:mod:`rolling_cli.references.hunter`, with the layer's normal compliance for the covers).
A thin cover is stiffer (a narrower contact) and loses less, with its peak at a smaller
V tau_c / a_r. Right: the shipped driven rubber cover (``cases/rubber_cover.toml``): its
rolling-resistance coefficient and its overfeed (creepage at the given Q) against the speed.

    python benchmarks/fig_viscoelastic_layer.py     # writes benchmarks/results/viscoelastic_layer.png
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402
from rolling_cli.references import hertz, hunter  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
A_R = hertz.half_width(1.0, 50.0, 10.0 / 0.75)
MATERIAL = {"radius": "inf", "young": 20.0, "relaxed_young": 10.0, "creep_time": 0.01, "poisson": 0.5}


def case(ratio: float, thickness: float | None) -> dict:
    """Hunter's roller at V tau_c / a_r = ratio on the half-plane (thickness None) or a cover."""
    body = {"kind": "viscoelastic", **MATERIAL}
    if thickness is not None:
        body = {"kind": "layered", "viscoelastic": True, "layer_thickness": thickness * A_R, **MATERIAL}
    return {
        "bodies": {"A": {"kind": "rigid", "radius": 50.0}, "B": body},
        "friction": {"mu": 0.0},
        "normal": {"load": 1.0},
        "rolling": {"speed": ratio * A_R / 0.01, "direction": -1},
        "discretization": {"element": "quadratic", "contact_elements": 60, "zone": 1.5},
    }


def curve(thickness: float | None, ratios: np.ndarray) -> np.ndarray:
    """M / (P R) of the solver at the ``ratios``."""
    return np.array([float(solve(load_case(case(r, thickness))).rolling_resistance_coefficient) for r in ratios])


def reference(thickness: float | None, ratios: np.ndarray) -> list[float]:
    """The Fourier complex-modulus reference (references.hunter, with the layer's normal compliance
    for a cover; 40 cells per a_r, 120 for the thin cover)."""
    cells = 120 if thickness is not None and thickness < 0.5 else 40
    layer = None if thickness is None else thickness * A_R
    return [
        hunter.rolling_resistance(1.0, 50.0, 20.0, 10.0, 0.01, 0.5, r * A_R / 0.01, -1, cells, thickness=layer)
        for r in ratios
    ]


def cover_speed_curve() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(speeds, M / (P R*), creepage) of the shipped driven rubber cover (``cases/rubber_cover.toml``,
    Q/(mu P) = 0.3) against the rolling speed."""
    from rolling_cli.case.io import with_overrides

    base = load_case(ROOT / "cases" / "rubber_cover.toml")
    speeds = np.logspace(2, 5, 16)
    coefficient, creep = [], []
    for speed in speeds:
        r = solve(with_overrides(base, {"rolling.speed": float(speed)}))
        coefficient.append(float(r.rolling_resistance_coefficient))
        creep.append(float(r.creep))
    return speeds, np.array(coefficient), np.array(creep)


def main() -> None:
    ratios = np.logspace(-2, 2, 13)
    fine = np.logspace(-2, 2, 33)
    fig, (ax, right) = plt.subplots(1, 2, figsize=(12.0, 4.4))
    for (thickness, marker), colour in zip(((None, "o"), (1.0, "s"), (0.1, "^")), ("C0", "C1", "C2"), strict=True):
        values = curve(thickness, ratios)
        label = "half-plane" if thickness is None else f"cover b = {thickness:g} a_r"
        ax.semilogx(fine, reference(thickness, fine), "-", color=colour, alpha=0.5, lw=1.5)
        ax.semilogx(ratios, values, marker, color=colour, label=f"rollc, {label}")
        print(label, " ".join(f"{v:.4g}" for v in values))
    ax.plot([], [], "-", color="0.5", label="Fourier complex-modulus references")
    ax.set_xlabel("V tau_c / a_r")
    ax.set_ylabel("M / (P R)")
    ax.set_title("Rigid roller on SLS covers (E_g = 2 E_r, nu = 0.5)")
    ax.legend(fontsize=8, loc="upper left")
    speeds, coefficient, creep = cover_speed_curve()
    right.semilogx(speeds, coefficient, "o-", label="M / (P R*)")
    right.set_xlabel("rolling speed |V| [mm/s]")
    right.set_ylabel("M / (P R*)")
    twin = right.twinx()
    twin.semilogx(speeds, -creep, "s--", color="C3", label="overfeed -xi")
    twin.set_ylabel("overfeed -xi at Q/(mu P) = 0.3")
    right.set_title("cases/rubber_cover.toml: 5 mm SLS cover, E_g = 3 E_r, driven")
    lines = right.get_legend_handles_labels()[0] + twin.get_legend_handles_labels()[0]
    right.legend(lines, [line.get_label() for line in lines], fontsize=8, loc="center left")
    print("cover speeds", " ".join(f"{v:.4g}" for v in coefficient), "|", " ".join(f"{v:.4g}" for v in creep))
    fig.tight_layout()
    out = ROOT / "benchmarks" / "results" / "viscoelastic_layer.png"
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()
