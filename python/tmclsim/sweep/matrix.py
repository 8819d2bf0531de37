"""The matrix file of a sweep (docs/sweeps.md): what to vary, how long to
run, when to stop, what decides pass or fail, what to record. Parsing checks
everything up front; an error names the offending key. Every input has a
limit (docs/sweeps.md, "Limits"): the scenarios are counted, never listed,
before the sweep starts."""

from __future__ import annotations

import copy
import functools
import math
import random
import re
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple

OPS = ("==", "!=", "<=", ">=", "<", ">")
METRICS = ("time", "position", "carriage", "max_load", "max_speed", "stalled", "end_stop", "limit_switch")
# A value read at every look (each `step`) and kept at its highest or
# lowest: `max ap 1 0` (how far the counter went), `min ap 206 0`.
AGGREGATES = ("max", "min")
CHECKS = ("expr", "no_stall", "no_end_stop", "no_limit_switch", "program_ended", "finished_within")

# The limits of a matrix (docs/sweeps.md, "Limits").
MAX_SCENARIOS = 10_000_000  # scenarios of one sweep: the product of the axes' sizes
MAX_AXIS_VALUES = 1_000_000  # values of one [[vary]] (a range's are counted, not listed)
MAX_AXES = 32  # [[vary]] entries: each is a column of the table
MAX_METRICS = 64  # metrics: each is a column of the table
MAX_DURATION = 86_400.0  # virtual seconds a scenario (or finished_within) runs at most
MIN_STEP = 1e-6  # the shortest step between looks, in seconds
MAX_LOOKS = 1_000_000  # looks per scenario: duration / step
MAX_DEPTH = 32  # tables and lists nested in one another, and parts of one key
MAX_MATRIX_BYTES = 1 << 20  # a matrix file
MAX_WORLD_INDEX = 63  # an entry of a world list other than inputs, analog, axis, travel
MAX_SEED = 2**64 - 1  # |seed|
WORLD_DIGITAL_INPUTS = 32  # the inputs a world file can list
WORLD_ANALOG_INPUTS = 8


class MatrixError(ValueError):
    """A matrix file that cannot be swept; the message names the key."""


def _show(value: Any) -> str:
    """A value as an error message quotes it: on one line, at most 40
    characters of it."""
    try:
        text = value if isinstance(value, str) else repr(value)
    except ValueError:  # an integer of more than 4300 digits
        text = f"a {type(value).__name__}"
    text = "".join(c if c.isprintable() else "?" for c in text[:41])
    return text if len(text) <= 40 else text[:39] + "…"


def seconds_text(seconds: float) -> str:
    """`40.1`, `60`, `0.000001`: a number of seconds as `tmclsim run --for`
    reads it (decimal, at most nanoseconds)."""
    return f"{seconds:.9f}".rstrip("0").rstrip(".")


_DURATION = re.compile(r"([0-9]+(?:\.[0-9]*)?|\.[0-9]+)\s*(us|ms|s|m|h)?")
_UNITS = {"us": 1e-6, "ms": 1e-3, "s": 1.0, "m": 60.0, "h": 3600.0, None: 1.0}


