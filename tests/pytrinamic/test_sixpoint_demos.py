"""Software nobody here wrote, on the sixPoint modules (TMC5130/TMC5160)
and the TMC4361A modules and the eight-point modules (TMC5240):
PyTrinamic's own demo scripts for the TMCM-1210, 1211, 1240, 1241, 1260,
1270, 1276, 1278, 6212 and 6214, for the TMCM-1316, 1321, 1370, 1378,
3312, 3351 and the TMCM-123x (TMCM-1230 and 1231 run the demos of
PyTrinamic's TMCM123x_0_1, the TMCL ones: not those in its CANopen
folder), and for the TMCM-1290 and 3216, from its source distribution on
PyPI
(pytrinamic_examples.sdist_dir), unchanged, against served modules at
speed 1, as a user runs them against the real ones.

- rotate_demo.py of every module: rotates, stops, (most of them) doubles
  the distance, moves back to 0. It prints each step it announces and ends
  at 0 on every motor it drives.
- six_point_ramp_demo.py (TMCM-1210, 1211, 1276, 1278, 6214): sets the
  sixPoint ramp (VSTART, A1, V1, AMAX, VMAX, DMAX, D1, VSTOP, the ramp
  wait), moves to 100 000 and back to 0 while sampling position and
  velocity, and plots them. The sampled velocity shows each phase with its
  own slope, the cruise at VMAX, the ramp wait between the moves
  (`ramp_phases`), and the motor ends at 0.
- eight_point_ramp_demo.py (TMCM-1290, 3216): the same moves with the
  eight-point ramp. The demo writes A1 and V1 twice (5000/10 000, then
  15 000/20 000, evidently meant for A2 and V2) and never A2 or V2, so the
  module runs A1 15 000 up to V1 20 000 and A2, V2, D2 as the profile's
  defaults leave them (V2 = 0: no A2/D2 band, the sixPoint ramp; the
  demo's D2 is unused). The check takes the slopes the module really runs:
  the demo's last writes over the profile's defaults (`served_ramp`).
- stop_switch_demo.py (TMCM-1276, 1278, 1290, 3216): rotates until the
  right stop switch stops the motor, then rotates back
  (sixpoint_stop_switch_world.toml).
- StallGuard2_demo.py (TMCM-1240, 1241, 6214, 1230, 1231): calibrates
  stallGuard2, then waits until a load stops the motor
  (sixpoint_stallguard2_world.toml).
- s_shaped_ramp_demo.py (TMCM-1316, 1321, 1370, 1378): sets the TMC4361A's
  S-shaped ramp (AP 14 = 1; the bows, VSTART, AMAX, DMAX, …), moves to
  100 000 and straight back to 0 while sampling position and velocity, and
  plots them. The sampled acceleration has no jump a bow does not explain
  (`acceleration_jumps`: a trapezoid's corners are jumps), and the motor
  ends at 0.

A demo that names its own connection (PCAN, a serial port chosen
interactively) gets the served module's: run_demo.py runs it with every
ConnectionManager given the test's arguments, the pty with serial_tmcl
for the demos written for a serial line (USB, PyTrinamic's default, or
serial_tmcl), TCP for the ones written for CAN. Its plot goes to PNG and
JSON files (run_demo.py) instead of a window. Each demo must run to its
end: exit status 0, no traceback, no TMCL status error.
"""

import json
import os
import re
import statistics
import subprocess
import sys
from dataclasses import dataclass

import pytest
from pytrinamic_examples import HERE, DownloadFailed, run_example, sdist_dir
from pytrinamic_links import connect, connection_arguments, wait_until
from tmclsim_binary import tmclsim_binary

SIXPOINT_MODULES = [1210, 1211, 1240, 1241, 1260, 1270, 1276, 1278, 6212, 6214]
TMC4361A_MODULES = [1316, 1321, 1370, 1378, 3312, 3351, 1230, 1231]
EIGHTPOINT_MODULES = [1290, 3216]
MODULES = SIXPOINT_MODULES + TMC4361A_MODULES + EIGHTPOINT_MODULES
ROTATE = "rotate_demo.py"
SIX_POINT = "six_point_ramp_demo.py"
EIGHT_POINT = "eight_point_ramp_demo.py"
STOP_SWITCH = "stop_switch_demo.py"
STALLGUARD2 = "StallGuard2_demo.py"
S_SHAPED = "s_shaped_ramp_demo.py"
# The modules whose examples have the demo besides rotate_demo.py.
SIX_POINT_MODULES = [1210, 1211, 1276, 1278, 6214]
EIGHT_POINT_MODULES = [1290, 3216]
STOP_SWITCH_MODULES = [1276, 1278, 1290, 3216]
STALLGUARD2_MODULES = [1240, 1241, 6214, 1230, 1231]
S_SHAPED_MODULES = [1316, 1321, 1370, 1378]
RAMP_DEMOS = [(m, SIX_POINT) for m in SIX_POINT_MODULES] + [(m, EIGHT_POINT) for m in EIGHT_POINT_MODULES]
DEMOS = (
    [(m, ROTATE) for m in MODULES]
    + RAMP_DEMOS
    + [(m, STOP_SWITCH) for m in STOP_SWITCH_MODULES]
    + [(m, STALLGUARD2) for m in STALLGUARD2_MODULES]
    + [(m, S_SHAPED) for m in S_SHAPED_MODULES]
)
# The examples folder of a module whose demos PyTrinamic files under
# another name than TMCM<number> (its TMCL demos, not the CANopen ones).
EXAMPLE_FOLDERS = {1230: "TMCM123x_0_1", 1231: "TMCM123x_0_1"}
RUNNER = HERE / "run_demo.py"
STOP_SWITCH_WORLD = HERE / "sixpoint_stop_switch_world.toml"
STALLGUARD2_WORLD = HERE / "sixpoint_stallguard2_world.toml"
# The world files' numbers the checks use (the files explain them).
RIGHT_SWITCH = (100000, 120000)
TIGHT_SPOT = (40000, 40200)

