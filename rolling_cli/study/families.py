"""Families of creep-force curves: ``rollc sweep --curve KIND --set KEY=VALUES``.

One curve per combination of the ``--set`` values (their product, or their
pairs with ``--zip``), each a creep-force curve of ``points`` points along the
curve's own key (``tangential.q_over_mu_p`` from -0.99 to 0.99, or
``tangential.creep`` over +-1.5 times the full-slip creepage of that curve's
case: mu a / R*, so a curve at a larger mu or load spans its own range).
Case ``i`` is point ``i % points`` of curve ``i // points``: the curve key
varies fastest, so each curve is a run of neighbouring cases, and
:meth:`FamilySpec.curve_of` cuts the sweep's chunks at curve ends, so each
curve is warm-started along itself, never from the end of the previous one.

A family that is not meaningful is refused with one line naming the key and
value: a swept tangential key (the curve sets the tangential control itself)
or a friction coefficient of 0 (no creep-force curve without friction).
"""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..case import Case
from ..errors import CaseError
from .sweep_spec import CHECK_VALUES, Linspace, SweepSpec, build

#: The key each kind of curve runs along.
CURVE_KEYS = {"load": "tangential.q_over_mu_p", "creep": "tangential.creep"}
#: Q/(mu P) of a load curve [-] runs over +-this; a creep curve over +-this times full slip.
LOAD_LIMIT = 0.99
CREEP_SPAN = 1.5


def full_slip_creepage(case: Case) -> float:
    """|xi| [-] at the onset of full slip of ``case``: mu a / R* (Carter), a measured when not Hertzian."""
    from .. import pipeline
    from ..references import carter

    the_plan = pipeline.measured_plan(case)
    return carter.full_slip_creepage(the_plan.half_width, the_plan.radius, case.friction.mu)


def curve_values(case: Case, kind: str, points: int) -> Linspace:
    """The values of one curve of ``case`` along its key (:data:`CURVE_KEYS`)."""
    if kind == "load":
        return Linspace(-LOAD_LIMIT, LOAD_LIMIT, points)
    full = full_slip_creepage(case)
    return Linspace(-CREEP_SPAN * full, CREEP_SPAN * full, points)


@dataclass(frozen=True)
class FamilySpec:
    """One ``kind`` curve of ``points`` points per combination of ``curves`` (the ``--set`` keys),
    with the interface of :class:`~rolling_cli.study.sweep_spec.SweepSpec` (keys: the curve keys, then
    the curve's own key)."""

    base: Case
    curves: SweepSpec
    kind: str
    points: int
    _values: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def keys(self) -> tuple[str, ...]:
        """The curve keys, then the key the curves run along."""
        return (*self.curves.keys, CURVE_KEYS[self.kind])

    @property
    def values(self) -> tuple[Sequence, ...]:
        """The curve keys' values, then the points of the first curve (for counts)."""
        return (*self.curves.values, self.along(0))

    @property
    def zipped(self) -> bool:
        """Whether the curve keys are paired (``--zip``)."""
        return self.curves.zipped

    @property
    def size(self) -> int:
        """The number of cases: curves times points."""
        return self.curves.size * self.points

    def curve_of(self, index: int) -> int:
        """The curve case ``index`` belongs to (warm starts never cross curves)."""
        return index // self.points

    def along(self, curve: int) -> Linspace:
        """The values of curve ``curve`` along its key (computed once per curve, on demand)."""
        if curve not in self._values:
            # the curve's case at zero traction (its own tangential control plays no part in the range)
            case = build(self.base, {**self.curves.combination(curve), CURVE_KEYS[self.kind]: 0.0})
            self._values[curve] = curve_values(case, self.kind, self.points)
        return self._values[curve]

    def combination(self, index: int) -> dict[str, Any]:
        """The swept values of case ``index`` as {dotted key: value}."""
        curve, point = divmod(index, self.points)
        return {**self.curves.combination(curve), CURVE_KEYS[self.kind]: self.along(curve)[point]}

    def combinations(self) -> Iterator[dict[str, Any]]:
        """Every case's swept values, in sweep order (lazily)."""
        return (self.combination(i) for i in range(self.size))

    def probes(self) -> Iterator[int]:
        """The cases a large family checks before the run: both ends of every curve (of the first
        and last curve beyond :data:`~rolling_cli.study.sweep_spec.CHECK_VALUES` curves)."""
        n = self.curves.size
        for curve in range(n) if n <= CHECK_VALUES // 10 else (0, n - 1):
            yield curve * self.points
            yield curve * self.points + self.points - 1

    def describe(self) -> str:
        """The specification as JSON: what ``--resume`` compares."""
        values = [v.text() if isinstance(v, Linspace) else list(v) for v in self.curves.values]
        values.append(f"{self.kind} curve of {self.points} points")
        return json.dumps({"keys": list(self.keys), "values": values, "zip": self.zipped, "curve": self.kind})


def family_spec(base: Case, kind: str, points: int, curves: SweepSpec) -> FamilySpec:
    """A family of ``kind`` curves, one per combination of ``curves``; refuses one that is not
    meaningful (:class:`CaseError`, one line naming the key and the value)."""
    for key, values in zip(curves.keys, curves.values, strict=True):
        if key.split(".")[0] == "tangential":
            raise CaseError(
                f"--curve {kind} --set {key}: the curve sets the tangential control itself "
                f"({CURVE_KEYS[kind]}); allowed: --set keys outside [tangential]"
            )
        if key == "friction.mu":
            ends = (values[0], values[len(values) - 1]) if isinstance(values, Linspace) else values
            for value in ends:
                if value <= 0.0:
                    raise CaseError(
                        f"--curve {kind} --set friction.mu: value {value!r}: no creep-force curve without "
                        "friction; allowed: friction.mu > 0"
                    )
    if "friction.mu" not in curves.keys and base.friction.mu <= 0.0:
        raise CaseError(f"{base.source or 'case'}: friction.mu = 0: no creep-force curve without friction")
    return FamilySpec(base, curves, kind, points)
