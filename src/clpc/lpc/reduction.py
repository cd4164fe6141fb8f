"""Order reduction of a fitted LPC model: near pole/zero pairs cancelled.

Total least squares at an order above the system's leaves the extra factor common to
``A`` and ``B`` and puts it near the unit circle (a Pisarenko effect), where it makes
free-run simulation fragile or unstable. :func:`reduce_model` removes every pole/zero
pair closer than :data:`clpc.core.polynomials.CANCEL_DISTANCE` and refits the offset
``c`` (eq. 24) on the reduced structure; the model's ``info`` says what was removed.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, cast

import numpy as np

from clpc.core.polynomials import CANCEL_DISTANCE, cancel_common_factors
from clpc.data import IOData
from clpc.lpc.regressors import regressors
from clpc.model import LinearModel, MimoMode, ModelError, Structure

__all__ = ["reduce_model"]


def reduce_model(model: LinearModel, data: IOData, tol: float = CANCEL_DISTANCE) -> LinearModel:
    """``model`` without its near-cancelling pole/zero pairs (or ``model`` itself).

    Every output equation must lose the same number of factors (one structure serves all
    outputs); otherwise, or when nothing cancels, the model is returned unchanged with
    ``info["cancelled"] = 0``.

    Parameters
    ----------
    model : LinearModel
        An LPC fit of ``data``.
    data : IOData
        The record it was fitted on (for the offset of the reduced equation).
    tol : float
        Largest pole-zero distance that counts as a common factor.

    Returns
    -------
    LinearModel
        ``info["cancelled"]`` (factors removed) and ``info["fitted_structure"]`` (the
        ``na``, ``nb``, ``nk`` that were solved) are set.
    """
    s = model.structure
    info: dict[str, Any] = dict(model.info)
    info["fitted_structure"] = {"na": s.na, "nb": s.nb, "nk": s.nk}
    info["cancelled"] = 0
    try:
        dens, nums = model.denominators, model.numerators
    except ModelError:
        return replace(model, info=info)
    parts = [cancel_common_factors(dens[j], nums[j], tol) for j in range(model.n_outputs)]
    removed = {m for _, _, m in parts}
    m = removed.pop() if len(removed) == 1 else 0
    if m == 0 or s.na - m < 1 or s.nb - m < 0:
        return replace(model, info=info)
    reduced = Structure(s.na - m, s.nb - m, s.nk)
    theta = np.array(
        [_theta(den, num, model.mode, j, s.nk) for j, (den, num, _) in enumerate(parts)]
    )
    lag_rows = regressors(data, reduced, cast(MimoMode, model.mode))  # (E, n, p)
    c = np.einsum("ep,ep->e", lag_rows.mean(axis=1), theta)  # eq. 24
    info["cancelled"] = m
    return replace(model, theta=theta, structure=reduced, c=c, info=info)


def _theta(den: np.ndarray, num: np.ndarray, mode: str, j: int, nk: int) -> np.ndarray:
    """Unit-norm ``[a; b]`` (paper convention, ``a0 > 0``) of monic ``den``, ``num``."""
    rows = [j] if mode == "paired" else range(num.shape[0])
    theta = np.concatenate([den, *(-num[i, nk:] for i in rows)])
    return theta / np.linalg.norm(theta)
