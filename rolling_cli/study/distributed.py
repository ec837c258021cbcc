"""Sweeps on a Dask cluster (optional extra ``rolling-cli[dask]``).

``--scheduler tcp://HOST:PORT`` connects to a running ``dask.distributed``
scheduler; ``--scheduler local:N`` starts a ``LocalCluster`` of N worker
processes with one thread each. The sweep hands whole chunks to the cluster
(cases that share an influence and a warm-start path stay together) and the
records stream back to the single writer in this process, so the file, its
layout, ``--resume`` and failure records are those of a local run. Each task
runs with one BLAS thread, so the numbers are bitwise the serial run's.
"""

from __future__ import annotations

import contextlib
import logging

from ..errors import CaseError

_limits = None


def solve_chunk_task(base, chunk, warm: bool, use_cache: bool) -> list:
    """A cluster task: the records of one chunk (built and solved there), with one BLAS thread.

    The limit is set once per worker process and kept (threadpoolctl's library scan costs ~30 ms).
    Workers should start with ``OPENBLAS_NUM_THREADS=1``, as dask's nanny starts them by default:
    an OpenBLAS that started with more threads, limited to one at run time, was measured 10 times
    slower when called from a thread other than the main one, where dask runs its tasks.
    """
    global _limits
    from .. import blas
    from .chunk import solve_items

    if _limits is None:
        _limits = blas.limit_threads()
    return list(solve_items(base, chunk, warm, use_cache))


@contextlib.contextmanager
def cluster(scheduler: str):
    """Yields ``(executor, workers)``: a concurrent.futures executor on the cluster and its worker count."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise CaseError(
            f"--scheduler {scheduler}: dask.distributed is not installed; allowed: pip install 'rolling-cli[dask]'"
        ) from None
    count = 0
    if scheduler.startswith("local:"):
        try:
            count = int(scheduler.split(":", 1)[1])
        except ValueError:
            count = 0
        if count < 1:
            raise CaseError(
                f"--scheduler {scheduler}: no worker count; allowed: local:N with N >= 1, or tcp://HOST:PORT"
            )
    quiet = logging.getLogger("distributed")
    level = quiet.level
    quiet.setLevel(logging.ERROR)  # its INFO lines (comms closing, workers leaving) are not the user's business
    local = None
    try:
        if count:
            import dask

            # the workers' sampling profiler (a thread waking every 10 ms) slows CPU-bound tasks; not needed
            with dask.config.set({"distributed.worker.profile.enabled": False}):
                local = LocalCluster(
                    n_workers=count,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=logging.ERROR,
                )
        try:
            client = Client(local if local is not None else scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as err:
            raise CaseError(
                f"--scheduler {scheduler}: cannot connect ({err}); allowed: the address of a running dask scheduler"
            ) from None
        with client:
            workers = max(1, sum(client.nthreads().values()))
            yield client.get_executor(pure=False), workers
    finally:
        if local is not None:
            local.close()
        quiet.setLevel(level)
