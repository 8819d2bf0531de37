"""One scenario: a virtual module in its world with its parameter set, the
program run in virtual time until it ends, a stop condition holds or the
duration is over; then the checks and the metrics. Pure and deterministic:
the same scenario gives the same row on any machine (docs/behaviour.md
rule 87)."""

from __future__ import annotations

import copy
from dataclasses import replace
from typing import Any, Dict, List, Optional, Tuple

from .matrix import MAX_WORLD_INDEX, Check, Condition, Matrix, MatrixError, Read


class ScenarioError(Exception):
    """The scenario could not be set up (a world value or a parameter the
    module refuses)."""


def set_world(doc: Dict[str, Any], path: str, value: Any) -> None:
    """Sets a dotted key of a world document (`axis.0.home_switch.from`;
    numbers index lists, which grow as needed, up to the largest entry a
    world file has). `…switch.width` of the home switch sets `to` from
    `from`."""
    parts = path.split(".")
    node: Any = doc
    for i, part in enumerate(parts[:-1]):
        nxt = parts[i + 1]
        # A list when the next part is a number; its entries are tables,
        # unless it is the last part (a list of numbers, `inputs.2`).
        want = [] if _index(nxt, path) is not None else {}
        k = _index(part, path)
        if k is not None:
            if not isinstance(node, list):
                raise MatrixError(f"world key {path}: '{part}' indexes a list")
            while len(node) <= k:
                node.append(copy.deepcopy(want))
            node = node[k]
        else:
            if not isinstance(node, dict):
                raise MatrixError(f"world key {path}: '{part}' names a table")
            node = node.setdefault(part, want)
    last = parts[-1]
    k = _index(last, path)
    if k is not None:
        # An entry of a list of numbers (`inputs.2`, `analog.0`).
        if not isinstance(node, list):
            raise MatrixError(f"world key {path}: '{last}' indexes a list")
        while len(node) <= k:
            node.append(0)
        node[k] = value
    else:
        node[last] = value


def _index(part: str, path: str) -> Optional[int]:
    """A list entry's number (ASCII digits), at most the largest a world
    file has; None for a table's key."""
    if not (part.isascii() and part.isdigit()):
        return None
    if len(part) > 9 or int(part) > MAX_WORLD_INDEX:
        raise MatrixError(f"world key {path}: list entry {part[:12]}; at most {MAX_WORLD_INDEX}")
    return int(part)


def world_document(mx: Matrix, values: Dict[str, Any]) -> Dict[str, Any]:
    doc = copy.deepcopy(mx.world)
    for a in mx.axes:
        if a.target == "world":
            set_world(doc, a.key, values[a.name])
    # A home switch given as from + width.
    for axis in doc.get("axis", []) if isinstance(doc.get("axis"), list) else []:
        home = axis.get("home_switch") if isinstance(axis, dict) else None
        if isinstance(home, dict) and "width" in home:
            width = home.pop("width")
            home["to"] = home.get("from", 0) + width
    return doc


def world_toml(doc: Dict[str, Any]) -> str:
    import tomli_w

    return tomli_w.dumps(doc)


def world_text(mx: Matrix, values: Dict[str, Any]) -> str:
    """The scenario's world file; a value no world file can hold (a text
    for a width) is the scenario's error."""
    try:
        return world_toml(world_document(mx, values))
    except MatrixError:
        raise
    except (TypeError, ValueError) as e:
        raise ScenarioError(f"world: {e}") from None


def _setup_errors():
    """What fails a scenario as `setup`, with its message in `error`."""
    import tmclsim

    return (ValueError, ScenarioError, MatrixError, tmclsim.TmclError)


def _files(text: str, lines: List[str]) -> Dict[str, str]:
    return {"world": text, "setup": "\n".join(lines) + ("\n" if lines else "")}


def files(mx: Matrix, index: int) -> Dict[str, str]:
    """The files that reproduce scenario `index`: its world file and its
    setup lines, as `run` gives them for a failure."""
    import tmclsim

    values = mx.scenario(index)
    text, lines = "", []
    try:
        text = world_text(mx, values)
        lines = setup_lines(tmclsim.Module(profile_of(mx, values), world=text), mx, values)
    except _setup_errors():
        pass
    return _files(text, lines)


def _number(m, kind: str, what: Any, index: int) -> int:
    """A parameter's number from its number or its name, as the module
    looks names up."""
    if isinstance(what, int):
        return what
    try:
        if kind == "ap":
            return m._axis_number(str(what))
        return m._global_number(str(what), index)[1]
    except ValueError as e:
        raise ScenarioError(str(e)) from None


