"""The `tmclsim` command of the Python package: the same program as the
Rust binary, run through the extension module (`tmclsim --help`)."""

import os
import sys


def main(argv=None):
    """Runs `tmclsim` with `argv` (default: this process's arguments) and
    ends the process with its exit status."""
    args = list(sys.argv if argv is None else argv)
    args[0] = "tmclsim"
    # `tmclsim sweep` runs on this interpreter, which has the package.
    os.environ.setdefault("TMCLSIM_PYTHON", sys.executable)
    from tmclsim._tmclsim import cli_main

    sys.stdout.flush()
    sys.exit(cli_main(args))
