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

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from clpc.data import IOData
from clpc.model.structure import (
    MimoMode,
    Structure,
    check_mode,
    column_labels,
    default_mode,
    input_blocks,
)

__all__ = [
    "MimoMode",
    "Structure",
    "check_mode",
    "column_labels",
    "default_mode",
    "lagged",
    "regressors",
    "siso_regressor",
]


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
def miso_regressor(
    y: np.ndarray, u: np.ndarray, structure: Structure, out: np.ndarray | None = None
) -> np.ndarray:
    """Lag matrix of one output on its own past and on every input.

    Parameters
    ----------
    y : ndarray, shape (T,)
        One output.
    u : ndarray, shape (T, m)
        All inputs.
    structure : Structure
        Orders and delay (shared by every input).
    out : ndarray, shape (T - max_lag, na + 1 + m (nb + 1)), optional
        Where to write the matrix (any memory order); default a new C-contiguous array.

    Returns
    -------
    ndarray, shape (T - max_lag, na + 1 + m (nb + 1))
        ``out``, or the new array.
    """
    start, na1, nb1 = structure.max_lag, structure.na + 1, structure.nb + 1
    if out is None:
        out = np.empty((y.shape[0] - start, na1 + u.shape[1] * nb1))
    end = y.shape[0]
    for j in range(na1):  # column by column: cheaper than a strided view at small T
        out[:, j] = y[start - j : end - j]
    for i in range(u.shape[1]):
        for j in range(nb1):
            lag = structure.nk + j
            out[:, na1 + i * nb1 + j] = u[start - lag : end - lag, i]
    return out


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
        Each ``[j]`` column-major (Fortran order). ``n_equations = n_outputs``;
        ``n_rows = T - max_lag``, summed over the experiments of a record that holds
        several (each experiment gives its own rows: no lag vector reaches across a
        boundary).
    """
    check_mode(mode, data.n_inputs, data.n_outputs)
    parts = data.split() if data.n_experiments > 1 else [data]
    for part in parts:
        part.require_samples(
            structure.max_lag + 2,
            f"A model with na={structure.na}, nb={structure.nb}, nk={structure.nk}",
        )
    rows = [part.n_samples - structure.max_lag for part in parts]
    p = structure.n_params(input_blocks(mode, data.n_inputs))
    # each out[j] column-major (Fortran order): a column is one contiguous run of a signal
    out = np.empty((data.n_outputs, p, sum(rows))).transpose(0, 2, 1)
    first = 0
    for part, n_rows in zip(parts, rows, strict=True):
        for j in range(data.n_outputs):
            inputs = part.u if mode == "miso" else part.u[:, j : j + 1]  # siso, paired: input j
            miso_regressor(part.y[:, j], inputs, structure, out[j, first : first + n_rows])
        first += n_rows
    return out
