"""The pytest plugin of tmclsim (registered by entry point: installing the
package is enough).

It provides the ``tmcl_module`` fixture: a virtual TMCL module served on
loopback TCP and a pty for the length of one test, with its control socket.
Options come from the ``tmcl_module`` marker or from indirect
parametrization::

    @pytest.mark.tmcl_module(profile="tmcm-1141", world="free", stepped=True)
    def test_something(tmcl_module):
        with tmcl_module.connect() as interface:   # PyTrinamic
            ...
        tmcl_module.advance(3600)                  # stepped virtual time

    @pytest.mark.parametrize("tmcl_module", [{"address": 3}], indirect=True)
    def test_other(tmcl_module): ...

    @pytest.mark.tmcl_module(speed=50)             # virtual time 50 × the wall clock
    def test_homing(tmcl_module):
        ...   # time.sleep, time.monotonic, threading waits: on the same scale

With ``speed=N`` the module's virtual time runs N times as fast as the wall
clock and the test body (and the code it calls, threads included) runs on
the same clock: ``tmclsim.clock`` is installed for the test. The
``tmcl_clock`` fixture does only the latter, for tests that serve modules
themselves::

    @pytest.mark.tmcl_clock(speed=50)
    def test_my_servers(tmcl_clock):          # tmcl_clock: the speed
        with tmclsim.serve(module, speed=tmcl_clock) as server: ...

The fixture's value is a ``tmclsim.Server``: ``.tcp``, ``.pty``,
``.control``, ``.pytrinamic_args``, ``.connect()``, ``.world(line)`` and the
world methods (``press_switch``, ``set_input``, ``load``…), ``.link_faults()``,
``.stepped`` (settable during the test), ``.advance(seconds)``, ``.time``,
and ``.module`` for the module itself.
"""

import contextlib

import pytest

import tmclsim
from tmclsim import clock

#: What the marker and indirect parameters may set, with the defaults.
DEFAULTS = {
    "profile": "tmcm-1141",
    "address": None,
    "world": None,
    "eeprom": None,
    "stepped": False,
    "tcp": "127.0.0.1:0",
    "pty": True,
    "wire_timing": False,
    "speed": 1,
}

MARKER = (
    "tmcl_module(profile='tmcm-1141', address=None, world=None, eeprom=None, stepped=False, "
    "tcp='127.0.0.1:0', pty=True, wire_timing=False, speed=1): options of the tmcl_module fixture "
    "(a virtual TMCL module served by tmclsim; speed N: its time and the test's clocks N times as fast)"
)

CLOCK_MARKER = "tmcl_clock(speed): the speed of the tmcl_clock fixture (the test's clocks that many times as fast)"


def pytest_configure(config):
    config.addinivalue_line("markers", MARKER)
    config.addinivalue_line("markers", CLOCK_MARKER)


@contextlib.contextmanager
def _clock_at(speed):
    """The process's clocks at ``speed`` for the block (nothing at 1)."""
    if speed == 1:
        yield
    else:
        with clock.scaled(speed):
            yield


def fixture_options(request):
    """The fixture's options: defaults, then the closest marker, then an
    indirect parameter (a profile name or a dict of options)."""
    options = dict(DEFAULTS)
    marker = request.node.get_closest_marker("tmcl_module")
    if marker is not None:
        if marker.args:
            options["profile"] = marker.args[0]
        options.update(marker.kwargs)
    param = getattr(request, "param", None)
    if param is not None:
        options.update(param if isinstance(param, dict) else {"profile": param})
    unknown = sorted(set(options) - set(DEFAULTS))
    if unknown:
        raise pytest.UsageError(f"tmcl_module: unknown option(s) {', '.join(unknown)}; known: {', '.join(DEFAULTS)}")
    return options


@pytest.fixture
def tmcl_module(request):
    """A virtual TMCL module served on loopback TCP and a pty, stopped after
    the test (a ``tmclsim.Server``). Real-time by default; options from the
    ``tmcl_module`` marker or indirect parametrization."""
    o = fixture_options(request)
    module = tmclsim.Module(profile=o["profile"], address=o["address"], eeprom=o["eeprom"], world=o["world"])
    server = tmclsim.serve(
        module, tcp=o["tcp"], pty=o["pty"], control=True, stepped=o["stepped"], wire_timing=o["wire_timing"], speed=o["speed"]
    )
    try:
        with _clock_at(o["speed"]):
            yield server
    finally:
        server.stop()


@pytest.fixture
def tmcl_clock(request):
    """The test's clocks (``time.sleep``, ``time.monotonic``, threading
    waits, asyncio, … as ``tmclsim.clock`` scales them) run N times as fast
    as the wall clock, N from the ``tmcl_clock`` marker or an indirect
    parameter; the fixture's value is N. For tests that serve modules
    themselves with ``tmclsim.serve(..., speed=N)``."""
    marker = request.node.get_closest_marker("tmcl_clock")
    speed = getattr(request, "param", None)
    if speed is None and marker is not None:
        speed = marker.kwargs.get("speed", marker.args[0] if marker.args else None)
    if speed is None:
        raise pytest.UsageError("tmcl_clock: give the speed, e.g. @pytest.mark.tmcl_clock(speed=50)")
    with clock.scaled(speed):
        yield speed
