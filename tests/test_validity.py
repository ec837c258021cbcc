"""Models within their validity (issue #15, item 9): a/R beyond the half-space
assumption is reported in the summary and as a result attribute."""

import math

import pytest

from helpers import STEEL, case_dict, run_cli, solve, write_case
from rolling_cli.files.io_hdf5 import read_result
from rolling_cli.model.validity import HALF_SPACE_LIMIT
from rolling_cli.references import hertz


def test_steel_carter_is_inside():
    result = solve(case_dict(**{"discretization.contact_elements": 40}))
    # a = 1.0 mm on R = 100 mm: the solved half-width within half a node spacing of Hertz
    a = result.contact_half_width
    assert result.half_space_ratio == pytest.approx(a / 100.0, rel=1e-12)
    assert result.half_space_ratio < HALF_SPACE_LIMIT and result.validity_warning == ""


def test_rubber_roller_on_steel_is_flagged(tmp_path):
    """The issue's case: a rubber roller (E = 10) on steel, P = 1812.5 N/mm: Hertz gives
    a ~ 100 mm on R = 100 mm cylinders; the solve converges, and says the model does not apply."""
    rubber = {"kind": "elastic", "radius": 100.0, "young": 10.0, "poisson": 0.49}
    data = case_dict(**{"bodies.A": rubber, "bodies.B": dict(STEEL), "discretization.contact_elements": 60})
    out = tmp_path / "rubber.h5"
    run = run_cli("solve", write_case(tmp_path, data), "-o", out)
    assert run.exit_code == 0, run.output
    stored = read_result(out)  # the file's (case) variables, as any reader sees them
    ratio, warning, a = stored.half_space_ratio, stored.validity_warning, stored.contact_half_width
    e_star = 1.0 / ((1 - 0.49**2) / 10.0 + (1 - 0.28**2) / STEEL["young"])
    assert a == pytest.approx(hertz.half_width(1812.5, 50.0, e_star), rel=0.05)  # the node cell
    assert ratio == pytest.approx(a / 100.0, rel=1e-12) and ratio > HALF_SPACE_LIMIT
    assert f"a/R = {ratio:.3g} > 0.1" in warning and "bodies.A.radius = 100" in warning
    # the summary wraps long lines at 160 characters with a 17-space continuation indent
    unwrapped = " ".join(line.strip() if line.startswith(" " * 17) else line for line in run.output.splitlines())
    assert f"  WARNING        {warning}" in unwrapped


def test_flat_and_most_curved_body():
    """The ratio uses the most curved body; a flat does not count; no contact gives NaN."""
    from rolling_cli.case import load_case
    from rolling_cli.model.validity import half_space_check

    case = load_case(case_dict(**{"bodies.A.radius": 5.0, "bodies.B.radius": "inf"}))
    found = half_space_check(case, 1.0)
    assert found["half_space_ratio"] == 0.2 and "bodies.A.radius = 5" in found["validity_warning"]
    assert math.isnan(half_space_check(case, math.nan)["half_space_ratio"])
    assert half_space_check(case, 0.5)["validity_warning"] == ""  # a/R = 0.1 exactly is allowed
