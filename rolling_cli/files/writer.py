"""The single writer of a result file (layout: :mod:`rolling_cli.files.layout`): rows appended, never rewritten.

Every variable with the ``case`` dimension is chunked, its chunks sized for a
capacity of rows; the ``case`` dimension (and the histories' ``row``) is as long
as the committed rows, so a reader that knows nothing of ``cases_complete``
(plain xarray, ncdump) sees no padding row. A commit of new rows extends those
dimensions (HDF5 allocates the chunks the rows reach; text goes to the global
heap), writes the rows, flushes, and writes the ``cases_complete`` attribute
last, in place: a kill between commits leaves a file whose rows are all
complete. (Readers and ``--resume`` trust nothing beyond ``cases_complete``.)

Anything that changes the structure (the first rows, more rows than the
capacity, a new variable, more nodes, cases whose grids differ, an extra group,
the final trim, rows out of sweep order at the end) rebuilds the file: a new
file under a temporary name, its space reserved first (so a full disk or a
file-size limit fails before HDF5 writes, leaving the old file untouched), the
committed rows copied block by block (in sweep order), then an atomic rename.
The first capacity is what fits in 256 MB (or the whole sweep, when smaller),
then four times more each time, so the growth copies at most a third of the
final file; the final trim (one copy) fits the chunks to the rows.

Text is stored as variable-length UTF-8 strings without a fill value: netCDF-4's
own ``string`` type (netCDF-C aborts on fixed-length HDF5 strings).
"""

from __future__ import annotations

import contextlib
import json
import math
import os

import h5py
import numpy as np

from . import outputs, storage
from .columns import Batch, values_of
from .layout import (
    CONVENTIONS,
    CONVERGENCE,
    GRID,
    HISTORY,
    INDEXES,
    NODE_FIELDS,
    SCALARS,
    Kind,
    Var,
    column_kind,
    coordinate_name,
    describe,
    dtype_kind,
    encode,
    merge,
    swept,
)
from .outputs import WriteError
from .reader import plain
from .rows import GROUP_HOOKS, Row

#: HDF5 format bounds: the oldest objects that do the job (netCDF-4 reads them), 1.8 features allowed.
LIBVER = ("earliest", "v108")
#: The first capacity of a file: the rows that fit in PREALLOCATE bytes, at least FIRST_ROWS (or its
#: total, when smaller); then GROWTH times more at each rebuild. Rebuilds stay few and their copies
#: proportional to the file.
FIRST_ROWS = 256
PREALLOCATE = 1 << 28
GROWTH = 4
#: Rows per block when a rebuild turns a shared grid into a per-case one (they bound its memory;
#: row copies use :data:`rolling_cli.files.storage.COPY_BYTES`).
BLOCK_ROWS = 4096


def _index(name: str) -> dict:
    return {"long_name": INDEXES[name], "units": "1"}


def _node_meta() -> dict:
    from ..result import DATASETS

    return {**DATASETS, **NODE_FIELDS}


