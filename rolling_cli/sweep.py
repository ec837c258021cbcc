"""Parameter studies: many solves of one case with some dotted keys varied.

Stages: a :class:`SweepSpec` (from ``--set KEY=VALUES`` or the case's
``[sweep]`` table) -> :func:`expand` (every case built and validated before the
first solve) -> chunks of neighbouring cases -> solves (serial, or chunks in
worker processes) -> one HDF5 file, updated after every finished case.

Reuse. Neighbouring cases that share geometry, materials and mesh share one
contact system (influence, slip operator, penalties) and each solve starts
from its neighbour's converged state (warm start). Chunks never depend on the
worker count, and BLAS runs one thread per process in both the serial and the
parallel sweep (:mod:`rolling_cli.blas`), so ``--workers N`` computes exactly
what the serial run computes.

Output layout (format "rolling_cli.sweep"): root attributes (provenance, the
base case, the sweep), one group ``cases/NNNN`` per case in the single-result
layout with the swept values as attributes named by their dotted keys, and a
``summary`` group with one dataset per column. Every update writes a temporary
copy and renames it, so the file on disk is always complete: an interrupted
sweep leaves the cases finished so far, and ``--resume`` continues from them.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import itertools
import json
import math
import multiprocessing
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import h5py
import numpy as np

from . import __version__, blas, pipeline
from .case import Case, case_to_dict, case_to_toml, with_overrides
from .case.validate import convert_scalar, field_metadata
from .errors import CaseError, GrossSlidingError, RollingError
from .io_hdf5 import atomic_h5, write_group
from .path import CasePath
from .references import carter
from .result import utc_timestamp
from .stresses.report import SWEEP_COLUMNS, sweep_columns

FORMAT = "rolling_cli.sweep"
FORMAT_VERSION = 1
#: Cases per chunk: the unit of warm starting and of work given to a process.
CHUNK = 8
SUMMARY_COLUMNS = ("converged", "q_over_mu_p", "creep", "normal_load", "tangential_load", "iterations", "time")


@dataclass(frozen=True)
class SweepSpec:
    """Dotted keys and their values; ``zipped`` pairs them, else their cartesian product."""

    keys: tuple[str, ...]
    values: tuple[tuple, ...]
    zipped: bool = False

    def combinations(self) -> list[dict[str, Any]]:
        """One {key: value} per case, in sweep order."""
        if self.zipped:
            lengths = {len(v) for v in self.values}
            if len(lengths) > 1:
                raise CaseError(
                    f"sweep: --zip needs equally many values per key, got "
                    f"{', '.join(f'{k}: {len(v)}' for k, v in zip(self.keys, self.values, strict=True))}; "
                    "allowed: lists of one length"
                )
            rows = zip(*self.values, strict=True)
        else:
            rows = itertools.product(*self.values)
        return [dict(zip(self.keys, row, strict=True)) for row in rows]

    def describe(self) -> str:
        return json.dumps({"keys": list(self.keys), "values": [list(v) for v in self.values], "zip": self.zipped})


def parse_values(key: str, text: str, source: str = "--set") -> tuple:
    """Values of one swept key: a comma list or a range start:stop:count (inclusive, evenly spaced).

    Each value is converted and checked by the key's schema rules.
    """
    meta = field_metadata(key)
    if not meta or meta.get("kind") == "table":
        raise CaseError(f"{source} {key}={text}: unknown case key; allowed: a dotted scalar key such as friction.mu")
    text = text.strip()
    if text.count(":") == 2 and "," not in text:
        start, stop, count = text.split(":")
        try:
            n = int(count)
            raw = list(np.linspace(float(start), float(stop), n))
        except ValueError:
            raise CaseError(
                f"{source} {key}={text}: not a range; allowed: start:stop:count with numbers and an integer count"
            ) from None
        if n < 1:
            raise CaseError(f"{source} {key}={text}: count {n}; allowed: a count >= 1")
        if meta.get("kind") == "int":
            raw = [round(v) for v in raw]
    else:
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
    """From the CLI's ``--set KEY=VALUES`` options."""
    keys, values = [], []
    for item in settings:
        if "=" not in item:
            raise CaseError(f"--set {item}: no '='; allowed: KEY=VALUES, for example friction.mu=0.1,0.2")
        key, text = item.split("=", 1)
        keys.append(key.strip())
        values.append(parse_values(key.strip(), text))
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
    """The creep-force curve: Q/(mu P) from -0.99 to 0.99, or the creepage over +-1.5 times full slip."""
    if base.friction.mu <= 0.0:
        raise CaseError(f"{base.source or 'case'}: friction.mu = 0: no creep-force curve without friction")
    if kind == "load":
        return SweepSpec(("tangential.q_over_mu_p",), (tuple(np.linspace(-0.99, 0.99, points)),))
    the_plan = pipeline.measured_plan(base)
    full = carter.full_slip_creepage(the_plan.half_width, the_plan.radius, base.friction.mu)
    return SweepSpec(("tangential.creep",), (tuple(np.linspace(-1.5 * full, 1.5 * full, points)),))


