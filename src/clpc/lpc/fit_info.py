"""The statistics of an LPC solve (``model.info``), each from :mod:`clpc.core.rules`."""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.core import rules
from clpc.lpc.solve import RobustRule, SolveResult

__all__ = ["fit_info"]


def fit_info(res: SolveResult, n_rows: np.ndarray, rule: RobustRule) -> dict[str, Any]:
    """Statistics of a solve as plain arrays (one entry per equation).

    Keys: ``eigenvalues``, ``lambda_min``, ``lambda_max``, ``D`` (``lambda_max -
    lambda_min``, the paper's degree of linearity), ``eig_ratio`` (``lambda_min /
    lambda_max``, scale-free), ``separation``, ``a0_weight`` (the unit-free ``y(n)``
    weight of the solution), ``c``, ``noise_variance``,
    ``log_likelihood``, ``J`` (eq. 22), ``n_rows``, ``n_null``, ``n_input_relations``,
    ``degenerate``, ``determined``. Each number comes from :mod:`clpc.core.rules`, the
    functions the CLPC kernel compiles.
    """
    vals = res.eigenvalues
    n = np.asarray(n_rows, dtype=np.float64) * np.ones(vals.shape[0])
    lam_min, lam_max = vals[:, 0].copy(), vals[:, -1].copy()
    ll_var = [
        rules.likelihood_variance(float(v), float(hi), float(m))
        for v, hi, m in zip(res.noise_variance, lam_max, n, strict=True)
    ]
    determined = [
        rules.is_determined(int(a), int(b), float(c), bool(d), rule.separation)
        for a, b, c, d in zip(
            res.n_null, res.n_input_relations, res.separation, res.degenerate, strict=True
        )
    ]
    return {
        "eigenvalues": vals,
        "lambda_min": lam_min,
        "lambda_max": lam_max,
        "D": lam_max - lam_min,
        "eig_ratio": np.array(
            [rules.eig_ratio(lo, hi) for lo, hi in zip(lam_min, lam_max, strict=True)]
        ),
        "separation": res.separation,
        "a0_weight": res.a0_weight,
        "c": res.c,
        "noise_variance": res.noise_variance,
        "log_likelihood": np.array(
            [rules.log_likelihood(v, m) for v, m in zip(ll_var, n, strict=True)]
        ),
        "J": np.array([rules.index_j(v, m) for v, m in zip(ll_var, n, strict=True)]),
        "n_rows": np.asarray(n_rows),
        "n_null": res.n_null,
        "n_input_relations": res.n_input_relations,
        "degenerate": res.degenerate,
        "determined": np.array(determined, dtype=bool),
    }
