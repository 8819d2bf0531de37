"""The browser IDE end to end: a real browser (Debian's chromium, driven by
Playwright), the app served by `tmclsim serve --web`, and PyTrinamic on the
module's TCP link at the same time."""

import json
import pathlib
import re
import tempfile
import urllib.error
import urllib.request

import pytest
from conftest import csv_rows, downloaded, open_app, series, shot, tab, until, until_js, wait_drawn, wait_samples
from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141

COUNTER_WITH_ERROR = """// counts in the accumulator
Start:  SAP 4, 0, 1000
Loop:   CALC ADD, 1
        WAIT TICKS, 0, 1
        JA Lop
"""


def pytrinamic(served):
    return ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}").connect()


def reads_ap_1(post_data):
    """Whether a read request's body reads AP 1 of motor 0."""
    reads = json.loads(post_data or "{}").get("reads", [])
    return any(r.get("kind") == "ap" and r.get("number") == 1 and r.get("index") == 0 for r in reads)


def test_module_list_and_filter(served, page, start):
    bus = start(["serve", "--bus", "tmcm-1141@1,tmcm-351@2,tmcm-6110@3", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"])
    open_app(page, bus.printed("web"))
    items = page.locator("[data-testid=module-item]")
    assert items.count() == 3
    # The module's name, not "351" alone: a port number in the link text
    # may hold those digits.
    page.fill("[data-testid=module-filter]", "TMCM-351")
    assert items.count() == 1
    assert "TMCM-351" in items.first.inner_text()
    items.first.click()
    page.wait_for_function("document.querySelector('[data-testid=module-title]').textContent.includes('TMCM-351')")
    page.fill("[data-testid=module-filter]", "")


def test_a_parameter_changed_in_the_grid_is_read_by_pytrinamic(served, page):
    open_app(page, served.url)
    tab(page, "params")
    page.fill("[data-testid=param-filter]", "maximum positioning speed")
    # Out of range (AP 4 takes 1…2047): refused in the app, nothing sent.
    page.fill("[data-testid=edit-ap-0-4]", "5000")
    page.click("[data-testid=set-ap-0-4]")
    assert "outside 1…2047" in page.inner_text("[data-testid=param-status]")
    page.fill("[data-testid=edit-ap-0-4]", "1234")
    page.click("[data-testid=set-ap-0-4]")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '1234'")
    with pytrinamic(served) as interface:
        assert TMCM1141(interface).motors[0].get_axis_parameter(4) == 1234
        # And the other way round: PyTrinamic writes, the grid shows it.
        TMCM1141(interface).motors[0].set_axis_parameter(4, 777)
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '777'")
    page.fill("[data-testid=param-filter]", "")
    # Only the rows on screen are read: the last readable one is read once
    # it is scrolled into view, and shows what PyTrinamic reads.
    last = page.evaluate("""() => {
        const rows = [...document.querySelectorAll('[data-testid^=row-ap-0-]')].filter((r) => r.cells[5].textContent.includes('R'));
        return Number(rows[rows.length - 1].dataset.testid.split('-').pop());
    }""")
    cell = f"[data-testid=value-ap-0-{last}]"
    # The grid's rounds of reads (POST …/read with the first row, AP 1).
    rounds = []
    page.on("requestfinished", lambda r: rounds.append(r.url) if r.url.endswith("/read") and reads_ap_1(r.post_data) else None)
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-1]').textContent !== '–'")
    # Two more rounds finished: the first of them is shown, and the last
    # row was not in it.
    before = len(rounds)
    until(page, "two more rounds of the grid's reads", lambda: len(rounds), lambda n: n >= before + 2)
    assert page.inner_text(cell) == "–"
    page.locator(cell).scroll_into_view_if_needed()
    page.wait_for_function(f"document.querySelector({cell!r}).textContent !== '–'")
    with pytrinamic(served) as interface:
        assert page.inner_text(cell) == str(TMCM1141(interface).motors[0].get_axis_parameter(last))
    page.locator("[data-testid=value-ap-0-0]").scroll_into_view_if_needed()
    shot(page, "parameters")


def test_a_move_from_pytrinamic_shows_on_the_chart_and_the_position(served, page):
    open_app(page, served.url)
    tab(page, "charts")
    with pytrinamic(served) as interface:
        TMCM1141(interface).motors[0].move_to(51200)
    page.wait_for_function("Number(document.querySelector('[data-testid=ro-position]').textContent) > 0")
    page.wait_for_function("Number(document.querySelector('[data-testid=ro-position]').textContent) === 51200", timeout=30000)
    # The position chart's last sample is the module's position.
    info = page.inner_text("[data-testid=chart-info]")
    assert re.search(r"\d+ samples", info), info
    assert page.locator("[data-testid=chart-position] canvas").count() == 1
    # The chart draws the position reached (its redraw follows the samples).
    until_js(page, "the position chart to draw 51200", "() => window.tmclsimCharts.charts[0].data[1]?.at(-1) === 51200",
             "() => window.tmclsimCharts.charts[0].data[1]?.slice(-3)")
    shot(page, "charts")
    with page.expect_download() as d:
        page.click("[data-testid=chart-csv]")
    csv = open(d.value.path()).read().splitlines()
    assert csv[0].startswith("t_s,Actual position (AP 1)")
    assert csv[-1].split(",")[1] == "51200"
    tab(page, "motion")
    assert page.inner_text("[data-testid=ro-position]") == "51200"
    shot(page, "motion")


def test_a_server_that_stopped_is_an_error_the_page_shows(served, page):
    # The page keeps running when its server goes away: each request that
    # gets no answer is shown as an error (the page fixture fails the test
    # on any error the page does not handle).
    open_app(page, served.url)
    served.stop()
    sockets = []
    page.on("websocket", lambda ws: sockets.append(ws.url))
    page.fill("[data-testid=direct-input]", "GAP 4, 0")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply]").wait_for()
    assert page.inner_text("[data-testid=direct-reply]").startswith("no answer from the server")
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", LOOP_WITH_WAIT)
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.startsWith('no answer from the server')")
    # And it goes on: its live stream, gone with the server, tries again
    # every second (api.js); two more tries without an error in the page.
    tries = len(sockets)
    until(page, "two more tries of the live stream", lambda: len(sockets), lambda n: n >= tries + 2)


