"""The pytest plugin: the tmcl_module fixture, its marker and indirect
parametrization, with PyTrinamic over TCP and the pty."""

from endpoints import port_open
import subprocess
import sys
import time

import pytest

pytest.importorskip("pytrinamic")
from pytrinamic.modules import TMCM1141  # noqa: E402


def test_the_fixture_serves_a_module_on_tcp_and_a_pty(tmcl_module):
    assert tmcl_module.tcp and tmcl_module.pty and tmcl_module.control
    assert not tmcl_module.stepped, "real time by default"
    assert tmcl_module.module.profile == "TMCM-1141"
    with tmcl_module.connect() as interface:
        TMCM1141(interface).move_to(0, 10000)
    with tmcl_module.connect(via="pty") as interface:
        deadline = time.monotonic() + 10
        while interface.get_axis_parameter(8, 0) != 1:  # position reached
            assert time.monotonic() < deadline, f"position not reached in 10 s: at {interface.get_axis_parameter(1, 0)}"
            time.sleep(0.01)  # the poll's interval
        assert interface.get_axis_parameter(1, 0) == 10000


@pytest.mark.tmcl_module(stepped=True, address=3, world="free")
def test_the_marker_chooses_the_options(tmcl_module):
    assert tmcl_module.stepped
    assert tmcl_module.module.address == 3
    with tmcl_module.connect() as interface:
        interface.send(1, 0, 0, 2047, module_id=3)  # ROR
        tmcl_module.advance(3600)
        # A free world has no switches: an hour of rotation.
        assert interface.get_axis_parameter(3, 0, module_id=3) == 2047
    assert tmcl_module.time == pytest.approx(3600, abs=0.01)


def test_a_test_can_switch_to_stepped_time(tmcl_module):
    with tmcl_module.connect() as interface:
        tmcm = TMCM1141(interface)
        tmcl_module.stepped = True
        tmcm.move_to(0, 30000)
        # about time: wall time passes, and in stepped time the module does
        # not move until the test advances it.
        time.sleep(0.05)
        assert tmcl_module.module.actual_position() == 0
        tmcl_module.advance(10)
        assert tmcm.motors[0].actual_position == 30000


@pytest.mark.parametrize("tmcl_module", ["tmcm-1141", {"address": 7, "stepped": True}], indirect=True)
def test_indirect_parametrization(tmcl_module):
    address = tmcl_module.module.address
    assert address in (1, 7)
    assert tmcl_module.stepped == (address == 7)
    assert tmcl_module.module.send("GGP 66, 0").value == address


def test_the_world_through_the_fixture(tmcl_module):
    from pytrinamic.tmcl import TMCLReplyChecksumError

    with tmcl_module.connect() as interface:
        tmcm = TMCM1141(interface)
        tmcl_module.set_input(1, True)
        assert tmcm.get_digital_input(1) == 1
        tmcl_module.link_faults(corrupt=1)
        with pytest.raises(TMCLReplyChecksumError):
            tmcm.get_digital_input(1)
        assert tmcm.get_digital_input(1) == 1
    # A dropped reply is a timeout for the host, as on a serial port.
    tmcl_module.link_faults(drop=1)
    with tmcl_module.connect(via="pty", timeout=0.3) as interface:
        with pytest.raises(RuntimeError, match="timed out"):
            interface.get_global_parameter(66, 0)
        assert interface.get_global_parameter(66, 0) == 1


INNER = """
import pathlib
import pytest

@pytest.mark.tmcl_module(stepped=True)
def test_inner(tmcl_module):
    pathlib.Path("endpoint.txt").write_text(tmcl_module.tcp)
    assert tmcl_module.stepped

@pytest.mark.parametrize("tmcl_module", ["tmcm-1141"], indirect=True)
def test_inner_param(tmcl_module):
    assert tmcl_module.module.profile == "TMCM-1141"
"""


def run_pytest(directory, *args):
    """Runs pytest in a fresh process in ``directory``: the plugin must come
    in by its entry point."""
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *args],
        cwd=directory, capture_output=True, text=True, timeout=120,
    )


def test_the_plugin_loads_by_entry_point_and_tears_down(tmp_path):
    (tmp_path / "test_inner.py").write_text(INNER)
    result = run_pytest(tmp_path, "-q", "--strict-markers")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 passed" in result.stdout
    address = (tmp_path / "endpoint.txt").read_text()
    assert not port_open(address), "the server stopped after the test"


def test_unknown_options_are_usage_errors(tmp_path):
    (tmp_path / "test_bad.py").write_text(
        "import pytest\n\n@pytest.mark.tmcl_module(pace=3)\ndef test_bad(tmcl_module):\n    pass\n"
    )
    result = run_pytest(tmp_path, "-q")
    assert result.returncode != 0
    assert "unknown option(s) pace" in result.stdout + result.stderr


def test_the_marker_is_registered(tmp_path):
    result = run_pytest(tmp_path, "--markers")
    assert "@pytest.mark.tmcl_module(profile=" in result.stdout
