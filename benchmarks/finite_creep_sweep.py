"""Why the creepage of the shipped finite rubber roller changes sign in its speed sweep.

cases/rubber_roller_finite.toml (driven, Q/(mu P) = 0.3, sgn(V) = -1) over |V| = 1 .. 1e7 mm/s. In
the adhesion zone the slip vanishes, so xi = -sgn(V) eps there (eps = u' - w/R, the hoop strain of
the cover's surface, influence/finite.py). Splitting eps by its source with the body's own compliance
(the solver's): eps_p from the pressure (the nearly incompressible cover squeezed out along the arc:
a stretch, > 0) and eps_t from the tangential traction (the Carter-like term, < 0); xi is their
small difference. Printed: xi, the adhesion zone, a, and the two parts averaged over the adhesion
nodes (their sum is xi to the solver's tolerance).

    python benchmarks/finite_creep_sweep.py
"""

from __future__ import annotations

import copy
import sys
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rolling_cli.case import load_case  # noqa: E402
from rolling_cli.influence.build import deformable_body  # noqa: E402
from rolling_cli.model.grid import shape_coefficients  # noqa: E402
from rolling_cli.pipeline import solve  # noqa: E402
from rolling_cli.pipeline.planning import plan  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def hoop_strain(body, p_n, p_t, element_length: float, radius: float) -> np.ndarray:
    """u' - w/R at the nodes [-] for tractions p_n, p_t [stress] (u' from each element's quadratic)."""
    local = np.array([-2.0 / 3.0, 0.0, 2.0 / 3.0])
    slopes = (shape_coefficients(2) @ np.vstack([0.0 * local, np.ones_like(local), 2.0 * local])).T
    u = body.S_tn @ p_n + body.S_tt @ p_t
    w = body.S_nn @ p_n + body.S_nt @ p_t
    return (u.reshape(-1, 3) @ slopes.T / (0.5 * element_length)).reshape(-1) - w / radius


def main() -> None:
    with open(ROOT / "cases" / "rubber_roller_finite.toml", "rb") as f:
        base = tomllib.load(f)
    radius, tau = float(base["bodies"]["A"]["radius"]), float(base["bodies"]["A"]["creep_time"])
    print("| V [mm/s] | V tau_c / a | a [mm] | adhesion zone [mm] | xi | eps_p (pressure) | eps_t (traction) |")
    print("|---:|---:|---:|---|---:|---:|---:|")
    for speed in (1.0, 100.0, 1e3, 3e3, 1e4, 3e4, 1e5, 1e7):
        data = copy.deepcopy(base)
        data["rolling"]["speed"] = speed
        case = load_case(data)
        r = solve(case)
        the_plan = plan(case, half_width=float(r.mesh_half_width))
        body, _ = deformable_body(case, the_plan, case.bodies.A)
        h = the_plan.grid.element_length
        eps_p = hoop_strain(body, r.p_n, 0.0 * r.p_t, h, radius)
        eps_t = hoop_strain(body, 0.0 * r.p_n, r.p_t, h, radius)
        stick = r.state == 1
        x = r.x[stick]
        print(
            f"| {speed:.3g} | {speed * tau / r.contact_half_width:.3g} | {r.contact_half_width:.2f} | "
            f"{x.min():+.2f} .. {x.max():+.2f} | {r.creep:+.5f} | {eps_p[stick].mean():+.5f} | "
            f"{eps_t[stick].mean():+.5f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
