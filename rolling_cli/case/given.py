"""Values of optional case keys where the case's validation has made them present.

The schema types a key that only some cases have (``normal.load``,
``bodies.B.layer_thickness``, ...) as ``float | None``; validation guarantees
it wherever a stage reads it. :func:`given` states that guarantee in the code
(and to a type checker): it returns the value as a float, and raises
:class:`~rolling_cli.errors.CaseError` naming the dotted key if it is missing,
which only a case built past validation can reach.
"""

from __future__ import annotations

from ..errors import CaseError


def given(value: float | int | None, key: str) -> float:
    """``value`` as a float (in the key's own unit); CaseError naming ``key`` if it is None."""
    if value is None:
        raise CaseError(f"{key} is required here", key=key)
    return float(value)
