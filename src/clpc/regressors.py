"""Lag (regressor) matrices of the paper's eq. 36, built without Python loops over samples.

A *structure* names the orders and the delay:

* ``na`` - output lags: ``y(n), y(n-1), ..., y(n-na)``  (``na + 1`` columns);
* ``nb`` - input lags after the delay: ``u(n-nk), ..., u(n-nk-nb)`` (``nb + 1`` columns);
* ``nk`` - input delay in samples (``nk = 0`` keeps ``b0``, the paper's choice).

The paper's order ``N`` is ``na = nb = N, nk = 0``; its ``parameters_size`` is ``N + 1``.

Row ``n`` of every matrix below is the lag vector ``z_n`` of sample ``n``; rows start at
``n = max_lag = max(na, nk + nb)`` so that every entry is a measured sample.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from .data import DataError, IOData

__all__ = [
    "MimoMode",
    "Structure",
    "lagged",
    "regressors",
    "siso_regressor",
]

MimoMode = Literal["siso", "paired", "miso"]


def _check_int(value: object, name: str, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an int in the range [{low}, inf); got {value!r}.")
    if value < low:
        raise ValueError(f"{name} must be an int in the range [{low}, inf); got {value}.")
    return int(value)


@dataclass(frozen=True)
class Structure:
    """Orders and delay of a linear difference equation ``A(q) y + B(q) u = r``.

    Parameters
    ----------
    na : int
        Output order (>= 1): ``a0 .. a_na``.
    nb : int
        Input order (>= 0): ``b0 .. b_nb``.
    nk : int
        Input delay in samples (>= 0): ``b0`` multiplies ``u(n - nk)``.
    """

    na: int
    nb: int
    nk: int = 0

    def __post_init__(self) -> None:
        _check_int(self.na, "na", 1)
        _check_int(self.nb, "nb", 0)
        _check_int(self.nk, "nk", 0)

    @classmethod
    def from_order(cls, order: int, nk: int = 0) -> Structure:
        """The paper's structure: ``na = nb = order``."""
        order = _check_int(order, "order", 1)
        return cls(order, order, nk)

    @classmethod
    def from_settings(
        cls, order: int, na: int | None = None, nb: int | None = None, nk: int = 0
    ) -> Structure:
        """``na = nb = order`` unless ``na``/``nb`` are given (estimator settings)."""
        if na is None and nb is None:
            return cls.from_order(order, nk)
        return cls(order if na is None else na, order if nb is None else nb, nk)

    @property
    def max_lag(self) -> int:
        """Largest lag used: the first sample index with a complete lag vector."""
        return max(self.na, self.nk + self.nb)

    def n_params(self, n_inputs: int = 1) -> int:
        """Length of ``theta = [a; b_1; ...; b_m]`` for ``n_inputs`` inputs."""
        return self.na + 1 + n_inputs * (self.nb + 1)

    def n_rows(self, n_samples: int) -> int:
        """Number of lag vectors in a record of ``n_samples`` samples."""
        return max(n_samples - self.max_lag, 0)


# Column j of the result holds x(n - delay - j); row r is sample n = start + r:
#
#            col 0            col 1              ...  col order
#   row 0  [ x(s-d)           x(s-d-1)           ...  x(s-d-order)        ]   n = s
#   row 1  [ x(s+1-d)         x(s-d)             ...  x(s+1-d-order)      ]   n = s+1
#    ...
#   last   [ x(T-1-d)         x(T-2-d)           ...  x(T-1-d-order)      ]   n = T-1
#
# (s = start, d = delay, T = len(x)); a strided view, no copy, no loop.
def lagged(x: np.ndarray, order: int, delay: int, start: int) -> np.ndarray:
    """Hankel-like view of lagged copies of a 1-D signal.

    Parameters
    ----------
    x : ndarray, shape (T,)
        Signal samples.
    order : int
        Highest lag after the delay; the view has ``order + 1`` columns.
    delay : int
        Delay of column 0 in samples.
    start : int
        First sample index ``n`` (must satisfy ``start >= delay + order``).

    Returns
    -------
    ndarray, shape (T - start, order + 1)
        Read-only view; entry ``[r, j]`` is ``x[start + r - delay - j]``.
    """
    if start < delay + order:
        raise ValueError(f"start={start} is too early for delay={delay} and order={order}.")
    first = start - delay - order
    last = x.shape[0] - delay  # exclusive end of the samples used
    windows = sliding_window_view(x[first:last], order + 1)
    return windows[:, ::-1]


