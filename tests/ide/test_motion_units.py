"""Speeds and accelerations of the modules whose motion units are not the
TMC429's, in the browser IDE: a sixPoint module (TMC5130/TMC5160), whose
unit mode (AP 255) makes them pps (1) or the chip's registers (0), and a
pps module (the TMCM-1310), whose values are pps as written
(profiles/README.md, motion_units; docs/ide.md, Units). The TMC429's
conversion is test_ide.py's."""

import subprocess

from conftest import csv_rows, open_app, shot, tab, until_js, wait_text
from pytrinamic.connections import ConnectionManager
from tmclsim_binary import tmclsim_binary

SIXPOINT = "tmcm-1260"
F_CLK = 16_000_000
VELOCITY_UNIT = F_CLK / 2**24  # pps of one register unit (docs/behaviour.md rule 104)
ACCELERATION_UNIT = F_CLK**2 / 2**41  # pps² of one register unit


def shown(x):
    """A value as the page shows it: six significant digits at most."""
    v = float(f"{x:.6g}")
    return str(int(v)) if v == int(v) else repr(v)


def serve(start, module):
    s = start(["serve", "--module", module, "--world", "free", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"])
    s.tcp = s.printed("tcp")
    s.url = s.printed("web")
    return s


def host(served):
    return ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}").connect()


def units(page, unit, fullsteps=200):
    page.select_option("[data-testid=units]", unit)
    page.fill("[data-testid=fullsteps]", str(fullsteps))
    page.dispatch_event("[data-testid=fullsteps]", "change")


def cell(page, number, column):
    """A cell of axis parameter `number`'s row of motor 0: 3 name, 4 value,
    5 unit."""
    return page.inner_text(f"[data-testid=row-ap-0-{number}] td:nth-child({column})")


def direct(page, line):
    """The reply text direct mode shows for `line`."""
    before = page.locator("[data-testid=direct-reply]").count()
    page.fill("[data-testid=direct-input]", line)
    page.press("[data-testid=direct-input]", "Enter")
    until_js(page, f"a reply to {line}", f"() => document.querySelectorAll('[data-testid=direct-reply]').length > {before}",
             "() => document.querySelectorAll('[data-testid=direct-reply]').length")
    return page.locator("[data-testid=direct-reply]").last.inner_text()


def velocity_chart(page):
    """The velocity chart's axis label and last value drawn."""
    return page.evaluate("(() => { const u = window.tmclsimCharts.charts.find((c) => c.panel.title === 'Velocity'); "
                         "return [u.axes[1].label, u.data[1][u.data[1].length - 1]]; })()")


def test_a_sixpoint_module_turns_in_pps_and_in_its_registers(page, start):
    served = serve(start, SIXPOINT)
    open_app(page, served.url)
    wait_text(page, "module-title", "t.startsWith('TMCM-1260')")
    units(page, "pps")

    # Unit mode 1 (the factory's): a speed in pps is sent as it is and read
    # back as it is; in rpm with 256 microsteps and 200 full steps.
    tab(page, "motion")
    wait_text(page, "motion-speed-unit", "t === 'pps'")
    page.fill("[data-testid=rot-speed]", "20000")
    page.click("[data-testid=ror]")
    wait_text(page, "motion-log", "t.includes('ROR 0, 20000') && t.includes('[100]')")
    wait_text(page, "ro-speed", "t === '20000'")
    assert "not read yet" not in page.inner_text("[data-testid=motion-log]")
    units(page, "rpm")
    wait_text(page, "ro-speed", f"t === '{shown(20000 * 60 / (256 * 200))}'")
    assert page.inner_text("[data-testid=motion-speed-unit]") == "rpm"

    # The grid: the sixPoint ramp's rows with their units, no TMC429 rows.
    units(page, "pps")
    tab(page, "params")
    ramp = {15: ("A1", "pps/s"), 16: ("V1", "pps"), 17: ("deceleration", "pps/s"), 18: ("D1", "pps/s"),
            19: ("VSTART", "pps"), 20: ("VSTOP", "pps"), 21: ("TZEROWAIT", "512 clocks")}
    wait_text(page, "value-ap-0-20", "t === '10'")
    for number, (name, unit) in ramp.items():
        assert name in cell(page, number, 3), (number, cell(page, number, 3))
        assert cell(page, number, 5) == unit, (number, cell(page, number, 5))
    wait_text(page, "value-ap-0-15", "t === '51200'")
    for number in (130, 138, 153, 154):
        assert page.locator(f"[data-testid=row-ap-0-{number}]").count() == 0, f"AP {number} is no sixPoint row"
    page.locator("[data-testid=row-ap-0-21]").scroll_into_view_if_needed()
    shot(page, "sixpoint-parameters")

    # Unit mode 0: the values are the chip's registers, converted with
    # f_CLK / 2^24 and f_CLK² / 2^41.
    page.fill("[data-testid=edit-ap-0-255]", "0")
    page.click("[data-testid=set-ap-0-255]")
    wait_text(page, "value-ap-0-255", "t === '0'")
    # Direct mode names the unit the unit mode selects.
    tab(page, "direct")
    assert "Maximum positioning velocity (4) = 51200 int (v·f_CLK/2^24 pps)" in direct(page, "GAP 4, 0")
    assert "Acceleration A1 (15) = 51200 int (a·f_CLK²/2^41 pps²)" in direct(page, "GAP 15, 0")
    direct(page, "SAP 255, 0, 1")
    assert "Acceleration A1 (15) = 51200 pps²" in direct(page, "GAP 15, 0")
    assert "Measured speed (29) = " in direct(page, "GAP 29, 0")
    direct(page, "SAP 255, 0, 0")
    tab(page, "params")
    wait_text(page, "value-ap-0-255", "t === '0'")
    # 30 000 pps² are register 258 (docs/behaviour.md rule 104), shown as
    # what 258 is.
    page.fill("[data-testid=edit-ap-0-15]", "30000")
    page.click("[data-testid=set-ap-0-15]")
    wait_text(page, "value-ap-0-15", f"t === '{shown(258 * ACCELERATION_UNIT)}'")
    with host(served) as interface:
        assert interface.get_axis_parameter(15, 0) == 258
    tab(page, "motion")
    register = round(20000 / VELOCITY_UNIT)
    page.fill("[data-testid=rot-speed]", "20000")
    page.click("[data-testid=ror]")
    wait_text(page, "motion-log", f"t.includes('ROR 0, {register}')")
    wait_text(page, "ro-speed", f"t === '{shown(register * VELOCITY_UNIT)}'")
    shot(page, "sixpoint-motion-registers")
    # In internal units, the register as the module reads it.
    units(page, "internal")
    wait_text(page, "ro-speed", f"t === '{register}'")
    wait_text(page, "motion-speed-unit", "t === 'int'")
    # The measured speed is pps in either mode; AP 3 is in the unit mode's.
    tab(page, "params")
    wait_text(page, "value-ap-0-3", f"t === '{register}'")
    assert (cell(page, 3, 5), cell(page, 29, 5)) == ("int", "pps")
    # Only the rows on screen are read.
    page.locator("[data-testid=row-ap-0-29]").scroll_into_view_if_needed()
    wait_text(page, "value-ap-0-29", f"t === '{int(register * VELOCITY_UNIT)}'")

    # The velocity chart draws pps, and its CSV says so.
    units(page, "pps")
    tab(page, "charts")
    until_js(page, "the velocity chart to draw the speed in pps",
             f"() => {{ const u = window.tmclsimCharts.charts.find((c) => c.panel.title === 'Velocity'); "
             f"return Math.abs(u.data[1]?.at(-1) - {register * VELOCITY_UNIT}) < 1e-6; }}",
             "() => window.tmclsimCharts.charts.find((c) => c.panel.title === 'Velocity').data[1]?.slice(-3)")
    label, last = velocity_chart(page)
    assert label == "pps" and abs(last - register * VELOCITY_UNIT) < 1e-6, (label, last)
    head, *rows = csv_rows(page, "chart-velocity-csv")
    assert head[1] == "Actual velocity (AP 3) [pps]", head
    assert abs(float(rows[-1][1]) - register * VELOCITY_UNIT) < 1e-6, rows[-1]


def test_a_pps_module_turns_in_pps_with_no_divisors(page, start):
    """The TMCM-1310: no ramp or pulse divisor to wait for; its values are
    pps, in rpm with its microstep resolution."""
    served = serve(start, "tmcm-1310")
    open_app(page, served.url)
    wait_text(page, "module-title", "t.startsWith('TMCM-1310')")
    units(page, "pps")
    tab(page, "motion")
    page.fill("[data-testid=rot-speed]", "1000")
    page.click("[data-testid=ror]")
    wait_text(page, "motion-log", "t.includes('ROR 0, 1000') && t.includes('[100]')")
    wait_text(page, "ro-speed", "t === '1000'")
    units(page, "rpm")
    wait_text(page, "ro-speed", f"t === '{shown(1000 * 60 / (256 * 200))}'")
    units(page, "internal")
    wait_text(page, "ro-speed", "t === '1000'")
    assert page.inner_text("[data-testid=motion-speed-unit]") == "pps", "the module's own values are pps"
    tab(page, "params")
    wait_text(page, "value-ap-0-4", "t !== '–'")
    assert (cell(page, 4, 5), cell(page, 5, 5)) == ("pps", "pps/s")
    units(page, "rpm")
    wait_text(page, "value-ap-0-2", f"t === '{shown(1000 * 60 / (256 * 200))}'")
    assert cell(page, 2, 5) == "rpm"


def test_a_tmc429_module_converts_with_its_divisors_as_before(page, start):
    """A TMC429 module reads AP 140, 153, 154 for its conversion and no
    unit mode."""
    served = serve(start, "tmcm-1141")
    open_app(page, served.url)
    profile = page.evaluate("() => fetch('/api/modules/0/profile').then((r) => r.json())")
    assert profile["motion_units"] == "tmc429"
    assert profile["conversion"] == {"microsteps": 140, "ramp_divisor": 153, "pulse_divisor": 154}
    units(page, "pps")
    tab(page, "motion")
    page.fill("[data-testid=rot-speed]", "51208.5")
    page.click("[data-testid=ror]")
    wait_text(page, "motion-log", "t.includes('ROR 0, 1678')")
    wait_text(page, "ro-speed", "t === '51208.5'")


def test_the_stallguard2_tool_runs_on_a_sixpoint_module_in_pps(page, start):
    """The tool's roles are the same numbers on a sixPoint module (AP 174,
    181, 206); its speeds are typed and shown in pps there, in unit mode 1
    as written."""
    served = serve(start, SIXPOINT)
    subprocess.run([tmclsim_binary(), "world", "--control", served.printed("control"), "--", "load", "0", "30"], check=True, capture_output=True)
    open_app(page, served.url)
    wait_text(page, "module-title", "t.startsWith('TMCM-1260')")
    units(page, "pps")
    tab(page, "tools")
    page.fill("[data-testid=sg-speed]", "20000")
    page.fill("[data-testid=sg-steps]", "2")
    page.click("[data-testid=sg-run]")
    page.locator("[data-testid=sg-suggestion]").wait_for(timeout=60000)
    result = page.inner_text("[data-testid=sg-result]")
    shot(page, "sixpoint-tools-stallguard")
    assert "at 20000 pps" in result and "10000 pps" in result, result
    page.click("[data-testid=sg-apply]")
    threshold = page.inner_text("[data-testid=sg-suggestion]")
    wait_text(page, "tools-message", f"t.includes('= {threshold}')")
    with host(served) as interface:
        assert interface.get_axis_parameter(181, 0) == 10000
        signed = interface.get_axis_parameter(174, 0)
        assert str(signed - (1 << 32) if signed >= 1 << 31 else signed) == threshold
