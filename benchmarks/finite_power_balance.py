"""Power balance of a viscoelastic finite roller on a rigid flat against a/R (issue 22, "Energy balance").

For each load of the shipped rubber roller (cases/rubber_roller_finite.toml: SLS cover 5 mm on a
rigid core, R = 25, nu = 0.49) and of a solid hollow roller (R = 10, bore 5, nu = 0.4), the speed
set so that V tau_c / a ~ 1 at the solved a, both free rolling (mu = 0) and driven
(Q/(mu P) = 0.3): the losses L = hysteresis (Michell's modal loss) + frictional power + xi Q, per
unit |V|, against three candidates for the rolling-resistance force (model/power_balance.py):

* M / R, the half-space's sgn(V) sum w p_n x / R;
* F_x - Q, the arc-frame resultant on the flat beyond the shaft torque R Q over R;
* F_rr, the same with the tractions at their displaced points (rolling_resistance_force).

    python benchmarks/finite_power_balance.py
"""

from __future__ import annotations

import copy
import sys
import tomllib
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _set(data: dict, **dotted) -> dict:
    out = copy.deepcopy(data)
    for key, value in dotted.items():
        *head, last = key.split(".")
        node = out
        for part in head:
            node = node.setdefault(part, {})
        if value is None:
            node.pop(last, None)
        else:
            node[last] = value
    return out


def _cover() -> dict:
    with open(ROOT / "cases" / "rubber_roller_finite.toml", "rb") as f:
        return tomllib.load(f)


def _hollow() -> dict:
    body = {"kind": "viscoelastic", "radius": 10.0, "young": 20.0, "relaxed_young": 10.0, "creep_time": 1.0,
            "poisson": 0.4, "shape": "cylinder", "inner_radius": 5.0}  # fmt: skip
    return {
        "bodies": {"A": body, "B": {"kind": "rigid", "radius": "inf"}},
        "friction": {"mu": 0.5},
        "normal": {"load": 1.0},
        "tangential": {"q_over_mu_p": 0.3},
        "rolling": {"direction": -1, "speed": 1.0},
        "discretization": {"element": "quadratic", "contact_elements": 60, "zone": 1.5},
    }


def row(data: dict, tau: float) -> dict:
    """Solve at V tau_c / a ~ 1 (one probe solve for a) and return the balance's terms."""
    first = solve(load_case(data))
    data = _set(data, **{"rolling.speed": float(first.contact_half_width) / tau})
    r = solve(load_case(data))
    radius = float(data["bodies"]["A"]["radius"])
    d = float(data["rolling"]["direction"])
    losses = r.hysteresis_power + r.frictional_power_total + r.creep * r.tangential_load
    return {
        "a/R": r.contact_half_width / radius,
        "L": losses,
        "M/R": r.rolling_resistance_moment / radius / losses - 1.0,
        "Fx-Q": d * (r.shaft_tangential_load - r.tangential_load) / losses - 1.0,
        "F_rr": r.rolling_resistance_force / losses - 1.0,
        "T_u/R": d * r.shaft_torque_displacement / radius / losses,
        "coef": r.rolling_resistance_coefficient,
    }


def main() -> None:
    print("| body | Q/(mu P) | a/R | losses L | M/R - L | (F_x - Q) - L | F_rr - L | -sgn(V) T_u/(R L) | F_rr/P |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, data, tau, loads in (
        ("cover", _cover(), 0.001, (1.5, 4.0, 10.0, 25.0, 60.0)),
        ("hollow", _hollow(), 1.0, (0.05, 0.2, 1.0, 3.0)),
    ):
        for ratio in (0.0, 0.3):
            for load in loads:
                extra = {"normal.load": load}
                if ratio == 0.0:
                    extra.update({"friction.mu": 0.0, "tangential.q_over_mu_p": None})
                else:
                    extra.update({"tangential.q_over_mu_p": ratio})
                out = row(_set(data, **extra), tau)
                print(
                    f"| {name} | {ratio:g} | {out['a/R']:.3f} | {out['L']:.4g} | {out['M/R']:+.2%} | "
                    f"{out['Fx-Q']:+.2%} | {out['F_rr']:+.3%} | {-out['T_u/R']:+.2%} | {out['coef']:.4g} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
