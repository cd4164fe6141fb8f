"""pandas DataFrames in and out of :class:`~clpc.data.IOData`, with the frame's own time base.

A frame's sample time comes, in this order, from ``time_column=`` (a column of times in s, ms
or us, or of dates), from a column named exactly ``time`` (what :func:`to_frame` writes), or
from a ``DatetimeIndex``/``TimedeltaIndex``; the steps must be uniform by the readers' rule
(:func:`clpc.data.timebase.check_time_base`), experiment by experiment, or the record is
refused with what was measured (``resample=True`` interpolates it onto a uniform grid instead).
:class:`FrameConversion`, a base class of :class:`~clpc.data.IOData`, gives it
``to_frame``/``from_frame``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Self

import numpy as np

from clpc.data.time_units import TIME_UNITS, time_unit
from clpc.data.timebase import (
    DEFAULT_TIME_RTOL,
    check_time_base,
    resample_to_grid,
)
from clpc.data.validation import DataError, check_dt

__all__ = ["FrameConversion", "FrameRecord", "from_frame", "to_frame"]


def to_frame(data: Any) -> Any:
    """A pandas DataFrame: ``time`` [s], the inputs, the outputs (and ``experiment``).

    Parameters
    ----------
    data : IOData
        The record.

    Returns
    -------
    pandas.DataFrame
        One row per sample; ``time`` restarts at 0 in each experiment.
    """
    import pandas as pd

    columns: dict[str, Any] = {"time": data.time}
    if data.n_experiments > 1:
        columns["experiment"] = np.repeat(np.arange(data.n_experiments), data.experiments)
    columns.update(zip(data.input_names, data.u.T, strict=True))
    columns.update(zip(data.output_names, data.y.T, strict=True))
    return pd.DataFrame(columns)


def _seconds(values: Any, unit: str | None, column: str, name: str) -> np.ndarray:
    """Times as float seconds: dates and durations from their start, numbers in ``unit``."""
    import pandas as pd

    index = pd.Index(values)
    if getattr(index, "tz", None) is not None:  # dates with a time zone: the same instants
        index = index.tz_convert(None)
    arr = index.to_numpy()
    if arr.dtype.kind in "mM":  # datetime64 / timedelta64: the unit is in the type
        if unit is not None:
            raise DataError(
                f"time_unit={unit!r} is for sample times written as numbers; {name} holds "
                "dates or durations, whose unit is their own: leave time_unit out."
            )
        return (arr - arr[0]) / np.timedelta64(1, "s") if arr.size else arr.astype(float)
    if arr.dtype.kind not in "iuf":
        raise DataError(
            f"time column {name} holds {arr.dtype} values; sample times must be numbers "
            "(s, ms or us) or dates/durations."
        )
    return arr.astype(np.float64) * TIME_UNITS[time_unit(unit, column)]


def _times(frame: Any, time_column: str | None, unit: str | None) -> tuple[Any, str] | None:
    """The frame's sample times [s] and what they are called, or None when it has none."""
    import pandas as pd

    if time_column is not None:
        if time_column not in frame:
            raise DataError(
                f"time column {time_column!r} is not in the frame; it has {list(frame.columns)}."
            )
        what = f"{time_column!r} of the frame"
        return _seconds(frame[time_column], unit, time_column, what), what
    if "time" in frame:
        return _seconds(frame["time"], unit, "time", "'time' of the frame"), "'time' of the frame"
    if isinstance(frame.index, (pd.DatetimeIndex, pd.TimedeltaIndex)):
        what = f"(the frame's {type(frame.index).__name__})"
        return _seconds(frame.index, unit, "", what), what
    if unit is not None:
        raise DataError(
            "time_unit needs sample times: a time_column, a column named 'time', or a "
            "DatetimeIndex/TimedeltaIndex."
        )
    return None


#: what :meth:`IOData.from_frame` builds its record from: ``u`` and ``y`` values, ``dt`` [s],
#: the input and output names, the samples of each experiment
FrameRecord = tuple[Any, Any, float, list[str], list[str], list[int]]


