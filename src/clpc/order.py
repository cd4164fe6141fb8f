"""Order selection: the paper's Remark 1 (raise N while J keeps falling), AIC and BIC.

All orders are compared on the same samples (the rows that the largest order can use), so
their likelihoods are comparable.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .data import as_iodata
from .lpc import LPC

__all__ = ["OrderSelection", "select_order"]


@dataclass(frozen=True)
class OrderSelection:
    """Table of criteria per order and the chosen order.

    Attributes
    ----------
    orders : ndarray of int, shape (n,)
    J, log_likelihood, aic, bic, noise_variance : ndarray, shape (n,)
        Criteria per order (summed over outputs); ``J`` is the paper's eq. 22.
    n_params : ndarray of int, shape (n,)
        Free parameters counted: ``p - 1`` (unit norm) plus ``c`` and ``sigma^2``.
    best : int
        The chosen order.
    criterion : str
    """

    orders: np.ndarray
    J: np.ndarray
    log_likelihood: np.ndarray
    aic: np.ndarray
    bic: np.ndarray
    noise_variance: np.ndarray
    n_params: np.ndarray
    best: int
    criterion: str

    def to_frame(self) -> Any:
        """The table as a pandas DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(
            {
                "order": self.orders,
                "J": self.J,
                "log_likelihood": self.log_likelihood,
                "aic": self.aic,
                "bic": self.bic,
                "noise_variance": self.noise_variance,
                "n_params": self.n_params,
            }
        ).set_index("order")


def select_order(
    u: Any,
    y: Any | None = None,
    *,
    orders: Any = range(1, 7),
    criterion: str = "bic",
    min_improvement: float = 0.1,
    estimator: LPC | None = None,
    dt: float | None = None,
) -> OrderSelection:
    """Choose the model order ``N`` (``na = nb = N``).

    Parameters
    ----------
    u, y, dt
        The record (see :meth:`clpc.LPC.fit`).
    orders : iterable of int
        Candidate orders, ascending.
    criterion : {"remark1", "aic", "bic"}
        ``"remark1"``: the paper's rule - from the lowest order, raise ``N`` while the
        noise variance (hence ``J``) falls by at least ``min_improvement`` (relative);
        ``"aic"``/``"bic"``: the minimum of the information criterion.
    min_improvement : float
        Relative decrease of ``sigma_r^2`` that counts as meaningful for ``"remark1"``.
    estimator : LPC, optional
        Settings (method, weighting, delay); its order is replaced.

    Returns
    -------
    OrderSelection
    """
    if criterion not in ("remark1", "aic", "bic"):
        raise ValueError(f"criterion must be 'remark1', 'aic' or 'bic'; got {criterion!r}.")
    orders = np.array(sorted({int(o) for o in orders}))
    if orders.size == 0 or orders[0] < 1:
        raise ValueError(f"orders must be ints >= 1; got {orders.tolist()}.")
    data = as_iodata(u, y, dt)
    base = estimator or LPC()
    largest = replace(base, order=int(orders[-1]), na=None, nb=None).structure().max_lag
    rows = []
    for order in orders:
        est = replace(base, order=int(order), na=None, nb=None)
        skip = largest - est.structure().max_lag  # drop samples so all use the same rows
        model = est.fit(data[skip:])
        info = model.info
        n = int(info["n_rows"][0])
        k = (model.theta.shape[1] - 1 + 2) * model.n_outputs
        ll = float(np.sum(info["log_likelihood"]))
        rows.append(
            (
                float(np.sum(info["J"])),
                ll,
                2 * k - 2 * ll,
                k * np.log(n) - 2 * ll,
                float(np.sum(info["noise_variance"])),
                k,
            )
        )
    J, ll, aic, bic, var, k = (np.array(col) for col in zip(*rows, strict=False))
    if criterion == "aic":
        best = int(orders[np.argmin(aic)])
    elif criterion == "bic":
        best = int(orders[np.argmin(bic)])
    else:
        best = int(orders[0])
        for i in range(1, orders.size):
            if var[i] < (1.0 - min_improvement) * var[i - 1]:
                best = int(orders[i])
            else:
                break
    return OrderSelection(orders, J, ll, aic, bic, var, k.astype(int), best, criterion)
