"""On-disk cache of condensed BEM compliances.

A body's compliance depends only on its geometry, material and mesh; the key
is a SHA-256 of exactly those inputs (and :data:`MODEL_VERSION`, bumped when
the BEM code changes its numbers). Location: ``$ROLLC_CACHE_DIR``, else
``$XDG_CACHE_HOME/rolling_cli``, else ``~/.cache/rolling_cli``. Disable with
``rollc solve --no-cache`` or ``ROLLC_NO_CACHE=1``.

Every entry proves what it holds: it records its full key (the JSON text the
file name hashes) and a SHA-256 checksum of its arrays, and both are verified
on load, with the shapes, finiteness and (for the BEM inputs) the contact
nodes of the key's grid. An entry that fails any check (a flipped byte, a
truncated or empty file, an entry copied in from another case, a wrong node
count) is reported once, deleted and recomputed. Entries are written to a
temporary file in the cache directory, flushed to disk and renamed over the
entry, so a reader never sees a partial entry and a crash leaves none.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from . import Compliance

log = logging.getLogger(__name__)

MODEL_VERSION = 3
_BLOCKS = ("S_nn", "S_nt", "S_tn", "S_tt")
_ARRAYS = ("x", "weights", "definite_normal", *_BLOCKS)

#: Layout of an entry file (arrays plus the recorded key and checksum); entries
#: of another layout are invalid and get recomputed.
ENTRY_FORMAT = 2


class InvalidEntry(Exception):
    """A cache entry that does not prove what it holds; ``str()`` says why."""


def cache_dir() -> Path:
    """The cache directory (not created until something is written)."""
    if os.environ.get("ROLLC_CACHE_DIR"):
        return Path(os.environ["ROLLC_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "rolling_cli"


def enabled() -> bool:
    """False when ``ROLLC_NO_CACHE`` is set to a non-empty value other than 0."""
    return os.environ.get("ROLLC_NO_CACHE", "") in ("", "0")


def key_text(inputs: dict) -> str:
    """The full key: canonical JSON of everything the compliance depends on."""
    return json.dumps({"model_version": MODEL_VERSION, **inputs}, sort_keys=True, default=float)


def key(inputs: dict) -> str:
    """SHA-256 of :func:`key_text` (the entry's file name)."""
    import hashlib  # lazy, as tempfile below: with the cache off, a process needs neither (~5 ms of imports)

    return hashlib.sha256(key_text(inputs).encode()).hexdigest()


def checksum(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 over each array's name, dtype, shape and bytes, in name order."""
    import hashlib

    digest = hashlib.sha256()
    for name in sorted(arrays):
        array = np.ascontiguousarray(arrays[name])
        digest.update(f"{name}:{array.dtype.str}:{array.shape};".encode())
        digest.update(array.data)  # the raw bytes (contiguous above)
    return digest.hexdigest()


def cached(inputs: dict, compute: Callable[[], Compliance], use_cache: bool = True) -> tuple[Compliance, str]:
    """The compliance for ``inputs``, from a verified cache entry or computed (and stored).

    Returns (compliance, "cache" | "computed"). An invalid entry is reported
    (a warning), deleted and recomputed.
    """
    if not (use_cache and enabled()):
        return compute(), "computed"
    path = cache_dir() / f"{key(inputs)}.npz"
    if path.exists():
        try:
            found = load_entry(path, inputs)
            log.info("influence from cache %s", path)
            return found, "cache"
        except InvalidEntry as err:
            log.warning("invalid influence cache entry %s (%s): deleted, recomputing", path, err)
            with contextlib.suppress(OSError):
                path.unlink()
    result = compute()
    try:
        write_entry(path, inputs, result)
    except OSError as err:
        log.warning("could not write the influence cache in %s (%s)", path.parent, err)
    return result, "computed"


def load_entry(path: Path, inputs: dict) -> Compliance:
    """Read and verify the entry at ``path`` for ``inputs``; raise :class:`InvalidEntry` if it fails."""
    try:
        with open(path, "rb") as handle, np.load(handle, allow_pickle=False) as data:
            names = set(data.files)
            missing = [name for name in (*_ARRAYS, "key", "checksum", "entry_format") if name not in names]
            if missing:
                raise InvalidEntry(f"no {', '.join(missing)}: not an entry of this rollc version")
            if int(data["entry_format"]) != ENTRY_FORMAT:
                raise InvalidEntry(f"entry format {int(data['entry_format'])}, expected {ENTRY_FORMAT}")
            if str(data["key"][()]) != key_text(inputs):
                raise InvalidEntry("it was written for another case: its recorded key differs")
            arrays = {name: data[name] for name in _ARRAYS}
            if checksum(arrays) != str(data["checksum"][()]):
                raise InvalidEntry("checksum mismatch: the data changed after it was written")
    except InvalidEntry:
        raise
    except Exception as err:  # any unreadable file: BadZipFile, EOFError, OSError, ValueError, ...
        raise InvalidEntry(f"unreadable: {type(err).__name__}: {err}") from None
    _check_shapes(arrays, inputs)
    return Compliance(
        x=arrays["x"],
        weights=arrays["weights"],
        definite_normal=bool(arrays["definite_normal"]),
        **{name: arrays[name] for name in _BLOCKS},
    )


def _check_shapes(arrays: dict[str, np.ndarray], inputs: dict) -> None:
    x = arrays["x"]
    n = x.shape[0] if x.ndim == 1 else -1
    if n < 1 or arrays["weights"].shape != (n,):
        raise InvalidEntry("inconsistent node arrays")
    for name in _BLOCKS:
        if arrays[name].shape != (n, n):
            raise InvalidEntry(f"{name} has shape {arrays[name].shape}, expected ({n}, {n})")
    if not all(np.isfinite(arrays[name]).all() for name in ("x", "weights", *_BLOCKS)):
        raise InvalidEntry("non-finite values")
    if "zone_half_width" in inputs and "elements" in inputs:
        from ..model.grid import ContactGrid

        if "element_edges" in inputs:  # a graded grid's entry
            grid = ContactGrid.graded(inputs["element_edges"], 2)
        else:
            grid = ContactGrid(inputs["zone_half_width"], inputs["elements"], 2)
        if n != grid.size or not np.array_equal(x, grid.x):
            raise InvalidEntry(f"{n} nodes that are not the {grid.size} contact nodes of its key")


def write_entry(path: Path, inputs: dict, result: Compliance) -> None:
    """Write an entry atomically: a temporary file in the same directory, fsync, rename."""
    arrays = {
        "x": result.x,
        "weights": result.weights,
        "definite_normal": np.asarray(result.definite_normal),
        **{name: getattr(result, name) for name in _BLOCKS},
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    import tempfile

    fd, tmp = tempfile.mkstemp(prefix=".entry.", suffix=".npz", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as handle:
            np.savez(
                handle,
                key=np.asarray(key_text(inputs)),
                checksum=np.asarray(checksum(arrays)),
                entry_format=np.asarray(ENTRY_FORMAT),
                **arrays,
            )
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