def test_direct_mode_answers_in_words(served, page):
    open_app(page, served.url)
    page.fill("[data-testid=direct-input]", "SAP maximum_positioning_speed, 0, 1500")
    page.press("[data-testid=direct-input]", "Enter")
    page.fill("[data-testid=direct-input]", "GAP 4, 0")
    page.click("[data-testid=direct-send]")
    replies = page.locator("[data-testid=direct-reply]")
    replies.nth(1).wait_for()
    assert replies.nth(1).inner_text().startswith("Maximum positioning speed (4) = 1500")
    page.fill("[data-testid=direct-input]", "GPA 4, 0")
    page.press("[data-testid=direct-input]", "Enter")
    replies.nth(2).wait_for()
    assert "did you mean 'GAP'" in replies.nth(2).inner_text()
    # History: the arrow key brings the last line back; Tab completes names.
    page.press("[data-testid=direct-input]", "ArrowUp")
    assert page.input_value("[data-testid=direct-input]") == "GPA 4, 0"
    page.fill("[data-testid=direct-input]", "GAP actual_pos")
    page.press("[data-testid=direct-input]", "Tab")
    assert page.input_value("[data-testid=direct-input]") == "GAP actual_position, "
    # A mnemonic, then its symbolic operand, are completed the same way, and
    # the completed line is one the module takes.
    page.fill("[data-testid=direct-input]", "rs")
    page.press("[data-testid=direct-input]", "Tab")
    assert page.input_value("[data-testid=direct-input]") == "RS"  # RSAP, RSGP, RSUB…
    page.fill("[data-testid=direct-input]", "MVP r")
    page.press("[data-testid=direct-input]", "Tab")
    assert page.input_value("[data-testid=direct-input]") == "MVP REL, "
    page.type("[data-testid=direct-input]", "0, 0")
    page.press("[data-testid=direct-input]", "Enter")
    replies.nth(3).wait_for()
    assert "[100 " in replies.nth(3).inner_text(), replies.nth(3).inner_text()
    page.fill("[data-testid=direct-input]", "")
    shot(page, "direct")


