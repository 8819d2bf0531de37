"""Benchmarks of tmclsim's Python API.

Prints a table: calls per second through the Python API for a few command
kinds and the parameter helpers, the time per call, the share of the Rust
core (the same operation timed in a Rust loop), and the binding's overhead
per call: what is left after subtracting the core and the cost of calling a
trivial Python method with the same arguments. The target for the overhead
is under 1 µs.

    python python/bench.py [--seconds 0.3]
"""

import argparse
import os
import sys
import timeit

# Run as a script, this file's directory (python/) comes first on the path,
# and its tmclsim/ holds the sources without the compiled extension: use the
# installed package instead.
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path = [p for p in sys.path if os.path.abspath(p or os.curdir) != HERE]

import tmclsim  # noqa: E402
from tmclsim import _tmclsim  # noqa: E402


class Trivial:
    """A Python object whose methods do nothing: the cost of a call."""

    def send(self, a, b=None, c=None, d=None):
        return None

    def get(self, a, b=0):
        return None

    def set(self, a, b, c):
        return None


def per_call(stmt, namespace, seconds):
    """Best time per call of ``stmt`` over five runs of about ``seconds``."""
    timer = timeit.Timer(stmt, globals=namespace)
    number, _ = timer.autorange()
    number = max(1, int(number * seconds / 0.2))
    return min(timer.repeat(repeat=5, number=number)) / number


def main(argv=None):
    parser = argparse.ArgumentParser(description="tmclsim Python API benchmarks")
    parser.add_argument("--seconds", type=float, default=0.3, help="length of one timing run")
    args = parser.parse_args(argv)

    module = tmclsim.Module()
    frame = tmclsim.Instruction.parse("GAP 4, 0").frame(1)
    ns = {"m": module, "t": Trivial(), "frame": frame, "ins": tmclsim.Instruction.parse("GAP 4, 0")}

    # (label, statement, trivial Python call with the same arguments, core operation)
    rows = [
        ("send(6, 4, 0, 0)           GAP as numbers", "m.send(6, 4, 0, 0)", "t.send(6, 4, 0, 0)", "send_frame"),
        ("send(Instruction)          GAP", "m.send(ins)", "t.send(ins)", "send_frame"),
        ('send("GAP 4, 0")           GAP as text', 'm.send("GAP 4, 0")', 't.send("GAP 4, 0")', "send_frame"),
        ("send_frame(9 bytes)        GAP raw", "m.send_frame(frame)", "t.send(frame)", "send_frame"),
        ("get_axis_parameter(4)", "m.get_axis_parameter(4)", "t.get(4)", "get_axis_parameter"),
        ('get_axis_parameter(name)', 'm.get_axis_parameter("Maximum positioning speed")', 't.get("Maximum positioning speed")', "get_axis_parameter"),
        ("set_axis_parameter(4, 0, v)", "m.set_axis_parameter(4, 0, 1000)", "t.set(4, 0, 1000)", "set_axis_parameter"),
        ("get_global_parameter(66)", "m.get_global_parameter(66)", "t.get(66)", "get_global_parameter"),
    ]

    print(f"tmclsim {tmclsim.__version__} Python API, Python {sys.version.split()[0]}, in-process TMCM-1141")
    header = f"{'call':44} {'calls/s':>11} {'ns/call':>9} {'core ns':>8} {'python ns':>10} {'binding ns':>11}"
    print(header)
    print("-" * len(header))
    overheads = []
    for label, stmt, trivial, core in rows:
        total = per_call(stmt, ns, args.seconds)
        python = per_call(trivial, ns, args.seconds)
        core_time = min(_tmclsim._time_core(module, core, 200_000) for _ in range(5))
        binding = total - python - core_time
        overheads.append(binding)
        print(f"{label:44} {1 / total:11,.0f} {total * 1e9:9.0f} {core_time * 1e9:8.0f} {python * 1e9:10.0f} {binding * 1e9:11.0f}")

    # A served module: the call goes through the server's lock.
    with tmclsim.serve(module, stepped=True):
        served = per_call("m.get_axis_parameter(4)", ns, args.seconds)
    print(f"{'get_axis_parameter(4), served (stepped)':44} {1 / served:11,.0f} {served * 1e9:9.0f}")
    print()
    worst = max(overheads)
    verdict = "met" if worst < 1e-6 else "NOT met"
    print(f"binding overhead per call: {min(overheads) * 1e9:.0f}…{worst * 1e9:.0f} ns (target < 1000 ns: {verdict})")
    print("columns: core = the same operation in a Rust loop; python = a trivial Python method call with the same")
    print("arguments; binding = ns/call - core - python")
    return 0


if __name__ == "__main__":
    sys.exit(main())
