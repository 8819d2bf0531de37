"""PyTrinamic 0.2.26 from the package registry against a virtual TMCM-1141,
over TCP (socket_serial_tmcl) and over the pty (serial_tmcl)."""

import pytest
from pytrinamic_links import LINKS, connect, module_time_passes, wait_until
from pytrinamic.modules import TMCM1141
from pytrinamic.tmcl import TMCLReplyStatusError


@pytest.mark.parametrize("link", LINKS)
def test_firmware_version(served, link):
    with connect(served, link) as interface:
        assert interface.get_version_string() == "1141V146"
        info = interface.send(136, 1, 0, 0)
        assert info.value == 0x0475012E


@pytest.mark.parametrize("link", LINKS)
def test_set_and_read_parameters(served, link):
    with connect(served, link) as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        motor.linear_ramp.max_velocity = 1234
        assert motor.linear_ramp.max_velocity == 1234
        module.set_axis_parameter(motor.AP.MaxAcceleration, 0, 555)
        assert module.get_axis_parameter(motor.AP.MaxAcceleration, 0) == 555
        module.set_global_parameter(module.GP0.tickTimer, 0, 0)
        assert module.get_global_parameter(module.GP0.serialAddress, 0) == 1
        # Out of range: the module answers status 4 and PyTrinamic raises.
        with pytest.raises(TMCLReplyStatusError) as err:
            module.set_axis_parameter(motor.AP.MaxVelocity, 0, 5000)
        assert err.value.reply.status == 4
        # Read-only parameter: status 3.
        with pytest.raises(TMCLReplyStatusError) as err:
            module.set_axis_parameter(motor.AP.ActualVelocity, 0, 1)
        assert err.value.reply.status == 3


@pytest.mark.parametrize("link", LINKS)
def test_move_to_and_wait_for_position_reached(served, link):
    with connect(served, link) as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        motor.linear_ramp.max_velocity = 2047
        motor.linear_ramp.max_acceleration = 2047
        module.move_to(0, 20000)
        assert motor.get_position_reached() == 0
        assert wait_until(lambda: motor.get_position_reached() == 1, seen=lambda: motor.actual_position)
        assert motor.actual_position == 20000
        motor.move_by(-5000)
        assert wait_until(lambda: motor.get_position_reached() == 1, seen=lambda: motor.actual_position)
        assert motor.actual_position == 15000


@pytest.mark.parametrize("link", LINKS)
def test_rotate_and_stop(served, link):
    with connect(served, link) as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        module.rotate(0, 800)
        assert wait_until(lambda: motor.actual_velocity == 800, seen=lambda: motor.actual_velocity)
        p1 = motor.actual_position
        assert wait_until(lambda: motor.actual_position > p1, what=f"the position to pass {p1}", seen=lambda: motor.actual_position)
        module.stop(0)
        assert wait_until(lambda: motor.actual_velocity == 0, seen=lambda: motor.actual_velocity)
        p2 = motor.actual_position
        # Stopped: the position stays while 50 ms of the module's time pass.
        module_time_passes(module, 50)
        assert motor.actual_position == p2
        module.rotate(0, -300)
        assert wait_until(lambda: motor.actual_velocity == -300, seen=lambda: motor.actual_velocity)
        module.stop(0)


@pytest.mark.parametrize("link", LINKS)
def test_digital_outputs_and_inputs(served, link):
    with connect(served, link) as interface:
        module = TMCM1141(interface)
        module.set_digital_output(1)
        assert module.get_digital_output(1) == 1
        module.clear_digital_output(1)
        assert module.get_digital_output(1) == 0
        assert module.get_analog_input(8) == 240


def test_eeprom_survives_a_restart(serve, tmp_path):
    eeprom = tmp_path / "module.eeprom"
    first = serve("--eeprom", str(eeprom))
    with connect(first, "tcp") as interface:
        module = TMCM1141(interface)
        module.set_axis_parameter(4, 0, 1717)
        module.store_axis_parameter(4, 0)
        module.set_global_parameter(42, 2, -99)
        module.store_global_parameter(42, 2)
    first.stop()
    second = serve("--eeprom", str(eeprom))
    assert any("restored from" in line for line in second.banner)
    with connect(second, "tcp") as interface:
        module = TMCM1141(interface)
        assert module.get_axis_parameter(4, 0) == 1717
        assert module.get_global_parameter(42, 2, signed=True) == -99


def test_banner_gives_a_connect_hint(served):
    assert served.connect_hint.startswith("connect with:")
    assert served.tcp in served.connect_hint