def setup_lines(m, mx: Matrix, values: Dict[str, Any]) -> List[str]:
    """The matrix's setup commands, then one SAP/SGP per varied parameter."""
    lines = list(mx.setup)
    for a in mx.axes:
        if a.target in ("ap", "gp"):
            v = values[a.name]
            if isinstance(v, float) and not v.is_integer():
                raise ScenarioError(f"{a.name}: a parameter takes whole numbers, not {v}")
            op = "SAP" if a.target == "ap" else "SGP"
            lines.append(f"{op} {_number(m, a.target, a.key, a.index)}, {a.index}, {int(v)}")
    return lines


def _is_207(m, r: Read) -> bool:
    if isinstance(r.what, int):
        return r.what == 207
    try:
        return m._axis_number(str(r.what)) == 207
    except ValueError:
        return False


def read(m, r: Read) -> int:
    """The value now. The sweep only looks: AP 207, which a GAP clears,
    is read without clearing it, so the program reads what it would have
    read without the sweep (and `tmclsim run` replays the same run)."""
    if r.kind == "var":
        return m.get_global_parameter(r.what, 2)
    if r.kind == "ap":
        if _is_207(m, r):
            return m.error_flags(r.index)
        return m.get_axis_parameter(r.what, r.index)
    return m.get_global_parameter(r.what, r.index)


def profile_of(mx: Matrix, values: Dict[str, Any]) -> str:
    for a in mx.axes:
        if a.target == "profile":
            return str(values[a.name]).lower()
    return mx.profile


def run(mx: Matrix, programs: Dict[str, bytes], index: int, values: Dict[str, Any]) -> Tuple[Dict[str, Any], Optional[Dict[str, str]]]:
    """Runs one scenario: its row, and for a failure the files that
    reproduce it (world TOML and setup lines)."""
    row: Dict[str, Any] = {"scenario": index, **values}
    profile = profile_of(mx, values)
    reads = _reads(mx)
    made = _Made()
    try:
        m = _set_up(mx, programs, profile, values, reads, made)
    except _setup_errors() as e:
        row.update(passed=False, failed_check="setup", error=str(e))
        for name in mx.metrics:
            row[name] = None
        return row, _files(made.text, made.lines)
    m.run()
    seen = _Seen(mx, m, reads)
    ended_at = _run_until_stop(mx, m, seen)
    failed = _first_failed(mx, seen, ended_at)
    row.update(passed=not failed, failed_check=failed, error="")
    _metrics(row, mx, m, seen)
    return row, _files(made.text, made.lines) if failed else None


def _reads(mx: Matrix) -> List[Read]:
    """Every value a stop condition, a check or a metric reads; those with
    max/min are kept over the run."""
    return list(mx.metric_reads) + [c.read for c in mx.stop_when] + [c.condition.read for c in mx.checks if c.condition]


class _Made:
    """What the set-up has made so far (the files of a failure)."""

    def __init__(self) -> None:
        self.text = ""
        self.lines: List[str] = []


def _set_up(mx: Matrix, programs: Dict[str, bytes], profile: str, values: Dict[str, Any], reads: List[Read], made: _Made):
    """The module in its world, its program loaded and its setup lines
    sent, as `files` makes them; every value read is tried once."""
    import tmclsim

    made.text = world_text(mx, values)
    m = tmclsim.Module(profile, world=made.text)
    made.lines = setup_lines(m, mx, values)
    m.load_program(tmclsim.Program.from_binary(programs[profile]))
    for line in made.lines:
        r = m.send(line)
        if r is None or not r.ok:
            raise ScenarioError(f"'{line}' answered {'nothing' if r is None else f'status {r.status} ({r.description})'}")
    for r in reads:
        # A value the module does not have is the scenario's error,
        # found before the program runs.
        read(m, replace(r, aggregate="") if r.aggregate else r)
    return m