def test_a_line_typed_while_a_command_is_on_its_way_is_kept(served, page):
    open_app(page, served.url)
    # The first command is held back until the test lets it go (a slow link).
    page.evaluate("""() => {
      const fetch = window.fetch;
      let first = true;
      window.fetch = async (url, init) => {
        if (first && String(url).endsWith("/command")) {
          first = false;
          await new Promise((r) => { window.letTheCommandGo = r; });
        }
        return fetch(url, init);
      };
    }""")
    page.fill("[data-testid=direct-input]", "GAP 4, 0")
    page.press("[data-testid=direct-input]", "Enter")
    page.fill("[data-testid=direct-input]", "GGP 65, 0")
    until_js(page, "the first command to be held", "() => !!window.letTheCommandGo", "() => String(window.letTheCommandGo)")
    page.evaluate("() => window.letTheCommandGo()")
    replies = page.locator("[data-testid=direct-reply]")
    replies.nth(0).wait_for()
    assert page.input_value("[data-testid=direct-input]") == "GGP 65, 0", "the reply did not clear the next line"
    page.press("[data-testid=direct-input]", "Enter")
    replies.nth(1).wait_for()
    entries = page.locator("[data-testid=direct-entry]")
    assert entries.nth(0).inner_text().startswith("> GAP 4, 0")
    assert entries.nth(1).inner_text().startswith("> GGP 65, 0")


def test_a_program_is_fixed_downloaded_and_stops_at_a_breakpoint(served, page):
    open_app(page, served.url)
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", COUNTER_WITH_ERROR)
    page.click("[data-testid=prog-assemble]")
    diag = page.locator("[data-testid=diagnostic]")
    diag.wait_for()
    assert "5:12: unknown label 'Lop'" in diag.inner_text() and "did you mean 'Loop'" in diag.inner_text()
    shot(page, "program-error")
    page.evaluate("() => { const e = window.tmclEditor; e.setValue(e.getValue().replace('JA Lop', 'JA Loop')); }")
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.includes('verified')")
    assert page.locator("[data-testid=diagnostic]").count() == 0
    progress = page.locator("[data-testid=prog-progress]")
    # Four words and the STOP appended after JA (docs/behaviour.md rule
    # 93): five written, five read back.
    assert progress.get_attribute("max") == progress.evaluate("p => String(p.value)") == "10"
    # A breakpoint on line 4 (WAIT TICKS), by a click on its line number.
    page.locator(".CodeMirror-linenumber").get_by_text("4", exact=True).click()
    page.locator("[data-testid=breakpoint]").wait_for()
    page.click("[data-testid=prog-run]")
    page.wait_for_function("document.querySelector('[data-testid=editor]').dataset.currentLine === '4'")
    page.wait_for_function("document.querySelector('[data-testid=ps-break]').textContent === 'at address 2'")
    assert page.inner_text("[data-testid=ps-acc]") == "1"
    assert page.locator(".cm-current-line").count() == 1
    shot(page, "program")
    page.click("[data-testid=prog-continue]")
    page.wait_for_function("document.querySelector('[data-testid=ps-acc]').textContent === '2'")
    page.click("[data-testid=prog-stop]")
    page.wait_for_function("document.querySelector('[data-testid=ps-mode]').textContent.startsWith('stopped')")
    assert page.inner_text("[data-testid=ps-break]") == "–"
    # A line inserted above moves the breakpoint with its line; after the
    # next download the program stops there, now line 5.
    page.evaluate("() => window.tmclEditor.replaceRange('// one line more\\n', { line: 0, ch: 0 })")
    page.evaluate("() => { document.querySelector('[data-testid=prog-message]').textContent = ''; }")
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.includes('verified')")
    page.click("[data-testid=prog-run]")
    # A stopped program stands at no breakpoint (its PC, 2, maps to line 5
    # with the new map before it runs), so the break is the new hit; then
    # the line it shows.
    page.wait_for_function("document.querySelector('[data-testid=ps-break]').textContent === 'at address 2'")
    assert page.get_attribute("[data-testid=editor]", "data-current-line") == "5"
    # States come as answers and by the live stream, in any order: one
    # observed before the state shown (here: the program running at address
    # 1, as the answer to "run" saw it on a busy machine) is dropped.
    dropped = page.evaluate("""() => {
      const p = window.tmclsimProgram;
      const before = Number(document.querySelector('[data-testid=ps-mode]').dataset.dropped ?? 0);
      p.showState({ mode: "running", pc: 1, waiting: false, accumulator: 1, x: 0, flags: null, stack_depth: null,
                    breakpoint: null, breakpoints: [2], user_variables: [], time: p.shownTime - 0.001 });
      return Number(document.querySelector('[data-testid=ps-mode]').dataset.dropped) - before;
    }""")
    assert dropped == 1
    assert page.inner_text("[data-testid=ps-break]") == "at address 2"
    assert page.get_attribute("[data-testid=editor]", "data-current-line") == "5"
    page.click("[data-testid=prog-stop]")