# A demo that takes longer is killed: at speed 1 they take 6 to 42 s.
TIMEOUT = 120
# What a failed run prints as a TMCL status error (PyTrinamic's
# TMCLReplyStatusError and its reply's description) or a traceback.
FAILURE = re.compile(r"Traceback|TMCLReply\w*Error|status\W+(error|code)", re.IGNORECASE)

# The sixPoint ramp's fit (`ramp_phases`). A phase's slope is compared with
# the demo's value within half a register unit of the chip's acceleration
# (rule 104 rounds pps² to whole register units, a_unit = f_CLK²/2^41, 116
# pps² at 16 MHz) plus SLOPE_TOLERANCE of the value: the sampling's jitter
# (the median fit below is within 0.1 % on an idle machine). Mixing the
# demo's accelerations up (D1 5000 against DMAX 20 000, A1 against AMAX)
# is off by a factor of 4 or more.
SLOPE_TOLERANCE = 0.03
# The fewest samples strictly inside a phase's velocity band (thousands on
# an idle machine: a sample takes three requests).
MIN_PHASE_SAMPLES = 20
# The ramp wait between the two moves is measured between the last moving
# sample of one and the first of the next: at least the wait minus what a
# late sample explains, at most the wait plus sampling gaps on a busy
# machine. Without the wait the gap is one loop turn, milliseconds.
WAIT_EARLY, WAIT_LATE = 0.1, 0.9


@pytest.fixture(scope="session")
def sdist():
    """PyTrinamic's source distribution, unpacked."""
    try:
        return sdist_dir()
    except DownloadFailed as e:
        pytest.skip(f"PyTrinamic's source distribution (with its examples) could not be downloaded from the package registry: {e}")


def demo_path(sdist, module, script):
    return sdist / "examples" / "modules" / EXAMPLE_FOLDERS.get(module, f"TMCM{module}") / "TMCL" / script


def own_connection(text):
    """The argument string the demo passes to ConnectionManager, or None
    (the command line, PyTrinamic's default usb_tmcl)."""
    m = re.search(r"ConnectionManager\(\s*(?:\"([^\"]*)\"|'([^']*)')?", text)
    if not m:
        raise AssertionError("the demo makes no ConnectionManager")
    given = m.group(1) if m.group(1) is not None else m.group(2)
    return given


def link_for(text):
    """The served link a demo runs on: the pty (serial_tmcl) when it was
    written for a serial line (USB, serial_tmcl, PyTrinamic's default),
    TCP when it was written for CAN."""
    given = own_connection(text)
    return "pty" if not given or re.search(r"\b(serial_tmcl|usb_tmcl)\b", given) else "tcp"


@dataclass
class Demo:
    module: int
    script: str
    text: str
    link: str
    served: object
    run: object
    connections: list
    figures: object

    def report(self):
        return (
            f"TMCM-{self.module} {self.script} over {self.link} (the demo's own connection {self.connections!r}): "
            f"exit status {self.run.returncode}, {self.run.wall:.1f} s\n"
            f"--- stdout (last 40 lines)\n" + "\n".join(self.run.stdout.splitlines()[-40:]) + f"\n--- stderr\n{self.run.stderr}"
        )

    def lines(self):
        return [line for line in self.run.stdout.splitlines() if line.strip()]


def run_demo(sdist, serve, tmp_path, module, script, world="free"):
    """Serves a TMCM-`module` in `world` and runs the demo through run_demo.py
    on its link; fails unless it ran to its end without a status error."""
    path = demo_path(sdist, module, script)
    text = path.read_text(encoding="utf-8")
    link = link_for(text)
    served = serve("--module", f"tmcm-{module}", "--world", str(world))
    figures = tmp_path / "figures"
    command = [sys.executable, str(RUNNER), "--figures", str(figures)]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    try:
        run = run_example(command, path, served.tcp, TIMEOUT, connection=connection_arguments(served, link), env=env)
    except subprocess.TimeoutExpired as e:
        pytest.fail(
            f"TMCM-{module} {script} over {link} did not end within {TIMEOUT} s (killed); its last output:\n"
            + "\n".join((e.stdout or "").splitlines()[-20:]) + f"\n--- stderr\n{e.stderr or ''}"
        )
    connections = json.loads((figures / "connections.json").read_text()) if (figures / "connections.json").exists() else []
    demo = Demo(module, script, text, link, served, run, connections, figures)
    assert run.returncode == 0, demo.report()
    bad = [line for line in (run.stdout + run.stderr).splitlines() if FAILURE.search(line)]
    assert not bad, f"{bad}\n{demo.report()}"
    assert connections, f"the demo made no ConnectionManager through the runner\n{demo.report()}"
    return demo