def from_frame(
    frame: Any,
    inputs: str | Sequence[str],
    outputs: str | Sequence[str],
    dt: float | None = None,
    experiment: str | None = None,
    *,
    time_column: str | None = None,
    time_unit: str | None = None,
    time_rtol: float = DEFAULT_TIME_RTOL,
    resample: bool = False,
) -> FrameRecord:
    """The samples, sample time and names of a record in a DataFrame (no ``IOData`` yet).

    The parameters are those of :meth:`clpc.IOData.from_frame`, which builds the record
    from what this returns (:data:`FrameRecord`): its values are checked there.
    """
    ins = [inputs] if isinstance(inputs, str) else list(inputs)
    outs = [outputs] if isinstance(outputs, str) else list(outputs)
    missing = [c for c in (*ins, *outs, *([experiment] if experiment else [])) if c not in frame]
    if missing:
        raise DataError(f"columns {missing} are not in the frame; it has {list(frame.columns)}.")
    parts = [len(frame)]
    if experiment is not None:
        labels = np.asarray(frame[experiment])
        change = np.flatnonzero(labels[1:] != labels[:-1]) + 1
        parts = np.diff([0, *change, labels.size]).tolist()
    found = _times(frame, time_column, time_unit)
    if found is None:
        if resample:
            raise DataError("resample needs sample times (time_column=, or a DatetimeIndex).")
        return frame[ins], frame[outs], 1.0 if dt is None else dt, ins, outs, parts
    t, name = found
    if not resample:
        step = _uniform_step(t, parts, name, dt, float(time_rtol))
        return frame[ins], frame[outs], step, ins, outs, parts
    rows = np.asarray(frame[[*ins, *outs]], dtype=np.float64)
    grid, first = None if dt is None else check_dt(dt), slice(0, parts[0])
    grid = resample_to_grid(t[first], rows[first], grid)[0]  # the first experiment's step
    pieces = [resample_to_grid(t[s], rows[s], grid)[1] for s in _slices(parts)]
    both = np.vstack(pieces)
    n_in = len(ins)
    return both[:, :n_in], both[:, n_in:], grid, ins, outs, [len(p) for p in pieces]


def _slices(parts: list[int]) -> list[slice]:
    """The rows of each experiment."""
    ends = np.cumsum(parts).tolist()
    return [slice(e - n, e) for n, e in zip(parts, ends, strict=True)]


def _rows_from(start: int) -> Callable[[int], str]:
    """Names sample ``k`` of an experiment by its row in the frame (``start + k``)."""
    return lambda k: f"row {start + k}"


def _uniform_step(
    t: np.ndarray, parts: list[int], name: str, dt: float | None, rtol: float
) -> float:
    """The sample time: uniform steps in every experiment, the same in all, agreeing with dt."""
    steps = [check_time_base(t[s], name, rtol, _rows_from(s.start)).dt for s in _slices(parts)]
    step = steps[0]
    for given, what in [*((s, f"experiment {i}") for i, s in enumerate(steps)), (dt, "dt")]:
        if given is not None and abs(check_dt(given) - step) > rtol * step:
            raise DataError(
                f"{what} gives a sample time of {given:.12g} s, but the sample times in "
                f"{name} step by {step:.12g} s in experiment 0; pass only one of dt and "
                "the sample times, or resample the record (resample=True)."
            )
    return step


class FrameConversion:
    """``to_frame`` and ``from_frame`` of a record; a base class of ``IOData``."""

    def to_frame(self) -> Any:
        """A pandas DataFrame: ``time`` [s], the inputs, the outputs (and ``experiment``)."""
        return to_frame(self)

    @classmethod
    def from_frame(
        cls,
        frame: Any,
        inputs: str | Sequence[str],
        outputs: str | Sequence[str],
        dt: float | None = None,
        experiment: str | None = None,
        *,
        time_column: str | None = None,
        time_unit: str | None = None,
        time_rtol: float = DEFAULT_TIME_RTOL,
        resample: bool = False,
    ) -> Self:
        """A record from DataFrame columns; :meth:`to_frame` round-trips.

        The sample time comes from ``time_column``, else from a column named ``time``, else
        from a ``DatetimeIndex`` or ``TimedeltaIndex``, else from ``dt`` (default 1). Sample
        times must step uniformly in each experiment, by the rule of the file readers
        (:func:`clpc.data.timebase.check_time_base`).

        Parameters
        ----------
        frame : pandas.DataFrame
            The samples, one column per channel.
        inputs, outputs : str or sequence of str
            Names of the input and output columns (also the channel names).
        dt : float, optional
            Sample time [s]. With sample times in the frame it must agree with their step
            (within ``time_rtol``); with ``resample`` it is the grid step.
        experiment : str, optional
            A column labelling the experiments; each change of label starts a new one.
        time_column : str, optional
            A column of sample times: numbers (in ``time_unit``) or dates/durations.
        time_unit : {"s", "ms", "us"}, optional
            Unit of a numeric time column; default the one its name says (``t_ms`` is in
            milliseconds), else seconds.
        time_rtol : float
            Largest relative deviation of one step from the median step (default 1e-2, as
            :func:`clpc.io.load_iodata`).
        resample : bool
            Interpolate each experiment onto the uniform grid ``t0 + k dt`` (linear)
            instead of refusing sample times that are not uniform.

        Returns
        -------
        IOData

        Raises
        ------
        DataError
            A missing column; sample times that are not numbers or dates, not increasing or
            not uniform; a ``dt`` or an experiment whose step disagrees with the first.
        """
        make: Callable[..., Self] = cls  # the record's constructor
        return make(
            *from_frame(
                frame,
                inputs,
                outputs,
                dt,
                experiment,
                time_column=time_column,
                time_unit=time_unit,
                time_rtol=time_rtol,
                resample=resample,
            )
        )
