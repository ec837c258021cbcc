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
        ("solver.penalty", "big", 'solver.penalty = "big": wrong type; allowed: "auto" or a number >= 1e-30'),
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


# Ranges that mean something (issue #15, item 10): what the schema refuses, and
# that the boundary values it accepts give a result passing the contact-law check
# or fail with a message.


@pytest.mark.parametrize(
    "key,value,expect",
    [
        ("solver.tolerance", 0.999, "solver.tolerance = 0.999: out of range; allowed: a number >= 1e-14 and <= 0.001"),
        ("solver.tolerance", 1e-15, "solver.tolerance = 1e-15: out of range"),
        ("friction.mu", 1e300, "friction.mu = 1e+300: out of range; allowed: 0, or a number >= 1e-06 and <= 100"),
        ("friction.mu", 1e-9, "friction.mu = 1e-09: too small to resolve in double precision; allowed: 0, or"),
        ("tangential.creep", 2.0, "tangential.creep = 2.0: out of range; allowed: a number >= -1 and <= 1"),
        ("tangential.load", -1e31, "tangential.load = -1e+31: out of range"),
        ("normal.load", 1e-300, "normal.load = 1e-300: out of range; allowed: a number >= 1e-30 and <= 1e+30"),
        ("bodies.A.young", 10**400, "bodies.A.young = 1000000000000000000"),  # an integer beyond any double
        ("bodies.A.radius", 1e31, "bodies.A.radius = 1e+31: out of range"),
        ("solver.penalty", 1e-31, "solver.penalty = 1e-31: out of range"),
        ("title", "two\nlines", 'title = "two\\nlines": control characters'),
        ("title", "x" * 1001, "too long (1001 characters); allowed: a string of at most 1000 characters"),
        ("units.force", "N\0", 'units.force = "N\\x00": control characters'),
    ],
)
def test_meaningful_ranges(key, value, expect):
    assert expect in _error(case_dict(**{key: value}))


def _layered(thickness: float, radius: float = 100.0) -> dict:
    layer = {"kind": "layered", "radius": radius, "young": 10.0, "poisson": 0.5, "layer_thickness": thickness}
    return case_dict(
        **{"bodies.A": {"kind": "rigid", "radius": 100.0}, "bodies.B": layer, "discretization.influence": "bem"}
    )


def test_layer_must_be_thinner_than_its_body():
    assert load_case(_layered(99.0)).bodies.B.layer_thickness == 99.0
    for thickness in (100.0, 250.0):
        assert f"bodies.B.layer_thickness = {thickness}: not thinner than the body (radius 100)" in _error(
            _layered(thickness)
        )
    assert "bodies.B.layer_thickness = 1e-300: out of range" in _error(_layered(1e-300))
    assert load_case(_layered(5.0, radius=math.inf)).bodies.B.layer_thickness == 5.0  # a layered flat


def test_overlap_smaller_than_radii_and_layers():
    layered = case_dict(_layered(0.1), **{"normal.overlap": 0.0042})
    assert load_case(layered).normal.overlap == 0.0042
    message = _error(case_dict(layered, **{"normal.overlap": 0.1}))
    assert "normal.overlap = 0.1: not smaller than bodies.B.layer_thickness = 0.1; allowed: a number < 0.1" in message
    bem = case_dict(**{"discretization.influence": "bem", "bodies.A.radius": 2.0, "normal.overlap": 3.0})
    assert "normal.overlap = 3.0: not smaller than bodies.A.radius = 2" in _error(bem)


def test_accepted_extremes_solve_or_fail_with_a_message():
    """The ends of the accepted ranges: tolerance 1e-3 and 1e-14, mu 1e-6 and 100, the
    largest creepage. Each passes the contact laws at its own tolerance or raises a
    solver error with a one-line message, never a wrong "converged". Those with a
    regular solution must solve; three may fail: 1e-14 lies below the residual's
    rounding floor on most meshes (about 5 eps n; the solver then converges to a
    small multiple of its estimate of that floor and records it as
    ``tolerance_applied``), mu = 100 on aluminium/steel is deep in the
    strong-coupling corner (mu |beta_Dundurs| = 14), and mu = 1e-6 on
    aluminium/steel has |beta_Dundurs| / mu = 1.4e5: its adhesion zone is far
    narrower than a node and the force is a staircase in the creepage (the
    message must say so)."""
    from helpers import assert_contact_laws, dissimilar, solve
    from rolling_cli.errors import RollingError

    small = {"discretization.contact_elements": 40}
    cases = [  # (case, its tolerance, must it solve?)
        (case_dict(**small, **{"solver.tolerance": 1e-3}), 1e-3, True),
        (case_dict(**small, **{"solver.tolerance": 1e-14}), 1e-14, False),
        (case_dict(**small, **{"friction.mu": 1e-6}), 1e-10, True),
        (dissimilar(**small, **{"friction.mu": 1e-6}), 1e-10, False),
        (case_dict(**small, **{"friction.mu": 100.0}), 1e-10, True),
        (dissimilar(**small, **{"friction.mu": 100.0, "tangential.q_over_mu_p": 0.5}), 1e-10, False),
        (case_dict(**small, **{"tangential.creep": -1.0}), 1e-10, True),
    ]
    for data, tolerance, must in cases:
        try:
            result = solve(data)
        except RollingError as err:
            assert not must, err
            assert "\n" not in str(err) and str(err)
            if data["friction"]["mu"] == 1e-6:
                assert "friction is tiny against the coupling" in str(err)
            continue
        assert result.tolerance_applied >= tolerance
        assert_contact_laws(result, result.tolerance_applied)
