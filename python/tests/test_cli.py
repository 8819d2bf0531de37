"""The package's `tmclsim` command: the same program as the Rust binary,
installed with the wheel as a console script and as `python -m tmclsim`."""

import os
import pathlib
import subprocess
import sys

import pytest


def scripts_dir():
    return pathlib.Path(sys.executable).parent


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=60, **kw)


@pytest.mark.parametrize("how", ["script", "module"])
def test_the_command_comes_with_the_package(how):
    cmd = [str(scripts_dir() / "tmclsim")] if how == "script" else [sys.executable, "-m", "tmclsim"]
    if how == "script" and not os.path.exists(cmd[0]):
        pytest.fail(f"pip installed no tmclsim script next to {sys.executable}")
    version = run(cmd + ["--version"])
    assert version.returncode == 0, version.stderr
    assert version.stdout.startswith("tmclsim 0.1.0 (git "), version.stdout
    profile = run(cmd + ["profile", "tmcm-1141"])
    assert profile.returncode == 0, profile.stderr
    assert profile.stdout.startswith("TMCM-1141: 1 axis(es)"), profile.stdout[:200]


def test_exit_statuses_are_the_commands(tmp_path):
    cmd = [sys.executable, "-m", "tmclsim"]
    assert run(cmd + ["no-such-command"]).returncode == 2, "a usage error"
    bad = tmp_path / "bad.tmc"
    bad.write_text("JA Nowhere\n")
    r = run(cmd + ["asm", str(bad)])
    assert r.returncode == 2 and "bad.tmc:1:4" in r.stderr, r.stderr
    good = tmp_path / "good.tmc"
    good.write_text("ROR 0, 500\nSTOP\n")
    r = run(cmd + ["asm", str(good)])
    assert r.returncode == 0 and (tmp_path / "good.bin").stat().st_size == 16, r.stderr
