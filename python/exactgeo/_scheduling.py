"""How exactgeo.distributed runs its blocks: on Dask (a client given, or a LocalCluster started for the run) or on
any concurrent.futures executor, with retries and a callback as each block finishes. The blocks themselves, and
the store they write into, are distributed.py's and the store component's business (docs/distributed.md)."""

from __future__ import annotations

import concurrent.futures
import os
import uuid
from typing import Any, Callable

from . import _inputs

MISSING_EXTRA = ("exactgeo.distributed needs its extra, dask[distributed] and zarr: "
                 "pip install 'dask[distributed]>=2023.1' 'zarr>=3'")
# The blocks a run computes: each block's arguments to the block function after the context, by block index.
Tasks = dict[int, tuple[Any, ...]]
# Called with a block's index once the block is done.
Finished = Callable[[int], None]
# The block function: (context, *arguments) -> anything; it writes the block into the store itself.
Compute = Callable[..., Any]


def _dask_client_type() -> type | None:
    try:
        from distributed import Client
    except ImportError:
        return None
    return Client


# Dask's housekeeping is tuned for interactive work: every worker ticks its event loop every 20 ms, samples its
# threads' stacks every 10 ms for the profiler and checks its memory every 100 ms. Beside blocks that keep
# every core busy for seconds, that took about 4% of the CPU time on 2 cores (the workers' main threads:
# 0.13 s each in 6 s, 650 wake-ups), and each wake-up preempts a block. The cluster exactgeo starts checks
# once a second and does not profile (0.02 s, 30 wake-ups).
_UNHURRIED_HOUSEKEEPING = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "1s",
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.worker.profile.enabled": False,
    "distributed.worker.memory.monitor-interval": "1s",
}


def local_cluster(workers: int | None = None) -> Any:
    """The LocalCluster distance_matrix_to_zarr starts when given no client: `workers` single-threaded worker
    processes (default: one per core) on 127.0.0.1, no dashboard, Dask's housekeeping slowed to once a second
    so that it takes little from the blocks. Use it as a context manager, with a Client on it, to run several
    matrices on one cluster:

        with distributed.local_cluster() as cluster, dask.distributed.Client(cluster) as client:
            distributed.distance_matrix_to_zarr(mesh, sources, "d.zarr", client=client)
    """
    try:
        import dask
        from distributed import LocalCluster
    except ImportError:
        raise ImportError(MISSING_EXTRA) from None
    count = _inputs.count((os.cpu_count() or 1) if workers is None else workers, "workers", minimum=1)
    # The scheduler takes the configuration set while it starts. The nannies hand `config` to every worker
    # process they start, a worker restarted after a crash included, which sets it key by key (dotted keys: a
    # nested dictionary would replace whole sections). No dashboard; the scheduler's HTTP server (health
    # checks) on a free loopback port, not 8787.
    with dask.config.set(_UNHURRIED_HOUSEKEEPING):
        return LocalCluster(n_workers=count, threads_per_worker=1, processes=True, host="127.0.0.1",
                            dashboard_address="127.0.0.1:0", scheduler_kwargs={"dashboard": False},
                            config=_UNHURRIED_HOUSEKEEPING)


def is_dask_client(client: Any) -> bool:
    client_type = _dask_client_type()
    return client_type is not None and isinstance(client, client_type)


def check_client(client: Any) -> None:
    """Before the store is touched: a client that cannot run the blocks leaves it as it was."""
    if client is not None and not is_dask_client(client) and not isinstance(client, concurrent.futures.Executor):
        raise TypeError(f"client must be None, a dask.distributed Client or a concurrent.futures.Executor, "
                        f"not {type(client).__name__}")


def run(client: Any, compute: Compute, tasks: Tasks, context: Any, reference: Any, retries: int,
        finished: Finished) -> None:
    """Runs `compute(context, *tasks[b])` for every block b: on Dask with `context` (scattered to every worker
    once), on an executor with `reference` (small, pickled with each task; each process reads what it stands for
    once)."""
    if client is None:
        try:
            from distributed import Client
        except ImportError:
            raise ImportError(MISSING_EXTRA) from None
        with local_cluster() as cluster, Client(cluster) as own:
            _run_dask(own, compute, tasks, context, retries, finished)
    elif is_dask_client(client):
        _run_dask(client, compute, tasks, context, retries, finished)
    else:
        _run_executor(client, compute, tasks, reference, retries, finished)


def _run_dask(client: Any, compute: Compute, tasks: Tasks, context: Any, retries: int, finished: Finished) -> None:
    from distributed import as_completed

    shared = client.scatter(context, broadcast=True, hash=False)  # the mesh goes to each worker once
    run_id = uuid.uuid4().hex[:8]
    futures = {}
    for block, arguments in tasks.items():
        future = client.submit(compute, shared, *arguments, key=f"exactgeo-block-{run_id}-{block}",
                               retries=retries, pure=False)
        futures[future] = block
    try:
        for future in as_completed(list(futures)):
            future.result()  # raises the block's error once its retries are spent
            finished(futures[future])
    except BaseException:
        client.cancel(list(futures))
        raise


def _run_executor(executor: concurrent.futures.Executor, compute: Compute, tasks: Tasks, reference: Any,
                  retries: int, finished: Finished) -> None:
    attempts = {block: 0 for block in tasks}
    pending = {executor.submit(compute, reference, *arguments): block for block, arguments in tasks.items()}
    try:
        while pending:
            complete, _ = concurrent.futures.wait(pending, return_when=concurrent.futures.FIRST_COMPLETED)
            for future in complete:
                block = pending.pop(future)
                error = future.exception()
                if error is None:
                    finished(block)
                elif isinstance(error, concurrent.futures.BrokenExecutor) or attempts[block] >= retries:
                    raise error
                else:
                    attempts[block] += 1
                    pending[executor.submit(compute, reference, *tasks[block])] = block
    except BaseException:
        for future in pending:
            future.cancel()
        raise
