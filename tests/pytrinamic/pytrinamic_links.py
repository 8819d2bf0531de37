"""Helpers shared by the PyTrinamic tests: a connection over one of the
served links, and waiting for a condition in wall-clock time."""

import time

from pytrinamic.connections import ConnectionManager

LINKS = ["tcp", "pty"]


def connect(served, link):
    """PyTrinamic's connection to the served module over `link` (tcp, or the
    pty at the module's default 9600 baud)."""
    if link == "tcp":
        args = f"--interface socket_serial_tmcl --port {served.tcp}"
    else:
        args = f"--interface serial_tmcl --port {served.pty_link} --data-rate 9600"
    return ConnectionManager(args.split()).connect()


def wait_until(predicate, timeout=20.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.01)
    return False