def test_a_stop_switch_pressed_in_the_world_panel_stops_the_motor(served, page):
    open_app(page, served.url)
    with pytrinamic(served) as interface:
        TMCM1141(interface).motors[0].rotate(-500)
    tab(page, "motion")
    page.wait_for_function("Number(document.querySelector('[data-testid=ro-speed]').textContent) < 0")
    tab(page, "world")
    page.click("[data-testid=sw-left-press]")
    page.wait_for_function("document.querySelector('[data-testid=sw-left-state]').textContent === 'pressed'")
    shot(page, "world")
    tab(page, "motion")
    page.wait_for_function("document.querySelector('[data-testid=ro-speed]').textContent === '0'")
    assert page.inner_text("[data-testid=ro-switches]").startswith("1 /")
    with pytrinamic(served) as interface:
        assert TMCM1141(interface).motors[0].actual_velocity == 0


def test_io_panel_sets_an_output_and_shows_inputs(served, page):
    open_app(page, served.url)
    tab(page, "world")
    page.click("[data-testid=world-in-1]")
    tab(page, "io")
    page.wait_for_selector("[data-testid=in-1].on")
    page.click("[data-testid=out-0]")
    page.wait_for_selector("[data-testid=out-0].on")
    with pytrinamic(served) as interface:
        # GIO 0, 2 reads the output back over the host's link.
        assert interface.send(15, 0, 2, 0).value == 1
    shot(page, "io")


def test_ide_against_a_served_module_over_tcp(served, page, start):
    ide = start(["ide", "--tcp", served.tcp, "--web", "127.0.0.1:0"], last="open:")
    open_app(page, ide.printed("open"))
    assert "TMCL link" in page.inner_text("[data-testid=target]")
    assert "TMCM-1141" in page.inner_text("[data-testid=module-item]")
    page.fill("[data-testid=direct-input]", "GAP 1, 0")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply]").wait_for()
    assert page.inner_text("[data-testid=direct-reply]").startswith("Actual position (1) = 0")
    tab(page, "world")
    assert page.is_visible("#world-none")
    assert not page.is_visible("#world-controls")
    # A program over TMCL: downloaded and verified, a breakpoint reached by
    # single steps; flags and stack depth are not in TMCL's answers.
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", COUNTER_WITH_ERROR.replace("JA Lop", "JA Loop"))
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.includes('verified')")
    page.locator(".CodeMirror-linenumber").get_by_text("4", exact=True).click()
    page.click("[data-testid=prog-run]")
    page.wait_for_function("document.querySelector('[data-testid=editor]').dataset.currentLine === '4'")
    page.wait_for_function("document.querySelector('[data-testid=ps-acc]').textContent === '1'")
    assert page.inner_text("[data-testid=ps-flags]") == "not reported over TMCL"
    assert page.inner_text("[data-testid=ps-stack]") == "not reported over TMCL"
    with pytrinamic(served) as interface:
        # The module the app drives over TMCL is the served one: 135 type 1
        # answers mode << 24 | waiting << 16 | program counter (behaviour
        # rule 17): in step mode, on the breakpoint's address.
        status = interface.send(135, 1, 0, 0).value
        assert (status >> 24, status & 0xFFFF) == (2, 2)
    page.click("[data-testid=prog-stop]")


def test_a_foreign_origin_is_refused(served):
    req = urllib.request.Request(served.url + "api/modules", headers={"Origin": "http://attacker.example"})
    try:
        urllib.request.urlopen(req)
        raise AssertionError("a foreign origin was served")
    except urllib.error.HTTPError as e:
        assert e.code == 403
        assert "refused" in json.loads(e.read())["error"]


def test_a_drag_zooms_and_pauses_the_view_while_the_samples_keep_coming(served, page):
    open_app(page, served.url)
    tab(page, "charts")
    wait_samples(page, 50)
    box = page.locator("[data-testid=chart-position] .u-over").bounding_box()
    y = box["y"] + box["height"] / 2
    page.mouse.move(box["x"] + box["width"] * 0.2, y)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] * 0.6, y, steps=5)
    page.mouse.up()
    assert page.inner_text("[data-testid=chart-pause]") == "Resume"
    view = "(() => { const u = window.tmclsimCharts.charts[0]; return [u.data[0].length, u.scales.x.min, u.scales.x.max]; })()"
    kept = page.evaluate("window.tmclsimCharts.t.length")
    frozen = page.evaluate(view)
    # 20 samples at 50 a second: several of the charts' redraws (every 100 ms).
    until_js(page, "paused: the samples keep coming", "(n) => window.tmclsimCharts.t.length >= n",
             "() => `${window.tmclsimCharts.t.length} samples`", arg=kept + 20)
    assert page.evaluate(view) == frozen, "paused and zoomed: the view stays"
    page.click("[data-testid=chart-pause]")
    page.wait_for_function(f"window.tmclsimCharts.charts[0].data[0].length > {frozen[0]}")
    # The samples taken while paused are drawn: no hole in the time axis.
    t = page.evaluate("window.tmclsimCharts.charts[0].data[0]")
    assert max(b - a for a, b in zip(t, t[1:])) < 0.3, "a hole where the view was paused"


