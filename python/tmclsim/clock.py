"""The host's clocks at a served module's speed.

A module served with ``tmclsim serve --speed N`` lives N times as fast as
the wall clock. This module puts an unmodified Python program on the same
scale: from the moment of :func:`install`, the program's clocks read

    virtual time = reading at install + (wall time since install) × N

and its waits with a timeout last timeout / N of wall time::

    python -m tmclsim.clock --speed 50 homing.py --port 127.0.0.1:1141
    python -m tmclsim.clock --speed 50 -m mypackage.main ARGS…

or in process::

    from tmclsim import clock

    with clock.scaled(50):
        time.sleep(60)          # a minute of virtual time, 1.2 s of wall time

Scaled, process-wide (every thread, including threads started before):

- ``time.monotonic``, ``time.perf_counter``, ``time.time`` and their
  ``_ns`` forms; ``time.sleep``.
- ``select.select`` (a select used as a sleep, or a loop's timeout) and the
  ``select`` method of every ``selectors`` class.
- ``threading``: ``Condition.wait`` and so ``Event.wait``,
  ``Semaphore.acquire``, ``Barrier.wait`` and ``Timer``; ``Thread.join``.
  ``queue.Queue.get/put`` and ``Condition.wait_for`` compute deadlines with
  the module-level copies ``queue.time`` and ``threading._time`` of
  ``time.monotonic``, taken when those modules were imported: the copies in
  ``threading``, ``queue``, ``subprocess``, ``socketserver`` and
  ``telnetlib`` are rebound at install too.
- asyncio: the loop's ``time()`` reads ``time.monotonic`` and the loop
  waits in its selector (on Windows, the proactor's ``select``, scaled as
  well), so ``asyncio.sleep``, ``call_later`` and ``wait_for`` run on the
  scaled clock.

On the wall clock, on purpose:

- pyserial: a module's reply takes wall time however fast its virtual time
  runs, so a serial port's read and write timeouts stay what they say. The
  scaled functions answer calls coming from the ``serial`` package (the
  caller's module name is ``serial`` or ``serial.…``) with the real ones:
  ``serial.serialutil.Timeout`` reads ``time.monotonic`` (through a class
  attribute copy, taken whenever pyserial was imported) and the POSIX port
  waits in ``select.select``; both stay wall, whatever the import order.
  (The Windows port waits inside the operating system and is untouched.)
- Socket timeouts (``settimeout``, ``create_connection(timeout=…)``): they
  are the socket's own, in C.

Not scaled, because they read the system's clocks from C:
``datetime.datetime.now()`` and ``date.today()``, ``time.localtime()``,
``gmtime()``, ``ctime()`` and ``strftime()`` without an argument,
``time.clock_gettime``, the CPU clocks (``process_time``, ``thread_time``),
C extensions' own clocks and waits (uvloop, numpy, the simulator itself),
``Lock.acquire(timeout=…)`` and ``RLock`` (C locks), ``queue.SimpleQueue``,
``select.poll``/``epoll``/``kqueue`` objects used directly, multiprocessing's
locks, and ``signal.alarm``/``setitimer``. Nor are functions that a module
copied before install (``from time import sleep``, ``def f(clock=
time.monotonic)``), apart from the standard library's copies above: install
before importing the host code, as ``python -m tmclsim.clock`` does. A copy
taken while installed keeps working and reads the real clock again after
:func:`uninstall`. A wait already under way at install or uninstall keeps
the length it started with. At high speeds the operating system's wait
resolution (about a millisecond for ``poll`` and ``epoll``, more on
Windows) becomes N milliseconds of virtual time. A child process is on the
wall clock unless it installs the clock itself (:func:`install_from_environment`
from a ``sitecustomize`` module, or ``python -m tmclsim.clock``); a forked
child inherits the patch.

Installing twice changes the speed: virtual time goes on from its current
reading at the new pace, so the clocks never jump. :func:`uninstall` puts
the original functions back (the very same objects) and is a no-op when
the clock is not installed; the clocks then read real time again, which
is behind the virtual readings. :func:`scaled` nests: it gives back the
speed (or the real clocks) it found.

Why not a library: ``time-machine`` and ``freezegun`` move or freeze the
clock (time-machine's ``tick`` lets it run, at the wall clock's pace) but
cannot change its rate, and leave ``time.sleep`` and the threading waits
real. ``libfaketime`` (through ``python-libfaketime``) can speed the clock
up (``FAKETIME="+0 x50"``) but works by LD_PRELOAD, so not on Windows, needs
the interpreter re-executed, and acts on the C library's calls for the
whole process, so pyserial's waits could not stay on the wall clock. This module is a small,
standard-library-only patch that does exactly the above.
"""

