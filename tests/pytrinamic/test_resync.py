"""docs/behaviour.md rule 85, with raw bytes as a host driver sends them
when it opens the port: nine zero bytes (address 0, opcode 0) get a reply
with status 2 on a point-to-point link (pty, TCP to one module); on a bus
only the addressed module answers."""

import socket

import serial

RESYNC = bytes(9)


def checksum_ok(reply):
    return sum(reply[:8]) % 256 == reply[8]


def over_tcp(served, frame, wait=2.0):
    host, port = served.tcp.rsplit(":", 1)
    with socket.create_connection((host, int(port)), timeout=wait) as s:
        s.sendall(frame)
        reply = b""
        try:
            while len(reply) < 9:
                chunk = s.recv(9 - len(reply))
                if not chunk:
                    break
                reply += chunk
        except socket.timeout:
            pass
    return reply


def test_resync_over_the_pty_gets_status_2(serve):
    served = serve("--module", "tmcm-3110", "--address", "5")
    with serial.Serial(served.pty_link, 9600, timeout=2) as port:
        port.write(RESYNC)
        reply = port.read(9)
        assert len(reply) == 9 and checksum_ok(reply), reply
        assert reply[:4] == bytes([2, 5, 2, 0]), "host 2, module 5, status 2 (invalid command), opcode 0"
        # The link is in step: the next command is answered as usual.
        port.write(bytes([5, 6, 140, 0, 0, 0, 0, 0, (5 + 6 + 140) % 256]))
        reply = port.read(9)
        assert reply[2] == 100 and int.from_bytes(reply[4:8], "big") == 8, reply


def test_resync_over_tcp_gets_status_2(serve):
    served = serve("--module", "tmcm-1140")
    reply = over_tcp(served, RESYNC)
    assert len(reply) == 9 and checksum_ok(reply), reply
    assert reply[:4] == bytes([2, 1, 2, 0])


def test_on_a_bus_nobody_answers_address_0(serve):
    served = serve("--bus", "tmcm-1141@1,tmcm-6110@2")
    assert over_tcp(served, RESYNC, wait=0.5) == b""
    reply = over_tcp(served, bytes([2, 6, 207, 5, 0, 0, 0, 0, (2 + 6 + 207 + 5) % 256]))
    assert reply[1:3] == bytes([2, 100]), "GAP 207, 5 of the TMCM-6110 at address 2"
