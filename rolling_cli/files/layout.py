"""The result file layout (format "rolling_cli.result", version 2): names, kinds and metadata.

One layout serves a single ``rollc solve`` result (one case) and a sweep (many),
netCDF-4/CF-compatible HDF5 that ``xarray.open_dataset`` opens as is:

* dimensions ``case`` (unlimited; coordinate ``case`` = the sweep's case index)
  and ``node`` (coordinate ``node`` = 0..n-1);
* every scalar of a result (loads, creepage, overlap, Hertz scales, converged,
  iterations, residual, times, message, ...) is a ``(case)`` variable, and so
  is any scalar another stage adds to ``Result.attributes``;
* the swept keys are ``(case)`` coordinates named by :func:`coordinate_name`
  (``friction.mu`` -> ``friction_mu``; the dotted key is in ``case_key``, the
  key's units in ``units``: :func:`swept`);
* every variable has ``long_name``, every number ``units`` ("1" when
  dimensionless; flags and text none); text is netCDF-4 ``string``
  (variable-length UTF-8: netCDF-C reads it);
* per-node fields (p_n, p_t, delta_n, s_t, state, the Hertz/Carter references,
  any array field of :class:`~rolling_cli.result.Result` over the nodes) are
  ``(case, node)`` variables, NaN-padded (state: -1) when node counts differ;
* the grid ``x`` and ``weights`` are ``(node)`` while every case shares them,
  ``(case, node)`` otherwise;
* group ``convergence``: the Newton histories as a CF indexed ragged array
  (dimension ``row``, ``case_index`` pointing into ``case``), one
  variable per column, the union of the columns of all cases;
* root attributes: ``Conventions``, ``title``, ``history``, ``source``,
  ``format``, ``format_version``, ``software_version``, ``created``, ``case``
  (the resolved case as TOML; the base case of a sweep), for sweeps ``sweep``
  (the specification, JSON), ``sweep_keys``, ``cases_total``, ``warm_start``,
  and ``cases_complete``, written last: rows at or beyond it are not trusted.

This module holds what the writer and the reader share; it does no I/O.
"""

from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..result import QUANTITIES

FORMAT = "rolling_cli.result"
FORMAT_VERSION = 2
#: Format name of version-1 sweep files (one HDF5 group per case); read only.
FORMAT_V1_SWEEP = "rolling_cli.sweep"
CONVENTIONS = "CF-1.8"
CONVERGENCE = "convergence"
#: Root attributes of a result that describe the file, not a case.
PROVENANCE = ("format", "format_version", "software_version", "created")
#: Per-node arrays whose values define the grid: one-dimensional while all cases share them.
GRID = ("x", "weights")
STATE_FILL = -1

#: Per-case scalars: name -> (long name, unit key of Result.units, "s", or None for text and
#: booleans). The result's quantities are declared once, in :mod:`rolling_cli.result.quantities`;
#: the two below describe a file's storage.
SCALARS = {
    **{name: (q.long_name, q.unit) for name, q in QUANTITIES.items() if q.kind != "array"},
    "nodes": ("contact nodes of the case (per-node variables are padded beyond)", "1"),
    "history_rows": ("rows of the case in group convergence", "1"),
}

#: Per-node fields: name -> (long name, unit key). Result.DATASETS adds to these.
NODE_FIELDS = {
    "weights": ("quadrature weight of each node (P = -sum w p_n, Q = sum w p_t)", "length"),
    "hertz_pressure": ("Hertz pressure p(x) >= 0 for the solved load", "stress"),
    "carter_traction": ("Carter tangential traction on A for the solved Q/(mu P)", "stress"),
}

#: Convergence history columns with known meaning.
HISTORY = {
    "stage": ("solver stage", None),
    "iteration": ("iteration within the stage", "1"),
    "residual": ("relative residual", "1"),
    "creep": ("creepage iterate", "1"),
    "overlap": ("overlap iterate", "length"),
    "contact": ("contact nodes", "1"),
    "stick": ("adhesion nodes", "1"),
    "step": ("line-search step length", "1"),
    "edge": ("the contact reaches an end of the potential zone", None),
    "level": ("mesh level of the row", None),
    "linear_solver": ("linear solver of the step", None),
    "reuse_iterations": ("GMRES iterations of a step solved on an earlier step's LU (0: a fresh LU)", "1"),
    "strategy": ("solver strategy of the row", None),
    "tolerance": ("residual tolerance applied at the row", "1"),
}

#: Unit keys of the variables of extra groups (rolling_cli.files.rows.GROUP_HOOKS) that lack units.
GROUP_UNITS = {"element_edges": "length"}

#: Index variables (dimension coordinates and the ragged array's index): long name, unit "1".
INDEXES = {
    "case": "case index in the sweep",
    "node": "contact node index",
    "row": "row of the Newton histories",
    "case_index": "case of the row",
}


#: The dtype of text variables: variable-length UTF-8 strings (h5py.string_dtype(), without importing h5py).
TEXT = np.dtype("O", metadata={"vlen": str})


