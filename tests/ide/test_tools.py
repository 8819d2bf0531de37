"""The browser IDE's tuning tools (stallGuard2, coolStep, reference search)
and what its panels must show correctly: a search's state after a stop, the
world's load, one selected motor for every panel, each user variable by its
own number, a long error within the window. On a virtual module (`tmclsim
serve --web`) and, where it applies, on the same module reached over a TCP
link (`tmclsim ide --tcp`), its world changed over the control socket."""

import json
import subprocess
import time
import urllib.request

import pytest
from conftest import open_app, shot, tab, text, until, wait_text
from pytrinamic.connections import ConnectionManager
from tmclsim_binary import tmclsim_binary

TARGETS = ["virtual", "link"]


def app_url(served, start, target):
    """The app on the served module itself, or on a link to it."""
    if target == "virtual":
        return served.url
    return start(["ide", "--tcp", served.tcp, "--web", "127.0.0.1:0"], last="open:").printed("open")


def world(served, line):
    """One line of the control protocol, as `tmclsim world` sends it."""
    out = subprocess.run([tmclsim_binary(), "world", "--control", served.printed("control"), "--", *line.split()], capture_output=True, text=True, check=True)
    return out.stdout


def tmcl(served, command, type_, motor, value=0):
    """One request from a host on the module's TCP link; the reply's value
    (signed)."""
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}").connect() as interface:
        v = interface.send(command, type_, motor, value).value
    return v - (1 << 32) if v >= 1 << 31 else v


# --- correct display ---------------------------------------------------------


@pytest.mark.parametrize("target", TARGETS)
def test_a_stopped_reference_search_is_no_longer_searching(served, page, start, target):
    open_app(page, app_url(served, start, target))
    tab(page, "tools")
    wait_text(page, "rfs-state", "t === 'not searching'")
    # Mode 1: the left stop switch, far away; stopped on the way.
    page.select_option("[data-testid=rfs-mode]", "1")
    page.click("[data-testid=rfs-start]")
    wait_text(page, "rfs-state", "t === 'searching'")
    page.click("[data-testid=rfs-stop]")
    wait_text(page, "rfs-final", "t.startsWith('Stopped at position')")
    assert text(page, "rfs-state") == "not searching"
    assert tmcl(served, 13, 2, 0) == 0
    # A search started and stopped by a host shows too.
    tmcl(served, 13, 0, 0)
    wait_text(page, "rfs-state", "t === 'searching'")
    tmcl(served, 13, 1, 0)
    wait_text(page, "rfs-state", "t === 'not searching'")


def test_the_world_panel_shows_the_worlds_load(served, page):
    open_app(page, served.url)
    tab(page, "world")
    page.wait_for_function("document.querySelector('[data-testid=world-state]').textContent.includes('load 0 %')")
    world(served, "load 0 80")
    page.wait_for_function("document.querySelector('[data-testid=world-state]').textContent.includes('load 80 %')")
    page.wait_for_function("document.querySelector('[data-testid=world-load]').value === '80'")
    assert "load 80 %" in world(served, "show 0")


