"""Benchmarks of the playground (target/playground, built by
scripts/playground); prints a table with each budget of docs/playground.md.

1. The page served from loopback by a static file server, opened in a fresh
   browser context (Debian's chromium through Playwright): the time from the
   navigation to the IDE ready (the module list drawn, the first module
   picked), the median of several loads.
2. The WebAssembly's size, as sent with gzip (level 6).
3. The in-page VM against the native one: a compute-only loop for an hour
   of virtual time in the page (window.tmclsim), in instructions per second,
   against `tmclsim bench`'s "VM, compute-only loop" row.
4. The manual's first program (section 2.4, moves and WAIT POS) for an hour
   of virtual time in the page.

Usage: python scripts/bench_playground.py [target/release/tmclsim]
Needs: playwright (pip), chromium (TMCLSIM_CHROMIUM, default /usr/bin/chromium).
"""

import functools
import gzip
import http.server
import os
import pathlib
import re
import statistics
import subprocess
import sys
import threading
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
PLAYGROUND = ROOT / "target" / "playground"
BIN = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target" / "release" / "tmclsim")
CHROMIUM = os.environ.get("TMCLSIM_CHROMIUM", "/usr/bin/chromium")
LOADS = 5

COMPUTE = "Loop:\n  CALC ADD, 1\n  COMP 2000000000\n  JC LT, Loop\n  STOP\n"

# Runs in the page: a program for an hour of virtual time, timed.
AN_HOUR = """source => {
  const m = new window.tmclsim.Module("tmcm-1141");
  const a = m.download(source);
  if (!a.ok) throw new Error(JSON.stringify(a.diagnostics));
  m.run();
  const t = performance.now();
  m.advance(3600);
  const ms = performance.now() - t;
  const executed = m.state().executed;
  m.free();
  return { ms, executed };
}"""


class Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def serve(root):
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(root)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def native_compute_rate():
    """`tmclsim bench`'s compute-only row, in instructions per second (the
    bench is stopped once it is printed)."""
    proc = subprocess.Popen([BIN, "bench"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        for line in proc.stdout:
            m = re.search(r"VM, compute-only loop.*?\| ([\d.]+) M instructions/s", line)
            if m:
                return float(m.group(1)) * 1e6
    finally:
        proc.kill()
        proc.wait()
    raise SystemExit(f"{BIN} bench printed no compute-only row")


def main():
    if not (PLAYGROUND / "index.html").is_file():
        raise SystemExit("no target/playground: run scripts/playground first")
    from playwright.sync_api import sync_playwright

    wasm = (PLAYGROUND / "assets" / "tmclsim_bg.wasm").read_bytes()
    gzipped = len(gzip.compress(wasm, compresslevel=6))
    native = native_compute_rate()
    server = serve(PLAYGROUND)
    url = f"http://127.0.0.1:{server.server_address[1]}/"
    rows = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=["--headless", "--no-sandbox", "--disable-gpu"])
        loads = []
        for _ in range(LOADS):
            context = browser.new_context()
            page = context.new_page()
            t = time.perf_counter()
            page.goto(url)
            page.wait_for_function("window.tmclsimReady === true", polling="raf")
            loads.append(time.perf_counter() - t)
            context.close()
        page = browser.new_page()
        page.goto(url)
        page.wait_for_function("window.tmclsimReady === true")
        compute = page.evaluate(AN_HOUR, COMPUTE)
        manual = page.evaluate(AN_HOUR, (ROOT / "crates/asm/tests/programs/first_steps_2_4.tmc").read_text())
        browser.close()
    server.shutdown()

    load_ms = statistics.median(loads) * 1e3
    in_page = compute["executed"] / (compute["ms"] / 1e3)
    rows.append(("page ready, from loopback (median of %d loads)" % LOADS, f"{load_ms:.0f} ms", "≤ 1000 ms", load_ms <= 1000))
    rows.append(("tmclsim_bg.wasm, gzip", f"{gzipped / 1e6:.2f} MB ({len(wasm) / 1e6:.2f} MB raw)", "≤ 1.5 MB", gzipped <= 1.5e6))
    share = in_page / native
    rows.append(
        (
            "VM compute-only loop, 1 h in the page",
            f"{in_page / 1e6:.1f} M instructions/s = {share:.0%} of native ({native / 1e6:.1f} M/s)",
            "≥ 25 %",
            share >= 0.25,
        )
    )
    rows.append(("manual 2.4 program, 1 h in the page", f"{manual['ms']:.1f} ms", "≤ 100 ms", manual["ms"] <= 100))
    print("| measurement | result | budget | within |")
    print("|---|---|---|---|")
    for name, result, budget, ok in rows:
        print(f"| {name} | {result} | {budget} | {'yes' if ok else 'NO'} |")


if __name__ == "__main__":
    main()
