"""Runs one of PyTrinamic's demo scripts, unchanged, against a served
module:

    python run_demo.py --figures DIR SCRIPT CONNECTION-ARGUMENTS…

e.g. `… rotate_demo.py --interface socket_serial_tmcl --port 127.0.0.1:PORT`.
The script runs as `python SCRIPT CONNECTION-ARGUMENTS…` would (as
`__main__`, its directory first on the path, those arguments in sys.argv),
with two things of its surroundings replaced:

- The connection. Many demos name their own (`ConnectionManager("--interface
  pcan_tmcl")`, a serial port chosen interactively, a CAN adapter): every
  ConnectionManager the script makes gets CONNECTION-ARGUMENTS instead of
  what the script passes. DIR/connections.json lists what the script
  passed, one entry per ConnectionManager (null: no argument, the command
  line).
- The plot window. matplotlib draws with its Agg backend (no display), and
  `plt.show()` saves each open figure, numbered from 1 over the run, as
  DIR/figure-N.png and its axes' lines as DIR/figure-N.json
  ({"axes": [{"title", "xlabel", "ylabel", "lines": [{"label", "x", "y"}]}]}),
  then closes it, as closing the window would.

Whatever the script raises ends the run as it would end `python SCRIPT`: a
traceback and exit status 1.
"""

import json
import os
import pathlib
import runpy
import sys


def usage():
    print(__doc__.split("\n\n")[1].strip(), file=sys.stderr)
    raise SystemExit(2)


def patch_connection_manager(arguments, record):
    """Every ConnectionManager gets `arguments`; what the script passed is
    appended to `record` (and written to the file at once, so that it is
    there however the script ends)."""
    from pytrinamic.connections import connection_manager

    cls = connection_manager.ConnectionManager
    original = cls.__init__

    def __init__(self, arg_list=None, connection_type="any"):
        passed = arg_list if arg_list is None or isinstance(arg_list, str) else list(arg_list)
        record.append(passed)
        original(self, list(arguments), connection_type)

    cls.__init__ = __init__


def patch_show(directory):
    """plt.show saves and closes every open figure (module docstring)."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    try:
        import matplotlib
    except ImportError:
        return  # a demo that plots fails at its own import, as it would
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = [0]

    def show(*args, **kwargs):
        for number in plt.get_fignums():
            figure = plt.figure(number)
            shown[0] += 1
            stem = directory / f"figure-{shown[0]}"
            figure.savefig(stem.with_suffix(".png"))
            axes = []
            for ax in figure.get_axes():
                lines = [
                    {
                        "label": line.get_label(),
                        "x": [float(x) for x in line.get_xdata()],
                        "y": [float(y) for y in line.get_ydata()],
                    }
                    for line in ax.get_lines()
                ]
                axes.append({"title": ax.get_title(), "xlabel": ax.get_xlabel(), "ylabel": ax.get_ylabel(), "lines": lines})
            stem.with_suffix(".json").write_text(json.dumps({"axes": axes}))
            plt.close(figure)

    plt.show = show


def main(argv):
    if len(argv) < 3 or argv[0] != "--figures":
        usage()
    directory = pathlib.Path(argv[1])
    script, arguments = argv[2], argv[3:]
    directory.mkdir(parents=True, exist_ok=True)
    connections = directory / "connections.json"

    class Record(list):
        def append(self, item):
            super().append(item)
            connections.write_text(json.dumps(self))

    record = Record()
    connections.write_text("[]")
    patch_show(directory)
    patch_connection_manager(arguments, record)
    sys.argv = [script, *arguments]
    sys.path[0] = os.path.dirname(os.path.abspath(script))
    runpy.run_path(script, run_name="__main__")


if __name__ == "__main__":
    main(sys.argv[1:])