def duration(text: Any, key: str) -> float:
    """`60s`, `500ms`, `2m`, `1h`, `250us` or a number of seconds: more than
    0, at most MAX_DURATION."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        try:
            value = float(text)
        except OverflowError:  # an integer beyond any float
            value = math.inf
    else:
        m = _DURATION.fullmatch(text.strip()) if isinstance(text, str) else None
        if not m:
            raise MatrixError(f"{key}: '{_show(text)}' is not a duration (e.g. 500ms, 60s, 2m)")
        value = float(m.group(1)) * _UNITS[m.group(2)]
    if not (value > 0 and math.isfinite(value)):
        raise MatrixError(f"{key}: '{_show(text)}': a duration is a finite time of more than 0 s")
    if value > MAX_DURATION:
        raise MatrixError(f"{key}: {value:g} s is longer than {MAX_DURATION / 3600:.0f} h, the limit of a scenario")
    return value


def _int(value: Any, key: str, lo: int, hi: int) -> int:
    """A whole number from lo to hi: an integer, a float without a
    fraction or the digits of one (not true or false)."""
    n: Optional[int] = None
    if isinstance(value, int) and not isinstance(value, bool):
        n = value
    elif isinstance(value, float) and value.is_integer():
        n = int(value)
    elif isinstance(value, str) and re.fullmatch(r"[+-]?[0-9]{1,30}", value.strip()):
        n = int(value)
    if n is None:
        raise MatrixError(f"{key}: '{_show(value)}' is not a whole number")
    if not lo <= n <= hi:
        raise MatrixError(f"{key}: {_show(n)} is outside {lo}…{hi}")
    return n


def _byte(value: Any, key: str) -> int:
    """A TMCL parameter number, motor, bank or user variable: 0…255."""
    return _int(value, key, 0, 255)


def count_text(n: int) -> str:
    """A count as a message gives it: exact up to 10^15, else its order."""
    return str(n) if n < 10**15 else f"about 10^{int(math.log10(n))}"


@dataclass(frozen=True)
class Read:
    """A value of the module: `var N`, `ap N|name MOTOR`, `gp N BANK`; with
    `max ` or `min ` in front, its highest or lowest over every look."""

    kind: str
    what: Any
    index: int = 0
    aggregate: str = ""

    @staticmethod
    def parse(words: List[str], key: str) -> Tuple["Read", List[str]]:
        aggregate = ""
        if words and words[0].lower() in AGGREGATES:
            aggregate, words = words[0].lower(), words[1:]
        if not words:
            raise MatrixError(f"{key}: a value is 'var N', 'ap N MOTOR' or 'gp N BANK' (with 'max ' or 'min ' in front: over the run)")
        kind = words[0].lower()
        if kind == "var" and len(words) >= 2:
            return Read("var", _byte(words[1], key), 0, aggregate), words[2:]
        if kind in ("ap", "gp") and len(words) >= 3:
            what = _byte(words[1], key) if re.fullmatch(r"[+-]?[0-9]+", words[1]) else words[1]
            return Read(kind, what, _byte(words[2], key), aggregate), words[3:]
        raise MatrixError(f"{key}: '{_show(' '.join(words))}': a value is 'var N', 'ap N|NAME MOTOR' or 'gp N BANK' (with 'max ' or 'min ' in front: over the run)")

    def label(self) -> str:
        text = f"var {self.what}" if self.kind == "var" else f"{self.kind} {self.what} {self.index}"
        return f"{self.aggregate} {text}" if self.aggregate else text


@dataclass(frozen=True)
class Condition:
    """`READ OP NUMBER`, e.g. `var 0 == 1`, `ap 1 0 >= -100`."""

    read: Read
    op: str
    value: float
    tolerance: float = 0.0
    text: str = ""

    @staticmethod
    def parse(text: Any, key: str, tolerance: float = 0.0) -> "Condition":
        if not isinstance(text, str):
            raise MatrixError(f"{key}: a condition is text such as \"var 0 == 1\"")
        words = text.split()
        read, rest = Read.parse(words, key)
        if len(rest) != 2 or rest[0] not in OPS:
            raise MatrixError(f"{key}: '{_show(text)}': write VALUE OP NUMBER with OP one of {' '.join(OPS)}")
        try:
            value = float(rest[1])
        except ValueError:
            raise MatrixError(f"{key}: '{_show(rest[1])}' is not a number") from None
        if not math.isfinite(value):
            raise MatrixError(f"{key}: '{_show(rest[1])}' is not a finite number")
        return Condition(read, rest[0], value, tolerance, text)

    def holds(self, v: float) -> bool:
        d = v - self.value
        return {
            "==": abs(d) <= self.tolerance,
            "!=": abs(d) > self.tolerance,
            "<": d < 0,
            "<=": d <= self.tolerance,
            ">": d > 0,
            ">=": d >= -self.tolerance,
        }[self.op]


@dataclass(frozen=True)
class Check:
    """What decides pass or fail: a condition on the final state (or on a
    `max`/`min` over the run), or one of `no_stall`, `no_end_stop`,
    `no_limit_switch`, `program_ended`, `finished_within`."""

    name: str
    kind: str
    condition: Optional[Condition] = None
    seconds: float = 0.0


class Range(Sequence):
    """The values of `range = [start, stop, step]`, computed from their
    position, never listed: a range of a million values costs no memory."""

    def __init__(self, start: Any, step: Any, count: int):
        self.start, self.step, self.count = start, step, count
        self.ints = isinstance(start, int) and isinstance(step, int)

    def __len__(self) -> int:
        return self.count

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(self.count))]
        if i < 0:
            i += self.count
        if not 0 <= i < self.count:
            raise IndexError(i)
        v = self.start + i * self.step
        return v if self.ints else round(v, 12)

    def __repr__(self) -> str:
        return f"Range(start={self.start!r}, step={self.step!r}, count={self.count})"


@dataclass
class Axis:
    """One varied quantity: its column name, where it goes, its values."""

    name: str
    target: str  # "world", "ap", "gp", "profile"
    key: Any  # world path, parameter number or name
    index: int
    values: Sequence[Any]


@dataclass
class Matrix:
    profile: str = "tmcm-1141"
    duration: float = 60.0
    step: float = 0.1
    seed: int = 0
    world: Dict[str, Any] = field(default_factory=lambda: {"base": "stage"})
    setup: List[str] = field(default_factory=list)
    axes: List[Axis] = field(default_factory=list)
    stop_program_ended: bool = True
    stop_when: List[Condition] = field(default_factory=list)
    checks: List[Check] = field(default_factory=list)
    metrics: List[str] = field(default_factory=lambda: ["time"])
    metric_reads: List[Read] = field(default_factory=list)

    def count(self) -> int:
        """How many scenarios: the product of the axes' sizes."""
        n = 1
        for a in self.axes:
            n *= len(a.values)
        return n

    def scenario(self, index: int) -> Dict[str, Any]:
        """Scenario `index` (0 ≤ index < count()); the first axis varies
        slowest."""
        if not 0 <= index < self.count():
            raise IndexError(f"scenario {index}: the matrix has {self.count()}")
        values: Dict[str, Any] = {}
        for a in reversed(self.axes):
            index, k = divmod(index, len(a.values))
            values[a.name] = a.values[k]
        return {a.name: values[a.name] for a in self.axes}

    def scenarios(self, start: int = 0, stop: Optional[int] = None) -> Iterator[Dict[str, Any]]:
        """Scenarios `start` up to `stop` (default: all), one at a time, in
        a fixed order; none is kept."""
        stop = self.count() if stop is None else min(stop, self.count())
        for i in range(max(0, start), stop):
            yield self.scenario(i)


