"""HDF5 result files (format "rolling_cli.result", version 1).

Layout of one result (the root of a result file, or a group of a sweep file):

* attributes: ``format``, ``format_version``, ``software_version``,
  ``created`` (ISO 8601 UTC), ``case`` (the resolved case as TOML), the solve's
  scalars (``converged``, ``iterations``, ``residual``, ``normal_load``,
  ``tangential_load``, ``creep``, ``overlap``, ``mu``, ``hertz_a``,
  ``hertz_p0``, ``beta_dundurs``, ``effects`` (JSON), ...);
* datasets of length n, each with ``units`` and ``long_name``: ``x``, ``p_n``,
  ``p_t``, ``delta_n``, ``s_t``, ``state`` (int8) and ``weights``;
* group ``convergence``: the Newton history, one dataset per column;
* group ``reference`` (similar materials): ``hertz_pressure``, ``carter_traction``.

Files are written to a temporary name in the target directory and renamed,
so a crash never leaves a partial file under the final name.
"""

from __future__ import annotations

import contextlib
import os
import tempfile

import h5py
import numpy as np

from .result import DATASETS, STATE_NAMES, Result

FORMAT = "rolling_cli.result"
FORMAT_VERSION = 1
HISTORY_COLUMNS = ("stage", "iteration", "residual", "creep", "overlap", "contact", "stick", "step")


@contextlib.contextmanager
def atomic_h5(path: str | os.PathLike, mode: str = "w"):
    """Open an HDF5 file under a temporary name and rename it onto ``path`` on success.

    With ``mode="a"`` an existing file is copied first, so an interrupted
    update leaves the previous file intact.
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{os.path.basename(path)}.", suffix=".tmp", dir=directory)
    os.close(fd)
    try:
        if mode == "a" and os.path.exists(path):
            with open(path, "rb") as src, open(tmp, "wb") as dst:
                dst.write(src.read())
            handle = h5py.File(tmp, "a")
        else:
            handle = h5py.File(tmp, "w")
        with handle:
            yield handle
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        raise


def write_result(result: Result, path: str | os.PathLike) -> None:
    """Write one result file atomically."""
    with atomic_h5(path) as handle:
        write_group(handle, result)


def _set_attr(node, key, value) -> None:
    if value is None:
        return
    if isinstance(value, bool) or isinstance(value, np.bool_):
        node.attrs[key] = np.bool_(value)
    else:
        node.attrs[key] = value


def write_group(node, result: Result) -> None:
    """Write a result into an open HDF5 group (the file root or a sweep case)."""
    units = result.units
    for key, value in result.attributes.items():
        _set_attr(node, key, value)
    node.attrs["format"] = FORMAT
    node.attrs["format_version"] = FORMAT_VERSION
    node.attrs["case"] = result.case_toml
    arrays = {
        "x": result.x,
        "p_n": result.p_n,
        "p_t": result.p_t,
        "delta_n": result.delta_n,
        "s_t": result.s_t,
        "state": result.state.astype(np.int8),
    }
    if result.frictional_power is not None:
        arrays["frictional_power"] = result.frictional_power
    for name, data in arrays.items():
        long_name, unit = DATASETS[name]
        ds = node.create_dataset(name, data=data)
        ds.attrs["units"] = units[unit]
        ds.attrs["long_name"] = long_name
    node["state"].attrs["flag_values"] = np.array(sorted(STATE_NAMES), dtype=np.int8)
    node["state"].attrs["flag_meanings"] = " ".join(STATE_NAMES[k] for k in sorted(STATE_NAMES))
    ds = node.create_dataset("weights", data=result.weights)
    ds.attrs["units"] = units["length"]
    ds.attrs["long_name"] = "quadrature weight of each node (P = -sum w p_n, Q = sum w p_t)"
    conv = node.create_group("convergence")
    conv.attrs["long_name"] = "Newton history: relative residual per iteration of each stage"
    for column in HISTORY_COLUMNS:
        values = [row.get(column, np.nan if column != "stage" else "") for row in result.history]
        if column == "stage":
            conv.create_dataset(column, data=np.array(values, dtype=h5py.string_dtype()))
        else:
            conv.create_dataset(column, data=np.array(values, dtype=float))
    if result.reference:
        ref = node.create_group("reference")
        names = {
            "hertz_pressure": "Hertz pressure p(x) >= 0 for the solved load",
            "carter_traction": "Carter tangential traction on A for the solved Q/(mu P)",
        }
        for name, data in result.reference.items():
            ds = ref.create_dataset(name, data=data)
            ds.attrs["units"] = units["stress"]
            ds.attrs["long_name"] = names.get(name, name)
    if result.stresses:
        from .stresses.io import write_stresses

        write_stresses(node, result.stresses, units)


def _decode(value):
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def read_group(node) -> Result:
    """Read a result from an HDF5 group written by :func:`write_group`."""
    if _decode(node.attrs.get("format")) != FORMAT:
        raise ValueError(f"not a {FORMAT} group (format = {node.attrs.get('format')!r})")
    attrs = {k: _decode(v) for k, v in node.attrs.items() if k != "case"}
    history = []
    if "convergence" in node:
        conv = node["convergence"]
        n = len(conv["residual"]) if "residual" in conv else 0
        cols = {c: conv[c][()] for c in HISTORY_COLUMNS if c in conv}
        for i in range(n):
            history.append({c: _decode(v[i]) for c, v in cols.items()})
    reference = {k: v[()] for k, v in node["reference"].items()} if "reference" in node else {}
    stresses = {}
    if "stresses" in node:
        from .stresses.io import read_stresses

        stresses = read_stresses(node["stresses"])
    return Result(
        x=node["x"][()],
        weights=node["weights"][()],
        p_n=node["p_n"][()],
        p_t=node["p_t"][()],
        delta_n=node["delta_n"][()],
        s_t=node["s_t"][()],
        state=node["state"][()],
        attributes=attrs,
        history=history,
        reference=reference,
        case_toml=_decode(node.attrs.get("case", "")),
        frictional_power=node["frictional_power"][()] if "frictional_power" in node else None,
        stresses=stresses,
    )


def read_result(path: str | os.PathLike) -> Result:
    """Read a single result file."""
    with h5py.File(path, "r") as handle:
        return read_group(handle)
