"""Benchmarks of the browser IDE's server; prints a table.

1. Streaming: a fleet of 16 virtual TMCM-1141 served with --web; 16
   WebSocket clients subscribe to 4 signals each at 50 Hz. The server's CPU
   time over the window (utime + stime from /proc) as % of one core, and the
   messages that arrived.
2. Direct mode: POST /command round trips over loopback (p50, p99).
3. In a real browser (Playwright + Debian's chromium, when installed): a
   click on "send" to the reply shown (p50), and the module list of a
   1000-module fleet rendered.

Usage: python scripts/bench_ide.py [target/release/tmclsim] [seconds]
Needs: pip install websockets (and playwright for the browser rows).
"""

import asyncio
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

BIN = sys.argv[1] if len(sys.argv) > 1 else "target/release/tmclsim"
SECONDS = float(sys.argv[2]) if len(sys.argv) > 2 else 10.0
TICK = os.sysconf("SC_CLK_TCK")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def serve_fleet(modules: int, tmp: str):
    """Serves `modules` TMCM-1141, one per TCP port, with the app; returns
    (process, web base URL)."""
    first = free_port()
    while True:
        # `modules` consecutive free ports from `first`.
        try:
            socks = []
            for p in range(first, first + modules):
                s = socket.socket()
                s.bind(("127.0.0.1", p))
                socks.append(s)
            break
        except OSError:
            first += modules
        finally:
            for s in socks:
                s.close()
    fleet = os.path.join(tmp, f"fleet-{modules}.toml")
    with open(fleet, "w") as f:
        f.write(f'world = "stage"\n[[link]]\ntcp = "127.0.0.1:{first}"\ncount = {modules}\nmodules = ["tmcm-1141@1"]\n')
    web = f"127.0.0.1:{free_port()}"
    proc = subprocess.Popen(
        [BIN, "serve", "--fleet", fleet, "--web", web, "--max-connections", "100000"],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )
    for line in proc.stdout:
        if line.startswith("connect with") or "connect with" in line:
            break
    return proc, f"http://{web}"


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK


async def stream(base: str, modules: int, seconds: float):
    import websockets

    signals = [{"kind": "ap", "number": n, "index": 0} for n in (0, 1, 3, 206)]
    counts = [0] * modules

    async def client(i):
        async with websockets.connect(base.replace("http", "ws") + f"/api/modules/{i}/live") as ws:
            await ws.send(json.dumps({"signals": signals, "rate": 50}))
            end = time.monotonic() + seconds
            while time.monotonic() < end:
                try:
                    await asyncio.wait_for(ws.recv(), timeout=max(0.01, end - time.monotonic()))
                    counts[i] += 1
                except asyncio.TimeoutError:
                    break

    await asyncio.gather(*(client(i) for i in range(modules)))
    return sum(counts)


def post(url: str, body: dict):
    req = urllib.request.Request(url, json.dumps(body).encode(), {"Content-Type": "application/json"})
    with urllib.request.urlopen(req) as r:
        return json.loads(r.read())


def browser_rows(base_1: str, base_1000: str):
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        return [("browser rows", "skipped: playwright is not installed")]
    chromium = os.environ.get("TMCLSIM_CHROMIUM", "/usr/bin/chromium")
    if not os.path.exists(chromium):
        return [("browser rows", f"skipped: no {chromium}")]
    args = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync"]
    rows = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=chromium, args=args)
        page = browser.new_page()
        page.goto(base_1)
        page.wait_for_selector("[data-testid=direct-input]")
        times = []
        for i in range(50):
            ms = page.evaluate(
                """async (n) => {
                    const input = document.querySelector('[data-testid=direct-input]');
                    const out = document.querySelector('[data-testid=direct-log]');
                    const before = out.textContent.length;
                    input.value = 'GAP 1, 0';
                    const t0 = performance.now();
                    document.querySelector('[data-testid=direct-send]').click();
                    while (out.textContent.length === before) {
                        await new Promise(r => requestAnimationFrame(r));
                    }
                    return performance.now() - t0;
                }""",
                i,
            )
            times.append(ms)
        rows.append(("click → reply shown, p50 (browser, 50 clicks)", f"{statistics.median(times):.1f} ms"))
        t0 = time.monotonic()
        page.goto(base_1000)
        page.wait_for_function("document.querySelectorAll('[data-testid=module-item]').length > 0")
        rows.append(("module list of a 1000-module fleet rendered (page load to first rows)", f"{(time.monotonic() - t0) * 1000:.0f} ms"))
        browser.close()
    return rows


def main():
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        proc, base = serve_fleet(16, tmp)
        try:
            time.sleep(0.5)
            idle0 = cpu_seconds(proc.pid)
            time.sleep(2.0)
            idle = (cpu_seconds(proc.pid) - idle0) / 2.0
            c0, t0 = cpu_seconds(proc.pid), time.monotonic()
            messages = asyncio.run(stream(base, 16, SECONDS))
            cpu = (cpu_seconds(proc.pid) - c0) / (time.monotonic() - t0)
            rows.append(("16 modules idle, app served: server CPU", f"{idle * 100:.2f} % of one core"))
            rows.append(("16 modules × 4 signals × 50 Hz streamed: server CPU", f"{cpu * 100:.2f} % of one core"))
            rows.append(("  messages received (expected 16 × 50/s)", f"{messages / SECONDS:.0f}/s"))
            lat = []
            for _ in range(500):
                t = time.perf_counter()
                post(base + "/api/modules/0/command", {"line": "GAP 1, 0"})
                lat.append((time.perf_counter() - t) * 1000)
            lat.sort()
            rows.append(("POST /command round trip p50 / p99 (HTTP, loopback)", f"{lat[len(lat) // 2]:.2f} / {lat[int(len(lat) * 0.99)]:.2f} ms"))
            proc1000, base1000 = serve_fleet(1000, tmp)
            try:
                rows += browser_rows(base, base1000)
            finally:
                proc1000.terminate()
                proc1000.wait()
        finally:
            proc.terminate()
            proc.wait()
    print("| measurement | result |")
    print("|---|---|")
    for name, value in rows:
        print(f"| {name} | {value} |")


if __name__ == "__main__":
    main()
