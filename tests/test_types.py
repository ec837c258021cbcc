"""The package type-checks: mypy, configured in pyproject.toml ([tool.mypy]), reports nothing.

Run in the suite (and so in CI) because a type error is a defect a reader of the code would
otherwise find first: a None where a value is needed, a unit-less attribute, a wrong signature.
"""

from __future__ import annotations

from pathlib import Path

from mypy import api

ROOT = Path(__file__).resolve().parents[1]


def test_mypy_reports_no_errors():
    out, err, status = api.run(["--config-file", str(ROOT / "pyproject.toml"), str(ROOT / "rolling_cli")])
    assert status == 0, out + err
