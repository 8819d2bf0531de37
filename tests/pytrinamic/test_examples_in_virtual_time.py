"""Software nobody here wrote, in virtual time: PyTrinamic's own example
scripts for the TMCM-1140 (rotate_demo.py, StallGuard2_demo.py,
CoolStep_demo.py from its source distribution on PyPI, unchanged) against
a served TMCM-1140, at speed 1 as written and at speed 50 through
`tmclsim clock`. At 50 they print the same results (pytrinamic_examples.py
says what "the same" means and why) in a fiftieth of the wall time, plus
the start-up that no speed shortens.

The served world has a tight spot on the axis (tmcm1140_examples_world.toml)
where stallGuard2 stops the motor, as StallGuard2_demo.py and
CoolStep_demo.py wait for."""

import subprocess
import sys

import pytest
from pytrinamic_examples import (
    MODULE,
    SCRIPTS,
    WORLD,
    DownloadFailed,
    clock_command,
    differences,
    examples_dir,
    run_example,
    startup_time,
)
from tmclsim_binary import tmclsim_binary

SPEED = 50
# Wall time of a run that is neither start-up nor sleep: the host's
# requests, replies and prints, which take as long at any speed (measured:
# 0.1 to 0.15 s per example; the budget leaves room for a busy machine).
HOST_ALLOWANCE = 0.5
# The longest example's virtual time: rotate_demo.py runs 27 s at speed 1.
LONGEST_EXAMPLE = 30.0
# A run that takes longer is killed: the speed-1 runs take 8 to 27 s.
TIMEOUT = 120
# Runs at speed 50 per test until one passes. The machine's delays only
# ever make a run later, and at speed 50 a scheduling delay of 20 ms (a
# busy CI machine) is a virtual second: a polling loop loses five lines, a
# motor at speed 1500 is 46 000 µsteps further. A run without the clock
# patch fails every time.
ATTEMPTS = 3


@pytest.fixture(scope="session")
def examples():
    """The examples' directory in PyTrinamic's source distribution."""
    try:
        return examples_dir()
    except DownloadFailed as e:
        pytest.skip(f"PyTrinamic's source distribution (with its examples) could not be downloaded from the package registry: {e}")


