"""tmclsim.clock: a Python program's clocks N times as fast as the wall clock.

Wall time is measured with the real clock taken when this file is imported,
before any install. The bounds are generous: a wait of 2 virtual seconds at
speed 50 takes 0.04 s of wall time, the tests allow it 1 s (unscaled, it
would take 2 s); virtual time is checked against the wall time measured
around it.
"""

import asyncio
import json
import math
import os
import queue
import select
import selectors
import socket
import subprocess
import sys
import textwrap
import threading
import time
from fractions import Fraction

import pytest

import tmclsim
from tmclsim import clock

WALL = time.perf_counter
REAL_SLEEP = time.sleep

SPEED = 50
VIRTUAL = 2.0  # the virtual length of each wait
WALL_LIMIT = 1.0  # its wall-clock bound
# Float rounding between a wait's virtual and wall length.
EPSILON = 1e-6

CLOCKS = ["monotonic", "perf_counter", "time", "monotonic_ns", "perf_counter_ns", "time_ns"]
SELECTOR_CLASSES = [
    getattr(selectors, name)
    for name in ("SelectSelector", "PollSelector", "EpollSelector", "DevpollSelector", "KqueueSelector")
    if hasattr(selectors, name)
]


def patch_sites():
    """Where the clock patches: (namespace, name) pairs."""
    sites = [(time, name) for name in CLOCKS + ["sleep"]]
    sites += [(select, "select"), (threading, "_time"), (queue, "time")]
    sites += [(threading.Condition, "wait"), (threading.Thread, "join")]
    for c in {*SELECTOR_CLASSES, *(base for c in SELECTOR_CLASSES for base in c.__mro__)}:
        if issubclass(c, selectors.BaseSelector) and "select" in vars(c) and c is not selectors.BaseSelector:
            sites.append((c, "select"))
    return sites


ORIGINALS = {site: vars(site[0])[site[1]] for site in patch_sites()}


@pytest.fixture(autouse=True)
def real_clocks_after_each_test():
    yield
    clock.uninstall()


def timed(wait):
    """(virtual seconds by time.monotonic, wall seconds) that wait() takes."""
    wall, virtual = WALL(), time.monotonic()
    wait()
    return time.monotonic() - virtual, WALL() - wall


def assert_scaled_wait(wait):
    with clock.scaled(SPEED):
        virtual, wall = timed(wait)
    assert wall < WALL_LIMIT, f"a wait of {VIRTUAL} virtual s took {wall:.3f} s of wall time at speed {SPEED}"
    assert virtual >= VIRTUAL - EPSILON, f"the wait ended after {virtual:.3f} virtual s, before its timeout"


# The clocks.


@pytest.mark.parametrize("name", CLOCKS)
def test_each_clock_starts_at_the_real_reading_and_runs_at_the_speed(name):
    real = ORIGINALS[time, name]
    unit = 1e9 if name.endswith("_ns") else 1.0
    before_install = real()
    clock.install(SPEED)
    scaled = getattr(time, name)
    assert scaled is not real
    a0, v0, a1 = real(), scaled(), real()
    REAL_SLEEP(0.05)  # about time: 50 ms of wall time for the clock to run at its speed
    b0, v1, b1 = real(), scaled(), real()
    assert isinstance(v1, type(a0))
    assert before_install <= v0 <= before_install + SPEED * (a1 - before_install) + EPSILON * unit
    assert SPEED * (b0 - a1) - EPSILON * unit <= v1 - v0 <= SPEED * (b1 - a0) + EPSILON * unit


def test_a_speed_below_one_slows_the_clocks():
    with clock.scaled(0.5):
        # about time: the sleep's length is measured
        virtual, wall = timed(lambda: time.sleep(0.1))
    assert wall >= 0.2 - EPSILON, "time.sleep(0.1) at speed 0.5 lasts 0.2 s of wall time"
    assert virtual >= 0.1 - EPSILON


def test_a_thread_started_before_install_sees_the_scaled_clock():
    go = threading.Event()
    measured = []

    def host():
        go.wait()
        # about time: the sleep's length is measured
        measured.append(timed(lambda: time.sleep(VIRTUAL)))

    thread = threading.Thread(target=host)
    thread.start()
    with clock.scaled(SPEED):
        go.set()
        thread.join()
    [(virtual, wall)] = measured
    assert wall < WALL_LIMIT and virtual >= VIRTUAL - EPSILON, (virtual, wall)


