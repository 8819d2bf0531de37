"""Fixtures of the browser IDE's end-to-end tests: `tmclsim serve --web`
(and `tmclsim ide`) processes on loopback, and a page in Debian's chromium
driven by Playwright. Everything started here is stopped here."""

import os
import pathlib
import re
import subprocess
import sys
import time

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from tmclsim_binary import ROOT, read_banner, stop, tmclsim_binary  # noqa: E402

CHROMIUM = os.environ.get("TMCLSIM_CHROMIUM", "/usr/bin/chromium")
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
# The screenshots the tests take go outside the source tree (into
# TMCLSIM_SCREENSHOTS, or target/ide-screenshots); with
# TMCLSIM_REFRESH_SCREENSHOTS=1 they replace the tracked ones docs/ide.md shows.
if os.environ.get("TMCLSIM_REFRESH_SCREENSHOTS") == "1":
    SHOTS = ROOT / "docs" / "ide"
else:
    SHOTS = pathlib.Path(os.environ.get("TMCLSIM_SCREENSHOTS") or ROOT / "target" / "ide-screenshots").resolve()
TAKEN = []


class Process:
    """A tmclsim process printing `key: value` lines up to `last`."""

    def __init__(self, args, last, timeout=30):
        self.proc = subprocess.Popen([tmclsim_binary(), *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines = read_banner(self.proc, last, timeout)

    def printed(self, key):
        m = re.search(rf"^\s*{key}: (\S+)", "".join(self.lines), re.M)
        return m.group(1) if m else None

    def stop(self):
        stop(self.proc)


@pytest.fixture
def start():
    """Starts tmclsim processes; all are stopped at teardown."""
    started = []

    def run(args, last="connect with:"):
        p = Process(args, last)
        started.append(p)
        return p

    yield run
    for p in started:
        p.stop()


@pytest.fixture
def served(start):
    """A virtual TMCM-1141 on TCP with the IDE beside it."""
    s = start(["serve", "--tcp", "127.0.0.1:0", "--web", "127.0.0.1:0"])
    s.tcp = s.printed("tcp")
    s.url = s.printed("web")
    return s


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright

    if not os.path.exists(CHROMIUM):
        pytest.fail(f"no chromium at {CHROMIUM} (apt-get install chromium, or set TMCLSIM_CHROMIUM)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


@pytest.fixture
def page(browser, start):
    """A page of its own; it closes before the test's processes stop
    (it depends on `start`), so no request of the page outlives its
    server. An error the page did not handle fails the test."""
    context = browser.new_context(viewport={"width": 1280, "height": 800}, accept_downloads=True)
    pg = context.new_page()
    errors = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    # The page's requests without an answer yet, and those that failed:
    # what open_app reports when the app does not get ready.
    pg.unanswered = {}
    pg.failed = []
    pg.on("request", lambda r: pg.unanswered.__setitem__(id(r), f"{r.method} {r.url}"))
    pg.on("requestfinished", lambda r: pg.unanswered.pop(id(r), None))
    pg.on("requestfailed", lambda r: pg.failed.append(f"{r.method} {r.url}: {r.failure}") or pg.unanswered.pop(id(r), None))
    # The helpers below that report on their own wait with the plain one.
    pg.wait_for_function_plain = pg.wait_for_function
    pg.wait_for_function = reporting(pg, pg.wait_for_function)
    yield pg
    context.close()
    assert not errors, f"errors in the page: {errors}"


def reporting(page, wait_for_function):
    """`page.wait_for_function` that, when its deadline passes, fails with
    what the elements its expression looks at held then (their text and
    data attributes), not Playwright's bare "Timeout exceeded"."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    def wait(expression, *args, **kwargs):
        try:
            return wait_for_function(expression, *args, **kwargs)
        except PlaywrightTimeout:
            ids = sorted(set(re.findall(r"data-testid=([\w-]+)", expression)))
            seen = page.evaluate("""(ids) => Object.fromEntries(ids.map((id) => {
                const e = document.querySelector(`[data-testid=${id}]`);
                return [id, e ? { text: e.textContent.slice(0, 200), data: { ...e.dataset } } : null];
            }))""", ids)
            raise AssertionError(f"waited for {expression!r}; saw {seen}") from None

    return wait


def open_app(page, url):
    page.goto(url)
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    try:
        getattr(page, "wait_for_function_plain", page.wait_for_function)("window.tmclsimReady === true")
    except PlaywrightTimeout:
        unanswered = list(getattr(page, "unanswered", {}).values())
        raise AssertionError(f"the app did not get ready: unanswered {unanswered}, failed {getattr(page, 'failed', [])}") from None
    return page


def tab(page, name):
    page.click(f"[data-testid=tab-{name}]")


def text(page, testid):
    """The text of the element with that test id."""
    return page.inner_text(f"[data-testid={testid}]")


def until(page, what, probe, ok=bool, timeout=10):
    """Polls `probe()` until `ok` takes its value (then returns it); the
    page's events come in between (page.wait_for_timeout, the poll's
    interval). After `timeout` seconds fails naming `what` and the last
    value seen."""
    deadline = time.monotonic() + timeout
    while True:
        value = probe()
        if ok(value):
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"waited {timeout} s for {what}; last saw {value!r}")
        page.wait_for_timeout(20)  # the poll's interval


def until_js(page, what, condition, seen, arg=None, timeout=10):
    """Waits until the JavaScript function `condition` (given `arg`) is true
    in the page; after `timeout` seconds fails naming `what` and what the
    JavaScript function `seen` (given `arg`) gives then."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    try:
        getattr(page, "wait_for_function_plain", page.wait_for_function)(condition, arg=arg, timeout=timeout * 1000)
    except PlaywrightTimeout:
        raise AssertionError(f"waited {timeout} s for {what}; saw {page.evaluate(seen, arg)!r}") from None


def wait_text(page, testid, expression, timeout=30):
    """Waits until the element's text `t` makes the JavaScript `expression`
    true; fails with the text it had."""
    until_js(
        page,
        f"[data-testid={testid}] to make `{expression}` true",
        f"() => {{ const t = document.querySelector('[data-testid={testid}]').textContent; return {expression}; }}",
        f"() => document.querySelector('[data-testid={testid}]')?.textContent",
        timeout=timeout,
    )


def shot(page, name):
    """A screenshot for docs/ide.md, taken by the tests so that it can be
    refreshed (TMCLSIM_REFRESH_SCREENSHOTS=1) and compared."""
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / f"{name}.png"))
    TAKEN.append(name)


