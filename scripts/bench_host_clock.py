"""PyTrinamic's example scripts for the TMCM-1140, unchanged, in virtual
time: each at speed 1 as written, then through `tmclsim clock --speed N`
against a TMCM-1140 served at N; prints rows of the table in
docs/host-software.md.

- wall time: the whole run, from starting the process to its end;
- outside the session: of it, the time before the script's first command
  and after its last (the interpreter, PyTrinamic's import, the clock
  patch, the exit): what no speed shortens;
- session: from the script's first command to its last (the served
  module's frame log), in wall time and in the module's virtual time;
- speed-up: the speed-1 run's wall time over this run's, for the whole
  run and for the session;
- same: the output prints the same results as at speed 1
  (tests/pytrinamic/pytrinamic_examples.py: `differences`), in every run.

Speed 1 runs once; every other time is the best of three runs (other
processes on the machine only ever make a run slower). The examples come
from PyTrinamic's source distribution (pip download, into
target/pytrinamic-sdist), the world from
tests/pytrinamic/tmcm1140_examples_world.toml.

Usage: python scripts/bench_host_clock.py TMCLSIM [SPEED …]   (default 50 100)
Needs: PyTrinamic (tests/pytrinamic/requirements.txt) and the Python
package (pip install ./python) in this Python.
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "pytrinamic"))
from pytrinamic_examples import MODULE, SCRIPTS, WORLD, clock_command, differences, examples_dir, run_example  # noqa: E402

REPEAT = 3
FRAME = re.compile(r"^tmclsim: (\d+(?:\.\d+)?) s ")


def serve(exe, speed, log):
    """`tmclsim serve` at `speed` with its frame log (wall seconds since
    the start) in the file `log`; returns (process, tcp address)."""
    proc = subprocess.Popen(
        [exe, "serve", "--module", MODULE, "--tcp", "127.0.0.1:0", "--speed", f"{speed:g}", "--world", str(WORLD), "--log-frames"],
        stdout=subprocess.PIPE,
        stderr=log,
        text=True,
    )
    tcp = None
    for line in proc.stdout:
        m = re.match(r"\s*tcp: (\S+)", line)
        if m:
            tcp = m.group(1)
        if line.startswith("connect with:"):
            break
    if tcp is None:
        proc.kill()
        raise RuntimeError("tmclsim serve did not start")
    return proc, tcp


def run_once(exe, command, script, speed, tmp):
    """One run: (Run, wall seconds of the session)."""
    log_path = os.path.join(tmp, "frames.log")
    with open(log_path, "w") as log:
        proc, tcp = serve(exe, speed, log)
        try:
            run = run_example(command, script, tcp, timeout=300)
        finally:
            proc.terminate()
            proc.wait()
            proc.stdout.close()
    with open(log_path) as log:
        times = [float(m.group(1)) for m in map(FRAME.match, log) if m]
    if run.returncode != 0 or not times:
        raise RuntimeError(f"{script.name} at speed {speed:g}: exit status {run.returncode}\n{run.stdout}\n{run.stderr}")
    return run, times[-1] - times[0]


def main():
    exe = os.path.abspath(shutil.which(sys.argv[1]) or sys.argv[1])
    speeds = [float(s) for s in sys.argv[2:]] or [50.0, 100.0]
    python = sys.executable
    examples = examples_dir()
    with tempfile.TemporaryDirectory() as tmp:
        for name in SCRIPTS:
            script = examples / name
            reference, session = run_once(exe, [python], script, 1.0, tmp)
            rows = [(1.0, reference, session, True)]
            for speed in speeds:
                runs = [run_once(exe, clock_command(exe, python, speed), script, speed, tmp) for _ in range(REPEAT)]
                run, session = min(runs, key=lambda r: r[0].wall)
                same = all(not differences(reference.stdout, r.stdout, speed) for r, _ in runs)
                rows.append((speed, run, session, same))
            base, base_session = reference.wall, rows[0][2]
            for speed, run, session, same in rows:
                # The frame log counts wall seconds; the module's clock runs
                # `speed` times as fast.
                print(
                    f"| {name} | {speed:g} | {run.wall:.2f} s | {run.wall - session:.2f} s | {session:.2f} s | {session * speed:.1f} s "
                    f"| {base / run.wall:.1f} | {base_session / session:.1f} | {'yes' if same else 'no'} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
