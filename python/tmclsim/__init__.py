"""tmclsim: virtual Trinamic TMCL modules for testing host software.

A virtual module (a TMCM-1141 today) answers the same 9-byte TMCL frames as
the real one, with the manual's parameter tables, EEPROM behaviour and
TMC429 motion, in deterministic virtual time. Use it in process::

    import tmclsim

    m = tmclsim.Module()                       # a TMCM-1141 on the built-in stage
    m.send("MVP ABS, 0, 51200")
    m.advance(2.0)                             # two seconds of virtual time
    assert m.get_axis_parameter("Actual position") == 51200

or serve it to host software on loopback TCP and a pty::

    with tmclsim.serve(tmclsim.Module(), pty=True) as server:
        interface = server.connect()           # a PyTrinamic connection
        ...

The ``tmcl_module`` pytest fixture (this package's pytest plugin) gives each
test a served module. See the README beside this package.
"""

import os
from typing import Callable, Optional, Union

from . import _tmclsim
from ._tmclsim import (
    Bus,
    Instruction,
    Program,
    Registers,
    Reply,
    assemble,
    assemble_file,
    disassemble,
    profiles,
    status_text,
)
from .errors import AssemblyError, Diagnostic, InternalError, TmclError
from .sweep import sweep

__all__ = [
    "AssemblyError",
    "Bus",
    "Diagnostic",
    "Instruction",
    "InternalError",
    "Module",
    "Program",
    "Registers",
    "Reply",
    "Server",
    "TmclError",
    "WorldControls",
    "assemble",
    "assemble_file",
    "disassemble",
    "profiles",
    "status_text",
    "serve",
    "sweep",
]

__version__ = "0.1.0"

_SWITCHES = ("left", "right", "home")


def _switch(which: str) -> str:
    if which not in _SWITCHES:
        raise ValueError(f"a switch is 'left', 'right' or 'home', not {which!r}")
    return which


class WorldControls:
    """Convenience methods for the world around a module, each one line of
    the control protocol (docs/world.md) sent through ``world(line)``,
    which the native class mixed with this one (``Module``, ``Server``)
    provides."""

    world: Callable[[str], str]

    def set_input(self, n: int, level: Union[bool, int]) -> None:
        """Drives digital input ``n`` high (true) or low."""
        self.world(f"input {int(n)} {1 if level else 0}")

    def set_analog(self, n: int, value: int) -> None:
        """Sets analog input ``n`` to an ADC value 0…4095 (IN0 reads high
        digitally from 2048 up)."""
        self.world(f"analog {int(n)} {int(value)}")

    def set_supply(self, volts: float) -> None:
        """Sets the supply voltage (GIO 8, 1 reads it in 0.1 V)."""
        self.world(f"supply {float(volts)}")

    def set_temperature(self, celsius: float) -> None:
        """Sets the driver temperature (120 °C pre-warning, 150 °C shutdown)."""
        self.world(f"temperature {float(celsius)}")

    def press_switch(self, axis: int, which: str) -> None:
        """Holds a switch (``"left"``, ``"right"`` or ``"home"``) pressed,
        wherever the carriage is."""
        self.world(f"switch {int(axis)} {_switch(which)} press")

    def release_switch(self, axis: int, which: str) -> None:
        """Holds a switch released, wherever the carriage is."""
        self.world(f"switch {int(axis)} {_switch(which)} release")

    def auto_switch(self, axis: int, which: str) -> None:
        """Gives a switch back to its position: pressed when the carriage is
        on it."""
        self.world(f"switch {int(axis)} {_switch(which)} auto")

    def place_switch(self, axis: int, which: str, position: float, width_or_to: Optional[float] = None) -> None:
        """Moves a switch: a stop switch to ``position`` (pressed for
        ``width`` beyond it, or to the end stop), the home switch to the
        range ``position``…``width_or_to``."""
        line = f"place {int(axis)} {_switch(which)} {position}"
        if width_or_to is not None:
            line += f" {width_or_to}"
        self.world(line)

    def set_travel(self, axis: int, low: float, high: float) -> None:
        """Moves the mechanical end stops."""
        self.world(f"travel {int(axis)} {low} {high}")

    def load(self, axis: int, torque: float, start: Optional[float] = None, end: Optional[float] = None) -> None:
        """Replaces the loads on an axis by one of ``torque`` % of the
        motor's rated torque (0 removes them), optionally only between the
        mechanical positions ``start`` and ``end``."""
        line = f"load {int(axis)} {float(torque)}"
        if start is not None or end is not None:
            if start is None or end is None:
                raise ValueError("a load range needs both start and end")
            line += f" {start} {end}"
        self.world(line)

    def fault(self, axis: int, which: str, on: bool = True) -> None:
        """Injects (or clears) a driver fault: ``"short-a"``, ``"short-b"``,
        ``"open-a"`` or ``"open-b"``."""
        self.world(f"fault {int(axis)} {which} {'on' if on else 'off'}")

    def show(self, axis: Optional[int] = None) -> str:
        """Time, position, carriage, speed and switch states, as text."""
        return self.world("show" if axis is None else f"show {int(axis)}")


