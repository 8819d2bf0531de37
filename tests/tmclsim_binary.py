"""Where the tests find the `tmclsim` binary (built if missing)."""

import os
import pathlib
import subprocess

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