def read_axis(served, link, axis, *numbers):
    """Axis parameters of the served module (signed), read after the demo."""
    with connect(served, link) as interface:
        return [interface.get_axis_parameter(n, axis, signed=True) for n in numbers]


def wait_for_standstill(served, link, axis):
    """Waits until the motor on `axis` stands (AP 3 is 0); returns its
    position (AP 1)."""
    with connect(served, link) as interface:
        wait_until(lambda: interface.get_axis_parameter(3, axis, signed=True) == 0, what=f"motor {axis} to stand",
                   seen=lambda: interface.get_axis_parameter(3, axis, signed=True))
        return interface.get_axis_parameter(1, axis, signed=True)


def test_every_demo_is_in_the_source_distribution(sdist):
    """The demos this suite runs are all there (a newer PyTrinamic that
    drops or renames one fails here, naming it)."""
    missing = [f"TMCM{m}/TMCL/{s}" for m, s in DEMOS if not demo_path(sdist, m, s).exists()]
    assert not missing, f"not in PyTrinamic's source distribution: {missing}"


# ---------------------------------------------------------------- rotate


@pytest.mark.slow
@pytest.mark.parametrize("module", MODULES, ids=lambda m: f"TMCM-{m}")
def test_rotate_demo(module, sdist, serve, tmp_path):
    """rotate_demo.py rotates, stops, (most of them) doubles the distance
    and moves back: it reports each step it announces (TMCM-1316's does
    not double the distance) and every motor it drives ends at position
    0."""
    demo = run_demo(sdist, serve, tmp_path, module, ROTATE)
    out = demo.run.stdout.lower()
    announced = demo.text.lower()
    for step in ("rotating", "stopping", "doubling moved distance", "furthest point reached", "moving back to 0", "reached position 0"):
        if step in announced or step in ("rotating", "stopping", "moving back to 0", "reached position 0"):
            assert step in out, f"no {step!r} in the output\n{demo.report()}"
    axes = sorted({int(n) for n in re.findall(r"module\.motors\[(\d+)\]", demo.text)})
    for axis in axes:
        position, velocity, reached = read_axis(demo.served, demo.link, axis, 1, 3, 8)
        assert (position, velocity, reached) == (0, 0, 1), f"motor {axis}: position {position}, speed {velocity}, reached {reached}\n{demo.report()}"


# ------------------------------------------------ sixPoint and eight-point ramps


def demo_parameters(text):
    """The axis parameters the demo sets by name, the last write of each:
    {"A1": 5000, …}."""
    return {name: int(value) for name, value in re.findall(r"set_axis_parameter\(\s*motor\.AP\.(\w+)\s*,\s*(-?\d+)\s*\)", text)}


def profile_text(module):
    """What `tmclsim profile tmcm-N` prints."""
    return subprocess.run([tmclsim_binary(), "profile", f"tmcm-{module}"], capture_output=True, text=True, check=True).stdout


def motion_clock_hz(module):
    """The module's motion clock, from its profile (`tmclsim profile`)."""
    return int(re.search(r"motion_clock_hz\s+(\d+)", profile_text(module)).group(1))


def profile_defaults(module):
    """The axis parameters' power-up values, from the profile: {number: value}."""
    rows = re.findall(r"^\s*(\d+)\s+R\S*\s+-?\d+…-?\d+\s+(-?\d+)\s", profile_text(module), re.MULTILINE)
    return {int(n): int(v) for n, v in rows}


def ap_numbers(module):
    """PyTrinamic's axis parameter names of the module: {"A1": 15, …}."""
    import pytrinamic.modules as modules

    ap = getattr(modules, f"TMCM{module}")._MotorTypeA.AP
    return {name: number for name, number in vars(ap).items() if isinstance(number, int)}


def served_ramp(module, text):
    """The ramp the module runs for the demo: the demo's last write of each
    parameter over the profile's power-up values, by PyTrinamic's names
    (A2, V2 and D2 too on an eight-point module)."""
    numbers = ap_numbers(module)
    defaults = profile_defaults(module)
    p = {name: defaults[n] for name, n in numbers.items() if n in defaults}
    p.update(demo_parameters(text))
    return p


def slope(points):
    """The slope of (t, v) points, robust against a late sample: the median
    of the slopes between each point and the one half the phase later."""
    half = len(points) // 2
    return statistics.median((points[i + half][1] - points[i][1]) / (points[i + half][0] - points[i][0]) for i in range(len(points) - half))


def moves(t, v, reversals=False):
    """The runs of moving samples (velocity not 0): [[(t, v)…]…]. With
    `reversals` a sample moving the other way than its run starts a new
    run too (a demo that starts the next move without waiting)."""
    runs, run = [], []
    for ti, vi in zip(t, v):
        if vi != 0 and reversals and run and (vi > 0) != (run[-1][1] > 0):
            runs.append(run)
            run = []
        if vi != 0:
            run.append((ti, vi))
        elif run:
            runs.append(run)
            run = []
    if run:
        runs.append(run)
    return runs


