"""Read a case from a TOML file or a dict; write the resolved case as TOML."""

from __future__ import annotations

import copy
import dataclasses
import os
import stat
import tomllib
from typing import Any

import tomli_w

from ..errors import CaseError
from . import schema
from .validate import build, check_consistency, resolved_friction

#: Largest case file read [bytes]. A case is a few hundred bytes; the cap keeps
#: a wrong path (a log, an image, a device) from being read into memory.
MAX_CASE_BYTES = 1_000_000

_ALLOWED_FILE = "a regular TOML case file of at most 1 MB"


def read_toml(path: str | os.PathLike) -> dict:
    """The parsed TOML document of a case file (errors as in :func:`load_case`).

    Only a regular file of at most :data:`MAX_CASE_BYTES` is read; a directory,
    FIFO, socket or device is refused without opening it for a blocking read.
    Every failure (missing, unreadable, too large, not UTF-8, invalid TOML,
    nested too deeply for the parser) is a one-line :class:`CaseError`.
    """
    path = os.fspath(path)
    text = _read_text(path)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"invalid TOML ({err}); allowed: TOML 1.0 syntax", file=path) from None
    except RecursionError:
        raise CaseError(
            "invalid TOML (arrays or inline tables nested too deeply for the parser); allowed: a case file", file=path
        ) from None
    except ValueError as err:  # e.g. an integer of more than 4300 digits
        raise CaseError(f"invalid TOML ({err}); allowed: TOML 1.0 syntax", file=path) from None


def _file_kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def _read_text(path: str) -> str:
    """The text of a regular case file: stat first (no side effects), then a
    non-blocking open that is checked again (the path may change in between),
    and at most :data:`MAX_CASE_BYTES` + 1 bytes read."""
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise CaseError(f"is {_file_kind(info.st_mode)}; allowed: {_ALLOWED_FILE}", file=path)
        if info.st_size > MAX_CASE_BYTES:
            raise CaseError(f"too large ({info.st_size} bytes); allowed: {_ALLOWED_FILE}", file=path)
        flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
        fd = os.open(path, flags)
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                raise CaseError(f"is {_file_kind(os.fstat(fd).st_mode)}; allowed: {_ALLOWED_FILE}", file=path)
            data = _read_at_most(fd, MAX_CASE_BYTES + 1)
        finally:
            os.close(fd)
    except FileNotFoundError:
        raise CaseError("file not found; allowed: a path to a TOML case file", file=path) from None
    except OSError as err:
        raise CaseError(f"cannot read ({err.strerror or err}); allowed: {_ALLOWED_FILE}", file=path) from None
    except ValueError as err:  # a path with a NUL byte
        raise CaseError(f"invalid path ({err}); allowed: a path to a TOML case file", file=path) from None
    if len(data) > MAX_CASE_BYTES:
        raise CaseError(f"too large (more than {MAX_CASE_BYTES} bytes); allowed: {_ALLOWED_FILE}", file=path)
    try:
        return data.decode("utf-8-sig")  # a leading byte-order mark is dropped
    except UnicodeDecodeError as err:
        raise CaseError(
            f"not UTF-8 text (byte 0x{data[err.start]:02x} at offset {err.start}); allowed: a TOML case file",
            file=path,
        ) from None


def _read_at_most(fd: int, limit: int) -> bytes:
    parts = []
    size = 0
    while size < limit:
        try:
            chunk = os.read(fd, min(65536, limit - size))
        except BlockingIOError:  # a regular file never blocks; be safe anyway
            break
        if not chunk:
            break
        parts.append(chunk)
        size += len(chunk)
    return b"".join(parts)


def load_case(source: str | os.PathLike | dict) -> schema.Case:
    """Validate a case file (path) or an already-parsed TOML dict into a :class:`Case`.

    Raises :class:`~rolling_cli.errors.CaseError` with a one-line message.
    """
    if isinstance(source, dict):
        return case_from_dict(source, None)
    path = os.fspath(source)
    return case_from_dict(read_toml(path), path)


def case_from_dict(data: dict, file: str | None) -> schema.Case:
    """Build and check a case from a parsed TOML document (``file`` names it in errors)."""
    data = {k: v for k, v in data.items() if k != "sweep"}
    case = build(schema.Case, data, "", file)
    check_consistency(case, file)
    return dataclasses.replace(resolved_friction(case), source=file)


def case_to_dict(case: schema.Case) -> dict:
    """The fully resolved case (defaults filled, unset optional keys left out) as a TOML-ready dict."""

    def convert(obj: Any) -> Any:
        if dataclasses.is_dataclass(obj):
            out = {}
            for f in dataclasses.fields(obj):
                if f.metadata.get("internal"):
                    continue
                value = convert(getattr(obj, f.name))
                if value is not None and value != {}:
                    out[f.name] = value
            return out
        return obj

    out = convert(case)
    if out.get("friction", {}).get("law", "constant") != "constant":
        out["friction"].pop("mu", None)  # set from mu_static on loading (validate.resolved_friction)
    return out


def case_to_toml(case: schema.Case, extra: dict | None = None) -> str:
    """The resolved case as TOML text; ``extra`` adds a table of derived values."""
    data = case_to_dict(case)
    if extra:
        data = {**data, **extra}
    return tomli_w.dumps(data)


def with_overrides(case: schema.Case, overrides: dict[str, Any]) -> schema.Case:
    """A new case with dotted keys replaced (``{"friction.mu": 0.2}``), re-validated."""
    data = copy.deepcopy(case_to_dict(case))
    for dotted, value in overrides.items():
        node = data
        parts = dotted.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise CaseError(f"{dotted} = {value!r}: not a table key; allowed: a dotted case key", file=case.source)
        _clear_exclusive(node, parts, value)
        node[parts[-1]] = value
    return case_from_dict(data, case.source)


_EXCLUSIVE = {
    "normal": ("load", "overlap"),
    "tangential": ("q_over_mu_p", "q_over_p", "load", "creep"),
}


def _clear_exclusive(node: dict, parts: list[str], value: Any) -> None:
    """Setting one of a group of exclusive keys (normal.load vs overlap) removes the others."""
    if len(parts) == 2 and parts[0] in _EXCLUSIVE and parts[1] in _EXCLUSIVE[parts[0]]:
        for other in _EXCLUSIVE[parts[0]]:
            if other != parts[1]:
                node.pop(other, None)
