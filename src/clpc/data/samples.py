"""The one input policy: what every entry point accepts as samples, and what it refuses.

:class:`clpc.IOData` (hence :class:`clpc.LPC`), :class:`clpc.CLPC` (``run``, ``push``,
``step``) and the file readers all turn user samples into float64 arrays here, so a kind of
input gets the same answer everywhere (the table is in ``docs/inputs.md``):

- numbers of any real dtype, booleans (0/1), pandas Series/DataFrames: converted;
- complex values: refused (casting would drop the imaginary part without a word);
- dates, times and durations (``datetime64``, ``timedelta64``, ``NaT``, datetime objects):
  refused (their integer nanoseconds are not samples; convert to seconds first);
- text: numbers written as the file readers read them (:data:`NUMBER_TEXT`) are converted,
  anything else (``"1_000"``, non-ASCII digits, words) is refused naming the value;
- other objects: ``None`` is a missing sample (NaN, refused later as not finite); anything
  but int, float, Decimal and Fraction is refused, naming the first offending value;
- magnitudes beyond :data:`MAX_MAGNITUDE` (or nonzero channels whose largest value is below
  :data:`MIN_MAGNITUDE`): refused, the windowed LPC solution squares and multiplies samples and
  cannot be computed in double precision there;
- with ``scaling="none"``, channels whose scales differ by more than :data:`MAX_SPREAD`:
  refused (the smaller channels vanish in the rounding of the larger in the scatter matrix;
  ``scaling="std"`` solves it).
"""

from __future__ import annotations

import datetime as dt
import math
import re
from decimal import Decimal
from fractions import Fraction
from typing import Any

import numpy as np

from clpc.data.errors import DataError

__all__ = [
    "MAX_MAGNITUDE",
    "MAX_SPREAD",
    "MIN_MAGNITUDE",
    "as_samples",
    "channel_ranges",
    "check_magnitude",
    "check_ranges",
    "check_spread",
]

#: Largest sample magnitude: the solution forms products of four samples (scatter matrix
#: and its eigen-solve), which overflow double precision (1.8e308) beyond about 1e77.
MAX_MAGNITUDE = 1e75
#: Smallest largest-magnitude of a nonzero channel (fourth powers underflow below 1e-308).
MIN_MAGNITUDE = 1e-75
#: Largest ratio of channel scales with ``scaling="none"``: 1/sqrt(machine epsilon); the
#: scatter matrix holds squares, so a smaller channel is then below the rounding of a larger.
MAX_SPREAD = 1.0 / math.sqrt(np.finfo(np.float64).eps)


def _refuse_kind(arr: np.ndarray, name: str) -> None:
    kind = arr.dtype.kind
    if kind == "c":
        raise DataError(
            f"{name} must hold real numbers; got complex values (dtype {arr.dtype}). Pass "
            "the real part (or the magnitude) explicitly if that is what you mean."
        )
    if kind in "mM":
        raise DataError(
            f"{name} holds dates or durations (dtype {arr.dtype}); samples must be numbers. "
            "Convert times to seconds first, e.g. (t - t[0]) / np.timedelta64(1, 's'), and "
            "pass them as dt or a time column, not as a channel."
        )
    if kind == "V":
        raise DataError(
            f"{name} must hold numbers; got records (dtype {arr.dtype}). Pass plain numeric "
            "columns."
        )


#: a number written as text, the same for every reader: ASCII digits with an optional sign,
#: point and exponent, or nan/inf; never "1_000", other scripts' digits or surrounding text
NUMBER_TEXT = re.compile(
    r"\s*[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|nan|inf|infinity)\s*",
    re.ASCII | re.IGNORECASE,
)


def _from_text(arr: np.ndarray, name: str) -> np.ndarray:
    """Text that is numbers (:data:`NUMBER_TEXT`) as float64, else a :class:`DataError`."""
    flat = arr.astype(str).ravel()
    for i, text in enumerate(flat):
        if NUMBER_TEXT.fullmatch(text) is None:
            raise DataError(
                f"{name} must hold numbers; value {i} is the text {text[:40]!r} (dtype "
                f"{arr.dtype}). Convert text columns to numbers first (e.g. pandas.to_numeric)."
            )
    return flat.astype(np.float64).reshape(arr.shape)