@functools.lru_cache(maxsize=None)
def profile_facts(profile: str) -> Tuple[str, int, Tuple[int, ...], Tuple[int, ...]]:
    """A module profile's name (`TMCM-1141`), its axes, and the numbers of
    its digital and of its analog inputs, as its world accepts them."""
    import tmclsim

    m = tmclsim.Module(profile)

    def accepted(line: str) -> bool:
        try:
            m.world(line)
            return True
        except ValueError:
            return False

    digital = tuple(n for n in range(WORLD_DIGITAL_INPUTS) if accepted(f"input {n} 0"))
    analog = tuple(n for n in range(WORLD_ANALOG_INPUTS) if accepted(f"analog {n} 0"))
    return m.profile, m.axes, digital, analog


def _numbers(ns: Sequence[int]) -> str:
    """`0…3`, `0, 2, 5` or `none`."""
    if not ns:
        return "none"
    if len(ns) > 1 and ns[-1] - ns[0] + 1 == len(ns):
        return f"{ns[0]}…{ns[-1]}"
    return ", ".join(map(str, ns))


def _profile(value: Any, key: str) -> str:
    import tmclsim

    known = tmclsim.profiles()
    if not isinstance(value, str) or value.lower() not in known:
        raise MatrixError(f"{key}: '{_show(value)}' is no module profile (profiles: {', '.join(sorted(known))})")
    return value.lower()


