"""Hostile values and long runs: world values out of range are refused
with ValueError (docs/behaviour.md rule 84), no panic reaches Python, and a
long advance can be stopped with Ctrl-C."""

import math
import signal
import threading
import time

import pytest

import tmclsim


def test_an_inverted_travel_is_refused_and_the_module_moves_on(module):
    with pytest.raises(ValueError, match=r"axis 0: travel from 10(\.0)? to -10(\.0)? is empty"):
        module.set_travel(0, 10, -10)
    with pytest.raises(ValueError, match="is empty"):
        module.set_travel(0, 5, 5)
    module.send("ROR 0, 500")
    module.advance(1)
    assert module.actual_position() > 0 and module.actual_speed() == 500


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda m: m.set_supply(math.nan), "supply NaN is not a finite number"),
        (lambda m: m.set_supply(-1), "supply -1 is outside 0…100 V"),
        (lambda m: m.set_temperature(math.inf), "temperature inf is not a finite number"),
        (lambda m: m.load(0, -1), "load torque -1 is outside 0…1000 %"),
        (lambda m: m.load(0, math.nan), "load torque NaN is not a finite number"),
        (lambda m: m.load(0, 50, 20, 10), "load range from 20 to 10 is empty"),
        (lambda m: m.set_input(99, 1), r"digital input 99 does not exist on the TMCM-1141 \(digital inputs: 0…3\)"),
        (lambda m: m.set_analog(5, 100), "analog input 5 does not exist"),
        (lambda m: m.place_switch(0, "left", math.nan), "left switch position NaN is not a finite number"),
        (lambda m: m.place_switch(0, "home", 9, 5), "home switch from 9 to 5 is empty"),
        (lambda m: m.world("place 0 right 0 -5"), "right switch width -5 is outside"),
    ],
)
def test_world_values_out_of_range_are_refused(module, call, message):
    before = module.show()
    with pytest.raises(ValueError, match=message):
        call(module)
    assert module.show() == before


def test_a_world_file_with_bad_values_is_refused():
    with pytest.raises(ValueError, match="temperature inf is not a finite number"):
        tmclsim.Module(world="temperature = inf\n")
    with pytest.raises(ValueError, match="axis 0: travel from 5 to 1 is empty"):
        tmclsim.Module(world="[[axis]]\ntravel = [5, 1]\n")


def test_a_panic_inside_becomes_an_internal_error():
    from tmclsim import _tmclsim

    with pytest.raises(tmclsim.InternalError, match="a panic on purpose") as caught:
        _tmclsim._panic_inside_guard()
    assert isinstance(caught.value, RuntimeError) and isinstance(caught.value, Exception)


@pytest.mark.parametrize("seconds", [math.inf, -math.inf, math.nan, -1.0, -1e-9])
def test_durations_that_are_not_a_time_forward_are_refused(module, seconds):
    with pytest.raises(ValueError, match="time moves forward only"):
        module.advance(seconds)
    assert module.time_ns == 0


@pytest.mark.parametrize("seconds", [1e12, 2.0**64 * 1e-9, 1e300])
def test_durations_beyond_virtual_time_are_refused_not_capped(module, seconds):
    with pytest.raises(ValueError, match="too long"):
        module.advance(seconds)
    with pytest.raises(ValueError, match="too long"):
        tmclsim.Bus([module]).advance(seconds)
    assert module.time_ns == 0


def test_an_advance_past_the_end_of_virtual_time_is_refused(module):
    module.advance(1e10)
    with pytest.raises(ValueError, match="passes the end of virtual time"):
        module.advance(1e10)
    assert module.time_ns == 10**19


def test_a_stepped_server_refuses_the_same_durations(module):
    with tmclsim.serve(module, stepped=True) as server:
        for seconds in (math.nan, -1, 1e12):
            with pytest.raises(ValueError):
                server.advance(seconds)
        server.advance(0.5)
        assert server.time == pytest.approx(0.5)


BUSY_PROGRAM = """
loop:
    CALC ADD, 1
    JA loop
"""


def test_ctrl_c_stops_a_long_advance(module):
    module.load_program(BUSY_PROGRAM)
    module.run()
    # Python's own Ctrl-C handler, whatever this process inherited (a
    # process started in the background may have SIGINT ignored).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.2, signal.raise_signal, (signal.SIGINT,))
    started = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            module.advance(1e9)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - started < 5
    # The module stays at the time reached and goes on from there.
    reached = module.time_ns
    assert 0 < reached < 10**18
    assert module.program_mode == "run"
    module.advance(0.001)
    assert module.time_ns == reached + 1_000_000


def test_a_short_advance_is_one_exact_step(module):
    module.send("MVP ABS, 0, 51200")
    module.advance(10)
    assert module.time_ns == 10_000_000_000
    assert module.actual_position() == 51200
