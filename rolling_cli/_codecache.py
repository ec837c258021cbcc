"""Start-up: the code :mod:`dataclasses` generates for the package's classes, compiled once per install.

``@dataclass`` writes each class's ``__init__``, ``__repr__``, ``__eq__``, ``__hash__`` (and, frozen,
``__setattr__`` and ``__delattr__``) as source text and compiles it at every import: the ~40 classes
a half-plane solve imports cost ~250 compilations, ~10 ms of a ~0.2 s whole process. Python keeps
the bytecode of modules (the .pyc files), not this. :func:`install` gives :mod:`dataclasses` an
``exec`` (a module global that shadows the builtin there, nowhere else) that looks each text of a
rolling_cli class up in a table of code objects kept beside this module's bytecode.

* The code objects are what ``compile`` makes of the same text with the same (no) future flags, so
  the classes are the ones ``@dataclass`` makes without the table; other modules' classes, and
  texts not yet in the table, are compiled as usual.
* The table lives where Python writes this module's .pyc (``__pycache__``, or under
  ``PYTHONPYCACHEPREFIX``), named for the interpreter's cache tag, headed by its bytecode magic
  number; it is written (atomically, at exit, when it gained texts) only where Python writes .pyc
  files (not under ``PYTHONDONTWRITEBYTECODE``), with the trust of those files. A missing,
  unreadable or foreign table counts as empty and is rewritten.
* Only the ``rollc`` entry (:func:`rolling_cli.cli.entry`) installs it: Python use of the package
  is left alone.
"""

import atexit
import builtins
import importlib.util
import marshal
import os
import sys

#: Texts kept at most (the classes of every command are ~300); beyond, the table starts afresh.
LIMIT = 4096
#: File header: the interpreter's bytecode magic number (code objects are not portable across it).
MAGIC = importlib.util.MAGIC_NUMBER

_codes: dict | None = None  # text -> code object; None until the first rolling_cli class
_added = False
_path: str | None = None


def table_path() -> str | None:
    """The table's file: this module's .pyc path with ``.dataclasses`` for ``.pyc`` (None: no cache
    tag, so no bytecode cache either)."""
    try:
        pyc = importlib.util.cache_from_source(__file__)
    except (NotImplementedError, ValueError):
        return None
    return pyc[: -len(".pyc")] + ".dataclasses" if pyc.endswith(".pyc") else None


def _load(path: str | None) -> dict:
    if path is None:
        return {}
    try:
        with open(path, "rb") as handle:
            if handle.read(len(MAGIC)) != MAGIC:
                return {}
            codes = marshal.load(handle)
    except (OSError, EOFError, ValueError, TypeError):
        return {}
    if not isinstance(codes, dict) or len(codes) > LIMIT:
        return {}
    return codes


def _save() -> None:
    """Write the table (atomically: a temporary file in the same directory, renamed)."""
    if not _added or _path is None or sys.dont_write_bytecode:
        return
    temporary = f"{_path}.{os.getpid()}.tmp"
    try:
        os.makedirs(os.path.dirname(_path), exist_ok=True)
        with open(temporary, "wb") as handle:
            handle.write(MAGIC)
            marshal.dump(_codes, handle)
        os.replace(temporary, _path)
    except (OSError, ValueError):  # read-only install, full disk: the table is only an optimisation
        try:
            os.remove(temporary)
        except OSError:
            pass


def _exec(source, globals=None, locals=None, /):
    """``exec`` for :mod:`dataclasses`: a rolling_cli class's text runs from the table's code."""
    global _codes, _added
    if type(source) is str and globals is not None and str(globals.get("__name__", "")).startswith("rolling_cli"):
        if _codes is None:
            _codes = _load(_path)
        code = _codes.get(source)
        if code is None:
            code = compile(source, "<string>", "exec", dont_inherit=True)
            if len(_codes) >= LIMIT:
                _codes.clear()
            if not _added:
                atexit.register(_save)
            _codes[source] = code
            _added = True
        source = code
    return builtins.exec(source, globals, locals)


def install() -> None:
    """Route :mod:`dataclasses`' compilations of rolling_cli classes through the table (idempotent)."""
    global _path
    import dataclasses

    if getattr(dataclasses, "exec", None) is _exec:
        return
    _path = table_path()
    dataclasses.exec = _exec
