"""What a sweep is: dotted keys and their values, expanded lazily into cases.

A :class:`SweepSpec` comes from ``--set KEY=VALUES`` options, a case's
``[sweep]`` table or ``--curve``. A range ``start:stop:count`` is a
:class:`Linspace`, which computes its values on demand, so a sweep of ten
million values costs nothing before it runs; case ``i`` is built only when it
is solved (:meth:`SweepSpec.combination`). Before the first solve,
:func:`validate` builds every case of a sweep of up to :data:`VALIDATE_ALL`
cases (larger ones: every value of every key, and the corners), and
:func:`check_resources` refuses a sweep whose file cannot fit on the disk.
:func:`difference` tells ``--resume`` whether a file holds this sweep.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import shutil
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

from ..case import Case, with_overrides
from ..case.validate import convert_scalar, field_metadata
from ..errors import CaseError

#: Sweeps of up to this many cases have every case built and validated before the first solve.
VALIDATE_ALL = 2_000
#: Values per range checked one by one before the run (beyond: the end points; ranges are monotone).
CHECK_VALUES = 100_000


class Linspace(Sequence):
    """``count`` evenly spaced values from ``start`` to ``stop`` (inclusive), computed on demand.

    Value ``i`` is numpy's ``linspace`` value (``start + i * step``, the last one
    ``stop`` exactly) rounded to 15 significant digits, so ``0.1:0.4:4`` gives
    0.3 as typed, not 0.30000000000000004. ``integer`` rounds to ints.
    """

    def __init__(self, start: float, stop: float, count: int, integer: bool = False) -> None:
        self.start, self.stop, self.size, self.integer = float(start), float(stop), int(count), integer
        self.step = (self.stop - self.start) / (self.size - 1) if self.size > 1 else 0.0

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self.size))]
        if i < 0:
            i += self.size
        if not 0 <= i < self.size:
            raise IndexError(i)
        value = self.stop if i == self.size - 1 and self.size > 1 else i * self.step + self.start
        return round(value) if self.integer else float(f"{value:.15g}")

    def __repr__(self) -> str:
        return f"Linspace({self.text()})"

    def text(self) -> str:
        """``start:stop:count``, the form it was given in."""
        return f"{self.start!r}:{self.stop!r}:{self.size}"


@dataclass(frozen=True)
class SweepSpec:
    """Dotted keys and their values (tuples or :class:`Linspace`); ``zipped`` pairs them, else the
    cartesian product (the last key varies fastest)."""

    keys: tuple[str, ...]
    values: tuple[Sequence, ...]
    zipped: bool = False

    def __post_init__(self) -> None:
        if self.zipped and len({len(v) for v in self.values}) > 1:
            counts = ", ".join(f"{k}: {len(v)}" for k, v in zip(self.keys, self.values, strict=True))
            raise CaseError(f"sweep: --zip needs equally many values per key, got {counts}; allowed: equal lengths")

    @property
    def size(self) -> int:
        """The number of cases."""
        if self.zipped:
            return len(self.values[0]) if self.values else 0
        return math.prod(len(v) for v in self.values)

    def combination(self, index: int) -> dict[str, Any]:
        """The swept values of case ``index`` as {dotted key: value}."""
        if self.zipped:
            return {k: v[index] for k, v in zip(self.keys, self.values, strict=True)}
        out = {}
        for key, values in zip(reversed(self.keys), reversed(self.values), strict=True):
            index, digit = divmod(index, len(values))
            out[key] = values[digit]
        return {k: out[k] for k in self.keys}

    def combinations(self) -> Iterator[dict[str, Any]]:
        """Every case's swept values, in sweep order (lazily)."""
        return (self.combination(i) for i in range(self.size))

    def curve_of(self, index: int) -> int:
        """The warm-start path case ``index`` is on: one for a plain sweep (a family of curves has one per
        curve, :class:`~rolling_cli.study.families.FamilySpec`); chunks never cross paths."""
        return 0

    def describe(self) -> str:
        """The specification as JSON (ranges as ``start:stop:count``): what ``--resume`` compares."""
        values = [v.text() if isinstance(v, Linspace) else list(v) for v in self.values]
        return json.dumps({"keys": list(self.keys), "values": values, "zip": self.zipped})


