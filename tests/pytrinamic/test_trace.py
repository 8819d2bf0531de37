"""`tmclsim trace` with PyTrinamic: a PyTrinamic session with a served
TMCM-1141, recorded through `tmclsim trace record`, checks clean on a fresh
virtual module; one reply altered in the file is exactly one difference."""

import json
import re
import subprocess

import pytest
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141
from pytrinamic_links import wait_until
from tmclsim_binary import read_banner, stop, tmclsim_binary

GAP_4 = "01 06 04 00 00 00 00 00 0B"  # GAP 4, 0: maximum positioning speed


@pytest.fixture
def recording(served, tmp_path):
    """`tmclsim trace record` between a host and the served module: the
    address to connect to and the trace file; stopped by the fixture."""
    trace = tmp_path / "session.jsonl"
    cmd = [tmclsim_binary(), "trace", "record", "--listen", "127.0.0.1:0", "--tcp", served.tcp, "--out", str(trace)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    banner = read_banner(proc)
    listen = re.search(r"listen: (\S+)", "".join(banner)).group(1)
    yield proc, listen, trace
    stop(proc)


def check(trace, *args):
    done = subprocess.run(
        [tmclsim_binary(), "trace", "check", str(trace), "--module", "tmcm-1141", *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    return done.returncode, done.stdout + done.stderr


def alter_value(trace, line_number, value, out):
    """Writes the trace to `out` with the reply on `line_number` (1-based)
    carrying `value`, its checksum made right."""
    lines = trace.read_text().splitlines()
    entry = json.loads(lines[line_number - 1])
    frame = bytearray(bytes.fromhex(entry["frame"]))
    frame[4:8] = value.to_bytes(4, "big", signed=True)
    frame[8] = sum(frame[:8]) & 0xFF
    entry["frame"] = " ".join(f"{b:02X}" for b in frame)
    lines[line_number - 1] = json.dumps(entry)
    out.write_text("\n".join(lines) + "\n")


def test_a_pytrinamic_session_checks_clean_and_an_altered_reply_is_one_difference(recording, tmp_path):
    proc, listen, trace = recording
    with ConnectionManager(f"--interface socket_serial_tmcl --port {listen}".split()).connect() as interface:
        module = TMCM1141(interface)
        motor = module.motors[0]
        motor.linear_ramp.max_velocity = 1800
        motor.linear_ramp.max_acceleration = 1000
        assert motor.linear_ramp.max_velocity == 1800
        module.move_to(0, 25600)
        positions = []

        def arrived():
            positions.append(motor.actual_position)
            return motor.get_position_reached() == 1

        assert wait_until(arrived)
        assert any(0 < p < 25600 for p in positions), positions
        assert motor.actual_position == 25600
        assert interface.get_version_string() == "1141V146"
    stop(proc)
    assert proc.returncode == 0

    code, out = check(trace)
    assert code == 0, out
    assert "result: 0 differences, 0 not comparable" in out, out

    lines = trace.read_text().splitlines()
    reply = next(i for i, line in enumerate(lines) if GAP_4 in line) + 2
    assert json.loads(lines[reply - 1])["dir"] == "module"
    altered = tmp_path / "altered.jsonl"
    alter_value(trace, reply, 1000, altered)
    code, out = check(altered)
    assert code == 1, out
    assert "result: 1 difference, 0 not comparable" in out, out
    assert "GAP 4 (Maximum positioning speed), motor 0: 1 difference\n" in out, out
    assert f"  line {reply} (request on line {reply - 1} at " in out, out
    assert "value 1000\n    actual    02 01 64 06 00 00 07 08 " in out, out
