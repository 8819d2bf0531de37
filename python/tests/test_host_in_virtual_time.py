"""Unmodified host code in virtual time: the pytest plugin's ``speed`` and
``tmcl_clock``, and a plain PyTrinamic polling loop homing across the
built-in stage at factory speed."""

import subprocess
import sys
import threading
import time

import pytest

import tmclsim
from tmclsim import clock

pytest.importorskip("pytrinamic")
from pytrinamic.modules import TMCM1141  # noqa: E402

RFS = 13
RFS_START, RFS_STATUS = 0, 2


@pytest.mark.tmcl_module(speed=100)
def test_a_reference_search_across_the_stage_at_factory_speed(tmcl_module):
    # Mode 1 at the factory search speed (AP 194 = 100, about 3050 µsteps/s)
    # from 0 to the left stop switch at −1000000: five and a half minutes of
    # virtual time. The loop is what a host writes, unchanged: a sleep of
    # 0.1 s between status requests, time.monotonic() to time it.
    wall_started = clock.real_monotonic()
    with tmcl_module.connect() as interface:
        motor = TMCM1141(interface).motors[0]
        assert motor.get_axis_parameter(motor.AP.ReferenceSearchSpeed) == 100, "the factory speed"
        module_started = tmcl_module.time
        started = time.monotonic()
        interface.send(RFS, RFS_START, 0, 0)
        while interface.send(RFS, RFS_STATUS, 0, 0).value != 0:
            time.sleep(0.1)
        measured = time.monotonic() - started
        module_took = tmcl_module.time - module_started
        assert motor.actual_position == 0
    wall = clock.real_monotonic() - wall_started
    assert module_took > 300, f"the search took {module_took} s of the module's time"
    assert wall < 10, f"{module_took:.0f} virtual seconds took {wall:.1f} s of wall time"
    assert measured == pytest.approx(module_took, rel=0.02), "the loop's clock is the module's"
    assert tmcl_module.module.mechanical_position() == pytest.approx(-1000000, abs=20000)


@pytest.mark.tmcl_module(speed=50)
def test_the_marker_runs_the_module_and_the_test_at_one_speed(tmcl_module):
    assert tmcl_module.speed == 50
    assert clock.installed_speed() == 50
    # A thread of the test's waits on the same clock.
    done = threading.Event()
    wall = clock.real_monotonic()
    threading.Timer(5.0, done.set).start()
    assert done.wait(timeout=30)
    assert clock.real_monotonic() - wall < 2.5, "5 virtual seconds are a tenth of a second"
    module_before = tmcl_module.time
    time.sleep(2)
    assert tmcl_module.time - module_before >= 2, "the module's clock moved as far as the test's"


def test_a_module_at_the_wall_clocks_speed_leaves_the_clocks_alone(tmcl_module):
    assert tmcl_module.speed == 1
    assert clock.installed_speed() is None


@pytest.mark.tmcl_clock(speed=20)
def test_the_clock_fixture_for_modules_served_by_the_test(tmcl_clock):
    assert tmcl_clock == 20 and clock.installed_speed() == 20
    with tmclsim.serve(tmclsim.Module("tmcm-1141"), speed=tmcl_clock) as server:
        before, started = server.time, time.monotonic()
        time.sleep(3)
        assert server.time - before == pytest.approx(time.monotonic() - started, rel=0.05)


def test_a_bad_speed_is_refused():
    for bad in (0, -1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="positive finite"):
            tmclsim.serve(tmclsim.Module("tmcm-1141"), speed=bad)
    with tmclsim.serve(tmclsim.Module("tmcm-1141"), speed=2) as server:
        with pytest.raises(ValueError, match="positive finite"):
            server.speed = 0
        assert server.speed == 2
        server.speed = 10
        assert server.speed == 10


def test_the_clock_command_runs_an_unmodified_script(tmp_path):
    # `tmclsim clock --speed N -- python SCRIPT ARGS`: the script's clocks
    # run N times as fast; its arguments and exit status are its own.
    script = tmp_path / "host.py"
    script.write_text(
        "import sys, time\n"
        "started = time.monotonic()\n"
        "time.sleep(4)\n"
        "print(sys.argv[1:], f'{time.monotonic() - started:.3f}')\n"
        "sys.exit(3)\n"
    )
    wall = clock.real_monotonic()
    done = subprocess.run(
        [sys.executable, "-m", "tmclsim", "clock", "--speed", "40", "--", sys.executable, str(script), "a", "b"],
        capture_output=True, text=True, timeout=60,
    )
    wall = clock.real_monotonic() - wall
    assert wall < 3.5, "4 virtual seconds at 40 × are a tenth of a second, plus two starts"
    args, elapsed = done.stdout.rsplit(" ", 1)
    assert args == "['a', 'b']", done.stdout + done.stderr
    # The sleep lasts its 4 virtual seconds; what the script spends beside
    # it (its wake-up on a busy machine) counts 40 times, within the run's
    # wall time.
    assert 4.0 <= float(elapsed) <= 4.0 + 40 * wall, (done.stdout, wall)
    assert done.returncode == 3
    refused = subprocess.run([sys.executable, "-m", "tmclsim", "clock", "--speed", "40", "--", "labview"], capture_output=True, text=True, timeout=60)
    assert refused.returncode == 2 and "is no Python interpreter" in refused.stderr
