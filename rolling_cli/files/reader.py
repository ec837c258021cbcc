"""Reading result files: format 2 (:mod:`rolling_cli.files.layout`) and format 1 (read only).

Only the first ``cases_complete`` rows of a format-2 file are read: rows
beyond it belong to a write that did not finish. Functions take an open h5py
file (or group) so a caller reads several things with one open.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
from typing import Any

import h5py
import numpy as np

from ..result import QUANTITIES, Result
from .layout import CONVERGENCE, FORMAT, FORMAT_V1_SWEEP, PROVENANCE
from .rows import GROUP_HOOKS

log = logging.getLogger(__name__)

#: Per-case variables that describe the file's storage, not the solve.
STORAGE = ("nodes", "history_rows")


def plain(value):
    """An HDF5 attribute or element as a plain Python value (bytes decoded, numpy scalars unwrapped)."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def version(handle) -> int:
    """The format version of an open file: 1 or 2 (ValueError when it is no rollc file)."""
    fmt = plain(handle.attrs.get("format"))
    if fmt not in (FORMAT, FORMAT_V1_SWEEP):
        raise ValueError(f"not a rolling_cli file (format = {fmt!r})")
    return int(handle.attrs.get("format_version", 1))


def is_sweep(handle) -> bool:
    """A sweep file (format 2: it records a sweep specification; format 1: its own format name)."""
    if plain(handle.attrs.get("format")) == FORMAT_V1_SWEEP:
        return True
    return version(handle) >= 2 and "sweep" in handle.attrs


def cases_complete(handle) -> int:
    """The number of trusted cases (rows) of a file."""
    if version(handle) == 1:
        return len(handle["cases"]) if "cases" in handle else 1
    return int(handle.attrs.get("cases_complete", 0))


def swept_names(handle) -> dict[str, str]:
    """Dotted swept key -> the name of its (case) coordinate, in sweep order."""
    keys = json.loads(plain(handle.attrs.get("sweep_keys")) or "[]")
    found = {
        plain(obj.attrs["case_key"]): name
        for name, obj in handle.items()
        if isinstance(obj, h5py.Dataset) and "case_key" in obj.attrs
    }
    return {key: found[key] for key in keys if key in found}


def _decode(ds, values: np.ndarray) -> np.ndarray:
    if ds.dtype.kind == "S" or (ds.dtype.kind == "O" and values.size and isinstance(values.flat[0], bytes)):
        return np.array([v.decode() for v in values], dtype=object)
    if plain(ds.attrs.get("dtype")) == "bool":
        return values.astype(bool)
    return values


def case_table(handle, names=None, start: int = 0, stop: int | None = None) -> dict[str, np.ndarray]:
    """The (case) variables of rows ``start:stop`` (default: all trusted rows), decoded:
    booleans as bool, text as str. ``names`` limits the variables; the ``case`` index comes first."""
    n = cases_complete(handle)
    stop = n if stop is None else min(stop, n)
    out = {"case": handle["case"][start:stop]}
    for name, ds in handle.items():
        if name == "case" or not isinstance(ds, h5py.Dataset) or ds.ndim != 1 or _dims(ds) != ("case",):
            continue
        if names is None or name in names:
            out[name] = _decode(ds, ds[start:stop])
    return out


def _dims(ds) -> tuple[str, ...]:
    return tuple(plain(ds.dims[i].keys()[0]) if ds.dims[i].keys() else "" for i in range(ds.ndim))


def node_variables(handle) -> list[str]:
    """Names of the per-node variables ((case, node) or (node)), x first."""
    names = [
        name for name, ds in handle.items() if isinstance(ds, h5py.Dataset) and name != "node" and "node" in _dims(ds)
    ]
    return sorted(names, key=lambda n: (n != "x", n != "weights"))


def node_values(handle, name: str, row: int, count: int | None = None) -> np.ndarray:
    """A per-node variable of one row (its first ``count`` nodes)."""
    ds = handle[name]
    values = ds[()] if ds.ndim == 1 else ds[row]
    values = _decode(ds, values)
    return values if count is None else values[:count]