def test_an_added_signal_starts_with_gaps_never_an_invented_zero(served, page):
    open_app(page, served.url)
    tab(page, "charts")
    wait_samples(page, 20)
    page.select_option("[data-testid=chart-add]", "ap:0:4")
    page.wait_for_function("(window.tmclsimCharts.store.get('ap:0:4') || []).filter((v) => v !== null).length >= 20")
    added, position = page.evaluate("['ap:0:4', 'ap:0:1'].map((k) => window.tmclsimCharts.store.get(k))")
    # The maximum positioning speed is 1000 from power-up: every value
    # read is 1000, and before the signal was added there are gaps.
    assert added[0] is None, "nothing was read before the signal was added"
    assert {v for v in added if v is not None} == {1000}, "a value that was never read"
    assert len(position) == len(added) and position[0] is not None, "the other series go on"
    head, *rows = csv_rows(page, "chart-added-csv")
    assert head == ["t_s", "Maximum positioning speed (AP 4) [int]"]
    assert rows[0][1] == "" and rows[-1][1] == "1000", "a gap is an empty cell"


def test_each_scale_group_has_its_own_axis(served, page):
    open_app(page, served.url)
    tab(page, "charts")
    wait_samples(page, 20)
    wait_drawn(page, 20)
    axes = page.evaluate("""Object.fromEntries(window.tmclsimCharts.charts.map((u) => [u.panel.title,
        u.axes.slice(1).map((a) => ({ scale: a.scale, label: a.label, min: u.scales[a.scale].min, max: u.scales[a.scale].max }))]))""")
    drawn_on = page.evaluate("Object.fromEntries(window.tmclsimCharts.charts.map((u) => [u.panel.title, u.series.slice(1).map((s) => s.scale)]))")
    # Load (0…1023) and current (0…31) each on their own axis.
    load = axes["Load and current"]
    assert [a["label"] for a in load] == ["0…1023", "0…31"], load
    assert drawn_on["Load and current"] == [load[0]["scale"], load[1]["scale"]] and load[0]["scale"] != load[1]["scale"]
    # Switches (0/1) on an axis that spans 0 and 1, not 0…100.
    [switches] = axes["Switches"]
    assert switches["min"] > -1 and switches["max"] < 2, switches
    assert drawn_on["Switches"] == [switches["scale"]] * 3
    [position] = axes["Position"]
    assert position["label"] == "µsteps" and drawn_on["Position"] == [position["scale"]] * 2, "actual and target share one axis"