def phases_of(p):
    """The phases of the ramp `p` (parameters by PyTrinamic's names) as
    (name, slope, sign, low, high): A1 from VSTART to V1, A2 from V1 to V2
    (an eight-point ramp's second knee, when p has a V2 above V1), AMAX up
    to VMAX; DMAX down to the highest knee, D2 to V1, D1 to VSTOP
    (docs/behaviour.md rules 105, 113)."""
    vstart, v1, vmax, vstop = p["StartVelocity"], p["V1"], p["MaxVelocity"], p["StopVelocity"]
    v2 = p.get("V2", 0)
    knee = max(v1, v2)
    phases = [("A1", p["A1"], 1, vstart, v1)]
    if v2 > v1:
        phases.append(("A2", p["A2"], 1, v1, v2))
    phases += [("AMAX", p["MaxAcceleration"], 1, knee, vmax), ("DMAX", p["MaxDeceleration"], -1, knee, vmax)]
    if v2 > v1:
        phases.append(("D2", p["D2"], -1, v1, v2))
    phases.append(("D1", p["D1"], -1, vstop, v1))
    return phases


def ramp_phases(t, v, p, clock_hz, n_moves):
    """What is wrong with a sampled sixPoint or eight-point velocity
    profile: `n_moves` moves, each starting at VSTART and running the
    phases of `phases_of(p)`, a cruise at VMAX between the way up and the
    way down; between two moves the ramp wait. `p` holds the ramp's
    parameters by PyTrinamic's names. A phase's samples are the ones
    strictly inside its velocity band, before the cruise (A1, A2, AMAX)
    or after it (DMAX, D2, D1). The top speed is VMAX, or as much below it
    as the time around the highest sample explains. An empty list when the
    profile is right."""
    vstart, v1, vmax, vstop = p["StartVelocity"], p["V1"], p["MaxVelocity"], p["StopVelocity"]
    unit = clock_hz**2 / 2**41
    phases = phases_of(p)
    found = []
    runs = moves(t, v)
    if len(runs) != n_moves:
        return [f"{len(runs)} runs of moving samples, expected {n_moves} moves: " + ", ".join(f"{r[0][0]:.3f}…{r[-1][0]:.3f} s" for r in runs)]
    for k, run in enumerate(runs):
        where = f"move {k + 1} ({run[0][0]:.3f}…{run[-1][0]:.3f} s)"
        direction = 1 if run[0][1] > 0 else -1
        if any(vi * direction < 0 for _, vi in run):
            found.append(f"{where}: changes direction without stopping")
            continue
        speed = [(ti, abs(vi)) for ti, vi in run]
        # The top: VMAX, or below it by what the motor gains or loses
        # while the highest sample and its neighbours were read (a ramp
        # that barely reaches VMAX is there for a few milliseconds only,
        # and a sample's speed is read after its time stamp, at the
        # latest when the next one is taken).
        top_index = max(range(len(speed)), key=lambda i: speed[i][1])
        top = speed[top_index][1]
        window = speed[min(top_index + 2, len(speed) - 1)][0] - speed[max(top_index - 1, 0)][0]
        short = window * max(value for name, value, *_ in phases if name in ("AMAX", "DMAX"))
        if not vmax - 1 - short <= top <= vmax + 1:
            found.append(f"{where}: top speed {top:g}, VMAX is {vmax} (the {window * 1000:.1f} ms around it explain {short:.0f} less)")
        low = min(s for _, s in speed)
        if low < min(vstart, vstop) - 1:
            found.append(f"{where}: moves at {low:g}, below VSTART {vstart} and VSTOP {vstop}")
        if not vstart - 1 <= speed[0][1] < v1:
            found.append(f"{where}: starts at {speed[0][1]:g}, not between VSTART {vstart} and V1 {v1}")
        if not vstop - 1 <= speed[-1][1] < v1:
            found.append(f"{where}: ends at {speed[-1][1]:g}, not between VSTOP {vstop} and V1 {v1}")
        cruise = [i for i, (_, s) in enumerate(speed) if s >= top - 1]
        parts = {1: speed[: cruise[0]], -1: speed[cruise[-1] + 1 :]}
        for name, value, sign, low_band, high_band in phases:
            points = [(ti, s) for ti, s in parts[sign] if low_band < s < high_band]
            if len(points) < MIN_PHASE_SAMPLES:
                found.append(f"{where}: {name}: {len(points)} samples between {low_band} and {high_band}, fewer than {MIN_PHASE_SAMPLES}")
                continue
            fitted = sign * slope(points)
            tolerance = unit / 2 + SLOPE_TOLERANCE * value
            if abs(fitted - value) > tolerance:
                found.append(f"{where}: {name}: slope {fitted:.0f} µsteps/s² over {len(points)} samples "
                             f"({points[0][0]:.3f}…{points[-1][0]:.3f} s), the demo sets {value} (±{tolerance:.0f})")
    wait = p.get("RampWaitTime", 0) * 512 / clock_hz
    for a, b in zip(runs, runs[1:]):
        gap = b[0][0] - a[-1][0]
        if not wait - WAIT_EARLY <= gap <= wait + WAIT_LATE:
            found.append(f"standstill {gap:.3f} s between moves ({a[-1][0]:.3f}…{b[0][0]:.3f} s), the ramp wait is {wait:.3f} s")
    return found


