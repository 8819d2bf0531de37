"""PyTrinamic's own example scripts for the TMCM-1140, from its source
distribution on PyPI, run unchanged against a served module: where they
come from, how they run (at speed 1 as written, in virtual time through
`tmclsim clock`), and what "the same printed results" means. Shared by
test_examples_in_virtual_time.py, test_sixpoint_demos.py (the sixPoint
modules' demos, from the same source distribution) and
scripts/bench_host_clock.py.

The scripts call `ConnectionManager()` without arguments: PyTrinamic then
reads the connection from the command line, so
`script.py --interface socket_serial_tmcl --port HOST:PORT` connects them
to `tmclsim serve --tcp`. Their calibrations wait for the operator's enter
key (`input()`): stdin gives them enter presses, the world is not touched
meanwhile.

What "the same" means (`differences`):

1. The same lines in the same order. Every line is reduced to its
   template (each integer replaced by #, the server's TCP port masked);
   consecutive lines of one template form a run. Both outputs must have
   the same runs in the same order: the same messages, parameter dumps,
   calibration steps, and the same branches taken (the motor stalled, the
   move ended).
2. Numbers the scripts set, read back at rest or get from the world
   without timing are equal: parameter dumps, calibration thresholds and
   results, the load reading of the free-running motor, every run's
   length outside the polling loops.
3. Numbers that depend on when they were sampled are equal within what
   the host's latency explains. At speed N every wall second the host
   spends outside its sleeps (requests, replies, printing) is N seconds of
   virtual time: a timed step of a script (a sleep with the requests and
   prints around it) ends up to N x LATENCY_WALL later in virtual time
   than at speed 1. LATENCY_WALL is 5 ms: measured, a polling iteration
   of three PyTrinamic requests and a print spends 1.6 ms beyond its sleep
   over TCP on a 2-core machine; the budget leaves room for a busy CI
   machine. At speed 50 that is 0.25 s of virtual time per step.
   - Positions sampled from a moving motor ("ActualPosition = X" after a
     timed rotation, the targets derived from it, the polled actual
     positions): within 2 x R x N x LATENCY_WALL, R how fast the position
     changes between two polls at speed 1 (a doubled distance,
     move_by(actual_position), carries twice the error). Polled positions
     move the same way as at speed 1 and stay within that run's range
     widened by the tolerance.
   - Polling loops (`while ...: print(...); time.sleep(0.2)`): each
     iteration lasts at most POLL + N x LATENCY_WALL and the loop starts
     at most STEPS_BEFORE_LOOP steps late, so a loop that printed n lines
     at speed 1 prints at least ((n - 1) x POLL - STEPS_BEFORE_LOOP x N x
     LATENCY_WALL) / (POLL + N x LATENCY_WALL) lines and at most n + 1.
   - A polled load reading may end with one 0: the motor stalled between
     the loop's velocity check and its load read.

Without the clock patch a script's sleeps last N times as long in virtual
time: at 50, rotate_demo's 5 s rotation lasts 250 s and its positions are
50 times as far; StallGuard2's calibration (150 s instead of 3 s) runs
into the tight spot, calibrates another threshold, prints other load
readings, and the motor never stops. The comparison fails, and so does the
bound on the wall time.
"""

import os
import pathlib
import re
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
from dataclasses import dataclass

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
# The served world: a tight spot for stallGuard2 (the file explains it).
WORLD = HERE / "tmcm1140_examples_world.toml"
MODULE = "tmcm-1140"
EXAMPLES = "examples/modules/TMCM1140/TMCL"
SCRIPTS = ["rotate_demo.py", "StallGuard2_demo.py", "CoolStep_demo.py"]
# Enough enter presses for every calibration prompt (CoolStep_demo.py
# asks five times); a script that asks more fails with EOFError.
ENTER_PRESSES = "\n" * 10

# Wall time a timed step of a script may spend beyond its sleep (see the
# module's docstring), the scripts' polling period, and the most timed
# steps between the start of a motion and the loop that polls it
# (StallGuard2's calibration: three sleeps of 1 s, one of 0.2 s, and the
# requests around them).
LATENCY_WALL = 0.005
POLL = 0.2
STEPS_BEFORE_LOOP = 5

