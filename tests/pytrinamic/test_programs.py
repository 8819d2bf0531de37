"""PyTrinamic downloads a TMCL binary assembled by `tmclsim asm` (8 bytes per
instruction, as the LoadTMCLBinary pattern reads it), verifies it by reading
the program memory back and starts it."""

import subprocess

from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141
from pytrinamic_links import wait_until

from tmclsim_binary import tmclsim_binary

PROGRAM = """
// Count to 100 in user variable 7, then blink OUT0 every 100 ms.
    CALC LOAD, 0
Count:
    CALC ADD, 1
    COMP 100
    JC LT, Count
    AGP 7, 2
Blink:
    SIO 0, 2, 1
    WAIT TICKS, 0, 10
    SIO 0, 2, 0
    WAIT TICKS, 0, 10
    JA Blink
"""


def assemble(tmp_path):
    src = tmp_path / "blink.tmc"
    src.write_text(PROGRAM)
    out = tmp_path / "blink.bin"
    subprocess.run([tmclsim_binary(), "asm", str(src), "-o", str(out)], check=True, capture_output=True)
    return out.read_bytes()


def words(binary):
    for i in range(0, len(binary), 8):
        w = binary[i : i + 8]
        assert sum(w[:7]) & 0xFF == w[7], "checksum of the binary word"
        yield w[0], w[1], w[2], int.from_bytes(w[3:7], "big", signed=True)


def test_pytrinamic_downloads_our_binary_and_runs_it(served, tmp_path):
    binary = assemble(tmp_path)
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}".split()).connect() as interface:
        module = TMCM1141(interface)
        interface.send(132, 0, 0, 0)  # enter download mode at address 0
        for op, typ, motor, value in words(binary):
            reply = interface.send(op, typ, motor, value)
            assert reply.status == 101
        interface.send(133, 0, 0, 0)
        # Read back: the reply carries the stored instruction.
        for address, (op, typ, motor, value) in enumerate(words(binary)):
            r = interface.send(134, 0, 0, address)
            assert (r.module_address, r.status, r.command) == (op, typ, motor)
            assert r.value == value & 0xFFFFFFFF
        interface.send(129, 1, 0, 0)
        wait_until(lambda: module.get_global_parameter(7, 2) == 100, 10, "user variable 7 to count to 100", seen=lambda: module.get_global_parameter(7, 2))
        assert module.get_global_parameter(128, 0) == 1  # running
        seen = set()

        def out0_was_both():
            seen.add(module.get_digital_output(0))
            return len(seen) == 2

        wait_until(out0_was_both, 10, "OUT0 to be both 0 and 1", seen=lambda: seen)
        assert seen == {0, 1}, "OUT0 blinks"
        interface.send(128, 0, 0, 0)
        assert module.get_global_parameter(128, 0) == 0