def parse_values(key: str, text: str, source: str = "--set") -> Sequence:
    """Values of one swept key: a comma list or a range start:stop:count (inclusive, evenly spaced).

    Each value is checked by the key's schema rules (a range of more than
    :data:`CHECK_VALUES` values: its end points, as ranges are monotone).
    """
    meta = field_metadata(key)
    if not meta or meta.get("kind") == "table":
        raise CaseError(f"{source} {key}={text}: unknown case key; allowed: a dotted scalar key such as friction.mu")
    text = text.strip()
    if text.count(":") == 2 and "," not in text:
        start, stop, count = text.split(":")
        try:
            n = int(count)
            values = Linspace(float(start), float(stop), n, integer=meta.get("kind") == "int")
        except (ValueError, OverflowError):
            raise CaseError(
                f"{source} {key}={text}: not a range; allowed: start:stop:count with numbers and an integer count"
            ) from None
        if n < 1:
            raise CaseError(f"{source} {key}={text}: count {n}; allowed: a count >= 1")
        checked = range(n) if n <= CHECK_VALUES else (0, n - 1)
        for i in checked:
            convert_scalar(values[i], meta, key, None)
        return values
    raw = [_literal(part.strip()) for part in text.split(",") if part.strip()]
    if not raw:
        raise CaseError(f"{source} {key}={text}: no values; allowed: a comma list or start:stop:count")
    return tuple(convert_scalar(v, meta, key, None) for v in raw)


def _literal(text: str) -> Any:
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return text.strip('"')


def spec_from_options(settings: list[str], zipped: bool) -> SweepSpec:
    """From the CLI's ``--set KEY=VALUES`` options (each key at most once)."""
    keys, values = [], []
    for item in settings:
        if "=" not in item:
            raise CaseError(f"--set {item}: no '='; allowed: KEY=VALUES, for example friction.mu=0.1,0.2")
        key, text = (part.strip() for part in item.split("=", 1))
        if key in keys:
            raise CaseError(f"--set {key}: given twice; allowed: each key once, with all its values in one --set")
        keys.append(key)
        values.append(parse_values(key, text))
    return SweepSpec(tuple(keys), tuple(values), zipped)


def spec_from_table(table: dict, file: str | None) -> SweepSpec:
    """From a case's ``[sweep]`` table: ``"friction.mu" = [0.1, 0.2]`` or ``"0.1:0.4:4"``; ``zip = true``."""
    zipped = bool(table.get("zip", False))
    keys, values = [], []
    for key, raw in table.items():
        if key == "zip":
            continue
        where = f"{file + ': ' if file else ''}sweep.{key}"
        if isinstance(raw, str):
            values.append(parse_values(key, raw, where))
        elif isinstance(raw, list) and raw:
            meta = field_metadata(key)
            if not meta or meta.get("kind") == "table":
                raise CaseError(
                    f"{where} = {raw!r}: unknown case key; allowed: a dotted scalar key such as friction.mu"
                )
            values.append(tuple(convert_scalar(v, meta, key, file) for v in raw))
        else:
            raise CaseError(f"{where} = {raw!r}: wrong type; allowed: a non-empty list or a 'start:stop:count' string")
        keys.append(key)
    if not keys:
        raise CaseError(f"{file + ': ' if file else ''}sweep: empty; allowed: dotted keys with lists of values")
    return SweepSpec(tuple(keys), tuple(values), zipped)