def test_every_chart_exports_png_and_csv(served, page):
    open_app(page, served.url)
    tab(page, "charts")
    wait_samples(page, 50)
    titles = page.evaluate("window.tmclsimCharts.panels.map((p) => p.title.toLowerCase().replace(/\\W+/g, '-'))")
    assert titles == ["position", "velocity", "load-and-current", "switches", "outputs"]
    for name in titles:
        assert page.inner_text(f"[data-testid=chart-{name}-png]") == "PNG"
        assert page.inner_text(f"[data-testid=chart-{name}-csv]") == "CSV"
    png = downloaded(page, "chart-position-png")
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 2000
    head, *rows = csv_rows(page, "chart-position-csv")
    assert head == ["t_s", "Actual position (AP 1)", "Target position (AP 0)"]
    t = [float(r[0]) for r in rows]
    # Seconds: 50 samples a second (the rate chosen) are 0.02 s apart.
    steps = sorted(b - a for a, b in zip(t, t[1:]))
    assert 0.01 < steps[len(steps) // 2] < 0.05, steps[len(steps) // 2]
    head, *rows = csv_rows(page, "chart-switches-csv")
    assert len(head) == 4 and all(set(r[1:]) <= {"0", "1"} for r in rows)


FLEET = """world = "stage"
[[link]]
pty = "{dir}/bus"
count = 4
bus = "tmcm-1141"
size = 250
"""


@pytest.fixture
def fleet_dir():
    """A short, neutral directory for the fleet's ptys (shown in the list);
    requested before `start`, so removed after the fleet has stopped."""
    with tempfile.TemporaryDirectory(prefix="tmclsim-fleet-") as d:
        yield pathlib.Path(d)


def test_one_module_found_among_a_thousand(page, fleet_dir, start):
    tmp_path = fleet_dir
    fleet = tmp_path / "fleet.toml"
    fleet.write_text(FLEET.format(dir=tmp_path))
    served = start(["serve", "--fleet", str(fleet), "--web", "127.0.0.1:0"])
    open_app(page, served.printed("web"))
    items = page.locator("[data-testid=module-item]")
    assert page.inner_text("[data-testid=module-count]") == "1000 of 1000 modules (first 200 shown)"
    assert items.count() == 200
    page.fill("[data-testid=module-filter]", "bus-3")
    assert page.inner_text("[data-testid=module-count]").startswith("250 of 1000")
    # A word that is an address brings that module first.
    page.fill("[data-testid=module-filter]", "bus-3 250")
    assert "address 250" in items.first.inner_text() and "bus-3" in items.first.inner_text()
    # While the picked module's profile is on its way, the panels still act
    # on the module picked before: the title still names that one, so a
    # command typed meanwhile goes where the title says.
    held = []
    page.route("**/api/modules/*/profile", lambda route: held.append(route))
    items.first.click()
    until(page, "the picked module's profile request", lambda: len(held))
    assert "address 1 " in page.inner_text("[data-testid=module-title]")
    page.fill("[data-testid=direct-input]", "SAP 4, 0, 1111")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply]").wait_for()
    for route in held:
        route.continue_()
    page.unroute("**/api/modules/*/profile")
    page.wait_for_function("document.querySelector('[data-testid=module-title]').textContent.includes('address 250')")
    page.fill("[data-testid=direct-input]", "SAP 4, 0, 1250")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply] >> nth=1").wait_for()
    page.fill("[data-testid=module-filter]", "250")
    assert items.count() == 4  # address 250 of each bus
    shot(page, "modules")
    # The app talked to module 250 of the fourth bus, and to no other.
    with ConnectionManager(f"--interface serial_tmcl --port {tmp_path}/bus-3 --module-id 250").connect() as interface:
        assert interface.get_axis_parameter(4, 0) == 1250
    with ConnectionManager(f"--interface serial_tmcl --port {tmp_path}/bus-0 --module-id 250").connect() as interface:
        assert interface.get_axis_parameter(4, 0) != 1250
    with ConnectionManager(f"--interface serial_tmcl --port {tmp_path}/bus-0 --module-id 1").connect() as interface:
        assert interface.get_axis_parameter(4, 0) == 1111


def test_charts_follow_a_chosen_motor_and_the_world_sets_an_analog_input(page, start):
    served = start(["serve", "--module", "tmcm-6110", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"])
    open_app(page, served.printed("web"))
    tab(page, "charts")
    wait_samples(page, 10)
    page.select_option("[data-testid=chart-axis]", "2")
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.printed('tcp')}").connect() as interface:
        interface.send(1, 0, 2, 300)  # ROR 2, 300
        until(page, "motor 2 at speed 300", lambda: interface.get_axis_parameter(3, 2), lambda v: v == 300)
        other = interface.get_axis_parameter(3, 0)
    until_js(page, "motor 2's speed 300 in the charts", "() => (window.tmclsimCharts.store.get('ap:2:3') || []).at(-1) === 300",
             "() => (window.tmclsimCharts.store.get('ap:2:3') || []).slice(-5)")
    # Motor 2's series start where it was chosen, with gaps before (never a
    # 0 that was not read); motor 0's samples are kept.
    motor2, motor0 = series(page, "ap:2:3"), series(page, "ap:0:3")
    assert motor2[0] is None and motor2[-1] == 300
    assert motor0[0] == 0 and motor0[-1] is None
    assert all(v is not None for v in motor2[motor2.index(300):]), "read every sample since"
    head, *rows = csv_rows(page, "chart-csv")
    assert "Actual speed (AP 3; motor 2) [int]" in head, head
    assert not any("motor 0" in h for h in head)
    assert int(rows[-1][head.index("Actual speed (AP 3; motor 2) [int]")]) == 300 != other
    # An ADC value set in the world is what GIO N, 1 reads in the IO panel.
    tab(page, "world")
    page.select_option("[data-testid=world-analog]", "4")
    page.fill("[data-testid=world-analog-value]", "3071")
    page.click("[data-testid=world-analog-set]")
    tab(page, "io")
    page.wait_for_function("document.querySelector('[data-testid=analog-1-4] .value').textContent === '3071'")
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.printed('tcp')}").connect() as interface:
        assert interface.send(15, 4, 1, 0).value == 3071