@pytest.mark.parametrize("target", TARGETS)
def test_one_motor_is_selected_for_every_panel(page, start, target):
    served = start(["serve", "--module", "tmcm-6110", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"])
    served.tcp, served.url = served.printed("tcp"), served.printed("web")
    open_app(page, app_url(served, start, target))
    selectors = ["param-axis", "motion-axis", "chart-axis", "tools-axis"] + (["world-axis"] if target == "virtual" else [])

    def shown():
        return [page.eval_on_selector(f"[data-testid={s}]", "e => e.value") for s in selectors]

    assert shown() == ["0"] * len(selectors)
    tab(page, "params")
    page.select_option("[data-testid=param-axis]", "2")
    assert shown() == ["2"] * len(selectors)
    page.locator("[data-testid=row-ap-2-1]").wait_for()
    tab(page, "motion")
    page.select_option("[data-testid=motion-axis]", "4")
    assert shown() == ["4"] * len(selectors)
    # The charts and the parameter grid follow: motor 4's rows and series.
    page.wait_for_function("window.tmclsimCharts.store.has('ap:4:1')")
    tab(page, "params")
    page.locator("[data-testid=row-ap-4-1]").wait_for()
    assert page.locator("[data-testid=row-ap-2-1]").count() == 0


@pytest.mark.parametrize("target", TARGETS)
def test_each_user_variable_is_named_by_its_own_number(served, page, start, target):
    url = app_url(served, start, target)
    with urllib.request.urlopen(url + "api/modules/0/profile") as r:
        rows = [x for x in json.loads(r.read())["global_parameters"] if x["bank"] == 2]
    assert len(rows) == 256 and all(x["name"] == f"User variable {x['number']}" for x in rows)
    open_app(page, url)
    tab(page, "params")
    page.check("input[name=ptable][value=global]")
    page.fill("[data-testid=param-filter]", "user variable 17")
    row = page.locator("[data-testid=row-gp-2-17] td.name")
    row.wait_for()
    assert row.inner_text() == "User variable 17"
    # The console takes the name too.
    tmcl(served, 9, 17, 2, 4321)
    tab(page, "direct")
    page.fill("[data-testid=direct-input]", "GGP user_variable_17, 2")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply]").wait_for()
    assert text(page, "direct-reply").startswith("User variable 17 (17) = 4321")


def test_a_long_error_wraps_and_the_page_stays_within_the_window(served, page):
    open_app(page, served.url)
    tab(page, "program")
    label = "Nowhere" + "AndFarAway" * 30
    page.evaluate("s => window.tmclEditor.setValue(s)", f"Start:  JA {label}\n")
    page.click("[data-testid=prog-assemble]")
    diag = page.locator("[data-testid=diagnostic]")
    diag.wait_for()
    assert label in diag.inner_text()
    assert page.viewport_size["width"] == 1280
    assert page.evaluate("document.documentElement.scrollWidth") <= 1280
    for testid in ["editor", "diagnostic", "prog-diagnostics", "prog-state"]:
        box = page.locator(f"[data-testid={testid}]").bounding_box()
        assert box["x"] + box["width"] <= 1280, (testid, box)
    # The diagnostic wraps: several lines high.
    assert diag.bounding_box()["height"] > 3 * 16
    shot(page, "program-error")


# --- tools -------------------------------------------------------------------


def stopped(served, page):
    """MST, and the motor at rest (AP 3 = 0)."""
    tmcl(served, 3, 0, 0)
    until(page, "the motor to stop after MST", lambda: tmcl(served, 6, 3, 0), lambda v: v == 0)


def stalls(served, page, speed):
    """ROR at `speed`: the motor moves, then stops by itself (a stall); then
    MST. AP 207 stays unread (a read clears it, rule 52)."""
    start = tmcl(served, 6, 1, 0)
    tmcl(served, 1, 0, 0, speed)
    until(page, f"the motor to move from {start} and stop by itself; (position, speed)", lambda: (tmcl(served, 6, 1, 0), tmcl(served, 6, 3, 0)),
          lambda seen: seen[0] != start and seen[1] == 0)
    stopped(served, page)


def runs_on(served, page, speed, seconds=1.5):
    """Whether the motor still runs `seconds` after ROR at `speed`; then stopped."""
    tmcl(served, 1, 0, 0, speed)
    # about time: no stall within 1.5 s, far longer than the ramp up to the
    # speed (about 0.3 s at the default acceleration) after which a stall
    # stops the motor (none while it accelerates, rule 78).
    time.sleep(seconds)
    running = tmcl(served, 6, 3, 0) != 0
    stopped(served, page)
    return running


@pytest.mark.parametrize("target", TARGETS)
def test_the_stallguard2_tool_suggests_the_threshold_that_detects_the_stall(served, page, start, target):
    # 30 %: a load the motor carries at its default current (AP 6 = 100).
    world(served, "load 0 30")
    open_app(page, app_url(served, start, target))
    tab(page, "tools")
    page.fill("[data-testid=sg-speed]", "500")
    page.fill("[data-testid=sg-steps]", "3")
    page.click("[data-testid=sg-run]")
    page.locator("[data-testid=sg-suggestion]").wait_for(timeout=60000)
    threshold = int(text(page, "sg-suggestion"))
    if target == "virtual":
        assert "world load 30 %" in text(page, "sg-result")
    # The run sets back what it changed.
    assert tmcl(served, 6, 174, 0) == 0 and tmcl(served, 6, 181, 0) == 0
    if target == "virtual":
        shot(page, "tools-stallguard")
    page.click("[data-testid=sg-apply]")
    wait_text(page, "tools-message", f"t.includes('= {threshold}')")
    assert tmcl(served, 6, 174, 0) == threshold and tmcl(served, 6, 181, 0) == 250
    # At this threshold the load stops the motor (a stall, AP 207); one
    # above it does not, and without the load the motor runs on.
    stalls(served, page, 500)
    assert tmcl(served, 6, 207, 0) == 1
    tmcl(served, 5, 174, 0, threshold + 1)
    assert runs_on(served, page, 500)
    tmcl(served, 5, 174, 0, threshold)
    world(served, "load 0 0")
    assert runs_on(served, page, 500)


@pytest.mark.parametrize("target", TARGETS)
def test_the_coolstep_tool_plots_the_current_within_its_band(served, page, start, target):
    tmcl(served, 5, 6, 0, 255)
    if target == "link":
        # Over a link the tool records what the module meets.
        world(served, "load 0 60")
    open_app(page, app_url(served, start, target))
    tab(page, "tools")
    for testid, value in [("cs-speed", "500"), ("cs-semin", "2"), ("cs-semax", "2"), ("cs-seimin", "0"), ("cs-up", "3"), ("cs-down", "3"),
                          ("cs-load", "80"), ("cs-steps", "4"), ("cs-dwell", "0.8")]:
        page.fill(f"[data-testid={testid}]", value)
    page.click("[data-testid=cs-run]")
    wait_text(page, "cs-result", "t.startsWith('Current scale between')")
    rows = page.evaluate("window.tmclsimTools.coolRows")
    band = page.evaluate("window.tmclsimTools.coolBand")
    # AP 6 = 255: scale 31; SEIMIN 0: down to half of it.
    assert band == {"top": 31, "bottom": 15, "lower": 64, "upper": 160}, band
    currents = [r[1] for r in rows]
    assert all(band["bottom"] <= c <= band["top"] for c in currents), rows
    if target == "virtual":
        assert [r[0] for r in rows] == [0, 20, 40, 60, 80]
        # No load: down to the minimum; the current rises with the load,
        # and where it stands above the minimum the load value is held
        # between SEMIN × 32 and (SEMIN + SEMAX + 1) × 32.
        assert currents[0] == band["bottom"], rows
        assert currents == sorted(currents) and currents[-1] > currents[0], rows
        assert all(band["lower"] <= r[4] <= band["upper"] for r in rows if r[1] > band["bottom"]), rows
        # The world's load is set back.
        assert "load 0 %" in world(served, "show 0")
        page.locator("[data-testid=cs-result]").scroll_into_view_if_needed()
        shot(page, "tools-coolstep")
    else:
        # Under 60 % the current stands above its minimum.
        assert min(currents) > band["bottom"], rows
    assert tmcl(served, 6, 172, 0) == 2 and tmcl(served, 6, 170, 0) == 2


@pytest.mark.parametrize("target", TARGETS)
def test_the_reference_search_tool_shows_the_switch_events_and_the_final_position(served, page, start, target):
    # The left stop switch near the carriage (at 0).
    world(served, "place 0 left -20000 5000")
    open_app(page, app_url(served, start, target))
    tab(page, "tools")
    # Mode 1: the left stop switch only.
    page.select_option("[data-testid=rfs-mode]", "1")
    page.fill("[data-testid=rfs-search-speed]", "1000")
    page.fill("[data-testid=rfs-switch-speed]", "200")
    page.click("[data-testid=rfs-start]")
    page.locator("[data-testid=rfs-position]").wait_for(timeout=60000)
    assert text(page, "rfs-state") == "not searching"
    assert text(page, "rfs-final").startswith("Done: final position")
    assert int(text(page, "rfs-position")) == tmcl(served, 6, 1, 0)
    assert tmcl(served, 6, 193, 0) == 1 and tmcl(served, 6, 194, 0) == 1000 and tmcl(served, 6, 195, 0) == 200
    events = page.locator("[data-testid=rfs-event]").all_inner_texts()
    assert any("left switch pressed" in e for e in events), events
    # Where the switch was hit: the last position before the zero (AP 197).
    hit = tmcl(served, 6, 197, 0)
    assert hit < 0 and f"Last reference position (AP 197) {hit}" in text(page, "rfs-final")
    if target == "virtual":
        shot(page, "tools-reference")
