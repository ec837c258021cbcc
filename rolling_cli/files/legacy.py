"""Format-1 files (one HDF5 group per case), converted to the current layout for reading.

``rollc plot``, ``rollc export`` and :func:`rolling_cli.open_result` read a
format-1 result or sweep by converting it to a format-2 file first
(:func:`converted`), so one reader serves every file.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile

import h5py

from .layout import FORMAT_V1_SWEEP
from .reader import plain, read_group
from .rows import row_from_failure, row_from_result
from .writer import ResultFile

#: Root attributes of a format-1 sweep carried into the converted file.
SWEEP_ATTRS = ("case", "sweep", "sweep_keys", "cases_total", "created", "software_version")


def convert(source: str, target: str) -> None:
    """Write the format-2 equivalent of the format-1 file ``source`` to ``target``."""
    from .io_hdf5 import root_attributes, write_result

    with h5py.File(source, "r") as handle:
        if plain(handle.attrs.get("format")) != FORMAT_V1_SWEEP:
            write_result(read_group(handle), target, command=f"converted from format 1: {source}")
            return
        keys = tuple(json.loads(plain(handle.attrs["sweep_keys"])))
        old = {k: plain(handle.attrs[k]) for k in SWEEP_ATTRS if k in handle.attrs}
        attrs = root_attributes("", old.get("case", ""), f"converted from format 1: {source}", old.get("created"))
        attrs.update({k: v for k, v in old.items() if k != "created"})
        names = sorted(handle["cases"])
        writer = ResultFile(target, attrs, keys, total=len(names))
        for name in names:
            group = handle["cases"][name]
            coords = {k: plain(group.attrs[k]) for k in keys if k in group.attrs}
            message = plain(group.attrs.get("message", ""))
            seconds = float(group.attrs.get("time", 0.0))
            if "x" in group:
                row = row_from_result(read_group(group), int(name), coords, time=seconds, message=message)
            else:
                row = row_from_failure(int(name), coords, message, seconds)
            writer.add(row)
        writer.close()


@contextlib.contextmanager
def converted(path: str):
    """Yields a path of ``path`` in format 2: the file itself, or a temporary conversion of a format-1 file."""
    with h5py.File(path, "r") as handle:
        version = int(handle.attrs.get("format_version", 1))
    if version >= 2:
        yield path
        return
    with tempfile.TemporaryDirectory(prefix="rollc-v1-") as directory:
        target = os.path.join(directory, os.path.basename(path))
        convert(path, target)
        yield target
