"""EtherCAT cycle times: a pysoem master runs 1 ms cycles against 1 and 16
virtual TMCM-1310 slaves on a veth pair and counts missed working counters.
Needs root (veth, raw sockets)."""

import os
import statistics
import struct
import subprocess
import sys
import time

import pysoem


def run(binary, slaves, cycles=5000, period=0.001):
    master_if, slave_if = "ecbm", "ecbs"
    subprocess.run(["ip", "link", "del", master_if], capture_output=True)
    subprocess.run(["ip", "link", "add", master_if, "type", "veth", "peer", "name", slave_if], check=True)
    subprocess.run(["ip", "link", "set", master_if, "up"], check=True)
    subprocess.run(["ip", "link", "set", slave_if, "up"], check=True)
    proc = subprocess.Popen([binary, "serve", "--module", "tmcm-1310", "--world", "free", "--ethercat", slave_if, "--slaves", str(slaves)], stdout=subprocess.DEVNULL)
    try:
        time.sleep(0.3)
        m = pysoem.Master()
        m.open(master_if)
        assert m.config_init() == slaves
        m.config_map()
        m.state_check(pysoem.SAFEOP_STATE, 50_000)
        for s in m.slaves:
            s.output = struct.pack("<Ii", 2, 300)
        m.send_processdata()
        m.receive_processdata(2000)
        m.state = pysoem.OP_STATE
        m.write_state()
        for _ in range(200):
            m.send_processdata()
            m.receive_processdata(2000)
            if m.state_check(pysoem.OP_STATE, 1000) == pysoem.OP_STATE:
                break
        rtt, missed = [], 0
        next_t = time.perf_counter()
        start = next_t
        for _ in range(cycles):
            t = time.perf_counter()
            m.send_processdata()
            wkc = m.receive_processdata(2000)
            rtt.append(time.perf_counter() - t)
            if wkc != m.expected_wkc:
                missed += 1
            next_t += period
            delay = next_t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
        elapsed = time.perf_counter() - start
        m.close()
        rtt.sort()
        print(f"| EtherCAT, {slaves} slave(s), {period * 1e3:.0f} ms cycles | {cycles} | mean cycle {elapsed / cycles * 1e3:.3f} ms; round trip p50 {statistics.median(rtt) * 1e6:.0f} µs, p99 {rtt[int(len(rtt) * 0.99)] * 1e6:.0f} µs, max {rtt[-1] * 1e6:.0f} µs; missed working counters {missed} |")
    finally:
        proc.terminate()
        proc.wait()
        subprocess.run(["ip", "link", "del", master_if], capture_output=True)


if __name__ == "__main__":
    if os.geteuid() != 0:
        print("| EtherCAT | – | skipped: needs root for a veth pair |")
        sys.exit(0)
    for n in (1, 16):
        run(sys.argv[1], n)