import contextlib
import functools
import importlib.util
import math
import numbers
import os
import runpy
import select
import selectors  # imported before any install: SelectSelector keeps the real select.select
import sys
import threading
import time
from typing import Any, Callable, Dict, Iterator, List, Mapping, NoReturn, Optional, Tuple

__all__ = [
    "ENVIRONMENT_VARIABLE",
    "install",
    "install_from_environment",
    "installed_speed",
    "main",
    "real_monotonic",
    "real_monotonic_ns",
    "real_perf_counter",
    "real_perf_counter_ns",
    "real_select",
    "real_sleep",
    "real_time",
    "real_time_ns",
    "scaled",
    "uninstall",
]

# The real functions, as they were when this module was imported.
real_monotonic = time.monotonic
real_monotonic_ns = time.monotonic_ns
real_perf_counter = time.perf_counter
real_perf_counter_ns = time.perf_counter_ns
real_time = time.time
real_time_ns = time.time_ns
real_sleep = time.sleep
real_select = select.select

ENVIRONMENT_VARIABLE = "TMCLSIM_CLOCK_SPEED"

_CLOCKS: Dict[str, Callable[[], Any]] = {
    "monotonic": real_monotonic,
    "monotonic_ns": real_monotonic_ns,
    "perf_counter": real_perf_counter,
    "perf_counter_ns": real_perf_counter_ns,
    "time": real_time,
    "time_ns": real_time_ns,
}

# Packages whose calls get the real functions: their waits are on the wall
# clock on purpose (module docstring).
_WALL_PACKAGES = ("serial",)

# The standard library's module-level copies of time.monotonic (`from time
# import monotonic as _time`), taken when the module is imported.
_COPIES = (
    ("threading", "_time"),
    ("queue", "time"),
    ("subprocess", "_time"),
    ("socketserver", "time"),
    ("telnetlib", "_time"),
)


class _Scale:
    """One installation: the speed and, for each clock, the real and the
    virtual reading virtual time counts from."""

    def __init__(self, speed: float, previous: Optional["_Scale"]):
        self.speed = speed
        self.origins = {}
        for name, real in _CLOCKS.items():
            now = real()
            self.origins[name] = (now, now if previous is None else previous.read(name, now))

    def read(self, name: str, real_now):
        """The virtual reading of clock `name` when it reads `real_now`."""
        real_origin, virtual_origin = self.origins[name]
        elapsed = (real_now - real_origin) * self.speed
        return virtual_origin + (int(elapsed) if isinstance(real_origin, int) else elapsed)


_state: Optional[_Scale] = None
_lock = threading.Lock()
# The methods wrapped at install, with the functions to put back.
_wrapped_methods: List[Tuple[type, str, Any]] = []


def _wall(seconds, speed: float):
    """The wall-clock length of a wait of `seconds` virtual seconds. None
    (no timeout) and values the real function refuses pass unchanged, so
    that it answers them as always."""
    try:
        return seconds / speed
    except TypeError:
        return seconds


class _Patched:
    """The stand-in for one function of ``time`` or ``select``. Not a
    descriptor, like the built-in it stands for: a copy kept as a class
    attribute (pyserial's ``Timeout.TIME = time.monotonic``) is called
    without ``self``."""

    def __init__(self, real: Callable, scaled: Callable, wall_callers: Tuple[str, ...]):
        functools.update_wrapper(self, real)
        self._scaled = scaled
        self._wall_callers = wall_callers

    def __call__(self, *args, **kwargs):
        state = _state
        if state is None or self._called_from_wall_caller():
            return self.__wrapped__(*args, **kwargs)
        return self._scaled(state, *args, **kwargs)

    def _called_from_wall_caller(self) -> bool:
        # Frame 0 is this method, 1 is __call__, 2 is the caller.
        caller = sys._getframe(2).f_globals.get("__name__") or ""
        return any(caller == p or caller.startswith(p + ".") for p in self._wall_callers)

    def __repr__(self) -> str:
        return f"<{self.__wrapped__.__name__} on tmclsim.clock's scaled clock>"


def _clock(name: str) -> _Patched:
    real = _CLOCKS[name]
    return _Patched(real, lambda state: state.read(name, real()), _WALL_PACKAGES)


def _scaled_sleep(state: _Scale, seconds):
    return real_sleep(_wall(seconds, state.speed))


def _scaled_select(state: _Scale, rlist, wlist, xlist, timeout=None):
    return real_select(rlist, wlist, xlist, _wall(timeout, state.speed))