def read_case(handle, row: int = 0, table: dict | None = None) -> Result:
    """The Result of one row of a format-2 file (a format-1 file: its case group ``row``).

    ``table``: the file's :func:`case_table`, when the caller reads many rows (read once)."""
    if version(handle) == 1:
        group = handle if "x" in handle else handle["cases"][sorted(handle["cases"])[row]]
        return read_group(group)
    if not 0 <= row < cases_complete(handle):
        raise IndexError(f"row {row} beyond the {cases_complete(handle)} complete cases")
    attrs = {k: plain(handle.attrs[k]) for k in PROVENANCE if k in handle.attrs}
    keys = {name: key for key, name in swept_names(handle).items()}
    swept = {}
    one = table is None
    rows = case_table(handle, start=row, stop=row + 1) if table is None else table
    for name, values in rows.items():
        if name in keys:
            swept[keys[name]] = plain(values[0 if one else row])
        elif name not in STORAGE and name != "case":
            attrs[name] = plain(values[0 if one else row])
    count = int(handle["nodes"][row]) if "nodes" in handle else None
    arrays: dict[str, Any] = {}
    reference = {}
    fields = {f.name for f in dataclasses.fields(Result)}
    for name in node_variables(handle):
        values = node_values(handle, name, row, count)
        if name in fields:
            arrays[name] = values
        elif not (values.dtype.kind == "f" and np.all(np.isnan(values))):
            reference[name] = values
    history = _history(handle, row)
    result = Result(
        **arrays,
        history=history,
        reference=reference,
        case_toml=plain(handle.attrs.get("case", "")),
        swept=swept,
    )
    _record(result, attrs)
    for name, hook in GROUP_HOOKS.items():
        group_name = f"{name}/case_{int(handle['case'][row]):06d}"
        if group_name in handle:
            setattr(result, name, hook.read(handle[group_name]))
    return result


def _record(result: Result, values: dict) -> None:
    """Record the file's values of declared quantities; others (a newer version's, or an older
    one's that this version no longer declares) are left out, and logged."""
    known = {k: v for k, v in values.items() if k in QUANTITIES}
    result.record(**known)
    result.swept.update({k: v for k, v in values.items() if "." in k})  # format 1: swept keys as attributes
    if len(known) + sum("." in k for k in values) < len(values):
        log.debug("not declared in this version, not read: %s", ", ".join(sorted(set(values) - set(known))))


def _history(handle, row: int) -> list[dict]:
    if CONVERGENCE not in handle or "history_rows" not in handle:
        return []
    counts = handle["history_rows"][: row + 1]
    start, count = int(counts[:-1].sum()), int(counts[-1])
    group = handle[CONVERGENCE]
    columns = {
        name: _decode(ds, ds[start : start + count])
        for name, ds in group.items()
        if isinstance(ds, h5py.Dataset) and name not in ("row", "case_index")
    }
    return [{name: plain(values[i]) for name, values in columns.items()} for i in range(count)]


def read_group(node) -> Result:
    """A result from a format-1 group (a result file's root, or a case group of a format-1 sweep)."""
    if plain(node.attrs.get("format")) != FORMAT:
        raise ValueError(f"not a {FORMAT} group (format = {node.attrs.get('format')!r})")
    attrs = {k: plain(v) for k, v in node.attrs.items() if k != "case"}
    history = []
    if "convergence" in node:
        conv = node["convergence"]
        cols = {c: conv[c][()] for c in conv}
        n = len(cols.get("residual", []))
        history = [{c: plain(v[i]) for c, v in cols.items()} for i in range(n)]
    reference = {k: v[()] for k, v in node["reference"].items()} if "reference" in node else {}
    result = Result(
        x=node["x"][()],
        weights=node["weights"][()],
        p_n=node["p_n"][()],
        p_t=node["p_t"][()],
        delta_n=node["delta_n"][()],
        s_t=node["s_t"][()],
        state=node["state"][()],
        history=history,
        reference=reference,
        case_toml=plain(node.attrs.get("case", "")),
    )
    _record(result, attrs)
    return result


def read_result(path: str | os.PathLike, row: int = 0) -> Result:
    """One result from a file: a ``rollc solve`` result, or row ``row`` of a sweep (any format)."""
    with h5py.File(path, "r") as handle:
        return read_case(handle, row)