def expand(base: Case, spec: SweepSpec) -> list[tuple[dict, Case]]:
    """Every swept case, built and validated before anything is solved."""
    out = []
    for combo in spec.combinations():
        try:
            out.append((combo, with_overrides(base, combo)))
        except CaseError as err:
            shown = ", ".join(f"{k} = {v!r}" for k, v in combo.items())
            raise CaseError(f"sweep case ({shown}): {err}") from None
    return out


def system_key(case: Case) -> str:
    """What a case's contact system depends on: neighbours with equal keys share it."""
    data = case_to_dict(case)
    keep = {k: data.get(k) for k in ("bodies", "normal", "rolling", "discretization", "effects")}
    keep["penalty"] = data.get("solver", {}).get("penalty")
    keep["frictionless"] = case.friction.mu == 0.0
    return json.dumps(keep, sort_keys=True, default=str)


def chunks(items: list[tuple[int, dict, Case]]) -> list[list[tuple[int, dict, Case]]]:
    """Runs of neighbouring cases with one contact system, cut into pieces of at most :data:`CHUNK`."""
    out: list[list] = []
    for _, group in itertools.groupby(items, key=lambda item: system_key(item[2])):
        group = list(group)
        out.extend(group[i : i + CHUNK] for i in range(0, len(group), CHUNK))
    return out


@dataclass
class Record:
    """The outcome of one swept case."""

    index: int
    values: dict
    result: Any = None  # Result when solved (converged or not)
    message: str = ""
    seconds: float = 0.0

    @property
    def converged(self) -> bool:
        return self.result is not None and bool(self.result.attributes.get("converged"))


def solve_chunk(chunk: list[tuple[int, dict, Case]], warm: bool, use_cache: bool) -> Iterator[Record]:
    """Solve a chunk in order on one contact system, each case warm-started along a
    :class:`~rolling_cli.path.CasePath` (the boundary secant of its two predecessors)."""
    path = None
    for index, values, case in chunk:
        start_time = time.perf_counter()
        try:
            if path is None:
                path = CasePath(pipeline.prepare(case, use_cache)[1], warm, use_cache)
            result = path.solve(case, values)
            yield Record(index, values, result, "", time.perf_counter() - start_time)
        except (RollingError, GrossSlidingError) as err:
            yield Record(index, values, None, str(err), time.perf_counter() - start_time)


def _worker(chunk, warm, use_cache):
    return list(solve_chunk(chunk, warm, use_cache))


def default_workers() -> int:
    """One process per core (this machine: 2)."""
    return max(1, os.cpu_count() or 1)


@dataclass
class SweepReport:
    """All records of a sweep (including resumed ones) and timings."""

    records: dict[int, Record] = field(default_factory=dict)
    skipped: int = 0
    seconds: float = 0.0

    @property
    def failed(self) -> list[Record]:
        return [r for r in self.records.values() if not r.converged]


def existing_indices(path: str, combos: list[dict]) -> set[int]:
    """Cases already in a sweep file; raises when the file holds a different sweep."""
    if not os.path.exists(path):
        return set()
    with h5py.File(path, "r") as handle:
        if handle.attrs.get("format") != FORMAT or "cases" not in handle:
            raise CaseError(f"{path}: not a {FORMAT} file; allowed: --resume on a sweep file written by rollc sweep")
        found = set()
        for name, group in handle["cases"].items():
            index = int(name)
            expected = combos[index] if index < len(combos) else None
            stored = {k: group.attrs.get(k) for k in (expected or {})}
            if expected is None or any(not _same(stored[k], v) for k, v in expected.items()):
                raise CaseError(
                    f"{path}: case {name} holds other swept values ({stored}); "
                    "allowed: --resume with the sweep that wrote the file"
                )
            found.add(index)
    return found


