"""Output files written safely: checked before any work, locked, never half-written.

* :func:`check_output`: an output path must not be an input, a symbolic link,
  a device or any other non-regular file; an existing file is refused unless
  ``--overwrite`` (or, for a rollc sweep file, ``--resume``) is given.
  Raised as :class:`~rolling_cli.errors.CaseError` (exit 2).
* :func:`claim`: an exclusive OS lock (``flock``) on a lock file beside the
  output, held for the whole run, so a second writer fails at once.
* :func:`new_temp`, :func:`publish`: files are written under a temporary name
  in the target directory, created with mode 0666 minus the umask (as any
  file), then renamed (or hard-linked, when nothing may be replaced).
* :class:`WriteError` (exit 1): an I/O error while writing, naming the path
  and the OS error; the temporary file is removed and an existing output left
  as it was.
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
from pathlib import Path

from ..errors import CaseError, RollingError

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


class WriteError(RollingError):
    """Writing ``path`` failed with an OS error.

    ``fatal`` is True when the HDF5 library itself failed on an open file:
    it cannot release such a file, and its exit handler may crash, so the
    command line ends the process at once after reporting.
    """

    def __init__(self, path: str, error: BaseException, *, fatal: bool = False, note: str = "") -> None:
        self.path = path
        self.error = error
        self.fatal = fatal
        reason = os.strerror(error.errno) if isinstance(error, OSError) and error.errno else str(error)
        text = f"{path}: cannot write: {reason}"
        if note:
            text += f"; {note}"
        super().__init__(text)


def _same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def is_rollc_file(path: str | os.PathLike) -> bool:
    """True for an HDF5 file whose root ``format`` attribute names a rollc result or sweep."""
    try:
        with open(path, "rb") as handle:
            if handle.read(8) != HDF5_SIGNATURE:
                return False
    except OSError:
        return False
    import h5py

    try:
        with h5py.File(path, "r") as handle:
            fmt = handle.attrs.get("format")
    except (OSError, KeyError, ValueError):
        return False
    fmt = fmt.decode() if isinstance(fmt, bytes) else fmt
    return fmt in ("rolling_cli.result", "rolling_cli.sweep")


def check_output(
    path: str | os.PathLike,
    *,
    inputs: tuple = (),
    overwrite: bool = False,
    resume: bool = False,
    kind: str = "result",
) -> None:
    """Refuse an output path before any work is done (raises CaseError, exit 2).

    Never an input, a symbolic link or a non-regular file; an existing regular
    file only with ``overwrite`` (or, for ``kind="sweep"``, ``resume`` on a
    rollc file). ``kind``: ``"result"``, ``"sweep"``, ``"figure"`` or ``"table"``.
    """
    path = os.fspath(path)
    for source in inputs:
        if source is not None and os.path.exists(source) and _same_file(path, source):
            raise CaseError(f"{path}: an input of this command; allowed: an output path that is not an input")
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        info = None
    if info is not None:
        if stat.S_ISLNK(info.st_mode):
            raise CaseError(f"{path}: a symbolic link; allowed: an output path that is a regular file or new")
        if not stat.S_ISREG(info.st_mode):
            raise CaseError(f"{path}: not a regular file; allowed: an output path that is a regular file or new")
        if resume and kind == "sweep":
            if not is_rollc_file(path):
                raise CaseError(f"{path}: not a rolling_cli file; allowed: --resume on a sweep file written by rollc")
        elif not overwrite:
            hint = "--overwrite to replace it, or --resume to continue it" if kind == "sweep" else "--overwrite"
            raise CaseError(f"{path}: exists; allowed: {hint}, or another output name")
    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise CaseError(f"{path}: directory {directory} does not exist; allowed: an output in an existing directory")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise CaseError(f"{path}: directory {directory} is not writable; allowed: an output in a writable directory")


def confined_output(configured: str, case_file: str) -> str:
    """``output.file`` of a case file: a name relative to the working directory, never leaving it.

    An absolute path or one that climbs out (``..``) could overwrite anything
    the user can write when someone else's case is run; such a path is only
    accepted from the command line (``-o``).
    """
    if os.path.isabs(configured) or ".." in Path(configured).parts:
        raise CaseError(
            f"output.file = {configured!r}: leaves the working directory; allowed: a relative path without '..' "
            "(give other paths with -o)",
            file=case_file,
        )
    return configured


def figure_path(result_path: str, suffix: str = ".png") -> str:
    """The figure written beside a result: its name with ``suffix``, never the result's own path."""
    stem, ext = os.path.splitext(result_path)
    candidate = stem + suffix
    if ext.lower() == suffix or _same_file(candidate, result_path):
        candidate = result_path + suffix
    return candidate