# The stand-ins, by (module, name). selectors' own calls of select.select
# are real: the selector classes scale their timeouts themselves.
_PATCHED: Dict[Tuple[Any, str], _Patched] = {
    **{(time, name): _clock(name) for name in _CLOCKS},
    (time, "sleep"): _Patched(real_sleep, _scaled_sleep, _WALL_PACKAGES),
    (select, "select"): _Patched(real_select, _scaled_select, _WALL_PACKAGES + ("selectors",)),
}


def _timeout_method(real: Callable) -> Callable:
    """A method ``(self, timeout=None)`` whose timeout is virtual."""

    @functools.wraps(real)
    def method(self, timeout=None):
        state = _state
        return real(self, timeout if state is None else _wall(timeout, state.speed))

    return method


def _classes_with_timeouts() -> List[type]:
    """The classes whose ``select``, ``wait`` or ``join`` method waits
    with a timeout in their own body."""
    classes = [threading.Condition, threading.Thread]
    for c in vars(selectors).values():  # DefaultSelector names one of them again
        if (
            isinstance(c, type)
            and issubclass(c, selectors.BaseSelector)
            and "select" in vars(c)
            and not getattr(vars(c)["select"], "__isabstractmethod__", False)
            and c not in classes
        ):
            classes.append(c)
    if sys.platform == "win32":
        # The proactor event loop waits in IocpProactor.select, not in a selector.
        from asyncio import windows_events

        classes.append(windows_events.IocpProactor)
    return classes


def _patch() -> None:
    for (module, name), patched in _PATCHED.items():
        if getattr(module, name) is patched.__wrapped__:
            setattr(module, name, patched)
    for module_name, name in _COPIES:
        module = sys.modules.get(module_name)
        if module is not None and vars(module).get(name) is real_monotonic:
            setattr(module, name, _PATCHED[time, "monotonic"])
    for cls in _classes_with_timeouts():
        for name in ("select", "wait", "join"):
            if name in vars(cls):
                original = vars(cls)[name]
                _wrapped_methods.append((cls, name, original))
                setattr(cls, name, _timeout_method(original))


def _unpatch() -> None:
    while _wrapped_methods:
        cls, name, original = _wrapped_methods.pop()
        setattr(cls, name, original)
    for module_name, name in _COPIES:
        module = sys.modules.get(module_name)
        copy = None if module is None else vars(module).get(name)
        if isinstance(copy, _Patched):
            setattr(module, name, copy.__wrapped__)
    for (module, name), patched in _PATCHED.items():
        if getattr(module, name) is patched:
            setattr(module, name, patched.__wrapped__)


#: The speeds a clock takes: the range `tmclsim serve --speed` and
#: ``tmclsim.serve(speed=…)`` take, so that a host's clock can match every
#: served module's and no other.
MIN_SPEED = 0.001
MAX_SPEED = 100_000


def _check_speed(speed) -> float:
    if isinstance(speed, numbers.Real) and not isinstance(speed, bool):
        try:
            value = float(speed)
        except OverflowError:
            value = math.inf
        if math.isfinite(value) and value > 0:
            if not MIN_SPEED <= value <= MAX_SPEED:
                raise ValueError(f"the clock speed {speed!r} is outside {MIN_SPEED}…{MAX_SPEED} (1 = the wall clock's pace)")
            return value
    raise ValueError(f"the clock speed must be a positive finite number (1 = the wall clock's pace), not {speed!r}")


def install(speed: float) -> None:
    """Runs the process's clocks ``speed`` times as fast as the wall
    clock (module docstring). ``speed`` is a positive finite number
    (``ValueError`` otherwise); installing again changes the speed, with
    virtual time going on from its current reading."""
    speed = _check_speed(speed)
    global _state
    with _lock:
        if _state is None:
            _patch()
        _state = _Scale(speed, _state)


def uninstall() -> None:
    """Puts the real clocks back (the original functions themselves); a
    no-op when the clock is not installed."""
    global _state
    with _lock:
        if _state is not None:
            _state = None
            _unpatch()


def installed_speed() -> Optional[float]:
    """The installed speed, or None when the clocks are the real ones."""
    state = _state
    return None if state is None else state.speed


@contextlib.contextmanager
def scaled(speed: float) -> Iterator[None]:
    """Installs the clock at ``speed`` for a ``with`` block, then gives
    back the speed, or the real clocks, found on entry."""
    previous = installed_speed()
    install(speed)
    try:
        yield
    finally:
        if previous is None:
            uninstall()
        else:
            install(previous)


