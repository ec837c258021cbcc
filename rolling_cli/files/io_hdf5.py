"""HDF5 result files: write one result; read any result or sweep file.

The layout (format "rolling_cli.result", version 2) is described in
:mod:`rolling_cli.files.layout`: a single result is the one-case form of the sweep
layout, netCDF-4/CF-compatible, so ``xarray.open_dataset`` opens it as is.
Version-1 files (one HDF5 group per case) are still read
(:func:`~rolling_cli.files.reader.read_group`).

Files are written under a temporary name in the target directory (mode 0666
minus the umask), their space reserved first, and renamed: a failure leaves
no partial file and an existing output untouched.
"""

from __future__ import annotations

import os

from .._version import __version__
from ..result import Result, utc_timestamp
from .layout import FORMAT, FORMAT_VERSION
from .reader import read_group, read_result
from .rows import row_from_result
from .writer import ResultFile

__all__ = ["write_result", "read_result", "read_group", "root_attributes"]


def root_attributes(title: str, case_toml: str, command: str | None = None, created: str | None = None) -> dict:
    """Provenance attributes of a new file: format, versions, ``created``, CF ``history`` and ``source``."""
    created = created or utc_timestamp()
    return {
        "title": title or "rolling_cli result",
        "source": f"rolling_cli {__version__}",
        "history": f"{created} {command or 'rolling_cli'}",
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "software_version": __version__,
        "created": created,
        "case": case_toml,
    }


def write_result(result: Result, path: str | os.PathLike, *, overwrite: bool = True, command: str | None = None):
    """Write one result file atomically (``overwrite=False``: never replace an existing file).

    ``command`` is recorded in the CF ``history`` attribute.
    """
    attrs = root_attributes(
        result.attributes.get("title", ""), result.case_toml or "", command, result.attributes.get("created")
    )
    writer = ResultFile(os.fspath(path), attrs, total=1, replace=overwrite)
    writer.add(row_from_result(result))
    writer.close()