# Waits with a timeout: each lasts its whole timeout of VIRTUAL seconds
# (about time: their lengths are measured).


def sleep():
    time.sleep(VIRTUAL)


def event_wait():
    assert threading.Event().wait(VIRTUAL) is False


def condition_wait():
    condition = threading.Condition()
    with condition:
        assert condition.wait(VIRTUAL) is False


def condition_wait_for():
    condition = threading.Condition()
    with condition:
        assert condition.wait_for(lambda: False, VIRTUAL) is False


def semaphore_acquire():
    assert threading.Semaphore(0).acquire(timeout=VIRTUAL) is False


def barrier_wait():
    with pytest.raises(threading.BrokenBarrierError):
        threading.Barrier(2, timeout=VIRTUAL).wait()


def queue_get():
    with pytest.raises(queue.Empty):
        queue.Queue().get(timeout=VIRTUAL)


def queue_put():
    full = queue.Queue(maxsize=1)
    full.put(1)
    with pytest.raises(queue.Full):
        full.put(2, timeout=VIRTUAL)


def thread_join():
    release = threading.Event()
    thread = threading.Thread(target=release.wait)
    thread.start()
    try:
        thread.join(timeout=VIRTUAL)
        assert thread.is_alive()
    finally:
        release.set()
        thread.join()


def timer():
    fired = threading.Event()
    threading.Timer(VIRTUAL, fired.set).start()
    fired.wait()


def select_on_a_socket():
    a, b = socket.socketpair()
    with a, b:
        assert select.select([a], [], [], VIRTUAL) == ([], [], [])


def select_as_a_sleep():
    assert select.select([], [], [], VIRTUAL) == ([], [], [])


WAITS = [
    sleep,
    event_wait,
    condition_wait,
    condition_wait_for,
    semaphore_acquire,
    barrier_wait,
    queue_get,
    queue_put,
    thread_join,
    timer,
    select_on_a_socket,
    pytest.param(
        select_as_a_sleep,
        marks=pytest.mark.skipif(sys.platform == "win32", reason="Windows' select needs a socket"),
    ),
]


@pytest.mark.parametrize("wait", WAITS, ids=lambda f: f.__name__)
def test_waits_with_a_timeout_are_scaled(wait):
    assert_scaled_wait(wait)


@pytest.mark.parametrize("selector_class", SELECTOR_CLASSES, ids=lambda c: c.__name__)
def test_selector_timeouts_are_scaled_once(selector_class):
    def wait():
        a, b = socket.socketpair()
        with a, b, selector_class() as selector:
            selector.register(a, selectors.EVENT_READ)
            assert selector.select(VIRTUAL) == []

    # Scaled twice, the wait would end after VIRTUAL / SPEED virtual seconds.
    assert_scaled_wait(wait)


def test_asyncio_runs_on_the_scaled_clock():
    async def host():
        loop = asyncio.get_running_loop()
        before, now, after = time.monotonic(), loop.time(), time.monotonic()
        assert before <= now <= after, "loop.time() is the scaled time.monotonic"
        lengths = {}

        async def measure(name, wait):
            wall, start = WALL(), loop.time()
            await wait
            lengths[name] = (loop.time() - start, WALL() - wall)

        await measure("sleep", asyncio.sleep(VIRTUAL))
        later = loop.create_future()
        loop.call_later(VIRTUAL, later.set_result, None)
        await measure("call_later", later)
        with pytest.raises(asyncio.TimeoutError):
            await measure("wait_for", asyncio.wait_for(asyncio.Event().wait(), VIRTUAL))
        return lengths

    with clock.scaled(SPEED):
        lengths = asyncio.run(host())
    for name, (virtual, wall) in lengths.items():
        assert wall < WALL_LIMIT and virtual >= VIRTUAL - EPSILON, (name, virtual, wall)


# Installing and uninstalling.


def test_uninstall_restores_the_original_functions():
    clock.install(SPEED)
    assert clock.installed_speed() == SPEED
    for (owner, name), original in ORIGINALS.items():
        assert vars(owner)[name] is not original, f"{owner.__name__}.{name} is not patched"
    clock.uninstall()
    for (owner, name), original in ORIGINALS.items():
        assert vars(owner)[name] is original, f"{owner.__name__}.{name} is not the original"
    assert clock.installed_speed() is None
    clock.uninstall()  # a no-op when not installed
    assert all(vars(owner)[name] is original for (owner, name), original in ORIGINALS.items())