class Module(_tmclsim.Module, WorldControls):
    __doc__ = _tmclsim.Module.__doc__


class Server(_tmclsim.Server, WorldControls):
    __doc__ = _tmclsim.Server.__doc__

    def __enter__(self) -> "Server":
        """Returns the server; it stops at the end of the ``with`` block."""
        return self

    def connect(self, via: Optional[str] = None, timeout: Optional[float] = None):
        """Opens a PyTrinamic connection to the served module (needs
        pytrinamic): over TCP (``via="tcp"``, the default when served on
        TCP) or the pty (``via="pty"``). Use it as a context manager, or
        close it with ``.close()``."""
        from pytrinamic.connections import ConnectionManager

        if via is None:
            via = "tcp" if self.tcp else "pty"
        if via == "tcp":
            args = self.pytrinamic_args if self.tcp else None
        elif via == "pty":
            args = self.pytrinamic_pty_args
        else:
            raise ValueError(f"via is 'tcp' or 'pty', not {via!r}")
        if args is None:
            raise ValueError(f"the server has no {via} endpoint")
        argv = args.split()
        if timeout is not None:
            argv += ["--timeout", str(timeout)]
        return ConnectionManager(argv).connect()


def serve(
    target: Union[_tmclsim.Module, Bus],
    tcp: Union[str, bool, None] = "127.0.0.1:0",
    pty: Union[str, "os.PathLike[str]", bool, None] = None,
    control: Union[str, bool, None] = True,
    stepped: bool = False,
    wire_timing: bool = False,
    speed: float = 1,
) -> Server:
    """Serves a module (or a bus of modules) in a background thread.

    - ``tcp``: the address to listen on (``"127.0.0.1:0"``: a free port);
      None for no TCP.
    - ``pty``: True for a pty behind a symlink in the temporary directory,
      a path for the symlink, None for no pty.
    - ``control``: the control socket (True: a free port on 127.0.0.1).
    - ``stepped``: virtual time moves only by ``server.advance(seconds)``
      instead of with the wall clock.
    - ``wire_timing``: replies take as long as their bytes at the module's
      baud rate (GP 65).
    - ``speed``: virtual time runs this many times as fast as the wall
      clock (0.001…100000); ``tmclsim.clock`` puts the host's own
      clocks on the same scale (docs/host-software.md).

    Returns a ``Server`` with the endpoints (``.tcp``, ``.pty``,
    ``.control``, ``.pytrinamic_args``), ``.connect()``, ``.world()``,
    ``.link_faults()``, ``.advance()``, ``.stepped`` and ``.stop()``; it is
    a context manager and stops when garbage collected. While served, the
    ``Module`` objects reach their modules through the server.
    """
    return Server(target, tcp=tcp, pty=pty, control=control, stepped=stepped, wire_timing=wire_timing, speed=speed)

