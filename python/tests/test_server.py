"""Serving: endpoints, PyTrinamic over TCP and the pty, stepped virtual
time, world and link faults, the module's hand-over and hand-back, and
stopping (explicitly, by context manager, by garbage collection)."""

import gc
import os
import socket
import time

import pytest

import tmclsim
from endpoints import port_open

pytrinamic = pytest.importorskip("pytrinamic")
from pytrinamic.modules import TMCM1141  # noqa: E402


def test_endpoints_and_pytrinamic_over_tcp():
    module = tmclsim.Module()
    with tmclsim.serve(module) as server:
        assert server.tcp.startswith("127.0.0.1:") and server.pty is None
        assert server.control.startswith("127.0.0.1:")
        assert server.pytrinamic_args == f"--interface socket_serial_tmcl --port {server.tcp}"
        with server.connect() as interface:
            assert interface.get_version_string() == "1141V146"
            motor = TMCM1141(interface).motors[0]
            motor.set_axis_parameter(motor.AP.MaxVelocity, 1500)
        assert module.served and module.get_axis_parameter(4) == 1500
    assert not server.running and not module.served
    assert module.get_axis_parameter(4) == 1500, "the module came back with its state"


def test_pytrinamic_over_the_pty(tmp_path):
    link = tmp_path / "ttyTMCL"
    with tmclsim.serve(tmclsim.Module(address=3), tcp=None, pty=link) as server:
        assert server.pty == str(link) and os.path.islink(link)
        assert server.pty_device.startswith("/dev/")
        assert server.pytrinamic_args == f"--interface serial_tmcl --port {link}"
        with server.connect(timeout=5) as interface:
            assert interface.get_global_parameter(66, 0, module_id=3) == 3
    assert not os.path.exists(link), "the symlink goes with the server"


def test_a_pty_in_the_temporary_directory():
    with tmclsim.serve(tmclsim.Module(), pty=True) as server:
        assert server.pty and os.path.islink(server.pty)
        assert server.pytrinamic_pty_args == f"--interface serial_tmcl --port {server.pty}"
        with server.connect(via="pty") as interface:
            assert interface.get_global_parameter(66, 0) == 1


def test_real_time_motion_over_tcp():
    module = tmclsim.Module()
    with tmclsim.serve(module) as server, server.connect() as interface:
        tmcm = TMCM1141(interface)
        tmcm.move_to(0, 20000)
        deadline = time.monotonic() + 10
        while not tmcm.motors[0].get_position_reached():
            assert time.monotonic() < deadline
            time.sleep(0.01)
        assert module.actual_position() == 20000
        assert server.time > 0


def test_stepped_time_runs_an_hour_in_moments():
    module = tmclsim.Module(world="free")
    module.advance(1.0)
    with tmclsim.serve(module, stepped=True) as server, server.connect() as interface:
        assert server.stepped and server.time == 1.0, "time goes on from where the module was"
        interface.send(1, 0, 0, 1000)  # ROR 0, 1000
        time.sleep(0.05)
        assert module.actual_position() == 0, "stepped: the wall clock moves nothing"
        started = time.perf_counter()
        server.advance(3600)
        assert time.perf_counter() - started < 0.5
        assert server.time == pytest.approx(3601.0)
        position = interface.get_axis_parameter(1, 0, signed=True)
        assert position == module.actual_position() and position > 10_000_000
        module.advance(1.0)  # the served module's own advance moves the link
        assert server.time == pytest.approx(3602.0)


def test_switching_between_real_and_stepped_time():
    module = tmclsim.Module()
    with tmclsim.serve(module) as server:
        with pytest.raises(RuntimeError, match="stepped"):
            server.advance(1)
        with pytest.raises(RuntimeError, match="real time"):
            module.advance(1)
        server.stepped = True
        frozen = server.time
        time.sleep(0.05)
        assert server.time == frozen
        server.advance(2.5)
        assert server.time == pytest.approx(frozen + 2.5)
        server.stepped = False
        time.sleep(0.05)
        assert server.time > frozen + 2.5


