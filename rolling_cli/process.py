"""The ``rollc`` process itself: how it uses memory and how it ends (the console entry's settings).

The library leaves its host's process alone; :func:`rolling_cli.cli.entry` (the console script)
calls :func:`reuse_freed_memory` at start and asks :func:`fast_exit_safe` before it ends the
process without the interpreter's teardown.
"""

from __future__ import annotations

import sys

#: Modules whose presence means the process may still own workers, threads or files that only the
#: interpreter's own shutdown ends cleanly: with any of them loaded, :func:`rolling_cli.cli.entry` exits normally.
_SLOW_EXIT_MODULES = ("multiprocessing", "concurrent.futures.process", "distributed", "dask", "matplotlib")


def fast_exit_safe() -> bool:
    """Whether the process may end without the interpreter's teardown: only the main thread runs, no
    worker machinery is loaded and no HDF5 file is open (HDF5's own exit handler would flush it)."""
    if any(name in sys.modules for name in _SLOW_EXIT_MODULES):
        return False
    threading = sys.modules.get("threading")
    if threading is not None and threading.active_count() > 1:
        return False
    h5py = sys.modules.get("h5py")
    if h5py is not None and h5py.h5f.get_obj_count(h5py.h5f.OBJ_ALL, h5py.h5f.OBJ_FILE):
        return False
    return True


#: glibc's mallopt parameters (malloc.h) and the values :func:`reuse_freed_memory` sets: blocks up
#: to 32 MiB (glibc's largest mmap threshold) from the heap, the heap's free top kept up to 1 GiB,
#: and one arena (a BEM body's second thread allocates from the heap's reused pages too).
_MALLOC_SETTINGS = ((-3, 32 * 2**20), (-1, 2**30), (-8, 1))  # M_MMAP_THRESHOLD, M_TRIM_THRESHOLD, M_ARENA_MAX


def reuse_freed_memory() -> None:
    """Let the process reuse the memory of freed arrays instead of returning it to the system.

    By default glibc serves large blocks (above a threshold that adapts from 128 KiB) by mmap
    and returns freed ones and the heap's free top to the system, so the next array of that
    size faults in every page anew (zeroed by the kernel): a finite roller's build and solve
    (arrays of 1-5 MB, allocated and freed many times) took ~40,000 page faults, ~0.1 s of system
    time on a virtual machine. With blocks up to 32 MiB from the heap and its top kept
    (``mallopt``, as the MALLOC_MMAP_THRESHOLD_ and MALLOC_TRIM_THRESHOLD_ variables would set
    them) the freed pages are reused: ~18,000 faults, the same peak memory (one arena: the
    second thread of :func:`.influence.bem.condense.solve_all` adds ~2,500 faults and 8 MB of peak
    memory in an arena of its own). The console command
    only (the library leaves its host's allocator alone); a no-op where the C library has no
    ``mallopt`` (not glibc) or refuses a value."""
    try:
        import ctypes

        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # no C library to load, or not glibc's
        return
    for parameter, value in _MALLOC_SETTINGS:
        mallopt(parameter, value)