def world_key(path: str, key: str, profiles: Sequence[str]) -> str:
    """A dotted key of the world file whose list entries exist on every
    profile the sweep runs on: `inputs.N` and `analog.N` an input of the
    module, `axis.N` one of its axes, `….travel.N` 0 or 1, any other entry
    at most MAX_WORLD_INDEX. Checked before any list is made."""
    parts = path.split(".")
    if len(parts) > MAX_DEPTH:
        raise MatrixError(f"{key}: '{_show(path)}' has more than {MAX_DEPTH} parts")
    for j, part in enumerate(parts):
        if not part:
            raise MatrixError(f"{key}: '{_show(path)}' has an empty part")
        if not re.fullmatch(r"[0-9]+", part):
            continue
        if j == 0:
            raise MatrixError(f"{key}: '{_show(path)}': the world file is a table, '{_show(part)}' indexes a list")
        n = int(part) if len(part) <= 9 else 10**9
        above = parts[j - 1]
        for p in profiles:
            name, axes, digital, analog = profile_facts(p)
            if j == 1 and above in ("inputs", "analog"):
                kind, have = ("digital", digital) if above == "inputs" else ("analog", analog)
                if n not in have:
                    raise MatrixError(f"{key}: '{_show(path)}': the {name} has no {kind} input {_show(part)} ({kind} inputs: {_numbers(have)})")
            elif j == 1 and above == "axis" and n >= axes:
                raise MatrixError(f"{key}: '{_show(path)}': the {name} has no axis {_show(part)} (axes: {_numbers(range(axes))})")
        if above == "travel" and n > 1:
            raise MatrixError(f"{key}: '{_show(path)}': travel is a pair, entries 0 and 1")
        if n > MAX_WORLD_INDEX:
            raise MatrixError(f"{key}: '{_show(path)}': list entry {_show(part)}; at most {MAX_WORLD_INDEX}")
    return path


def _number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _values(entry: Dict[str, Any], key: str) -> Tuple[int, Any]:
    """How many values an axis has, counted without listing them, and what
    gives them: the list, a Range, or the random draw's (min, max, integer)."""
    given = [k for k in ("values", "range", "random") if k in entry]
    if len(given) != 1:
        raise MatrixError(f"{key}: give exactly one of values = [...], range = [start, stop, step], random = {{ min, max, count }}")
    if "values" in entry:
        v = entry["values"]
        if not isinstance(v, list) or not v:
            raise MatrixError(f"{key}.values: a non-empty list")
        if len(v) > MAX_AXIS_VALUES:
            raise MatrixError(f"{key}.values: {len(v)} values; at most {MAX_AXIS_VALUES}")
        return len(v), v
    if "range" in entry:
        r = entry["range"]
        if not (isinstance(r, list) and len(r) == 3 and all(_number(x) for x in r)):
            raise MatrixError(f"{key}.range: [start, stop, step] (stop included)")
        start, stop, step = r
        if step <= 0 or stop < start:
            raise MatrixError(f"{key}.range: step more than 0 and stop not below start")
        if all(isinstance(x, int) for x in r):
            n = (stop - start) // step + 1
        else:
            # Counted, not listed: (stop - start) / step may be 10^300.
            span = (stop - start) / step
            if not math.isfinite(span):
                raise MatrixError(f"{key}.range: more values than any count; at most {MAX_AXIS_VALUES} (a longer step)")
            n = int(math.floor(span + 1e-9)) + 1
        if n > MAX_AXIS_VALUES:
            raise MatrixError(f"{key}.range: {count_text(n)} values; at most {MAX_AXIS_VALUES} (a longer step)")
        return n, Range(start, step, n)
    d = entry["random"]
    if not isinstance(d, dict) or set(d) - {"min", "max", "count", "integer"} or not {"min", "max", "count"} <= set(d):
        raise MatrixError(f"{key}.random: {{ min = …, max = …, count = N }} (integer = true for whole numbers)")
    count = _int(d["count"], f"{key}.random.count", 1, MAX_AXIS_VALUES)
    lo, hi = d["min"], d["max"]
    if not (_number(lo) and _number(hi)) or lo > hi:
        raise MatrixError(f"{key}.random: min and max are numbers, min not above max")
    integer = d.get("integer", isinstance(lo, int) and isinstance(hi, int))
    if not isinstance(integer, bool):
        raise MatrixError(f"{key}.random.integer: true or false")
    return count, (lo, hi, integer)


def _draw(spec: Tuple[Any, Any, bool], count: int, seed: int, name: str) -> List[Any]:
    # Seeded by the matrix seed and the axis name: the same file draws the
    # same values on every machine.
    rng = random.Random(f"{seed}:{name}")
    lo, hi, integer = spec
    if integer:
        return [rng.randint(int(lo), int(hi)) for _ in range(count)]
    return [rng.uniform(float(lo), float(hi)) for _ in range(count)]


