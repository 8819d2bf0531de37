"""A web page of any origin makes the browser send HTTP requests to any
port of the machine it runs on. Here a page posts TMCL frames, in every
alignment, to a served module's TMCL port and control socket, as an attacker's
page would (docs/behaviour.md rule 90): the motor must not move and the
world must not change."""

import http.server
import socket
import threading

import pytest

from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141


def frame(op, kind, motor, value, address=1):
    body = bytes([address, op, kind, motor]) + value.to_bytes(4, "big", signed=True)
    return body + bytes([sum(body) & 0xFF])


ATTACK = """
async (target) => {
  // How each request ended: "closed" when the server closed the connection
  // (the fetch fails at once), else the error's name ("TimeoutError": a
  // server that took the request for frames and never answered it).
  const ends = [];
  const post = async (url, body) => {
    try {
      await fetch(url, {method: "POST", mode: "no-cors", body, signal: AbortSignal.timeout(5000)});
      ends.push("answered");
    } catch (e) {
      ends.push(e.name === "TypeError" ? "closed" : e.name);
    }
  };
  const frames = new Uint8Array(target.frames);
  for (let skew = 0; skew < 9; skew++) {
    const body = new Uint8Array(skew + frames.length);
    body.set(frames, skew);
    await post(target.url, body);
  }
  if (target.control) await post(target.control, "link mute on\\n");
  return ends;
}
"""


class AnotherSite(http.server.BaseHTTPRequestHandler):
    def do_GET(self):
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.end_headers()
        self.wfile.write(b"<title>another site</title>")

    def log_message(self, *args):
        pass


@pytest.fixture
def another_site():
    """A page of another origin on this machine (a development server, a
    local tool): the browser lets it reach loopback ports."""
    site = http.server.HTTPServer(("127.0.0.1", 0), AnotherSite)
    thread = threading.Thread(target=site.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{site.server_port}/"
    site.shutdown()
    site.server_close()
    thread.join()


def test_a_web_page_cannot_drive_a_motor_or_mute_a_link(served, page, another_site):
    control = served.printed("control")
    ror = b"".join(frame(1, 0, 0, 800) for _ in range(40))
    page.goto(another_site)
    # Every request is closed by the server (none times out): the server
    # is done with each before the checks below.
    ends = page.evaluate(ATTACK, {"url": f"http://{served.tcp}/", "control": f"http://{control}/", "frames": list(ror)})
    assert ends == ["closed"] * 10, ends
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}").connect() as interface:
        motor = TMCM1141(interface).motors[0]
        assert motor.get_axis_parameter(motor.AP.TargetVelocity) == 0, "the page did not start the motor"
        assert motor.actual_velocity == 0
    # The link is not muted: a plain socket gets its reply.
    with socket.create_connection(tuple(served.tcp.rsplit(":", 1)), timeout=3) as s:
        s.sendall(frame(6, 4, 0, 0))
        assert len(s.recv(9)) == 9


def test_a_web_page_cannot_reach_a_module_through_the_trace_proxy(served, page, another_site, start, tmp_path):
    """`tmclsim trace record` forwards what a host sends to a module, often a
    real one on USB: its listening port screens what a page sends as the
    TMCL port does, and the recording goes on (docs/behaviour.md rule 90)."""
    trace = tmp_path / "session.jsonl"
    recorder = start(["trace", "record", "--listen", "127.0.0.1:0", "--tcp", served.tcp, "--out", str(trace)])
    listen = recorder.printed("listen")
    ror = b"".join(frame(1, 0, 0, 800) for _ in range(40))
    page.goto(another_site)
    ends = page.evaluate(ATTACK, {"url": f"http://{listen}/", "control": None, "frames": list(ror)})
    assert ends == ["closed"] * 9, ends
    # The recording goes on: a host through the proxy finds the motor still.
    with ConnectionManager(f"--interface socket_serial_tmcl --port {listen}").connect() as interface:
        motor = TMCM1141(interface).motors[0]
        assert motor.get_axis_parameter(motor.AP.TargetVelocity) == 0, "the page did not start the motor"
    recorder.proc.terminate()
    log = recorder.proc.stdout.read()
    assert recorder.proc.wait(timeout=10) == 0, log
    closed = [line for line in log.splitlines() if "it opened with an HTTP request, not TMCL; nothing was executed" in line]
    assert len(closed) == 9 and all(line.startswith("tmclsim: closing connection tcp 127.0.0.1:") for line in closed), log
    assert "stopping; 2 frame(s) in" in log, log
    recorded = trace.read_text()
    assert frame(1, 0, 0, 800).hex(" ").upper() not in recorded, recorded