class ResultFile:
    """Appends rows (:class:`~rolling_cli.files.rows.Row`) to one result file.

    ``attrs``: root attributes (provenance, case, sweep); ``keys``: the swept
    dotted keys, in order; ``total``: the number of cases the file will hold
    (None when unknown), which caps the capacity; ``replace``: the first
    write may replace an existing file (``--overwrite``). The caller holds the
    output's lock (:func:`rolling_cli.files.outputs.claim`).
    """

    def __init__(
        self, path: str, attrs: dict, keys: tuple[str, ...] = (), total: int | None = None, replace: bool = False
    ) -> None:
        self.path = os.fspath(path)
        self.attrs = dict(attrs)
        self.keys = tuple(keys)
        self._coords = {coordinate_name(k) for k in self.keys}
        self.total = total
        self.replace = replace
        self.schema: dict[str, Var] = {}
        self.history: dict[str, Var] = {}
        self.grid: dict[str, np.ndarray] = {}  # shared (node) grid variables
        self.extras: set[str] = set()
        self.done = 0
        self.hist_done = 0
        self.case_cap = self.node_cap = self.hist_cap = 0
        self.pending: list[Row] = []
        self.exists = False
        self.broken = False
        self.restructure = True  # the next commit rebuilds (root attributes changed)
        self.units = dict(storage.DEFAULT_UNITS)

    # ----------------------------------------------------------------- opening
    @classmethod
    def open(cls, path: str) -> ResultFile:
        """An existing format-2 file, to append to (``--resume``)."""
        with h5py.File(path, "r") as handle:
            attrs = {k: plain(v) for k, v in handle.attrs.items()}
            keys = tuple(json.loads(attrs.get("sweep_keys") or "[]"))
            self = cls(path, attrs, keys, attrs.get("cases_total"))
            self.exists = True
            self.done = int(attrs.get("cases_complete", 0))
            self.case_cap = handle["case"].shape[0]
            self.node_cap = handle["node"].shape[0] if "node" in handle else 0
            self.schema = storage.read_schema(handle, ("case", "node"))
            if CONVERGENCE in handle:
                self.history = storage.read_schema(handle[CONVERGENCE], ("row",))
                self.hist_cap = handle[CONVERGENCE]["row"].shape[0]
            if "history_rows" in handle and self.done:
                self.hist_done = int(handle["history_rows"][: self.done].sum())
            for name in GRID:
                if name in self.schema and self.schema[name].dims == ("node",):
                    self.grid[name] = handle[name][()]
            self.extras = {name for name in GROUP_HOOKS if name in handle}
            self.units = storage.read_units(handle)
            fixed_text = any(isinstance(o, h5py.Dataset) and o.dtype.kind == "S" for o in storage.datasets(handle))
        described = self._describe_all()
        self.restructure = fixed_text or described  # an older file: the next commit rebuilds it
        return self

    def _describe_all(self) -> bool:
        """Give the variables of an older file the ``long_name`` and ``units`` they lack; True if any did."""
        keys = {coordinate_name(k): k for k in self.keys}
        node_meta = _node_meta()
        changed = False
        for table, schema in ((None, self.schema), (HISTORY, self.history)):
            for name, var in schema.items():
                if table is HISTORY:
                    known = describe(name, HISTORY, self.units)
                elif name in keys:
                    known = swept(keys[name], self.units, text=var.kind.name == "str")
                else:
                    known = describe(name, SCALARS if var.dims == ("case",) else node_meta, self.units)
                missing = {k: v for k, v in known.items() if k not in var.attrs}
                var.attrs.update(missing)
                changed = changed or bool(missing)
        return changed

    # ----------------------------------------------------------------- public
    def add(self, row: Row) -> None:
        """Queue a row; it reaches the file at the next :meth:`commit`.

        A scalar named like a swept coordinate is stored as ``<name>_result``.
        """
        if self._coords.intersection(row.scalars):
            row.scalars = {(k + "_result" if k in self._coords else k): v for k, v in row.scalars.items()}
        self.pending.append(row)

    def set_attrs(self, **attrs) -> None:
        """Change root attributes (applied by the next commit, which rebuilds)."""
        self.attrs.update(attrs)
        self.restructure = True

    def commit(self) -> None:
        """Write the queued rows: appended in place, or by a rebuild when the structure must change.

        Interrupted (Ctrl-C), the rows stay queued for the next commit; after a WriteError the
        writer writes nothing more (the file keeps what it had).
        """
        rows, self.pending = self.pending, []
        if self.broken or (not rows and not self.restructure and self.exists):
            return
        try:
            batch = Batch.of(rows, self.keys)
            plan = self._plan(batch)
            if plan is None and not self.restructure and self.exists:
                self._append(batch)
            else:
                self._rebuild(batch, plan or self._same_plan())
        except WriteError:
            self.broken = True
            raise
        except BaseException:
            self.pending = rows + self.pending
            raise

    def close(self) -> None:
        """Commit, then trim every dimension to its exact length and put the rows in sweep order (a
        rebuild when there is slack or the rows are out of order: a parallel run interrupted and
        resumed commits the cases its workers had finished before those it had not)."""
        self.commit()
        if self.broken:
            return
        order = self._sweep_order()
        if self.case_cap > self.done or self.hist_cap > self.hist_done or order is not None:
            plan = self._same_plan()
            plan["case_cap"], plan["hist_cap"] = self.done, self.hist_done
            plan["copied"] = True  # every element is copied: no fill values to write first
            plan["order"] = order
            self._rebuild(Batch.of([], self.keys), plan)

    def _sweep_order(self) -> np.ndarray | None:
        """The committed rows' order by case index (None when they are in that order already)."""
        if not self.exists or self.done < 2:
            return None
        with h5py.File(self.path, "r") as handle:
            cases = storage.get(handle, "case", 0, self.done)
        return None if np.all(np.diff(cases) > 0) else np.argsort(cases, kind="stable")

    # ----------------------------------------------------------------- planning
    def _same_plan(self) -> dict:
        return {
            "schema": self.schema,
            "history": self.history,
            "grid": self.grid,
            "node_cap": self.node_cap,
            "case_cap": self.case_cap,
            "hist_cap": self.hist_cap,
            "extras": self.extras,
            "fixed": self.total == 1,
        }

    def _plan(self, batch: Batch) -> dict | None:
        """The structure the batch needs, or None when it fits the file as it is."""
        rows = batch.rows
        schema, history, grid = dict(self.schema), dict(self.history), dict(self.grid)
        node_cap = self.node_cap
        units = next((r.units for r in rows if r.units), None)
        if units and not self.schema:
            self.units = {**self.units, **units}
        for key, values in batch.coords.items():
            kind = column_kind(values)
            attrs = swept(key, self.units, text=kind is not None and kind.name == "str")
            storage.widen(schema, coordinate_name(key), kind, ("case",), attrs)
        for name, values in batch.scalars.items():
            storage.widen(schema, name, column_kind(values), ("case",), describe(name, SCALARS, self.units))
        node_meta = _node_meta()
        for name, arrays in batch.arrays.items():
            present = [a for a in arrays if a is not None]
            node_cap = max(node_cap, *(a.size for a in present))
            dims: tuple[str, ...] = ("case", "node")
            if name in GRID and (name not in schema or schema[name].dims == ("node",)):
                shared = grid.setdefault(name, present[0])
                if all(a.shape == shared.shape and np.array_equal(a, shared) for a in present):
                    dims = ("node",)
                else:
                    del grid[name]
            node_kind: Kind | None = None
            for dtype in {a.dtype for a in present}:
                node_kind = merge(node_kind, dtype_kind(dtype))
            storage.widen(schema, name, node_kind, dims, describe(name, node_meta, self.units))
        for name, values in batch.history.items():
            storage.widen(history, name, column_kind(values), ("row",), describe(name, HISTORY, self.units))
        need_rows = self.done + len(rows)
        need_hist = self.hist_done + len(batch.history_cases)
        extras = self.extras | {name for r in rows for name in r.extras}
        same = (
            schema.keys() == self.schema.keys()
            and all(schema[k] is self.schema[k] for k in schema)
            and history.keys() == self.history.keys()
            and all(history[k] is self.history[k] for k in history)
            and node_cap == self.node_cap
            and need_rows <= self.case_cap
            and need_hist <= self.hist_cap
            and not any(r.extras for r in rows)
        )
        if same:
            return None
        row_bytes = sum(
            v.kind.dtype.itemsize * (node_cap if "node" in v.dims else 1) for v in schema.values() if "case" in v.dims
        )
        case_cap = self._capacity(need_rows, self.case_cap, self.total, PREALLOCATE // max(row_bytes, 1))
        complete = self.total is not None and need_rows >= self.total  # no rows (nor history rows) to come
        hist_cap = self._capacity(need_hist, self.hist_cap, need_hist if complete else None)
        if need_rows and case_cap > need_rows:  # room for the history rows of the rows to come
            hist_cap = max(hist_cap, math.ceil(1.25 * case_cap * need_hist / need_rows))
        return {
            "schema": schema,
            "history": history,
            "grid": grid,
            "node_cap": node_cap,
            "case_cap": case_cap,
            "hist_cap": hist_cap,
            "extras": extras,
            "fixed": self.total == 1,
        }

    @staticmethod
    def _capacity(need: int, current: int, total, first: int = 0) -> int:
        """Room for ``need`` rows: at first ``first`` rows (at least :data:`FIRST_ROWS`), then four times
        as many at each growth, never beyond a known total."""
        if need <= current:
            return current
        grown = max(need, GROWTH * current, FIRST_ROWS, first)
        if total is not None:
            grown = min(grown, max(int(total), need))
        return grown

    # ----------------------------------------------------------------- writing
    def _append(self, batch: Batch) -> None:
        """Rows into the space the file already has; ``cases_complete`` last."""
        rows = batch.rows
        try:
            with h5py.File(self.path, "r+", libver=LIBVER) as handle:
                storage.extend(
                    handle, self.schema, self.history, self.done + len(rows), self.hist_done + len(batch.history_cases)
                )
                self._write_rows(handle, batch, self.schema, self.history, self.node_cap)
                handle.flush()
                outputs.fsync(self.path)  # the rows are on disk before the counter says so
                done = self.done + len(rows)
                h5py.h5a.open(handle.id, b"cases_complete").write(np.array(done, dtype=np.int64))
        except (OSError, RuntimeError) as err:
            raise WriteError(self.path, err, fatal=True, note=self._kept()) from None
        self.done += len(rows)
        self.hist_done += len(batch.history_cases)

    def _kept(self) -> str:
        if self.total == 1 or not self.exists:
            return "nothing was written"
        return f"the {self.done} cases committed before are kept (continue with --resume)"

    def _rebuild(self, batch: Batch, plan: dict) -> None:
        """A new file with the planned structure, the committed rows and the batch; renamed over the old."""
        rows = batch.rows
        plan = {
            **plan,
            "case_rows": self.done + len(rows),
            "hist_rows": self.hist_done + len(batch.history_cases),
        }
        tmp = outputs.new_temp(self.path)
        with self._undone(tmp):
            storage.skeleton(tmp)
            outputs.preallocate(tmp, self._estimate(plan, rows))
        with self._undone(tmp, fatal=True), h5py.File(tmp, "r+", libver=LIBVER) as new:
            self._create(new, plan)
            if self.exists and self.done:
                with h5py.File(self.path, "r") as old:
                    self._copy(old, new, plan)
            self._write_rows(new, batch, plan["schema"], plan["history"], plan["node_cap"])
            self._write_extras(new, rows)
            new.attrs["cases_complete"] = np.int64(self.done + len(rows))
        with self._undone(tmp):
            outputs.fsync(tmp)
            outputs.publish(tmp, self.path, replace=self.exists or self.replace)
        self.schema, self.history, self.grid = plan["schema"], plan["history"], plan["grid"]
        self.node_cap, self.case_cap, self.hist_cap = plan["node_cap"], plan["case_cap"], plan["hist_cap"]
        self.extras = plan["extras"]
        self.done += len(rows)
        self.hist_done += len(batch.history_cases)
        self.exists = True
        self.restructure = False

    @contextlib.contextmanager
    def _undone(self, tmp: str, fatal: bool = False):
        """On any failure in the body remove ``tmp``; an OS error (and, inside HDF5, any error of the
        library: ``fatal``) becomes a WriteError that says what the file still holds."""
        try:
            yield
        except (OSError, RuntimeError) as err:
            outputs.remove_quietly(tmp)
            if isinstance(err, RuntimeError) and not fatal:
                raise
            raise WriteError(self.path, err, fatal=fatal, note=self._kept()) from None
        except BaseException:
            outputs.remove_quietly(tmp)
            raise

    def _estimate(self, plan: dict, rows: list[Row]) -> int:
        """Bytes the rebuilt file may need (generous: its space is reserved, then trimmed by HDF5)."""
        total = 1 << 16
        datasets = 3
        for var in plan["schema"].values():
            total += self._storage(var, plan)
            datasets += 1
        for var in plan["history"].values():
            total += self._storage(var, plan)
            datasets += 1
        total += (plan["case_cap"] + 2 * plan["hist_cap"]) * 8 + plan["node_cap"] * 4
        total += sum(len(encode(v)) for v in self.attrs.values()) * 2
        total += datasets * (1 << 12)  # object header, chunk index, attributes: ~1-3 kB measured
        if plan["extras"] and self.exists:
            total += os.path.getsize(self.path)
        total += sum(sum(storage.nbytes(p) for p in r.extras.values()) for r in rows)
        return int(total * 1.25)

    @staticmethod
    def _storage(var: Var, plan: dict) -> int:
        shape, chunks = storage.chunk_layout(var, plan)
        if chunks is None:
            return int(np.prod(shape)) * var.kind.dtype.itemsize
        count = 1
        for size, chunk in zip(shape, chunks, strict=True):
            count *= max(1, -(-size // chunk))
        return count * int(np.prod(chunks)) * var.kind.dtype.itemsize

    def _create(self, handle, plan: dict) -> None:
        """Every dimension, coordinate and variable of ``plan``, its space allocated and filled."""
        root = {**self.attrs, "Conventions": CONVENTIONS}
        storage.set_attrs(
            handle, {k: np.int8(v) if isinstance(v, bool) else v for k, v in root.items() if v is not None}
        )
        case = storage.dataset(handle, "case", Var(("case",), Kind("i8"), _index("case")), plan)
        case.make_scale("case")
        storage.set_attrs(case, {"_Netcdf4Dimid": np.int32(0), "_Netcdf4Coordinates": np.array([0], dtype=np.int32)})
        node = storage.dataset(handle, "node", Var(("node",), Kind("i8"), _index("node")), plan)
        node[:] = np.arange(plan["node_cap"])
        node.make_scale("node")
        storage.set_attrs(node, {"_Netcdf4Dimid": np.int32(1), "_Netcdf4Coordinates": np.array([1], dtype=np.int32)})
        scales = {"case": case, "node": node}
        coords = [coordinate_name(k) for k in self.keys if coordinate_name(k) in plan["schema"]]
        for name, var in plan["schema"].items():
            ds = storage.dataset(handle, name, var, plan)
            storage.attach(ds, var.dims, scales)
            if name not in coords:
                extra = ["x"] if "node" in var.dims and name != "x" and "x" in plan["schema"] else []
                if coords or extra:
                    storage.set_attrs(ds, {"coordinates": " ".join(coords + extra)})
            if name in plan["grid"]:
                ds[: plan["grid"][name].size] = plan["grid"][name]
        group = handle.create_group(CONVERGENCE, track_order=True)
        storage.set_attrs(group, {"long_name": "Newton histories: a CF indexed ragged array, one row per iteration"})
        iteration = storage.dataset(group, "row", Var(("row",), Kind("i8"), _index("row")), plan)
        iteration[:] = np.arange(plan["hist_rows"])
        iteration.make_scale("row")
        storage.set_attrs(
            iteration, {"_Netcdf4Dimid": np.int32(2), "_Netcdf4Coordinates": np.array([2], dtype=np.int32)}
        )
        scales["row"] = iteration
        index_var = Var(("row",), Kind("i8"), {**_index("case_index"), "instance_dimension": "case"})
        ds = storage.dataset(group, "case_index", index_var, plan)
        storage.attach(ds, ("row",), scales)
        for name, var in plan["history"].items():
            storage.attach(storage.dataset(group, name, var, plan), ("row",), scales)

    def _copy(self, old, new, plan: dict) -> None:
        """The committed rows of ``old`` into ``new``, block by block (kinds widened, grids broadcast)."""
        n, m = self.done, self.hist_done
        order = plan.get("order")  # new row i is old row order[i] (None: the same order)
        solved = storage.get(old, "nodes", 0, n) > 0 if "nodes" in old else np.ones(n, dtype=bool)
        storage.copy_rows(old, new, "case", n, plan["node_cap"], order=order)
        for name, var in self.schema.items():
            target = plan["schema"][name]
            if target.dims == ("node",):
                continue
            if var.dims == ("node",):  # a shared grid that is per case from now on
                grid = storage.get(old, name, 0, self.node_cap)
                for start in range(0, n, BLOCK_ROWS):
                    stop = min(n, start + BLOCK_ROWS)
                    block = np.full((stop - start, plan["node_cap"]), target.kind.fill, dtype=target.kind.dtype)
                    block[solved[start:stop], : self.node_cap] = grid
                    storage.put(new, name, start, block)
            else:
                storage.copy_rows(old, new, name, n, self.node_cap, target.kind.dtype, order)
        group, source = new[CONVERGENCE], old[CONVERGENCE]
        history_order = (
            None if order is None or not m else storage.ragged_order(storage.get(old, "history_rows", 0, n), order)
        )
        for name in ("case_index", *self.history):
            dtype = plan["history"][name].kind.dtype if name in plan["history"] else None
            storage.copy_rows(source, group, name, m, 0, dtype, history_order)
        for name in self.extras:  # through the group's own hook: an HDF5 copy across files breaks the
            hook = GROUP_HOOKS[name]  # object references of dimension scales inside the group
            target = new.require_group(name)
            for key, source in old[name].items():
                if old[name].get(key, getlink=True).__class__ is h5py.SoftLink:
                    continue  # a single result's links are made again below
                storage.write_group(target.create_group(key), name, hook.read(source), self.units)
            if self.total == 1:
                for key in list(target):
                    for sub in target[key] if key.startswith("case_") else ():
                        target[sub] = h5py.SoftLink(f"/{name}/{key}/{sub}")

    def _write_rows(self, handle, batch: Batch, schema: dict, history: dict, node_cap: int) -> None:
        """The batch's values at rows ``done`` on (and its history rows at ``hist_done`` on)."""
        rows = batch.rows
        if not rows:
            return
        start = self.done
        storage.put(handle, "case", start, np.array([r.index for r in rows], dtype=np.int64))
        by_name = {coordinate_name(k): k for k in self.keys}
        for name, var in schema.items():
            if var.dims == ("node",):
                continue
            if var.dims == ("case",):
                values = batch.coords[by_name[name]] if name in by_name else batch.scalars.get(name)
                if values is not None:
                    storage.put(handle, name, start, values_of(var.kind, values))
            elif name in batch.arrays:
                block = np.full((len(rows), node_cap), var.kind.fill, dtype=var.kind.dtype)
                for i, array in enumerate(batch.arrays[name]):
                    if array is not None:
                        block[i, : array.size] = array
                storage.put(handle, name, start, block)
        if batch.history_cases:
            group = handle[CONVERGENCE]
            lo = self.hist_done
            storage.put(group, "row", lo, np.arange(lo, lo + len(batch.history_cases), dtype=np.int64))
            storage.put(group, "case_index", lo, np.array(batch.history_cases, dtype=np.int64))
            for name, values in batch.history.items():
                storage.put(group, name, lo, values_of(history[name].kind, values))

    def _write_extras(self, handle, rows: list[Row]) -> None:
        for row in rows:
            for name, payload in row.extras.items():
                group = handle.require_group(name).create_group(f"case_{row.index:06d}")
                storage.write_group(group, name, payload, self.units)
                if self.total == 1:  # a single result: its subgroups also at /<name>/<sub> (e.g. stresses/A)
                    for sub in group:
                        handle[name][sub] = h5py.SoftLink(f"/{name}/case_{row.index:06d}/{sub}")
