"""Scenario sweeps (docs/sweeps.md): matrix files, scenarios run in virtual
time, pass/fail from the simulator, failures that `tmclsim run` reproduces,
and the same table from one process, an embedded Dask cluster and a real
`dask scheduler` with two `dask worker` processes."""

import os
import pathlib
import re
import socket
import subprocess
import sys

import pytest

import tmclsim
from tmclsim.sweep import MatrixError, parse

ROOT = pathlib.Path(__file__).resolve().parents[2]
HOMING = ROOT / "examples" / "sweep-homing" / "homing.tmc"

# Homing by reference search; user variable 0: 1 homed, 2 timed out.
SMALL = {
    "duration": "60s",
    "step": "100ms",
    "metrics": ["time", "position", "carriage", "var 0"],
    "world": {"base": "stage", "axis": [{"home_switch": {"from": 0, "width": 2000}}]},
    "vary": [
        {"name": "home", "world": "axis.0.home_switch.from", "values": [-400000, 800000]},
        {"name": "load", "world": "axis.0.load.0.torque", "values": [0, 60]},
    ],
    "check": [{"name": "homed", "expr": "var 0 == 1"}],
}


def tmclsim_bin():
    path = os.environ.get("TMCLSIM_BIN") or str(ROOT / "target" / "release" / "tmclsim")
    if not os.path.exists(path):
        subprocess.run(["cargo", "build", "--release", "-p", "tmclsim"], cwd=ROOT, check=True)
    return path


def test_the_simulator_decides_pass_and_fail():
    t = tmclsim.sweep(HOMING, SMALL, workers=0)
    assert list(t.columns[:3]) == ["scenario", "home", "load"]
    by = {(r.home, r.load): r for r in t.itertuples()}
    # A home switch on the search's way, no load: homed, counter 0 there.
    ok = by[(-400000, 0)]
    assert ok.passed and ok.failed_check == ""
    assert ok.position == 0
    # The negative search meets the switch at its upper edge (from + width).
    assert ok.carriage == -400000 + 2000
    # Beyond the left stop and back takes longer than the program's 40 s
    # timeout; a load of 60 % stalls the motor at the search speed.
    for key in [(800000, 0), (-400000, 60), (800000, 60)]:
        r = by[key]
        assert not r.passed and r.failed_check == "homed"
        assert r.time > 40.0
    assert t.loc[t.home == -400000].loc[t.load == 60, "var 0"].item() == 2


def test_parameters_by_name_and_random_draws_are_reproducible():
    m = dict(SMALL)
    m["seed"] = 7
    m["vary"] = [
        {"name": "speed", "ap": "reference_search_speed", "motor": 0, "values": [500, 2047]},
        {"name": "home", "world": "axis.0.home_switch.from", "random": {"min": -600000, "max": -100000, "count": 3}},
    ]
    a = tmclsim.sweep(HOMING, m, workers=0)
    b = tmclsim.sweep(HOMING, m, workers=0)
    assert a.equals(b)
    assert len(a) == 6 and a.home.nunique() == 3
    assert all(-600000 <= h <= -100000 for h in a.home)
    # The program sets AP 194 itself (2047): a varied AP 194 is overwritten,
    # so both speeds home alike; the parameter reached the module first.
    assert a.passed.all()


def test_matrix_errors_name_the_key():
    cases = [
        ({"vary": [{"world": "axis.0.start"}]}, "vary[0]: give exactly one of values"),
        ({"vary": [{"ap": 4, "values": []}]}, "vary[0].values: a non-empty list"),
        ({"vary": [{"world": "x", "ap": 4, "values": [1]}]}, "vary[0]: name what it varies"),
        ({"check": [{"expr": "var 0 = 1"}]}, "check[0].expr"),
        ({"duration": "soon"}, "duration: 'soon' is not a duration"),
        ({"metrics": ["speed"]}, "metrics[0]: 'speed'"),
        ({"colour": 1}, "colour: unknown key"),
        ({"vary": [{"world": "a", "range": [10, 0, 1]}]}, "vary[0].range"),
        ({"vary": 3}, "vary: a list of tables"),
        ({"check": {"expr": "var 0 == 1"}}, "check: a list of tables"),
        ({"stop": {"when": "var 0 == 1"}}, "stop.when: a list of conditions"),
        ({"vary": [{"world": "a", "range": [float("inf"), float("inf"), 1]}]}, "vary[0].range"),
        ({"vary": [{"world": "a", "random": {"min": 5, "max": 1, "count": 2}}]}, "min not above max"),
        ({"vary": [{"world": "a", "name": [1], "values": [1]}]}, "vary[0].name"),
        ({"vary": [{"profile": True, "values": [1]}]}, "vary[0].values: profile names"),
    ]
    for doc, message in cases:
        with pytest.raises(MatrixError) as e:
            parse(doc)
        assert message in str(e.value), (doc, str(e.value))


