"""Where the tests find the `tmclsim` binary (built if missing), and what
every suite does with a tmclsim process it starts: read its banner, stop it."""

import os
import pathlib
import subprocess
import threading

ROOT = pathlib.Path(__file__).resolve().parents[1]


def tmclsim_binary():
    path = os.environ.get("TMCLSIM_BIN")
    if path:
        return path
    built = ROOT / "target" / "release" / "tmclsim"
    if not built.exists():
        subprocess.run(["cargo", "build", "--release", "-p", "tmclsim"], cwd=ROOT, check=True)
    return str(built)


def stop(proc):
    """Stops a tmclsim process a test started: SIGTERM, then SIGKILL after
    10 s; its piped output is closed."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    if proc.stdout:
        proc.stdout.close()


def read_banner(proc, last="connect with:", timeout=30):
    """The lines `proc` prints up to the one that starts with `last`, read
    on a thread of their own, so that a process that prints nothing more
    cannot hold the wait past `timeout` seconds. A process that exits
    first, or prints no such line in time, is stopped and fails the wait
    with what it printed."""
    lines = []

    def read():
        try:
            for line in proc.stdout:
                lines.append(line)
                if line.startswith(last):
                    return
        except (OSError, ValueError):
            pass  # the pipe was closed: the process was stopped

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(timeout)
    if not lines or not lines[-1].startswith(last):
        state = f"printed no {last!r} line within {timeout} s" if reader.is_alive() else "exited"
        stop(proc)
        raise RuntimeError(f"tmclsim {state}; it printed: " + "".join(lines))
    return lines
