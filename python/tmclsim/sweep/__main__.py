"""`tmclsim sweep PROGRAM --matrix FILE …` (also `python -m tmclsim.sweep`):
runs the sweep, prints a summary, writes the table and the failures. A bad
option or matrix ends it with one line on stderr and exit status 2."""

from __future__ import annotations

import argparse
import sys

from . import MAX_BATCH, MAX_WORKERS, MatrixError, check_options, load, reproduce_command, sweep


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):
        # One line, without the usage (`--help` has it).
        self.exit(2, f"{self.prog}: {message}\n")


def _whole(lo: int, hi: int):
    def parse(text: str) -> int:
        try:
            n = int(text.strip(), 10)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text[:40]}' is not a whole number ({lo}…{hi})") from None
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"{n} is outside {lo}…{hi}")
        return n

    parse.__name__ = "whole number"
    return parse


def main(argv=None) -> int:
    p = _Parser(prog="tmclsim sweep", description="Run a TMCL program against every scenario of a matrix file (docs/sweeps.md).")
    p.add_argument("program", help="TMCL source file")
    p.add_argument("--matrix", required=True, help="the matrix file (TOML)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=_whole(0, MAX_WORKERS), default=None,
                       help=f"worker processes of an embedded Dask cluster (default: one per core; 0: in this process; at most {MAX_WORKERS})")
    where.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://HOST:8786")
    p.add_argument("--out", help="write the table: FILE.parquet or FILE.csv")
    p.add_argument("--failures", default="sweep-failures", help="directory for each failure's world and setup files (default: sweep-failures)")
    p.add_argument("--batch", type=_whole(1, MAX_BATCH), default=None, help=f"scenarios per task (default: about 8 tasks per worker, at most 1000; 1…{MAX_BATCH})")
    a = p.parse_args(argv)
    try:
        check_options(scheduler=a.scheduler, out=a.out, failures=a.failures, prefix="--")
    except ValueError as e:
        p.error(str(e))
    try:
        mx = load(a.matrix)
    except (MatrixError, OSError) as e:
        message = str(e)
        print(f"tmclsim sweep: {message if message.startswith(str(a.matrix)) else f'{a.matrix}: {message}'}", file=sys.stderr)
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
