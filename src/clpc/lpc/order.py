"""Order selection: the paper's Remark 1 (raise N while J keeps falling), AIC and BIC.

All orders are compared on the same samples (the rows that the largest order can use), so
their likelihoods are comparable.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from clpc.data import as_iodata
from clpc.lpc.estimator import LPC

__all__ = ["DelaySelection", "OrderSelection", "select_delay", "select_order"]


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
    validation_fit: np.ndarray | None = None

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
    k: int = 10,
    validation_fraction: float = 1.0 / 3.0,
    parsimony: float = 1.0,
) -> OrderSelection:
    """Choose the model order ``N`` (``na = nb = N``).

    Parameters
    ----------
    u, y, dt
        The record (see :meth:`clpc.LPC.fit`).
    orders : iterable of int
        Candidate orders, ascending.
    criterion : {"remark1", "aic", "bic", "validation"}
        ``"remark1"``: the paper's rule - from the lowest order, raise ``N`` while the
        noise variance (hence ``J``) falls by at least ``min_improvement`` (relative);
        ``"aic"``/``"bic"``: the minimum of the information criterion;
        ``"validation"``: fit on the first ``1 - validation_fraction`` of the record and
        take the order with the best ``k``-step-ahead prediction fit % on the rest (the
        criterion that works on real data, where the likelihood keeps rising with the
        order).
    min_improvement : float
        Relative decrease of ``sigma_r^2`` that counts as meaningful for ``"remark1"``.
    estimator : LPC, optional
        Settings (method, weighting, delay); its order is replaced.
    k : int
        Prediction horizon for ``"validation"``.
    validation_fraction : float
        Share of the record held out for ``"validation"`` (0 < f < 1).
    parsimony : float
        ``"validation"`` takes the lowest order whose fit is within this many points of the
        best (a larger order must earn its parameters).

    Returns
    -------
    OrderSelection
    """
    if criterion not in ("remark1", "aic", "bic", "validation"):
        raise ValueError(
            f"criterion must be 'remark1', 'aic', 'bic' or 'validation'; got {criterion!r}."
        )
    if not 0.0 < validation_fraction < 1.0:
        raise ValueError(f"validation_fraction must be in (0, 1); got {validation_fraction!r}.")
    orders = np.array(sorted({int(o) for o in orders}))
    if orders.size == 0 or orders[0] < 1:
        raise ValueError(f"orders must be ints >= 1; got {orders.tolist()}.")
    data = as_iodata(u, y, dt)
    base = estimator or LPC()
    largest = replace(base, order=int(orders[-1]), na=None, nb=None).structure().max_lag
    rows = []
    for order in orders:
        # the likelihood table compares the orders as fitted (no cancellation)
        est = replace(base, order=int(order), na=None, nb=None, cancel=False)
        skip = largest - est.structure().max_lag  # drop samples so all use the same rows
        model = est.fit(data[skip:])
        info = model.info
        n = int(info["n_rows"][0])
        n_free = (model.theta.shape[1] - 1 + 2) * model.n_outputs
        loglik = float(np.sum(info["log_likelihood"]))
        rows.append(
            (
                float(np.sum(info["J"])),
                loglik,
                2 * n_free - 2 * loglik,
                n_free * np.log(n) - 2 * loglik,
                float(np.sum(info["noise_variance"])),
                n_free,
            )
        )
    cols = [np.array(col) for col in zip(*rows, strict=True)]
    J, ll, aic, bic, var, n_par = cols
    val_fit = None
    if criterion == "validation":
        val_fit = _validation_fits(data, base, orders, k, validation_fraction)
        best = int(orders[np.flatnonzero(val_fit >= val_fit.max() - parsimony)[0]])
    elif criterion == "aic":
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
    return OrderSelection(orders, J, ll, aic, bic, var, n_par.astype(int), best, criterion, val_fit)


def _validation_fits(
    data: Any, base: LPC, orders: np.ndarray, k: int, fraction: float
) -> np.ndarray:
    """``k``-step-ahead fit % on the held-out tail, per order (summed over outputs' errors)."""
    split = round(data.n_samples * (1.0 - fraction))
    est, val = data[:split], data[split:]
    fits = []
    for order in orders:
        model = replace(base, order=int(order), na=None, nb=None).fit(est)
        y_hat = np.asarray(model.predict(val.u, val.y, k=k)).reshape(val.y.shape)
        start = model.structure.max_lag
        err = np.linalg.norm(val.y[start:] - y_hat[start:])
        ref = np.linalg.norm(val.y[start:] - val.y[start:].mean(axis=0))
        ok = np.isfinite(err) and ref > 0
        fits.append(100.0 * (1.0 - err / ref) if ok else -np.inf)
    return np.array(fits)


@dataclass(frozen=True)
class DelaySelection:
    """Held-out ``k``-step fit % per input delay and the chosen delay."""

    delays: np.ndarray
    validation_fit: np.ndarray
    best: int


def select_delay(
    u: Any,
    y: Any | None = None,
    *,
    delays: Any = range(0, 5),
    estimator: LPC | None = None,
    dt: float | None = None,
    k: int = 10,
    validation_fraction: float = 1.0 / 3.0,
    parsimony: float = 1.0,
) -> DelaySelection:
    """Choose the input delay ``nk`` by held-out ``k``-step prediction fit.

    Parameters
    ----------
    u, y, dt
        The record.
    delays : iterable of int
        Candidate delays (>= 0).
    estimator : LPC, optional
        Settings (order, method...); its ``nk`` is replaced.
    k, validation_fraction, parsimony
        As for :func:`select_order`: the smallest delay whose fit is within ``parsimony``
        points of the best wins.

    Returns
    -------
    DelaySelection
    """
    cands = np.array(sorted({int(d) for d in delays}))
    if cands.size == 0 or cands[0] < 0:
        raise ValueError(f"delays must be ints >= 0; got {cands.tolist()}.")
    if not 0.0 < validation_fraction < 1.0:
        raise ValueError(f"validation_fraction must be in (0, 1); got {validation_fraction!r}.")
    data = as_iodata(u, y, dt)
    base = estimator or LPC()
    split = round(data.n_samples * (1.0 - validation_fraction))
    est, val = data[:split], data[split:]
    fits = []
    for nk in cands:
        model = replace(base, nk=int(nk)).fit(est)
        y_hat = np.asarray(model.predict(val.u, val.y, k=k)).reshape(val.y.shape)
        start = replace(base, nk=int(cands[-1])).structure().max_lag
        err = np.linalg.norm(val.y[start:] - y_hat[start:])
        ref = np.linalg.norm(val.y[start:] - val.y[start:].mean(axis=0))
        fits.append(100.0 * (1.0 - err / ref) if np.isfinite(err) and ref > 0 else -np.inf)
    fit = np.array(fits)
    best = int(cands[np.flatnonzero(fit >= fit.max() - parsimony)[0]])
    return DelaySelection(cands, fit, best)