# Templates whose numbers are sampled in time.
POLLED_POSITIONS = "target position: #; actual position: #"
POLLED_LOADS = "Actual load value: #"
TIMED_POSITION = "ActualPosition = #"
POLLED = {POLLED_POSITIONS, POLLED_LOADS}

NUMBER = re.compile(r"-?\d+")
PORT = re.compile(r"\bport=\d+")


class DownloadFailed(Exception):
    """pip could not get PyTrinamic's source distribution."""


def pinned_version():
    """PyTrinamic's version the tests pin (requirements.txt)."""
    for line in (HERE / "requirements.txt").read_text().splitlines():
        m = re.fullmatch(r"pytrinamic==(\S+)", line.strip())
        if m:
            return m.group(1)
    raise RuntimeError("tests/pytrinamic/requirements.txt pins no pytrinamic==VERSION")


def examples_dir(python=sys.executable):
    """The directory of the TMCM-1140 examples in PyTrinamic's source
    distribution (`sdist_dir`)."""
    return sdist_dir(python) / EXAMPLES


def sdist_dir(python=sys.executable):
    """PyTrinamic's source distribution, unpacked: downloaded with pip from
    the package registry into target/pytrinamic-sdist (scripts/test's
    preparation does it; here only when that did not run) and unpacked
    there, once."""
    version = pinned_version()
    cache = ROOT / "target" / "pytrinamic-sdist"
    tree = cache / f"pytrinamic-{version}"
    if not tree.is_dir():
        archive = cache / f"pytrinamic-{version}.tar.gz"
        if not archive.exists():
            cache.mkdir(parents=True, exist_ok=True)
            cmd = [python, "-m", "pip", "download", "-q", "--no-deps", "--no-binary", ":all:", "-d", str(cache), f"pytrinamic=={version}"]
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0 or not archive.exists():
                raise DownloadFailed(f"{' '.join(cmd[2:])}: {(r.stdout + r.stderr).strip()}")
        # Unpacked beside the archive and renamed into place: a concurrent
        # run never sees half a tree.
        with tempfile.TemporaryDirectory(dir=cache) as tmp:
            with tarfile.open(archive) as tar:
                if hasattr(tarfile, "data_filter"):
                    tar.extractall(tmp, filter="data")
                else:
                    tar.extractall(tmp)
            try:
                os.rename(pathlib.Path(tmp) / f"pytrinamic-{version}", tree)
            except OSError:
                if not tree.is_dir():
                    raise
    return tree


def clock_command(tmclsim, python, speed):
    """The command that runs a Python script in virtual time: `tmclsim
    clock --speed N -- PYTHON` (the script and its arguments follow). A
    relative path to tmclsim is made absolute: the script runs in its own
    directory."""
    if os.sep in str(tmclsim):
        tmclsim = os.path.abspath(tmclsim)
    return [tmclsim, "clock", "--speed", f"{speed:g}", "--", python]


@dataclass
class Run:
    returncode: int
    stdout: str
    stderr: str
    wall: float


