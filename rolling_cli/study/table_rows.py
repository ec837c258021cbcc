"""The rows of a two-axis creep-force table on the sweep machinery: local workers and ``--resume``.

A row (the adaptive sampling in u at one friction coefficient,
:func:`rolling_cli.study.tabulate.sample_row`) is independent of every other:
it starts cold and warm-starts only along itself. So the rows of one pass of
:func:`~rolling_cli.study.tabulate.build_friction` (its first rows, then the
mid-rows of every interval in mu still open) are solved as tasks:

* in this process (:func:`serial`), or in ``--workers N`` local processes
  (:func:`in_workers`: the sweep's pool, :mod:`rolling_cli.study.workers`:
  spawned with one BLAS thread each, dead with their parent), which compute
  the serial run's numbers (the same rows, each solved alike);
* each finished row is appended to a journal beside the output
  (``TABLE.rows``, JSON lines: a header naming the case, the ranges, the
  tolerance and the first pass, then one line per row with its floats written
  exactly), flushed at once: an interrupted ``rollc table`` keeps its finished
  rows, and ``--resume`` takes them from the journal instead of solving them
  again (a header that differs is refused). The journal is removed once the
  table is written. A one-axis table is one row: it is neither split nor
  journalled.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from .. import blas
from ..case import Case, case_to_toml
from ..errors import CaseError

JOURNAL_FORMAT = "rolling_cli.table.rows"
#: Row fields kept in the journal (arrays as lists of floats; JSON writes a float's shortest exact repr).
_ARRAYS = ("nodes", "values", "slopes", "mu_slopes", "intervals")

#: Solves the rows at the given friction coefficients, each within the given budget of solves.
RowSolver = Callable[[list[float], int], list]


@dataclass
class Row:
    """One row of a table: the normalised creepages ``nodes`` u at friction ``mu``, Q/(mu P) ``values``,
    their slopes in u (``slopes``) and in mu at fixed u (``mu_slopes``), the error estimate of each
    interval, the solves made and whether the estimate met the tolerance."""

    mu: float
    nodes: np.ndarray
    values: np.ndarray
    slopes: np.ndarray
    mu_slopes: np.ndarray
    intervals: np.ndarray
    cases: int
    met: bool


def journal_path(output: str) -> str:
    """The journal of a table file's finished rows (module docstring)."""
    return f"{output}.rows"


def header(case: Case, lo: float, hi: float, mu_low: float, mu_high: float, tolerance: float, initial: int) -> dict:
    """What a journal's rows depend on (checked by ``--resume``)."""
    return {
        "format": JOURNAL_FORMAT,
        "case_toml": case_to_toml(case),
        "range": [lo, hi],
        "mu": [mu_low, mu_high],
        "tolerance": tolerance,
        "initial": initial,
    }


def open_journal(
    output: str, case: Case, span: tuple[float, float], friction: tuple[float, float], tolerance: float,
    initial: int, resume: bool, overwrite: bool,
) -> Journal:  # fmt: skip
    """The journal of a two-axis table's finished rows beside ``output``: continued with ``resume``,
    replaced with ``overwrite``, else refused (CaseError) when one is there. ``initial``: the nodes of
    a row's first pass (part of the header)."""
    path = journal_path(output)
    if os.path.exists(path) and not (resume or overwrite):
        raise CaseError(f"{path}: an interrupted table's rows are there; allowed: --resume, or --overwrite")
    return Journal(path, header(case, *span, *friction, tolerance, initial), resume)


