"""Parameter studies: many solves of one case with some dotted keys varied.

Stages: a :class:`~rolling_cli.study.sweep_spec.SweepSpec` (``--set KEY=VALUES``,
the case's ``[sweep]`` table, ``--curve``) -> checks before any solve (the
output path, the disk space, the cases: :mod:`rolling_cli.study.sweep_spec`) ->
the swept values in sweep order, cut into chunks of neighbouring cases that
define one contact system (nothing built yet) -> each chunk built and solved
where it runs (:func:`solve_items`: serially, in local worker processes or on
a Dask cluster) -> the single writer (:class:`~rolling_cli.files.writer.ResultFile`),
which appends rows to the file.

Reuse. Neighbouring cases that share geometry, materials and mesh share one
contact system (influence, slip operator, penalties) and each solve starts
from its neighbour's converged state (warm start). Chunks never depend on the
worker count, and BLAS runs one thread in the serial run, the workers and
the cluster tasks alike (:mod:`rolling_cli.blas`), so any parallel run
computes exactly what the serial run computes. Records come back in chunk
order (a bounded reorder buffer), so the file's rows are in sweep order.

Files. The output is locked for the run, checked before anything is solved,
and written by appending rows (at most every :data:`FLUSH_SECONDS`, and on
exit): a kill at any moment leaves a file that opens, holding the cases
committed so far, and ``--resume`` (which first checks that the file holds
this base case and this sweep) completes it. Ctrl-C and SIGTERM keep every
case finished in a worker; those rows may then be out of sweep order (the
``case`` coordinate always says which case a row is).
"""

from __future__ import annotations

import collections
import concurrent.futures
import contextlib
import functools
import itertools
import json
import os
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field

import h5py
import numpy as np

from .. import blas
from ..case import Case, case_to_toml
from ..errors import CaseError
from ..files import outputs
from ..files.io_hdf5 import root_attributes
from ..files.reader import plain
from ..files.rows import row_from_failure, row_from_result
from ..files.writer import ResultFile
from ..result import SURFACES, utc_timestamp
from . import workers as local_workers
from .chunk import (  # noqa: F401  (the sweep API: chunks are solved there)
    CHUNK,
    SYSTEM_SECTIONS,
    Record,
    chunks,
    combo_key,
    solve_chunk,
    solve_items,
    system_key,
)
from .sweep_spec import (  # noqa: F401  (the sweep API: specifications live in sweep_spec)
    Linspace,
    SweepSpec,
    build,
    check_resources,
    curve_spec,
    difference,
    given,
    parse_values,
    spec_from_options,
    spec_from_table,
    validate,
)


#: Seconds between two commits of the sweep file (the end of a sweep always commits);
#: ``ROLLC_FLUSH_SECONDS`` sets it (smaller: less lost to a kill, more commits).
def _seconds(text: str | None, default: float) -> float:
    try:
        value = float(text) if text is not None else default
    except ValueError:
        return default
    return value if value >= 0.0 else default


FLUSH_SECONDS = _seconds(os.environ.get("ROLLC_FLUSH_SECONDS"), 1.0)
#: The largest share of a sweep's time its commits may take (they are spaced out to keep it), the
#: longest time between two commits, and the most array bytes finished rows may hold before one.
COMMIT_SHARE = 0.02
MAX_SECONDS = 10.0
PENDING_BYTES = 16 << 20
#: Seconds an interrupted parallel sweep waits for its workers' finished cases.
STOP_SECONDS = 30.0
#: Rows of the end-of-sweep table shown at its head and tail (all of them up to twice this).
TABLE_ROWS = 50


def default_workers() -> int:
    """The CPUs this process may use (its affinity set; a batch scheduler's allocation)."""
    return local_workers.default_count()


def _todo(spec: SweepSpec, done: np.ndarray) -> Iterator[list[tuple[int, dict]]]:
    """The cases still to solve as chunks of (index, swept values): runs of one contact system
    (:func:`combo_key`), cut into pieces of at most :data:`CHUNK`; nothing is built here."""
    items = ((i, spec.combination(i)) for i in range(spec.size) if not done[i])
    for _, group in itertools.groupby(items, key=lambda item: (combo_key(item[1]), spec.curve_of(item[0]))):
        while piece := list(itertools.islice(group, CHUNK)):
            yield piece