def run_example(command, script, tcp, timeout, connection=None, env=None):
    """Runs `command + [script, connection arguments]` in the script's
    directory with enter presses on stdin; its wall time is from the start
    of the process to its end. The connection arguments are PyTrinamic's
    `--interface socket_serial_tmcl --port TCP`, or the list `connection`
    (e.g. serial_tmcl on the pty); `env`, when given, is the process's
    environment. On timeout the whole process group (the clock's
    interpreter too) is killed and TimeoutExpired raised, with what the
    process printed."""
    script = pathlib.Path(script)
    if connection is None:
        connection = ["--interface", "socket_serial_tmcl", "--port", tcp]
    args = [*command, script.name, *connection]
    start = time.monotonic()
    proc = subprocess.Popen(
        args,
        cwd=script.parent,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        env=env,
    )
    try:
        stdout, stderr = proc.communicate(ENTER_PRESSES, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        os.killpg(proc.pid, signal.SIGKILL)
        e.stdout, e.stderr = proc.communicate()
        raise
    return Run(proc.returncode, stdout, stderr, time.monotonic() - start)


STARTUP_SCRIPT = "import pytrinamic\nimport pytrinamic.connections\nimport pytrinamic.modules\n"


def startup_time(command, directory, timeout=60):
    """Wall time of starting `command` on a script that only imports what
    the examples import: the interpreter, PyTrinamic and (through `tmclsim
    clock`) the clock patch, which no speed shortens."""
    script = pathlib.Path(directory) / "startup.py"
    script.write_text(STARTUP_SCRIPT)
    start = time.monotonic()
    subprocess.run([*command, str(script)], check=True, timeout=timeout, stdin=subprocess.DEVNULL)
    return time.monotonic() - start


def template(line):
    return NUMBER.sub("#", PORT.sub("port=PORT", line))


def runs(text):
    """The output's runs: [(template, [numbers of each line])]."""
    out = []
    for line in text.splitlines():
        t = template(line)
        numbers = [int(n) for n in NUMBER.findall(PORT.sub("port=PORT", line))]
        if out and out[-1][0] == t:
            out[-1][1].append(numbers)
        else:
            out.append((t, [numbers]))
    return out


def motor_rate(reference_runs):
    """How fast the polled position changes at speed 1, in µsteps per
    second of virtual time: the median of the steps between two polls (a
    poll the machine delayed makes a longer step; 0 when nothing is
    polled)."""
    steps = []
    for t, lines in reference_runs:
        if t == POLLED_POSITIONS:
            xs = [n[1] for n in lines]
            steps += [abs(b - a) for a, b in zip(xs, xs[1:])]
    return sorted(steps)[len(steps) // 2] / POLL if steps else 0.0


def min_polls(n, speed):
    """The fewest lines a polling loop that printed `n` at speed 1 prints
    at `speed` (at least one)."""
    late = speed * LATENCY_WALL
    return max(1, int(((n - 1) * POLL - STEPS_BEFORE_LOOP * late) / (POLL + late)))


def differences(reference, output, speed):
    """How `output` (a run at `speed`) differs from `reference` (the same
    script at speed 1) beyond the tolerances of the module's docstring:
    an empty list when both print the same results."""
    a, b = runs(reference), runs(output)
    ta, tb = [t for t, _ in a], [t for t, _ in b]
    if ta != tb:
        import difflib

        diff = difflib.unified_diff(ta, tb, "speed 1", f"speed {speed:g}", lineterm="", n=2)
        return ["the lines differ (templates, one per run of lines):", *diff]
    tolerance = 2 * motor_rate(a) * speed * LATENCY_WALL
    found = []
    for i, ((t, la), (_, lb)) in enumerate(zip(a, b)):
        where = f"run {i} ({t!r}, {len(la)} line(s) at speed 1, {len(lb)} at speed {speed:g})"
        if t in POLLED:
            low, high = min_polls(len(la), speed), len(la) + 1
            if not low <= len(lb) <= high:
                found.append(f"{where}: {len(lb)} lines, expected {low}…{high}")
        elif len(la) != len(lb):
            found.append(f"{where}: a different number of lines")
            continue
        if t == POLLED_POSITIONS:
            targets = {n[0] for n in la} | {n[0] for n in lb}
            if max(targets) - min(targets) > tolerance:
                found.append(f"{where}: targets {sorted(targets)} differ by more than {tolerance:.0f}")
            xa, xb = [n[1] for n in la], [n[1] for n in lb]
            lo, hi = min(xa) - tolerance, max(xa) + tolerance
            if not all(lo <= x <= hi for x in xb):
                found.append(f"{where}: positions {xb} leave {lo:.0f}…{hi:.0f}")
            up = xa[-1] >= xa[0]
            if any((y < x) if up else (y > x) for x, y in zip(xb, xb[1:])):
                found.append(f"{where}: positions {xb} do not move {'up' if up else 'down'} as at speed 1")
        elif t == POLLED_LOADS:
            va, vb = [n[0] for n in la], [n[0] for n in lb]
            if len(va) > 1 and va[-1] == 0:
                va = va[:-1]
            if len(vb) > 1 and vb[-1] == 0:
                vb = vb[:-1]
            if set(va) != set(vb):
                found.append(f"{where}: load readings {sorted(set(vb))}, at speed 1 {sorted(set(va))}")
        elif t == TIMED_POSITION:
            for na, nb in zip(la, lb):
                if any(abs(x - y) > tolerance for x, y in zip(na, nb)):
                    found.append(f"{where}: {nb} against {na} at speed 1, more than {tolerance:.0f} apart")
        elif la != lb:
            found.append(f"{where}: numbers {lb} against {la} at speed 1")
    return found