def _same(a, b) -> bool:
    if isinstance(b, float) or isinstance(a, float):
        return a is not None and float(a) == float(b)
    return (a.decode() if isinstance(a, bytes) else a) == b


def run(
    base: Case,
    spec: SweepSpec,
    output: str,
    workers: int = 1,
    resume: bool = False,
    warm: bool = True,
    use_cache: bool = True,
    progress: Callable[[int, int, int], None] | None = None,
) -> SweepReport:
    """Run the sweep into ``output``; returns the report (failures included)."""
    t0 = time.perf_counter()
    cases = expand(base, spec)
    combos = [combo for combo, _ in cases]
    done = existing_indices(output, combos) if resume else set()
    report = SweepReport(skipped=len(done))
    writer = SweepWriter(output, spec.keys)
    if resume and os.path.exists(output):
        writer.load_summary()
    else:
        writer.start(base, spec, len(cases))
    todo = [(i, combo, case) for i, (combo, case) in enumerate(cases) if i not in done]

    def finished(record: Record) -> None:
        report.records[record.index] = record
        writer.add(record)
        if progress:
            progress(len(report.records) + report.skipped, len(cases), len(report.failed))

    try:
        if workers <= 1:
            with blas.single_threaded():
                for chunk in chunks(todo):
                    for record in solve_chunk(chunk, warm, use_cache):
                        finished(record)
                        writer.flush()
        else:
            context = multiprocessing.get_context("spawn")
            with (
                _environment(blas.SINGLE_THREAD_ENV),
                concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool,
            ):
                futures = [pool.submit(_worker, chunk, warm, use_cache) for chunk in chunks(todo)]
                try:
                    for future in concurrent.futures.as_completed(futures):
                        for record in future.result():
                            finished(record)
                        writer.flush()
                except BaseException:
                    for future in futures:
                        future.cancel()
                    raise
    finally:
        writer.flush(force=True)
        report.seconds = time.perf_counter() - t0
    return report


@contextlib.contextmanager
def _environment(values: dict[str, str]):
    """Set environment variables for processes started in the body (the workers inherit them)."""
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