# The paper's SISO lag matrix (eq. 36 with q = 1), one row per lag vector z_n:
#
#          | y(n)      y(n-1)   ...  y(n-na)    | u(n-nk)   u(n-nk-1) ... u(n-nk-nb)   |
#   M  =   | y(n+1)    y(n)     ...  y(n+1-na)  | u(n+1-nk) u(n-nk)   ... u(n+1-nk-nb) |
#          |  ...                               |  ...                                 |
#          | y(T-1)    y(T-2)   ...  y(T-1-na)  | u(T-1-nk) ...           u(T-1-nk-nb) |
#
#           \_______ a0 .. a_na (output) ______/ \__________ b0 .. b_nb (input) _______/
#
# first row n = max_lag.  M @ theta = r (eq. 17), theta = [a; b].
def siso_regressor(y: np.ndarray, u: np.ndarray, structure: Structure) -> np.ndarray:
    """Lag matrix of one output ``y`` and one input ``u`` (paper eq. 36).

    Parameters
    ----------
    y, u : ndarray, shape (T,)
        Output and input samples.
    structure : Structure
        Orders and delay.

    Returns
    -------
    ndarray, shape (T - max_lag, na + nb + 2)
        Rows ``[y(n)..y(n-na), u(n-nk)..u(n-nk-nb)]`` for ``n = max_lag .. T-1``.
    """
    return miso_regressor(y, u[:, None], structure)


# MISO: one output j on its own past and on all m inputs, each with the same lags:
#
#        | y_j(n) .. y_j(n-na) | u_1(n-nk) .. u_1(n-nk-nb) | ... | u_m(n-nk) .. u_m(n-nk-nb) |
#   M =  |  ...                |  ...                      |     |  ...                      |
#
# theta = [a; b_1; ...; b_m] and a(q) y_j + sum_i b_i(q) u_i = r.
def miso_regressor(y: np.ndarray, u: np.ndarray, structure: Structure) -> np.ndarray:
    """Lag matrix of one output on its own past and on every input.

    Parameters
    ----------
    y : ndarray, shape (T,)
        One output.
    u : ndarray, shape (T, m)
        All inputs.
    structure : Structure
        Orders and delay (shared by every input).

    Returns
    -------
    ndarray, shape (T - max_lag, na + 1 + m (nb + 1))
        A new C-contiguous array.
    """
    start = structure.max_lag
    blocks = [lagged(y, structure.na, 0, start)]
    blocks += [lagged(u[:, i], structure.nb, structure.nk, start) for i in range(u.shape[1])]
    return np.concatenate(blocks, axis=1)


# The paper's paired MIMO (eqs. 35-38): q separate SISO systems, output j driven by input j
# only; one matrix M_j per pair, stacked along axis 0:
#
#   M[j] = | y_j(n) .. y_j(n-na) | u_j(n-nk) .. u_j(n-nk-nb) |      j = 1 .. q
#          |  ...                |  ...                      |
def regressors(data: IOData, structure: Structure, mode: MimoMode) -> np.ndarray:
    """Lag matrices of every equation of a record, stacked along axis 0.

    Parameters
    ----------
    data : IOData
        The record.
    structure : Structure
        Orders and delay.
    mode : {"siso", "paired", "miso"}
        ``"siso"``: one input, one output. ``"paired"``: the paper's q pairs, output j on
        input j (needs ``n_inputs == n_outputs``). ``"miso"``: each output on its own past
        and on all inputs.

    Returns
    -------
    ndarray, shape (n_equations, n_rows, n_params)
        ``n_equations = n_outputs``; ``n_rows = T - max_lag``.
    """
    check_mode(mode, data.n_inputs, data.n_outputs)
    data.require_samples(
        structure.max_lag + 2,
        f"A model with na={structure.na}, nb={structure.nb}, nk={structure.nk}",
    )
    if mode == "miso":
        mats = [miso_regressor(data.y[:, j], data.u, structure) for j in range(data.n_outputs)]
    else:  # siso and paired: output j with input j
        mats = [
            miso_regressor(data.y[:, j], data.u[:, j : j + 1], structure)
            for j in range(data.n_outputs)
        ]
    return np.stack(mats)


def check_mode(mode: str, n_inputs: int, n_outputs: int) -> None:
    """Raise a clear error when ``mode`` does not fit the channel counts."""
    if mode not in ("siso", "paired", "miso"):
        raise ValueError(f"mimo mode must be 'siso', 'paired' or 'miso'; got {mode!r}.")
    if mode == "siso" and (n_inputs != 1 or n_outputs != 1):
        raise DataError(
            f"mode 'siso' needs one input and one output; got {n_inputs} input(s) and "
            f"{n_outputs} output(s). Use mimo='paired' or mimo='miso'."
        )
    if mode == "paired" and n_inputs != n_outputs:
        raise DataError(
            f"mode 'paired' (paper eqs. 35-38) needs as many inputs as outputs; got "
            f"{n_inputs} input(s) and {n_outputs} output(s). Use mimo='miso'."
        )


def default_mode(n_inputs: int, n_outputs: int) -> MimoMode:
    """``"siso"`` for one input and one output, otherwise ``"miso"``."""
    return "siso" if n_inputs == 1 and n_outputs == 1 else "miso"


def column_labels(
    structure: Structure, output: str = "y", inputs: tuple[str, ...] = ("u",)
) -> list[str]:
    """Human-readable labels of the lag-vector entries, e.g. ``['y(n)', 'y(n-1)', ...]``."""

    def lab(name: str, lag: int) -> str:
        return f"{name}(n)" if lag == 0 else f"{name}(n-{lag})"

    labels = [lab(output, i) for i in range(structure.na + 1)]
    for name in inputs:
        labels += [lab(name, structure.nk + i) for i in range(structure.nb + 1)]
    return labels
