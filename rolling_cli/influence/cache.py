"""On-disk cache of condensed BEM compliances.

A body's compliance depends only on its geometry, material and mesh; the key
is a SHA-256 of exactly those inputs (and :data:`MODEL_VERSION`, bumped when
the BEM code changes its numbers). Location: ``$ROLLC_CACHE_DIR``, else
``$XDG_CACHE_HOME/rolling_cli``, else ``~/.cache/rolling_cli``. Disable with
``rollc solve --no-cache`` or ``ROLLC_NO_CACHE=1``. Entries are written under a
temporary name and renamed, so a crash never leaves a partial entry; an
unreadable entry is recomputed.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from . import Compliance

log = logging.getLogger(__name__)

MODEL_VERSION = 2
_BLOCKS = ("S_nn", "S_nt", "S_tn", "S_tt")


def cache_dir() -> Path:
    """The cache directory (not created until something is written)."""
    if os.environ.get("ROLLC_CACHE_DIR"):
        return Path(os.environ["ROLLC_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "rolling_cli"


def enabled() -> bool:
    """False when ``ROLLC_NO_CACHE`` is set to a non-empty value other than 0."""
    return os.environ.get("ROLLC_NO_CACHE", "") in ("", "0")


def key(inputs: dict) -> str:
    """SHA-256 of the JSON of everything the compliance depends on."""
    text = json.dumps({"model_version": MODEL_VERSION, **inputs}, sort_keys=True, default=float)
    return hashlib.sha256(text.encode()).hexdigest()


def cached(inputs: dict, compute: Callable[[], Compliance], use_cache: bool = True) -> tuple[Compliance, str]:
    """The compliance for ``inputs``, from the cache or computed (and stored).

    Returns (compliance, "cache" | "computed").
    """
    if not (use_cache and enabled()):
        return compute(), "computed"
    path = cache_dir() / f"{key(inputs)}.npz"
    if path.exists():
        try:
            with np.load(path) as data:
                found = Compliance(
                    x=data["x"],
                    weights=data["weights"],
                    definite_normal=bool(data["definite_normal"]),
                    **{name: data[name] for name in _BLOCKS},
                )
            log.info("influence from cache %s", path)
            return found, "cache"
        except (OSError, KeyError, ValueError) as err:
            log.warning("ignoring unreadable cache entry %s (%s)", path, err)
    result = compute()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".entry.", suffix=".npz", dir=path.parent)
        with os.fdopen(fd, "wb") as handle:
            np.savez(
                handle,
                x=result.x,
                weights=result.weights,
                definite_normal=result.definite_normal,
                **{name: getattr(result, name) for name in _BLOCKS},
            )
        os.replace(tmp, path)
    except OSError as err:
        log.warning("could not write the influence cache in %s (%s)", path.parent, err)
    return result, "computed"
