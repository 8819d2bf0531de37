"""The playground (scripts/playground): the browser IDE against virtual
modules living in the page, served as static files from a subpath by a
small file server on loopback that records every request."""

import http.server
import pathlib
import threading
import urllib.parse

import pytest
from conftest import ROOT, open_app, shot, tab, text, until_js, wait_text

PLAYGROUND = ROOT / "target" / "playground"
# Served under a subpath, as from a project's pages.
PREFIX = "/tmclsim/"

COUNTER_WITH_ERROR = """// counts in the accumulator
Start:  SAP 4, 0, 1000
Loop:   CALC ADD, 1
        WAIT TICKS, 0, 1
        JA Lop
"""


class StaticFiles:
    """target/playground at PREFIX on 127.0.0.1, on a thread; `paths` holds
    every path asked for, `missing` those that are not files."""

    def __init__(self, root):
        self.paths, self.missing = [], []
        files = self

        class Handler(http.server.SimpleHTTPRequestHandler):
            def __init__(self, *args, **kwargs):
                super().__init__(*args, directory=str(root), **kwargs)

            def translate_path(self, path):
                path = urllib.parse.urlsplit(path).path
                files.paths.append(path)
                if not path.startswith(PREFIX):
                    files.missing.append(path)
                    return str(root / "not-under-the-prefix")
                local = root / urllib.parse.unquote(path[len(PREFIX):])
                if local.is_dir():
                    local = local / "index.html"
                if not local.is_file():
                    files.missing.append(path)
                return str(local)

            def log_message(self, *args):
                pass

        self.server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}{PREFIX}"
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def stop(self):
        self.server.shutdown()
        self.server.server_close()
        self.thread.join()


@pytest.fixture
def playground():
    if not (PLAYGROUND / "index.html").is_file():
        pytest.fail(f"no playground in {PLAYGROUND}: run scripts/playground")
    files = StaticFiles(PLAYGROUND)
    yield files
    files.stop()


def test_the_playground_runs_the_ide_in_the_page_from_static_files_only(playground, page):
    requests, sockets = [], []
    page.on("request", lambda r: requests.append(r.url))
    page.on("websocket", lambda w: sockets.append(w.url))
    open_app(page, playground.url)
    assert page.evaluate("() => new window.tmclsim.Module('1141').profile") == "TMCM-1141"
    assert "in this page" in text(page, "target")
    assert page.locator("[data-testid=module-item]").count() == 1

    # A module of another profile joins the list and is picked.
    page.select_option("[data-testid=add-profile]", "tmcm-3110")
    page.click("[data-testid=add-go]")
    wait_text(page, "module-title", "t.startsWith('TMCM-3110')")
    assert page.locator("[data-testid=module-item]").count() == 2
    assert text(page, "module-count") == "2 of 2 modules"
    page.locator("[data-testid=module-item]").first.click()
    wait_text(page, "module-title", "t.startsWith('TMCM-1141')")

    # Direct mode, with a parameter's name, answered in words.
    page.fill("[data-testid=direct-input]", "SAP maximum_positioning_speed, 0, 1200")
    page.press("[data-testid=direct-input]", "Enter")
    reply = page.locator("[data-testid=direct-reply]").last
    reply.wait_for()
    assert "1200" in reply.inner_text() and "[100" in reply.inner_text(), reply.inner_text()
    shot(page, "playground-direct")

    # A parameter written in the grid is read back.
    tab(page, "params")
    page.fill("[data-testid=edit-ap-0-5]", "700")
    page.click("[data-testid=set-ap-0-5]")
    wait_text(page, "value-ap-0-5", "t === '700'")

    # The motor turns in virtual time that follows the clock; the right stop
    # switch pressed in the world stops it.
    tab(page, "motion")
    page.fill("[data-testid=rot-speed]", "400")
    page.click("[data-testid=ror]")
    wait_text(page, "ro-speed", "t === '400'")
    wait_text(page, "ro-position", "Number(t) > 1000")
    tab(page, "charts")
    until_js(page, "the position chart to draw the motor's move", "() => window.tmclsimCharts.charts[0].data[1]?.at(-1) > 1000",
             "() => window.tmclsimCharts.charts[0].data[1]?.slice(-3)")
    shot(page, "playground-charts")
    tab(page, "world")
    page.click("[data-testid=sw-right-press]")
    wait_text(page, "sw-right-state", "t === 'pressed'")
    tab(page, "motion")
    wait_text(page, "ro-speed", "t === '0'")
    assert text(page, "ro-switches").startswith("0 / 1")

    # The assembler's diagnostics at line:column; then a download and a run
    # that stops at a breakpoint.
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", COUNTER_WITH_ERROR)
    page.click("[data-testid=prog-assemble]")
    diag = page.locator("[data-testid=diagnostic]")
    diag.wait_for()
    assert "5:12: unknown label 'Lop'" in diag.inner_text()
    shot(page, "playground-program-error")
    page.evaluate("() => { const e = window.tmclEditor; e.setValue(e.getValue().replace('JA Lop', 'JA Loop')); }")
    page.click("[data-testid=prog-download]")
    wait_text(page, "prog-message", "t.includes('verified')")
    assert page.locator("[data-testid=diagnostic]").count() == 0
    page.locator(".CodeMirror-linenumber").get_by_text("4", exact=True).click()
    page.locator("[data-testid=breakpoint]").wait_for()
    page.click("[data-testid=prog-run]")
    wait_text(page, "ps-break", "t === 'at address 2'")
    assert page.get_attribute("[data-testid=editor]", "data-current-line") == "4"
    assert text(page, "ps-acc") == "1"
    page.click("[data-testid=prog-continue]")
    wait_text(page, "ps-acc", "t === '2'")
    shot(page, "playground-program")
    page.click("[data-testid=prog-stop]")
    wait_text(page, "ps-mode", "t.startsWith('stopped')")

    # Nothing but the playground's files was asked for: no API, no socket.
    assert not sockets, sockets
    assert not playground.missing, playground.missing
    origin = playground.url[: -len(PREFIX)]
    assert all(u.startswith(playground.url) for u in requests), [u for u in requests if not u.startswith(origin + PREFIX)]
    assert not [p for p in playground.paths if "/api/" in p]
    assert {PREFIX, f"{PREFIX}assets/tmclsim_bg.wasm", f"{PREFIX}assets/js/playground.js"} <= set(playground.paths)


