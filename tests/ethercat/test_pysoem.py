"""A real EtherCAT master (pysoem, from the package registry) against the
virtual TMCM-1310 slave on a veth pair: enumeration and identity, the state
machine up to OP and its refusals, process data moves, TMCL over the
mailbox, and frames that are not valid."""

import socket
import struct
import time

import pysoem
import pytest

TMCL = 0x2000


def open_master(iface, expect=1):
    m = pysoem.Master()
    m.open(iface)
    # Below 0: no frame of its own came back in SOEM's time (-1 none, -2
    # only another, e.g. a late answer to an earlier try) on a busy test
    # machine; a master asks again. Any count is the answer.
    for _ in range(5):
        found = m.config_init()
        if found >= 0:
            break
    assert found == expect
    return m


# How long a state change may take: SOEM's own default (EC_TIMEOUTSTATE).
# A slave answers at once, but on a busy test machine the frames that ask
# and check can be late.
STATE_TIMEOUT_US = 2_000_000
# How long a cycle waits for its process data frame: 100 ms, not a real-time
# master's fraction of a millisecond, since the slave is a process on a test
# machine that may be busy.
RECEIVE_TIMEOUT_US = 100_000
# The process data watchdog the tests set: 5 s. A busy test machine can
# hold the master (or the slave process) for longer than the slave's
# 100 ms default, which would stop the motor and drop the slave to SafeOp
# in the middle of a move; the watchdog's own test sets 100 ms again.
WATCHDOG_MS = 5000


def to_op(m):
    m.config_map()
    for s in m.slaves:
        s.set_watchdog("processdata", WATCHDOG_MS)
    assert m.state_check(pysoem.SAFEOP_STATE, STATE_TIMEOUT_US) == pysoem.SAFEOP_STATE
    for s in m.slaves:
        s.output = struct.pack("<Ii", 0, 0)
    m.send_processdata()
    m.receive_processdata(RECEIVE_TIMEOUT_US)
    m.state = pysoem.OP_STATE
    m.write_state()
    deadline = time.monotonic() + STATE_TIMEOUT_US / 1e6
    while time.monotonic() < deadline:
        m.send_processdata()
        m.receive_processdata(RECEIVE_TIMEOUT_US)
        if m.state_check(pysoem.OP_STATE, 10_000) == pysoem.OP_STATE:
            return
    pytest.fail("no OP")


def cycle_until(m, done, timeout=10.0):
    """Process data cycles until `done()`; fails after `timeout` seconds
    with the last working counter and the slaves' inputs."""
    deadline = time.monotonic() + timeout
    wkc = None
    while time.monotonic() < deadline:
        m.send_processdata()
        wkc = m.receive_processdata(RECEIVE_TIMEOUT_US)
        if wkc <= 0:
            # The frame came back late (a busy test machine): a master
            # skips the cycle. A frame that came back was worked on by
            # every slave.
            continue
        assert wkc == m.expected_wkc
        if done():
            return
        time.sleep(0.001)  # the cycle's interval
    pytest.fail(f"process data never showed the expected state in {timeout} s: last working counter {wkc}, inputs {[inputs(s) for s in m.slaves]}")


def inputs(slave):
    return struct.unpack("<12i", slave.input)


def tmcl(slave, opcode, kind, motor, value, address=1):
    slave.sdo_write(TMCL, 0, bytes([address, opcode, kind, motor]) + struct.pack(">i", value))
    reply = slave.sdo_read(TMCL, 0)
    host, module, status, op = reply[:4]
    return status, struct.unpack(">i", reply[4:])[0]


def test_enumerate_and_identity(ethercat):
    m = open_master(ethercat())
    s = m.slaves[0]
    assert (s.name, s.man, s.id, s.rev) == ("TMCM-1310", 0x286, 1310, 0x0001000E)
    assert m.read_state() == pysoem.PREOP_STATE
    assert s.sdo_read(0x1018, 1) == struct.pack("<I", 0x286)
    m.close()


def test_op_and_process_data_moves(ethercat):
    m = open_master(ethercat())
    s = m.slaves[0]
    to_op(m)
    assert (len(s.output), len(s.input)) == (8, 48)
    # Position mode: set-point 51200.
    s.output = struct.pack("<Ii", 1, 51200)
    cycle_until(m, lambda: inputs(s)[1] == 51200)
    f = inputs(s)
    assert f[0] == 51200 and f[2] == 51200, "target and virtual position"
    assert f[7] & 0b1001 == 0b1001, "status word: target reached, position mode"
    # Velocity mode: set-point 500 (pps).
    s.output = struct.pack("<Ii", 2, 500)
    cycle_until(m, lambda: inputs(s)[5] == 500)
    assert inputs(s)[4] == 500
    assert inputs(s)[7] & 0b10000, "velocity mode bit"
    s.output = struct.pack("<Ii", 2, 0)
    cycle_until(m, lambda: inputs(s)[5] == 0)
    m.close()


