"""The matrix file of a sweep (docs/sweeps.md): what to vary, how long to
run, when to stop, what decides pass or fail, what to record. Parsing checks
everything up front; an error names the offending key."""

from __future__ import annotations

import copy
import itertools
import math
import random
import re
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

OPS = ("==", "!=", "<=", ">=", "<", ">")
METRICS = ("time", "position", "carriage", "max_load", "max_speed", "stalled", "end_stop", "limit_switch")
# A value read at every look (each `step`) and kept at its highest or
# lowest: `max ap 1 0` (how far the counter went), `min ap 206 0`.
AGGREGATES = ("max", "min")
CHECKS = ("expr", "no_stall", "no_end_stop", "no_limit_switch", "program_ended", "finished_within")


class MatrixError(ValueError):
    """A matrix file that cannot be swept; the message names the key."""


def duration(text: Any, key: str) -> float:
    """`60s`, `500ms`, `2m`, `1h` or a number of seconds."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = float(text)
    else:
        m = re.fullmatch(r"\s*([0-9.]+)\s*(ms|s|m|h)?\s*", str(text))
        if not m:
            raise MatrixError(f"{key}: '{text}' is not a duration (e.g. 500ms, 60s, 2m)")
        value = float(m.group(1)) * {"ms": 1e-3, "s": 1.0, "m": 60.0, "h": 3600.0, None: 1.0}[m.group(2)]
    if not (value > 0 and math.isfinite(value)):
        raise MatrixError(f"{key}: a duration is more than 0 s")
    return value


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
            return Read("var", _int(words[1], key), 0, aggregate), words[2:]
        if kind in ("ap", "gp") and len(words) >= 3:
            what = int(words[1]) if words[1].lstrip("-").isdigit() else words[1]
            return Read(kind, what, _int(words[2], key), aggregate), words[3:]
        raise MatrixError(f"{key}: '{' '.join(words)}': a value is 'var N', 'ap N|NAME MOTOR' or 'gp N BANK' (with 'max ' or 'min ' in front: over the run)")

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
            raise MatrixError(f"{key}: '{text}': write VALUE OP NUMBER with OP one of {' '.join(OPS)}")
        try:
            value = float(rest[1])
        except ValueError:
            raise MatrixError(f"{key}: '{rest[1]}' is not a number") from None
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


@dataclass
class Axis:
    """One varied quantity: its column name, where it goes, its values."""

    name: str
    target: str  # "world", "ap", "gp", "profile"
    key: Any  # world path, parameter number or name
    index: int
    values: List[Any]


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

    def scenarios(self) -> List[Dict[str, Any]]:
        """Every combination of the axes' values, in a fixed order."""
        if not self.axes:
            return [{}]
        names = [a.name for a in self.axes]
        return [dict(zip(names, combo)) for combo in itertools.product(*(a.values for a in self.axes))]


def _int(text: Any, key: str) -> int:
    try:
        return int(text)
    except (TypeError, ValueError):
        raise MatrixError(f"{key}: '{text}' is not a whole number") from None


def _values(entry: Dict[str, Any], key: str, seed: int, name: str) -> List[Any]:
    given = [k for k in ("values", "range", "random") if k in entry]
    if len(given) != 1:
        raise MatrixError(f"{key}: give exactly one of values = [...], range = [start, stop, step], random = {{ min, max, count }}")
    if "values" in entry:
        v = entry["values"]
        if not isinstance(v, list) or not v:
            raise MatrixError(f"{key}.values: a non-empty list")
        return v
    if "range" in entry:
        r = entry["range"]
        if not (isinstance(r, list) and len(r) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in r)):
            raise MatrixError(f"{key}.range: [start, stop, step] (stop included)")
        start, stop, step = r
        if step <= 0 or stop < start:
            raise MatrixError(f"{key}.range: step more than 0 and stop not below start")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > 1_000_000:
            raise MatrixError(f"{key}.range: {n} values; at most 1000000")
        ints = all(isinstance(x, int) for x in r)
        return [start + i * step if ints else round(start + i * step, 12) for i in range(n)]
    d = entry["random"]
    if not isinstance(d, dict) or set(d) - {"min", "max", "count", "integer"} or not {"min", "max", "count"} <= set(d):
        raise MatrixError(f"{key}.random: {{ min = …, max = …, count = N }} (integer = true for whole numbers)")
    count = _int(d["count"], f"{key}.random.count")
    if not 1 <= count <= 1_000_000:
        raise MatrixError(f"{key}.random.count: 1…1000000")
    # Seeded by the matrix seed and the axis name: the same file draws the
    # same values on every machine.
    rng = random.Random(f"{seed}:{name}")
    lo, hi = d["min"], d["max"]
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in (lo, hi)) or lo > hi:
        raise MatrixError(f"{key}.random: min and max are numbers, min not above max")
    integer = d.get("integer", isinstance(lo, int) and isinstance(hi, int))
    if not isinstance(integer, bool):
        raise MatrixError(f"{key}.random.integer: true or false")
    if integer:
        return [rng.randint(int(lo), int(hi)) for _ in range(count)]
    return [rng.uniform(float(lo), float(hi)) for _ in range(count)]


