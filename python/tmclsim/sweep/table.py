"""The table of a sweep, filled as rows come back, in any order. A row is
not kept: its varied values follow from its scenario number (and are made
once, for the whole column, at the end), and every other column is kept
in an array of its own, typed while its values allow it: 1 byte a row for
`passed`, 4 for `failed_check` and `error` (numbers of their texts), at
most 8 for a metric. The DataFrame is the one pandas makes of the rows."""

from __future__ import annotations

from array import array
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence

from .matrix import Axis, Matrix

_INT64 = (-(2**63), 2**63 - 1)


def _kind(v: Any) -> str:
    if isinstance(v, bool):
        return "b"
    if isinstance(v, int) and _INT64[0] <= v <= _INT64[1]:
        return "q"
    if isinstance(v, float):
        return "d"
    return "O"


class Column:
    """One metric's values: bool, int64 or float64 while they all are (an
    int among floats is a float, as in pandas), a list of objects once they
    are not; None (a scenario that could not run) marked apart."""

    def __init__(self, count: int):
        self.count = count
        self.kind: Optional[str] = None
        self.data: Any = None
        self.missing: Optional[bytearray] = None

    def put(self, i: int, v: Any) -> None:
        if v is None:
            if self.missing is None:
                self.missing = bytearray(self.count)
            self.missing[i] = 1
            return
        k = _kind(v)
        if k != self.kind and not (self.kind == "d" and k == "q"):
            self._widen(k)
        self.data[i] = float(v) if self.kind == "d" else v

    def _widen(self, k: str) -> None:
        n = self.count
        if self.kind is None:
            self.data = bytearray(n) if k == "b" else array(k, bytes(8 * n)) if k in "qd" else [None] * n
            self.kind = k
        elif self.kind == "q" and k == "d":
            self.data = array("d", self.data)
            self.kind = "d"
        else:
            self.data = [bool(x) for x in self.data] if self.kind == "b" else list(self.data) if self.kind != "O" else self.data
            self.kind = "O"

    def values(self):
        """The column as pandas takes it."""
        import numpy as np

        mask = None if self.missing is None else np.frombuffer(self.missing, dtype=bool)
        if self.kind is None:
            return [None] * self.count
        if self.kind in "qd":
            a = np.frombuffer(self.data, dtype=np.int64 if self.kind == "q" else np.float64)
            if mask is None or not mask.any():
                return a
            a = a.astype(np.float64)  # as pandas makes whole numbers with gaps
            a[mask] = np.nan
            return a
        if self.kind == "b" and (mask is None or not mask.any()):
            return np.frombuffer(self.data, dtype=bool)
        out = [bool(x) for x in self.data] if self.kind == "b" else self.data
        if mask is not None:
            for i in np.flatnonzero(mask).tolist():
                out[i] = None
        return out


class Texts:
    """A column of texts, few of them distinct: a number per row."""

    def __init__(self, count: int):
        self.codes = array("I", bytes(4 * count))
        self.texts: List[str] = [""]
        self.numbers: Dict[str, int] = {"": 0}

    def put(self, i: int, text: str) -> None:
        n = self.numbers.get(text)
        if n is None:
            n = self.numbers[text] = len(self.texts)
            self.texts.append(text)
        self.codes[i] = n

    def values(self):
        import numpy as np

        return _take(self.texts, np.frombuffer(self.codes, dtype=np.uint32).astype(np.intp))


def _take(values: List[Any], which):
    """values[which[i]] for every i, of the type pandas gives `values`
    (the type it gives a column of them in rows: few distinct values
    decide it), without a Python object per row."""
    import pandas as pd

    return pd.Series(values, dtype=None if values else object).array.take(which)


def axis_values(axis: Axis, count: int, every: int):
    """An axis's column: its value k for the scenarios i with
    (i // every) % len == k (the first axis varies slowest)."""
    import numpy as np

    n = len(axis.values)
    which = np.tile(np.repeat(np.arange(n, dtype=np.intp), every), count // (n * every))
    return _take([axis.values[k] for k in range(n)], which)


class Table:
    """The columns of a sweep's `count` rows, filled by `add` in any order;
    `frame` makes the DataFrame once every row is in."""

    def __init__(self, mx: Matrix, count: int):
        self.mx, self.count, self.added = mx, count, 0
        self.passed = bytearray(count)
        self.failed_check = Texts(count)
        self.error = Texts(count)
        self.metrics = {name: Column(count) for name in mx.metrics}

    def add(self, row: Dict[str, Any]) -> None:
        i = row["scenario"]
        self.passed[i] = bool(row["passed"])
        self.failed_check.put(i, row["failed_check"])
        self.error.put(i, row["error"])
        for name, column in self.metrics.items():
            column.put(i, row[name])
        self.added += 1

    def failed(self) -> Sequence[int]:
        """The numbers of the scenarios that failed, in order."""
        import numpy as np

        return np.flatnonzero(np.frombuffer(self.passed, dtype=bool) == 0)

    def frame(self):
        import numpy as np
        import pandas as pd

        if self.added != self.count:
            raise RuntimeError(f"the sweep returned {self.added} of {self.count} scenarios")
        columns: Dict[str, Any] = {"scenario": np.arange(self.count, dtype=np.int64)}
        every = self.count
        for a in self.mx.axes:
            every //= len(a.values)
            columns[a.name] = axis_values(a, self.count, every)
        columns["passed"] = np.frombuffer(self.passed, dtype=bool)
        columns["failed_check"] = self.failed_check.values()
        columns["error"] = self.error.values()
        for name, column in self.metrics.items():
            columns[name] = column.values()
        return pd.DataFrame(columns, copy=False)


class Failures(Mapping):
    """The failed scenarios' files by scenario number (`{"world": …,
    "setup": …}`), made again when asked for: a sweep of millions of
    failures keeps their numbers only."""

    def __init__(self, mx: Matrix, failed: Sequence[int]):
        self.mx = mx
        self.failed = failed

    def _has(self, i: Any) -> bool:
        import numpy as np

        try:
            k = int(np.searchsorted(self.failed, i))
        except (TypeError, ValueError):
            return False
        return k < len(self.failed) and self.failed[k] == i

    def __getitem__(self, i: int) -> Dict[str, str]:
        from . import scenario

        if not self._has(i):
            raise KeyError(i)
        return scenario.files(self.mx, int(i))

    def __contains__(self, i: object) -> bool:
        return self._has(i)

    def __iter__(self) -> Iterator[int]:
        return (int(i) for i in self.failed)

    def __len__(self) -> int:
        return len(self.failed)