class Journal:
    """The rows finished so far (``done``: mu -> row) and the file they are appended to."""

    def __init__(self, path: str, head: dict, resume: bool) -> None:
        self.path, self.done = path, {}
        if resume and os.path.exists(path):
            with open(path, encoding="utf-8") as handle:
                lines = [json.loads(line) for line in handle if line.strip()]
            if not lines or lines[0] != head:
                raise CaseError(
                    f"{path}: --resume refused: the journal holds another table (case, ranges, tolerance); "
                    "allowed: --resume with the request that wrote it, or --overwrite"
                )
            for line in lines[1:]:
                nodes, values, slopes, mu_slopes, intervals = (np.array(line[k], dtype=float) for k in _ARRAYS)
                cases, met = int(line["cases"]), bool(line["met"])
                self.done[line["mu"]] = Row(line["mu"], nodes, values, slopes, mu_slopes, intervals, cases, met)
            self._handle = open(path, "a", encoding="utf-8")  # noqa: SIM115 - closed by close()
        else:
            self._handle = open(path, "w", encoding="utf-8")  # noqa: SIM115 - closed by close()
            self._write(head)

    def add(self, row) -> None:
        """Append a finished row (flushed to the disk before the next is solved)."""
        self.done[row.mu] = row
        self._write({
            "mu": row.mu, **{k: [float(v) for v in getattr(row, k)] for k in _ARRAYS},
            "cases": int(row.cases), "met": bool(row.met),
        })  # fmt: skip

    def _write(self, record: dict) -> None:
        self._handle.write(json.dumps(record) + "\n")
        self._handle.flush()
        os.fsync(self._handle.fileno())

    def close(self, remove: bool = False) -> None:
        """Close the file; ``remove`` it too (the table was written)."""
        self._handle.close()
        if remove:
            with contextlib.suppress(FileNotFoundError):
                os.remove(self.path)


def skipping_done(solve: RowSolver, journal: Journal | None) -> RowSolver:
    """``solve`` for the rows the journal does not hold; the others taken from it."""
    if journal is None:
        return solve

    def rows(friction: list[float], budget: int) -> list:
        missing = [mu for mu in friction if mu not in journal.done]
        if missing:
            solve(missing, budget)  # each row is in the journal once solved
        return [journal.done[mu] for mu in friction]

    return rows


def serial(task: Callable[[float, int], object], journal: Journal | None) -> RowSolver:
    """Rows one after the other in this process, each journalled when finished."""

    def rows(friction: list[float], budget: int) -> list:
        out = []
        for mu in friction:
            out.append(task(mu, budget))
            if journal is not None:
                journal.add(out[-1])
        return out

    return skipping_done(rows, journal)


@contextlib.contextmanager
def in_process(task: Callable[[float, int], object], journal: Journal | None) -> Iterator[RowSolver]:
    """:func:`serial` with one BLAS thread, as the workers run (the sweep's serial path does the
    same): multi-threaded BLAS sums in another order, so only then is the serial table the
    workers' bit for bit, whatever the caller's thread settings."""
    with blas.single_threaded():
        yield serial(task, journal)


@contextlib.contextmanager
def on_cluster(scheduler: str, task: Callable[[float, int], object], journal: Journal | None) -> Iterator[RowSolver]:
    """Rows as tasks of a Dask cluster (``scheduler``: tcp://HOST:PORT or local:N, as ``rollc sweep
    --scheduler``; :func:`rolling_cli.study.distributed.cluster`), each finished row journalled as it
    arrives; on any exception the pending rows are cancelled and the exception re-raised."""
    from .distributed import cluster

    with cluster(scheduler) as (pool, _):
        yield skipping_done(_submitting(pool, task, journal, lambda: None), journal)


def _submitting(pool, task: Callable[[float, int], object], journal: Journal | None, on_error) -> RowSolver:
    """The row solver that submits one task per row to ``pool`` (a concurrent.futures executor) and
    journals each row as it completes; ``on_error()`` runs before an exception propagates."""
    import concurrent.futures

    def rows(friction: list[float], budget: int) -> list:
        futures = {pool.submit(task, mu, budget): mu for mu in friction}
        out = {}
        try:
            for future in concurrent.futures.as_completed(futures):
                out[futures[future]] = future.result()
                if journal is not None:
                    journal.add(out[futures[future]])
        except BaseException:
            for future in futures:
                future.cancel()
            on_error()
            raise
        return [out[mu] for mu in friction]

    return rows


@contextlib.contextmanager
def in_workers(workers: int, task: Callable[[float, int], object], journal: Journal | None) -> Iterator[RowSolver]:
    """Rows as tasks of ``workers`` local processes (the sweep's pool, spawned with one BLAS thread
    each). Each finished row goes to the journal as soon as it arrives, so an interrupt keeps it; on
    any exception the workers are killed (a row is the unit of work) and the exception re-raised."""
    from .sweep import _kill_stragglers
    from .workers import executor

    with blas.single_thread_environment(), executor(workers) as pool:
        yield skipping_done(_submitting(pool, task, journal, lambda: _kill_stragglers(pool)), journal)