def test_a_failure_is_reproduced_by_tmclsim_run(tmp_path):
    m = dict(SMALL)
    m["vary"] = SMALL["vary"] + [{"name": "accel", "ap": 5, "motor": 0, "values": [1500]}]
    s = tmclsim.sweep(HOMING, m, workers=0, failures=tmp_path, details=True)
    failed = s.table[~s.table.passed]
    assert len(failed) == 3 and set(s.failures) == set(failed.scenario)
    row = failed.iloc[0]
    i = int(row.scenario)
    setup = (tmp_path / f"failure-{i}.setup").read_text()
    assert "SAP 5, 0, 1500" in setup
    out = subprocess.run(
        [tmclsim_bin(), "run", str(HOMING), "--world", str(tmp_path / f"failure-{i}.toml"),
         "--setup", str(tmp_path / f"failure-{i}.setup"), "--for", f"{row.time}s"],
        capture_output=True, text=True, check=True,
    ).stdout
    # The same final state as in the sweep: position counter and variable 0.
    assert re.search(rf"axis 0: position {int(row.position)} ", out), out
    assert re.search(rf"user variables 0={int(row['var 0'])}\b", out), out


def same(a, b):
    return a.drop(columns=[]).to_dict("records") == b.to_dict("records")


def test_an_embedded_cluster_gives_the_serial_table(tmp_path):
    serial = tmclsim.sweep(HOMING, SMALL, workers=0)
    parallel = tmclsim.sweep(HOMING, SMALL, workers=2, batch=1, out=tmp_path / "r.parquet")
    assert same(serial, parallel)
    import pandas as pd

    assert same(serial, pd.read_parquet(tmp_path / "r.parquet"))


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_a_real_scheduler_and_two_workers_give_the_serial_table():
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard"],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from dask.distributed import Client

        with Client(address, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
            assert len(c.scheduler_info()["workers"]) == 2
        serial = tmclsim.sweep(HOMING, SMALL, workers=0)
        remote = tmclsim.sweep(HOMING, SMALL, scheduler=address, batch=1)
        assert same(serial, remote)
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def test_the_command_line(tmp_path):
    matrix = tmp_path / "m.toml"
    matrix.write_text('duration = "60s"\nmetrics = ["time"]\n[world]\naxis = [{ home_switch = { from = 0, width = 2000 } }]\n'
                      '[[vary]]\nworld = "axis.0.home_switch.from"\nvalues = [-400000, 800000]\n'
                      '[[check]]\nname = "homed"\nexpr = "var 0 == 1"\n')
    env = dict(os.environ, TMCLSIM_PYTHON=sys.executable)
    out = tmp_path / "r.csv"
    # Failure files of an earlier sweep go; other files stay.
    (tmp_path / "f").mkdir()
    (tmp_path / "f" / "failure-99.toml").write_text("")
    (tmp_path / "f" / "notes.txt").write_text("mine")
    r = subprocess.run([tmclsim_bin(), "sweep", str(HOMING), "--matrix", str(matrix), "--workers", "0", "--out", str(out),
                        "--failures", str(tmp_path / "f")], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert r.returncode == 1, r.stderr  # a failure: exit status 1
    assert "2 scenarios" in r.stdout and "1 passed, 1 failed" in r.stdout and "homed" in r.stdout
    assert "--world " in r.stdout and (tmp_path / "f" / "failure-1.toml").exists()
    assert sorted(p.name for p in (tmp_path / "f").iterdir()) == ["failure-1.setup", "failure-1.toml", "notes.txt"]
    assert out.read_text().splitlines()[0].startswith("scenario,axis.0.home_switch.from,passed")
    bad = tmp_path / "bad.toml"
    bad.write_text("[[vary]]\nworld = 3\nvalues = [1]\n")
    r = subprocess.run([tmclsim_bin(), "sweep", str(HOMING), "--matrix", str(bad)], capture_output=True, text=True, env=env)
    assert r.returncode == 2 and "vary[0].world" in r.stderr


def test_world_keys_reach_lists_of_tables_and_of_numbers():
    from tmclsim.sweep.scenario import set_world

    doc = {"base": "stage"}
    set_world(doc, "axis.0.load.1.torque", 30)
    set_world(doc, "inputs.2", 1)
    set_world(doc, "axis.0.start", -5000)
    assert doc == {"base": "stage", "axis": [{"load": [{}, {"torque": 30}], "start": -5000}], "inputs": [0, 0, 1]}
    # The input reaches the module: GIO 2, 0 reads 1 in the scenario.
    m = {"duration": "1s", "step": "1s", "metrics": ["gp 0 2"],
         "setup": [], "vary": [{"name": "in2", "world": "inputs.2", "values": [0, 1]}],
         "check": [{"name": "input seen", "expr": "var 0 == 0"}]}
    # The program copies input 2 into user variable 0.
    program = tmclsim.assemble("GIO 2, 0\nAGP 0, 2\nSTOP\n")
    t = tmclsim.sweep(program, m, workers=0)
    assert list(t["gp 0 2"]) == [0, 1]
    assert list(t.passed) == [True, False]


def test_any_matrix_document_is_parsed_or_refused_with_a_matrix_error():
    import random as rnd

    r = rnd.Random(17)
    atoms = [0, 1, -5, 2.5, "x", "60s", "var 0 == 1", True, [], {}, [1, 2], {"min": 0, "max": 1, "count": 2}, [0, 10, 5], None]
    keys = ["profile", "duration", "step", "seed", "world", "setup", "vary", "stop", "check", "metrics", "values", "range",
            "random", "ap", "gp", "motor", "bank", "name", "expr", "when", "program_ended", "tolerance", "no_stall", "finished_within"]

    def value(depth):
        k = r.random()
        if depth > 2 or k < 0.5:
            v = r.choice(atoms)
            return v if v is not None else {}
        if k < 0.75:
            return [value(depth + 1) for _ in range(r.randint(0, 3))]
        return {r.choice(keys): value(depth + 1) for _ in range(r.randint(0, 4))}

    def entry(names):
        return {r.choice(names): value(1) for _ in range(r.randint(1, 5))}

    for i in range(6000):
        doc = {r.choice(keys[:10]): value(0) for _ in range(r.randint(0, 5))}
        if i % 2:
            # Tables shaped like the real ones, with values of every type.
            doc["vary"] = [entry(["world", "ap", "gp", "profile", "name", "motor", "bank", "values", "range", "random"]) for _ in range(r.randint(1, 3))]
            doc["check"] = [entry(["expr", "name", "tolerance", "no_stall", "finished_within"]) for _ in range(r.randint(0, 2))]
        try:
            m = parse(doc)
            list(m.scenarios())
        except MatrixError:
            pass


STALL_WATCH = """\
        SAP 181, 0, 100         // stop on stall from speed 100 up
        SGP 1, 2, 0
        ROR 0, 1500
Loop:   WAIT TICKS, 0, 50       // look every 0.5 s
        GAP 207, 0              // (reading clears it)
        COMP 0
        JC EQ, Loop
        SGP 1, 2, 1             // the program saw the stall
        STOP
"""


def test_looking_for_stalls_leaves_the_flag_to_the_program(tmp_path):
    # The sweep looks at AP 207 every 100 ms, the program every 500 ms: a
    # look that cleared it (as GAP 207 does) would hide the stall from the
    # program, and `tmclsim run` would end otherwise.
    source = tmp_path / "stall.tmc"
    source.write_text(STALL_WATCH)
    m = {"duration": "3s", "world": {"base": "free"}, "metrics": ["stalled", "var 1", "time"],
         "vary": [{"name": "load", "world": "axis.0.load.0.torque", "values": [0, 60]}],
         "check": [{"name": "no stall", "no_stall": True}]}
    s = tmclsim.sweep(source, m, workers=0, failures=tmp_path / "f", details=True)
    t = s.table
    assert list(t.passed) == [True, False] and list(t.stalled) == [False, True]
    assert list(t["var 1"]) == [0, 1], "the program saw its stall"
    assert t.failed_check[1] == "no stall" and t.time[1] < 3
    out = subprocess.run(
        [tmclsim_bin(), "run", str(source), "--world", str(tmp_path / "f" / "failure-1.toml"),
         "--setup", str(tmp_path / "f" / "failure-1.setup"), "--for", f"{t.time[1]}s"],
        capture_output=True, text=True, check=True,
    ).stdout
    assert re.search(r"user variables 1=1\b", out), out


def test_end_stops_limit_switches_and_values_over_the_run():
    # A move to +200 000 on a free axis whose travel may end before it: the
    # counter gets there, the carriage stops at the end stop. (The program
    # stays there for 0.5 s: values over the run are looked at every step.)
    program = tmclsim.assemble("MVP ABS, 0, 200000\nWAIT POS, 0, 0\nWAIT TICKS, 0, 50\nMVP ABS, 0, 0\nWAIT POS, 0, 0\nSTOP\n")
    m = {"duration": "30s", "world": {"base": "free"},
         "metrics": ["end_stop", "limit_switch", "max ap 1 0", "min ap 1 0", "carriage", "position"],
         "vary": [{"name": "travel", "world": "axis.0.travel", "values": [[-300000, 300000], [-300000, 100000]]}],
         "check": [{"name": "overrun", "expr": "max ap 1 0 <= 200000"}, {"name": "end stop", "no_end_stop": True},
                   {"name": "switches", "no_limit_switch": True}]}
    t = tmclsim.sweep(program, m, workers=0)
    assert list(t["max ap 1 0"]) == [200000, 200000] and list(t["min ap 1 0"]) == [0, 0]
    assert list(t.end_stop) == [False, True] and not t.limit_switch.any()
    assert list(t.passed) == [True, False] and t.failed_check[1] == "end stop"
    # Back at 0 by the counter; the carriage lost the steps beyond the stop.
    assert list(t.position) == [0, 0]
    assert t.carriage[0] == 0 and t.carriage[1] == -100000
    # On the stage, the right stop switch at +1 000 000 stops the move.
    m2 = dict(m, world={"base": "stage"}, vary=[{"name": "target", "ap": 4, "motor": 0, "values": [2047]}], check=m["check"][1:])
    program2 = tmclsim.assemble("MVP ABS, 0, 1010000\nWAIT TICKS, 0, 3000\nSTOP\n")
    t2 = tmclsim.sweep(program2, m2, workers=0)
    assert t2.limit_switch[0] and not t2.end_stop[0] and t2.failed_check[0] == "switches"


def test_a_scenario_the_module_refuses_is_a_setup_failure():
    m = {"duration": "1s", "metrics": ["time", "ap 4 0"],
         "vary": [{"name": "speed", "ap": "maximum_positioning_speed", "values": [1000, 5000]}]}
    t = tmclsim.sweep(tmclsim.assemble("STOP\n"), m, workers=0)
    assert list(t.passed) == [True, False]
    assert t.failed_check[1] == "setup" and "SAP 4, 0, 5000" in t.error[1] and "status 4" in t.error[1]
    assert t["ap 4 0"][0] == 1000
    # A value the module does not have: the scenario's error, not a traceback.
    t = tmclsim.sweep(tmclsim.assemble("STOP\n"), {"duration": "1s", "metrics": ["ap no_such_parameter 0"]}, workers=0)
    assert t.failed_check[0] == "setup" and "no_such_parameter" in t.error[0]


def test_columns_have_one_name():
    with pytest.raises(MatrixError, match=r"metrics\[1\]: 'time' is listed twice"):
        parse({"metrics": ["time", "time"]})
    with pytest.raises(MatrixError, match=r"metrics\[0\]: 'var 0' is a column"):
        parse({"metrics": ["var 0"], "vary": [{"name": "var 0", "world": "supply", "values": [24]}]})
    with pytest.raises(MatrixError, match=r"vary\[0\].name: 'passed'"):
        parse({"vary": [{"name": "passed", "world": "supply", "values": [24]}]})
    with pytest.raises(MatrixError, match=r"check\[0\].expr"):
        parse({"check": [{"expr": "max 0 == 1"}]})
    assert parse({"metrics": ["max ap 1 0", "min var 3"]}).metrics == ["max ap 1 0", "min var 3"]


def test_the_command_line_without_the_python_package(tmp_path):
    # An interpreter without tmclsim: the command says how to install it.
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(tmp_path / "bare")], check=True)
    bare = tmp_path / "bare" / "bin" / "python"
    r = subprocess.run([tmclsim_bin(), "sweep", str(HOMING), "--matrix", "m.toml"], capture_output=True, text=True,
                       env=dict(os.environ, TMCLSIM_PYTHON=str(bare)))
    assert r.returncode != 0 and "pip install './python[sweep]'" in r.stderr, r.stderr
    r = subprocess.run([tmclsim_bin(), "sweep", "--help"], capture_output=True, text=True,
                       env=dict(os.environ, TMCLSIM_PYTHON=sys.executable))
    assert r.returncode == 0 and "--scheduler" in r.stdout and "--matrix" in r.stdout


