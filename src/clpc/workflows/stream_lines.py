"""Lines of a stream read one at a time: csv or JSON samples, a header, a time column.

Every malformed line raises a ``ValueError`` naming the line (what :mod:`clpc.workflows.stream`
reports and skips); named columns the header lacks raise :class:`SettingsError`.
"""

from __future__ import annotations

import json
import math
from typing import Any

from clpc.io.errors import is_number, parse_number
from clpc.workflows.common import SettingsError

__all__ = ["CutLine", "LineReader", "Timed", "parse_csv_sample", "parse_jsonl_sample"]

Sample = tuple[list[float], list[float]]
#: a sample with its time (``None`` without a time column)
Timed = tuple[list[float], list[float], float | None]


class CutLine(str):
    """The last line of a stream when it had no newline: a write cut short, not a sample."""

    __slots__ = ()


def _finite(values: list[float]) -> None:
    for i, v in enumerate(values, 1):
        if not math.isfinite(v):
            raise ValueError(f"value {i} is {v}; samples must be finite")


def _numbers(fields: list[str]) -> list[float]:
    values = []
    for i, f in enumerate(fields, 1):
        try:
            values.append(parse_number(f))
        except ValueError:
            raise ValueError(
                f"field {i} {f!r} is not a number (ASCII digits with optional sign, point "
                "and exponent)"
            ) from None
    _finite(values)
    return values


def parse_csv_sample(line: str, n_in: int, n_out: int) -> Sample:
    """One sample from a line ``"u1,...,y1,..."``.

    Parameters
    ----------
    line : str
        The line, without its newline.
    n_in, n_out : int
        Inputs and outputs per sample.

    Returns
    -------
    u, y : list of float
        The inputs and the outputs.

    Raises
    ------
    ValueError
        Wrong number of fields, a field that is not a number (``1_5``, other scripts'
        digits and text included), a value that is not finite.
    """
    fields = [f.strip() for f in line.split(",")]
    if len(fields) != n_in + n_out:
        raise ValueError(
            f"expected {n_in + n_out} comma-separated numbers ({n_in} input(s) then "
            f"{n_out} output(s)); got {len(fields)} field(s)"
        )
    values = _numbers(fields)
    return values[:n_in], values[n_in:]


def _json_number(val: Any, key: str) -> float:
    if not isinstance(val, (int, float)) or isinstance(val, bool):
        raise ValueError(f"{key!r} must be a number; got {val!r:.40}")
    try:
        out = float(val)
    except OverflowError:
        raise ValueError(f"{key!r} holds a number too large for a float") from None
    if not math.isfinite(out):
        raise ValueError(f"{key!r} is {out}; samples must be finite")
    return out


def _json_object(line: str) -> dict[str, Any]:
    try:
        obj = json.loads(line)
    except json.JSONDecodeError as exc:
        raise ValueError(f"not valid JSON ({exc.msg})") from None
    except RecursionError:
        raise ValueError("not a sample: JSON nested too deeply") from None
    except ValueError as exc:  # e.g. an integer with more digits than Python converts
        raise ValueError(f"not a sample: {exc}") from None
    if not isinstance(obj, dict):
        raise ValueError(f"expected a JSON object; got {type(obj).__name__}")
    return obj


def parse_jsonl_sample(line: str, n_in: int, n_out: int) -> Sample:
    """One sample from a line ``{"u": ..., "y": ...}`` (a number, or a list per channel).

    Parameters
    ----------
    line : str
        The line, without its newline.
    n_in, n_out : int
        Inputs and outputs per sample.

    Returns
    -------
    u, y : list of float
        The inputs and the outputs.

    Raises
    ------
    ValueError
        Not JSON, not such an object, wrong counts or types, values that are not finite.
    """
    obj = _json_object(line)
    if "u" not in obj or "y" not in obj:
        raise ValueError('expected an object {"u": ..., "y": ...}')
    out = []
    for key, n in (("u", n_in), ("y", n_out)):
        val = obj[key]
        vals = val if isinstance(val, list) else [val]
        if len(vals) != n or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in vals
        ):
            want = "a number" if n == 1 else f"a list of {n} numbers"
            raise ValueError(f"{key!r} must be {want}; got {val!r:.60}")
        out.append([_json_number(v, key) for v in vals])
    return out[0], out[1]


def _is_header(line: str) -> bool:
    fields = [f.strip() for f in line.split(",")]
    return all(f and not is_number(f) for f in fields)


