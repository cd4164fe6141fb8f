"""Input/output data: the one place where user data are validated.

Everything downstream (lag matrices, LPC, CLPC, models) trusts an :class:`IOData`:
finite float64 arrays ``u`` of shape (n_samples, n_inputs) and ``y`` of shape
(n_samples, n_outputs), a positive sample time and channel names. A record may hold several
experiments (:meth:`IOData.concat`), stacked along the sample axis; estimators build their
lag vectors inside each experiment, never across a boundary. Its methods on experiments
(:mod:`clpc.data.experiments`), its preprocessing (:mod:`clpc.data.processing`) and its
DataFrame conversion (:mod:`clpc.data.frames`) come from base classes beside those rules.
"""

from __future__ import annotations

import html
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import html_table, summarise
from clpc.data.experiments import Experiments, check_experiments, slice_experiments
from clpc.data.frames import FrameConversion
from clpc.data.processing import Preprocessing
from clpc.data.validation import (
    DataError,
    channel_names,
    check_dt,
    check_finite,
    to_2d_float,
)

__all__ = ["DataError", "IOData", "as_iodata", "check_dt"]


@dataclass(frozen=True, eq=False)
class IOData(Experiments, Preprocessing, FrameConversion):
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
        parts = check_experiments(experiments, u_arr.shape[0])
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

    def __len__(self) -> int:
        return self.n_samples

    def __getitem__(self, index: slice) -> IOData:
        """Return the samples ``index`` (a slice) as a new :class:`IOData`.

        A slice of several experiments keeps the boundaries that fall inside it (step 1 only).
        """
        if not isinstance(index, slice):
            raise TypeError(f"IOData supports slicing only; got {type(index).__name__}.")
        parts = slice_experiments(self.experiments, *index.indices(self.n_samples))
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
