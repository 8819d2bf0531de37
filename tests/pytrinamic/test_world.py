"""The served world, seen through PyTrinamic: homing against the built-in
stage over the pty, switches and inputs driven through the control socket,
and link faults that look like a real link's timeouts and checksum errors."""

import time

import pytest
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141
from pytrinamic.tmcl import TMCLReplyChecksumError
from pytrinamic_links import module_time_passes, wait_until


def pty_connection(served, timeout=5):
    args = f"--interface serial_tmcl --port {served.pty_link} --data-rate 9600 --timeout {timeout}"
    return ConnectionManager(args.split()).connect()


def tcp_connection(served):
    return ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}".split()).connect()


def test_homing_routine_over_the_pty(served):
    """Search the home switch (mode 8: positive direction, middle of the
    switch), then move relative to it: the pattern of a host's homing."""
    with pty_connection(served) as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        motor.set_axis_parameter(motor.AP.ReferenceSearchMode, 8)
        motor.set_axis_parameter(motor.AP.ReferenceSearchSpeed, 2047)
        motor.set_axis_parameter(motor.AP.ReferenceSwitchSpeed, 500)
        interface.send(13, 0, 0, 0)  # RFS START
        # RFS STATUS: 0 once the search is done.
        wait_until(lambda: interface.send(13, 2, 0, 0).value == 0, 30, "the homing to finish", seen=lambda: f"position {motor.actual_position}")
        assert motor.actual_position == 0
        # The built-in stage's home switch spans 100000…110000: its middle
        # is where the position counter was 105000 before homing.
        assert motor.get_axis_parameter(motor.AP.LastReferenceSwitchPosition, signed=True) == 105000
        motor.linear_ramp.max_velocity = 2047
        module.move_to(0, -20000)
        wait_until(lambda: motor.get_position_reached(), 10, "position reached", seen=lambda: f"position {motor.actual_position}")
        assert motor.actual_position == -20000


def test_switches_and_inputs_from_the_control_socket(served):
    with tcp_connection(served) as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        assert module.get_digital_input(2) == 0
        served.world("input 2 1")
        assert module.get_digital_input(2) == 1
        served.world("analog 0 1234")
        assert module.get_analog_input(0) == 1234
        served.world("switch 0 right press")
        assert motor.get_axis_parameter(motor.AP.RightEndstop) == 1
        module.rotate(0, 500)
        module_time_passes(module, 50)
        assert motor.actual_velocity == 0, "the pressed right switch blocks positive motion"
        served.world("switch 0 right auto")
        assert "axis 0" in served.world("show 0")
        module.stop(0)


def test_link_faults_look_like_a_real_links(served):
    with tcp_connection(served) as interface:
        module = TMCM1141(interface)
        interface.set_timeout(0.3)
        assert module.get_global_parameter(66, 0) == 1
        served.world("link corrupt 1")
        with pytest.raises(TMCLReplyChecksumError):
            module.get_global_parameter(66, 0)
        assert module.get_global_parameter(66, 0) == 1
        served.world("link delay 100")
        t = time.monotonic()
        module.get_global_parameter(66, 0)
        assert time.monotonic() - t >= 0.1
        served.world("link delay 0")
    # A dropped reply is a timeout for the host (over the pty, as a serial port).
    served.world("link drop 1")
    with pty_connection(served, timeout=0.3) as interface:
        with pytest.raises(RuntimeError, match="timed out"):
            interface.get_global_parameter(66, 0)
        assert interface.get_global_parameter(66, 0) == 1
