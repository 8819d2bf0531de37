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

The fixture's value is a ``tmclsim.Server``: ``.tcp``, ``.pty``,
``.control``, ``.pytrinamic_args``, ``.connect()``, ``.world(line)`` and the
world methods (``press_switch``, ``set_input``, ``load``…), ``.link_faults()``,
``.stepped`` (settable during the test), ``.advance(seconds)``, ``.time``,
and ``.module`` for the module itself.
"""

import pytest

import tmclsim

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
}

MARKER = (
    "tmcl_module(profile='tmcm-1141', address=None, world=None, eeprom=None, stepped=False, "
    "tcp='127.0.0.1:0', pty=True, wire_timing=False): options of the tmcl_module fixture "
    "(a virtual TMCL module served by tmclsim)"
)


def pytest_configure(config):
    config.addinivalue_line("markers", MARKER)


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
    server = tmclsim.serve(module, tcp=o["tcp"], pty=o["pty"], control=True, stepped=o["stepped"], wire_timing=o["wire_timing"])
    try:
        yield server
    finally:
        server.stop()
