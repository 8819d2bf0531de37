"""A web page of any origin makes the browser send HTTP requests to any
port of the machine it runs on. Here a page posts TMCL frames, in every
alignment, to a served module's TMCL port and control socket, as an attacker's
page would (docs/behaviour.md rule 90): the motor must not move and the
world must not change."""

import http.server
import socket
import threading
import time

import pytest

from pytrinamic.connections import ConnectionManager
from pytrinamic.modules import TMCM1141


def frame(op, kind, motor, value, address=1):
    body = bytes([address, op, kind, motor]) + value.to_bytes(4, "big", signed=True)
    return body + bytes([sum(body) & 0xFF])


ATTACK = """
async (target) => {
  const frames = new Uint8Array(target.frames);
  for (let skew = 0; skew < 9; skew++) {
    const body = new Uint8Array(skew + frames.length);
    body.set(frames, skew);
    try {
      // A server that takes the request for frames never answers it.
      await fetch(target.url, {method: "POST", mode: "no-cors", body, signal: AbortSignal.timeout(500)});
    } catch (e) {}
  }
  try {
    await fetch(target.control, {method: "POST", mode: "no-cors", body: "link mute on\\n", signal: AbortSignal.timeout(500)});
  } catch (e) {}
  return true;
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
    assert page.evaluate(ATTACK, {"url": f"http://{served.tcp}/", "control": f"http://{control}/", "frames": list(ror)})
    time.sleep(0.3)
    with ConnectionManager(f"--interface socket_serial_tmcl --port {served.tcp}").connect() as interface:
        motor = TMCM1141(interface).motors[0]
        assert motor.get_axis_parameter(motor.AP.TargetVelocity) == 0, "the page did not start the motor"
        assert motor.actual_velocity == 0
    # The link is not muted: a plain socket gets its reply.
    with socket.create_connection(tuple(served.tcp.rsplit(":", 1)), timeout=3) as s:
        s.sendall(frame(6, 4, 0, 0))
        assert len(s.recv(9)) == 9