def parse(doc: Dict[str, Any]) -> Matrix:
    """A matrix from the parsed TOML document."""
    known = {"profile", "duration", "step", "seed", "world", "setup", "vary", "stop", "check", "metrics"}
    for k in doc:
        if k not in known:
            raise MatrixError(f"{k}: unknown key (known: {', '.join(sorted(known))})")
    mx = Matrix()
    mx.profile = str(doc.get("profile", mx.profile)).lower()
    mx.duration = duration(doc.get("duration", "60s"), "duration")
    mx.step = duration(doc.get("step", "100ms"), "step")
    if mx.step > mx.duration:
        raise MatrixError("step: longer than the duration")
    mx.seed = _int(doc.get("seed", 0), "seed")
    world = doc.get("world", {"base": "stage"})
    if not isinstance(world, dict):
        raise MatrixError("world: a table with the keys of a world file (docs/world.md)")
    mx.world = copy.deepcopy(world)
    setup = doc.get("setup", [])
    if not isinstance(setup, list) or not all(isinstance(x, str) for x in setup):
        raise MatrixError("setup: a list of direct-mode commands, e.g. [\"SAP 4, 0, 1000\"]")
    mx.setup = list(setup)
    for k in ("vary", "check"):
        if not isinstance(doc.get(k, []), list):
            raise MatrixError(f"{k}: a list of tables ([[{k}]] sections)")
    seen = set()
    for i, entry in enumerate(doc.get("vary", [])):
        key = f"vary[{i}]"
        if not isinstance(entry, dict):
            raise MatrixError(f"{key}: a table ([[vary]])")
        targets = [t for t in ("world", "ap", "gp", "profile") if t in entry]
        if len(targets) != 1:
            raise MatrixError(f"{key}: name what it varies with exactly one of world = \"axis.0.home_switch.from\", ap = N, gp = N, profile = true")
        target = targets[0]
        allowed = {"name", target, "values", "range", "random"} | ({"motor"} if target == "ap" else {"bank"} if target == "gp" else set())
        for k in entry:
            if k not in allowed:
                raise MatrixError(f"{key}.{k}: unknown key")
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
            index = _int(entry.get("motor" if target == "ap" else "bank", 0), f"{key}.{'motor' if target == 'ap' else 'bank'}")
            name = entry.get("name", f"{target} {what} {index}")
            axis = Axis(name, target, what, index, [])
        if not isinstance(name, str) or not name:
            raise MatrixError(f"{key}.name: a column name (text)")
        if name in seen:
            raise MatrixError(f"{key}.name: '{name}' is used twice")
        seen.add(name)
        axis.values = _values(entry, key, mx.seed, name)
        if target == "profile" and not all(isinstance(v, str) for v in axis.values):
            raise MatrixError(f"{key}.values: profile names, e.g. [\"tmcm-1141\", \"tmcm-1140\"]")
        mx.axes.append(axis)
    total = 1
    for a in mx.axes:
        total *= len(a.values)
    if total > 10_000_000:
        raise MatrixError(f"vary: {total} scenarios; at most 10000000")
    stop = doc.get("stop", {})
    if not isinstance(stop, dict) or set(stop) - {"program_ended", "when"}:
        raise MatrixError("stop: a table with program_ended = true|false and when = [\"var 0 != 0\", …]")
    mx.stop_program_ended = bool(stop.get("program_ended", True))
    when = stop.get("when", [])
    if not isinstance(when, list):
        raise MatrixError("stop.when: a list of conditions, e.g. [\"var 0 != 0\"]")
    mx.stop_when = [Condition.parse(t, f"stop.when[{i}]") for i, t in enumerate(when)]
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
                raise MatrixError(f"{key}.{k}: unknown key")
        name = c.get("name", c[kind] if kind == "expr" else kind)
        if not isinstance(name, str):
            raise MatrixError(f"{key}.name: text")
        if kind == "expr":
            tol = c.get("tolerance", 0)
            if isinstance(tol, bool) or not isinstance(tol, (int, float)) or tol < 0:
                raise MatrixError(f"{key}.tolerance: a number, 0 or more")
            mx.checks.append(Check(name, kind, Condition.parse(c["expr"], f"{key}.expr", float(tol))))
        elif kind == "finished_within":
            mx.checks.append(Check(name, kind, seconds=duration(c[kind], f"{key}.finished_within")))
        else:
            if c[kind] is not True:
                raise MatrixError(f"{key}.{kind}: write {kind} = true")
            mx.checks.append(Check(name, kind))
    metrics = doc.get("metrics", ["time"])
    if not isinstance(metrics, list):
        raise MatrixError("metrics: a list, e.g. [\"time\", \"max_load\", \"ap 1 0\"]")
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
                raise MatrixError(f"metrics[{i}]: '{x}' is none of {', '.join(METRICS)} and no value ('var N', 'ap N MOTOR', 'gp N BANK', 'max ap N MOTOR', …)") from None
            if rest:
                raise MatrixError(f"metrics[{i}]: '{x}': extra words")
            if read.label() in mx.metrics:
                raise MatrixError(f"metrics[{i}]: '{x}' is listed twice")
            mx.metrics.append(read.label())
            mx.metric_reads.append(read)
    # Every column of the table has one name.
    columns = {"scenario", "passed", "failed_check", "error"}
    for i, a in enumerate(mx.axes):
        if a.name in columns:
            raise MatrixError(f"vary[{i}].name: '{a.name}' is a column of the table already")
        columns.add(a.name)
    for i, name in enumerate(mx.metrics):
        if name in columns:
            raise MatrixError(f"metrics[{i}]: '{name}' is a column of the table already (a [[vary]] name?)")
    return mx


def load(path) -> Matrix:
    """Reads and parses a matrix file."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    with open(path, "rb") as f:
        try:
            doc = tomllib.load(f)
        except tomllib.TOMLDecodeError as e:
            raise MatrixError(f"{path}: {e}") from None
    return parse(doc)