def test_a_copy_taken_while_installed_reads_the_real_clock_after():
    with clock.scaled(SPEED):
        monotonic, sleep = time.monotonic, time.sleep
    before, copy, after = ORIGINALS[time, "monotonic"](), monotonic(), ORIGINALS[time, "monotonic"]()
    assert before <= copy <= after
    wall = WALL()
    sleep(0.05)  # about time: its length is measured
    assert WALL() - wall >= 0.05 - EPSILON


def test_installing_again_changes_the_speed_and_time_goes_on():
    clock.install(SPEED)
    wall0, before = WALL(), time.monotonic()
    clock.install(0.5)
    after, wall1 = time.monotonic(), WALL()
    assert clock.installed_speed() == 0.5
    assert before <= after <= before + SPEED * (wall1 - wall0) + EPSILON, "virtual time jumped"
    virtual, wall = timed(lambda: time.sleep(0.1))  # about time: its length is measured
    assert wall >= 0.2 - EPSILON and virtual >= 0.1 - EPSILON


def test_scaled_gives_back_what_it_found():
    with clock.scaled(10):
        with clock.scaled(SPEED):
            assert clock.installed_speed() == SPEED
        assert clock.installed_speed() == 10
    assert clock.installed_speed() is None
    assert time.monotonic is ORIGINALS[time, "monotonic"]


@pytest.mark.parametrize(
    "bad", [0, -1, -0.5, 0.0, math.nan, math.inf, -math.inf, 10**400, True, False, "20", None, Fraction(0)]
)
def test_bad_speeds_are_refused(bad):
    with pytest.raises(ValueError, match="positive finite number") as refused:
        clock.install(bad)
    assert repr(bad) in str(refused.value)
    assert clock.installed_speed() is None and time.sleep is REAL_SLEEP
    clock.install(SPEED)
    with pytest.raises(ValueError):
        clock.install(bad)
    assert clock.installed_speed() == SPEED


@pytest.mark.parametrize("outside", [1e9, 1e-4, 1e300, 100_000.5, 0.000999])
def test_speeds_outside_the_served_range_are_refused(outside):
    """The clock takes the speeds a served module takes, 0.001…100000:
    no host clock can run at a speed no module runs at."""
    with pytest.raises(ValueError, match="outside 0.001…100000"):
        clock.install(outside)
    with pytest.raises(ValueError, match="outside 0.001…100000"):
        with clock.scaled(outside):
            pass
    assert clock.installed_speed() is None and time.sleep is REAL_SLEEP
    # A served module refuses the same speeds, with the same range.
    with pytest.raises(ValueError, match="outside 0.001…100000"):
        tmclsim.serve("tmcm-1141", speed=outside)


def test_the_range_s_ends_are_taken():
    for speed in (clock.MIN_SPEED, clock.MAX_SPEED):
        with clock.scaled(speed):
            assert clock.installed_speed() == speed
    assert clock.installed_speed() is None


def test_the_command_refuses_a_speed_outside_the_range(tmp_path):
    script = tmp_path / "script.py"
    script.write_text("print('ran')\n")
    for speed in ("1e9", "1e-4", "1e300"):
        run = subprocess.run([sys.executable, "-m", "tmclsim.clock", "--speed", speed, str(script)], capture_output=True, text=True, timeout=60)
        assert run.returncode == 2, run
        assert f"--speed must be a number from 0.001 to 100000, not '{speed}'" in run.stderr, run.stderr
        assert "ran" not in run.stdout


def test_speeds_of_other_number_types_are_taken():
    clock.install(Fraction(5, 2))
    assert clock.installed_speed() == 2.5


def test_install_from_environment():
    assert clock.install_from_environment({}) is None
    assert clock.install_from_environment({clock.ENVIRONMENT_VARIABLE: " "}) is None
    assert clock.installed_speed() is None
    assert clock.install_from_environment({clock.ENVIRONMENT_VARIABLE: "20"}) == 20
    assert clock.installed_speed() == 20
    with pytest.raises(ValueError, match="TMCLSIM_CLOCK_SPEED='fast'"):
        clock.install_from_environment({clock.ENVIRONMENT_VARIABLE: "fast"})


# pyserial's timeouts stay on the wall clock.