@dataclass
class SweepReport:
    """What a run did: counts, timings, the rows of the end table, and the cases by index
    (:attr:`records`, read from the file on demand, so memory does not grow with the sweep)."""

    output: str
    keys: tuple[str, ...]
    total: int
    skipped: int = 0
    seconds: float = 0.0
    solve_seconds: float = 0.0
    write_seconds: float = 0.0
    solved_mask: np.ndarray = field(init=False)  # (total,) bool: solved (or failed) in this run
    failed_mask: np.ndarray = field(init=False)  # (total,) bool: failed in this run
    head: list = field(default_factory=list)
    tail: collections.deque = field(default_factory=lambda: collections.deque(maxlen=TABLE_ROWS))
    #: Cases whose result warns that it is outside its model's validity (a/R > 0.1), and the first such warning.
    invalid: int = 0
    first_invalid: str = ""

    def __post_init__(self) -> None:
        self.solved_mask = np.zeros(self.total, dtype=bool)
        self.failed_mask = np.zeros(self.total, dtype=bool)

    @property
    def solved(self) -> int:
        """Cases solved (or failed) in this run."""
        return int(self.solved_mask.sum())

    @property
    def records(self) -> Mapping[int, Record]:
        """The cases of this run by index, read from the output file."""
        return FileRecords(self.output, self.solved_mask, self.keys)

    @property
    def failed(self) -> list[Record]:
        """The failed cases of this run, read from the output file."""
        records = FileRecords(self.output, self.failed_mask, self.keys)
        return [records[i] for i in records]

    def note(self, record: Record) -> None:
        """Count a finished record (and keep what the end table shows of it)."""
        self.solved_mask[record.index] = True
        self.failed_mask[record.index] = not record.converged
        self.solve_seconds += record.seconds
        warning = record.result.attributes.get("validity_warning", "") if record.result is not None else ""
        if warning:
            self.invalid += 1
            self.first_invalid = self.first_invalid or f"sweep case ({given(record.values)}): {warning}"
        if len(self.head) < TABLE_ROWS:
            self.head.append(_table_entry(record))
        else:
            self.tail.append(record)  # the last TABLE_ROWS records, formatted at the end


class FileRecords(Mapping):
    """Records of the cases marked in ``mask``, read from the sweep file when asked for."""

    def __init__(self, path: str, mask: np.ndarray, keys: tuple[str, ...]) -> None:
        self.path, self.mask, self.swept_keys = path, mask, keys
        self._rows: dict[int, int] | None = None

    def __len__(self) -> int:
        return int(self.mask.sum())

    def __iter__(self):
        return iter(np.flatnonzero(self.mask).tolist())

    def __getitem__(self, index: int) -> Record:
        from ..files.reader import case_table, read_case

        if not (0 <= index < self.mask.size and self.mask[index]):
            raise KeyError(index)
        with h5py.File(self.path, "r") as handle:
            if self._rows is None:
                self._table = case_table(handle)  # read once for all the records asked for
                self._rows = {int(c): r for r, c in enumerate(self._table["case"])}
            row = self._rows[index]
            result = read_case(handle, row, self._table)
            solved = int(handle["nodes"][row]) > 0
        attrs = result.attributes
        values = {k: result.swept.get(k) for k in self.swept_keys}
        return Record(index, values, result if solved else None, attrs.get("message", ""), attrs.get("time", 0.0))


class _Sink:
    """Takes finished records: to the writer, the report, the progress.

    Commits happen only when a whole chunk has been added (:meth:`chunk_done`):
    a killed run then leaves whole chunks, and ``--resume`` starts the next
    chunk from its first case, on the warm-start path of the uninterrupted run,
    which it therefore reproduces bit for bit. (Ctrl-C and SIGTERM commit the
    part of a chunk that is finished too.) A commit follows at most every
    FLUSH_SECONDS, and never sooner than
    :data:`COMMIT_SHARE` of the time since the last one allows (the writer
    then costs at most that share of the run, whatever a commit costs here),
    but at least every :data:`MAX_SECONDS` and whenever the waiting rows hold
    :data:`PENDING_BYTES` of arrays (memory stays flat, a kill loses little).
    """

    def __init__(self, writer: ResultFile, report: SweepReport, progress) -> None:
        self.writer, self.report, self.progress = writer, report, progress
        self.last = time.monotonic()
        self.interval = FLUSH_SECONDS
        self.pending_bytes = 0

    def add(self, record: Record, notify: bool = True) -> None:
        """A finished record to the writer (committing when due), the report and the progress."""
        start = time.perf_counter()
        if record.result is not None:
            message = record.message or record.result.attributes.get("message", "")
            row = row_from_result(  # no surface displacements (rollc plot --deformed draws single results)
                record.result, record.index, record.values, SURFACES, time=record.seconds, message=message
            )
        else:
            row = row_from_failure(record.index, record.values, record.message, record.seconds)
        self.writer.add(row)
        self.report.note(record)
        self.pending_bytes += sum(array.nbytes for array in row.arrays.values())
        self.report.write_seconds += time.perf_counter() - start
        if notify and self.progress:
            report = self.report
            self.progress(report.solved + report.skipped, report.total, int(report.failed_mask.sum()))

    def chunk_done(self) -> None:
        """A whole chunk has been added: commit if one is due."""
        if time.monotonic() - self.last >= self.interval or self.pending_bytes >= PENDING_BYTES:
            begun = time.monotonic()
            self.writer.commit()
            self.last = time.monotonic()
            self.interval = min(MAX_SECONDS, max(FLUSH_SECONDS, (self.last - begun) / COMMIT_SHARE))
            self.pending_bytes = 0
            self.report.write_seconds += self.last - begun