def test_the_examples_open_from_the_menu_and_run(playground, page):
    open_app(page, playground.url)
    tab(page, "program")
    menu = page.locator("[data-testid=prog-example]")
    menu.wait_for()
    names = menu.locator("option").evaluate_all("os => os.map(o => o.value).filter(Boolean)")
    assert names == ["first-steps", "homing", "reference-searches", "stallguard"]
    for name in names:
        menu.select_option(name)
        page.wait_for_function("t => window.tmclEditor.getValue() === t", arg=(PLAYGROUND / "examples" / f"{name}.tmc").read_text())
        page.click("[data-testid=prog-assemble]")
        wait_text(page, "prog-message", "t.startsWith('assembled')")
    # stallGuard2: the motor turns until a full load stalls it; the program
    # counts the stall.
    page.click("[data-testid=prog-download]")
    wait_text(page, "prog-message", "t.includes('verified')")
    page.click("[data-testid=prog-run]")
    tab(page, "motion")
    wait_text(page, "ro-speed", "t === '500'")
    tab(page, "world")
    page.fill("[data-testid=world-load]", "100")
    page.click("[data-testid=world-load-set]")
    tab(page, "program")
    wait_text(page, "var-0", "Number(t) >= 1")
    shot(page, "playground-example")
    assert not playground.missing, playground.missing


def test_an_example_opens_from_its_address(playground, page):
    open_app(page, playground.url + "?example=homing")
    page.wait_for_function("() => window.tmclEditor.getValue().includes('Homing by reference search')")
    assert page.locator("[data-testid=panel-program]").is_visible()
    assert "timeout" in text(page, "prog-message")


def test_the_page_runs_at_the_speed_of_its_address(playground, page):
    # ?speed=50: the header says it, and the modules' tick timer (GP 132)
    # runs fifty times as fast as the page's clock.
    open_app(page, playground.url + "?speed=50")
    assert "time ×50" in text(page, "target")
    shot(page, "playground-speed")
    # Virtual time moves only when the page's timer advances it: each read
    # of the tick timer is paired with the wall time of the last advance
    # (a timer that fires late on a busy machine moves time in one bigger
    # step, never faster than 50 times the wall clock).
    page.evaluate("""() => {
      const p = window.tmclsimPage, advance = p.advanceWall.bind(p);
      window.lastAdvance = null;
      p.advanceWall = (s) => { advance(s); window.lastAdvance = performance.now(); };
    }""")
    page.wait_for_function("() => window.lastAdvance !== null")
    ticks = "() => JSON.parse(window.tmclsimPage.request('POST', '/api/modules/0/command', JSON.stringify({line: 'GGP 132, 0'}))).value"
    start = page.evaluate(f"() => [({ticks})(), window.lastAdvance]")
    page.wait_for_function(f"() => ({ticks})() - {start[0]} >= 50000")
    virtual_ms, wall_ms = page.evaluate(f"() => [({ticks})() - {start[0]}, window.lastAdvance - {start[1]}]")
    # The tick timer counts whole milliseconds: 0.1 % of the 50 virtual
    # seconds looked at. Below: a late timer loses time (at most 0.25 s of
    # wall time a step), so the pace may drop, far from 1.
    assert 10 <= virtual_ms / wall_ms <= 50.05, (virtual_ms, wall_ms)
    # A speed the binding refuses is said in the page; time keeps the wall
    # clock's pace.
    open_app(page, playground.url + "?speed=0")
    page.locator("[data-testid=notice]").wait_for()
    assert "?speed=0: speed 0 is not a positive finite number" in text(page, "notice")
    shot(page, "playground-speed-refused")
    assert "time ×" not in text(page, "target")