_NUMBER_TYPES = (int, float, np.integer, np.floating, np.bool_, Decimal, Fraction)


def _object_error(v: Any, i: int, name: str) -> DataError:
    if isinstance(v, (complex, np.complexfloating)):
        return DataError(f"{name} must hold real numbers; value {i} is complex ({v!r}).")
    if isinstance(v, (np.datetime64, np.timedelta64, dt.date, dt.time, dt.timedelta)) or (
        hasattr(v, "isoformat")
    ):
        return DataError(
            f"{name} holds dates or durations (value {i} is {v!r:.40}); samples must be "
            "numbers. Convert times to seconds first."
        )
    what = "the text" if isinstance(v, (str, bytes)) else type(v).__name__
    return DataError(
        f"{name} must hold numbers; value {i} is {what} {v!r:.40}. Convert the data to "
        "numbers first (e.g. pandas.to_numeric)."
    )


def _from_objects(arr: np.ndarray, name: str) -> np.ndarray:
    """An object array as float64 (``None`` becomes NaN), or a :class:`DataError`."""
    flat = arr.ravel()
    kinds = set(map(type, flat))
    bad = {t for t in kinds if not issubclass(t, _NUMBER_TYPES) and t is not type(None)}
    if bad:
        i = next(
            (
                i
                for i, v in enumerate(flat)
                if type(v) in bad and not (isinstance(v, str) and NUMBER_TEXT.fullmatch(v))
            ),
            None,
        )
        if i is not None:
            raise _object_error(flat[i], i, name)
    if type(None) in kinds:
        flat = np.array([np.nan if v is None else v for v in flat], dtype=object)
    try:
        return flat.astype(np.float64).reshape(arr.shape)
    except OverflowError:
        raise DataError(f"{name} holds an integer too large for a float.") from None


def as_samples(values: Any, name: str) -> tuple[np.ndarray, list[str] | None]:
    """``values`` as a float64 array (same shape) under the input policy; column names.

    Parameters
    ----------
    values : array_like, pandas Series or DataFrame, or a scalar
        The samples.
    name : str
        What they are (``"u"``, ``"y"``), for the messages.

    Returns
    -------
    arr : ndarray
        float64, the shape of ``values`` (no copy when already float64).
    columns : list of str or None
        Column names of a DataFrame (the name of a named Series), else ``None``.

    Raises
    ------
    DataError
        Complex, date/time, text or other non-numeric values; ragged nesting; an integer no
        float holds; a magnitude above :data:`MAX_MAGNITUDE`.
    """
    columns: list[str] | None = None
    if hasattr(values, "to_numpy") and hasattr(values, "columns"):  # DataFrame
        columns = [str(c) for c in values.columns]
        dtypes = getattr(values, "dtypes", [])
        for col, kind in zip(columns, dtypes, strict=False):
            if getattr(kind, "kind", "") in "mM" or "datetime" in str(kind):
                raise DataError(
                    f"{name} column {col!r} holds dates or durations (dtype {kind}); samples "
                    "must be numbers. Convert times to seconds first."
                )
        values = values.to_numpy()
    elif hasattr(values, "to_numpy") and hasattr(values, "name"):  # Series
        kind = getattr(values, "dtype", None)
        if getattr(kind, "kind", "") in "mM" or "datetime" in str(kind):
            raise DataError(
                f"{name} holds dates or durations (dtype {kind}); samples must be numbers. "
                "Convert times to seconds first."
            )
        columns = [str(values.name)] if values.name is not None else None
        values = values.to_numpy()
    try:
        arr = np.asarray(values)
    except (TypeError, ValueError) as exc:  # ragged lists and the like
        raise DataError(
            f"{name} must be a numeric array-like; could not convert it ({exc}). "
            "Pass a list, numpy array, pandas Series or DataFrame of numbers."
        ) from None
    except OverflowError:
        raise DataError(f"{name} holds an integer too large for a float.") from None
    _refuse_kind(arr, name)
    if arr.dtype.kind in "US":
        arr = _from_text(arr, name)
    elif arr.dtype == object:
        arr = _from_objects(arr, name)
    elif arr.dtype != np.float64:
        arr = arr.astype(np.float64)
    check_magnitude(arr, name)
    return arr, columns