def curve_spec(base: Case, kind: str, points: int) -> SweepSpec:
    """The creep-force curve: Q/(mu P) from -0.99 to 0.99, or the creepage over +-1.5 times full slip.
    With friction that falls with the slip speed the load curve runs through its turning points
    (:func:`load_curve_through_peaks`)."""
    if base.friction.mu <= 0.0:
        raise CaseError(f"{base.source or 'case'}: friction.mu = 0: no creep-force curve without friction")
    if kind == "load":
        if base.friction.law != "constant":
            through = load_curve_through_peaks(base, points)
            if through is not None:
                return through
        return SweepSpec(("tangential.q_over_mu_p",), (Linspace(-0.99, 0.99, points),))
    from .. import pipeline
    from ..references import carter

    the_plan = pipeline.measured_plan(base)
    full = carter.full_slip_creepage(the_plan.half_width, the_plan.radius, base.friction.mu)
    return SweepSpec(("tangential.creep",), (Linspace(-1.5 * full, 1.5 * full, points),))


#: The load curve's targets stop this close to a turning point (its slope dQ/dxi -> 0 there, so a
#: force-controlled Newton at the peak itself is singular); the plot finds the turn between them.
PEAK_FRACTION = 0.995


def load_curve_through_peaks(base: Case, points: int) -> SweepSpec | None:
    """The force-controlled creep-force curve of a slip-speed law, in creepage order through both
    turning points: the high-slip branch from the creepage curve's end (-1.5 times Carter's full
    slip, mu_static) up to :data:`PEAK_FRACTION` of the peak, the low-slip branch across Q = 0 to
    the other peak, the other high-slip branch down to +1.5 times full slip. The swept keys are
    ``tangential.q_over_mu_p`` and ``solver.branch`` (zipped); each piece gets points in
    proportion to its arc length in the plane (xi / (1.5 full slip), Q/(mu P)), at least
    two (so at least six in all). The peaks and ends are found by
    creepage-controlled solves before the sweep (:func:`~rolling_cli.pipeline.branches.peak_on_side`,
    some 25 solves); None when the curve has no turning point (a law that does not fall),
    and the plain load curve is swept."""
    import numpy as np

    from .. import pipeline
    from ..pipeline import branches
    from ..references import carter
    from ..result import recorded

    sides = []
    the_plan, system = pipeline.prepare(base)
    ends = 1.5 * carter.full_slip_creepage(the_plan.half_width, the_plan.radius, base.friction.mu)
    for sign in (-1.0, 1.0):
        peak = branches.peak_on_side(base, sign, pipeline.solve, pipeline.prepare)
        if peak is None or abs(recorded(peak.creep, "creep")) >= ends:
            return None
        end = pipeline.solve(with_overrides(base, {"tangential.creep": sign * ends}), system=system)
        q_peak, q_end = recorded(peak.q_over_mu_p, "q_over_mu_p"), recorded(end.q_over_mu_p, "q_over_mu_p")
        sides.append((PEAK_FRACTION * q_peak, q_end, recorded(peak.creep, "creep")))
    (peak_lo, end_lo, xi_lo), (peak_hi, end_hi, xi_hi) = sides
    # arc lengths in the plane (xi / xi_end, Q/(mu P)): both are of order one along the curve
    creep_spans = np.array([ends - abs(xi_lo), abs(xi_hi - xi_lo), ends - abs(xi_hi)]) / ends
    spans = np.hypot(creep_spans, [peak_lo - end_lo, peak_hi - peak_lo, end_hi - peak_hi])
    counts = np.maximum(2, np.round(spans / spans.sum() * points)).astype(int)
    counts[1] = max(2, points - counts[0] - counts[2])
    pieces = [
        (np.linspace(end_lo, peak_lo, counts[0]), "high-slip"),
        (np.linspace(peak_lo, peak_hi, counts[1]), "low-slip"),
        (np.linspace(peak_hi, end_hi, counts[2]), "high-slip"),
    ]
    values = [float(f"{v:.12g}") for q, _ in pieces for v in q]
    labels = [branch for q, branch in pieces for _ in q]
    return SweepSpec(("tangential.q_over_mu_p", "solver.branch"), (tuple(values), tuple(labels)), zipped=True)


