"""Fixtures: a veth pair made for the test, and `tmclsim serve --ethercat`
on one end; the master (pysoem) opens the other."""

import os
import pathlib
import subprocess
import sys
import time
import uuid

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from tmclsim_binary import tmclsim_binary  # noqa: E402


def _ip(*args):
    subprocess.run(["ip", *args], check=True, capture_output=True)


@pytest.fixture
def veth():
    if os.geteuid() != 0:
        pytest.skip("a veth pair needs root")
    tag = uuid.uuid4().hex[:6]
    master, slave = f"ecm{tag}", f"ecs{tag}"
    _ip("link", "add", master, "type", "veth", "peer", "name", slave)
    try:
        _ip("link", "set", master, "up")
        _ip("link", "set", slave, "up")
        yield master, slave
    finally:
        subprocess.run(["ip", "link", "del", master], capture_output=True)


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
        line = p.stdout.readline()
        assert "EtherCAT slave" in line, line
        p.stdout.readline()
        time.sleep(0.1)
        return master

    yield start
    for p in procs:
        p.terminate()
        p.wait(timeout=10)
        p.stdout.close()