def run(
    base: Case,
    spec: SweepSpec,
    output: str,
    workers: int = 1,
    resume: bool = False,
    warm: bool = True,
    use_cache: bool = True,
    progress: Callable[[int, int, int], None] | None = None,
    overwrite: bool = False,
    scheduler: str | None = None,
    command: str | None = None,
) -> SweepReport:
    """Run the sweep into ``output``; returns the report (failures included).

    ``workers`` > 1: local processes; ``scheduler``: a Dask scheduler address
    or ``local:N``. ``overwrite``: replace an existing file; ``resume``:
    continue one (refused when it holds another base case or sweep).
    ``command`` goes into the file's ``history``. Raises CaseError (bad
    input, output refused or locked), WriteError (the file could not be
    written: the committed cases stay), KeyboardInterrupt (after committing).
    """
    t0 = time.perf_counter()
    output = os.fspath(output)
    outputs.check_output(output, inputs=(base.source,), overwrite=overwrite, resume=resume, kind="sweep")
    check_resources(base, spec, output)
    built = validate(base, spec)
    with outputs.claim(output), _executor(workers, scheduler) as (executor, count, task, stop):
        for stale in outputs.stale_temps(output):
            outputs.remove_quietly(stale)
        writer, done = _open(base, spec, output, resume, overwrite, warm, command)
        report = SweepReport(output, spec.keys, spec.size, skipped=int(done.sum()))
        sink = _Sink(writer, report, progress)
        todo = _todo(spec, done)
        try:
            if executor is not None:
                built.clear()  # the workers build their own
                _parallel(executor, count, todo, functools.partial(task, base), warm, use_cache, sink, stop)
            else:
                with blas.single_threaded():
                    for chunk in todo:
                        for record in solve_items(base, chunk, warm, use_cache, built):
                            sink.add(record)
                        sink.chunk_done()
        finally:
            start = time.perf_counter()
            writer.close()
            report.write_seconds += time.perf_counter() - start
            report.seconds = time.perf_counter() - t0
    return report


@contextlib.contextmanager
def _executor(workers: int, scheduler: str | None):
    """Yields (executor, worker count, chunk task, stop function): a Dask cluster, local processes,
    or (None, 1, None, None) for the serial run. Entered before the output is opened, so a cluster
    that cannot be reached leaves no file."""
    if scheduler:
        from . import distributed

        with distributed.cluster(scheduler) as (executor, count):
            yield executor, count, distributed.solve_chunk_task, None
    elif workers > 1:
        with blas.single_thread_environment(), local_workers.executor(workers) as pool:
            yield pool, workers, local_workers.solve_chunk_until_stopped, local_workers.interrupt
    else:
        yield None, 1, None, None


def _open(base, spec, output, resume, overwrite, warm, command) -> tuple[ResultFile, np.ndarray]:
    """The writer, and which cases the file already holds (none unless resuming)."""
    done = np.zeros(spec.size, dtype=bool)
    line = f"{utc_timestamp()} {command or 'rolling_cli.study.sweep.run'}"
    if resume and os.path.exists(output):
        with h5py.File(output, "r") as handle:
            attrs = {k: plain(v) for k, v in handle.attrs.items()}
            why = difference(attrs, case_to_toml(base), spec, warm)
            if why:
                raise CaseError(
                    f"{output}: --resume refused: {why}; allowed: --resume with the case and sweep that wrote it, "
                    "or --overwrite"
                )
            cases = handle["case"][: int(attrs.get("cases_complete", 0))]
        done[cases] = True
        writer = ResultFile.open(output)
        writer.set_attrs(history=f"{writer.attrs.get('history', '')}\n{line}".strip())
        return writer, done
    attrs = root_attributes(base.title or "", case_to_toml(base), command)
    attrs.update(
        history=line,
        sweep=spec.describe(),
        sweep_keys=json.dumps(list(spec.keys)),
        cases_total=spec.size,
        warm_start=bool(warm),
    )
    writer = ResultFile(output, attrs, spec.keys, spec.size, replace=overwrite)
    writer.commit()  # the (empty) file exists from here on
    return writer, done


