"""PyTrinamic's firmware update tool (`tmclfwupload`, from the package
installed from the registry, run as it is) against a served TMCM-1141's
bootloader (docs/behaviour.md rules 99-103): a complete update over TCP
and over the pty, one killed after the erase and recovered, and the images
the tool refuses."""

import os
import pathlib
import re
import subprocess
import sys
import time

import pytest
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141
from pytrinamic.tmcl import TMCLReplyStatusError
from tmclsim_binary import tmclsim_binary

TOOL = pathlib.Path(sys.executable).parent / "tmclfwupload"


def image(tmp_path, module="tmcm-1141", version="1.47"):
    out = tmp_path / f"{module}-{version}.hex"
    subprocess.run([tmclsim_binary(), "firmware", "image", "--module", module, "--version", version, "-o", str(out)], check=True, capture_output=True)
    return out


def link_args(served, link):
    if link == "tcp":
        return ["--interface", "socket_serial_tmcl", "--port", served.tcp]
    return ["--interface", "serial_tmcl", "--port", served.pty_link]


def update(hex_file, args, timeout=300):
    """Runs the tool to its end; its exit code and output."""
    done = subprocess.run([str(TOOL), str(hex_file), *args], capture_output=True, text=True, timeout=timeout)
    return done.returncode, done.stdout + done.stderr


def version(served, module_id=1):
    args = f"--interface socket_serial_tmcl --port {served.tcp} --module-id {module_id}"
    with ConnectionManager(args.split()).connect() as interface:
        return interface.get_version_string()


@pytest.mark.parametrize("link", ["tcp", "pty"])
def test_a_complete_update_runs_the_images_version(serve, tmp_path, link):
    served = serve("--eeprom", str(tmp_path / "m.eeprom"))
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}".split()).connect() as interface:
        module = TMCM1141(interface)
        module.set_axis_parameter(module.motors[0].AP.MaxVelocity, 0, 777)
        interface.send(7, 4, 0, 0)  # STAP 4, 0
    code, out = update(image(tmp_path), link_args(served, link))
    assert code == 0, out
    assert "Switching to bootloader mode" in out
    assert "Bootloader version: 1141B106" in out
    assert "Firmware version:   1141V147" in out
    assert "Checksum of the uploaded firmware matches" in out
    assert version(served) == "1141V147"
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}".split()).connect() as interface:
        # The EEPROM outlives the update (rule 102).
        assert TMCM1141(interface).get_axis_parameter(4, 0) == 777


def test_an_update_killed_after_the_erase_leaves_the_bootloader_and_a_second_run_recovers(serve, tmp_path):
    eeprom = tmp_path / "m.eeprom"
    served = serve("--eeprom", str(eeprom))
    hex_file = image(tmp_path, version="1.48")
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    tool = subprocess.Popen([str(TOOL), str(hex_file), *link_args(served, "pty")], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    seen = []
    for line in tool.stdout:
        seen.append(line)
        if line.startswith("Writing page"):
            break
    tool.kill()
    tool.wait()
    tool.stdout.close()
    assert "Erasing the old firmware\n" in seen, "".join(seen)
    # Power off and on (the control socket): the bootloader stays, at address 1.
    served.world("power cycle")
    assert version(served) == "1141B106"
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}".split()).connect() as interface:
        with pytest.raises(TMCLReplyStatusError) as err:
            TMCM1141(interface).get_axis_parameter(1, 0)
        assert err.value.reply.status == 2
    # The server restarted with the same EEPROM file: still the bootloader.
    served.stop()
    again = serve("--eeprom", str(eeprom))
    assert any("is in its bootloader (1141B106, at address 1)" in line for line in again.banner), again.banner
    code, out = update(hex_file, link_args(again, "tcp"))
    assert code == 0, out
    assert "Switching to bootloader mode" not in out, "the tool found the module in its bootloader"
    assert version(again) == "1141V148"


def test_the_images_the_tool_refuses_leave_the_firmware_as_it_was(serve, tmp_path):
    served = serve()
    code, out = update(image(tmp_path, module="tmcm-351", version="4.45"), link_args(served, "tcp"))
    assert code == 1, out
    assert "Error: No matching version string found in firmware image" in out
    # The tool switched to the bootloader first; nothing was erased, so
    # a power cycle starts the firmware again.
    assert version(served) == "1141B106"
    served.world("power cycle")
    assert version(served) == "1141V146"

    # An image that starts elsewhere than the bootloader's flash.
    text = image(tmp_path).read_text()
    moved = tmp_path / "moved.hex"
    moved.write_text(text.replace(":020000040800F2", ":020000040801F1", 1))
    code, out = update(moved, link_args(served, "tcp"))
    assert code == 1, out
    assert re.search(r"Error: Start address of firmware \(0x08014000\) does not match start address of bootloader \(0x08004000\)", out), out
