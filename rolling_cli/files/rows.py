"""One case as a row of the result file: the plain values the writer stores.

A :class:`Row` is built from a :class:`~rolling_cli.result.Result` (or from a
failure, which has no arrays) without knowing which fields other stages add:
every scalar of ``Result.attributes`` becomes a per-case variable, every array
field over the nodes (and every array in a dict field such as ``reference``)
a per-node variable, and the Newton history rows keep whatever keys they have.
Extra groups (for example subsurface stresses) travel by name in ``extras``
and are written by the functions registered in :data:`GROUP_HOOKS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .layout import PROVENANCE


@dataclass(frozen=True)
class GroupHook:
    """How an extra group of a result is written and read.

    ``write(group, payload)`` fills an empty h5py group with a result's
    ``payload`` (the value of the Result attribute of the hook's name);
    ``read(group)`` returns it. The group of case ``index`` is
    ``/<name>/case_<index>`` in every file, one case or many.
    """

    write: Callable[[Any, Any], None]
    read: Callable[[Any], Any]


def _write_stresses(group, bodies) -> None:
    from ..stresses.io import write_bodies  # the stress machinery loads only for files that have stresses

    write_bodies(group, bodies)


def _read_stresses(group):
    from ..stresses.io import read_stresses

    return read_stresses(group)


def _write_edges(group, edges) -> None:
    ds = group.create_dataset("element_edges", data=np.asarray(edges, dtype=float))
    ds.attrs["long_name"] = "element edges of the graded contact grid (x, in the solver's frame)"
    ds.make_scale("element_edges")  # its own dimension (netCDF readers need one; no phony dimension)


def _read_edges(group) -> np.ndarray:
    return group["element_edges"][()]


#: name -> hook; a Result whose attribute ``name`` is set (not None, not empty) gets that group.
#: ``element_edges`` (an adaptive or graded grid's edges [length], a per-case array of its own
#: length) is a Result attribute: it is read back into ``Result.attributes``.
GROUP_HOOKS: dict[str, GroupHook] = {
    "stresses": GroupHook(_write_stresses, _read_stresses),
    "element_edges": GroupHook(_write_edges, _read_edges),
}


@dataclass
class Row:
    """The values of one case: ``index`` (its place in the sweep), the swept values by dotted
    key, per-case scalars, per-node arrays (``x`` among them when solved), the history rows
    and the payloads of extra groups."""

    index: int
    coords: dict[str, Any]
    scalars: dict[str, Any]
    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    history: list[dict] = field(default_factory=list)
    extras: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] | None = None


def node_arrays(result, without: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """Every array over the result's nodes: its array fields (but those named in ``without``) and
    the arrays of its dict fields."""
    n = result.x.shape
    out = {}
    for name, value in vars(result).items():
        if isinstance(value, np.ndarray) and value.shape == n and name not in without:
            out[name] = value
        elif isinstance(value, dict) and name != "attributes":
            out.update({k: v for k, v in value.items() if isinstance(v, np.ndarray) and v.shape == n})
    return out


def row_from_result(
    result, index: int = 0, coords: dict | None = None, without: tuple[str, ...] = (), **scalars
) -> Row:
    """The row of a solved case (converged or not); ``scalars`` add or replace per-case values;
    ``without``: array fields left out (a sweep's rows leave out the surface displacements)."""
    values = {k: v for k, v in result.attributes.items() if k not in PROVENANCE and k not in GROUP_HOOKS}
    values.update(scalars)
    values["nodes"] = int(result.x.size)
    values["history_rows"] = len(result.history)
    extras = {name: getattr(result, name) for name in GROUP_HOOKS if _present(getattr(result, name, None))}
    arrays = node_arrays(result, without)
    return Row(index, dict(coords or {}), values, arrays, result.history, extras, result.units)


def _present(payload) -> bool:
    """An extra group is written when its payload is set: not None, and not an empty dict or list."""
    if payload is None:
        return False
    if isinstance(payload, np.ndarray):
        return payload.size > 0
    return len(payload) > 0 if isinstance(payload, (dict, list, tuple)) else True


def row_from_failure(index: int, coords: dict, message: str, seconds: float) -> Row:
    """The row of a case that failed before it had a result (gross sliding, no convergence)."""
    scalars = {"converged": False, "message": message, "time": seconds, "nodes": 0, "history_rows": 0}
    return Row(index, dict(coords), scalars)
