"""HDF5 storage of the result layout: datasets with their chunks, dimension scales and
attributes (through h5py's low-level API where the high-level one costs), row copies and
extents. :mod:`rolling_cli.files.writer` decides what to write and when; this module writes it."""

from __future__ import annotations

import os

import h5py
import numpy as np

from .layout import CONVERGENCE, GROUP_UNITS, Kind, Var, merge, units_of
from .reader import plain
from .rows import GROUP_HOOKS

#: Bytes per chunk of the (case, node) variables; (case) variables take CHUNK_ROWS rows.
CHUNK_BYTES = 1 << 16
CHUNK_ROWS = 1024
#: Bytes per block when a rebuild copies rows (its memory does not grow with the file).
COPY_BYTES = 1 << 22


def extend(handle, schema: dict, history: dict, rows: int, history_rows: int) -> None:
    """Every (case) and (case, node) variable ``rows`` long, every variable of the histories
    ``history_rows`` long: the file shows plain netCDF readers the committed rows only."""
    names = ["case", *(name for name, var in schema.items() if var.dims[0] == "case")]
    group = handle[CONVERGENCE]
    for parent, targets, length in ((handle, names, rows), (group, ["row", "case_index", *history], history_rows)):
        for name in targets:
            dataset = h5py.h5d.open(parent.id, name.encode())
            if dataset.shape[0] != length:
                dataset.set_extent((length, *dataset.shape[1:]))


def write_group(group, name: str, payload, units: dict[str, str]) -> None:
    """An extra group through its hook; its variables that have no units get those of
    :data:`~rolling_cli.files.layout.GROUP_UNITS` (the hooks do not know the case's units)."""
    GROUP_HOOKS[name].write(group, payload)
    for ds in datasets(group):
        key = GROUP_UNITS.get(ds.name.rsplit("/", 1)[-1])
        if key and "units" not in ds.attrs:
            ds.attrs["units"] = units_of(key, units)


def datasets(group) -> list:
    """The datasets of ``group`` and of its subgroups."""
    found: list = []
    group.visititems(lambda _, obj: found.append(obj) if isinstance(obj, h5py.Dataset) else None)
    return found


def put(group, name: str, start: int, values: np.ndarray) -> None:
    """Write ``values`` into rows ``start``.. (all columns from the first) of a dataset: one HDF5 call."""
    if values.shape[0] == 0:
        return
    dataset = h5py.h5d.open(group.id, name.encode())
    space = dataset.get_space()
    space.select_hyperslab((start,) + (0,) * (values.ndim - 1), values.shape)
    dataset.write(h5py.h5s.create_simple(values.shape), space, np.ascontiguousarray(values))


def get(group, name: str, start: int, stop: int, columns: int | None = None) -> np.ndarray:
    """Rows ``start:stop`` (and the first ``columns`` columns) of a dataset: one HDF5 call."""
    dataset = h5py.h5d.open(group.id, name.encode())
    space = dataset.get_space()
    shape = (stop - start, *((columns,) if space.shape[1:] and columns is not None else space.shape[1:]))
    out = np.empty(shape, dtype=dataset.dtype)
    if shape[0] and all(shape):
        space.select_hyperslab((start,) + (0,) * (len(shape) - 1), shape)
        dataset.read(h5py.h5s.create_simple(shape), space, out)
    return out


