"""One chunk of a sweep: neighbouring cases on one contact system, built and solved in order,
each warm-started along a :class:`~rolling_cli.study.path.CasePath`. A chunk runs where it is sent:
in the sweep's process, a local worker process (:mod:`rolling_cli.study.workers`) or a Dask task
(:mod:`rolling_cli.study.distributed`); its records go back to the sweep (:mod:`rolling_cli.study.sweep`)."""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from .. import pipeline
from ..case import Case
from ..errors import CaseError, GrossSlidingError, RollingError
from ..pipeline.resources import check_resources as check_memory
from .path import CasePath
from .sweep_spec import build, given

#: Cases per chunk: the unit of warm starting and of work given to a process.
CHUNK = 8


def system_key(case: Case) -> tuple:
    """What a case's contact system depends on: neighbours with equal keys share it."""
    parts = (case.bodies, case.normal, case.rolling, case.discretization, case.effects)
    return (*parts, case.solver.penalty, case.friction.mu == 0.0)


#: Sections of a case whose keys define the contact system (with solver.penalty and mu = 0 or not).
SYSTEM_SECTIONS = ("bodies", "normal", "rolling", "discretization", "effects")


def combo_key(combo: dict) -> tuple:
    """:func:`system_key` of a swept case from its swept values alone (the rest is the base case's):
    equal keys, one contact system. Lets cases be grouped without building them."""
    key = []
    for dotted, value in combo.items():
        if dotted.split(".")[0] in SYSTEM_SECTIONS or dotted == "solver.penalty":
            key.append((dotted, value))
        elif dotted == "friction.mu":
            key.append((dotted, value == 0.0))
    return tuple(key)


def chunks(items: Iterable[tuple[int, dict, Case]]) -> Iterator[list[tuple[int, dict, Case]]]:
    """Runs of neighbouring cases with one contact system, cut into pieces of at most :data:`CHUNK` (lazily)."""
    for _, group in itertools.groupby(items, key=lambda item: system_key(item[2])):
        while piece := list(itertools.islice(group, CHUNK)):
            yield piece


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
        """Solved and converged."""
        return self.result is not None and bool(self.result.attributes.get("converged"))


def solve_chunk(chunk: list[tuple[int, dict, Case]], warm: bool, use_cache: bool) -> Iterator[Record]:
    """Solve a chunk in order on one contact system, each case warm-started along a
    :class:`~rolling_cli.study.path.CasePath` (the boundary secant of its two predecessors)."""
    path = None
    for index, values, case in chunk:
        start_time = time.perf_counter()
        try:
            if path is None:  # one contact system per chunk: its memory is checked before it is built
                check_memory(case)
                path = CasePath(pipeline.prepare(case, use_cache)[1], warm, use_cache)
            result = path.solve(case, values)
            yield Record(index, values, result, "", time.perf_counter() - start_time)
        except (RollingError, GrossSlidingError) as err:  # quoted with the values as given (a path's step may differ)
            message = f"sweep case ({given(values)}): {err}"
            yield Record(index, values, None, message, time.perf_counter() - start_time)


def solve_items(
    base: Case, items: list[tuple[int, dict]], warm: bool, use_cache: bool, built: dict[int, Case] | None = None
) -> Iterator[Record]:
    """Build the cases of a chunk (or take them from ``built``, the cases :func:`validate` built, by
    sweep index) and solve them with :func:`solve_chunk`; a case that fails to build (a large sweep
    validates only its values and corners up front) is a failed record, and the warm-start chain
    restarts after it. Runs where the chunk runs: in this process, a worker process or a cluster task."""
    run: list[tuple[int, dict, Case]] = []
    fits: set = set()
    for index, combo in items:
        try:
            case = built.pop(index, None) if built else None
            run.append((index, combo, case if case is not None else build(base, combo, fits)))
        except CaseError as err:
            yield from solve_chunk(run, warm, use_cache)
            run = []
            yield Record(index, combo, None, str(err), 0.0)
    yield from solve_chunk(run, warm, use_cache)
