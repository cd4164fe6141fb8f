"""Input/output data: the one place where user data are validated.

Everything downstream (lag matrices, LPC, CLPC, models) trusts an :class:`IOData`:
finite float64 arrays ``u`` of shape (n_samples, n_inputs) and ``y`` of shape
(n_samples, n_outputs), a positive sample time and channel names. A record may hold several
experiments (:meth:`IOData.concat`), stacked along the sample axis; estimators build their
lag vectors inside each experiment, never across a boundary.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import html_table, summarise
from clpc.data import processing
from clpc.data.timebase import DEFAULT_TIME_RTOL
from clpc.data.validation import (
    DataError,
    channel_names,
    check_dt,
    check_finite,
    to_2d_float,
)

__all__ = ["DataError", "IOData", "as_iodata", "check_dt"]


@dataclass(frozen=True, eq=False)
class IOData:
    """Validated input/output record of a black box.

    Parameters
    ----------
    u : array_like, shape (n_samples,) or (n_samples, n_inputs)
        Input samples (e.g. position command [rad] or torque command [N m]).
    y : array_like, shape (n_samples,) or (n_samples, n_outputs)
        Output samples (e.g. measured position [rad]).
    dt : float, optional
        Sample time [s], > 0. Default 1.0 (unknown sample time: frequencies are then
        per sample).
    input_names, output_names : sequence of str, optional
        Channel names; default ``u0, u1, ...`` / ``y0, y1, ...`` or the DataFrame columns.
    experiments : sequence of int, optional
        Samples of each experiment when the record holds several, in order (summing to
        ``n_samples``); default one experiment. See :meth:`concat`.

    Notes
    -----
    Construction validates once: equal lengths, numeric, finite (the message names the
    channel and the first bad sample), non-empty, 1-D or 2-D, positive sample time.
    Use :func:`as_iodata` to accept either an :class:`IOData` or raw ``u, y``.
    """

    u: np.ndarray
    y: np.ndarray
    dt: float = 1.0
    input_names: tuple[str, ...] = ()
    output_names: tuple[str, ...] = ()
    experiments: tuple[int, ...] = ()

    def __init__(
        self,
        u: Any,
        y: Any,
        dt: float = 1.0,
        input_names: Sequence[str] | None = None,
        output_names: Sequence[str] | None = None,
        experiments: Sequence[int] | None = None,
    ) -> None:
        u_arr, u_cols = to_2d_float(u, "u")
        y_arr, y_cols = to_2d_float(y, "y")
        if u_arr.shape[0] != y_arr.shape[0]:
            raise DataError(
                "u and y must have the same number of samples; "
                f"got len(u)={u_arr.shape[0]}, len(y)={y_arr.shape[0]}. "
                "Trim both records to a common time span."
            )
        dt = check_dt(dt)
        in_names = channel_names(input_names, u_cols, u_arr.shape[1], "u", "input_names")
        out_names = channel_names(output_names, y_cols, y_arr.shape[1], "y", "output_names")
        check_finite(u_arr, "u", in_names)
        check_finite(y_arr, "y", out_names)
        parts = _experiments(experiments, u_arr.shape[0])
        u_arr.setflags(write=False)
        y_arr.setflags(write=False)
        object.__setattr__(self, "u", u_arr)
        object.__setattr__(self, "y", y_arr)
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "input_names", in_names)
        object.__setattr__(self, "output_names", out_names)
        object.__setattr__(self, "experiments", parts)

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.u.shape[0])

    @property
    def n_inputs(self) -> int:
        """Number of input channels."""
        return int(self.u.shape[1])

    @property
    def n_outputs(self) -> int:
        """Number of output channels."""
        return int(self.y.shape[1])

    @property
    def time(self) -> np.ndarray:
        """Sample times ``k * dt`` [s] from 0 in each experiment, shape (n_samples,)."""
        starts = np.repeat(np.cumsum((0, *self.experiments[:-1])), self.experiments)
        return (np.arange(self.n_samples) - starts) * self.dt

    @property
    def n_experiments(self) -> int:
        """Number of experiments in the record."""
        return len(self.experiments)

    def __len__(self) -> int:
        return self.n_samples

    def __getitem__(self, index: slice) -> IOData:
        """Return the samples ``index`` (a slice) as a new :class:`IOData`.

        A slice of several experiments keeps the boundaries that fall inside it (step 1 only).
        """
        if not isinstance(index, slice):
            raise TypeError(f"IOData supports slicing only; got {type(index).__name__}.")
        start, stop, step = index.indices(self.n_samples)
        parts: list[int] = []  # one experiment: whatever length the slice has
        if self.n_experiments > 1:
            if step != 1:
                raise DataError("a record of several experiments can be sliced with step 1 only.")
            ends = np.cumsum(self.experiments)
            lo = np.clip(ends - np.asarray(self.experiments), start, max(stop, start))
            parts = [int(n) for n in np.clip(ends, start, max(stop, start)) - lo if n > 0]
        return self._with(self.u[index], self.y[index], experiments=parts)

    def __repr__(self) -> str:
        more = (
            f", experiments={summarise(list(self.experiments))}" if self.n_experiments > 1 else ""
        )
        return (
            f"IOData(n_samples={self.n_samples}, inputs={summarise(list(self.input_names))}, "
            f"outputs={summarise(list(self.output_names))}, dt={self.dt:g}{more})"
        )

    def _repr_html_(self) -> str:
        """The record as an HTML table (Jupyter): sample time, experiments, every channel."""
        rows = [("samples", str(self.n_samples)), ("dt [s]", f"{self.dt:g}")]
        if self.n_experiments > 1:
            rows.append(("experiments", html.escape(summarise(list(self.experiments)))))
        for names, values in ((self.input_names, self.u), (self.output_names, self.y)):
            rows += [(n, html.escape(summarise(values[:, i]))) for i, n in enumerate(names)]
        return html_table("IOData", rows)

    def _with(self, u: Any, y: Any, dt: float | None = None, experiments: Any = None) -> IOData:
        """A new record with these samples and this record's names."""
        parts = self.experiments if experiments is None else experiments
        return IOData(
            u, y, self.dt if dt is None else dt, self.input_names, self.output_names, parts
        )

    # ------------------------------------------------------------ experiments
    @classmethod
    def concat(cls, records: Sequence[IOData]) -> IOData:
        """Several experiments as one record (their boundaries kept, see :meth:`split`).

        Parameters
        ----------
        records : sequence of IOData
            The experiments, in order; same sample time and same channel names.

        Returns
        -------
        IOData
            The samples stacked, with one entry of ``experiments`` per record's experiment.

        Raises
        ------
        DataError
            No record, or records with different sample times or channel names.
        """
        records = list(records)
        if not records or not all(isinstance(r, IOData) for r in records):
            raise DataError("concat needs a non-empty sequence of IOData records.")
        first = records[0]
        for i, r in enumerate(records[1:], 1):
            if abs(r.dt - first.dt) > 1e-9 * first.dt:
                raise DataError(
                    f"experiment {i} has dt = {r.dt:g} s but experiment 0 has {first.dt:g} s; "
                    "resample them to one sample time first (IOData.resample)."
                )
            if (r.input_names, r.output_names) != (first.input_names, first.output_names):
                raise DataError(
                    f"experiment {i} has channels {list(r.input_names)} -> "
                    f"{list(r.output_names)} but experiment 0 has {list(first.input_names)} "
                    f"-> {list(first.output_names)}; give every experiment the same channels."
                )
        return first._with(
            np.concatenate([r.u for r in records]),
            np.concatenate([r.y for r in records]),
            experiments=[n for r in records for n in r.experiments],
        )

    def split(self) -> list[IOData]:
        """One record per experiment."""
        ends = np.cumsum(self.experiments)
        return [
            self._with(self.u[e - n : e], self.y[e - n : e], experiments=[n])
            for n, e in zip(self.experiments, ends, strict=True)
        ]

    # ------------------------------------------------------------ preprocessing
    def detrend(self, kind: str = "constant") -> IOData:
        """Remove each channel's mean (``"constant"``) or line (``"linear"``) per experiment.

        Parameters
        ----------
        kind : {"constant", "linear"}
            Remove the mean (default) or the least-squares straight line.

        Returns
        -------
        IOData
        """
        both = processing.detrend_parts(np.hstack([self.u, self.y]), self.experiments, kind)
        return self._with(both[:, : self.n_inputs], both[:, self.n_inputs :])

    def filter(
        self,
        cutoff: float | Sequence[float],
        btype: str = "lowpass",
        order: int = 4,
        zero_phase: bool = True,
    ) -> IOData:
        """Butterworth-filter every channel (see :func:`clpc.data.processing.filter_parts`).

        ``zero_phase=True`` (default) filters forwards and backwards, so the filter adds no
        delay (a causal filter would shift the estimated delay ``nk``).

        Parameters
        ----------
        cutoff : float or (float, float)
            Cut-off frequency [Hz] (two for ``"bandpass"``/``"bandstop"``), below the
            Nyquist frequency ``1 / (2 dt)``.
        btype : {"lowpass", "highpass", "bandpass", "bandstop"}
            Filter type; default ``"lowpass"``.
        order : int
            Butterworth order (default 4; doubled in effect by ``zero_phase``).
        zero_phase : bool
            Filter forwards and backwards (no delay, default) instead of causally.

        Returns
        -------
        IOData
        """
        both = processing.filter_parts(
            np.hstack([self.u, self.y]), self.experiments, self.dt, cutoff, btype, order, zero_phase
        )
        return self._with(both[:, : self.n_inputs], both[:, self.n_inputs :])

    def resample(self, dt: float) -> IOData:
        """The record at sample time ``dt`` [s] (polyphase, anti-aliased; per experiment).

        Parameters
        ----------
        dt : float
            New sample time [s], > 0; ``self.dt / dt`` must be a fraction ``up / down``
            with ``down <= 1000``.

        Returns
        -------
        IOData
        """
        new_dt = check_dt(dt)
        both, parts = processing.resample_parts(
            np.hstack([self.u, self.y]), self.experiments, self.dt, new_dt
        )
        return self._with(both[:, : self.n_inputs], both[:, self.n_inputs :], new_dt, parts)

    # ------------------------------------------------------------ DataFrames
    def to_frame(self) -> Any:
        """A pandas DataFrame: ``time`` [s], the inputs, the outputs (and ``experiment``)."""
        from clpc.data.frames import to_frame

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
    ) -> IOData:
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
        from clpc.data.frames import from_frame

        return cls(
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

    def plot(self, path: Any = None, *, title: str | None = None, ax: Any = None) -> Any:
        """Plot every channel against time (needs matplotlib).

        See :func:`clpc.data.plot.plot_iodata`.

        Parameters
        ----------
        path : str or path-like, optional
            Also write the figure as PNG here (parent folders are created).
        title : str, optional
            Figure title (default: the sample count and sample time).
        ax : sequence of matplotlib Axes, optional
            ``n_inputs + n_outputs`` axes to draw on; default: a new figure.

        Returns
        -------
        matplotlib.figure.Figure
        """
        from clpc.data.plot import plot_iodata

        return plot_iodata(self, path, title=title, ax=ax)

    def require_samples(self, needed: int, why: str) -> None:
        """Raise :class:`DataError` unless at least ``needed`` samples are present.

        Parameters
        ----------
        needed : int
            Minimum number of samples.
        why : str
            What needs them, starting the error message (e.g. ``"An ARX fit with 5
            parameters"``).

        Raises
        ------
        DataError
            The record has fewer than ``needed`` samples.
        """
        if self.n_samples < needed:
            raise DataError(
                f"{why} needs at least {needed} samples; the record has {self.n_samples}. "
                "Use a longer record or a lower order."
            )


def _experiments(given: Sequence[int] | None, n: int) -> tuple[int, ...]:
    if given is None or len(given) == 0:
        return (n,)
    parts = tuple(int(k) for k in given)
    if any(k < 1 for k in parts) or sum(parts) != n:
        raise DataError(
            f"experiments must be positive sample counts summing to {n}; got {list(given)}."
        )
    return parts


def as_iodata(u: Any, y: Any | None = None, dt: float | None = None, **names: Any) -> IOData:
    """Return ``u`` if it is an :class:`IOData`, else build one from ``u, y, dt``.

    Further keyword arguments (``input_names``, ``output_names``) are passed to
    :class:`IOData`.

    Parameters
    ----------
    u : IOData, sequence of IOData, or array_like, shape (n_samples,) or (n_samples, n_inputs)
        A validated record, several experiments (joined by :meth:`IOData.concat`), or the
        input samples.
    y : array_like, shape (n_samples,) or (n_samples, n_outputs), optional
        Output samples; required unless ``u`` is an :class:`IOData`.
    dt : float, optional
        Sample time [s]; overrides the record's when given.

    Returns
    -------
    IOData
    """
    if isinstance(u, (list, tuple)) and u and all(isinstance(r, IOData) for r in u):
        if y is not None:
            raise DataError("pass either records (IOData) or (u, y), not both.")
        u = IOData.concat(u)  # several experiments: lag vectors stay inside each
    if isinstance(u, IOData):
        if y is not None:
            raise DataError("pass either an IOData or (u, y), not both.")
        if dt is not None and check_dt(dt) != u.dt:
            return IOData(u.u, u.y, dt, u.input_names, u.output_names, u.experiments)
        return u
    if y is None:
        raise DataError("y is missing: pass the outputs y together with the inputs u.")
    return IOData(u, y, 1.0 if dt is None else dt, **names)