def test_world_and_link_faults_through_the_server():
    with tmclsim.serve(tmclsim.Module()) as server, server.connect() as interface:
        tmcm = TMCM1141(interface)
        server.set_input(2, 1)
        assert tmcm.get_digital_input(2) == 1
        server.press_switch(0, "right")
        assert tmcm.motors[0].get_axis_parameter(tmcm.motors[0].AP.RightEndstop) == 1
        assert "right 1" in server.show(0)
        assert server.world("link corrupt 1") == ""
        with pytest.raises(Exception):
            interface.get_global_parameter(66, 0)
        faults = server.link_faults(delay_ms=100)
        assert faults == {"drop": 0, "corrupt": 0, "delay_ms": 100, "mute": False}
        started = time.monotonic()
        interface.get_global_parameter(66, 0)
        assert time.monotonic() - started >= 0.1
        assert server.link_faults(clear=True)["delay_ms"] == 0
        with pytest.raises(ValueError, match="unknown command"):
            server.world("levitate")


def test_the_control_socket_speaks_the_line_protocol():
    with tmclsim.serve(tmclsim.Module()) as server:
        host, port = server.control.rsplit(":", 1)
        with socket.create_connection((host, int(port)), timeout=5) as s:
            s.sendall(b"input 1 1\nshow 0\n")
            answers = s.makefile()
            lines = answers.readline(), answers.readline()
        assert lines[0].strip() == "ok" and lines[1].startswith("ok time")
        assert server.module.send("GIO 1, 0").value == 1


def test_stop_is_final_and_repeatable():
    module = tmclsim.Module()
    server = tmclsim.serve(module)
    address = server.tcp
    assert port_open(address)
    server.stop()
    server.stop()
    assert not port_open(address)
    with pytest.raises(RuntimeError, match="stopped"):
        server.world("show")
    with pytest.raises(RuntimeError, match="stopped"):
        server.time
    assert "stopped" in repr(server)


def test_garbage_collection_stops_the_server():
    module = tmclsim.Module()
    server = tmclsim.serve(module)
    address = server.tcp
    assert module.served
    del server
    gc.collect()
    assert not port_open(address)
    assert not module.served


def test_a_served_module_cannot_be_served_twice():
    module = tmclsim.Module()
    with tmclsim.serve(module):
        with pytest.raises(RuntimeError, match="served"):
            tmclsim.serve(module)
        with pytest.raises(RuntimeError, match="served"):
            module.step()


def test_a_busy_port_leaves_the_module_where_it_was():
    blocker = socket.socket()
    blocker.bind(("127.0.0.1", 0))
    blocker.listen()
    try:
        module = tmclsim.Module()
        module.send("SAP 4, 0, 1234")
        with pytest.raises(OSError, match="cannot serve"):
            tmclsim.serve(module, tcp="%s:%d" % blocker.getsockname())
        assert not module.served and module.get_axis_parameter(4) == 1234
    finally:
        blocker.close()
    with pytest.raises(ValueError, match="tcp, pty or both"):
        tmclsim.serve(tmclsim.Module(), tcp=None)
    with pytest.raises(TypeError):
        tmclsim.serve("tmcm-1141")


def test_eeprom_file_of_a_served_module(tmp_path):
    path = tmp_path / "served.eeprom"
    module = tmclsim.Module(eeprom=path)
    with tmclsim.serve(module) as server, server.connect() as interface:
        interface.set_axis_parameter(4, 0, 999)
        interface.send(7, 4, 0, 0)  # STAP 4, 0
    del module, server, interface  # the file has one user at a time
    assert tmclsim.Module(eeprom=path).get_axis_parameter(4) == 999


def test_events_go_out_on_the_link():
    with tmclsim.serve(tmclsim.Module(), stepped=True) as server:
        host, port = server.tcp.rsplit(":", 1)
        with socket.create_connection((host, int(port)), timeout=5) as s:
            for ins in ["#138 0 0 1", "MVP ABS, 0, 5000"]:
                s.sendall(tmclsim.Instruction.parse(ins).frame(1))
                assert tmclsim.Reply(s.recv(9)).ok
            server.advance(5)
            event = tmclsim.Reply(s.recv(9))
        assert (event.status, event.opcode, event.value) == (128, 138, 1)
