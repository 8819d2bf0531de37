"""The Python package drives the firmware's Bus like every front end:
module differences come from the profile, a Bus shares one clock, world
commands reach any module of a bus by address, and a served module is the
same object as the in-process one."""

import tmclsim


def test_features_come_from_the_profile():
    assert tmclsim.Module("tmcm-1141").features["reference_search"].startswith("TMC429")
    f351 = tmclsim.Module("tmcm-351").features
    assert f351["reference_search"].startswith("TMC428")
    assert f351["eeprom_lock"] == "GP 73"
    assert f351["can"].startswith("own identifiers: GP 71")
    assert tmclsim.Module("tmcm-1310").features["closed_loop"] == "yes"


def test_stall_detection_is_the_profile_data_not_its_description():
    assert tmclsim.Module("tmcm-1141").stall_detection == "stallguard2"
    assert tmclsim.Module("tmcm-351").stall_detection == "tmc249"
    assert tmclsim.Module("tmcm-1141").features["stall_detection"].startswith("stallGuard2 (")
    assert tmclsim.Module("tmcm-1141").features["closed_loop"] == "no"


def test_a_bus_moves_its_modules_together():
    a, b = tmclsim.Module(address=1), tmclsim.Module(address=2)
    a.advance(0.5)
    bus = tmclsim.Bus([a, b])
    # The bus brought both to the later time; both now move with it.
    assert a.time == b.time == 0.5
    bus.send(2, "ROR 0, 500")
    b.advance(1.0)
    assert a.time == b.time == bus.time == 1.5
    assert b.actual_speed(0) == 500
    assert a.actual_speed(0) == 0


def test_world_commands_reach_any_module_of_a_bus_by_address():
    a, b = tmclsim.Module(address=1), tmclsim.Module(address=2)
    tmclsim.Bus([a, b])
    a.world("@2 input 1 1")
    assert b.send("GIO 1, 0").value == 1
    assert a.send("GIO 1, 0").value == 0


def test_a_module_served_and_stopped_keeps_its_state():
    m = tmclsim.Module()
    m.set_axis_parameter(4, 0, 1234)
    with tmclsim.serve(m, stepped=True) as server:
        server.advance(0.25)
        assert m.get_axis_parameter(4, 0) == 1234
    assert not m.served
    assert m.time == 0.25
    m.advance(0.25)
    assert m.time == 0.5


def test_events_wait_on_the_bus_for_an_in_process_reader():
    m = tmclsim.Module()
    m.send("#138 0 0 1")
    m.send("MVP ABS, 0, 1000")
    m.advance(2.0)
    events = m.take_events()
    assert [e.status for e in events] == [128]
    assert m.take_events() == []


def test_status_words_come_from_the_firmware():
    assert tmclsim.status_text(4) == "invalid value"
    err = None
    try:
        tmclsim.Module().set_axis_parameter(4, 0, 99999)
    except tmclsim.TmclError as e:
        err = e
    assert err is not None and err.status == 4
    assert err.description == tmclsim.status_text(4)