# Limits (docs/sweeps.md, "Limits"): every input is checked before anything
# runs, the matrix is counted before it is listed, and nothing of a sweep
# grows with its scenarios but its table.


def test_the_scenarios_are_counted_before_anything_is_listed():
    import tracemalloc

    huge = {"vary": [{"name": f"x{i}", "world": "supply", "range": [0, 999_999, 1]} for i in range(7)]}
    tracemalloc.start()
    try:
        with pytest.raises(MatrixError) as e:
            parse(huge)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    # Seven ranges of a million values: refused without listing them.
    assert peak < 2_000_000, peak
    assert str(e.value).startswith("vary: about 10^42 scenarios (1000000 × 1000000 × "), str(e.value)
    assert "at most 10000000" in str(e.value)
    # A range's values are counted from its bounds, even when they pass
    # any float.
    with pytest.raises(MatrixError, match=r"vary\[0\]\.range: 10000000001 values; at most 1000000"):
        parse({"vary": [{"world": "supply", "range": [0, 1, 1e-10]}]})
    with pytest.raises(MatrixError, match=r"vary\[0\]\.range: more values than any count"):
        parse({"vary": [{"world": "supply", "range": [-1e308, 1e308, 1e-300]}]})
    # Ten million scenarios are within the limit; any one of them is
    # decoded from its number, none is listed.
    mx = parse({"vary": [{"name": "a", "world": "supply", "range": [0, 9_999, 1]},
                         {"name": "b", "world": "temperature", "range": [0.5, 500.0, 0.5]}]})
    assert mx.count() == 10_000_000
    assert mx.scenario(0) == {"a": 0, "b": 0.5} and mx.scenario(9_999_999) == {"a": 9_999, "b": 500.0}
    assert mx.scenario(1001) == {"a": 1, "b": 1.0}
    import itertools

    assert list(itertools.islice(mx.scenarios(), 2)) == [{"a": 0, "b": 0.5}, {"a": 0, "b": 1.0}]
    assert [mx.scenario(i) for i in range(4000, 4003)] == list(mx.scenarios(4000, 4003))