@dataclass(frozen=True)
class Kind:
    """The storage kind of a variable: ``"f8"``, ``"i8"``, ``"i1"`` (state), ``"bool"`` or ``"str"``.

    ``width``: the bytes of a fixed-width text variable of a file of rollc <= 0.1 (read only; 0 for
    the variable-length text written now, which any text fits, so a longer text changes nothing).
    """

    name: str
    width: int = 0

    @functools.cached_property
    def dtype(self) -> np.dtype:
        """The HDF5/numpy storage type (bool as int8, text as variable-length UTF-8: netCDF-4's
        ``string``, which netCDF-C reads; it aborts on fixed-length HDF5 strings)."""
        if self.name == "str":
            return TEXT
        return np.dtype({"bool": "i1"}.get(self.name, self.name))

    @property
    def fill(self):
        """The value of a missing element: NaN, -1 (counts, state), 0 (false), empty text."""
        return {"f8": math.nan, "i8": -1, "i1": STATE_FILL, "bool": 0, "str": b""}[self.name]


def kind_of(value) -> Kind | None:
    """The kind that stores a Python/numpy scalar; None for None (missing)."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)):
        return Kind("bool")
    if isinstance(value, (int, np.integer)):
        return Kind("i8")
    if isinstance(value, (float, np.floating)):
        return Kind("f8")
    return Kind("str")


#: Python types that a numeric kind stores as they are.
_NUMBERS = (
    ("bool", {bool, np.bool_}),
    ("i8", {int, np.int64, np.int32}),
    ("f8", {float, np.float64, int, np.int64, np.int32}),
)


def column_kind(values: list) -> Kind | None:
    """The kind that stores every value of a column (None: all missing); one pass over the types."""
    types = set(map(type, values))
    types.discard(type(None))
    if not types:
        return None
    if types == {str}:
        return Kind("str")
    for name, allowed in _NUMBERS:
        if types <= allowed:
            return Kind(name)
    kind = None
    for value in values:
        kind = merge(kind, kind_of(value))
    return kind


@functools.lru_cache(maxsize=64)
def dtype_kind(dtype: np.dtype) -> Kind:
    """The kind of a per-node array's dtype: float -> f8, bool -> bool, int8 -> i1 (flags), other ints -> i8."""
    if dtype == np.bool_:
        return Kind("bool")
    if dtype == np.int8:
        return Kind("i1")
    if np.issubdtype(dtype, np.integer):
        return Kind("i8")
    return Kind("f8")


def merge(a: Kind | None, b: Kind | None) -> Kind | None:
    """The kind that holds values of both kinds (numbers promote to f8, anything with text to text)."""
    if a is None or b is None:
        return a or b
    if a == b:
        return a
    if a.name == "str" or b.name == "str":
        return Kind("str")  # variable-length: any text fits
    if a.name == b.name:
        return a
    return Kind("f8")


def encode(value) -> bytes:
    """UTF-8 bytes of a text value; dicts and lists as JSON."""
    if isinstance(value, bytes):
        return value
    if isinstance(value, (dict, list, tuple)):
        value = json.dumps(value)
    return str(value).encode()


def coordinate_name(key: str) -> str:
    """The variable name of a swept dotted key: ``friction.mu`` -> ``friction_mu``.

    A name that a result variable already has (``normal.load`` -> ``normal_load``,
    which holds the solved P) gets ``_set`` appended: ``normal_load_set``.
    """
    name = re.sub(r"\W", "_", key)
    return name + "_set" if name in RESERVED else name


#: Names of the file's own variables, never taken by a swept key.
RESERVED = {"case", "node", "x", "p_n", "p_t", "delta_n", "s_t", "state", *SCALARS, *NODE_FIELDS}


@dataclass
class Var:
    """One variable of the file: dimensions, kind and attributes."""

    dims: tuple[str, ...]
    kind: Kind
    attrs: dict = field(default_factory=dict)


def units_of(unit_key: str | None, units: dict[str, str]) -> str | None:
    """The unit text of a unit key ("length", "stress", ...; "s"; "1"), from a result's units."""
    if unit_key is None:
        return None
    if unit_key == "stress/length":
        return f"{units['stress']}/{units['length']}"
    if unit_key.endswith(")") and "/(" in unit_key:  # a quotient by a compound unit: "length/(force/length)"
        numerator, denominator = unit_key[:-1].split("/(", 1)
        return f"{units_of(numerator, units)}/({units_of(denominator, units)})"
    if unit_key == "moment/length":
        return f"{units['force/length']} {units['length']}"
    return units.get(unit_key, unit_key)


def swept(key: str, units: dict[str, str], text: bool) -> dict:
    """Attributes of the coordinate of the swept dotted ``key``: its case key, a long name from the
    case schema's documentation, and its units (the ``[length]`` etc. of that documentation in the
    case's units; "1" for numbers without one; none for text)."""
    from ..case.validate import field_metadata

    doc = field_metadata(key).get("doc", "")
    found = re.search(r"\[([a-z/^]+)\]", doc)
    attrs = {"long_name": f"swept case key {key}" + (f": {doc}" if doc else ""), "case_key": key}
    if not text:
        attrs["units"] = (units_of(found.group(1), units) or "1") if found else "1"
    return attrs


def describe(name: str, table: dict, units: dict[str, str]) -> dict:
    """``long_name`` and ``units`` attributes of a known variable (none for unknown ones)."""
    if name not in table:
        return {}
    long_name, unit_key = table[name]
    unit = units_of(unit_key, units)
    return {"long_name": long_name, **({"units": unit} if unit else {})}