def copy_rows(old, new, name: str, n: int, columns: int, dtype=None, order: np.ndarray | None = None) -> None:
    """The first ``n`` rows (and ``columns`` columns) of a dataset of ``old`` into ``new``, in blocks of
    :data:`COPY_BYTES` (the memory of a rebuild does not grow with the file); with ``order``, row i
    of ``new`` is row ``order[i]`` of ``old``."""
    row_bytes = max(1, columns) * 16
    step = max(1, COPY_BYTES // row_bytes)
    for start in range(0, n, step):
        if order is None:
            block = get(old, name, start, min(n, start + step), columns or None)
        else:
            block = gather(old[name], order[start : start + step], columns or None)
        put(new, name, start, block if dtype is None or block.dtype == dtype else block.astype(dtype))


def gather(dataset, rows: np.ndarray, columns: int | None) -> np.ndarray:
    """Rows ``rows`` (distinct, in any order) of a dataset, and its first ``columns`` columns."""
    where = np.argsort(rows)
    picked = dataset[rows[where]] if dataset.ndim == 1 else dataset[rows[where], : columns or dataset.shape[1]]
    block = np.empty(picked.shape, dtype=dataset.dtype)
    block[where] = picked
    return block


def ragged_order(counts: np.ndarray, order: np.ndarray) -> np.ndarray:
    """The history rows in the new case order: case ``order[i]``'s rows (``counts`` of each old case,
    stored contiguously in the old order) come i-th."""
    counts = counts.astype(np.int64)
    starts = np.cumsum(counts) - counts
    lengths = counts[order]
    return np.repeat(starts[order] - (np.cumsum(lengths) - lengths), lengths) + np.arange(lengths.sum())


def widen(table: dict[str, Var], name: str, kind: Kind | None, dims: tuple[str, ...], attrs: dict) -> None:
    """Make ``table[name]`` hold values of ``kind`` with ``dims`` (a new Var only when something changes)."""
    old = table.get(name)
    if old is None:
        if kind is not None:
            table[name] = Var(dims, kind, attrs)
        return
    new = merge(old.kind, kind) or old.kind
    if new != old.kind or dims != old.dims:
        table[name] = Var(dims, new, old.attrs)


def skeleton(path: str) -> None:
    """An empty HDF5 file: creation order tracked (as netCDF-4 does), small chunk-index nodes."""
    fcpl = h5py.h5p.create(h5py.h5p.FILE_CREATE)
    order = h5py.h5p.CRT_ORDER_TRACKED | h5py.h5p.CRT_ORDER_INDEXED
    fcpl.set_link_creation_order(order)
    fcpl.set_attr_creation_order(order)
    fapl = h5py.h5p.create(h5py.h5p.FILE_ACCESS)
    fapl.set_libver_bounds(h5py.h5f.LIBVER_EARLIEST, h5py.h5f.LIBVER_V18)
    h5py.h5f.create(os.fsencode(path), h5py.h5f.ACC_TRUNC, fcpl=fcpl, fapl=fapl).close()


def nbytes(payload) -> int:
    if isinstance(payload, np.ndarray):
        return payload.nbytes
    if isinstance(payload, dict):
        return sum(nbytes(v) for v in payload.values())
    return 1 << 12


def chunk_layout(var: Var, plan: dict) -> tuple[tuple, tuple | None]:
    """Capacity shape and chunk shape of a variable (None: contiguous, for the (node) variables and
    for files of a fixed number of cases, such as one ``rollc solve`` result)."""
    sizes = {"case": plan["case_cap"], "node": plan["node_cap"], "row": plan["hist_cap"]}
    shape = tuple(sizes[d] for d in var.dims)
    if var.dims == ("node",) or (plan.get("fixed") and extent(var, plan) == shape):
        return shape, None
    if var.dims == ("case", "node"):
        rows = max(1, min(CHUNK_BYTES // max(1, plan["node_cap"] * var.kind.dtype.itemsize), max(shape[0], 1)))
        return shape, (rows, max(1, plan["node_cap"]))
    rows = CHUNK_ROWS * (16 if var.dims == ("row",) else 1)
    return shape, (max(1, min(rows, shape[0])),)


def extent(var: Var, plan: dict) -> tuple:
    """The shape a variable has in the file: its ``case`` and ``row`` dimensions as long as the
    committed rows (plain netCDF readers see no padding rows), the ``node`` one the capacity."""
    sizes = {"case": plan["case_rows"], "node": plan["node_cap"], "row": plan["hist_rows"]}
    return tuple(sizes[d] for d in var.dims)


def dataset(group, name: str, var: Var, plan: dict):
    """Create one variable: chunked (its chunks sized for the capacity, those within the committed
    rows allocated now), fill set; its shape is :func:`extent`."""
    capacity, chunks = chunk_layout(var, plan)
    shape = extent(var, plan)
    maxshape = tuple(None if d in ("case", "row") else s for d, s in zip(var.dims, capacity, strict=True))
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_alloc_time(h5py.h5d.ALLOC_TIME_EARLY)
    if plan.get("copied") and var.kind.name != "str":  # HDF5 fills variable-length data always
        dcpl.set_fill_time(h5py.h5d.FILL_TIME_NEVER)
    if chunks is None and var.kind.dtype.kind in "iuf":
        ds = contiguous(group, name, shape, var.kind.dtype, var.kind.fill, dcpl)
    else:
        ds = group.create_dataset(
            name,
            shape=shape,
            maxshape=maxshape if chunks else None,
            chunks=chunks,
            dtype=var.kind.dtype,
            fillvalue=None if var.kind.name == "str" else var.kind.fill,  # text: netCDF-C's own (NULL, read as "")
            dcpl=dcpl,
            track_times=False,
        )
    attrs = dict(var.attrs)
    if var.kind.name == "bool":
        attrs.update(dtype="bool", flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="false true")
    elif name == "state":
        from ..result import STATE_NAMES

        attrs["flag_values"] = np.array(sorted(STATE_NAMES), dtype=np.int8)
        attrs["flag_meanings"] = " ".join(STATE_NAMES[k] for k in sorted(STATE_NAMES))
        attrs["valid_range"] = np.array([min(STATE_NAMES), max(STATE_NAMES)], dtype=np.int8)
    set_attrs(ds, attrs)
    return ds


def attach(ds, dims: tuple[str, ...], scales: dict) -> None:
    ids = {"case": 0, "node": 1, "row": 2}
    for axis, dim in enumerate(dims):
        ds.dims[axis].attach_scale(scales[dim])
    set_attrs(ds, {"_Netcdf4Coordinates": np.array([ids[d] for d in dims], dtype=np.int32)})


#: HDF5 types of the numeric datasets, per dtype (what ``create_dataset`` derives for each anew).
_DATASET_TYPES: dict = {}


def contiguous(group, name: str, shape: tuple, dtype: np.dtype, fill, dcpl) -> h5py.Dataset:
    """A contiguous numeric dataset, as ``group.create_dataset(name, shape=shape, dtype=dtype,
    fillvalue=fill, dcpl=dcpl, track_times=False)`` makes it (the same property list, type, space and
    link), through h5py's low-level API: that call's argument checks and type derivation are ~40 % of
    its time for the ~77 small datasets of a result file."""
    tid = _DATASET_TYPES.get(dtype.str)
    if tid is None:
        tid = _DATASET_TYPES[dtype.str] = h5py.h5t.py_create(dtype, logical=1)
    dcpl.set_fill_value(np.array(fill))
    dcpl.set_obj_track_times(False)
    order = h5py.get_config().track_order  # create_dataset's default for track_order
    dcpl.set_attr_creation_order(h5py.h5p.CRT_ORDER_TRACKED | h5py.h5p.CRT_ORDER_INDEXED if order else 0)
    space = h5py.h5s.create_simple(shape, None)
    return h5py.Dataset(h5py.h5d.create(group.id, name.encode(), tid, space, dcpl=dcpl))


#: h5py's type for a Python str attribute: variable-length UTF-8.
_STR = h5py.string_dtype()
#: (file type, memory type) of an attribute, per value kind: what h5py's ``attrs[name] = value`` derives
#: (``h5t.py_create`` logical and bit-for-bit) for every attribute anew, derived once.
_ATTR_TYPES: dict = {}
_SCALAR_SPACE = None


def set_attrs(obj, attrs: dict) -> None:
    """Write attributes as ``obj.attrs[name] = value`` does (same HDF5 types, shapes and values, an
    existing attribute replaced), through h5py's low-level API with the types derived once per kind:
    about half the time of the high-level path (which guesses the dtype and derives both HDF5 types
    anew for each attribute; measured on 300 attributes, 18 -> 10 ms), for the ~220 attributes of a
    result file. Values other than a str or a numeric (int, unsigned, float) numpy scalar, array or
    Python number take the high-level path unchanged.
    """
    global _SCALAR_SPACE
    oid = obj.id
    for name, value in attrs.items():
        if type(value) is str:
            data, key = np.array(value, dtype=_STR), "str"
        elif isinstance(value, (int, float, np.ndarray, np.number)) and not isinstance(value, bool):
            data = np.asarray(value, order="C")
            key = data.dtype.str
            if data.dtype.kind not in "iuf":
                obj.attrs[name] = value
                continue
        else:
            obj.attrs[name] = value
            continue
        types = _ATTR_TYPES.get(key)
        if types is None:
            types = _ATTR_TYPES[key] = (h5py.h5t.py_create(data.dtype, logical=True), h5py.h5t.py_create(data.dtype))
        if data.shape:
            space = h5py.h5s.create_simple(data.shape)
        else:
            if _SCALAR_SPACE is None:
                _SCALAR_SPACE = h5py.h5s.create_simple(())
            space = _SCALAR_SPACE
        encoded = name.encode()
        if h5py.h5a.exists(oid, encoded):
            h5py.h5a.delete(oid, encoded)
        attr = h5py.h5a.create(oid, encoded, types[0], space)
        try:
            attr.write(data, mtype=types[1])
        except BaseException:
            attr.close()
            h5py.h5a.delete(oid, encoded)
            raise
        attr.close()


#: The unit names a file uses unless its variables say otherwise.
DEFAULT_UNITS = {"length": "length", "stress": "stress", "force/length": "force/length", "1": "1"}
_INTERNAL = {"DIMENSION_LIST", "REFERENCE_LIST", "CLASS", "NAME", "_Netcdf4Dimid", "_Netcdf4Coordinates"}


def read_schema(group, skip) -> dict[str, Var]:
    """The variables of an existing file's ``group`` (datasets not in ``skip``) as layout :class:`Var` s."""
    out = {}
    for name, obj in group.items():
        if not isinstance(obj, h5py.Dataset) or name in skip or name == "case_index":
            continue
        dims = tuple(obj.dims[i].keys()[0] if obj.dims[i].keys() else "" for i in range(obj.ndim))
        attrs = {k: v for k, v in obj.attrs.items() if k not in _INTERNAL}
        if obj.dtype.kind == "S":  # fixed-width text (rollc <= 0.1): rebuilt as variable-length
            kind = Kind("str", obj.dtype.itemsize)
        elif h5py.check_string_dtype(obj.dtype):
            kind = Kind("str")
        elif plain(attrs.get("dtype")) == "bool":
            kind = Kind("bool")
        elif obj.dtype == np.int8:
            kind = Kind("i1")
        elif obj.dtype.kind in "iu":
            kind = Kind("i8")
        else:
            kind = Kind("f8")
        generated = ("coordinates", "dtype", "_Encoding", "flag_values", "flag_meanings", "valid_range")
        attrs = {k: v for k, v in attrs.items() if k not in generated}
        out[name] = Var(dims, kind, attrs)
    return out


def read_units(handle) -> dict[str, str]:
    """The unit names of an existing file (length, stress, force/length), read off its variables."""
    units = dict(DEFAULT_UNITS)
    for name, key in (("x", "length"), ("p_n", "stress"), ("normal_load", "force/length")):
        if name in handle and "units" in handle[name].attrs:
            units[key] = plain(handle[name].attrs["units"])
    return units