def plotted_lines(figures):
    """The dumped figure's lines by label: {"Velocity": (x, y), …}."""
    dumps = sorted(figures.glob("figure-*.json"))
    assert len(dumps) == 1, f"expected one figure shown, found {[d.name for d in dumps]}"
    found = {}
    for ax in json.loads(dumps[0].read_text())["axes"]:
        for line in ax["lines"]:
            found[line["label"]] = (line["x"], line["y"])
    return found


@pytest.mark.slow
@pytest.mark.parametrize(("module", "script"), RAMP_DEMOS, ids=lambda x: f"TMCM-{x}" if isinstance(x, int) else x.removesuffix(".py"))
def test_ramp_demo(module, script, sdist, serve, tmp_path):
    """six_point_ramp_demo.py's and eight_point_ramp_demo.py's sampled
    velocity shows the ramp the module runs for the demo's parameters
    (`served_ramp`), both ways, with the ramp wait between; the position
    rests at the first target in the wait and the motor ends at 0."""
    demo = run_demo(sdist, serve, tmp_path, module, script)
    assert (demo.figures / "figure-1.png").exists(), demo.report()
    lines = plotted_lines(demo.figures)
    t, v = lines["Velocity"]
    tp, p = lines["Position"]
    assert tp == t, "the position and the velocity are plotted over different times"
    params = served_ramp(module, demo.text)
    targets = [int(x) for x in re.findall(r"motor\.move_to\(\s*(-?\d+)\s*\)", demo.text)]
    assert targets == [100000, 0], targets
    found = ramp_phases(t, v, params, motion_clock_hz(module), len(targets))
    # The samples between the moves (the ramp wait): the motor rests on
    # the first target. A sample reads the position before the velocity:
    # the first one may have read it just before the motor arrived.
    runs = moves(t, v)
    if len(runs) == 2:
        between = [p[i] for i in range(len(t)) if runs[0][-1][0] < t[i] < runs[1][0][0]]
        if len(between) < 2 or set(between[1:]) != {float(targets[0])}:
            found.append(f"the positions at standstill between the moves are {sorted(set(between))[:10]}, not {targets[0]}")
    position, velocity, reached = read_axis(demo.served, demo.link, 0, 1, 3, 8)
    if (position, velocity, reached) != (targets[-1], 0, 1):
        found.append(f"after the demo: position {position}, speed {velocity}, reached {reached}; expected {targets[-1]}, 0, 1")
    ramp = ", ".join(f"{name} {value}" for name, value, *_ in phases_of(params))
    summary = f"{len(t)} samples over {t[-1]:.2f} s; the ramp served: {ramp}; plot {demo.figures / 'figure-1.png'}"
    assert not found, "\n".join(found) + f"\n{summary}\n{demo.report()}"


def test_the_eight_point_demo_runs_a1_to_v1_and_no_a2_band(sdist):
    """What eight_point_ramp_demo.py asks of the TMCM-1290 and 3216: its
    second writes of A1 and V1 win, A2, V2 and D2 keep the profile's
    power-up values, and V2 = 0 leaves the A2/D2 band out: A1 15 000 from
    VSTART 5000 to V1 20 000, AMAX 30 000 to VMAX 40 000, DMAX 20 000 and
    D1 5000 down to VSTOP 5000."""
    for module in EIGHT_POINT_MODULES:
        text = demo_path(sdist, module, EIGHT_POINT).read_text(encoding="utf-8")
        assert "motor.AP.A2" not in text and "motor.AP.V2" not in text, "the demo now writes A2/V2: update this test"
        p = served_ramp(module, text)
        assert (p["A1"], p["V1"], p["V2"], p["D2"]) == (15000, 20000, 0, 10000), p
        phases = [(name, value, low, high) for name, value, _, low, high in phases_of(p)]
        assert phases == [("A1", 15000, 5000, 20000), ("AMAX", 30000, 20000, 40000), ("DMAX", 20000, 20000, 40000), ("D1", 5000, 5000, 20000)], phases


def synthetic_profile(p, clock_hz, d1=None, wait=None, a2=None, step=0.002):
    """A ramp demo's run sampled every `step` s: to 100 000 and back with
    the register values of `p` (rule 104) through the phases of
    `phases_of(p)`, optionally with another D1, A2 or ramp wait."""

    def register(a):
        unit = clock_hz**2 / 2**41
        return max(1, round(a / unit)) * unit

    given = {"D1": d1, "A2": a2}
    phases = [(name, register(given.get(name) or value), sign, low, high) for name, value, sign, low, high in phases_of(p)]
    vmax = p["MaxVelocity"]
    pause = wait if wait is not None else p["RampWaitTime"] * 512 / clock_hz
    # Phase durations and distances of one move of 100 000 µsteps.
    up = [(acc, low, high) for _, acc, sign, low, high in phases if sign > 0 and high > low]
    down = [(-acc, high, low) for _, acc, sign, low, high in reversed(phases) if sign < 0 and high > low]
    down.sort(key=lambda ph: -ph[1])
    ramp = [(abs(b - a) / abs(acc), (a + b) / 2 * abs(b - a) / abs(acc)) for acc, a, b in up + down]
    cruise = (100000 - sum(d for _, d in ramp)) / vmax
    segments = [(r[0], ph) for r, ph in zip(ramp[: len(up)], up)] + [(cruise, (0, vmax, vmax))] + [(r[0], ph) for r, ph in zip(ramp[len(up) :], down)]
    t, v = [], []
    now = 0.0
    for sign in (1, -1):
        start = now
        for duration, (acc, a, _) in segments:
            end = start + duration
            while now < end:
                t.append(now)
                v.append(sign * round(a + acc * (now - start)))
                now += step
            start = end
        pause_end = now + pause
        while now < pause_end:
            t.append(now)
            v.append(0)
            now += step
    return t, v


