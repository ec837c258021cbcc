"""dQ/db and dxi/db of a layered body (issue 24 item 1, ``[output] layer_derivative``).

rolling_cli/solver/sensitivity.py differentiates the solve implicitly with the influence blocks'
central difference in the layer thickness b (rolling_cli/pipeline/assemble.py builds the contact
systems at b +- 1e-4 b on the case's grid). Reference: central differences of re-solved cases at
b +- 1e-6 b on the same grid (the creepage held for dQ/db, the force Q for dxi/db, the load P
held in both), independent Newton solves to 1e-13.
"""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import pytest

from rolling_cli import pipeline
from rolling_cli.case import load_case
from rolling_cli.case.io import read_toml
from rolling_cli.pipeline.planning import build_contact_system
from rolling_cli.solver.formulation import State

CASES = Path(__file__).resolve().parents[1] / "cases"
#: The difference's error: truncation (1e-12 relative) and the re-solves' residual (1e-13 of mu P
#: over the step 1e-6 b: ~1e-7 relative), the sensitivity's own central difference of the influence
#: (h = 1e-4 b: ~1e-8); measured 6e-9 on cases/tyred_fig11_q41 at 100 elements. 1e-5 is the issue's
#: figure for every sensitivity.
TOLERANCE = 1e-5


def _tyred(**output) -> dict:
    data = read_toml(CASES / "tyred_fig11_q41.toml")
    data["discretization"]["contact_elements"] = 80
    data["output"] = output
    return data


@pytest.fixture(scope="module")
def solved():
    case = load_case(_tyred(layer_derivative=True))
    the_plan, system = pipeline.prepare(case)
    return case, the_plan, pipeline.solve(case, system=system)


def _resolved(case, the_plan, result, thickness: float, force: bool):
    """The case at layer thickness ``thickness`` on the same grid, under load control at the solved P
    and creepage (or force) control at the solved creepage (or Q), from the solved state."""
    body = dataclasses.replace(case.bodies.B, layer_thickness=thickness)
    tangential = (
        type(case.tangential)(load=result.tangential_load) if force else type(case.tangential)(creep=result.creep)
    )
    moved = dataclasses.replace(
        case,
        bodies=dataclasses.replace(case.bodies, B=body),
        normal=dataclasses.replace(case.normal, overlap=None, load=result.normal_load),
        tangential=tangential,
        solver=dataclasses.replace(case.solver, tolerance=1e-13),
        output=dataclasses.replace(case.output, layer_derivative=False),
    )
    start = State(result.p_n, result.p_t, result.solved_overlap, result.creep)
    return pipeline.solve(moved, system=build_contact_system(moved, the_plan, use_cache=False), start=start)


def test_thickness_derivatives_against_resolved_differences(solved):
    """dQ/db (xi held) and dxi/db (Q held) equal central differences of re-solves within 1e-5."""
    case, the_plan, r = solved
    b = float(case.bodies.B.layer_thickness)
    h = 1e-6 * b
    plus, minus = (_resolved(case, the_plan, r, b + s * h, force=False) for s in (1, -1))
    assert (plus.tangential_load - minus.tangential_load) / (2 * h) == pytest.approx(r.dQ_db, rel=TOLERANCE)
    plus, minus = (_resolved(case, the_plan, r, b + s * h, force=True) for s in (1, -1))
    assert (plus.creep - minus.creep) / (2 * h) == pytest.approx(r.dxi_db, rel=TOLERANCE)
    # one linearisation: dxi/db = -(dQ/db)/(dQ/dxi) (to rounding)
    assert r.dxi_db == pytest.approx(-r.dQ_db / r.dQ_dxi, rel=1e-10)


def test_not_recorded_unless_asked():
    """Without ``output.layer_derivative`` the result has no dQ_db (no BEM builds are spent on it)."""
    result = pipeline.solve(load_case(_tyred()))
    assert result.dQ_db is None and result.dxi_db is None


def test_needs_one_layered_body(caplog):
    """Two half-spaces: nothing to differentiate; a warning says why, and dQ_db is NaN."""
    data = read_toml(CASES / "carter.toml")
    data["discretization"]["contact_elements"] = 60
    data["output"] = {"layer_derivative": True}
    with caplog.at_level(logging.WARNING):
        result = pipeline.solve(load_case(data))
    assert "exactly one layered body" in caplog.text
    assert result.dQ_db != result.dQ_db  # NaN
