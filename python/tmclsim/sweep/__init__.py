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
import sys
import time
from typing import Any, Dict, Optional, Union

from . import engine, scenario
from .matrix import Matrix, MatrixError, load, parse

__all__ = ["sweep", "Matrix", "MatrixError", "load", "parse", "Sweep"]

_Path = Union[str, "os.PathLike[str]"]


class Sweep:
    """What a finished sweep knows beyond its table: the failures' files
    and how long it took."""

    def __init__(self, table, failures: Dict[int, Dict[str, str]], seconds: float):
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
    files named failure-N.toml and failure-N.setup), so that the directory
    holds this sweep's failures and no others."""
    d = pathlib.Path(directory)
    if d.is_dir():
        for f in d.iterdir():
            if _FAILURE_FILE.fullmatch(f.name) and f.is_file():
                f.unlink()


def write_failure(directory: _Path, index: int, files: Dict[str, str]) -> pathlib.Path:
    """`failure-N.toml` (the world) and `failure-N.setup` (the parameter
    set as direct-mode commands) for `tmclsim run --world … --setup …`."""
    d = pathlib.Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    world = d / f"failure-{index}.toml"
    world.write_text(files["world"])
    (d / f"failure-{index}.setup").write_text(files["setup"])
    return world


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
    import pandas as pd

    mx = matrix if isinstance(matrix, Matrix) else parse(matrix) if isinstance(matrix, dict) else load(matrix)
    programs = _programs(program, mx)
    items = list(enumerate(mx.scenarios()))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(items), unit="scenario", file=sys.stderr, disable=not sys.stderr.isatty())

    def done(n):
        if bar is not None:
            bar.update(n)

    start = time.monotonic()
    if workers == 0 and not scheduler:
        results = engine.serial(mx, programs, items, done)
    else:
        results = engine.dask(mx, programs, items, done, workers, scheduler, batch)
    rows, failed = [], {}
    for row, files in results:
        rows.append(row)
        if files is not None:
            failed[row["scenario"]] = files
    if bar is not None:
        bar.close()
    seconds = time.monotonic() - start
    table = pd.DataFrame(sorted(rows, key=lambda r: r["scenario"])).reset_index(drop=True)
    if out is not None:
        path = pathlib.Path(out)
        if path.suffix == ".parquet":
            table.to_parquet(path, index=False)
        elif path.suffix == ".csv":
            table.to_csv(path, index=False)
        else:
            raise ValueError(f"{path}: the table is written as .parquet or .csv")
    if failures is not None:
        clear_failures(failures)
        for i, files in failed.items():
            write_failure(failures, i, files)
    return Sweep(table, failed, seconds) if details else table
