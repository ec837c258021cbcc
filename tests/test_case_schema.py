"""Case validation: dotted keys, values, allowed values, did-you-mean, defaults."""

import math

import pytest

from helpers import CARTER, case_dict
from rolling_cli.case import case_to_dict, load_case, with_overrides
from rolling_cli.errors import CaseError


def _error(data) -> str:
    with pytest.raises(CaseError) as info:
        load_case(data)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_defaults_are_filled():
    data = case_dict(**{"discretization": None, "rolling": None, "tangential": None})
    case = load_case(data)
    assert case.discretization.contact_elements == 200
    assert case.discretization.influence == "auto"
    assert case.discretization.zone == 1.5
    assert case.rolling.direction == -1
    assert case.solver.tolerance == 1e-10 and case.solver.penalty == "auto"
    assert case.tangential.control() == ("load", 0.0)
    resolved = case_to_dict(case)
    assert resolved["solver"]["max_iterations"] == 100


@pytest.mark.parametrize(
    "key,value,expect",
    [
        ("bodies.A.yung", 2e5, "bodies.A.yung = 200000.0: unknown key (did you mean bodies.A.young?)"),
        ("frictoin", {"mu": 0.1}, "did you mean friction?"),
        ("bodies.A.poisson", 0.7, "bodies.A.poisson = 0.7: out of range; allowed: a number >= 0 and <= 0.5"),
        ("bodies.B.young", "steel", 'bodies.B.young = "steel": wrong type'),
        ("rolling.direction", 0, "rolling.direction = 0: not a valid choice; allowed: -1 | 1"),
        ("discretization.influence", "bme", 'not a valid choice (did you mean "bem"?)'),
        ("discretization.contact_elements", 2.5, "discretization.contact_elements = 2.5: wrong type"),
        ("friction.mu", -0.1, "friction.mu = -0.1: out of range"),
        ("solver.penalty", "big", 'solver.penalty = "big": wrong type; allowed: "auto" or a number > 0'),
        ("bodies.A.radius", -1.0, "bodies.A.radius = -1.0: out of range"),
    ],
)
def test_errors_name_key_value_and_allowed(key, value, expect):
    assert expect in _error(case_dict(**{key: value}))


def test_both_load_and_overlap_is_an_error():
    data = case_dict()
    data["normal"]["overlap"] = 0.01
    msg = _error(data)
    assert "normal.load and normal.overlap" in msg and "exactly one" in msg


def test_two_tangential_controls_is_an_error():
    data = case_dict()
    data["tangential"]["creep"] = -1e-4
    assert "more than one given" in _error(data)


def test_missing_required():
    assert "friction: missing table" in _error(case_dict(**{"friction": None}))
    assert "bodies.A.radius: missing key" in _error(case_dict(**{"bodies.A.radius": None}))
    assert 'bodies.B.young: missing key (kind = "elastic")' in _error(case_dict(**{"bodies.B.young": None}))


def test_rigid_and_flat_rules():
    rigid = case_dict(**{"bodies.A": {"kind": "rigid", "radius": 100.0}})
    assert load_case(rigid).bodies.A.rigid
    both = case_dict(**{"bodies.A": {"kind": "rigid", "radius": 100.0}, "bodies.B": {"kind": "rigid", "radius": 1.0}})
    assert "both bodies are rigid" in _error(both)
    rigid_with_young = case_dict(**{"bodies.A": {"kind": "rigid", "radius": 1.0, "young": 1.0}})
    assert 'not used by kind = "rigid"' in _error(rigid_with_young)
    flat = load_case(case_dict(**{"bodies.B.radius": "inf"}))
    assert math.isinf(flat.bodies.B.radius)
    assert "both bodies are flat" in _error(case_dict(**{"bodies.A.radius": math.inf, "bodies.B.radius": "inf"}))


def test_overlap_needs_a_definite_compliance():
    msg = _error(case_dict(**{"normal.overlap": 0.015}))
    assert "normal.overlap = 0.015" in msg and "influence" in msg


def test_file_errors_name_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[friction\nmu = 0.1\n")
    with pytest.raises(CaseError, match=r"bad.toml: invalid TOML"):
        load_case(path)
    with pytest.raises(CaseError, match="file not found"):
        load_case(tmp_path / "missing.toml")


def test_overrides_revalidate_and_replace_exclusive_keys():
    case = load_case(CARTER)
    changed = with_overrides(case, {"friction.mu": 0.3, "tangential.creep": -1e-4})
    assert changed.friction.mu == 0.3
    assert changed.tangential.control() == ("creep", -1e-4)
    with pytest.raises(CaseError, match="friction.mu = -1"):
        with_overrides(case, {"friction.mu": -1})