@pytest.fixture(scope="session")
def clock():
    """`tmclsim clock --speed 50 -- python`. The clock patch is the Python
    package's: this interpreter must have it (scripts/test installs the
    package before these tests run)."""
    r = subprocess.run([sys.executable, "-c", "import tmclsim.clock"], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.fail(f"{sys.executable} has no tmclsim.clock (install the Python package: pip install ./python):\n{r.stderr}")
    return clock_command(tmclsim_binary(), sys.executable, SPEED)


def serve_tmcm1140(serve, speed):
    return serve("--module", MODULE, "--speed", f"{speed:g}", "--world", str(WORLD))


def report(run):
    return f"exit status {run.returncode}, {run.wall:.2f} s\n--- stdout\n{run.stdout}\n--- stderr\n{run.stderr}"


def run_at_speed_50(command, script, serve, tmp_path, check):
    """Runs `script` through `command` against a TMCM-1140 served at speed
    50 (a fresh one each time), up to ATTEMPTS times, until `check(run,
    startup)` finds nothing wrong; `startup` is the wall time of starting
    the same command on a script that only imports what the examples
    import, measured just before (the interpreter, PyTrinamic's import and
    the clock patch: what no speed shortens). Fails with every attempt's
    findings."""
    findings = []
    for attempt in range(1, ATTEMPTS + 1):
        startup = startup_time(command, tmp_path)
        served = serve_tmcm1140(serve, SPEED)
        try:
            run = run_example(command, script, served.tcp, TIMEOUT)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{script.name} at speed {SPEED} did not end within {TIMEOUT} s (killed)")
        finally:
            served.stop()
        found = [f"exit status {run.returncode}"] if run.returncode != 0 else check(run, startup)
        if not found:
            return
        findings.append(f"=== attempt {attempt} (start-up {startup:.2f} s): " + "\n".join(found) + f"\n{report(run)}")
    pytest.fail(f"{script.name} at speed {SPEED}, {ATTEMPTS} attempts:\n" + "\n".join(findings))


@pytest.mark.parametrize("script", SCRIPTS)
def test_example_runs_to_the_end_at_speed_50(script, examples, clock, serve, tmp_path):
    """At speed 50 the script finishes (StallGuard2's and CoolStep's loops
    end when the motor stalls at the tight spot) within its virtual time
    over 50 plus the start-up: the scripts sleep 11 to 17 s, so without
    the clock patch they take longer than that."""

    def check(run, startup):
        found = []
        if run.stdout.rstrip().splitlines()[-1:] != ["Ready."]:
            found.append("the output does not end with Ready.")
        bound = LONGEST_EXAMPLE / SPEED + startup + HOST_ALLOWANCE
        if run.wall > bound:
            found.append(f"{run.wall:.2f} s, more than {bound:.2f} s")
        return found

    run_at_speed_50(clock, examples / script, serve, tmp_path, check)


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS)
def test_example_prints_the_same_at_speed_50_in_a_fiftieth_of_the_time(script, examples, clock, serve, tmp_path):
    """The script at speed 1 as written (its own interpreter, no patch),
    then through `tmclsim clock --speed 50` against a module served at 50:
    the same printed results (pytrinamic_examples.differences), in at most
    a fiftieth of the wall time plus the start-up and HOST_ALLOWANCE."""
    at_1 = serve_tmcm1140(serve, 1)
    reference = run_example([sys.executable], examples / script, at_1.tcp, TIMEOUT)
    at_1.stop()
    assert reference.returncode == 0, report(reference)

    def check(run, startup):
        found = differences(reference.stdout, run.stdout, SPEED)
        bound = reference.wall / SPEED + startup + HOST_ALLOWANCE
        if run.wall > bound:
            found.append(
                f"{run.wall:.2f} s, more than {bound:.2f} s "
                f"({reference.wall:.2f} s at speed 1 / {SPEED} + start-up {startup:.2f} s + {HOST_ALLOWANCE} s)"
            )
        return found

    run_at_speed_50(clock, examples / script, serve, tmp_path, check)


def rotate_output(first, stride, lines, dump="'max_velocity': 1000"):
    """An output shaped like rotate_demo.py's: a timed position, a doubled
    distance polled every 0.2 s, the final position."""
    target = 2 * first
    polled = [f"target position: {target}; actual position: {min(first + i * stride, target)}" for i in range(lines)]
    return "\n".join(["Preparing parameters...", f"LinearRamp {{{dump}}}", "Rotating...", f"ActualPosition = {first}", *polled, f"ActualPosition = {target}", "Ready."])


def test_the_comparison_tells_a_missing_clock_apart():
    """The comparison passes what latency explains and fails the rest: what
    a run without the clock patch prints (every sleep 50 times as long in
    virtual time), a changed parameter, a missing line."""
    reference = rotate_output(150000, 6000, 26)
    # The host's latency at speed 50: a bit further, coarser polls.
    assert differences(reference, rotate_output(152500, 8000, 20), SPEED) == []
    # No clock: the 5 s rotation lasts 250 s, one poll.
    assert differences(reference, rotate_output(7500000, 300000, 1), SPEED)
    # The motion right, the polling loop 50 times too slow.
    assert differences(reference, rotate_output(150000, 300000, 2), SPEED)
    assert differences(reference, rotate_output(152500, 8000, 20, dump="'max_velocity': 2000"), SPEED)
    assert differences(reference, reference.replace("Rotating...\n", ""), SPEED)
    # A load reading polled from a free-running motor is exact; the last
    # may read the stall the loop waits for.
    loads = "Try to stop motor...\n" + "Actual load value: 800\n" * 16 + "Motor stopped by StallGuard2!\n"
    assert differences(loads, loads.replace("800\nMotor", "0\nMotor"), SPEED) == []
    assert differences(loads, loads.replace("value: 800", "value: 790", 1), SPEED)