SIX_POINT_PARAMETERS = {
    "MaxVelocity": 40000, "MaxAcceleration": 30000, "A1": 5000, "V1": 10000, "MaxDeceleration": 20000,
    "D1": 5000, "StartVelocity": 5000, "StopVelocity": 5000, "RampWaitTime": 31250,
}


def test_the_ramp_check_tells_a_wrong_phase_apart():
    """`ramp_phases` passes the demo's ramp in register units (30 000 pps²
    runs at 30 034) with a late sample, and fails a ramp that brakes with
    DMAX instead of D1 below V1, one without the ramp wait, and one that
    never reaches VMAX; with a second knee V2 it passes the eight-point
    ramp and fails one that runs AMAX instead of A2 between V1 and V2."""
    p, clock = SIX_POINT_PARAMETERS, 16_000_000
    t, v = synthetic_profile(p, clock)
    assert ramp_phases(t, v, p, clock, 2) == []
    # A sample that came 30 ms late: the median fit ignores it.
    late = list(t)
    late[100] += 0.03
    assert ramp_phases(late, v, p, clock, 2) == []
    wrong = ramp_phases(*synthetic_profile(p, clock, d1=p["MaxDeceleration"]), p, clock, 2)
    assert wrong and all(": D1: " in f for f in wrong), wrong
    no_wait = ramp_phases(*synthetic_profile(p, clock, wait=0.004), p, clock, 2)
    assert len(no_wait) == 1 and "ramp wait" in no_wait[0], no_wait
    slower = {**p, "MaxVelocity": 45000}
    assert any("top speed" in f for f in ramp_phases(t, v, slower, clock, 2))
    # The eight-point ramp: A1 to V1 10 000, A2 15 000 to V2 20 000, D2
    # 10 000 from V2 down to V1.
    eight = {**p, "A2": 15000, "V2": 20000, "D2": 10000}
    assert [name for name, *_ in phases_of(eight)] == ["A1", "A2", "AMAX", "DMAX", "D2", "D1"]
    assert ramp_phases(*synthetic_profile(eight, clock), eight, clock, 2) == []
    no_a2 = ramp_phases(*synthetic_profile(eight, clock, a2=p["MaxAcceleration"]), eight, clock, 2)
    assert no_a2 and all(": A2: " in f for f in no_a2), no_a2
    # The same run checked as if V2 were 0 (the sixPoint ramp): the
    # AMAX and DMAX bands then take in the A2 and D2 phases and fail.
    assert ramp_phases(*synthetic_profile(eight, clock), {**eight, "V2": 0}, clock, 2)
    # The eight-point demo's ramp as served (A1 15 000 to V1 20 000, no
    # A2 band) is at VMAX for 3 ms only: a sampling gap of 10 ms over the
    # top leaves the highest sample below VMAX by what the gap explains,
    # which passes; a VMAX it never reaches still fails.
    served = {**p, "A1": 15000, "V1": 20000, "V2": 0, "A2": 51200, "D2": 10000}
    t, v = synthetic_profile(served, clock, step=0.0005)
    peaks = [t[i] for i in range(len(t)) if abs(v[i]) == served["MaxVelocity"]]
    gapped = [(ti, vi) for ti, vi in zip(t, v) if not any(abs(ti - peak) < 0.005 for peak in peaks)]
    t, v = [ti for ti, _ in gapped], [vi for _, vi in gapped]
    assert max(abs(x) for x in v) < served["MaxVelocity"] - 50
    assert ramp_phases(t, v, served, clock, 2) == []
    assert any("top speed" in f for f in ramp_phases(t, v, {**served, "MaxVelocity": 41000}, clock, 2))


# ------------------------------------------------------- S-shaped ramp

# The S-shaped ramp's check (`acceleration_jumps`). The sampled velocity is
# read from a tight loop (three requests a sample, one every millisecond or
# so, its velocity in whole pps): differentiated sample by sample, it is
# noise (1 pps over 1 ms is 1000 pps²). The acceleration is sampled per
# window of ACCELERATION_WINDOW s instead: `slope` of the window's samples
# (robust against a late sample). Two windows one window apart may differ
# by what the largest bow explains over the window (bow × window) plus
# ACCELERATION_TOLERANCE, the sampling's error (measured: the demo's
# windows, a few hundred samples each, differ by at most 50 pps² more than
# the bows explain, on a machine busy with builds). A trapezoid's
# corners jump by whole accelerations (the demo's smallest, DMAX 20 000 to
# DFINAL 8000, is 12 000 pps²): with the windows ACCELERATION_STRIDE apart a
# jump lies within a sixteenth of the window from a window's edge, and the
# two windows on either side differ by nearly all of it.
ACCELERATION_WINDOW = 0.25
ACCELERATION_STRIDE = ACCELERATION_WINDOW / 8
ACCELERATION_TOLERANCE = 1500
# The fewest samples a window needs (hundreds on an idle machine).
MIN_WINDOW_SAMPLES = 10