def test_a_step_that_would_never_end_is_refused():
    # Below the clock's nanosecond a step advances nothing: the scenario
    # would run forever. A step is at least 1 µs, a scenario at most a
    # million looks and 24 h of virtual time.
    with pytest.raises(MatrixError, match="step: .* shorter than 1 µs"):
        parse({"duration": "1s", "step": 1e-10})
    with pytest.raises(MatrixError, match=r"step: 86400 s in steps of 0\.001 s is 86400000 looks per scenario; at most 1000000"):
        parse({"duration": "24h", "step": "1ms"})
    with pytest.raises(MatrixError, match="duration: 90000 s is longer than 24 h"):
        parse({"duration": "25h", "step": "1m"})
    for bad in ["nan", "inf", float("nan"), float("inf"), "1.2.3", "-5s", "0s", True, [1], 10**400]:
        with pytest.raises(MatrixError, match="^duration: "):
            parse({"duration": bad})
    with pytest.raises(MatrixError, match=r"check\[0\]\.finished_within"):
        parse({"check": [{"finished_within": float("nan")}]})
    assert parse({"duration": "1s", "step": "250us"}).step == 250e-6


def test_a_world_list_entry_must_exist_on_the_module():
    from tmclsim.sweep.scenario import set_world

    with pytest.raises(MatrixError) as e:
        parse({"vary": [{"world": "inputs.5000000", "values": [1]}]})
    assert str(e.value) == "vary[0].world: 'inputs.5000000': the TMCM-1141 has no digital input 5000000 (digital inputs: 0…3)"
    cases = [
        ({"world": "inputs.4"}, "the TMCM-1141 has no digital input 4"),
        ({"world": "analog.1"}, "the TMCM-1141 has no analog input 1 (analog inputs: 0)"),
        ({"world": "axis.1.start"}, "the TMCM-1141 has no axis 1 (axes: 0)"),
        ({"world": "axis.0.travel.2"}, "travel is a pair"),
        ({"world": "axis.0.load.64.torque"}, "list entry 64; at most 63"),
        ({"world": "0.x"}, "the world file is a table"),
        ({"world": "axis..start"}, "an empty part"),
    ]
    for entry, message in cases:
        with pytest.raises(MatrixError) as e:
            parse({"vary": [dict(entry, values=[1])]})
        assert str(e.value).startswith("vary[0].world: ") and message in str(e.value), str(e.value)
    # On every module the sweep runs on.
    assert parse({"profile": "tmcm-351", "vary": [{"world": "analog.3", "values": [1]}]}).count() == 1
    with pytest.raises(MatrixError, match=r"vary\[1\]\.world: 'analog\.1': the TMCM-1141 has no analog input 1"):
        parse({"vary": [{"profile": True, "values": ["tmcm-1310", "tmcm-1141"]}, {"world": "analog.1", "values": [1]}]})
    assert parse({"vary": [{"world": "axis.0.load.63.torque", "values": [1]}, {"world": "inputs.3", "values": [1]}]}).count() == 1
    # The world document never grows a list past what a world file holds.
    doc = {}
    with pytest.raises(MatrixError, match="list entry 5000000"):
        set_world(doc, "inputs.5000000", 1)
    assert doc == {}