def test_a_public_address_needs_the_token(page, start):
    served = start(["serve", "--tcp", "127.0.0.1:0", "--web", "0.0.0.0:0", "--web-public"])
    url = served.printed("web").replace("0.0.0.0", "127.0.0.1")
    base, token = url.split("?token=")
    try:
        urllib.request.urlopen(base + "api/modules")
        raise AssertionError("served without the token")
    except urllib.error.HTTPError as e:
        assert e.code == 403
    # The page opened with the token keeps it (a cookie) for the API and
    # the live stream.
    open_app(page, url)
    tab(page, "motion")
    page.wait_for_function("document.querySelector('[data-testid=ro-position]').textContent === '0'")
    with urllib.request.urlopen(f"{base}api/modules?token={token}") as r:
        assert json.loads(r.read())[0]["profile"] == "TMCM-1141"


LOOP_WITH_WAIT = """Loop:   CALC ADD, 1
        WAIT TICKS, 0, 50
        CALC ADD, 10
        JA Loop
"""


def current_line(page, line):
    page.wait_for_function(f"document.querySelector('[data-testid=editor]').dataset.currentLine === '{line}'")


@pytest.mark.parametrize("target", ["virtual", "link"])
def test_a_breakpoint_stops_the_loop_every_time_and_a_waiting_wait_is_the_current_line(served, page, start, target):
    url = served.url
    if target == "link":
        url = start(["ide", "--tcp", served.tcp, "--web", "127.0.0.1:0"], last="open:").printed("open")
    open_app(page, url)
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", LOOP_WITH_WAIT)
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.includes('verified')")
    # On the line after the WAIT: every pass of the loop stops there.
    page.locator(".CodeMirror-linenumber").get_by_text("3", exact=True).click()
    page.locator("[data-testid=breakpoint]").wait_for()
    page.click("[data-testid=prog-run]")
    # The break itself is what to wait for: a running program passes
    # address 2 (line 3) on every turn, on a link between two steps too,
    # and the accumulator has its value during the WAIT before the break.
    at_break = (
        "acc => document.querySelector('[data-testid=ps-break]').textContent === 'at address 2'"
        " && document.querySelector('[data-testid=ps-acc]').textContent === acc"
    )
    for acc in ["1", "12", "23"]:
        page.wait_for_function(at_break, arg=acc)
        current_line(page, 3)
        page.click("[data-testid=prog-continue]")
    page.wait_for_function(at_break, arg="34")
    # Single steps: onto the WAIT, then into it; while it waits the WAIT's
    # line is the current one (the counter holds its address, rule 35).
    page.click("[data-testid=prog-step]")
    page.click("[data-testid=prog-step]")
    page.click("[data-testid=prog-step]")
    current_line(page, 2)
    page.click("[data-testid=prog-step]")
    page.wait_for_function("document.querySelector('[data-testid=ps-mode]').textContent.includes('(WAIT)')")
    current_line(page, 2)
    assert page.inner_text("[data-testid=ps-pc]") == "1"
    page.click("[data-testid=prog-stop]")


def test_a_link_is_scanned_a_program_read_back_and_the_version_shown(page, start):
    bus = start(["serve", "--bus", "tmcm-1141@1,tmcm-351@7", "--tcp", "127.0.0.1:0"])
    ide = start(["ide", "--tcp", bus.printed("tcp"), "--bus-addresses", "1,5", "--web", "127.0.0.1:0"], last="open:")
    open_app(page, ide.printed("open"))
    assert page.locator("[data-testid=module-item]").count() == 1
    page.click("[data-testid=scan-go]")
    page.locator("[data-testid=scan-item]").nth(1).wait_for()
    items = page.locator("[data-testid=scan-item]").all_inner_texts()
    assert "TMCM-1141 · address 1" in items[0] and "1141V146" in items[0]
    assert "TMCM-351 · address 7" in items[1] and "351V.445" in items[1] and "not listed" in items[1]
    page.fill("[data-testid=direct-input]", "#136 0 0 0")
    page.press("[data-testid=direct-input]", "Enter")
    page.locator("[data-testid=direct-reply]").wait_for()
    assert page.inner_text("[data-testid=direct-reply]") == "version 1141V146"
    tab(page, "program")
    page.evaluate("s => window.tmclEditor.setValue(s)", LOOP_WITH_WAIT)
    page.click("[data-testid=prog-download]")
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.includes('verified')")
    page.evaluate("() => window.tmclEditor.setValue('')")
    page.click("[data-testid=prog-read]")
    # The four words and the STOP appended after JA (docs/behaviour.md rule 93).
    page.wait_for_function("document.querySelector('[data-testid=prog-message]').textContent.startsWith('read 5 words')")
    text = page.evaluate("() => window.tmclEditor.getValue()")
    assert "CALC ADD, 1" in text and "WAIT TICKS, 0, 50" in text and "JA " in text


