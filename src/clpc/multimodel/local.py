"""Local linear models fitted with validity weights over all lag vectors.

A local model ``i`` is fitted on *every* lag vector ``z_n`` of the record, each weighted by
its validity ``w_n = phi_i(psi_n)``: the weighted mean ``Z = sum w z / sum w``, the
weighted scatter ``A = sum w (z - Z)(z - Z)^T`` and ``n_rows = sum w`` go through the same
solve as the global estimator (:func:`clpc.lpc.solve.solve_scatter`, with the SVD of the
rows ``sqrt(w) (z - Z)``). With all weights 1 this *is* the global LPC fit.

Guard: a local LPC model whose largest pole lies outside the unit circle (beyond
:data:`clpc.lpc.heldout.UNIT_CIRCLE_TOL`) is replaced by the weighted least-squares fit
of the same rows and flagged (``info["replaced"]``); total least squares on a region with
little excitation can put a pole outside, least squares shrinks it inside.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.lpc.fit_info import fit_info
from clpc.lpc.heldout import stability
from clpc.lpc.scatter import structure_blocks
from clpc.lpc.solve import RobustRule, solve_scatter
from clpc.model import LinearModel
from clpc.model.structure import Structure

__all__ = ["fit_local", "weighted_lpc", "weighted_ls"]


def _weighted_moments(rows: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    total = float(w.sum())
    mean = (w @ rows) / total
    centered = rows - mean
    return mean, centered, total


def weighted_lpc(
    rows: np.ndarray, w: np.ndarray, structure: Structure, n_inputs: int, method: str = "robust"
) -> tuple[np.ndarray, float, dict[str, Any]]:
    """Validity-weighted LPC of lag vectors ``rows`` (shape (n, p)) with weights ``w`` (n,).

    Returns ``(theta, c, info)``: unit-norm ``theta`` (shape (p,)), ``c = Z^T theta`` and
    the statistics of :func:`clpc.lpc.fit_info.fit_info` (``n_rows = sum w``).
    """
    mean, centered, total = _weighted_moments(rows, w)
    scaled = centered * np.sqrt(w)[:, None]
    scatter = scaled.T @ scaled
    rule = RobustRule()
    res = solve_scatter(
        scatter[None],
        mean[None],
        np.array([total]),
        n_output_cols=structure.na + 1,
        blocks=structure_blocks(structure, n_inputs),
        method=method,
        rule=rule,
        data=scaled[None],
    )
    info = fit_info(res, np.array([total]), rule)
    return res.theta[0], float(res.c[0]), info


def weighted_ls(rows: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, float, dict[str, Any]]:
    """Validity-weighted least squares of ``y(n)`` (column 0) on the rest of ``rows``.

    Returns the unit-norm ``theta = [1, x] / ||[1, x]||``, ``c = Z^T theta`` and an empty
    statistics dict.
    """
    mean, centered, _ = _weighted_moments(rows, w)
    sw = np.sqrt(w)[:, None]
    x, *_ = np.linalg.lstsq(centered[:, 1:] * sw, -centered[:, 0] * sw[:, 0], rcond=None)
    theta = np.concatenate([[1.0], x])
    theta /= np.linalg.norm(theta)
    return theta, float(mean @ theta), {}


def fit_local(
    rows: np.ndarray,
    w: np.ndarray,
    structure: Structure,
    n_inputs: int,
    *,
    estimator: str = "lpc",
    dt: float = 1.0,
    method: str = "robust",
) -> LinearModel:
    """One local model (``estimator`` ``"lpc"`` with the stability guard, or ``"ls"``).

    Returns
    -------
    LinearModel
        ``info`` holds ``estimator`` (what was used), ``replaced`` (LPC came out unstable
        and least squares replaced it), ``weight`` (``sum w``: the effective number of lag
        vectors) and, for LPC, the fit statistics.
    """
    replaced = False
    if estimator == "lpc":
        theta, c, info = weighted_lpc(rows, w, structure, n_inputs, method)
        model = _model(theta, c, structure, n_inputs, dt, info)
        if stability(model) in ("unstable", "no model"):
            replaced = True
            theta, c, info = weighted_ls(rows, w)
            model = _model(theta, c, structure, n_inputs, dt, {"lpc_poles": _poles(model)})
    else:
        theta, c, info = weighted_ls(rows, w)
        model = _model(theta, c, structure, n_inputs, dt, info)
    model.info.update(
        estimator="least-squares" if (replaced or estimator == "ls") else "lpc",
        replaced=replaced,
        weight=float(w.sum()),
    )
    return model


def _poles(model: LinearModel) -> list[complex]:
    try:
        return [complex(p) for p in model.poles()]
    except Exception:  # a0 = 0: no poles
        return []


def _model(
    theta: np.ndarray, c: float, structure: Structure, n_inputs: int, dt: float, info: dict
) -> LinearModel:
    return LinearModel(
        theta=np.atleast_2d(theta),
        structure=structure,
        n_inputs=n_inputs,
        mode="siso" if n_inputs == 1 else "miso",
        c=np.array([c]),
        dt=dt,
        input_names=tuple(f"u{i}" for i in range(n_inputs)) if n_inputs > 1 else ("u",),
        info=dict(info),
    )