def test_every_matrix_value_is_checked_with_its_key():
    cases = [
        ({"seed": float("inf")}, "seed: 'inf' is not a whole number"),
        ({"seed": 1.5}, "seed: '1.5' is not a whole number"),
        ({"seed": True}, "seed: 'True' is not a whole number"),
        ({"seed": 2**65}, "seed: 36893488147419103232 is outside"),
        ({"profile": 5}, "profile: '5' is no module profile"),
        ({"profile": "tmcm-9999"}, "profile: 'tmcm-9999' is no module profile"),
        ({"vary": [{"ap": 4, "motor": 300, "values": [1]}]}, "vary[0].motor: 300 is outside 0…255"),
        ({"vary": [{"ap": 4, "motor": float("inf"), "values": [1]}]}, "vary[0].motor: 'inf' is not a whole number"),
        ({"vary": [{"gp": 300, "values": [1]}]}, "vary[0].gp: 300 is outside 0…255"),
        ({"vary": [{"world": "a", "random": {"min": 0, "max": 1, "count": float("inf")}}]}, "vary[0].random.count: 'inf' is not a whole number"),
        ({"vary": [{"world": "a", "random": {"min": 0, "max": 1, "count": 10**7}}]}, "vary[0].random.count: 10000000 is outside 1…1000000"),
        ({"metrics": ["ap 4 300"]}, "metrics[0]: 'ap 4 300' is none of"),
        ({"metrics": ["var ²"]}, "metrics[0]: 'var ²' is none of"),
        ({"check": [{"expr": "var 0 == nan"}]}, "check[0].expr: 'nan' is not a finite number"),
        ({"check": [{"expr": "var 0 == 1", "tolerance": float("nan")}]}, "check[0].tolerance: a finite number"),
        ({"stop": {"program_ended": "no"}}, "stop.program_ended: true or false"),
        ({"vary": [{"world": "supply", "values": [1]}] * 33}, "vary: 33 [[vary]] sections; at most 32"),
        ({"metrics": [f"var {i}" for i in range(65)]}, "metrics: 65 metrics; at most 64"),
    ]
    for doc, message in cases:
        with pytest.raises(MatrixError) as e:
            parse(doc)
        assert message in str(e.value) and "\n" not in str(e.value), (doc, str(e.value))