class SweepWriter:
    """Appends finished cases to the sweep file, atomically and at most every :data:`FLUSH_SECONDS`.

    Each flush copies the file, adds the new case groups, rewrites the summary
    from rows kept in memory and renames the copy over the file: the file on
    disk is always complete. Ctrl-C and SIGTERM end with a forced flush; a
    SIGKILL loses at most the cases finished since the last flush.
    """

    def __init__(self, path: str, keys: tuple[str, ...]) -> None:
        self.path = path
        self.keys = keys
        self.rows: dict[int, dict] = {}
        self.pending: list[Record] = []
        self.last = 0.0

    def start(self, base: Case, spec: SweepSpec, total: int) -> None:
        with atomic_h5(self.path) as handle:
            handle.attrs["format"] = FORMAT
            handle.attrs["format_version"] = FORMAT_VERSION
            handle.attrs["software_version"] = __version__
            handle.attrs["created"] = utc_timestamp()
            handle.attrs["case"] = case_to_toml(base)
            handle.attrs["sweep"] = spec.describe()
            handle.attrs["sweep_keys"] = json.dumps(list(spec.keys))
            handle.attrs["cases_total"] = total
            handle.create_group("cases")
            self._write_summary(handle)
        self.last = time.monotonic()

    def load_summary(self) -> None:
        """The rows of the cases already in the file (for --resume)."""
        with h5py.File(self.path, "r") as handle:
            for name, group in handle["cases"].items():
                self.rows[int(name)] = self._row(dict(group.attrs), {k: group.attrs.get(k) for k in self.keys})

    def add(self, record: Record) -> None:
        attrs = dict(record.result.attributes) if record.result is not None else {"converged": False}
        attrs["time"] = record.seconds
        attrs["message"] = record.message or attrs.get("message", "")
        self.rows[record.index] = self._row(attrs, record.values)
        self.pending.append(record)

    def flush(self, force: bool = False) -> None:
        if not self.pending or (not force and time.monotonic() - self.last < FLUSH_SECONDS):
            return
        with atomic_h5(self.path, mode="a") as handle:
            cases = handle["cases"]
            for record in self.pending:
                name = f"{record.index:04d}"
                if name in cases:
                    del cases[name]
                group = cases.create_group(name)
                if record.result is not None:
                    write_group(group, record.result)
                else:
                    group.attrs["format"] = "rolling_cli.result"
                    group.attrs["converged"] = False
                group.attrs["message"] = self.rows[record.index]["message"]
                group.attrs["time"] = record.seconds
                for key, value in record.values.items():
                    group.attrs[key] = value
            self._write_summary(handle)
        self.pending.clear()
        self.last = time.monotonic()

    @staticmethod
    def _row(attrs: dict, values: dict) -> dict:
        def get(name, missing):
            value = attrs.get(name, missing)
            return value.decode() if isinstance(value, bytes) else value

        return {
            "values": values,
            "converged": bool(get("converged", False)),
            "q_over_mu_p": float(get("q_over_mu_p", math.nan)),
            "creep": float(get("creep", math.nan)),
            "normal_load": float(get("normal_load", math.nan)),
            "tangential_load": float(get("tangential_load", math.nan)),
            "iterations": int(get("iterations", -1)),
            "time": float(get("time", math.nan)),
            "message": str(get("message", "")),
            "extra": sweep_columns(attrs),  # stress maxima (when computed) and frictional power
        }

    def _write_summary(self, handle) -> None:
        if "summary" in handle:
            del handle["summary"]
        summary = handle.create_group("summary")
        summary.attrs["long_name"] = (
            "one row per case in this file: swept values, outcome, loads, creepage, Newton iterations, seconds"
        )
        order = sorted(self.rows)
        rows = [self.rows[i] for i in order]
        summary.create_dataset("index", data=np.array(order, dtype=np.int64))
        for key in self.keys:
            values = [row["values"].get(key) for row in rows]
            if values and all(isinstance(v, (str, bytes)) for v in values):
                summary.create_dataset(key, data=np.array(values, dtype=h5py.string_dtype()))
            else:
                summary.create_dataset(key, data=np.array(values, dtype=float))
        types = {"converged": bool, "iterations": np.int64}
        for column in SUMMARY_COLUMNS:
            summary.create_dataset(column, data=np.array([row[column] for row in rows], dtype=types.get(column, float)))
        summary.create_dataset("message", data=np.array([row["message"] for row in rows], dtype=h5py.string_dtype()))
        for column in SWEEP_COLUMNS:
            if any(column in row["extra"] for row in rows):
                summary.create_dataset(column, data=np.array([row["extra"].get(column, np.nan) for row in rows]))


#: Seconds between two writes of the sweep file (a forced write ends every sweep).
FLUSH_SECONDS = 1.0


def summary_table(report: SweepReport, keys: tuple[str, ...]) -> str:
    """The end-of-sweep table (one row per case, solved in this run or resumed ones excluded)."""
    head = [*keys, "converged", "Q/(mu P)", "creep", "P", "Q", "iterations", "time [s]"]
    rows = []
    for index in sorted(report.records):
        rec = report.records[index]
        values = [f"{rec.values[k]:.6g}" if isinstance(rec.values[k], float) else str(rec.values[k]) for k in keys]
        if rec.result is not None:
            a = rec.result.attributes
            cells = [
                "yes" if rec.converged else "NO",
                f"{a['q_over_mu_p']:.5f}",
                f"{a['creep']:.5e}",
                f"{a['normal_load']:.6g}",
                f"{a['tangential_load']:.6g}",
                str(a["iterations"]),
            ]
        else:
            cells = ["NO: " + rec.message[:60], "", "", "", "", ""]
        rows.append([*values, *cells, f"{rec.seconds:.3f}"])
    widths = [max(len(str(c)) for c in col) for col in zip(head, *rows, strict=False)]
    lines = ["  ".join(str(c).rjust(w) for c, w in zip(head, widths, strict=False))]
    lines += ["  ".join(str(c).rjust(w) for c, w in zip(row, widths, strict=False)) for row in rows]
    return "\n".join(lines)
