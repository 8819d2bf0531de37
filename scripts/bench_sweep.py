"""Benchmarks of scenario sweeps; prints a table (docs/sweeps.md quotes it).

The scenarios are the homing example's (examples/sweep-homing), each run for
the full 60 s of virtual time (no early stop), with home switch positions
drawn at random so that every scenario differs.

- in process: scenarios per second on one core;
- Dask LocalCluster with 1 and with 2 worker processes: throughput and the
  scaling from 1 to 2;
- the cost of a task: the same scenarios in tasks of one scenario each
  against tasks of many.

Every time is the best of three runs (other processes on the machine only
ever make a run slower); the load average before the first run is printed
with the table.

Usage: python scripts/bench_sweep.py [scenarios]   (default 4000)
Needs: pip install './python[sweep]'
"""

import os
import pathlib
import sys
import time

import tmclsim

ROOT = pathlib.Path(__file__).resolve().parents[1]
PROGRAM = ROOT / "examples" / "sweep-homing" / "homing.tmc"
N = int(sys.argv[1]) if len(sys.argv) > 1 else 4000


def matrix(n):
    return {
        "duration": "60s",
        "step": "100ms",
        "seed": 1,
        "metrics": ["time", "var 0"],
        "world": {"base": "stage", "axis": [{"home_switch": {"from": 0, "width": 2000}}]},
        "vary": [{"name": "home", "world": "axis.0.home_switch.from", "random": {"min": -900000, "max": 900000, "count": n}}],
        "stop": {"program_ended": False},
        "check": [{"name": "homed", "expr": "var 0 == 1"}],
    }


def timed(repeat=3, **kw):
    """The best of `repeat` runs, and the table."""
    n = kw.pop("n", N)
    best = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        table = tmclsim.sweep(PROGRAM, matrix(n), **kw)
        s = time.perf_counter() - t0
        best = s if best is None else min(best, s)
    return best, table


def main():
    rows = []
    load = os.getloadavg()[0]
    timed(workers=0, n=4, repeat=1)  # warm up: imports, first assembly
    serial_s, serial = timed(workers=0)
    per = serial_s / N
    rows.append(("in process, 1 core", f"{N / serial_s:.0f} scenarios/s ({per * 1e3:.2f} ms per scenario of 60 s virtual time)"))
    from dask.distributed import LocalCluster

    times = {}
    for k in (1, 2):
        t0 = time.perf_counter()
        with LocalCluster(n_workers=k, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            start_s = time.perf_counter() - t0
            timed(scheduler=cluster.scheduler_address, n=2 * k, repeat=1)  # warm up the workers
            times[k], table = timed(scheduler=cluster.scheduler_address)
            assert table.equals(serial), "the tables differ"
            # Task overhead: tasks of one scenario against tasks of N/(8k).
            if k == 2:
                m = min(N, 1000)
                small_s, _ = timed(scheduler=cluster.scheduler_address, n=m, batch=1)
                big_s, _ = timed(scheduler=cluster.scheduler_address, n=m, batch=max(1, m // 16))
                overhead = max(0.0, (small_s - big_s) * k / (m - 16))
        rows.append((f"Dask LocalCluster, {k} worker{'s' if k > 1 else ''}", f"{N / times[k]:.0f} scenarios/s ({times[k]:.2f} s; the cluster started in {start_s:.2f} s)"))
    rows.append(("scaling 1 → 2 workers", f"{times[1] / times[2]:.2f}×"))
    rows.append(("task overhead (per task, on 2 workers: batch=1 against 16 tasks)", f"{overhead * 1e3:.2f} ms"))
    print(f"{N} scenarios of the homing example, 60 s of virtual time each; {os.cpu_count()} cores, load average {load:.2f} before the first run; best of 3")
    print()
    print("| measurement | result |")
    print("|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |")


if __name__ == "__main__":
    main()
