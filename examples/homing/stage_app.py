"""A small host application for a TMCM-1141 driving a linear stage.

It homes the axis against the stage's home switch (reference search mode 8:
the home switch in the positive direction, zero at the middle of the
switch), then runs a move sequence, reporting where each move ended. It
talks to the module through PyTrinamic, so the same code drives a real
module on a serial port or a virtual one served by tmclsim:

    python stage_app.py --interface serial_tmcl --port /dev/ttyACM0
    python stage_app.py --interface socket_serial_tmcl --port 127.0.0.1:1141 \\
        --sequence 10000,-50000,200000,0

It waits as host code does, with ``time.sleep`` and ``time.monotonic``:
its tests run it unchanged against modules served with a speed (an hour of
motion in seconds), with tmclsim's clock patch putting those calls on the
modules' time (see test_stage_app.py).
"""

import argparse
import sys
import time

from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141

RFS_START, RFS_STOP, RFS_STATUS = 0, 1, 2
RFS = 13  # TMCL opcode of the reference search


class HomingError(RuntimeError):
    """The reference search did not finish in time."""


class MoveError(RuntimeError):
    """A move did not reach its target in time."""


class StageApp:
    """Homing and moves of one axis of a TMCM-1141."""

    #: Reference search mode 8: the home switch, searched in the positive
    #: direction; the reference point is the middle of the switch.
    HOME_MODE = 8

    def __init__(self, interface, axis=0, search_speed=2047, switch_speed=500, max_speed=2047, poll=0.01):
        self.interface = interface
        self.axis = axis
        self.module = TMCM1141(interface)
        self.motor = self.module.motors[axis]
        self.search_speed = search_speed
        self.switch_speed = switch_speed
        self.max_speed = max_speed
        self.poll = poll

    def _wait(self, done, timeout):
        """Polls ``done()`` every ``poll`` seconds; False after ``timeout``."""
        deadline = time.monotonic() + timeout
        while not done():
            if time.monotonic() >= deadline:
                return False
            time.sleep(self.poll)
        return True

    def home(self, timeout=30.0):
        """Runs the reference search; afterwards position 0 is the middle of
        the home switch. Returns where the position counter stood at the
        reference point before (AP 197). Raises ``HomingError`` on timeout,
        after stopping the search."""
        ap = self.motor.AP
        self.motor.set_axis_parameter(ap.ReferenceSearchMode, self.HOME_MODE)
        self.motor.set_axis_parameter(ap.ReferenceSearchSpeed, self.search_speed)
        self.motor.set_axis_parameter(ap.ReferenceSwitchSpeed, self.switch_speed)
        self.interface.send(RFS, RFS_START, self.axis, 0)
        finished = self._wait(lambda: self.interface.send(RFS, RFS_STATUS, self.axis, 0).value == 0, timeout)
        if not finished:
            self.interface.send(RFS, RFS_STOP, self.axis, 0)
            raise HomingError(f"the reference search did not finish within {timeout} s (is the home switch working?)")
        if self.motor.actual_position != 0:
            raise HomingError(f"after homing the position is {self.motor.actual_position}, not 0")
        return self.motor.get_axis_parameter(ap.LastReferenceSwitchPosition, signed=True)

    def move_to(self, position, timeout=30.0):
        """Moves to an absolute position and waits until it is reached;
        returns the actual position."""
        self.motor.linear_ramp.max_velocity = self.max_speed
        self.module.move_to(self.axis, position)
        if not self._wait(self.motor.get_position_reached, timeout):
            self.module.stop(self.axis)
            raise MoveError(f"the move to {position} did not finish within {timeout} s")
        return self.motor.actual_position

    def run_sequence(self, positions, dwell=0.0, timeout=30.0):
        """Moves to each position in turn, pausing ``dwell`` seconds at
        each; returns the positions reached."""
        reached = []
        for p in positions:
            reached.append(self.move_to(p, timeout))
            if dwell:
                time.sleep(dwell)
        return reached


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sequence", default="10000,-50000,200000,0",
                        help="comma-separated target positions after homing (microsteps)")
    parser.add_argument("--axis", type=int, default=0)
    args, connection = parser.parse_known_args(argv)
    positions = [int(p) for p in args.sequence.split(",") if p.strip()]
    with ConnectionManager(connection).connect() as interface:
        app = StageApp(interface, axis=args.axis)
        before = app.home()
        print(f"homed: the reference point was at {before}")
        for target, reached in zip(positions, app.run_sequence(positions)):
            print(f"moved to {target}: at {reached}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