def test_a_deeply_nested_matrix_is_refused_not_a_recursion_error(tmp_path):
    from tmclsim.sweep import load

    files = {
        "lists": "x = " + "[" * 100_000 + "]" * 100_000 + "\n",
        "inline tables": "x = " + "{a = " * 100_000 + "1" + "}" * 100_000 + "\n",
        "a table header": "[world" + ".a" * 100_000 + "]\nb = 1\n",
        "a dotted key": "[world]\n" + "a." * 5_000 + "b = 1\n",
    }
    for what, text in files.items():
        path = tmp_path / "m.toml"
        path.write_text(text)
        with pytest.raises(MatrixError) as e:
            load(path)
        assert str(e.value).startswith(f"{path}: line ") and "the limit" in str(e.value), (what, str(e.value))
    # Within the limit of parts and of brackets, nested deeper in all:
    # refused after parsing, by the walk.
    path.write_text("[world" + ".a" * 20 + "]\n" + "b." * 20 + "c = 1\n")
    with pytest.raises(MatrixError, match="nested more than 32 deep"):
        load(path)
    # From Python: a deep or a cyclic document.
    deep = {"base": "stage"}
    for _ in range(10_000):
        deep = {"a": deep}
    cyclic = {"a": []}
    cyclic["a"].append(cyclic)
    for world in (deep, cyclic):
        with pytest.raises(MatrixError, match="nested more than 32 deep"):
            parse({"world": world})
    # A file larger than 1 MiB is not read on; one that is no text says so.
    path.write_bytes(b"#" * (1 << 20) + b"\n")
    with pytest.raises(MatrixError, match="larger than 1 MiB, the limit for a matrix file"):
        load(path)
    path.write_bytes(b"duration = \"\xff\"\n")
    with pytest.raises(MatrixError, match="not UTF-8"):
        load(path)
    path.write_text("seed = " + "1" * 5000 + "\n")
    with pytest.raises(MatrixError, match=str(path)):
        load(path)


def test_the_nesting_check_passes_every_toml_file_it_may_meet():
    import random as rnd

    import tomli_w

    from tmclsim.sweep.matrix import check_toml_nesting

    try:
        import tomllib
    except ImportError:
        import tomli as tomllib
    for path in list(ROOT.glob("profiles/*.toml")) + list(ROOT.glob("examples/**/*.toml")):
        check_toml_nesting(path.read_text())
    tricky = ('a."b.c".d = 1  # a.b.c.d.e.f\n[x."y.z"]\ns = """\n[[q.w.e]]\n. . .\n"""\nt = \'\'\'\n{[\'\'\'\n'
              'u = "\\"[{"\nv = [1.5, 2.5, {w.x = 1}, [[], [{}]]]\n[[p.q]]\n')
    check_toml_nesting(tricky)
    tomllib.loads(tricky)
    r = rnd.Random(5)
    words = ["a", "b.c", "x y", "[", "'", '"', "#", "=", "{", "1.5"]

    def value(depth):
        k = r.random()
        if depth >= 10 or k < 0.4:
            return r.choice([1, 2.5, True, r.choice(words), "line\nbreak \"q\" '''"])
        if k < 0.7:
            return [value(depth + 1) for _ in range(r.randint(0, 3))]
        return {r.choice(words): value(depth + 1) for _ in range(r.randint(0, 3))}

    for _ in range(300):
        doc = {r.choice(words): value(0) for _ in range(r.randint(1, 4))}
        text = tomli_w.dumps(doc, multiline_strings=r.random() < 0.5)
        check_toml_nesting(text)
        assert tomllib.loads(text) == doc


def test_options_are_checked_before_anything_runs(tmp_path):
    program = tmclsim.assemble("STOP\n")
    m = {"duration": "1s"}
    (tmp_path / "file").write_text("")
    cases = [
        (dict(batch=-1), "batch: -1 is outside 1…100000"),
        (dict(batch=0), "batch: 0 is outside 1…100000"),
        (dict(batch=True), "batch: a whole number"),
        (dict(batch=2.5), "batch: a whole number"),
        (dict(workers=-1), "workers: -1 is outside 0…256"),
        (dict(workers=10**6), "workers: 1000000 is outside 0…256"),
        (dict(workers="2"), "workers: a whole number"),
        (dict(scheduler=""), "scheduler: the address of a Dask scheduler"),
        (dict(workers=0, out=tmp_path / "r.txt"), "out: "),
        (dict(workers=0, out=tmp_path / "no" / "r.csv"), "is no directory"),
        (dict(workers=0, failures=tmp_path / "file"), "failures: "),
    ]
    for options, message in cases:
        with pytest.raises(ValueError) as e:
            tmclsim.sweep(program, m, **options)
        assert message in str(e.value), (options, str(e.value))
    assert not (tmp_path / "r.txt").exists()