def given(combo: dict) -> str:
    """The swept values of a case as the user gave them: ``key = value, ...``."""
    return ", ".join(f"{k} = {v!r}" for k, v in combo.items())


def _memory_key(case: Case) -> tuple:
    """What a case's memory estimate and element rule depend on (equal keys: the same verdict)."""
    parts = (case.bodies, case.normal, case.rolling, case.discretization, case.effects, case.stresses)
    return (*parts, case.tangential.control()[0], case.friction.mu == 0.0, case.solver.penalty)


def build(base: Case, combo: dict, fits: set | None = None) -> Case:
    """The case of one combination, validated, with the checks ``rollc solve`` makes before solving
    that need no solve (gross sliding: :func:`~rolling_cli.pipeline.check_gross_sliding`; memory
    and the layer's element rule: :func:`~rolling_cli.pipeline.resources.check_resources`). A
    :class:`CaseError` names the swept keys and the values as given. ``fits``: the memory keys
    found to fit so far in this run (a memo; None: check every case)."""
    from ..errors import GrossSlidingError
    from ..pipeline import check_gross_sliding
    from ..pipeline.resources import check_resources as check_memory

    try:
        case = with_overrides(base, combo)
        check_gross_sliding(case)
        key = _memory_key(case)
        if fits is None or key not in fits:  # once per contact system: the estimate costs a millisecond
            check_memory(case)
            if fits is not None and len(fits) < 10_000:
                fits.add(key)
        return case
    except (CaseError, GrossSlidingError) as err:
        raise CaseError(f"sweep case ({given(combo)}): {err}") from None


def validate(base: Case, spec: SweepSpec) -> dict[int, Case]:
    """Build and validate the cases before anything is solved (:func:`build`: the checks ``rollc
    solve`` makes before solving, memory once per contact system): all of them up to
    :data:`VALIDATE_ALL` (returned by sweep index, so a serial run need not build
    them again), else every value of each key (the others at their first value)
    and every corner of the value ranges (returns {}). Cases of a large sweep that
    only fail in the run are recorded as failed cases."""
    fits: set = set()
    if spec.size <= VALIDATE_ALL:
        return {index: build(base, combo, fits) for index, combo in enumerate(spec.combinations())}
    if hasattr(spec, "probes"):  # a family of curves: the ends of its curves
        for index in spec.probes():
            build(base, spec.combination(index), fits)
        return {}
    firsts = {k: v[0] for k, v in zip(spec.keys, spec.values, strict=True)}
    for key, values in zip(spec.keys, spec.values, strict=True):
        picks = range(len(values)) if len(values) <= CHECK_VALUES // 10 else (0, len(values) - 1)
        for i in picks:
            build(base, {**firsts, key: values[i]}, fits)
    ends = [sorted({0, len(v) - 1}) for v in spec.values]
    for corner in itertools.product(*ends):
        if spec.zipped and len(set(corner)) > 1:
            continue
        build(base, {k: v[i] for k, v, i in zip(spec.keys, spec.values, corner, strict=True)}, fits)
    return {}


def bytes_per_case(base: Case, spec: SweepSpec) -> int:
    """Estimated bytes of one case in the file: ten per-node doubles over the largest grid, the
    per-case scalars and texts, and a Newton history of a few dozen rows."""
    elements = base.discretization.contact_elements
    if "discretization.contact_elements" in spec.keys:
        values = spec.values[spec.keys.index("discretization.contact_elements")]
        elements = max(values[0], values[len(values) - 1], *(values if len(values) <= 1000 else ()))
    nodes = elements * (3 if base.discretization.element == "quadratic" else 1)
    return 10 * 8 * nodes + 4096


