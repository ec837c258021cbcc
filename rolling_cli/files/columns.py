"""A commit's rows as typed columns: what the writer's planning and writing both read, gathered once."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .layout import Kind, encode
from .rows import Row


def values_of(kind: Kind, values: list) -> np.ndarray:
    """A column of ``kind`` from Python values (None -> the fill value)."""
    try:  # the common case, in numpy's own loop: no value missing, text in ASCII
        if kind.name == "str":
            return np.array(values, dtype=kind.dtype) if all(type(v) is str for v in values) else _slow(kind, values)
        return np.array(values, dtype=kind.dtype)
    except (TypeError, ValueError, UnicodeEncodeError):
        return _slow(kind, values)


def _slow(kind: Kind, values: list) -> np.ndarray:
    fill = kind.fill
    if kind.name == "str":
        return np.array([fill if v is None else encode(v) for v in values], dtype=kind.dtype)
    if kind.name == "f8":
        return np.array([fill if v is None else float(v) for v in values], dtype=float)
    return np.array([fill if v is None else int(v) for v in values], dtype=kind.dtype)


@dataclass
class Batch:
    """The rows of one commit as columns: what planning and writing both read, gathered once."""

    rows: list[Row]
    coords: dict[str, list]
    scalars: dict[str, list]
    arrays: dict[str, list]
    history_cases: list[int]
    history: dict[str, list]

    @classmethod
    def of(cls, rows: list[Row], keys: tuple[str, ...]) -> Batch:
        """Gather the columns of ``rows`` (``keys``: the swept keys, in order)."""
        cases = [r.index for r in rows for _ in r.history]
        return cls(
            rows,
            {k: [r.coords.get(k) for r in rows] for k in keys},
            _columns([r.scalars for r in rows]),
            _columns([r.arrays for r in rows]),
            cases,
            _columns([e for r in rows for e in r.history]),
        )


def _columns(dicts: list[dict]) -> dict[str, list]:
    """The values of many dicts as one list per key (None where a dict lacks it), in key order.

    Dicts with the same keys in the same order (the usual rows of a sweep) are transposed in one
    step; otherwise each key is looked up in each dict.
    """
    if not dicts:
        return {}
    first = tuple(dicts[0])
    if all(tuple(d) == first for d in dicts):
        return dict(zip(first, map(list, zip(*(d.values() for d in dicts), strict=True)), strict=True))
    names = dict.fromkeys(itertools.chain.from_iterable(dicts))
    return {n: [d.get(n) for d in dicts] for n in names}
