"""The in-process Module: commands, replies, parameters, errors, time,
EEPROM and the world."""

import json

import pytest

import tmclsim
from tmclsim import Instruction, TmclError


def test_send_a_command_line_and_decode_the_reply(module):
    reply = module.send("GAP 1, 0")
    assert (reply.status, reply.value, reply.opcode, reply.module, reply.host) == (100, 0, 6, 1, 2)
    assert reply.ok and reply.checksum_ok and not reply.special
    assert reply.description == "ok"
    assert len(reply.raw) == 9 and bytes(reply) == reply.raw


def test_send_opcode_type_motor_value_and_instructions(module):
    assert module.send(5, 4, 0, 1000).ok  # SAP 4, 0, 1000
    assert module.send(6, 4, 0).value == 1000
    assert module.send(Instruction(6, 4, 0, 0)).value == 1000
    assert module.send(Instruction.parse("GAP 4, 0")).value == 1000
    assert module.send("#6 4 0 0").value == 1000
    with pytest.raises(TypeError):
        module.send("GAP 4, 0", 1)


def test_error_replies_are_returned_not_raised(module):
    reply = module.send("GAP 250, 0")
    assert reply.status == 3 and not reply.ok
    assert reply.description == "wrong type"
    with pytest.raises(TmclError) as e:
        reply.check()
    assert e.value.status == 3
    assert module.send("SAP 4, 0, 99999").status == 4
    assert module.send(47, 0, 0, 0).status == 2  # no such command
    assert module.send("ROR 0, 100").check().ok


def test_bad_command_lines_say_where(module):
    with pytest.raises(ValueError, match="column 11"):
        module.send("SAP 4, 0, x12")
    with pytest.raises(ValueError, match="unknown command 'FOO'"):
        module.send("FOO 1")


def test_special_replies_keep_their_bytes(module):
    version = module.send(136, 0, 0, 0)
    assert version.special and version.version == "1141V146"
    assert version.raw == b"\x02" + b"1141V146"
    assert module.version == "1141V146"
    assert module.send("#136 1 0 0").value == 0x0475012E
    module.load_program("MVP ABS, 0, 1000\nSTOP\n")
    word = module.send(134, 0, 0, 0)
    assert word.special and word.instruction == Instruction.parse("MVP ABS, 0, 1000")


def test_raw_frames(module):
    frame = Instruction.parse("GAP 4, 0").frame(1)
    reply = module.send_frame(frame)
    assert tmclsim.Reply(reply).value == 2047 or tmclsim.Reply(reply).ok
    bad = bytearray(frame)
    bad[8] ^= 0xFF
    assert tmclsim.Reply(module.send_frame(bytes(bad))).status == 1
    assert module.send_frame(Instruction.parse("GAP 4, 0").frame(5)) is None  # another address
    with pytest.raises(ValueError, match="9 bytes"):
        module.send_frame(b"\x01\x02")


def test_parameters_by_number_and_by_name(module):
    module.set_axis_parameter(4, 0, 1500)
    assert module.get_axis_parameter(4) == 1500
    for name in ["Maximum positioning speed", "maximum positioning SPEED", "maximum_positioning_speed", "MaximumPositioningSpeed"]:
        assert module.get_axis_parameter(name) == 1500
    module.set_axis_parameter("maximum_acceleration", 0, 100)
    assert module.send("GAP 5, 0").value == 100
    assert module.get_global_parameter("Serial address") == 1
    assert module.get_global_parameter(66, 0) == 1
    module.set_global_parameter("Timer 0 period (ms)", None, 250)
    assert module.get_global_parameter(0, 3) == 250
    module.set_global_parameter(10, 2, -7)
    assert module.get_global_parameter(10, 2) == -7
    names = {p["snake_name"]: p for p in module.axis_parameters()}
    assert names["maximum_positioning_speed"]["number"] == 4
    assert names["actual_position"]["access"] == "RW"
    banks = {p["bank"] for p in module.global_parameters()}
    assert banks == {0, 2, 3}


def test_parameter_errors_raise_tmcl_error_with_the_status(module):
    with pytest.raises(TmclError) as e:
        module.set_axis_parameter("Maximum positioning speed", 0, 99999)
    assert e.value.status == 4
    assert "Maximum positioning speed" in str(e.value) and "1…2047" in str(e.value)
    with pytest.raises(TmclError) as e:
        module.get_axis_parameter(250)
    assert e.value.status == 3 and e.value.description == "wrong type"
    with pytest.raises(TmclError) as e:
        module.set_axis_parameter("Actual speed", 0, 5)
    assert e.value.status == 3 and "read-only" in str(e.value)
    with pytest.raises(TmclError) as e:
        module.get_axis_parameter(1, 3)
    assert e.value.status == 4 and "motor 3" in str(e.value)
    with pytest.raises(TmclError) as e:
        module.get_global_parameter(0, 1)
    assert e.value.status == 4 and "bank 1" in str(e.value)


def test_unknown_names_are_value_errors_with_suggestions(module):
    with pytest.raises(ValueError, match="did you mean 'Maximum positioning speed'"):
        module.get_axis_parameter("positioning speed")
    with pytest.raises(ValueError, match="give the number"):
        module.get_global_parameter("User variables #0…#55")
    with pytest.raises(ValueError, match="bank 0, not of bank 2"):
        module.get_global_parameter("Serial address", 2)
    with pytest.raises(ValueError, match="0…255"):
        module.get_axis_parameter(300)