def check_depth(doc: Any, what: str = "the matrix") -> None:
    """Tables and lists nested at most MAX_DEPTH deep (a cycle, from
    Python, is deeper than any limit), walked without recursion: nothing
    after it (copies, the world file's text) meets a RecursionError."""

    def inside(node):
        return node.values() if isinstance(node, dict) else node if isinstance(node, (list, tuple)) else ()

    if not isinstance(doc, (dict, list, tuple)):
        return
    reach: Dict[int, int] = {}  # containers walked: how many levels they hold
    stack = [[doc, iter(inside(doc)), 0]]  # a container, its entries left, the deepest entry so far
    on_path = {id(doc)}
    while stack:
        frame = stack[-1]
        for child in frame[1]:
            if not isinstance(child, (dict, list, tuple)):
                continue
            levels = reach.get(id(child))
            if levels is None and id(child) not in on_path and len(stack) < MAX_DEPTH:
                on_path.add(id(child))
                stack.append([child, iter(inside(child)), 0])
                break
            if levels is None or len(stack) + levels > MAX_DEPTH:
                raise MatrixError(f"{what}: tables and lists nested more than {MAX_DEPTH} deep, the limit")
            frame[2] = max(frame[2], levels)
        else:
            stack.pop()
            on_path.discard(id(frame[0]))
            reach[id(frame[0])] = frame[2] + 1
            if stack:
                stack[-1][2] = max(stack[-1][2], frame[2] + 1)


def parse(doc: Dict[str, Any]) -> Matrix:
    """A matrix from the parsed TOML document. Its parts are read in a
    fixed order, and the first mistake met is the one reported."""
    if not isinstance(doc, dict):
        raise MatrixError("the matrix is a table (a TOML document)")
    check_depth(doc)
    known = {"profile", "duration", "step", "seed", "world", "setup", "vary", "stop", "check", "metrics"}
    for k in doc:
        if k not in known:
            raise MatrixError(f"{_show(k)}: unknown key (known: {', '.join(sorted(known))})")
    mx = Matrix()
    _timing(mx, doc)
    _world_and_setup(mx, doc)
    for k in ("vary", "check"):
        if not isinstance(doc.get(k, []), list):
            raise MatrixError(f"{k}: a list of tables ([[{k}]] sections)")
    if len(doc.get("vary", [])) > MAX_AXES:
        raise MatrixError(f"vary: {len(doc['vary'])} [[vary]] sections; at most {MAX_AXES}")
    draws, worlds = _vary(mx, doc)
    _draw_values(mx, draws, worlds)
    _stop(mx, doc)
    _checks(mx, doc)
    _metrics(mx, doc)
    _columns(mx)
    return mx


def _timing(mx: Matrix, doc: Dict[str, Any]) -> None:
    """The profile, duration, step (and so the looks per scenario), seed."""
    mx.profile = _profile(doc.get("profile", mx.profile), "profile")
    mx.duration = duration(doc.get("duration", "60s"), "duration")
    mx.step = duration(doc.get("step", "100ms"), "step")
    if mx.step > mx.duration:
        raise MatrixError("step: longer than the duration")
    if mx.step < MIN_STEP:
        raise MatrixError(f"step: {seconds_text(mx.step) if mx.step >= 1e-9 else _show(mx.step)} s is shorter than 1 µs, the shortest step")
    looks = math.ceil(mx.duration / mx.step - 1e-9)
    if looks > MAX_LOOKS:
        raise MatrixError(f"step: {seconds_text(mx.duration)} s in steps of {seconds_text(mx.step)} s is {looks} looks per scenario; "
                          f"at most {MAX_LOOKS} (a longer step or a shorter duration)")
    mx.seed = _int(doc.get("seed", 0), "seed", -MAX_SEED, MAX_SEED)


