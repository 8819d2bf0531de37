"""The homing sweep of README.md: the failing regions are the ones it
explains, and a failure's files reproduce it with `tmclsim run`."""

import os
import pathlib
import re
import subprocess

import tmclsim

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def test_the_failing_regions_are_the_explained_ones(tmp_path):
    s = tmclsim.sweep(HERE / "homing.tmc", HERE / "sweep.toml", workers=0, failures=tmp_path, details=True)
    t = s.table
    assert len(t) == 54
    failed = t[~t.passed]
    # Load 40 %: every position, every width stalls and times out.
    heavy = t[t.load == 40]
    assert (~heavy.passed).all() and (heavy["var 0"] == 2).all()
    assert heavy.stalled.all() and (heavy.failed_check == "no stall").all()
    assert (heavy.carriage.abs() < 100).all(), "the motor stalls at the start"
    # The counter runs on (in the search's negative direction) while the
    # carriage stands.
    assert (heavy["min ap 1 0"] < -2_000_000).all()
    # Without that load: the switch at +400 000 (wide) and beyond times out.
    light = t[t.load < 40]
    far = (light.home_from > 400000) | ((light.home_from == 400000) & (light.home_width == 20000))
    assert (~light[far].passed).all() and light[~far].passed.all()
    assert (light[far]["var 0"] == 2).all() and (light[far].time > 40).all()
    assert not light.stalled.any() and (light[far].failed_check == "homed").all()
    assert len(failed) == 18 + 10
    # Homed scenarios: the counter is 0 where the search met the switch.
    assert (t[t.passed].position == 0).all()


def test_a_failure_reproduces_with_tmclsim_run(tmp_path):
    s = tmclsim.sweep(HERE / "homing.tmc", HERE / "sweep.toml", workers=0, failures=tmp_path, details=True)
    row = s.table[(s.table.home_from == 800000) & (s.table.load == 0)].iloc[0]
    i = int(row.scenario)
    binary = os.environ.get("TMCLSIM_BIN") or str(ROOT / "target" / "release" / "tmclsim")
    out = subprocess.run(
        [binary, "run", str(HERE / "homing.tmc"), "--world", str(tmp_path / f"failure-{i}.toml"),
         "--setup", str(tmp_path / f"failure-{i}.setup"), "--for", f"{row.time}s"],
        capture_output=True, text=True, check=True,
    ).stdout
    assert re.search(rf"axis 0: position {int(row.position)} ", out), out
    assert "user variables 0=2" in out
