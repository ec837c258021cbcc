"""The result's scalars are declared once (rolling_cli.result.quantities): typed fields with a
unit and a long name, which the file's variables carry; nothing undeclared is recorded."""

import dataclasses

import h5py
import numpy as np
import pytest

from helpers import case_dict, run_cli, write_case
from rolling_cli.files.layout import SCALARS
from rolling_cli.files.reader import case_table, read_result
from rolling_cli.result import QUANTITIES, Result
from rolling_cli.result.quantities import UNIT_KEYS
from rolling_cli.stresses.report import INDICATORS


def _result() -> Result:
    z = np.zeros(3)
    return Result(z, z, z, z, z, z, np.zeros(3, dtype=np.int8))


def test_every_quantity_is_a_typed_field_with_unit_and_long_name():
    fields = {f.name: f for f in dataclasses.fields(Result)}
    for name, q in QUANTITIES.items():
        assert name in fields and fields[name].default is None, name
        assert q.long_name and q.unit in UNIT_KEYS, name
        # text and flags carry no unit; every number has one ("1" when dimensionless)
        assert (q.unit is None) == (q.kind in ("str", "bool")), name
    assert not hasattr(Result, "__getattr__")


def test_the_stress_indicators_are_declared():
    for name in INDICATORS:
        for suffix in ("", "_x_over_a", "_z_over_a", "_body"):
            assert f"stress_max_{name}{suffix}" in QUANTITIES


def test_an_undeclared_quantity_is_refused_and_swept_keys_go_to_swept():
    result = _result()
    with pytest.raises(KeyError, match="undeclared result quantity 'creepage'"):
        result.attributes["creepage"] = 0.1
    result.attributes["creep"] = -1e-3
    result.attributes["friction.mu"] = 0.3
    assert result.creep == -1e-3 and result.swept == {"friction.mu": 0.3}
    assert dict(result.attributes) == {"creep": -1e-3}  # iteration: the recorded quantities
    assert result.attributes["friction.mu"] == 0.3


def test_the_file_carries_each_quantity_s_declaration(tmp_path):
    """A solved case's file: every (case) variable is declared, with the declared long name and,
    for numbers, a unit; reading it back gives the same recorded quantities."""
    out = tmp_path / "c.h5"
    run = run_cli("solve", write_case(tmp_path, case_dict(**{"discretization.contact_elements": 40})), "-o", out)
    assert run.exit_code == 0, run.output
    result = read_result(out)
    with h5py.File(out) as f:
        names = [name for name in case_table(f) if name != "case"]
        assert len(names) > 40
        for name in names:
            ds = f[name]
            assert name in SCALARS, name
            long_name, unit = SCALARS[name]
            assert ds.attrs["long_name"] == long_name, name
            assert ("units" in ds.attrs) == (unit is not None), name
    recorded = dict(result.attributes)
    assert recorded["creep"] == result.creep and recorded["converged"] is True
    assert set(recorded) <= set(QUANTITIES)


def test_the_result_holds_every_declared_group():
    """The Result's bases and the groups the file lists are two lists of the same groups."""
    from rolling_cli.result import Result
    from rolling_cli.result.quantities import GROUPS

    assert set(Result.__bases__) == set(GROUPS)
