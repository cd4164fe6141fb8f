"""The parameter covariance an LPC fit offers: a block jackknife of its solve.

Each replicate solves the scatter down-dated by one block of lag vectors
(:func:`clpc.lpc.uncertainty.lpc_jackknife`) with the fit's own settings, at the model's
structure (the reduced one after a cancellation).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.data import IOData
from clpc.lpc.regressors import regressors
from clpc.lpc.scatter import structure_blocks
from clpc.lpc.solve import RobustRule, noise_covariance, solve_scatter
from clpc.lpc.uncertainty import covariance_entries, jackknife_blocks, lpc_jackknife, monic_map
from clpc.model import LinearModel, ModelError
from clpc.model.structure import input_blocks

__all__ = ["jackknife_entries"]


def jackknife_entries(
    model: LinearModel,
    data: IOData,
    rule: RobustRule,
    *,
    method: str,
    scaling: str,
    noise_cov: Any,
    noise_ratio: float | None,
) -> dict[str, Any]:
    """The block-jackknife covariance of an LPC solve at ``model``'s structure (entries).

    Parameters
    ----------
    model : LinearModel
        The fitted model (its structure and mode, after any cancellation).
    data : IOData
        The record it was fitted on.
    rule : RobustRule
        Thresholds of the robust solution.
    method, scaling, noise_cov, noise_ratio
        The settings of the fit (see :class:`clpc.LPC`).

    Returns
    -------
    dict
        :func:`clpc.lpc.uncertainty.covariance_entries`, or ``covariance_note`` alone when
        the jackknife cannot run.
    """
    s, mode = model.structure, model.mode
    n_blocks_in = input_blocks(mode, data.n_inputs)
    mats = regressors(data, s, mode)  # type: ignore[arg-type]
    groups = jackknife_blocks(mats.shape[1], mats.shape[2])
    if not groups:
        return {"covariance_note": f"{mats.shape[1]} lag vectors are too few to split"}
    try:
        solve_cov = noise_covariance(noise_cov, noise_ratio, s, n_blocks_in)
    except ValueError:
        return {"covariance_note": "the noise covariance does not fit the reduced order"}

    def solve(scatter: np.ndarray, mean: np.ndarray, rows: np.ndarray) -> np.ndarray:
        return solve_scatter(
            scatter, mean, rows, n_output_cols=s.na + 1,
            blocks=structure_blocks(s, n_blocks_in), method=method,
            noise_cov=solve_cov, rule=rule, scaling=scaling,
        ).theta  # fmt: skip

    def to_monic(theta: np.ndarray, j: int) -> np.ndarray:
        a0 = theta[:, :1]
        if np.any(np.abs(a0) <= 1e-9 * np.linalg.norm(theta, axis=1, keepdims=True)):
            raise ModelError("a jackknife replicate has a0 about 0 (no monic form)")
        return (theta[:, 1:] / a0) @ monic_map(s, model.n_inputs, mode, j).T

    try:
        cov = lpc_jackknife(mats, solve, to_monic, groups)
    except (ModelError, ValueError) as exc:  # no monic replicate; a noise_cov of p entries
        return {"covariance_note": f"the jackknife could not run: {exc}"}
    how = f"block jackknife over {groups} segments"
    if model.info.get("cancelled"):
        how += " (LPC solve at the reduced order)"
    return covariance_entries(cov, groups - 1, how)
