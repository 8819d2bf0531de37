"""Tests of the stage application against a virtual TMCM-1141.

The ``tmcl_module`` fixture (tmclsim's pytest plugin) serves a fresh module
on the built-in linear stage for each test: home switch between 100000 and
110000 µsteps, stop switches at ±1000000, carriage at 0. Tests that pass
``speed=N`` run the module's time N times as fast as the wall clock, and
the application's own ``time.sleep`` and ``time.monotonic`` with it: the
application is not changed for its tests, minutes of motion take seconds.
"""

import time

import pytest

from stage_app import HomingError, StageApp

# The middle of the built-in stage's home switch, seen from the carriage's
# start at 0.
HOME_MIDDLE = 105000


def test_homing_in_real_time_over_tcp(tmcl_module):
    with tmcl_module.connect() as interface:
        app = StageApp(interface)
        assert app.home() == HOME_MIDDLE
    # The carriage stands in the middle of the switch; the counter says 0.
    module = tmcl_module.module
    assert module.actual_position() == 0
    assert module.mechanical_position() == pytest.approx(HOME_MIDDLE, abs=1)
    assert module.switches() == (False, False, True)


@pytest.mark.tmcl_module(speed=50)
def test_move_sequence_after_homing(tmcl_module):
    with tmcl_module.connect() as interface:
        app = StageApp(interface)
        app.home()
        targets = [10000, -50000, 200000, -800000, 0]
        assert app.run_sequence(targets, dwell=0.5) == targets
    # Positions are now relative to the home switch's middle.
    assert tmcl_module.module.mechanical_position() == pytest.approx(HOME_MIDDLE, abs=1)


@pytest.mark.tmcl_module(speed=50)
def test_homing_over_the_serial_port(tmcl_module):
    with tmcl_module.connect(via="pty") as interface:
        app = StageApp(interface)
        assert app.home() == HOME_MIDDLE
        assert app.move_to(-20000) == -20000


@pytest.mark.tmcl_module(speed=100, world="[[axis]]\nstart = -400000\n")
def test_homing_from_far_below_the_switch(tmcl_module):
    with tmcl_module.connect() as interface:
        app = StageApp(interface)
        # 505000 µsteps at the search speed take longer than the default
        # 30 s: at speed 100 a generous timeout costs three wall seconds.
        assert app.home(timeout=300) == HOME_MIDDLE + 400000


@pytest.mark.tmcl_module(speed=100)
def test_a_dead_home_switch_ends_in_a_clean_error(tmcl_module):
    tmcl_module.release_switch(0, "home")
    with tmcl_module.connect() as interface:
        app = StageApp(interface)
        started = tmcl_module.time
        with pytest.raises(HomingError, match="did not finish"):
            app.home(timeout=120)
        # The application's 120 s are the module's: its clock moved as far.
        assert tmcl_module.time - started >= 120
        # The application stopped the search: the motor brakes and stands.
        assert interface.send(13, 2, 0, 0).value == 0
        deadline = time.monotonic() + 30
        while tmcl_module.module.actual_speed() != 0:
            assert time.monotonic() < deadline, "the motor did not stop"
            time.sleep(0.1)


@pytest.mark.slow
@pytest.mark.tmcl_module(speed=500)
def test_an_hour_of_back_and_forth_takes_seconds(tmcl_module):
    with tmcl_module.connect() as interface:
        app = StageApp(interface, poll=0.5)
        app.home()
        started, module_started = time.monotonic(), tmcl_module.time
        while time.monotonic() - started < 3600:
            app.run_sequence([400000, -400000])
        # The application's hour is the module's hour (within the time one
        # last poll takes).
        assert tmcl_module.time - module_started == pytest.approx(time.monotonic() - started, rel=0.02)
        assert app.move_to(0) == 0
