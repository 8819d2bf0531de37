"""Scenario sweeps: one TMCL program against many worlds and parameter
sets, in virtual time, in this process or on a Dask cluster
(docs/sweeps.md).

    import tmclsim
    table = tmclsim.sweep("homing.tmc", "sweep.toml")           # pandas DataFrame
    table[~table.passed]
"""

from __future__ import annotations

import math
import numbers
import operator
import os
import pathlib
import re
import secrets
import shlex
import sys
import time
from typing import Any, Dict, Optional, Union

from . import engine, scenario
from .matrix import MAX_DURATION, MAX_LOOKS, MAX_SCENARIOS, MIN_STEP, Matrix, MatrixError, count_text, load, parse, seconds_text
from .table import Failures, Table

__all__ = ["sweep", "Matrix", "MatrixError", "load", "parse", "Sweep"]

_Path = Union[str, "os.PathLike[str]"]

# The limits of the options (docs/sweeps.md, "Limits").
MAX_WORKERS = 256  # worker processes of an embedded cluster
MAX_BATCH = 100_000  # scenarios per task


class Sweep:
    """What a finished sweep knows beyond its table: the failures' files
    (made again when asked for) and how long it took."""

    def __init__(self, table, failures: Failures, seconds: float):
        self.table = table
        self.failures = failures
        self.seconds = seconds


def whole(value: Any, name: str, lo: int, hi: int) -> int:
    """An option that is a whole number from lo to hi (not true or false);
    otherwise a ValueError naming it."""
    try:
        if isinstance(value, bool):
            raise TypeError
        n = operator.index(value)
    except TypeError:
        raise ValueError(f"{name}: a whole number {lo}…{hi}, not {value!r}"[:200]) from None
    if not lo <= n <= hi:
        raise ValueError(f"{name}: {n} is outside {lo}…{hi}")
    return n


def check_options(workers: Any = None, scheduler: Any = None, out: Any = None, failures: Any = None, batch: Any = None, prefix: str = "") -> None:
    """Every option of a sweep, before anything runs: a ValueError naming
    the first bad one (with `prefix`, `--` for the command line)."""
    if workers is not None:
        whole(workers, f"{prefix}workers", 0, MAX_WORKERS)
    if batch is not None:
        whole(batch, f"{prefix}batch", 1, MAX_BATCH)
    if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
        raise ValueError(f"{prefix}scheduler: the address of a Dask scheduler, e.g. tcp://HOST:8786")
    if out is not None:
        path = pathlib.Path(out)
        if path.suffix not in (".parquet", ".csv"):
            raise ValueError(f"{prefix}out: {path}: the table is written as .parquet or .csv")
        if not path.parent.is_dir():
            raise ValueError(f"{prefix}out: {path.parent} is no directory")
    if failures is not None:
        d = pathlib.Path(failures)
        if not str(failures) or (d.exists() and not d.is_dir()):
            raise ValueError(f"{prefix}failures: {str(failures) or repr('')} is no directory")


def check_limits(mx: Matrix) -> None:
    """The limits a parsed matrix keeps, for a Matrix made by hand."""
    if not (isinstance(mx.duration, numbers.Real) and math.isfinite(mx.duration) and 0 < mx.duration <= MAX_DURATION):
        raise MatrixError(f"duration: {mx.duration!r}: more than 0, at most {MAX_DURATION:.0f} s")
    if not (isinstance(mx.step, numbers.Real) and MIN_STEP <= mx.step <= mx.duration):
        raise MatrixError(f"step: {mx.step!r}: at least {MIN_STEP} s, at most the duration")
    if math.ceil(mx.duration / mx.step - 1e-9) > MAX_LOOKS:
        raise MatrixError(f"step: more than {MAX_LOOKS} looks per scenario")
    if mx.count() > MAX_SCENARIOS:
        raise MatrixError(f"vary: {count_text(mx.count())} scenarios; at most {MAX_SCENARIOS}")


def _programs(program, mx: Matrix) -> Dict[str, bytes]:
    """The program assembled for every profile the sweep runs on."""
    import tmclsim

    profiles = {mx.profile}
    for a in mx.axes:
        if a.target == "profile":
            profiles |= {str(v).lower() for v in a.values}
    out = {}
    for p in sorted(profiles):
        if isinstance(program, tmclsim.Program):
            out[p] = program.to_binary()
        else:
            out[p] = tmclsim.assemble_file(program, profile=p).to_binary()
    return out


_FAILURE_FILE = re.compile(r"failure-[0-9]+\.(toml|setup)")


