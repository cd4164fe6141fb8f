"""Input/output data: the one place where user data are validated.

Everything downstream (lag matrices, LPC, CLPC, models) trusts an :class:`IOData`:
finite float64 arrays ``u`` of shape (n_samples, n_inputs) and ``y`` of shape
(n_samples, n_outputs), a positive sample time and channel names.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data.errors import DataError
from clpc.data.samples import as_samples

__all__ = ["DataError", "IOData", "as_iodata"]


def _to_2d_float(values: Any, name: str) -> tuple[np.ndarray, list[str] | None]:
    """Convert array-like data to a float64 array of shape (n_samples, n_channels).

    The input policy is :func:`clpc.data.samples.as_samples`. Returns the array and the
    column names found on pandas objects (else ``None``).
    """
    arr, columns = as_samples(values, name)
    if arr.ndim == 0:
        raise DataError(f"{name} must be 1-D or 2-D; got a scalar. Pass one value per sample.")
    if arr.ndim == 1:
        arr = arr[:, None]
    elif arr.ndim != 2:
        raise DataError(
            f"{name} must be 1-D (one channel) or 2-D (n_samples, n_channels); "
            f"got {arr.ndim}-D with shape {arr.shape}."
        )
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise DataError(f"{name} is empty (shape {arr.shape}); at least one sample is needed.")
    # an owned copy: the caller's array is neither aliased nor made read-only
    return np.array(arr, dtype=np.float64, order="C", copy=True), columns


def _check_finite(arr: np.ndarray, name: str, channels: Sequence[str]) -> None:
    bad = ~np.isfinite(arr)
    if bad.any():
        row, col = np.argwhere(bad)[0]
        kind = "NaN" if np.isnan(arr[row, col]) else "inf"
        count = int(bad[:, col].sum())
        raise DataError(
            f"{name} channel '{channels[col]}' has {count} non-finite value(s); "
            f"the first is {kind} at sample index {row}. "
            "Remove or interpolate missing samples before identification."
        )


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

    def __init__(
        self,
        u: Any,
        y: Any,
        dt: float = 1.0,
        input_names: Sequence[str] | None = None,
        output_names: Sequence[str] | None = None,
    ) -> None:
        u_arr, u_cols = _to_2d_float(u, "u")
        y_arr, y_cols = _to_2d_float(y, "y")
        if u_arr.shape[0] != y_arr.shape[0]:
            raise DataError(
                "u and y must have the same number of samples; "
                f"got len(u)={u_arr.shape[0]}, len(y)={y_arr.shape[0]}. "
                "Trim both records to a common time span."
            )
        dt = check_dt(dt)
        in_names = _names(input_names, u_cols, u_arr.shape[1], "u", "input_names")
        out_names = _names(output_names, y_cols, y_arr.shape[1], "y", "output_names")
        _check_finite(u_arr, "u", in_names)
        _check_finite(y_arr, "y", out_names)
        u_arr.setflags(write=False)
        y_arr.setflags(write=False)
        object.__setattr__(self, "u", u_arr)
        object.__setattr__(self, "y", y_arr)
        object.__setattr__(self, "dt", dt)
        object.__setattr__(self, "input_names", in_names)
        object.__setattr__(self, "output_names", out_names)

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
        """Sample times ``k * dt`` [s], shape (n_samples,)."""
        return np.arange(self.n_samples) * self.dt

    def __len__(self) -> int:
        return self.n_samples

    def __getitem__(self, index: slice) -> IOData:
        """Return the samples ``index`` (a slice) as a new :class:`IOData`."""
        if not isinstance(index, slice):
            raise TypeError(f"IOData supports slicing only; got {type(index).__name__}.")
        return IOData(self.u[index], self.y[index], self.dt, self.input_names, self.output_names)

    def __repr__(self) -> str:
        return (
            f"IOData(n_samples={self.n_samples}, inputs={list(self.input_names)}, "
            f"outputs={list(self.output_names)}, dt={self.dt:g})"
        )

    def plot(self, path: Any = None, *, title: str | None = None, ax: Any = None) -> Any:
        """Plot every channel against time; returns the figure (needs matplotlib).

        See :func:`clpc.data.plot.plot_iodata` (``path`` also writes a PNG, ``ax`` takes
        ``n_inputs + n_outputs`` axes).
        """
        from clpc.data.plot import plot_iodata

        return plot_iodata(self, path, title=title, ax=ax)

    def require_samples(self, needed: int, why: str) -> None:
        """Raise :class:`DataError` unless at least ``needed`` samples are present."""
        if self.n_samples < needed:
            raise DataError(
                f"{why} needs at least {needed} samples; the record has {self.n_samples}. "
                "Use a longer record or a lower order."
            )


def check_dt(dt: Any) -> float:
    """``dt`` as a positive finite number of seconds (:class:`DataError` otherwise)."""
    if isinstance(dt, (bool, np.bool_, str, bytes)):
        raise DataError(f"dt (sample time) must be a number of seconds; got {dt!r}.")
    try:
        value = float(dt)
    except (TypeError, ValueError, OverflowError):
        raise DataError(f"dt (sample time) must be a number of seconds; got {dt!r:.60}.") from None
    if not np.isfinite(value) or value <= 0:
        raise DataError(
            f"dt (sample time) must be a positive finite number of seconds; got {dt!r}."
        )
    return value


def _names(
    given: Sequence[str] | None, found: list[str] | None, n: int, prefix: str, label: str
) -> tuple[str, ...]:
    if given is None:
        given = found if found is not None and len(found) == n else None
    if given is None:
        return tuple(f"{prefix}{i}" for i in range(n)) if n > 1 else (prefix,)
    if isinstance(given, str):
        given = [given]
    names = tuple(str(g) for g in given)
    if len(names) != n:
        raise DataError(f"{label} must name {n} channel(s); got {len(names)}: {list(names)}.")
    return names


def as_iodata(u: Any, y: Any | None = None, dt: float | None = None, **names: Any) -> IOData:
    """Return ``u`` if it is an :class:`IOData`, else build one from ``u, y, dt``.

    Parameters
    ----------
    u : IOData or array_like, shape (n_samples,) or (n_samples, n_inputs)
        A validated record, or the input samples.
    y : array_like, shape (n_samples,) or (n_samples, n_outputs), optional
        Output samples; required unless ``u`` is an :class:`IOData`.
    dt : float, optional
        Sample time [s]; overrides the record's when given.
    **names
        ``input_names`` / ``output_names`` passed to :class:`IOData`.

    Returns
    -------
    IOData
    """
    if isinstance(u, IOData):
        if y is not None:
            raise DataError("pass either an IOData or (u, y), not both.")
        if dt is not None and check_dt(dt) != u.dt:
            return IOData(u.u, u.y, dt, u.input_names, u.output_names)
        return u
    if y is None:
        raise DataError("y is missing: pass the outputs y together with the inputs u.")
    return IOData(u, y, 1.0 if dt is None else dt, **names)