def _world_and_setup(mx: Matrix, doc: Dict[str, Any]) -> None:
    """The world of every scenario and the direct-mode commands before it."""
    world = doc.get("world", {"base": "stage"})
    if not isinstance(world, dict):
        raise MatrixError("world: a table with the keys of a world file (docs/world.md)")
    mx.world = copy.deepcopy(world)
    setup = doc.get("setup", [])
    if not isinstance(setup, list) or not all(isinstance(x, str) for x in setup):
        raise MatrixError("setup: a list of direct-mode commands, e.g. [\"SAP 4, 0, 1000\"]")
    mx.setup = list(setup)


def _vary(mx: Matrix, doc: Dict[str, Any]) -> Tuple[Dict[int, Tuple[Any, Any, bool]], List[Tuple[str, str]]]:
    """The [[vary]] axes, with their values listed or counted: the random
    ones (by axis index) are drawn once the sweep's size is known, the
    world keys (key, dotted path) checked against its modules."""
    seen = set()
    draws: Dict[int, Tuple[Any, Any, bool]] = {}
    worlds: List[Tuple[str, str]] = []
    for i, entry in enumerate(doc.get("vary", [])):
        key = f"vary[{i}]"
        axis, path = _axis(entry, key, seen)
        if path is not None:
            worlds.append((f"{key}.world", path))
        target = axis.target
        count, values = _values(entry, key)
        if isinstance(values, tuple):
            # Drawn below, once the sweep's size is known.
            draws[len(mx.axes)] = values
            values = Range(0, 0, count)
        elif target == "profile":
            if not all(isinstance(v, str) for v in values):
                raise MatrixError(f"{key}.values: profile names, e.g. [\"tmcm-1141\", \"tmcm-1140\"]")
            for j, v in enumerate(values):
                _profile(v, f"{key}.values[{j}]")
        axis.values = values
        mx.axes.append(axis)
    return draws, worlds


def _axis(entry: Any, key: str, seen: set) -> Tuple[Axis, Optional[str]]:
    """One [[vary]] table's axis, without values, and the dotted world key
    it varies (None for another target); its name joins `seen`."""
    if not isinstance(entry, dict):
        raise MatrixError(f"{key}: a table ([[vary]])")
    targets = [t for t in ("world", "ap", "gp", "profile") if t in entry]
    if len(targets) != 1:
        raise MatrixError(f"{key}: name what it varies with exactly one of world = \"axis.0.home_switch.from\", ap = N, gp = N, profile = true")
    target = targets[0]
    allowed = {"name", target, "values", "range", "random"} | ({"motor"} if target == "ap" else {"bank"} if target == "gp" else set())
    for k in entry:
        if k not in allowed:
            raise MatrixError(f"{key}.{_show(k)}: unknown key")
    if target == "world":
        path = entry["world"]
        if not isinstance(path, str) or not path:
            raise MatrixError(f"{key}.world: a dotted key of the world file, e.g. \"axis.0.home_switch.from\"")
        name = entry.get("name", path)
        axis = Axis(name, "world", path, 0, [])
    elif target == "profile":
        name = entry.get("name", "profile")
        axis = Axis(name, "profile", None, 0, [])
    else:
        what = entry[target]
        if isinstance(what, bool) or not isinstance(what, (int, str)):
            raise MatrixError(f"{key}.{target}: a parameter number or name")
        if isinstance(what, int):
            _byte(what, f"{key}.{target}")
        which = "motor" if target == "ap" else "bank"
        index = _byte(entry.get(which, 0), f"{key}.{which}")
        name = entry.get("name", f"{target} {what} {index}")
        axis = Axis(name, target, what, index, [])
    if not isinstance(name, str) or not name:
        raise MatrixError(f"{key}.name: a column name (text)")
    if name in seen:
        raise MatrixError(f"{key}.name: '{_show(name)}' is used twice")
    seen.add(name)
    return axis, (path if target == "world" else None)


def _draw_values(mx: Matrix, draws: Dict[int, Tuple[Any, Any, bool]], worlds: List[Tuple[str, str]]) -> None:
    """Counts the scenarios, then draws the random values and checks the
    world keys on every module the sweep runs on."""
    # The scenarios are counted before any value is drawn or listed.
    total = mx.count()
    if total > MAX_SCENARIOS:
        sizes = " × ".join(str(len(a.values)) for a in mx.axes)
        raise MatrixError(f"vary: {count_text(total)} scenarios ({sizes}); at most {MAX_SCENARIOS}")
    for i, spec in draws.items():
        a = mx.axes[i]
        a.values = _draw(spec, len(a.values), mx.seed, a.name)
    # List entries of the world exist on every module the sweep runs on.
    profiles = next((a.values for a in mx.axes if a.target == "profile"), [mx.profile])
    for key, path in worlds:
        world_key(path, key, sorted({p.lower() for p in profiles}))