def cell(page, number):
    return page.inner_text(f"[data-testid=value-ap-0-{number}]")


def test_speeds_and_accelerations_convert_with_the_modules_formula(served, page):
    """The example of docs/ide.md: AP 4 = 1678 and AP 5 = 100 with pulse
    divisor 3, ramp divisor 7 and 256 microsteps (the TMCM-1141's
    defaults), a 200-step motor."""
    open_app(page, served.url)
    page.select_option("[data-testid=units]", "internal")
    page.fill("[data-testid=fullsteps]", "200")
    page.dispatch_event("[data-testid=fullsteps]", "change")
    with pytrinamic(served) as interface:
        interface.set_axis_parameter(4, 0, 1678)
        interface.set_axis_parameter(5, 0, 100)
    tab(page, "params")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '1678'")
    page.select_option("[data-testid=units]", "pps")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '51208.5'")
    assert cell(page, 5) == "46566.1"
    assert page.inner_text("[data-testid=row-ap-0-5] td:nth-child(5)") == "pps/s"
    page.select_option("[data-testid=units]", "rpm")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '60.01'")
    assert cell(page, 5) == "54.5697"
    assert page.inner_text("[data-testid=row-ap-0-4] td:nth-child(5)") == "rpm"
    assert cell(page, 1) == "0", "a position is not converted"
    # A 400-step motor turns at half the speed.
    page.fill("[data-testid=fullsteps]", "400")
    page.dispatch_event("[data-testid=fullsteps]", "change")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '30.005'")
    shot(page, "parameters-rpm")
    # A value typed in rpm is sent in internal units: 30 rpm of a 200-step
    # motor is 10 240 pps, 838.9 → 839.
    page.fill("[data-testid=fullsteps]", "200")
    page.dispatch_event("[data-testid=fullsteps]", "change")
    page.fill("[data-testid=edit-ap-0-4]", "30")
    page.click("[data-testid=set-ap-0-4]")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '30.005'")
    with pytrinamic(served) as interface:
        assert interface.get_axis_parameter(4, 0) == 839
    # The conversion follows the pulse divisor: 4 halves every speed.
    page.fill("[data-testid=edit-ap-0-154]", "4")
    page.click("[data-testid=set-ap-0-154]")
    page.wait_for_function("document.querySelector('[data-testid=value-ap-0-4]').textContent === '15.0025'")
    page.fill("[data-testid=edit-ap-0-154]", "3")
    page.click("[data-testid=set-ap-0-154]")
    # The motion panel takes and shows rpm; the chart draws them.
    tab(page, "motion")
    page.fill("[data-testid=rot-speed]", "60")
    page.click("[data-testid=ror]")
    page.wait_for_function("document.querySelector('[data-testid=motion-log]').textContent.includes('ROR 0, 1678')")
    page.wait_for_function("document.querySelector('[data-testid=ro-speed]').textContent === '60.01'")
    with pytrinamic(served) as interface:
        assert interface.get_axis_parameter(2, 0) == 1678
    tab(page, "charts")
    until_js(page, "the velocity chart to draw 60.01 rpm", "() => Math.abs(window.tmclsimCharts.charts[1].data[1]?.at(-1) - 60.00996) < 1e-4",
             "() => window.tmclsimCharts.charts[1].data[1]?.slice(-3)")
    velocity = page.evaluate("(() => { const u = window.tmclsimCharts.charts[1]; return [u.axes[1].label, u.data[1][u.data[1].length - 1]]; })()")
    assert velocity[0] == "rpm" and abs(velocity[1] - 60.00996) < 1e-4, velocity
    head, *rows = csv_rows(page, "chart-velocity-csv")
    assert head == ["t_s", "Actual speed (AP 3) [rpm]"]
    assert abs(float(rows[-1][1]) - 60.00996) < 1e-4