def _parallel(executor, count: int, todo: Iterator[list], task, warm: bool, use_cache: bool, sink: _Sink, stop=None):
    """Chunks on ``executor`` (at most about two per worker in flight or waiting), records released
    to ``sink`` in chunk order. On any exception (Ctrl-C, SIGTERM): ``stop`` the workers, keep what
    they finished, re-raise."""
    limit = 2 * count + 2
    inflight: dict = {}
    waiting: dict[int, list[Record]] = {}
    next_seq = 0
    source = enumerate(todo)
    exhausted = False
    try:
        while True:
            while not exhausted and len(inflight) + len(waiting) < limit:
                item = next(source, None)
                if item is None:
                    exhausted = True
                    break
                seq, chunk = item
                inflight[executor.submit(task, chunk, warm, use_cache)] = seq
            while next_seq in waiting:
                records = waiting[next_seq]
                while records:  # popped before it is added: an exception in add never loses or repeats one
                    sink.add(records.pop(0))
                del waiting[next_seq]
                next_seq += 1
                sink.chunk_done()
            if not inflight:
                if exhausted and not waiting:
                    return
                continue
            finished, _ = concurrent.futures.wait(inflight, return_when=concurrent.futures.FIRST_COMPLETED)
            for future in finished:
                waiting[inflight.pop(future)] = future.result()
    except BaseException:
        for future in inflight:
            future.cancel()
        if stop is not None:
            stop(executor)
        running = [f for f in inflight if not f.cancelled()]
        finished, _ = concurrent.futures.wait(running, timeout=STOP_SECONDS)
        for future in finished:
            with contextlib.suppress(Exception):
                waiting[inflight[future]] = future.result()
        for seq in sorted(waiting):
            for record in waiting[seq]:
                sink.add(record, notify=False)
        _kill_stragglers(executor)
        raise


def _kill_stragglers(executor) -> None:
    """Local workers still running after the stop wait are killed, so the exit is prompt (they are
    this process's children: ``multiprocessing.active_children``)."""
    import multiprocessing

    for process in multiprocessing.active_children():
        with contextlib.suppress(Exception):
            process.kill()
    with contextlib.suppress(Exception):
        executor.shutdown(wait=False, cancel_futures=True)


_TABLE_ATTRS = ("q_over_mu_p", "creep", "normal_load", "tangential_load", "iterations")


def _table_entry(record: Record) -> tuple:
    """What the end table shows of a record (formatted only if shown; no arrays kept)."""
    attrs = record.result.attributes if record.result is not None else None
    values = tuple(attrs[k] for k in _TABLE_ATTRS) if attrs is not None else None
    return record.values, record.converged, values, record.message, record.seconds


def _table_row(entry: tuple, keys: tuple[str, ...]) -> list[str]:
    swept, converged, values, message, seconds = entry
    cells = [f"{swept[k]:.6g}" if isinstance(swept[k], float) else str(swept[k]) for k in keys]
    if values is not None:
        q, creep, load, tangential, iterations = values
        cells += ["yes" if converged else "NO", f"{q:.5f}", f"{creep:.5e}", f"{load:.6g}", f"{tangential:.6g}"]
        cells.append(str(iterations))
    else:
        cells += ["NO: " + message[:60], "", "", "", "", ""]
    return [*cells, f"{seconds:.3f}"]


def summary_table(report: SweepReport, keys: tuple[str, ...]) -> str:
    """The end-of-sweep table: one row per case solved in this run (resumed ones excluded); of a
    long run its first and last :data:`TABLE_ROWS` rows (``rollc export`` writes them all)."""
    head = [*keys, "converged", "Q/(mu P)", "creep", "P", "Q", "iterations", "time [s]"]
    first = [_table_row(entry, keys) for entry in report.head]
    last = [_table_row(_table_entry(record), keys) for record in report.tail]
    rows = first + last
    widths = [max(len(str(c)) for c in col) for col in zip(head, *rows, strict=False)]

    def line(cells):
        return "  ".join(str(c).rjust(w) for c, w in zip(cells, widths, strict=False))

    lines = [line(head)] + [line(r) for r in first]
    omitted = report.solved - len(first) - len(last)
    if omitted > 0:
        lines.append(f"  ... {omitted} more rows (rollc export {report.output} writes every row)")
    lines += [line(r) for r in last]
    return "\n".join(lines)