def test_pyserial_timeout_stays_on_the_wall_clock():
    # Imported before install here (its Timeout keeps the function it
    # copied); imported after install: test_pyserial_imported_by_the_program….
    serialutil = pytest.importorskip("serial.serialutil", reason="pyserial is not installed")
    with clock.scaled(SPEED):
        timeout = serialutil.Timeout(5.0)
        time.sleep(5.0)  # about time: 5 virtual s, 0.1 s of wall time
        assert not timeout.expired()
        assert 2.5 < timeout.time_left() <= 5.0


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pty")
def test_a_serial_read_timeout_stays_on_the_wall_clock():
    serial = pytest.importorskip("serial", reason="pyserial is not installed")
    controller, device = os.openpty()
    try:
        with serial.Serial(os.ttyname(device), timeout=0.3) as port, clock.scaled(SPEED):
            wall = WALL()
            assert port.read(1) == b""  # about time: the read's timeout is measured
            wall = WALL() - wall
    finally:
        os.close(controller)
        os.close(device)
    assert wall >= 0.3 - EPSILON, "pyserial's read timeout was scaled"


# python -m tmclsim.clock


def run_clock(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "tmclsim.clock", *args], capture_output=True, text=True, timeout=60, cwd=cwd
    )


HOST = """\
import json, sys, time
import tmclsim
from tmclsim import clock

wall, virtual = clock.real_monotonic(), time.monotonic()
time.sleep(1)  # about time: its length is measured
print(json.dumps({
    "argv": sys.argv,
    "virtual": time.monotonic() - virtual,
    "wall": clock.real_monotonic() - wall,
    "name": __name__,
    "path0": sys.path[0],
    "speed": clock.installed_speed(),
}))
"""


def test_the_command_runs_a_script_on_the_scaled_clock(tmp_path):
    script = tmp_path / "host.py"
    script.write_text(HOST)
    run = run_clock("--speed", "20", str(script), "a", "b", cwd=os.getcwd())
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["argv"] == [str(script), "a", "b"]
    assert out["virtual"] >= 1.0 - EPSILON and out["wall"] < WALL_LIMIT, out
    assert out["name"] == "__main__"
    assert out["path0"] == os.path.dirname(os.path.abspath(script))
    assert out["speed"] == 20


def test_the_command_runs_a_module(tmp_path):
    package = tmp_path / "hostpkg"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "main.py").write_text(HOST)
    run = run_clock("--speed=20", "-m", "hostpkg.main", "--port", "x", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["argv"][1:] == ["--port", "x"] and out["argv"][0].endswith("main.py")
    assert out["virtual"] >= 1.0 - EPSILON and out["wall"] < WALL_LIMIT, out
    assert out["name"] == "__main__" and out["speed"] == 20


def test_the_scripts_exit_status_is_the_commands(tmp_path):
    (tmp_path / "fails.py").write_text("raise SystemExit(3)\n")
    assert run_clock("--speed", "2", "fails.py", cwd=tmp_path).returncode == 3


def test_pyserial_imported_by_the_program_stays_on_the_wall_clock(tmp_path):
    pytest.importorskip("serial", reason="pyserial is not installed")
    (tmp_path / "host.py").write_text(
        textwrap.dedent(
            """\
            import time
            from serial.serialutil import Timeout

            timeout = Timeout(5.0)
            time.sleep(5.0)  # about time: 5 virtual s, 0.1 s of wall time
            print(timeout.expired(), timeout.time_left())
            """
        )
    )
    run = run_clock("--speed", str(SPEED), "host.py", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    expired, left = run.stdout.split()
    assert expired == "False" and 2.5 < float(left) <= 5.0, run.stdout


@pytest.mark.parametrize(
    "args, message",
    [
        (["--speed", "0", "host.py"], "not '0'"),
        (["--speed", "fast", "host.py"], "not 'fast'"),
        (["--speed", "nan", "host.py"], "not 'nan'"),
        (["--speed"], "--speed needs a number"),
        (["host.py"], "--speed N is required"),
        (["--speed", "20"], "a SCRIPT or -m MODULE"),
        (["--speed", "20", "missing.py"], "can't open file 'missing.py'"),
        (["--speed", "20", "-m", "no_such_module_here"], "no_such_module_here"),
        (["--speed", "20", "-u", "host.py"], "unknown option '-u'"),
    ],
)
def test_usage_errors_exit_with_status_2(tmp_path, args, message):
    (tmp_path / "host.py").write_text(HOST)
    run = run_clock(*args, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.startswith("usage: python -m tmclsim.clock --speed N"), run.stderr
    assert message in run.stderr, run.stderr
    assert run.stdout == ""
