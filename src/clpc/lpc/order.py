"""Order selection: the paper's Remark 1 (raise N while J keeps falling), AIC and BIC.

All orders are compared on the same samples (the rows that the largest order can use), so
their likelihoods are comparable.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.data import as_iodata
from clpc.lpc import heldout
from clpc.lpc.estimator import LPC

__all__ = ["DelaySelection", "OrderSelection", "select_delay", "select_order"]


def candidate_settings(estimator: Any) -> Any:
    """The estimator without covariance and assessment: candidates only need their fit."""
    quick = {k: False for k in ("uncertainty", "assess") if hasattr(estimator, k)}
    return replace(estimator, **quick)


@compact_repr
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
    validation_fit, free_run_fit, kstep_fit : ndarray, shape (n,), optional
        ``"validation"``: the score (mean of the free-run and the ``horizon``-step fit %
        on the held-out part) and its two parts, per order.
    stability : tuple of str
        ``"validation"``: ``"stable"``, ``"integrating"`` or ``"unstable"`` per order.
    horizon : int, optional
        The prediction horizon [samples] the validation used.
    reason : str
        Why ``best`` was chosen, in words.
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
    free_run_fit: np.ndarray | None = None
    kstep_fit: np.ndarray | None = None
    stability: tuple[str, ...] = ()
    horizon: int | None = None
    reason: str = ""

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
    criterion: str = "validation",
    min_improvement: float = 0.1,
    estimator: LPC | None = None,
    dt: float | None = None,
    k: int | None = None,
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
        ``"validation"`` (default, as in the command line): fit on the first
        ``1 - validation_fraction`` of the record and score each order on the rest by the
        mean of its free-run fit % and its ``k``-step-ahead prediction fit %
        (:mod:`clpc.lpc.heldout`); unstable candidates are never chosen while a stable or
        integrating one exists (the criterion that works on real data, where the
        likelihood keeps rising with the order).
    min_improvement : float
        Relative decrease of ``sigma_r^2`` that counts as meaningful for ``"remark1"``.
    estimator : LPC, optional
        Settings (method, weighting, delay); its order is replaced.
    k : int, optional
        Prediction horizon [samples] for ``"validation"``; default: one dominant time
        constant of the lowest order's model (:func:`clpc.lpc.heldout.horizon`).
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
    base = candidate_settings(estimator or LPC())
    largest = replace(base, order=int(orders[-1]), na=None, nb=None).structure().max_lag
    rows = []
    for order in orders:
        # the likelihood table compares the orders as fitted (no cancellation)
        est = replace(base, order=int(order), na=None, nb=None, cancel=False)
        skip = largest - est.structure().max_lag  # drop samples so all use the same rows
        model = est.fit(data[skip:])
        info = model.info
        n = int(np.atleast_1d(info["n_rows"])[0])
        n_free = (model.theta_matrix.shape[1] - 1 + 2) * model.n_outputs
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
    table = OrderSelection(orders, J, ll, aic, bic, var, n_par.astype(int), 0, criterion)
    if criterion == "validation":
        return _by_validation(table, data, base, (k, validation_fraction, parsimony))
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
    return replace(table, best=best, reason=f"the {criterion} criterion")


def _by_validation(
    table: OrderSelection, data: Any, base: LPC, opts: tuple[int | None, float, float]
) -> OrderSelection:
    """The order chosen on held-out data (see :func:`select_order`)."""
    k, fraction, parsimony = opts
    split = round(data.n_samples * (1.0 - fraction))
    models = [
        replace(base, order=int(order), na=None, nb=None).fit(data[:split])
        for order in table.orders
    ]
    k = k if k is not None else heldout.horizon(models[0], data.n_samples - split)
    scores = [heldout.score(m, data, split, k) for m in models]
    total = np.array([s.score for s in scores])
    usable = np.array([s.stability in ("stable", "integrating") for s in scores])
    usable &= np.isfinite(total)
    pool = usable if usable.any() else np.isfinite(total)
    if not pool.any():
        pool = np.ones(total.size, dtype=bool)
    top = total[pool].max()
    best_i = int(np.flatnonzero(pool & (total >= top - parsimony))[0])
    if usable.any():
        rejected = [int(o) for o, ok in zip(table.orders, usable, strict=True) if not ok]
        reason = (
            f"order {table.orders[best_i]}: the lowest whose held-out score (mean of free-run "
            f"and {k}-step fit %) is within {parsimony:g} point{'' if parsimony == 1 else 's'} "
            "of the best stable one"
            + (f"; unstable or diverging orders {rejected} were rejected" if rejected else "")
        )
    else:
        reason = (
            f"order {table.orders[best_i]}: every candidate is unstable or diverges on the "
            "held-out data; this is the least bad, not a good model"
        )
    return replace(
        table,
        best=int(table.orders[best_i]),
        validation_fit=total,
        free_run_fit=np.array([s.free_run for s in scores]),
        kstep_fit=np.array([s.kstep for s in scores]),
        stability=tuple(s.stability for s in scores),
        horizon=int(k),
        reason=reason,
    )


@compact_repr
@dataclass(frozen=True)
class DelaySelection:
    """Held-out ``k``-step fit % per input delay and the chosen delay.

    Attributes
    ----------
    delays : ndarray of int, shape (n_delays,)
        The candidate input delays ``nk`` [samples], ascending.
    validation_fit : ndarray, shape (n_delays,)
        Held-out ``k``-step prediction fit [%] of each candidate (all outputs together).
    best : int
        The chosen delay [samples]: the smallest within ``parsimony`` points of the best fit.
    """

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
    base = candidate_settings(estimator or LPC())
    split = round(data.n_samples * (1.0 - validation_fraction))
    est, val = data[:split], data[split:]
    fits = []
    for nk in cands:
        model = replace(base, nk=int(nk)).fit(est)
        y_hat = np.asarray(model.predict(val.u, val.y, k=k)).reshape(val.y.shape)
        start = replace(base, nk=int(cands[-1])).structure().max_lag
        fits.append(heldout.fit_percent(val.y[start:], y_hat[start:]))
    fit = np.array(fits)
    best = int(cands[np.flatnonzero(fit >= fit.max() - parsimony)[0]])
    return DelaySelection(cands, fit, best)