@contextlib.contextmanager
def claim(path: str | os.PathLike):
    """Hold an exclusive lock on ``path`` (a lock file ``.NAME.lock`` beside it) for the body.

    A second process claiming the same output gets a CaseError at once. The
    lock is the kernel's (``flock``): a killed process releases it. The lock
    file is removed on release; a claim re-checks that the file it locked is
    still the one in the directory, so removal never lets two writers in.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX: no lock, the rest still applies
        yield
        return
    path = os.fspath(path)
    lock = os.path.join(os.path.dirname(os.path.abspath(path)), f".{os.path.basename(path)}.lock")
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as err:
            os.close(fd)
            if err.errno not in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK):
                raise
            owner = _read_owner(lock)
            raise CaseError(
                f"{path}: another rollc process{owner} is writing it; allowed: wait for it to finish, "
                "or another output name"
            ) from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # the previous holder removed it after we opened it: lock the new one
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        yield
    finally:
        with contextlib.suppress(OSError):
            os.remove(lock)
        os.close(fd)


def _read_owner(lock: str) -> str:
    try:
        with open(lock) as handle:
            pid = handle.read().strip()
    except OSError:
        return ""
    return f" (pid {pid})" if pid.isdigit() else ""


def new_temp(path: str) -> str:
    """Create an empty temporary file beside ``path`` (mode 0666 minus the umask); returns its name."""
    directory = os.path.dirname(os.path.abspath(path))
    base = os.path.basename(path)
    for attempt in range(100):
        tmp = os.path.join(directory, f".{base}.{os.getpid()}.{attempt}.tmp")
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(errno.EEXIST, "no free temporary name", path)


def stale_temps(path: str) -> list[str]:
    """Temporary files a killed writer of ``path`` left behind (remove them while holding its lock)."""
    directory = os.path.dirname(os.path.abspath(path))
    prefix = f".{os.path.basename(path)}."
    return [
        os.path.join(directory, name)
        for name in os.listdir(directory)
        if name.startswith(prefix) and name.endswith(".tmp")
    ]


def preallocate(path: str, size: int) -> None:
    """Reserve ``size`` bytes for ``path``, so that a full disk or a file-size limit fails here, cleanly."""
    fd = os.open(path, os.O_WRONLY)
    try:
        if hasattr(os, "posix_fallocate"):
            os.posix_fallocate(fd, 0, max(int(size), 1))
        else:  # pragma: no cover - macOS: only the size limit is checked
            os.ftruncate(fd, max(int(size), 1))
    finally:
        os.close(fd)


def fsync(path: str) -> None:
    """Flush a file's data to the disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def publish(tmp: str, path: str, replace: bool) -> None:
    """Give the finished ``tmp`` its final name: rename over ``path``, or, when nothing may be
    replaced, hard-link it so that a file created meanwhile is never clobbered."""
    if replace:
        os.replace(tmp, path)
        return
    try:
        os.link(tmp, path)
    except FileExistsError:
        os.remove(tmp)
        raise CaseError(f"{path}: appeared while this command ran; allowed: --overwrite, or another name") from None
    except OSError:  # no hard links here (some network or FAT file systems): a plain rename
        if os.path.lexists(path):
            os.remove(tmp)
            raise CaseError(f"{path}: exists; allowed: --overwrite, or another output name") from None
        os.replace(tmp, path)
        return
    os.remove(tmp)


def remove_quietly(path: str | None) -> None:
    """Remove a temporary file if it is there."""
    if path:
        with contextlib.suppress(FileNotFoundError):
            os.remove(path)


@contextlib.contextmanager
def atomic_file(path: str, replace: bool):
    """Write a plain file (figure, table) under a temporary name; publish it when the body succeeds.

    Yields the temporary path. Any failure removes it; OSErrors become WriteError.
    """
    tmp = new_temp(path)
    try:
        yield tmp
        publish(tmp, path, replace)
    except OSError as err:
        remove_quietly(tmp)
        raise WriteError(path, err) from None
    except BaseException:
        remove_quietly(tmp)
        raise
