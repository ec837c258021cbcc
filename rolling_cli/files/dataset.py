"""``rolling_cli.open_result``: a result or sweep file as an ``xarray.Dataset`` (or Result objects).

With xarray and h5netcdf installed (extra ``rolling-cli[xarray]``) the file
opens as a Dataset with dimensions ``case`` and ``node`` (see
:mod:`rolling_cli.files.layout`), trimmed to the complete cases; it is the same as
``xarray.open_dataset(path)`` on a finished file. Without xarray: the
:class:`~rolling_cli.result.Result` of a one-case file, or a list of Results
(one per case; a failed case has empty arrays) of a sweep.
"""

from __future__ import annotations

import os

import h5py

from .legacy import converted
from .reader import cases_complete, read_case, version


def open_result(path: str | os.PathLike):
    """The file at ``path`` as an xarray.Dataset (loaded into memory for a format-1 file), or as
    Result objects when xarray is not installed."""
    path = os.fspath(path)
    try:
        import xarray
    except ImportError:
        xarray = None  # type: ignore[assignment]  # optional extra: Result objects instead
    with converted(path) as source:
        with h5py.File(source, "r") as handle:
            version(handle)
            n = cases_complete(handle)
            if xarray is None:
                results = [read_case(handle, row) for row in range(n)]
                return results[0] if n == 1 else results
        dataset = xarray.open_dataset(source, engine="h5netcdf")
        if dataset.sizes.get("case", n) > n:
            dataset = dataset.isel(case=slice(0, n))
        if source != path:  # a temporary conversion: load it before it goes
            dataset = dataset.load()
            dataset.close()
        return dataset