def _stop(mx: Matrix, doc: Dict[str, Any]) -> None:
    """When a scenario ends before its duration."""
    stop = doc.get("stop", {})
    if not isinstance(stop, dict) or set(stop) - {"program_ended", "when"}:
        raise MatrixError("stop: a table with program_ended = true|false and when = [\"var 0 != 0\", …]")
    ended = stop.get("program_ended", True)
    if not isinstance(ended, bool):
        raise MatrixError("stop.program_ended: true or false")
    mx.stop_program_ended = ended
    when = stop.get("when", [])
    if not isinstance(when, list):
        raise MatrixError("stop.when: a list of conditions, e.g. [\"var 0 != 0\"]")
    mx.stop_when = [Condition.parse(t, f"stop.when[{i}]") for i, t in enumerate(when)]


def _checks(mx: Matrix, doc: Dict[str, Any]) -> None:
    """The [[check]] tables: what makes a scenario pass."""
    for i, c in enumerate(doc.get("check", [])):
        key = f"check[{i}]"
        if not isinstance(c, dict):
            raise MatrixError(f"{key}: a table ([[check]])")
        kinds = [k for k in CHECKS if k in c]
        if len(kinds) != 1:
            raise MatrixError(f"{key}: exactly one of expr = \"var 0 == 1\", no_stall, no_end_stop, no_limit_switch, program_ended, finished_within = \"30s\"")
        kind = kinds[0]
        for k in c:
            if k not in {"name", kind, "tolerance"}:
                raise MatrixError(f"{key}.{_show(k)}: unknown key")
        name = c.get("name", c[kind] if kind == "expr" else kind)
        if not isinstance(name, str):
            raise MatrixError(f"{key}.name: text")
        if kind == "expr":
            tol = c.get("tolerance", 0)
            if not _number(tol) or tol < 0:
                raise MatrixError(f"{key}.tolerance: a finite number, 0 or more")
            mx.checks.append(Check(name, kind, Condition.parse(c["expr"], f"{key}.expr", float(tol))))
        elif kind == "finished_within":
            mx.checks.append(Check(name, kind, seconds=duration(c[kind], f"{key}.finished_within")))
        else:
            if c[kind] is not True:
                raise MatrixError(f"{key}.{kind}: write {kind} = true")
            mx.checks.append(Check(name, kind))


def _metrics(mx: Matrix, doc: Dict[str, Any]) -> None:
    """The values each scenario reports beside its axes."""
    metrics = doc.get("metrics", ["time"])
    if not isinstance(metrics, list):
        raise MatrixError("metrics: a list, e.g. [\"time\", \"max_load\", \"ap 1 0\"]")
    if len(metrics) > MAX_METRICS:
        raise MatrixError(f"metrics: {len(metrics)} metrics; at most {MAX_METRICS}")
    mx.metrics = []
    for i, x in enumerate(metrics):
        if x in METRICS:
            if x in mx.metrics:
                raise MatrixError(f"metrics[{i}]: '{x}' is listed twice")
            mx.metrics.append(x)
        else:
            try:
                read, rest = Read.parse(str(x).split(), f"metrics[{i}]")
            except MatrixError:
                raise MatrixError(f"metrics[{i}]: '{_show(x)}' is none of {', '.join(METRICS)} and no value ('var N', 'ap N MOTOR', 'gp N BANK', 'max ap N MOTOR', …)") from None
            if rest:
                raise MatrixError(f"metrics[{i}]: '{_show(x)}': extra words")
            if read.label() in mx.metrics:
                raise MatrixError(f"metrics[{i}]: '{_show(x)}' is listed twice")
            mx.metrics.append(read.label())
            mx.metric_reads.append(read)


