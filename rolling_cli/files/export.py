"""Tables for spreadsheets and multibody codes: ``rollc export``.

* the summary table: one row per case, the case index and swept values first,
  then the outcome (converged, Q/(mu P), creepage, P, Q, mu, iterations,
  residual, time, message), then every other per-case value; for a
  ``--curve`` sweep these first columns are the creep-force curve;
* with ``--fields`` the per-node table: one row per case and node (case index,
  swept values, node, x, then every per-node field).

CSV, one header line of variable names (units: the file's ``units``
attributes; README "Result files"), numbers at full precision, empty cells
for missing values, ``true``/``false`` for flags. Rows are streamed in blocks,
so a table of any length costs bounded memory.
"""

from __future__ import annotations

import csv
import math
import os

import h5py
import numpy as np

from . import outputs
from .legacy import converted
from .reader import case_table, cases_complete, node_variables, swept_names

#: The outcome columns that follow the swept values (those present in the file).
FIRST = (
    "converged",
    "q_over_mu_p",
    "creep",
    "normal_load",
    "tangential_load",
    "mu",
    "iterations",
    "residual",
    "time",
    "message",
)
#: Per-case variables left out of the tables (storage bookkeeping, long JSON).
SKIP = ("nodes", "history_rows", "effects")
BLOCK = 4096


def _cell(value) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (float, np.floating)):
        return "" if math.isnan(value) else repr(float(value))
    if isinstance(value, np.integer):
        return str(int(value))
    return str(value)


def _cells(values: np.ndarray) -> list[str]:
    """CSV cells of an array (floats at full precision, NaN empty)."""
    if values.dtype.kind == "f":
        return ["" if v != v else repr(v) for v in values.tolist()]
    return [_cell(v) for v in values]


def summary_columns(handle) -> list[str]:
    """The summary table's columns, in order."""
    swept = list(swept_names(handle).values())
    present = set(case_table(handle, start=0, stop=0))
    first = [c for c in FIRST if c in present]
    rest = [c for c in present if c not in ("case", *swept, *first, *SKIP)]
    return ["case", *swept, *first, *sorted(rest)]


def write_summary(handle, stream) -> int:
    """The summary table of an open format-2 file as CSV; returns the number of rows."""
    columns = summary_columns(handle)
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(columns)
    n = cases_complete(handle)
    for start in range(0, n, BLOCK):
        table = case_table(handle, columns, start, start + BLOCK)
        writer.writerows(zip(*(_cells(table[c]) for c in columns), strict=True))
    return n


def write_fields(handle, stream) -> int:
    """The per-node table (one row per case and node) as CSV; returns the number of rows."""
    swept = list(swept_names(handle).values())
    fields = node_variables(handle)
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(["case", *swept, "node", *fields])
    rows = 0
    n = cases_complete(handle)
    for start in range(0, n, BLOCK):
        stop = min(n, start + BLOCK)
        table = case_table(handle, ["nodes", *swept], start, stop)
        arrays = {f: handle[f][()] if handle[f].ndim == 1 else handle[f][start:stop] for f in fields}
        for i in range(stop - start):
            count = int(table["nodes"][i])
            head = [_cell(table["case"][i]), *(_cell(table[s][i]) for s in swept)]
            columns = [_cells(arrays[f][:count] if arrays[f].ndim == 1 else arrays[f][i, :count]) for f in fields]
            writer.writerows([*head, str(node), *cells] for node, cells in enumerate(zip(*columns, strict=True)))
            rows += count
    return rows


def fields_path(summary_path: str) -> str:
    """Where ``--fields`` writes the per-node table: beside the summary, ``<stem>_fields.csv``."""
    stem, ext = os.path.splitext(summary_path)
    return f"{stem}_fields{ext or '.csv'}"


def export(path: str, output: str, fields: bool = False, overwrite: bool = False) -> list[str]:
    """Write the summary table of ``path`` to ``output`` (and, with ``fields``, the per-node table
    beside it); returns the files written. Each is written under a temporary name and renamed."""
    written = []
    with converted(path) as source, h5py.File(source, "r") as handle:
        targets = [(output, write_summary)] + ([(fields_path(output), write_fields)] if fields else [])
        for target, write in targets:
            with outputs.atomic_file(target, replace=overwrite) as tmp, open(tmp, "w", newline="") as stream:
                write(handle, stream)
            written.append(target)
    return written
