"""Does the record look like errors in variables? LPC against exact-input total least squares.

LPC (total least squares in the data's units) is consistent when every entry of the lag
vector carries white noise of the same variance. With **exact inputs and noise on the output
only** the lag vector's noise covariance is ``sigma^2 diag(1, ..., 1, 0, ..., 0)`` (ones on the
output lags), and the consistent solution of the same scatter ``S`` is the *exact-input*
total least squares: the input block ``b`` is eliminated exactly,

    a = smallest eigenvector of  S_aa - S_ab S_bb^-1 S_ba,      b = -S_bb^-1 S_ba a,

i.e. least squares corrected for white output noise. The output-error fit (:class:`clpc.OE`)
is consistent under output-only noise too (white or not), by a different route (simulation
error). So output-only noise predicts a pattern: the exact-input solution and OE agree, LPC
stands apart. With equal noise on both channels, LPC is the consistent one and the two
others are biased in different directions, so they do not agree better with each other
than with LPC.

The check (per output, monic parameter vectors ``[a_1..a_na, b...]``)::

    ratio = ||p_LPC - p_OE|| / ||p_exact - p_OE||

flags *violated* when ``ratio >= RATIO`` and ``||p_LPC - p_OE|| >= MIN_RELATIVE ||p_OE||``
(the disagreement is material). Measured by ``benchmarks/eiv_check.py`` (a second-order
system, 1000 samples, 20 seeds per case; ``tests/test_identify.py`` repeats a few): noise on
the output only at 10 % and 30 % of its standard deviation gives ratios 6.4-491, all 40
flagged; equal noise on both channels 0.68-3.4, none flagged; noise-free records ratios below
0.5 at distances of 1e-15, none flagged. Input noise 0.3 times the output's (LPC's equal
variances violated the other way) is flagged in 36 of 40.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.data import IOData
from clpc.lpc.estimator import LPC
from clpc.lpc.regressors import regressors
from clpc.model import LinearModel

__all__ = ["MIN_RELATIVE", "RATIO", "EivCheck", "check_eiv", "exact_input_tls"]

#: LPC this many times farther from OE than the exact-input solution: output-only noise.
RATIO = 5.0
#: ... and farther than this share of the OE parameter vector's norm (a material difference).
MIN_RELATIVE = 0.05


@compact_repr
@dataclass(frozen=True)
class EivCheck:
    """Evidence on the errors-in-variables assumption of LPC.

    Attributes
    ----------
    ratio : ndarray, shape (n_outputs,)
        ``||p_LPC - p_OE|| / ||p_exact - p_OE||`` per output (``inf`` when the second is 0).
    lpc_distance : ndarray, shape (n_outputs,)
        ``||p_LPC - p_OE|| / ||p_OE||``.
    violated : bool
        Some output has ``ratio >= RATIO`` and ``lpc_distance >= MIN_RELATIVE``.
    reason : str
        The evidence in words, with the thresholds.
    """

    ratio: np.ndarray
    lpc_distance: np.ndarray
    violated: bool
    reason: str


def exact_input_tls(data: IOData, model: LinearModel) -> np.ndarray:
    """Total least squares with exact inputs, in ``model``'s structure and channels.

    Parameters
    ----------
    data : IOData
        The record.
    model : LinearModel
        Gives the structure and MIMO mode (its parameters are not used).

    Returns
    -------
    ndarray, shape (n_outputs, p)
        Monic parameter vectors ``theta / theta[0]`` (paper convention: ``[a; b]``).
    """
    mats = regressors(data, model.structure, model.mode)  # type: ignore[arg-type]
    na1 = model.structure.na + 1
    out = np.empty((mats.shape[0], mats.shape[2]))
    for j, mat in enumerate(mats):
        centered = mat - mat.mean(axis=0)
        scatter = centered.T @ centered
        s_aa, s_ab, s_bb = scatter[:na1, :na1], scatter[:na1, na1:], scatter[na1:, na1:]
        x = np.linalg.lstsq(s_bb, s_ab.T, rcond=None)[0]  # S_bb^-1 S_ba
        _, vecs = np.linalg.eigh(s_aa - s_ab @ x)
        a = vecs[:, 0]
        theta = np.concatenate([a, -x @ a])
        out[j] = theta / theta[0]
    return out


def check_eiv(
    data: IOData, oe_model: LinearModel, lpc_model: LinearModel | None = None
) -> EivCheck:
    """Compare LPC, exact-input TLS and OE on a record (see the module).

    Parameters
    ----------
    data : IOData
        The record ``oe_model`` was fitted on.
    oe_model : LinearModel
        The :class:`clpc.OE` fit.
    lpc_model : LinearModel, optional
        An LPC fit in the same structure; default ``LPC(cancel=False)`` with the same
        structure and mode.

    Returns
    -------
    EivCheck
    """
    s = oe_model.structure
    if lpc_model is None:
        lpc_model = LPC(
            na=s.na,
            nb=s.nb,
            nk=s.nk,
            mimo=oe_model.mode,  # type: ignore[arg-type]
            cancel=False,
            uncertainty=False,
            assess=False,
        ).fit(data)
    p_oe = _monic(oe_model.theta)
    p_lpc = _monic(lpc_model.theta)
    p_exact = exact_input_tls(data, oe_model)[:, 1:]
    d_lpc = np.linalg.norm(p_lpc - p_oe, axis=1)
    d_exact = np.linalg.norm(p_exact - p_oe, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(d_exact > 0, d_lpc / d_exact, np.where(d_lpc > 0, np.inf, 0.0))
    rel = d_lpc / np.maximum(np.linalg.norm(p_oe, axis=1), 1e-300)
    flagged = (ratio >= RATIO) & (rel >= MIN_RELATIVE)
    j = int(np.argmax(np.where(flagged, ratio, -1.0))) if flagged.any() else int(np.argmax(rel))
    name = f" (output {oe_model.output_names[j]})" if oe_model.n_outputs > 1 else ""
    far = f"{ratio[j]:.2f} times as far from the output-error fit as the exact-input total "
    far += f"least squares is{name} (threshold {RATIO:g})"
    apart = f"{100 * rel[j]:.1f} % of OE's parameter norm (threshold {100 * MIN_RELATIVE:g} %)"
    if flagged.any():
        reason = (
            f"the errors-in-variables assumption of LPC looks violated: LPC is {far}, and "
            f"differs from OE by {apart}. That is what exact inputs with noise on the output "
            "only predict; prefer OE (or least squares) on this record."
        )
    elif rel[j] >= MIN_RELATIVE:  # they differ, but not in output-only noise's pattern
        reason = (
            f"no sign that LPC's errors-in-variables assumption is violated: LPC differs "
            f"from OE by {apart}, but it is only {far}; the exact-input solution disagrees "
            "with OE as well, which output-only noise would not make it do"
        )
    else:
        reason = (
            f"no sign that LPC's errors-in-variables assumption is violated: LPC agrees with "
            f"OE within {apart}"
        )
    return EivCheck(ratio, rel, bool(flagged.any()), reason)


def _monic(theta: Any) -> np.ndarray:
    """``[a_1.., b..]`` of each output: ``theta / theta[0]`` without the leading 1."""
    t = np.atleast_2d(np.asarray(theta, dtype=np.float64))
    return (t / t[:, :1])[:, 1:]