def install_from_environment(environ: Mapping[str, str] = os.environ) -> Optional[float]:
    """Installs the clock at the speed that ``TMCLSIM_CLOCK_SPEED`` names,
    when it is set and not empty, and returns that speed (None when it is
    not set): for a launcher that cannot start its Python child with
    ``-m tmclsim.clock`` (call it from the child's ``sitecustomize``)."""
    text = environ.get(ENVIRONMENT_VARIABLE, "").strip()
    if not text:
        return None
    try:
        speed = _check_speed(float(text))
    except ValueError:
        raise ValueError(f"{ENVIRONMENT_VARIABLE}={text!r}: the clock speed must be a number from {MIN_SPEED} to {MAX_SPEED}") from None
    install(speed)
    return speed


_PROG = "python -m tmclsim.clock"
_USAGE = f"usage: {_PROG} --speed N (SCRIPT | -m MODULE) [ARGS ...]"
_HELP = f"""{_USAGE}

Runs a Python program with its clocks N times as fast as the wall clock,
for modules served with `tmclsim serve --speed N`: time.sleep, time.monotonic,
time.time, the threading, queue, select and asyncio timeouts are scaled;
pyserial's and sockets' timeouts stay on the wall clock.

  --speed N    virtual seconds per wall-clock second (0.001 to 100000)
  SCRIPT       a Python file, run as `python SCRIPT ARGS` would
  -m MODULE    a module, run as `python -m MODULE ARGS` would
"""


def _usage_error(message: str) -> NoReturn:
    print(f"{_USAGE}\n{_PROG}: error: {message}", file=sys.stderr)
    raise SystemExit(2)


def _parse(argv: List[str]) -> Tuple[float, Optional[str], List[str]]:
    """(speed, MODULE or None for a script, [SCRIPT or MODULE, ARGS…])."""
    speed = None
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg in ("-h", "--help"):
            print(_HELP, end="")
            raise SystemExit(0)
        if arg == "--speed" or arg.startswith("--speed="):
            if arg == "--speed":
                if i + 1 == len(argv):
                    _usage_error("--speed needs a number")
                text, i = argv[i + 1], i + 2
            else:
                text, i = arg[len("--speed=") :], i + 1
            try:
                speed = _check_speed(float(text))
            except ValueError:
                _usage_error(f"--speed must be a number from {MIN_SPEED} to {MAX_SPEED}, not {text!r}")
            continue
        if speed is None:
            _usage_error("--speed N is required, before the program")
        if arg == "-m":
            if i + 1 == len(argv):
                _usage_error("-m needs a module name")
            return speed, argv[i + 1], argv[i + 1 :]
        if arg.startswith("-"):
            _usage_error(
                f"unknown option {arg!r}: name a SCRIPT or -m MODULE (interpreter options go before -m tmclsim.clock)"
            )
        return speed, None, argv[i:]
    if speed is None:
        _usage_error("--speed N is required")
    _usage_error("name the program: a SCRIPT or -m MODULE")


def main(argv: Optional[List[str]] = None) -> None:
    """``python -m tmclsim.clock --speed N (SCRIPT | -m MODULE) [ARGS…]``:
    installs the clock, then runs the program as ``__main__`` with
    ``sys.argv = [SCRIPT or MODULE, ARGS…]``."""
    speed, module, program_argv = _parse(sys.argv[1:] if argv is None else argv)
    if module is None and not os.path.exists(program_argv[0]):
        _usage_error(f"can't open file {program_argv[0]!r}: no such file or directory")
    install(speed)
    sys.argv = program_argv
    if module is not None:
        # Looked up after install: importing its package may start clocks.
        try:
            found = importlib.util.find_spec(module) is not None
        except (ImportError, ValueError) as e:
            _usage_error(f"can't find module {module!r}: {e}")
        if not found:
            _usage_error(f"no module named {module!r}")
        # runpy sets sys.argv[0] to the module's file; sys.path[0] stays the
        # working directory, as for `python -m MODULE`.
        runpy.run_module(module, run_name="__main__", alter_sys=True)
        return
    if not getattr(sys.flags, "safe_path", False):
        # As `python SCRIPT`: the script's directory first on the path,
        # where `python -m` put the working directory.
        sys.path[0] = os.path.dirname(os.path.abspath(program_argv[0]))
    runpy.run_path(program_argv[0], run_name="__main__")


if __name__ == "__main__":
    # `python -m` runs a copy of this file as __main__; the program's
    # `import tmclsim.clock` must find the installed clock, so run the
    # package's module.
    from tmclsim.clock import main as _main

    _main()