def test_the_reference_search_tool_runs_in_the_page(playground, page):
    open_app(page, playground.url)
    # The left stop switch near the carriage, placed in the world panel.
    tab(page, "world")
    page.select_option("[data-testid=place-which]", "left")
    page.fill("[data-testid=place-at]", "-20000")
    page.click("[data-testid=place-go]")
    wait_text(page, "world-show", "t.includes('place 0 left -20000') && !t.includes('error')")
    tab(page, "tools")
    page.select_option("[data-testid=rfs-mode]", "1")
    page.fill("[data-testid=rfs-search-speed]", "1000")
    page.click("[data-testid=rfs-start]")
    page.locator("[data-testid=rfs-position]").wait_for(timeout=30000)
    assert text(page, "rfs-state") == "not searching"
    events = page.locator("[data-testid=rfs-event]").all_inner_texts()
    assert any("left switch pressed" in e for e in events), events
    # The final position is the module's AP 1.
    final = text(page, "rfs-position")
    tab(page, "motion")
    wait_text(page, "ro-position", f"t === '{final}'")


def test_a_sixpoint_module_of_the_list_turns_in_pps_in_the_page(playground, page):
    """A TMC5160 module added from the built-in profiles: speeds in pps
    (its unit mode 1), the sixPoint ramp's rows in the grid with their
    units, a reference search at a speed typed in pps (docs/ide.md,
    Units)."""
    open_app(page, playground.url)
    page.select_option("[data-testid=units]", "pps")
    page.select_option("[data-testid=add-profile]", "tmcm-1260")
    page.click("[data-testid=add-go]")
    wait_text(page, "module-title", "t.startsWith('TMCM-1260')")
    tab(page, "motion")
    page.fill("[data-testid=rot-speed]", "1000")
    page.click("[data-testid=ror]")
    wait_text(page, "motion-log", "t.includes('ROR 0, 1000') && t.includes('[100]')")
    wait_text(page, "ro-speed", "t === '1000'")
    page.select_option("[data-testid=units]", "rpm")
    # 1000 pps of a 200-step motor at 256 microsteps.
    wait_text(page, "ro-speed", "t === '1.17188'")
    page.click("[data-testid=mst]")
    wait_text(page, "ro-speed", "t === '0'")

    page.select_option("[data-testid=units]", "pps")
    tab(page, "params")
    for number, unit in {15: "pps/s", 16: "pps", 17: "pps/s", 18: "pps/s", 19: "pps", 20: "pps", 21: "512 clocks"}.items():
        wait_text(page, f"row-ap-0-{number}", f"t.includes('{unit}')")
    page.locator("[data-testid=row-ap-0-21]").scroll_into_view_if_needed()
    wait_text(page, "value-ap-0-15", "t === '51200'")
    shot(page, "playground-sixpoint-parameters")

    # The reference search tool takes its speed in pps.
    tab(page, "world")
    page.select_option("[data-testid=place-which]", "left")
    page.fill("[data-testid=place-at]", "-5000")
    page.click("[data-testid=place-go]")
    wait_text(page, "world-show", "t.includes('place 0 left -5000') && !t.includes('error')")
    tab(page, "tools")
    page.select_option("[data-testid=rfs-mode]", "1")
    page.fill("[data-testid=rfs-search-speed]", "2000")
    page.click("[data-testid=rfs-start]")
    page.locator("[data-testid=rfs-position]").wait_for(timeout=30000)
    assert text(page, "tools-message") == "", text(page, "tools-message")
    ask = "(l) => JSON.parse(window.tmclsimPage.request('POST', '/api/modules/1/command', JSON.stringify({line: l}))).value"
    assert page.evaluate(ask, "GAP 194, 0") == 2000
    events = page.locator("[data-testid=rfs-event]").all_inner_texts()
    assert any("left switch pressed" in e for e in events), events