def _columns(mx: Matrix) -> None:
    """Every column of the table has one name: the fixed ones, the axes',
    the metrics'."""
    columns = {"scenario", "passed", "failed_check", "error"}
    for i, a in enumerate(mx.axes):
        if a.name in columns:
            raise MatrixError(f"vary[{i}].name: '{_show(a.name)}' is a column of the table already")
        columns.add(a.name)
    for i, name in enumerate(mx.metrics):
        if name in columns:
            raise MatrixError(f"metrics[{i}]: '{_show(name)}' is a column of the table already (a [[vary]] name?)")


# Outside strings and comments: the characters that open, close or divide
# keys, tables and lists.
_SIGNIFICANT = re.compile(r"[\n#\"'\[\]{}=.,]")
_STRING_ENDS = {
    '"""': re.compile(r'(?:[^"\\]|\\.|"(?!""))*(?:"""(?:""|")?|\Z)', re.S),
    "'''": re.compile(r"(?:[^']|'(?!''))*(?:'''(?:''|')?|\Z)"),
    '"': re.compile(r'(?:[^"\\\n]|\\.)*(?:"|(?=\n)|\Z)'),
    "'": re.compile(r"[^'\n]*(?:'|(?=\n)|\Z)"),
}


def check_toml_nesting(text: str) -> None:
    """Before a TOML parser sees `text`: no key or table header of more
    than MAX_DEPTH parts, and no more than MAX_DEPTH lists and inline
    tables open at once. (tomllib recurses into nested lists, and takes
    memory quadratic in the parts of a dotted key: 10 000 parts cost it
    400 MB.) Strings and comments are skipped; whatever else is wrong is
    the parser's to report."""
    i, n, line = 0, len(text), 1
    nested: List[str] = []  # "[" and "{" open in a value
    mode = "start"  # of a line; then "key" or "header" (parts counted), or "value"
    parts = 1
    while True:
        m = _SIGNIFICANT.search(text, i)
        j = m.start() if m else n
        if mode == "start" and text[i:j].strip(" \t\r"):
            mode, parts = "key", 1
        if not m:
            return
        c, i = text[j], j + 1
        if c == "\n":
            line += 1
            if not nested:
                mode = "start"
        elif c == "#":
            end = text.find("\n", i)
            i = n if end < 0 else end
        elif c in "\"'":
            quote = c * 3 if text.startswith(c * 3, j) else c
            end = _STRING_ENDS[quote].match(text, j + len(quote)).end()
            line += text.count("\n", j, end)
            i = end
            if mode == "start":
                mode, parts = "key", 1
        elif mode == "start" and c == "[":
            mode, parts = "header", 1
        elif mode != "value":
            if mode == "start":
                mode, parts = "key", 1
            if c == ".":
                parts += 1
                if parts > MAX_DEPTH:
                    raise MatrixError(f"line {line}: a key of more than {MAX_DEPTH} parts, the limit")
            elif c == "=" and mode == "key":
                mode = "value"
            elif c == "]" and mode == "header":
                mode = "value"
            elif c == "}" and nested:
                nested.pop()
                mode = "value"
        elif c in "[{":
            nested.append(c)
            if len(nested) > MAX_DEPTH:
                raise MatrixError(f"line {line}: lists and inline tables nested more than {MAX_DEPTH} deep, the limit")
            if c == "{":
                mode, parts = "key", 1
        elif c in "]}":
            if nested:
                nested.pop()
        elif c == "," and nested and nested[-1] == "{":
            mode, parts = "key", 1


def load(path) -> Matrix:
    """Reads and parses a matrix file (at most MAX_MATRIX_BYTES)."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    with open(path, "rb") as f:
        data = f.read(MAX_MATRIX_BYTES + 1)
    if len(data) > MAX_MATRIX_BYTES:
        raise MatrixError(f"{path}: larger than {MAX_MATRIX_BYTES >> 20} MiB, the limit for a matrix file")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise MatrixError(f"{path}: not UTF-8 text (byte {e.start})") from None
    try:
        check_toml_nesting(text)
    except MatrixError as e:
        raise MatrixError(f"{path}: {e}") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise MatrixError(f"{path}: {e}") from None
    except (ValueError, RecursionError) as e:  # e.g. an integer of more than 4300 digits
        raise MatrixError(f"{path}: {str(e).splitlines()[0] if str(e) else type(e).__name__}") from None
    return parse(doc)
