"""A virtual module on a real serial device (`tmclsim serve --serial`):
one end of a null-modem pair made by socat, PyTrinamic's serial_tmcl on
the other end, as host software that only opens serial ports would."""

import pathlib
import re
import shutil
import subprocess
import threading

import pytest
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141
from pytrinamic_links import wait_until
from tmclsim_binary import stop, tmclsim_binary

SOCAT = shutil.which("socat")
pytestmark = pytest.mark.skipif(SOCAT is None, reason="socat is not installed (scripts/test installs it as root)")


class NullModem:
    """A pair of ptys joined by socat: what one end writes, the other
    reads, as two serial ports joined by a null-modem cable."""

    def __init__(self, tmp_path: pathlib.Path):
        self.module_end = str(tmp_path / "module-end")
        self.host_end = str(tmp_path / "host-end")
        self.proc = None
        self.plug()

    def plug(self):
        ends = [f"pty,rawer,link={end}" for end in (self.module_end, self.host_end)]
        self.proc = subprocess.Popen([SOCAT, *ends], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        ends = (self.module_end, self.host_end)
        wait_until(lambda: all(pathlib.Path(e).exists() for e in ends), what="socat's two ends",
                   seen=lambda: {e: pathlib.Path(e).exists() for e in ends} | {"socat's exit status": self.proc.poll()})

    def unplug(self):
        """The cable is gone: both ptys vanish (as a USB adapter does)."""
        self.proc.terminate()
        self.proc.wait(timeout=10)
        wait_until(lambda: not pathlib.Path(self.module_end).exists(), what=f"socat's end {self.module_end} to be removed")

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


class Serving:
    """`tmclsim serve` with its output collected line by line."""

    def __init__(self, *args):
        cmd = [tmclsim_binary(), "serve", *args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()
        wait_until(lambda: any(line.startswith("connect with:") for line in self.lines) or self.proc.poll() is not None,
                   what="the banner", seen=self.text)
        assert self.proc.poll() is None, "".join(self.lines)

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line)

    def text(self):
        return "".join(self.lines)

    def wait_for(self, pattern):
        wait_until(lambda: re.search(pattern, self.text()), what=f"{pattern!r} in the output", seen=self.text)

    def stop(self):
        stop(self.proc)
        self.reader.join(timeout=10)


@pytest.fixture
def null_modem(tmp_path):
    pair = NullModem(tmp_path)
    yield pair
    pair.close()


@pytest.fixture
def serving():
    started = []

    def start(*args):
        s = Serving(*args)
        started.append(s)
        return s

    yield start
    for s in started:
        s.stop()


def connect(port, module_id=1, baud=9600):
    args = f"--interface serial_tmcl --port {port} --data-rate {baud} --module-id {module_id} --timeout 2"
    return ConnectionManager(args.split()).connect()


def test_pytrinamic_drives_a_module_on_the_other_end_of_the_line(null_modem, serving):
    served = serving("--serial", null_modem.module_end)
    # The rate of GP 65 = 0 (TMCM-1141 manual, GP 65: 9600 by default).
    assert f"serial: {null_modem.module_end} at 9600 baud" in served.text()
    assert "--interface serial_tmcl --port <the other end of" in served.text()
    with connect(null_modem.host_end) as interface:
        assert interface.get_version_string() == "1141V146"
        module = TMCM1141(interface)
        motor = module.motors[0]
        motor.linear_ramp.max_velocity = 2047
        motor.linear_ramp.max_acceleration = 2047
        assert motor.linear_ramp.max_velocity == 2047
        module.move_to(0, 20000)
        assert wait_until(lambda: motor.get_position_reached() == 1, seen=lambda: motor.actual_position)
        assert motor.actual_position == 20000


def test_a_bus_on_the_line_answers_by_address(null_modem, serving):
    serving("--bus", "tmcm-1141@1,tmcm-351@3", "--serial", null_modem.module_end, "--baud", "115200")
    with connect(null_modem.host_end, module_id=3, baud=115200) as interface:
        assert interface.get_version_string() == "351V.445"
    with connect(null_modem.host_end, module_id=1, baud=115200) as interface:
        assert interface.get_version_string() == "1141V146"


def test_a_vanished_device_is_served_again_when_it_is_back_and_tcp_goes_on(null_modem, serving):
    served = serving("--serial", null_modem.module_end, "--tcp", "127.0.0.1:0")
    tcp = re.search(r"tcp: (\S+)", served.text()).group(1)
    with connect(null_modem.host_end) as interface:
        TMCM1141(interface).motors[0].linear_ramp.max_velocity = 1000
    null_modem.unplug()
    served.wait_for(rf"serial {re.escape(null_modem.module_end)}: lost \(")
    # The other links go on while the device is gone.
    with ConnectionManager(f"--interface socket_serial_tmcl --port {tcp}".split()).connect() as interface:
        assert TMCM1141(interface).motors[0].linear_ramp.max_velocity == 1000
    assert served.proc.poll() is None
    null_modem.plug()
    served.wait_for(rf"serial {re.escape(null_modem.module_end)}: back")
    with connect(null_modem.host_end) as interface:
        # The same module: what was set before the device vanished is there.
        assert TMCM1141(interface).motors[0].linear_ramp.max_velocity == 1000


def test_a_device_that_cannot_be_opened_is_refused_at_start(tmp_path):
    missing = str(tmp_path / "no-such-device")
    done = subprocess.run([tmclsim_binary(), "serve", "--serial", missing], capture_output=True, text=True, timeout=60)
    assert done.returncode != 0
    assert f"cannot open the serial device {missing}" in done.stderr
