"""Where scenarios run: in this process, on an embedded Dask LocalCluster
sized to the machine, or on a running Dask cluster (`scheduler`). Scenarios
go in batches, one task per batch, so the per-task overhead stays small;
a batch is a range of scenario numbers, which the worker turns into
scenarios itself. Results come back as tasks complete, with a few tasks per
worker in flight: neither the scenarios nor the results of a sweep are ever
held at once."""

from __future__ import annotations

import itertools
import os
from typing import Any, Callable, Dict, Iterator, Optional, Tuple

from . import scenario
from .matrix import Matrix

Result = Tuple[Dict[str, Any], Optional[Dict[str, str]]]

# Tasks in flight per worker: enough that none waits for the next.
IN_FLIGHT = 4


def batches(count: int, workers: int, size: Optional[int]) -> Iterator[Tuple[int, int]]:
    """Scenarios `start` up to `stop`: about eight batches per worker (so
    that late ones balance), at most 1000 scenarios each (a few seconds of
    work)."""
    if size is None:
        size = max(1, min(1000, -(-count // max(1, 8 * workers))))
    for start in range(0, count, size):
        yield start, min(count, start + size)


def serial(mx: Matrix, programs: Dict[str, bytes], count: int, on_done: Callable[[int], None]) -> Iterator[Result]:
    for i, values in enumerate(mx.scenarios(0, count)):
        r = scenario.run(mx, programs, i, values)
        on_done(1)
        yield r


def dask(mx: Matrix, programs: Dict[str, bytes], count: int, on_done: Callable[[int], None], workers: Optional[int], scheduler: Optional[str],
         batch: Optional[int]) -> Iterator[Result]:
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    if scheduler:
        client = Client(scheduler)
        n = max(1, len(client.scheduler_info().get("workers", {})))
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
        client = Client(cluster)
    try:
        mx_future = client.scatter(mx, broadcast=True)
        programs_future = client.scatter(programs, broadcast=True)
        todo = batches(count, n, batch)

        def submit(b: Tuple[int, int]):
            return client.submit(scenario.run_batch, mx_future, programs_future, b[0], b[1], pure=False)

        running = as_completed([submit(b) for b in itertools.islice(todo, IN_FLIGHT * n)])
        for f in running:
            rows = f.result()
            # The worker may forget the result: it is here now.
            f.release()
            nxt = next(todo, None)
            if nxt is not None:
                running.add(submit(nxt))
            on_done(len(rows))
            yield from rows
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
