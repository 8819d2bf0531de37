"""Helpers shared by the PyTrinamic tests: a connection over one of the
served links, and waiting for a condition in wall-clock time."""

import inspect
import time

from pytrinamic.connections import ConnectionManager

LINKS = ["tcp", "pty"]


def connection_arguments(served, link):
    """PyTrinamic's connection arguments for the served module's `link`
    (tcp, or the pty at the module's default 9600 baud)."""
    if link == "tcp":
        args = f"--interface socket_serial_tmcl --port {served.tcp}"
    else:
        args = f"--interface serial_tmcl --port {served.pty_link} --data-rate 9600"
    return args.split()


def connect(served, link):
    """PyTrinamic's connection to the served module over `link` (tcp, or the
    pty at the module's default 9600 baud)."""
    return ConnectionManager(connection_arguments(served, link)).connect()


def wait_until(predicate, timeout=20.0, what=None, seen=None):
    """Polls `predicate()` until it is true (returns True). After `timeout`
    seconds fails, naming `what` was awaited (by default the predicate's
    source line) and what `seen()` gives then."""
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            saw = f"; saw {seen()!r}" if seen else ""
            raise AssertionError(f"waited {timeout} s for {what or _source(predicate)}{saw}")
        time.sleep(0.01)  # the poll's interval
    return True


def _source(function):
    try:
        return inspect.getsource(function).strip()
    except (OSError, TypeError):
        return repr(function)


def module_time_passes(module, ms):
    """Waits until `ms` milliseconds of the module's own time pass (its tick
    timer, GP 132): what a check that something does not happen waits for."""
    start = module.get_global_parameter(132, 0)
    wait_until(lambda: (module.get_global_parameter(132, 0) - start) % 2**31 >= ms, what=f"{ms} ms of the module's time (GP 132 from {start})",
               seen=lambda: module.get_global_parameter(132, 0))