def test_the_command_line_refuses_bad_options_in_one_line(tmp_path):
    matrix = tmp_path / "m.toml"
    matrix.write_text('duration = "1s"\n')
    program = tmp_path / "p.tmc"
    program.write_text("STOP\n")
    (tmp_path / "file").write_text("")
    cases = [
        (["--batch", "-1"], "--batch: -1 is outside 1…100000"),
        (["--batch", "0"], "--batch: 0 is outside 1…100000"),
        (["--batch", "many"], "--batch: 'many' is not a whole number"),
        (["--workers", "-1"], "--workers: -1 is outside 0…256"),
        (["--workers", "1e9"], "--workers: '1e9' is not a whole number"),
        (["--workers", "0", "--out", "r.txt"], "--out: r.txt: the table is written as .parquet or .csv"),
        (["--workers", "0", "--failures", str(tmp_path / "file")], "--failures: "),
        (["--workers", "0", "--matrix", str(tmp_path / "missing.toml")], "missing.toml"),
    ]
    for extra, message in cases:
        args = [sys.executable, "-m", "tmclsim.sweep", str(program), "--matrix", str(matrix), *extra]
        r = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path)
        assert r.returncode == 2 and r.stderr.count("\n") == 1 and message in r.stderr, (extra, r.stderr)
        assert "Traceback" not in r.stderr and r.stdout == ""
    # The same through `tmclsim sweep`.
    r = subprocess.run([tmclsim_bin(), "sweep", str(program), "--matrix", str(matrix), "--batch", "0"], capture_output=True, text=True,
                       env=dict(os.environ, TMCLSIM_PYTHON=sys.executable), cwd=tmp_path)
    assert r.returncode == 2 and r.stderr == "tmclsim sweep: argument --batch: 0 is outside 1…100000\n", r.stderr
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 100_000 + "]" * 100_000 + "\n")
    r = subprocess.run([sys.executable, "-m", "tmclsim.sweep", str(program), "--matrix", str(deep)], capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "nested more than 32 deep" in r.stderr, r.stderr


def test_a_replay_command_is_always_one_that_runs(tmp_path):
    import shlex

    from tmclsim.sweep import reproduce_command

    # One scenario the module refuses (no time: NaN in the table), one
    # that fails its check; a failure directory with a space in its name.
    program = tmp_path / "my prog.tmc"
    program.write_text("STOP\n")
    m = {"duration": "2s", "metrics": ["time"], "vary": [{"name": "speed", "ap": 4, "values": [5000, 1000]}],
         "check": [{"name": "never", "expr": "var 0 == 1"}]}
    d = tmp_path / "fail ures"
    s = tmclsim.sweep(program, m, workers=0, failures=d, details=True)
    t = s.table
    assert t.failed_check.tolist() == ["setup", "never"] and t.time.isna().tolist() == [True, False]
    mx = parse(m)
    for row in t.to_dict("records"):
        words = shlex.split(reproduce_command(program, mx, row, d))
        assert words[:3] == ["tmclsim", "run", str(program)] and words[words.index("--world") + 1] == str(d / f"failure-{row['scenario']}.toml")
        seconds = words[words.index("--for") + 1]
        assert seconds.endswith("s") and "nan" not in seconds
        if row["failed_check"] == "setup":
            assert seconds == "2s"  # the matrix's duration
        else:
            out = subprocess.run([tmclsim_bin(), *words[1:]], capture_output=True, text=True)
            assert out.returncode == 0, out.stderr
    for t in [float("nan"), float("inf"), -1.0, None, True]:
        assert shlex.split(reproduce_command("p.tmc", mx, {"scenario": 0, "speed": 1000, "time": t}, "f"))[-1] == "2s"
    assert shlex.split(reproduce_command("p.tmc", mx, {"scenario": 0, "speed": 1000, "time": 1e-05}, "f"))[-1] == "0.00001s"


def test_failure_files_never_follow_a_link(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    victim = outside / "victim.txt"
    victim.write_text("mine")
    d = tmp_path / "failures"
    d.mkdir()
    # Links planted where this sweep's failure 1 and an earlier sweep's
    # failure 7 would be, pointing outside the directory.
    (d / "failure-1.toml").symlink_to(victim)
    (d / "failure-1.setup").symlink_to(outside / "new.setup")
    (d / "failure-7.toml").symlink_to(victim)
    m = {"duration": "60s", "world": {"axis": [{"home_switch": {"from": 0, "width": 2000}}]},
         "vary": [{"name": "home", "world": "axis.0.home_switch.from", "values": [-400000, 800000]}],
         "check": [{"name": "homed", "expr": "var 0 == 1"}]}
    s = tmclsim.sweep(HOMING, m, workers=0, failures=d, details=True)
    assert list(s.failures) == [1]
    assert victim.read_text() == "mine" and sorted(p.name for p in outside.iterdir()) == ["victim.txt"]
    assert sorted(p.name for p in d.iterdir()) == ["failure-1.setup", "failure-1.toml"]
    world = d / "failure-1.toml"
    assert not world.is_symlink() and world.read_text() == s.failures[1]["world"] and "800000" in world.read_text()
    assert (d / "failure-1.setup").read_text() == s.failures[1]["setup"]


def test_a_world_value_no_world_file_holds_is_a_setup_failure():
    m = {"duration": "1s", "world": {"axis": [{"home_switch": {"from": 0}}]},
         "vary": [{"name": "width", "world": "axis.0.home_switch.width", "values": [2000, "wide"]}]}
    t = tmclsim.sweep(tmclsim.assemble("STOP\n"), m, workers=0)
    assert t.passed.tolist() == [True, False]
    assert t.failed_check[1] == "setup" and t.error[1].startswith("world: ")


@pytest.mark.slow
def test_a_sweep_keeps_no_row_and_no_failure_file(monkeypatch):
    # The engine and the table alone (each scenario a row made up, a third
    # of them failures): memory of the sweep in this process grows by the
    # table's columns, not by a dict or a file per scenario.
    import tracemalloc

    from tmclsim.sweep import scenario

    def made_up(mx, programs, index, values):
        row = {"scenario": index, **values}
        failed = index % 3 == 0
        row.update(passed=not failed, failed_check="homed" if failed else "", error="", time=40.0 + index % 1000 * 1e-3, position=index * 7)
        return row, {"world": f"[[axis]]\nstart = {index}\n", "setup": ""} if failed else None

    monkeypatch.setattr(scenario, "run", made_up)
    n = 200_000
    m = {"duration": "1s", "metrics": ["time", "position"],
         "vary": [{"name": "a", "world": "axis.0.start", "range": [0, 999, 1]}, {"name": "b", "world": "supply", "range": [1, n // 1000, 1]}]}
    program = tmclsim.assemble("STOP\n")
    tmclsim.sweep(program, {"duration": "1s"}, workers=0)  # what it imports is not the sweep's
    tracemalloc.start()
    try:
        s = tmclsim.sweep(program, m, workers=0, details=True)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    t = s.table
    assert len(t) == n and t.scenario.tolist() == list(range(n)) and t.a[1001] == 5 and t.b[1001] == 2
    assert len(s.failures) == -(-n // 3) and 3 in s.failures and 4 not in s.failures
    # Far below what rows as dicts take (over 800 bytes each).
    assert peak < 100 * n, f"{peak / n:.0f} bytes per scenario"


def test_the_table_is_the_one_pandas_makes_of_the_rows():
    import math

    import pandas as pd

    from tmclsim.sweep.table import Table

    mx = parse({"metrics": ["time", "position", "stalled", "var 0", "max ap 1 0", "gp 0 2", "min ap 1 0", "end_stop"],
                "vary": [{"name": "a", "world": "axis.0.travel", "values": [[-5, 5], [-9, 9]]},
                         {"name": "b", "world": "supply", "values": [1, 2.5, 3]},
                         {"name": "c", "profile": True, "values": ["tmcm-1141", "tmcm-1140"]}]})
    rows = []
    for i, values in enumerate(mx.scenarios()):
        setup = i % 5 == 3
        row = {"scenario": i, **values, "passed": i % 2 == 0, "failed_check": "" if i % 2 == 0 else "setup" if setup else "homed",
               "error": "no such thing" if setup else ""}
        metrics = {"time": i * 0.5, "position": i * 1000, "stalled": i % 3 == 0, "var 0": [1, 2][i % 2],
                   "max ap 1 0": 2**40 if i == 2 else i, "gp 0 2": 1.5 if i == 7 else i, "min ap 1 0": "x" if i == 4 else i,
                   "end_stop": False}
        row.update({k: None if setup else v for k, v in metrics.items()})
        rows.append(row)
    table = Table(mx, len(rows))
    for row in reversed(rows):
        table.add(row)
    got, want = table.frame(), pd.DataFrame(rows)
    assert list(got.columns) == list(want.columns) and got.dtypes.to_dict() == want.dtypes.to_dict()
    def equal(x, y):
        return x == y or (isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y))

    for g, w in zip(got.to_dict("records"), want.to_dict("records")):
        assert g.keys() == w.keys() and all(equal(g[k], w[k]) for k in g), (g, w)


def test_an_embedded_cluster_refills_its_tasks_as_they_finish():
    # One worker, a task per scenario: more tasks than are in flight.
    m = dict(SMALL, vary=[{"name": "home", "world": "axis.0.home_switch.from", "values": [-400000, 800000, -300000, 700000, -200000]},
                          SMALL["vary"][1]])
    serial = tmclsim.sweep(HOMING, m, workers=0)
    parallel = tmclsim.sweep(HOMING, m, workers=1, batch=1)
    assert len(serial) == 10 and same(serial, parallel)
