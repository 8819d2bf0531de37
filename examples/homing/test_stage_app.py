"""Tests of the stage application against a virtual TMCM-1141.

The ``tmcl_module`` fixture (tmclsim's pytest plugin) serves a fresh module
on the built-in linear stage for each test: home switch between 100000 and
110000 µsteps, stop switches at ±1000000, carriage at 0. Tests that pass
``stepped=True`` run in virtual time: the application sleeps by advancing
the module's clock, so minutes of motion take milliseconds.
"""

import pytest

from stage_app import HomingError, StageApp

# The middle of the built-in stage's home switch, seen from the carriage's
# start at 0.
HOME_MIDDLE = 105000


def virtual_time_app(served, interface, **options):
    """The application sleeping and timing in the module's virtual time."""
    return StageApp(interface, sleep=served.advance, clock=lambda: served.time, **options)


def test_homing_in_real_time_over_tcp(tmcl_module):
    with tmcl_module.connect() as interface:
        app = StageApp(interface)
        assert app.home() == HOME_MIDDLE
    # The carriage stands in the middle of the switch; the counter says 0.
    module = tmcl_module.module
    assert module.actual_position() == 0
    assert module.mechanical_position() == pytest.approx(HOME_MIDDLE, abs=1)
    assert module.switches() == (False, False, True)


@pytest.mark.tmcl_module(stepped=True)
def test_move_sequence_after_homing(tmcl_module):
    with tmcl_module.connect() as interface:
        app = virtual_time_app(tmcl_module, interface)
        app.home()
        targets = [10000, -50000, 200000, -800000, 0]
        assert app.run_sequence(targets, dwell=0.5) == targets
    # Positions are now relative to the home switch's middle.
    assert tmcl_module.module.mechanical_position() == pytest.approx(HOME_MIDDLE, abs=1)


@pytest.mark.tmcl_module(stepped=True)
def test_homing_over_the_serial_port(tmcl_module):
    with tmcl_module.connect(via="pty") as interface:
        app = virtual_time_app(tmcl_module, interface)
        assert app.home() == HOME_MIDDLE
        assert app.move_to(-20000) == -20000


@pytest.mark.tmcl_module(stepped=True, world="[[axis]]\nstart = -400000\n")
def test_homing_from_far_below_the_switch(tmcl_module):
    with tmcl_module.connect() as interface:
        app = virtual_time_app(tmcl_module, interface)
        # 505000 µsteps at the search speed take longer than the default
        # 30 s: virtual time makes a generous timeout free.
        assert app.home(timeout=300) == HOME_MIDDLE + 400000


@pytest.mark.tmcl_module(stepped=True)
def test_a_dead_home_switch_ends_in_a_clean_error(tmcl_module):
    tmcl_module.release_switch(0, "home")
    with tmcl_module.connect() as interface:
        app = virtual_time_app(tmcl_module, interface)
        started = tmcl_module.time
        with pytest.raises(HomingError, match="did not finish"):
            app.home(timeout=120)
        assert tmcl_module.time - started >= 120
        # The application stopped the search: the motor brakes and stands.
        assert interface.send(13, 2, 0, 0).value == 0
        tmcl_module.advance(1.0)
    assert tmcl_module.module.actual_speed() == 0


@pytest.mark.tmcl_module(stepped=True)
def test_an_hour_of_back_and_forth_takes_moments(tmcl_module):
    with tmcl_module.connect() as interface:
        app = virtual_time_app(tmcl_module, interface, poll=0.5)
        app.home()
        started = tmcl_module.time
        while tmcl_module.time - started < 3600:
            app.run_sequence([400000, -400000])
        assert tmcl_module.time - started >= 3600
        assert app.move_to(0) == 0
