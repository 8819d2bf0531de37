"""Fixtures: a veth pair made for the test, and `tmclsim serve --ethercat`
on one end; the master (pysoem) opens the other.

The pair lives in a network namespace of the test's own: the machine's
interfaces never change, so nothing else sees links come and go (a
browser aborts its page loads with ERR_NETWORK_CHANGED when they do, and
the browser tests run beside these). The test's thread enters the
namespace for the test; the processes it starts inherit it; the pair goes
with the namespace when the last of them has left."""

import ctypes
import os
import pathlib
import subprocess
import sys
import uuid

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from tmclsim_binary import read_banner, tmclsim_binary  # noqa: E402


def _ip(*args):
    subprocess.run(["ip", *args], check=True, capture_output=True)


CLONE_NEWNET = 0x40000000
_libc = ctypes.CDLL(None, use_errno=True)


def _enter(call, *args):
    if call(*args) != 0:
        errno = ctypes.get_errno()
        raise OSError(errno, os.strerror(errno))


@pytest.fixture
def veth():
    if os.geteuid() != 0:
        pytest.skip("a veth pair needs root")
    home = os.open("/proc/thread-self/ns/net", os.O_RDONLY)
    try:
        _enter(_libc.unshare, CLONE_NEWNET)
        tag = uuid.uuid4().hex[:6]
        master, slave = f"ecm{tag}", f"ecs{tag}"
        _ip("link", "add", master, "type", "veth", "peer", "name", slave)
        _ip("link", "set", master, "up")
        _ip("link", "set", slave, "up")
        yield master, slave
    finally:
        _enter(_libc.setns, home, CLONE_NEWNET)
        os.close(home)


@pytest.fixture
def ethercat(veth):
    """Starts slaves on the veth pair: ethercat(n) → master interface."""
    procs = []

    def start(slaves=1, eeprom=None):
        master, slave = veth
        extra = ["--eeprom", str(eeprom)] if eeprom else []
        p = subprocess.Popen(
            [tmclsim_binary(), "serve", "--module", "tmcm-1310", "--world", "free", "--ethercat", slave, "--slaves", str(slaves), *extra],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        procs.append(p)
        # The banner's last line comes once the slaves' raw socket is bound:
        # from then on the master's frames wait for them in its queue.
        lines = read_banner(p, timeout=10)
        assert "EtherCAT slave" in lines[0], lines
        return master

    yield start
    for p in procs:
        p.terminate()
        p.wait(timeout=10)
        p.stdout.close()