def check_resources(base: Case, spec: SweepSpec, output: str) -> None:
    """Refuse a sweep that cannot fit: its bookkeeping (:data:`BYTES_IN_MEMORY` per case) against
    half the available memory, and twice its file's estimated size (a rebuild holds two copies)
    against the free space of the output's disk. Names the keys and the estimate. The expansion
    itself costs nothing (it is lazy); a disk that fills up later fails the write cleanly."""
    cases = spec.size
    per_case = bytes_per_case(base, spec)
    counts = ", ".join(f"{k}: {len(v)} values" for k, v in zip(spec.keys, spec.values, strict=True))
    from ..pipeline.resources import available_memory

    memory = available_memory()
    if memory is not None and BYTES_IN_MEMORY * cases > memory // 2:
        raise CaseError(
            f"sweep: {cases} cases ({counts}) need about {_size(BYTES_IN_MEMORY * cases)} of memory to track, "
            f"more than half the {_size(memory)} available; allowed: fewer values"
        )
    try:
        free = shutil.disk_usage(os.path.dirname(os.path.abspath(output))).free
    except OSError:
        return
    if 2 * cases * per_case > free:
        raise CaseError(
            f"sweep: {cases} cases ({counts}) need about {_size(cases * per_case)} of output "
            f"({_size(per_case)} per case, twice that while the file is rebuilt), but {output} has "
            f"{_size(free)} free on its disk; allowed: fewer values, or an output where they fit"
        )


#: Bytes per case a run keeps in memory (which cases are done, solved, failed).
BYTES_IN_MEMORY = 3


def _size(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB", "PB"):
        if n < 1000 or unit == "PB":
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"


def difference(attrs: dict, base_toml: str, spec: SweepSpec, warm: bool) -> str | None:
    """The first way a file's recorded sweep differs from this one (None: the same sweep).

    Compares the format version, the base case key by key, the swept keys,
    ``--zip``, each key's values, and the warm-start setting.
    """
    import tomllib

    from ..files.layout import FORMAT_VERSION

    version = attrs.get("format_version", 1)
    if version != FORMAT_VERSION:
        return f"the file has format version {version}, this rollc writes {FORMAT_VERSION}"
    recorded = _with_defaults(tomllib.loads(attrs.get("case", "")))
    now = tomllib.loads(base_toml)
    for key, (a, b) in _first_difference(recorded, now).items():
        return f"the base case differs at {key}: file {a!r}, now {b!r}"
    try:
        stored = json.loads(attrs.get("sweep", ""))
    except ValueError:
        return "the file records no sweep"
    mine = json.loads(spec.describe())
    if stored["keys"] != mine["keys"]:
        return f"the swept keys differ: file {stored['keys']}, now {mine['keys']}"
    if stored["zip"] != mine["zip"]:
        return f"--zip differs: file {stored['zip']}, now {mine['zip']}"
    for key, a, b in zip(mine["keys"], stored["values"], mine["values"], strict=True):
        if a != b:
            return f"the values of {key} differ: file {_short(a)}, now {_short(b)}"
    if bool(attrs.get("warm_start", 1)) != warm:
        was = "on" if attrs.get("warm_start", 1) else "off"
        return f"warm starts differ: file {was}, now {'on' if warm else 'off'}"
    return None


def _with_defaults(data: dict) -> dict:
    """A recorded case with the keys this rollc's schema adds at their defaults (a file written
    before ``friction.law`` existed is the same sweep); the record as it is if it no longer validates."""
    import tomllib

    from ..case.io import case_from_dict, case_to_toml

    try:
        return tomllib.loads(case_to_toml(case_from_dict(data, None)))
    except CaseError:
        return data


def _short(values) -> str:
    text = values if isinstance(values, str) else json.dumps(values)
    return text if len(text) <= 60 else text[:57] + "..."


def _first_difference(a: dict, b: dict, prefix: str = "") -> dict:
    for key in sorted(set(a) | set(b)):
        dotted = f"{prefix}{key}"
        x, y = a.get(key), b.get(key)
        if isinstance(x, dict) and isinstance(y, dict):
            found = _first_difference(x, y, dotted + ".")
            if found:
                return found
        elif x != y:
            return {dotted: (x, y)}
    return {}
