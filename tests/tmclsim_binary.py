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