def test_motion_in_virtual_time(module):
    module.send("MVP ABS, 0, 51200")
    assert module.time == 0.0
    module.advance(0.1)
    assert 0 < module.actual_position() < 51200 and module.actual_speed() > 0
    module.advance(10)
    assert module.actual_position() == 51200
    assert module.get_axis_parameter("Position reached flag") == 1
    assert module.time == pytest.approx(10.1)
    assert module.time_ns == 10_100_000_000
    with pytest.raises(ValueError):
        module.advance(-1)


def test_an_hour_of_motion_takes_milliseconds(module):
    import time

    module.send("ROR 0, 500")
    started = time.perf_counter()
    module.advance(3600)
    assert time.perf_counter() - started < 0.5
    # Rotating right, the carriage ran into the right stop switch.
    assert module.switches()[1] and module.actual_speed() == 0


def test_target_reached_events(module):
    module.send("#138 0 0 1")  # arm for the next MVP of motor 0
    module.send("MVP ABS, 0, 1000")
    module.advance(5)
    events = module.take_events()
    assert [(e.status, e.opcode, e.value) for e in events] == [(128, 138, 1)]
    assert module.take_events() == []


def test_the_eeprom_file_survives_the_process(tmp_path):
    path = tmp_path / "m.eeprom"
    m = tmclsim.Module(eeprom=path)
    assert path.exists() and str(m.eeprom_path) == str(path)
    m.set_axis_parameter(4, 0, 1234)
    m.send("STAP 4, 0")
    m.set_global_parameter("Serial address", None, 3)
    stored = json.loads(path.read_text())
    assert stored["axis"]["0/4"] == 1234
    del m  # the file has one user at a time
    again = tmclsim.Module(eeprom=path)
    assert again.get_axis_parameter(4) == 1234 and again.address == 3
    with pytest.raises(ValueError, match="holds the EEPROM"):
        bad = tmp_path / "other.eeprom"
        bad.write_text(path.read_text().replace("TMCM-1141", "TMCM-351"))
        tmclsim.Module(eeprom=bad)


def test_address_and_eeprom_save_and_power_cycle(tmp_path, module):
    m = tmclsim.Module(address=5)
    assert m.address == 5 and m.send("GAP 1, 0").module == 5
    module.set_axis_parameter(4, 0, 777)
    module.send("STAP 4, 0")
    module.set_axis_parameter(4, 0, 100)
    module.power_cycle()
    assert module.get_axis_parameter(4) == 777
    module.eeprom_save(tmp_path / "copy.json")
    assert tmclsim.Module(eeprom=tmp_path / "copy.json").get_axis_parameter(4) == 777


def test_world_controls(module):
    assert module.send("GIO 2, 0").value == 0
    module.set_input(2, True)
    assert module.send("GIO 2, 0").value == 1
    module.set_analog(0, 1234)
    assert module.send("GIO 0, 1").value == 1234
    module.press_switch(0, "left")
    assert module.get_axis_parameter("Left limit switch state") == 1
    module.auto_switch(0, "left")
    assert module.get_axis_parameter("Left limit switch state") == 0
    module.set_supply(12.5)
    assert module.send("GIO 8, 1").value == 125
    assert "axis 0" in module.show() and module.show(0).startswith("time")
    module.place_switch(0, "home", -5000, 5000)
    assert module.switches() == (False, False, True)
    with pytest.raises(ValueError, match="unknown command"):
        module.world("levitate 0")
    with pytest.raises(ValueError, match="need a link"):
        module.world("link drop 1")
    with pytest.raises(ValueError, match="'left', 'right' or 'home'"):
        module.press_switch(0, "middle")


def test_loads_and_faults_reach_the_driver(module):
    module.send("ROR 0, 1000")
    module.advance(0.5)
    free = module.get_axis_parameter("Actual load value")
    module.load(0, 60)
    module.advance(0.5)
    assert module.get_axis_parameter("Actual load value") < free
    module.fault(0, "open-a")
    assert module.get_axis_parameter("TMC262 error flags") & (1 << 5)
    module.fault(0, "open-a", on=False)


def test_worlds(tmp_path):
    free = tmclsim.Module(world="free")
    free.send("ROR 0, 2047")
    free.advance(3600)
    assert free.actual_speed() == 2047, "no switches in a free world"
    world_file = tmp_path / "w.toml"
    world_file.write_text("base = 'free'\n[[axis]]\nhome_switch = { from = -10, to = 10 }\n")
    assert tmclsim.Module(world=world_file).switches() == (False, False, True)
    assert tmclsim.Module(world=str(world_file)).switches() == (False, False, True)
    assert tmclsim.Module(world="[[axis]]\nstart = 100000\n").switches() == (False, False, True)
    with pytest.raises(ValueError, match="world"):
        tmclsim.Module(world="nowhere.toml")
    with pytest.raises(ValueError, match="no built-in profile"):
        tmclsim.Module(profile="tmcm-9999")
    assert "tmcm-1141" in tmclsim.profiles()


def test_repr_and_properties(module):
    assert "TMCM-1141" in repr(module) and "in process" in repr(module)
    assert module.profile == "TMCM-1141" and module.axes == 1 and not module.served
    assert module.outputs == 0
    module.send("SIO 1, 2, 1")
    assert module.outputs == 2


@pytest.mark.parametrize("profile", tmclsim.profiles())
def test_every_built_in_profile(profile):
    module = tmclsim.Module(profile)
    assert module.profile.lower() == profile
    assert module.send("GAP 1, 0").ok
    assert module.send(136, 0, 0, 0).version == module.version
    first = module.axis_parameters()[0]
    assert module.get_axis_parameter(first["name"]) == module.get_axis_parameter(first["number"])
    assert module.show().startswith("time 0.000 s")
    with tmclsim.serve(module, stepped=True) as server:
        server.advance(1.0)
        assert module.time == 1.0