def check_magnitude(arr: np.ndarray, name: str) -> None:
    """Refuse finite values above :data:`MAX_MAGNITUDE` (a :class:`DataError`)."""
    if arr.size == 0:
        return
    hi, lo = float(arr.max()), float(arr.min())  # two passes, no temporary of arr's size
    if math.isfinite(hi) and math.isfinite(lo):
        peak = max(hi, -lo)
    else:  # a NaN or an infinity (refused later, with its index): the largest finite value
        with np.errstate(invalid="ignore"):
            peak = np.nanmax(np.where(np.isfinite(arr), np.abs(arr), 0.0))
    if peak > MAX_MAGNITUDE:
        raise DataError(
            f"{name} reaches {peak:.3g}: beyond {MAX_MAGNITUDE:.0e} this cannot be solved in "
            "double precision (the solution multiplies four samples together, which "
            "overflows). Rescale the channel (other units, or divide by its RMS)."
        )


def channel_ranges(arr: np.ndarray) -> np.ndarray:
    """Each channel's range ``max - min``, shape (channels,) (zeros for no rows).

    The scale the centred solve sees: every solve centres the lag vectors in two passes
    (eqs. 24-25), so an offset costs no precision. Ranges of parts merge exactly (the
    largest maximum, the smallest minimum), so a record split into pieces on a cluster
    gives the same ranges as the whole.
    """
    a = np.atleast_2d(arr.T).T if arr.ndim == 1 else arr
    if not a.shape[0]:
        return np.zeros(a.shape[1])
    return np.asarray(a.max(axis=0) - a.min(axis=0))


def check_spread(u: np.ndarray, y: np.ndarray, scaling: str = "none") -> None:
    """Refuse a whole record that double precision cannot solve (a :class:`DataError`).

    :func:`check_ranges` of the channels' :func:`channel_ranges`.

    Parameters
    ----------
    u, y : ndarray, shape (n,) or (n, channels)
        The record's finite inputs and outputs.
    scaling : {"none", "std"}
        The estimator's scaling; ``"std"`` scales each channel first and has no spread limit.
    """
    u_ranges, y_ranges = channel_ranges(u), channel_ranges(y)
    check_ranges(np.concatenate([u_ranges, y_ranges]), u_ranges.size, scaling)


def check_ranges(ranges: np.ndarray, n_inputs: int, scaling: str = "none") -> None:
    """Refuse channel ranges that double precision cannot solve together.

    A channel that varies, but over less than :data:`MIN_MAGNITUDE`; with
    ``scaling="none"``, channels whose ranges differ by more than :data:`MAX_SPREAD`.
    Ranges, not magnitudes: an offset (a position logged as 1e12 counts) costs no precision.

    Parameters
    ----------
    ranges : ndarray, shape (channels,)
        :func:`channel_ranges` of the inputs, then of the outputs.
    n_inputs : int
        How many of ``ranges`` are inputs.
    scaling : {"none", "std"}
        As for :func:`check_spread`.
    """
    peaks = np.asarray(ranges, dtype=float)
    names = [f"u{i}" for i in range(n_inputs)] + [f"y{i}" for i in range(peaks.size - n_inputs)]
    nonzero = peaks > 0
    for p, n in zip(peaks, names, strict=True):
        if 0 < p < MIN_MAGNITUDE:
            raise DataError(
                f"channel {n} varies over a range of only {p:.3g}: below {MIN_MAGNITUDE:.0e} "
                "this cannot be solved in double precision (products of four samples "
                "underflow to 0). Rescale the channel (other units, or divide by its RMS)."
            )
    if scaling == "none" and nonzero.sum() > 1:
        big, small = peaks[nonzero].max(), peaks[nonzero].min()
        if big / small > MAX_SPREAD:
            lo = names[int(np.flatnonzero(peaks == small)[0])]
            hi = names[int(np.flatnonzero(peaks == big)[0])]
            raise DataError(
                f"channel {lo} (range {small:.3g}) and channel {hi} (range {big:.3g}) differ "
                f"in scale by {big / small:.3g} > {MAX_SPREAD:.3g}: with scaling='none' this "
                "cannot be solved in double precision (the smaller channel falls below the "
                "rounding of the larger). Pass scaling='std', or rescale the channels."
            )