def pytest_terminal_summary(terminalreporter):
    if TAKEN:
        terminalreporter.write_line(f"screenshots: {len(TAKEN)} in {SHOTS}")


def downloaded(page, testid):
    """The bytes of the file a click on `testid` downloads."""
    with page.expect_download() as d:
        page.click(f"[data-testid={testid}]")
    return pathlib.Path(d.value.path()).read_bytes()


def csv_rows(page, testid):
    """The CSV a click on `testid` downloads, as lists of cells."""
    return [line.split(",") for line in downloaded(page, testid).decode().splitlines()]


def series(page, key):
    """The charts' samples of one signal (`ap:0:1`: AP 1 of motor 0), as
    kept: None where it was not read."""
    return page.evaluate("(k) => window.tmclsimCharts.store.get(k)", key)


def wait_samples(page, n, timeout=30):
    """Until the charts hold at least `n` samples."""
    until_js(page, f"{n} samples in the charts", f"() => window.tmclsimCharts.t.length >= {n}", "() => `${window.tmclsimCharts.t.length} samples`", timeout=timeout)


def wait_drawn(page, n, timeout=10):
    """Until every chart draws at least `n` samples (the store's samples
    are drawn on the charts' next redraw)."""
    until_js(
        page,
        f"every chart to draw {n} samples",
        f"() => window.tmclsimCharts.charts.every((u) => u.data[0].length >= {n})",
        "() => window.tmclsimCharts.charts.map((u) => `${u.panel.title}: ${u.data[0].length}`)",
        timeout=timeout,
    )