def test_tmcl_over_the_mailbox(ethercat):
    m = open_master(ethercat())
    s = m.slaves[0]
    assert tmcl(s, 5, 4, 0, 1234) == (100, 1234)  # SAP 4
    assert tmcl(s, 6, 4, 0, 0) == (100, 1234)  # GAP 4
    assert tmcl(s, 5, 4, 0, 327680000)[0] == 4  # out of range (1…327679999 pps)
    assert tmcl(s, 6, 99, 0, 0)[0] == 3  # no such parameter
    assert tmcl(s, 200, 0, 0, 0)[0] == 2  # no such command
    assert tmcl(s, 9, 66, 0, 5)[0] == 8  # SGP 66: password protected
    s.sdo_write(TMCL, 0, bytes([1, 136, 0, 0, 0, 0, 0, 0]))
    assert s.sdo_read(TMCL, 0) == b"1310V114"
    # Download over the mailbox answers 100 (EtherCAT has no 101).
    assert tmcl(s, 132, 0, 0, 0) == (100, 0)
    assert tmcl(s, 3, 0, 0, 0)[0] == 100
    assert tmcl(s, 133, 0, 0, 0)[0] == 100
    m.close()


def test_stap_over_the_mailbox_reaches_the_eeprom_file(ethercat, tmp_path):
    # The slave's module is on a bus like every front end's: its EEPROM
    # writes are saved. A master gives a mailbox frame a few milliseconds,
    # a synced file write can take longer: the frames do not wait for the
    # file, so a burst of stores all succeed and the file ends with the
    # last of them.
    eeprom = tmp_path / "slave.json"
    m = open_master(ethercat(eeprom=eeprom))
    s = m.slaves[0]
    for value in range(1000, 1040):
        assert tmcl(s, 5, 4, 0, value) == (100, value)  # SAP 4
        assert tmcl(s, 7, 4, 0, 0)[0] == 100  # STAP 4
    m.close()
    deadline = time.monotonic() + 10
    while True:
        text = eeprom.read_text() if eeprom.exists() else "(no file)"
        if '"0/4": 1039' in text:
            break
        assert time.monotonic() < deadline, f"the EEPROM file was not written in 10 s: {text[:500]}"
        time.sleep(0.05)  # the poll's interval


def test_the_state_machine_refuses_invalid_transitions(ethercat):
    m = open_master(ethercat())
    s = m.slaves[0]
    # PreOp → Op directly: refused, the slave stays in PreOp with an error.
    s.state = pysoem.OP_STATE
    s.write_state()
    m.read_state()
    assert s.state == pysoem.PREOP_STATE | 0x10
    assert s.al_status == 0x0011
    # Acknowledge, then SafeOp without the process data SyncManagers.
    s.state = pysoem.PREOP_STATE | 0x10
    s.write_state()
    m.read_state()
    assert s.state == pysoem.PREOP_STATE
    s.state = pysoem.SAFEOP_STATE
    s.write_state()
    m.read_state()
    assert s.state & 0x0F == pysoem.PREOP_STATE and s.al_status in (0x001D, 0x001E)
    m.close()


def test_malformed_frames_are_ignored(ethercat):
    iface = ethercat()
    raw = socket.socket(socket.AF_PACKET, socket.SOCK_RAW)
    raw.bind((iface, 0))
    head = b"\xff" * 6 + b"\x02" * 6 + b"\x88\xa4"
    for junk in [
        head + b"\xff\x1f",  # length beyond the frame
        head + b"\x10\x10" + b"\x04\x00\x00\x00\x30\x01\x50\x00",  # truncated datagram
        head + bytes(range(46)),  # random datagrams
        head,  # header only
        b"\x00" * 8,  # not even Ethernet
    ]:
        raw.send(junk.ljust(14, b"\x00"))
    raw.close()
    # A veth hands each frame to the peer as it is sent: the junk waits on
    # the slave's socket ahead of the master's frames, so the slave has gone
    # through it when it answers them.
    m = open_master(iface)
    to_op(m)
    m.close()


def test_sixteen_slaves_on_one_segment(ethercat):
    m = open_master(ethercat(16), expect=16)
    to_op(m)
    for i, s in enumerate(m.slaves):
        s.output = struct.pack("<Ii", 1, 1000 * (i + 1))
    cycle_until(m, lambda: all(inputs(s)[1] == 1000 * (i + 1) for i, s in enumerate(m.slaves)))
    m.close()


def test_process_data_watchdog(ethercat):
    m = open_master(ethercat())
    s = m.slaves[0]
    to_op(m)
    s.output = struct.pack("<Ii", 2, 800)
    cycle_until(m, lambda: inputs(s)[5] == 800)
    s.set_watchdog("processdata", 100)
    assert s.get_watchdog("processdata") == pytest.approx(100)
    # No more process data: after 100 ms the watchdog drops the slave to
    # SafeOp with an error.
    deadline = time.monotonic() + 10
    while True:
        m.read_state()
        if s.state == pysoem.SAFEOP_STATE | 0x10:
            break
        assert time.monotonic() < deadline, f"no SafeOp with an error in 10 s: state {s.state:#x}, AL status {s.al_status:#06x}"
        time.sleep(0.01)  # the poll's interval
    assert s.al_status == 0x001B
    assert tmcl(s, 6, 2, 0, 0) == (100, 0), "the motor was stopped"
    m.close()
