"""Round trips and client CPU per command of PyTrinamic against `tmclsim
serve`, over TCP and the pty; prints rows of the bench table."""

import os
import re
import subprocess
import sys
import tempfile
import time

from pytrinamic.connections import ConnectionManager


def main():
    exe = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 5000
    with tempfile.TemporaryDirectory() as tmp:
        pty = os.path.join(tmp, "pty")
        proc = subprocess.Popen([exe, "serve", "--tcp", "127.0.0.1:0", "--pty", pty], stdout=subprocess.PIPE, text=True)
        try:
            tcp = None
            for line in proc.stdout:
                m = re.match(r"\s*tcp: (\S+)", line)
                if m:
                    tcp = m.group(1)
                if line.startswith("connect with:"):
                    break
            for name, args in [
                ("TCP round trip, PyTrinamic", f"--interface socket_serial_tmcl --port {tcp}"),
                ("pty round trip, PyTrinamic", f"--interface serial_tmcl --port {pty} --data-rate 9600"),
            ]:
                with ConnectionManager(args.split()).connect() as interface:
                    for _ in range(200):
                        interface.get_axis_parameter(1, 0)
                    samples = []
                    cpu0 = time.process_time()
                    for _ in range(n):
                        t = time.perf_counter()
                        interface.get_axis_parameter(1, 0)
                        samples.append(time.perf_counter() - t)
                    cpu = time.process_time() - cpu0
                samples.sort()
                p = lambda q: samples[min(int(len(samples) * q), len(samples) - 1)] * 1e6
                print(f"| {name} | {n} | p50 {p(0.5):.1f} µs, p99 {p(0.99):.1f} µs, max {samples[-1] * 1e6:.1f} µs; client CPU {cpu / n * 1e6:.1f} µs/command |")
        finally:
            proc.terminate()
            proc.wait()


if __name__ == "__main__":
    main()