def windowed_accelerations(run, window=ACCELERATION_WINDOW, stride=ACCELERATION_STRIDE):
    """The acceleration of a run of (t, speed) samples sampled per window:
    {k: (start, slope, samples)} for the windows [start, start + window),
    start = the run's first sample + k × `stride`, that fit into the run
    and hold MIN_WINDOW_SAMPLES."""
    found = {}
    times = [ti for ti, _ in run]
    i, k = 0, 0
    while times[0] + k * stride + window <= times[-1]:
        start = times[0] + k * stride
        while times[i] < start:
            i += 1
        j = i
        while j < len(run) and times[j] < start + window:
            j += 1
        if j - i >= MIN_WINDOW_SAMPLES:
            found[k] = (start, slope(run[i:j]), j - i)
        k += 1
    return found, k


def acceleration_jumps(t, v, bow, n_moves, window=ACCELERATION_WINDOW, tolerance=ACCELERATION_TOLERANCE):
    """What is wrong with a sampled S-shaped velocity profile of `n_moves`
    moves (each one way, the next one may follow without a standstill
    sample): a jump of the windowed acceleration (`windowed_accelerations`)
    between two windows one window apart beyond `bow` × window +
    `tolerance` (`bow`: the largest of the ramp's jerks, pps³), windows with
    too few samples, a move too short to sample. An empty list when the
    acceleration is continuous."""
    runs = moves(t, v, reversals=True)
    if len(runs) != n_moves:
        return [f"{len(runs)} runs of moving samples, expected {n_moves} moves: " + ", ".join(f"{r[0][0]:.3f}…{r[-1][0]:.3f} s" for r in runs)]
    stride = window / round(window / ACCELERATION_STRIDE)
    apart = round(window / stride)
    limit = bow * window + tolerance
    found = []
    for n, run in enumerate(runs):
        where = f"move {n + 1} ({run[0][0]:.3f}…{run[-1][0]:.3f} s)"
        windows, fitted = windowed_accelerations([(ti, abs(vi)) for ti, vi in run], window, stride)
        pairs = [(windows[k], windows[k + apart]) for k in windows if k + apart in windows]
        if not pairs:
            found.append(f"{where}: no two windows of {window} s with {MIN_WINDOW_SAMPLES} samples or more one window apart")
            continue
        if len(windows) < fitted * 0.9:
            found.append(f"{where}: {fitted - len(windows)} of {fitted} windows of {window} s with fewer than {MIN_WINDOW_SAMPLES} samples")
        a, b = max(pairs, key=lambda ab: abs(ab[1][1] - ab[0][1]))
        jump = b[1] - a[1]
        if abs(jump) > limit:
            found.append(f"{where}: the acceleration jumps from {a[1]:.0f} ({a[0]:.3f}…{a[0] + window:.3f} s, {a[2]} samples) to "
                         f"{b[1]:.0f} pps² ({b[0]:.3f}…{b[0] + window:.3f} s, {b[2]} samples): {jump:+.0f}, a bow of {bow} pps³ "
                         f"explains {bow * window:.0f} over {window} s (+{tolerance} sampling tolerance)")
    return found


def bows(params):
    """The demo's bows (AP 22-25 by PyTrinamic's names Bow1…Bow4)."""
    found = [params[f"Bow{n}"] for n in range(1, 5) if f"Bow{n}" in params]
    assert len(found) == 4, f"the demo sets the bows {found}, expected four: {params}"
    return found


@pytest.mark.slow
@pytest.mark.parametrize("module", S_SHAPED_MODULES, ids=lambda m: f"TMCM-{m}")
def test_s_shaped_ramp_demo(module, sdist, serve, tmp_path):
    """s_shaped_ramp_demo.py's sampled velocity is continuous in its
    acceleration on both moves (`acceleration_jumps` with the demo's bows),
    the first move goes up and the second down, and the motor ends at 0."""
    demo = run_demo(sdist, serve, tmp_path, module, S_SHAPED)
    assert (demo.figures / "figure-1.png").exists(), demo.report()
    lines = plotted_lines(demo.figures)
    t, v = lines["Velocity"]
    tp, p = lines["Position"]
    assert tp == t, "the position and the velocity are plotted over different times"
    params = demo_parameters(demo.text)
    assert params.get("RampType") == 1, f"the demo does not choose the S-shaped ramp: {params}"
    targets = [int(x) for x in re.findall(r"motor\.move_to\(\s*(-?\d+)\s*\)", demo.text)]
    assert targets == [100000, 0], targets
    found = acceleration_jumps(t, v, max(bows(params)), len(targets))
    runs = moves(t, v, reversals=True)
    if len(runs) == 2 and not (runs[0][0][1] > 0 > runs[1][0][1]):
        found.append(f"the first move starts at {runs[0][0][1]:g} pps, the second at {runs[1][0][1]:g}: expected up, then down")
    if max(p) > targets[0] or min(p) < targets[1]:
        found.append(f"the sampled positions reach {min(p):g}…{max(p):g}, beyond the targets {targets}")
    position, velocity, reached = read_axis(demo.served, demo.link, 0, 1, 3, 8)
    if (position, velocity, reached) != (targets[-1], 0, 1):
        found.append(f"after the demo: position {position}, speed {velocity}, reached {reached}; expected {targets[-1]}, 0, 1")
    summary = f"{len(t)} samples over {t[-1]:.2f} s; the demo's parameters {params}; plot {demo.figures / 'figure-1.png'}"
    assert not found, "\n".join(found) + f"\n{summary}\n{demo.report()}"


