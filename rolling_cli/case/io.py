"""Read a case from a TOML file or a dict; write the resolved case as TOML."""

from __future__ import annotations

import copy
import dataclasses
import os
import tomllib
from typing import Any

import tomli_w

from ..errors import CaseError
from . import schema
from .validate import build, check_consistency


def read_toml(path: str | os.PathLike) -> dict:
    """The parsed TOML document of a case file (errors as in :func:`load_case`)."""
    path = os.fspath(path)
    try:
        with open(path, "rb") as handle:
            return tomllib.load(handle)
    except FileNotFoundError:
        raise CaseError("file not found; allowed: a path to a TOML case file", file=path) from None
    except IsADirectoryError:
        raise CaseError("is a directory; allowed: a path to a TOML case file", file=path) from None
    except tomllib.TOMLDecodeError as err:
        raise CaseError(f"invalid TOML ({err}); allowed: TOML 1.0 syntax", file=path) from None
    except UnicodeDecodeError:
        raise CaseError("not UTF-8 text; allowed: a TOML case file", file=path) from None


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
    return dataclasses.replace(case, source=file)


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

    return convert(case)


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
