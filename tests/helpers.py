"""Shared test helpers: case dictionaries and the contact-law checks.

Tolerances for the contact laws are derived from the solve itself: the
relative residual bounds |F| / p_scale, and F_n = p_n - min(0, p_n + r_n delta)
then bounds a negative gap by |F| / r_n; F_t bounds the adhesion slip by |F| / r_t
(r the reference penalties written in the result).
"""

from __future__ import annotations

import copy

import numpy as np

import rolling_cli

CARTER = {
    "title": "test Carter",
    "bodies": {
        "A": {"kind": "elastic", "radius": 100.0, "young": 210000.0, "poisson": 0.3},
        "B": {"kind": "elastic", "radius": 100.0, "young": 210000.0, "poisson": 0.3},
    },
    "friction": {"mu": 0.1},
    "normal": {"load": 1812.5},
    "tangential": {"q_over_mu_p": 0.51},
    "rolling": {"direction": -1},
    "discretization": {"influence": "half-plane", "contact_elements": 200, "zone": 1.5},
}

ALUMINIUM = {"kind": "elastic", "radius": 100.0, "young": 60260.0, "poisson": 0.31}
STEEL = {"kind": "elastic", "radius": 100.0, "young": 209920.0, "poisson": 0.28}


def case_dict(base: dict | None = None, **dotted) -> dict:
    """A copy of ``base`` (default: Carter) with dotted keys set; ``None`` deletes a key.

    Setting one of normal.load/overlap or a tangential key replaces the others.
    """
    data = copy.deepcopy(base or CARTER)
    exclusive = {"normal": ("load", "overlap"), "tangential": ("q_over_mu_p", "q_over_p", "load", "creep")}
    for key, value in dotted.items():
        parts = key.split(".")
        node = data
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        if len(parts) == 2 and parts[0] in exclusive and parts[1] in exclusive[parts[0]]:
            for other in exclusive[parts[0]]:
                node.pop(other, None)
        if value is None:
            node.pop(parts[-1], None)
        else:
            node[parts[-1]] = value
    return data


def write_case(directory, data: dict, name: str = "case.toml"):
    """Write a case dict as a TOML file in ``directory``; returns its path."""
    import tomli_w

    path = directory / name
    path.write_text(tomli_w.dumps(data))
    return path


def run_cli(*args):
    """Invoke ``rollc`` in-process with string arguments; returns click's Result."""
    from click.testing import CliRunner

    from rolling_cli.cli import main

    return CliRunner().invoke(main, [str(a) for a in args])


def random_case(
    young_a, young_b, rigid_a, nu_a, nu_b, radius_a, radius_b, mu, load, q, direction, elements, influence
) -> tuple[dict, float]:
    """A case of the property test and of benchmarks/robustness.py, and its mu |beta_Dundurs|.

    Body A is rigid when ``rigid_a`` (its modulus and ratio then unused); B is
    always elastic. Loaded by P and Q/(mu P).
    """
    from rolling_cli.model import materials

    body_a = (
        {"kind": "rigid", "radius": radius_a}
        if rigid_a
        else {"kind": "elastic", "radius": radius_a, "young": young_a, "poisson": nu_a}
    )
    body_b = {"kind": "elastic", "radius": radius_b, "young": young_b, "poisson": nu_b}
    data = case_dict(
        **{
            "bodies.A": body_a,
            "bodies.B": body_b,
            "friction.mu": mu,
            "normal.load": load,
            "tangential.q_over_mu_p": q,
            "rolling.direction": direction,
            "discretization.contact_elements": elements,
            "discretization.influence": influence,
        }
    )
    beta = materials.dundurs_beta(float("inf") if rigid_a else young_a, 0.0 if rigid_a else nu_a, young_b, nu_b)
    return data, mu * abs(beta)


def dissimilar(**dotted) -> dict:
    """Aluminium (A) on steel (B), beta_seed = 0.288, P = 1000 N/mm."""
    base = case_dict(CARTER, **{"normal.load": 1000.0})
    base["bodies"] = {"A": dict(ALUMINIUM), "B": dict(STEEL)}
    return case_dict(base, **dotted)


def solve(data: dict) -> rolling_cli.Result:
    return rolling_cli.solve(rolling_cli.load_case(data))


def assert_contact_laws(result, tolerance: float = 1e-10) -> None:
    """The contact laws at every node, within bounds derived from the residual.

    p_n <= 0; delta_n >= 0; p_n delta_n = 0; |p_t| <= mu |p_n|; adhesion: s_t = 0;
    slip: |p_t| = mu |p_n| and s_t p_t <= 0 (slip opposes the traction).
    """
    assert result.converged
    assert result.residual <= tolerance
    mu = result.mu
    scale = result.traction_scale
    f = tolerance * scale  # bound on |F| in stress units
    gap_tol = f / result.reference_penalty_n
    slip_tol = f / result.reference_penalty_t
    p_n, p_t, gap, s = result.p_n, result.p_t, result.delta_n, result.s_t
    contact = p_n < 0.0
    assert np.all(p_n <= f), "tensile normal traction"
    assert np.all(gap >= -gap_tol), f"penetration {gap.min():.3e} beyond {gap_tol:.1e}"
    assert np.all(np.abs(p_n * gap) <= np.abs(p_n) * gap_tol + f * np.abs(gap) + f * gap_tol), "complementarity"
    assert np.all(np.abs(gap[contact]) <= gap_tol), "gap on contact nodes"
    assert np.all(np.abs(p_t) <= mu * np.abs(p_n) + 2 * f), "Coulomb bound exceeded"
    stick = result.state == 1
    slip = result.state == 2
    assert np.array_equal(result.state > 0, contact)
    if mu > 0.0:
        assert np.all(np.abs(s[stick]) <= slip_tol), f"adhesion slip {np.abs(s[stick]).max():.3e} > {slip_tol:.1e}"
        assert np.all(np.abs(np.abs(p_t[slip]) - mu * np.abs(p_n[slip])) <= 2 * f), "slip below the bound"
        assert np.all(s[slip] * p_t[slip] <= slip_tol * np.abs(p_t[slip])), "slip along the traction"
    assert np.all(p_t[~contact] == 0.0), "traction outside the contact"


def assert_force_balance(result, load: float | None = None, q: float | None = None, tolerance: float = 1e-10):
    """Global equilibrium: P = -sum w p_n and Q = sum w p_t match the prescribed loads.

    The load equations are rows of the Newton residual, (sum w p - load) / L_zone,
    so the relative residual bounds their error by tolerance * p_scale * L_zone.
    """
    w = result.weights
    P = float(-(w @ result.p_n))
    Q = float(w @ result.p_t)
    assert np.isclose(P, result.normal_load, rtol=1e-12, atol=0.0)
    assert np.isclose(Q, result.tangential_load, rtol=1e-12, atol=1e-12 * P)
    bound = tolerance * result.traction_scale * float(w.sum())
    if load is not None:
        assert abs(P - load) <= bound
    if q is not None:
        assert abs(Q - q) <= bound


def without_timings(dataset):
    """An xarray Dataset without its wall-clock variables (``time`` and every ``time_*``): what differs
    between two runs that compute exactly the same numbers."""
    return dataset.drop_vars([v for v in dataset.variables if v == "time" or str(v).startswith("time_")])