def synthetic_s_curve(phases, v0, a0, step=0.001):
    """A velocity profile of constant-jerk phases [(duration, jerk)] from
    speed `v0` and acceleration `a0`, sampled every `step` s in whole pps,
    one move up and the same move down."""
    t, v = [], []
    now = 0.0
    for sign in (1, -1):
        speed, acc = v0, a0
        for duration, jerk in phases:
            end = now + duration
            while now < end:
                t.append(now)
                v.append(sign * round(max(speed, 0.0)))
                speed += acc * step + jerk * step * step / 2
                acc += jerk * step
                now += step
    return t, v


# s_shaped_ramp_demo.py's ramp by PyTrinamic's names, mapped onto the
# sixPoint names `synthetic_profile` takes for the trapezoid (AP 14 = 0):
# VSTART, ASTART up to VBREAK, AMAX up to VMAX, DMAX down to VBREAK,
# DFINAL down to VSTOP (0).
S_SHAPED_AS_TRAPEZOID = {
    "MaxVelocity": 51200, "MaxAcceleration": 51200, "A1": 5000, "V1": 7000, "MaxDeceleration": 20000,
    "D1": 8000, "StartVelocity": 5000, "StopVelocity": 0, "RampWaitTime": 0,
}


def test_the_acceleration_check_tells_a_trapezoid_apart():
    """`acceleration_jumps` passes an S-curve of the demo's bows (500 pps³)
    sampled every millisecond, with a late sample; it fails the trapezoid
    with the demo's accelerations (to 100 000 and back) and an S-curve
    whose acceleration jumps by half the trapezoid's smallest corner
    midway."""
    bow = 500
    # From VSTART with AMAX cut to what BOW2 brings back to 0, up to the
    # top speed, then braking with BOW3 and BOW4 to rest (B2, B3, B34, B4).
    s_curve = [(8, -bow), (6, -bow), (1, 0), (6, bow)]
    t, v = synthetic_s_curve(s_curve, 5000, 4000)
    assert acceleration_jumps(t, v, bow, 2) == []
    late = list(t)
    late[3000] += 0.03
    assert acceleration_jumps(late, v, bow, 2) == []
    trapezoid = acceleration_jumps(*synthetic_profile(S_SHAPED_AS_TRAPEZOID, 16_000_000, step=0.001), bow, 2)
    assert len(trapezoid) == 2 and all("jumps" in f for f in trapezoid), trapezoid
    half_corner = acceleration_jumps(*synthetic_s_curve([(8, -bow), (0.001, -6000 / 0.001), (6, -bow), (1, 0), (6, bow)], 5000, 4000), bow, 2)
    assert half_corner and all("jumps" in f for f in half_corner), half_corner


# ------------------------------------------------------------ stop switch


@pytest.mark.slow
@pytest.mark.parametrize("module", STOP_SWITCH_MODULES, ids=lambda m: f"TMCM-{m}")
def test_stop_switch_demo(module, sdist, serve, tmp_path):
    """stop_switch_demo.py rotates until the right stop switch stops the
    motor on it, sees the switch pressed at its first look, and rotates
    back for 5 s: about 250 000 µsteps back from the switch."""
    demo = run_demo(sdist, serve, tmp_path, module, STOP_SWITCH, world=STOP_SWITCH_WORLD)
    assert demo.lines()[1:] == ["Preparing parameters", "Rotating", "Rotating in opposite direction"], demo.report()
    position = wait_for_standstill(demo.served, demo.link, 0)
    # Back for at least the demo's 5 s at 50 000 µsteps/s (the ramps up
    # and down take as long as they give back, both with AMAX, rule 109),
    # at most 2 s more on a busy machine.
    back = 5 * 50000
    stopped_at = (position + back - 500, position + back + 2 * 50000)
    assert stopped_at[0] <= RIGHT_SWITCH[1] and stopped_at[1] >= RIGHT_SWITCH[0], (
        f"ends at {position}: the motor stopped at {stopped_at[0]}…{stopped_at[1]}, not on the switch {RIGHT_SWITCH}\n{demo.report()}"
    )


# ------------------------------------------------------------ stallGuard2


@pytest.mark.slow
@pytest.mark.parametrize("module", STALLGUARD2_MODULES, ids=lambda m: f"TMCM-{m}")
def test_stallguard2_demo(module, sdist, serve, tmp_path):
    """StallGuard2_demo.py calibrates while the motor runs freely and ends
    when stallGuard2 stops it: at the tight spot, with the stall flag
    (AP 207 bit 0) set."""
    demo = run_demo(sdist, serve, tmp_path, module, STALLGUARD2, world=STALLGUARD2_WORLD)
    assert demo.lines()[-1] == "Motor stopped by StallGuard2!", demo.report()
    position, velocity, flags = read_axis(demo.served, demo.link, 0, 1, 3, 207)
    assert velocity == 0 and TIGHT_SPOT[0] <= position <= TIGHT_SPOT[1] and flags & 1, (
        f"after the demo: position {position} (the tight spot is {TIGHT_SPOT}), speed {velocity}, AP 207 = {flags}\n{demo.report()}"
    )
