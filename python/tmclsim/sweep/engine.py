"""Where scenarios run: in this process, on an embedded Dask LocalCluster
sized to the machine, or on a running Dask cluster (`scheduler`). Scenarios
go in batches, one task per batch, so the per-task overhead stays small;
results come back as tasks complete."""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Iterator, List, Optional, Tuple

from . import scenario
from .matrix import Matrix

Result = Tuple[Dict[str, Any], Optional[Dict[str, str]]]


def batches(items: List[Tuple[int, Dict[str, Any]]], workers: int, size: Optional[int]) -> List[List[Tuple[int, Dict[str, Any]]]]:
    """About eight batches per worker (so that late ones balance), at most
    1000 scenarios each (a few seconds of work)."""
    if size is None:
        size = max(1, min(1000, -(-len(items) // max(1, 8 * workers))))
    return [items[i : i + size] for i in range(0, len(items), size)]


def serial(mx: Matrix, programs: Dict[str, bytes], items, on_done: Callable[[int], None]) -> Iterator[Result]:
    for i, values in items:
        r = scenario.run(mx, programs, i, values)
        on_done(1)
        yield r


def dask(mx: Matrix, programs: Dict[str, bytes], items, on_done: Callable[[int], None], workers: Optional[int], scheduler: Optional[str], batch: Optional[int]) -> Iterator[Result]:
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
        futures = [client.submit(scenario.run_batch, mx_future, programs_future, b, pure=False) for b in batches(items, n, batch)]
        for f in as_completed(futures):
            rows = f.result()
            on_done(len(rows))
            yield from rows
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
