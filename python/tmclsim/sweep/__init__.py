"""Scenario sweeps: one TMCL program against many worlds and parameter
sets, in virtual time, in this process or on a Dask cluster
(docs/sweeps.md).

    import tmclsim
    table = tmclsim.sweep("homing.tmc", "sweep.toml")           # pandas DataFrame
    table[~table.passed]
"""

from __future__ import annotations

import os
import pathlib
import re
import secrets
import sys
import time
from typing import Any, Dict, Optional, Union

from . import engine, scenario
from .matrix import Matrix, MatrixError, load, parse
from .table import Failures, Table

__all__ = ["sweep", "Matrix", "MatrixError", "load", "parse", "Sweep"]

_Path = Union[str, "os.PathLike[str]"]


class Sweep:
    """What a finished sweep knows beyond its table: the failures' files
    (made again when asked for) and how long it took."""

    def __init__(self, table, failures: Failures, seconds: float):
        self.table = table
        self.failures = failures
        self.seconds = seconds


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
    d = pathlib.Path(directory)
    i = row["scenario"]
    profile = scenario.profile_of(mx, row)
    return (f"tmclsim run {program} --module {profile} --world {d / f'failure-{i}.toml'} "
            f"--setup {d / f'failure-{i}.setup'} --for {row.get('time') or mx.duration}s")


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
    removed first)."""
    import pandas  # noqa: F401 (the table's: missing, the sweep fails now, not at its end)

    mx = matrix if isinstance(matrix, Matrix) else parse(matrix) if isinstance(matrix, dict) else load(matrix)
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
        elif path.suffix == ".csv":
            frame.to_csv(path, index=False)
        else:
            raise ValueError(f"{path}: the table is written as .parquet or .csv")
    return Sweep(frame, Failures(mx, table.failed()), seconds) if details else frame