class _Seen:
    """What the run showed: the kept maxima and minima of the reads, and
    what the checks and metrics look at after each step (only that)."""

    def __init__(self, mx: Matrix, m, reads: List[Read]) -> None:
        self.m = m
        self.axes = m.axes
        self.kept: Dict[Read, Optional[int]] = {r: None for r in reads if r.aggregate}
        self.plain = {r: replace(r, aggregate="") for r in self.kept}
        self.stalled = self.end_stop = self.limit_switch = False
        self.max_load = self.max_speed = 0
        kinds = {c.kind for c in mx.checks}
        self.watch_speed = "max_speed" in mx.metrics
        self.watch_end_stop = "no_end_stop" in kinds or "end_stop" in mx.metrics
        self.watch_switches = "no_limit_switch" in kinds or "limit_switch" in mx.metrics
        self.watch_stall = "no_stall" in kinds or "stalled" in mx.metrics
        self.stallguard = m.stall_detection == "stallguard2"
        self.watch_load = "max_load" in mx.metrics
        self.watch_any = self.watch_speed or self.watch_end_stop or self.watch_switches or self.watch_stall or self.watch_load

    def value(self, r: Read) -> int:
        return self.kept[r] if r.aggregate else read(self.m, r)

    def keep(self) -> None:
        for r, v in self.kept.items():
            now = read(self.m, self.plain[r])
            self.kept[r] = now if v is None else max(v, now) if r.aggregate == "max" else min(v, now)

    def look(self) -> None:
        """After a step: every axis's speed, stops, switches, stall and load
        that are watched."""
        m = self.m
        for a in range(self.axes) if self.watch_any else ():
            if self.watch_speed:
                self.max_speed = max(self.max_speed, abs(m.actual_speed(a)))
            if self.watch_end_stop:
                self.end_stop = self.end_stop or m.at_end_stop(a)
            if self.watch_switches:
                left, right, _home = m.switches(a)
                self.limit_switch = self.limit_switch or left or right
            if self.watch_stall:
                # A stall stop (AP 207 bit 0, looked at without clearing
                # it), or stallGuard2's flag (AP 208 bit 0: the motor turns
                # with a load reading of 0, losing steps).
                self.stalled = (
                    self.stalled or bool(m.error_flags(a) & 1) or (self.stallguard and bool(m.get_axis_parameter(208, a) & 1))
                )
            if self.watch_load:
                self.max_load = max(self.max_load, m.get_axis_parameter(206, a))


def _run_until_stop(mx: Matrix, m, seen: _Seen) -> Optional[float]:
    """Virtual time in steps until the duration is over, the program ends
    (when that stops the run) or a stop condition holds; when the program
    ended, if it did."""
    ended_at: Optional[float] = None
    seen.keep()  # the state the scenario starts from counts
    t = 0.0
    while t < mx.duration - 1e-12:
        m.advance(min(mx.step, mx.duration - t))
        if m.time <= t:
            break  # a step below the clock's nanosecond (a Matrix made by hand): time stands
        t = m.time
        seen.look()
        seen.keep()
        if mx.stop_program_ended and m.program_mode == "stop":
            ended_at = t
            break
        if ended_at is None and not mx.stop_program_ended and m.program_mode == "stop":
            ended_at = t
        if mx.stop_when and any(c.holds(seen.value(c.read)) for c in mx.stop_when):
            break
    return ended_at


def _first_failed(mx: Matrix, seen: _Seen, ended_at: Optional[float]) -> str:
    """The name of the first check that fails, or ""."""
    for c in mx.checks:
        if not _check(c, seen.value, ended_at, seen.stalled, seen.end_stop, seen.limit_switch):
            return c.name
    return ""


def _metrics(row: Dict[str, Any], mx: Matrix, m, seen: _Seen) -> None:
    """The metrics' columns of the row."""
    for name in mx.metrics:
        row[name] = {
            "time": lambda: round(m.time, 9),
            "position": lambda: m.actual_position(0),
            "carriage": lambda: m.mechanical_position(0),
            "max_load": lambda: seen.max_load,
            "max_speed": lambda: seen.max_speed,
            "stalled": lambda: seen.stalled,
            "end_stop": lambda: seen.end_stop,
            "limit_switch": lambda: seen.limit_switch,
        }.get(name, lambda: None)()
    for r in mx.metric_reads:
        row[r.label()] = seen.value(r)


def _check(c: Check, value, ended_at, stalled, end_stop, limit_switch) -> bool:
    if c.kind == "expr":
        cond: Condition = c.condition
        return cond.holds(value(cond.read))
    if c.kind == "no_stall":
        return not stalled
    if c.kind == "no_end_stop":
        return not end_stop
    if c.kind == "no_limit_switch":
        return not limit_switch
    if c.kind == "program_ended":
        return ended_at is not None
    if c.kind == "finished_within":
        return ended_at is not None and ended_at <= c.seconds + 1e-9
    raise AssertionError(c.kind)


def run_batch(mx: Matrix, programs: Dict[str, bytes], start: int, stop: int):
    """Scenarios `start` up to `stop` in one process (one Dask task)."""
    return [run(mx, programs, i, values) for i, values in enumerate(mx.scenarios(start, stop), start)]
