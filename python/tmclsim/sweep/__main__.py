"""`tmclsim sweep PROGRAM --matrix FILE …` (also `python -m tmclsim.sweep`):
runs the sweep, prints a summary, writes the table and the failures."""

from __future__ import annotations

import argparse
import pathlib
import sys

from . import MatrixError, load, reproduce_command, sweep


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="tmclsim sweep", description="Run a TMCL program against every scenario of a matrix file (docs/sweeps.md).")
    p.add_argument("program", help="TMCL source file")
    p.add_argument("--matrix", required=True, help="the matrix file (TOML)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, help="worker processes of an embedded Dask cluster (default: one per core; 0: in this process)")
    where.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://HOST:8786")
    p.add_argument("--out", help="write the table: FILE.parquet or FILE.csv")
    p.add_argument("--failures", default="sweep-failures", help="directory for each failure's world and setup files (default: sweep-failures)")
    p.add_argument("--batch", type=int, default=None, help="scenarios per task (default: about 8 tasks per worker)")
    a = p.parse_args(argv)
    if a.workers is not None and a.workers < 0:
        p.error("--workers: 0 or more")
    if a.out and pathlib.Path(a.out).suffix not in (".parquet", ".csv"):
        p.error("--out: FILE.parquet or FILE.csv")
    try:
        mx = load(a.matrix)
    except (MatrixError, OSError) as e:
        print(f"tmclsim sweep: {a.matrix}: {e}", file=sys.stderr)
        return 2
    try:
        result = sweep(a.program, mx, workers=a.workers, scheduler=a.scheduler, out=a.out, failures=a.failures, batch=a.batch, progress=True, details=True)
    except Exception as e:  # an assembly error, an unreachable scheduler
        print(f"tmclsim sweep: {e}", file=sys.stderr)
        return 2
    t = result.table
    n, failed = len(t), int((~t.passed).sum())
    print(f"{n} scenarios in {result.seconds:.2f} s ({n / max(result.seconds, 1e-9):.0f}/s): {n - failed} passed, {failed} failed")
    if failed:
        counts = t[~t.passed].groupby("failed_check").size().sort_values(ascending=False)
        for check, k in counts.items():
            first = t[(~t.passed) & (t.failed_check == check)].iloc[0]
            why = f"   (scenario {first.scenario}: {first.error})" if first.error else ""
            print(f"  {k:6d}  {check}{why}")
        print(f"failures reproduce with (files in {a.failures}/):")
        for _, row in t[~t.passed].head(5).iterrows():
            print("  " + reproduce_command(a.program, mx, row.to_dict(), a.failures))
        if failed > 5:
            print(f"  … and {failed - 5} more")
    if a.out:
        print(f"table: {a.out}")
    return 1 if failed else 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except BrokenPipeError:  # the reader stopped early (`| head`)
        sys.stderr.close()
        sys.exit(0)