def clear_failures(directory: _Path) -> None:
    """Removes the failure files an earlier sweep left in `directory` (only
    entries named failure-N.toml and failure-N.setup: files, or links,
    which go themselves, never what they point to), so that the directory
    holds this sweep's failures and no others."""
    d = pathlib.Path(directory)
    if d.is_dir():
        with os.scandir(d) as entries:
            for e in entries:
                if _FAILURE_FILE.fullmatch(e.name) and (e.is_symlink() or e.is_file(follow_symlinks=False)):
                    os.unlink(e.path)


def _write_new(d: pathlib.Path, name: str, text: str) -> None:
    """Writes `d/name` as a new file: first a file of a new name, created
    (O_EXCL, O_NOFOLLOW) so that nothing else is written through, then
    renamed over `name`, which replaces whatever entry is there, a link
    included, and never writes where a link points."""
    while True:
        temporary = d / f".{name}.{secrets.token_hex(6)}"
        try:
            fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o666)
            break
        except FileExistsError:
            continue
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(temporary, d / name)
    except BaseException:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        raise


def write_failure(directory: _Path, index: int, files: Dict[str, str]) -> pathlib.Path:
    """`failure-N.toml` (the world) and `failure-N.setup` (the parameter
    set as direct-mode commands) for `tmclsim run --world … --setup …`.
    Links planted under those names are replaced, not followed."""
    d = pathlib.Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    _write_new(d, f"failure-{index}.toml", files["world"])
    _write_new(d, f"failure-{index}.setup", files["setup"])
    return d / f"failure-{index}.toml"


def reproduce_command(program: _Path, mx: Matrix, row: Dict[str, Any], directory: _Path) -> str:
    """The `tmclsim run` command line that replays a failure: its time is
    the scenario's when that is a time (a scenario that could not start
    has none: then the matrix's duration), every word quoted for a shell."""
    d = pathlib.Path(directory)
    i = int(row["scenario"])
    profile = scenario.profile_of(mx, row)
    t = row.get("time")
    if not (isinstance(t, numbers.Real) and not isinstance(t, bool) and math.isfinite(t) and 0 <= t <= MAX_DURATION):
        t = mx.duration
    words = ["tmclsim", "run", str(program), "--module", profile, "--world", str(d / f"failure-{i}.toml"),
             "--setup", str(d / f"failure-{i}.setup"), "--for", f"{seconds_text(float(t))}s"]
    return " ".join(shlex.quote(w) for w in words)


def sweep(program, matrix, workers: Optional[int] = None, scheduler: Optional[str] = None, out: Optional[_Path] = None,
          failures: Optional[_Path] = None, batch: Optional[int] = None, progress: bool = False, details: bool = False):
    """Runs the program (a path, or a `tmclsim.Program`) against every
    scenario of `matrix` (a path, a parsed `Matrix` or a dict). `workers=0`
    runs in this process; otherwise on a Dask LocalCluster of `workers`
    processes (default: one per core), or on the cluster at `scheduler`.
    Returns a pandas DataFrame, one row per scenario in scenario order
    (with `details=True`, a `Sweep` with the failures' files too). `out`
    writes the table (.parquet or .csv); `failures` a directory for each
    failure's world and setup files (those an earlier sweep left there are
    removed first). Every option and the matrix are checked before
    anything runs (ValueError; MatrixError for the matrix)."""
    import pandas  # noqa: F401 (the table's: missing, the sweep fails now, not at its end)

    check_options(workers=workers, scheduler=scheduler, out=out, failures=failures, batch=batch)
    if isinstance(matrix, Matrix):
        mx = matrix
        check_limits(mx)
    else:
        mx = parse(matrix) if isinstance(matrix, dict) else load(matrix)
    programs = _programs(program, mx)
    count = mx.count()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=count, unit="scenario", file=sys.stderr, disable=not sys.stderr.isatty())

    def done(n):
        if bar is not None:
            bar.update(n)

    if failures is not None:
        clear_failures(failures)
    start = time.monotonic()
    if workers == 0 and not scheduler:
        results = engine.serial(mx, programs, count, done)
    else:
        results = engine.dask(mx, programs, count, done, workers, scheduler, batch)
    # Rows are not kept: their values go to the table's columns, a
    # failure's files to the directory as it comes.
    table = Table(mx, count)
    for row, files in results:
        table.add(row)
        if files is not None and failures is not None:
            write_failure(failures, row["scenario"], files)
    if bar is not None:
        bar.close()
    seconds = time.monotonic() - start
    frame = table.frame()
    if out is not None:
        path = pathlib.Path(out)
        if path.suffix == ".parquet":
            frame.to_parquet(path, index=False)
        else:
            frame.to_csv(path, index=False)
    return Sweep(frame, Failures(mx, table.failed()), seconds) if details else frame
