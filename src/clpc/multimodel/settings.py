"""The settings of a multi-model, checked once (the constructor of :class:`clpc.MultiModel`)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["check_settings"]


def check_settings(
    *,
    n_models: int | None,
    max_models: int,
    estimator: str,
    window_size: int,
    cluster_size: int,
    holdout: float,
    tolerance: float,
    method: str,
) -> dict[str, Any]:
    """The multi-model's settings as a plain dict, each checked (see :class:`clpc.MultiModel`).

    Parameters
    ----------
    n_models : int, optional
        Number of local models (>= 1), or ``None`` for the automatic choice.
    max_models : int
        Largest number the automatic choice tries (>= 1).
    estimator : {"auto", "lpc", "ls"}
        Local estimator.
    window_size, cluster_size : int
        Windows placing the centres (samples, >= 2; windows per cluster, >= 1).
    holdout : float
        Share of the record held out, in [0.05, 0.5].
    tolerance : float
        Points of held-out fit within which fewer models are preferred (>= 0).
    method : {"robust", "paper"}
        LPC solution.

    Returns
    -------
    dict
        ``n_models``, ``max_models``, ``estimator``, ``window_size``, ``cluster_size``,
        ``holdout``, ``tolerance``, ``method``.

    Raises
    ------
    ValueError
        A setting out of its range.
    """
    for name, value, low in (
        ("n_models", n_models, 1),
        ("max_models", max_models, 1),
        ("window_size", window_size, 2),
        ("cluster_size", cluster_size, 1),
    ):
        if value is None and name == "n_models":
            continue
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
            raise ValueError(f"{name} must be an int >= {low}; got {value!r}.")
    if estimator not in ("auto", "lpc", "ls"):
        raise ValueError(f"estimator must be 'auto', 'lpc' or 'ls'; got {estimator!r}.")
    if not 0.05 <= float(holdout) <= 0.5:
        raise ValueError(f"holdout must be a share in [0.05, 0.5]; got {holdout!r}.")
    if not float(tolerance) >= 0:
        raise ValueError(f"tolerance must be >= 0 points; got {tolerance!r}.")
    return {
        "n_models": None if n_models is None else int(n_models),
        "max_models": int(max_models),
        "estimator": estimator,
        "window_size": int(window_size),
        "cluster_size": int(cluster_size),
        "holdout": float(holdout),
        "tolerance": float(tolerance),
        "method": method,
    }
