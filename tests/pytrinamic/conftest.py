"""Fixtures: a `tmclsim serve` process on loopback TCP and a pty."""

import pathlib
import re
import subprocess
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from tmclsim_binary import ROOT, read_banner, stop, tmclsim_binary  # noqa: E402,F401


class Served:
    """A running `tmclsim serve`; stopped by the fixture."""

    def __init__(self, args, tmp_path):
        self.pty_link = str(tmp_path / "tmcm-1141")
        cmd = [tmclsim_binary(), "serve", "--tcp", "127.0.0.1:0", "--pty", self.pty_link, *args]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.banner = read_banner(self.proc)
        text = "".join(self.banner)
        self.tcp = re.search(r"tcp: (\S+)", text).group(1)
        control = re.search(r"control: (\S+)", text)
        self.control = control.group(1) if control else None
        self.connect_hint = self.banner[-1]

    def world(self, command):
        """Sends one line to the control socket; returns the answer."""
        import socket

        host, port = self.control.rsplit(":", 1)
        with socket.create_connection((host, int(port)), timeout=5) as s:
            s.sendall(command.encode() + b"\n")
            answer = s.makefile().readline().strip()
        assert answer.startswith("ok"), answer
        return answer

    def stop(self):
        stop(self.proc)


@pytest.fixture
def served(tmp_path):
    s = Served([], tmp_path)
    yield s
    s.stop()


@pytest.fixture
def serve(tmp_path):
    """Start servers with extra arguments; all are stopped at teardown."""
    started = []

    def start(*args):
        s = Served(list(args), tmp_path)
        started.append(s)
        return s

    yield start
    for s in started:
        s.stop()
