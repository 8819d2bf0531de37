"""Several modules on one link: in process and served."""

import socket

import pytest

import tmclsim
from tmclsim import Bus, Instruction, Module


def test_only_the_addressed_module_answers():
    bus = Bus([Module(address=1), Module(address=2)])
    assert len(bus) == 2 and [m.address for m in bus] == [1, 2]
    bus.send(2, "SAP 4, 0, 1500").check()
    assert bus.modules[1].get_axis_parameter(4) == 1500
    assert bus.modules[0].get_axis_parameter(4) != 1500
    assert bus.send(2, "GAP 4, 0").module == 2
    assert bus.send(3, "GAP 4, 0") is None
    assert bus.send_frame(Instruction.parse("GAP 4, 0").frame(1)) is not None
    assert bus.module(2) is bus[1]
    with pytest.raises(ValueError, match="answers to address 9"):
        bus.module(9)


def test_a_bus_shares_virtual_time():
    a, b = Module(address=1), Module(address=2)
    a.advance(2.0)
    bus = Bus([a, b])
    assert b.time == 2.0
    bus.send(1, "ROR 0, 500")
    bus.send(2, "ROL 0, 500")
    bus.advance(1.0)
    assert bus.time == 3.0 == a.time == b.time
    assert a.actual_position() == -b.actual_position() > 0


def test_addresses_must_differ():
    with pytest.raises(ValueError, match="two modules have address 1"):
        Bus([Module(), Module()])
    with pytest.raises(ValueError, match="at least one"):
        Bus([])


def test_serving_a_bus():
    bus = Bus([Module(address=1), Module(address=2)])
    with tmclsim.serve(bus, stepped=True) as server:
        assert server.modules == bus.modules
        host, port = server.tcp.rsplit(":", 1)
        with socket.create_connection((host, int(port)), timeout=5) as s:
            s.sendall(Instruction.parse("SAP 4, 0, 1700").frame(2))
            reply = tmclsim.Reply(s.recv(9))
            assert reply.module == 2 and reply.ok
        assert bus.modules[1].get_axis_parameter(4) == 1700
        server.world("input 3 1", module=1)
        assert bus.send(2, "GIO 3, 0").value == 1
        assert bus.send(1, "GIO 3, 0").value == 0
        bus.send(1, "ROR 0, 300")
        server.advance(1.0)
        assert bus.modules[0].actual_speed() == 300
        assert bus.time == server.time
        with pytest.raises(ValueError, match="the server has 2"):
            server.world("show", module=2)
    assert not any(m.served for m in bus)


def test_pytrinamic_on_a_served_bus():
    pytest.importorskip("pytrinamic")
    bus = Bus([Module(address=1), Module(address=2)])
    with tmclsim.serve(bus) as server, server.connect() as interface:
        interface.set_axis_parameter(4, 0, 1111, module_id=2)
        assert interface.get_axis_parameter(4, 0, module_id=2) == 1111
        assert interface.get_axis_parameter(4, 0, module_id=1) != 1111