class LineReader:
    """Samples from numbered lines: blanks and comments skipped, a first csv header used."""

    def __init__(self, settings: Any) -> None:
        self.s = settings  # a StreamSettings
        self.n_in, self.n_out = settings.channels
        self.header_possible = settings.fmt == "csv"
        self.no = 0  # physical line number (1-based)
        self.names: list[str] | None = None
        self.use: list[int] | None = None  # csv columns: inputs, outputs, then time
        self.notes: list[str] = []
        wanted = (*settings.inputs, *settings.outputs)
        if settings.time_col is not None:
            wanted += (settings.time_col,)
        self.wanted = wanted
        if settings.fmt == "csv" and wanted and all(w.isdigit() for w in wanted):
            self.use = [int(w) for w in wanted]
        self._check_roles(list(self.use) if self.use is not None else list(wanted))

    def _check_roles(self, columns: list[Any]) -> None:
        """A SettingsError when one column (name or index) is given two roles."""
        roles = ["input"] * self.n_in + ["output"] * self.n_out + ["time column"]
        seen: dict[Any, str] = {}
        for column, role in zip(columns, roles, strict=False):
            if column in seen:
                shown = self.names[column] if isinstance(column, int) and self.names else column
                raise SettingsError(
                    f"column {shown!r} is selected as {seen[column]} and as {role}; each "
                    f"column can have one role. Name another column for the {role}."
                )
            seen[column] = role

    @property
    def time_name(self) -> str:
        """The time column's name (from the header for a column given by index)."""
        col = str(self.s.time_col)
        if self.names is not None and self.use is not None and col.isdigit():
            return self.names[self.use[-1]]
        return col

    def read(self, line: str, complete: bool = True) -> Timed | None:
        """The sample of the next line, or None; ``ValueError("line N: ...")`` if malformed.

        ``complete=False``: the last line of the stream had no newline (a write cut short):
        it is not taken as a sample (a ``ValueError``).
        """
        self.no += 1
        text = line.strip().lstrip("\ufeff")
        if not text or text.startswith("#"):
            return None
        if not complete:
            raise ValueError(
                f"line {self.no}: the last line has no newline (cut short?); not used as a "
                f"sample: {text[:80]!r}"
            )
        try:
            if self.header_possible:
                self.header_possible = False
                if self._header(text):
                    return None
            if self.s.fmt == "csv":
                return self._csv(text)
            return self._jsonl(text)
        except SettingsError:
            raise
        except ValueError as exc:
            raise ValueError(f"line {self.no}: {exc}: {text[:80]!r}") from None

    def _header(self, text: str) -> bool:
        """Use ``text`` as the header when it is one; a SettingsError if names are missing."""
        if not _is_header(text):
            if self.wanted and self.use is None:
                raise SettingsError(
                    f"columns were named ({', '.join(self.wanted)}) but the first line "
                    f"(line {self.no}) is not a header of column names: {text[:80]!r}; name "
                    "the columns by 0-based index instead."
                )
            return False
        names = [f.strip() for f in text.split(",")]
        if self.use is None and not self.wanted and len(names) != self.n_in + self.n_out:
            return False  # not this stream's header: reported as a malformed line
        if self.use is None and self.wanted:
            missing = [w for w in self.wanted if w not in names]
            if missing:
                raise SettingsError(
                    f"column(s) {missing} are not in the header (line {self.no}): "
                    f"{', '.join(names)}."
                )
            self.use = [names.index(w) for w in self.wanted]
        beyond = [i for i in self.use or () if i >= len(names)]
        if beyond:
            raise SettingsError(
                f"column index {beyond[0]} is past the header's {len(names)} columns "
                f"(line {self.no}: {', '.join(names)}); 0-based indices go up to "
                f"{len(names) - 1}."
            )
        self.names = names
        self._check_roles(list(self.use or ()))
        self.notes.append(f"line {self.no}: header (column names): {', '.join(names)}")
        return True

    def _csv(self, text: str) -> Timed:
        if self.use is None:
            u, y = parse_csv_sample(text, self.n_in, self.n_out)
            return u, y, None
        fields = [f.strip() for f in text.split(",")]
        need = len(self.names) if self.names is not None else max(self.use) + 1
        if len(fields) != need and (self.names is not None or len(fields) < need):
            raise ValueError(f"expected {need} comma-separated fields; got {len(fields)}")
        values = _numbers([fields[i] for i in self.use])
        n = self.n_in + self.n_out
        t = values[n] if len(values) > n else None
        return values[: self.n_in], values[self.n_in : n], t

    def _jsonl(self, text: str) -> Timed:
        if not self.wanted:
            u, y = parse_jsonl_sample(text, self.n_in, self.n_out)
            return u, y, None
        obj = _json_object(text)
        missing = [k for k in self.wanted if k not in obj]
        if missing:
            raise ValueError(f"the object has no key(s) {missing}")
        values = [_json_number(obj[k], k) for k in self.wanted]
        n = self.n_in + self.n_out
        t = values[n] if len(values) > n else None
        return values[: self.n_in], values[self.n_in : n], t
