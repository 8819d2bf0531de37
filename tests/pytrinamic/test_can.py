"""PyTrinamic over a virtual serial-line CAN adapter (python-can's slcan
interface, from the package registry) against two modules on one CAN bus;
and three modules on one RS485-style bus over TCP, each answering only for
itself."""

import can
import pytest
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141


def test_two_modules_on_one_can_bus(serve, tmp_path):
    slcan = tmp_path / "slcan"
    serve("--bus", "tmcm-1141@1,tmcm-351@3", "--slcan", str(slcan))
    for module_id, version in [(1, "1141V146"), (3, "351V.445")]:
        args = f"--interface slcan_tmcl --port {slcan} --data-rate 1000000 --module-id {module_id} --timeout 2"
        with ConnectionManager(args.split()).connect() as interface:
            assert interface.get_version_string() == version
            interface.set_axis_parameter(4, 0, 1000 + module_id)
            assert interface.get_axis_parameter(4, 0) == 1000 + module_id
            if module_id == 3:
                # The TMCM-351 has three axes and 32-bit positions. The
                # motor is stopped first (MST: velocity mode at 0), as the
                # manual asks before AP 1 is overwritten: in position mode
                # it would head for the target at once.
                interface.stop(2)
                interface.set_axis_parameter(1, 2, -2147483648)
                assert interface.get_axis_parameter(1, 2, signed=True) == -2147483648


def test_python_can_sees_only_addressed_replies(serve, tmp_path):
    slcan = tmp_path / "slcan"
    serve("--bus", "tmcm-1141@1,tmcm-1141@2", "--slcan", str(slcan))
    with can.Bus(interface="slcan", channel=str(slcan), bitrate=1000000) as bus:
        # GGP 66, 0 to module 2: seven data bytes, no address, no checksum.
        bus.send(can.Message(arbitration_id=2, is_extended_id=False, data=[10, 66, 0, 0, 0, 0, 0]))
        replies = []
        while True:
            msg = bus.recv(timeout=0.5)
            if msg is None:
                break
            replies.append(msg)
        assert len(replies) == 1
        reply = replies[0]
        assert reply.arbitration_id == 2  # the host address
        assert bytes(reply.data) == bytes([2, 100, 10, 0, 0, 0, 2])


def test_three_modules_on_one_rs485_bus(serve):
    served = serve("--bus", "tmcm-1141@1,tmcm-1141@2,tmcm-351@5")
    for module_id in (1, 2, 5):
        args = f"--interface socket_serial_tmcl --port {served.tcp} --module-id {module_id}"
        with ConnectionManager(args.split()).connect() as interface:
            interface.set_axis_parameter(4, 0, 100 * module_id)
    for module_id in (1, 2, 5):
        args = f"--interface socket_serial_tmcl --port {served.tcp} --module-id {module_id}"
        with ConnectionManager(args.split()).connect() as interface:
            module = TMCM1141(interface, module_id=module_id)
            assert module.get_axis_parameter(4, 0) == 100 * module_id
            assert module.get_global_parameter(66, 0) == module_id
    # Nobody answers for address 4: the host times out (over the pty; the
    # socket connection of PyTrinamic 0.2.26 waits without a timeout).
    args = f"--interface serial_tmcl --port {served.pty_link} --module-id 4 --timeout 0.3"
    with ConnectionManager(args.split()).connect() as interface:
        with pytest.raises(RuntimeError, match="timed out"):
            interface.get_axis_parameter(4, 0)
