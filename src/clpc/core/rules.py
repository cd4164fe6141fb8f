"""Every rule of the LPC solution, written once (plain Python in numba's subset).

The batch estimator (:class:`clpc.LPC`) calls these functions per equation after its numpy
SVD, as plain Python; the CLPC kernel (:mod:`clpc.appraiser.kernel`) compiles them into its
per-window loop (each is registered with ``numba.extending.register_jitable``). Thresholds
are named constants or fields of :class:`RobustRule`; none is written as a bare literal in
the logic.

The paper's solution (section III) is in :mod:`clpc.core.solution`. The problem actually
solved there is ``T^T A T`` for a transform ``T`` (:data:`NO_TRANSFORM`:
``T = I``, the paper; :data:`CHANNEL_SCALES`: each channel divided by its standard
deviation; :data:`FIXED_TRANSFORM`: ``T^T W T = I`` for a known noise covariance ``W``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba.extending import register_jitable

__all__ = [
    "CHANNEL_SCALES",
    "FIXED_TRANSFORM",
    "NO_TRANSFORM",
    "RobustRule",
    "SolveSettings",
    "accepts",
    "is_determined",
    "is_excited",
    "is_input_relation",
    "is_trusted",
    "transform_mode",
]

# ------------------------------------------------------------------ named thresholds
#: The solved problem ``T^T A T``: the paper's ``A`` itself.
NO_TRANSFORM = 0
#: ... each channel scaled to unit standard deviation (its lags share the scale).
CHANNEL_SCALES = 1
#: ... whitened by a known noise covariance (weighted LPC).
FIXED_TRANSFORM = 2

#: A residual variance below this many machine epsilons of ``lambda_max / n`` is rounding,
#: not noise: the likelihood uses the floor instead (2.2e-13 relative variance, 126 dB).
ROUNDING_VARIANCE_FACTOR = 1e3
#: A trusted CLPC window holds at least this many lag vectors per parameter ...
TRUST_ROWS_PER_PARAMETER = 10
#: ... and at least this fraction of the full window (whichever is more, at most W).
TRUST_WINDOW_FRACTION = 0.5
#: The output is excited in a window when its standard deviation there is at least this
#: many quantization steps (its smallest nonzero change between consecutive samples of the
#: window): below it a quantized signal takes a handful of values and satisfies exact
#: spurious relations.
EXCITATION_QUANTA = 3.0
#: A fit's verdict calls the model adequate only when its held-out free-run fit
#: (:func:`clpc.lpc.assessment.heldout_evidence`) is at least this many percent and its
#: residuals are independent of the input (:mod:`clpc.model.residuals`); below it the
#: model describes the record poorly (the dryer record at N = 2, nk = 0: 43 %; with the
#: order or the delay right: 85-88 %).
MIN_HELDOUT_FIT = 60.0

_EPS = 2.0**-52
_TINY = 2.2250738585072014e-308
_LOG_2PI = math.log(2.0 * math.pi)


@dataclass(frozen=True)
class RobustRule:
    """Thresholds of the excitation-aware (``method="robust"``) solution.

    Parameters
    ----------
    min_a0_weight : float
        An eigenvector of the solved scatter matrix is a candidate system relation when
        its unit-free ``y(n)`` weight (:func:`clpc.core.near_null.unit_free_weights`) is at
        least this (0 < value <= 1). Smaller eigenvectors below the first candidate are
        relations that do not determine ``y(n)``, and a *solution* below it is an input
        relation (:func:`is_input_relation`): it is counted in ``n_input_relations``, is
        never determined and never accepted by the appraiser. This is the one threshold
        of "determines ``y(n)``". Why 0.1: a plant's own relation has a much larger
        weight (the dryer's windows 0.37-0.44; a second-order plant with poles at
        ``0.97 +- 0.05j`` about 0.42), while the input-only relations measured were 0.006
        (``u(n) ~ u(n-1)`` on a drive record, accepted by the 1e-3 rule used before) and
        0.07-0.09 (a chirp input with the output 100 times the input's size, method
        ``"paper"``). A slow plant of high order has a small weight of its own (all
        ``na = 5`` poles near 1: about ``1 / sqrt(252) = 0.063``): lower it there.
    degeneracy_ratio : float, optional
        Eigenvalues within this factor of the candidate's belong to the same near-null
        subspace (the noise cannot tell them apart); the solution is then the minimum-norm
        vector with ``a0 = 1`` in that subspace. Default: the ratio of the edges of the
        Marchenko-Pastur law, ``((1 + sqrt(p/n)) / (1 - sqrt(p/n)))^2`` (the spread of the
        eigenvalues of pure noise with ``n`` rows and ``p`` columns; 2.0 for ``p = 6, n = 200``
        and 1.03 for ``n = 1e5``), at most :data:`~clpc.core.near_null.MAX_DEGENERACY_RATIO`.
    zero_tol : float
        Eigenvalues below ``zero_tol * lambda_max`` are zero (rounding level): they are
        always in the near-null subspace, whatever their ratios.
    min_output_weight : float
        An eigenvector whose output block ``||v[y]||^2`` is below this is an input-only
        relation (the input is not persistently exciting).
    separation : float
        The solution is *determined* when the candidate eigenvalue is at most this fraction
        of the next eigenvalue outside the near-null subspace.
    """

    min_a0_weight: float = 0.1
    degeneracy_ratio: float | None = None
    zero_tol: float = 1e-12
    min_output_weight: float = 0.05
    separation: float = 0.1

    def __post_init__(self) -> None:
        a0 = self.min_a0_weight
        if not (_is_number(a0) and 0.0 < a0 <= 1.0):
            raise ValueError(
                f"RobustRule.min_a0_weight must be a number in (0, 1]; got {a0!r} (a solution "
                "with no y(n) weight has no monic form)."
            )
        for name in ("zero_tol", "min_output_weight", "separation"):
            value = getattr(self, name)
            if not (_is_number(value) and 0.0 <= value <= 1.0):
                raise ValueError(f"RobustRule.{name} must be a number in [0, 1]; got {value!r}.")
        ratio = self.degeneracy_ratio
        if ratio is not None and not (_is_number(ratio) and ratio >= 1.0):
            raise ValueError(
                f"RobustRule.degeneracy_ratio must be None (Marchenko-Pastur) or a number >= 1; "
                f"got {ratio!r}."
            )


def _is_number(value: object) -> bool:
    """An int or float, not a bool."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


class SolveSettings(NamedTuple):
    """What one solve needs besides the data (numba passes it as a named tuple)."""

    robust: bool  #: the excitation-aware pick (else the paper's smallest eigenvector)
    transform_mode: int  #: NO_TRANSFORM, CHANNEL_SCALES or FIXED_TRANSFORM
    n_out_cols: int  #: output columns ``na + 1``; column 0 is ``y(n)``
    n_channels: int  #: channel blocks (output first), for the scaling
    min_a0_weight: float
    degeneracy_ratio: float  #: <= 0: the Marchenko-Pastur ratio
    zero_tol: float
    min_output_weight: float


#: the choices of ``scaling``: the raw units of the data (the default: consistent under
#: errors-in-variables) or each channel divided by its standard deviation
SCALINGS = ("none", "std")


def transform_mode(scaling: str, has_noise_cov: bool) -> int:
    """The solved problem: a known noise covariance wins, else ``scaling``.

    ``"none"`` solves ``A`` in the data's units: total least squares, consistent when the
    noise on every lag entry has the same variance (errors-in-variables with equal noise,
    the case TLS exists for). ``"std"`` solves ``S^-1 A S^-1`` with ``S`` the channels'
    standard deviations: unit-free, but consistent only when every channel has the same
    signal-to-noise ratio.
    """
    if scaling not in SCALINGS:
        raise ValueError(f"scaling must be 'none' or 'std'; got {scaling!r}.")
    if has_noise_cov:
        return FIXED_TRANSFORM
    return CHANNEL_SCALES if scaling == "std" else NO_TRANSFORM


def solve_settings(
    rule: RobustRule, robust: bool, transform_mode: int, n_out_cols: int, n_channels: int
) -> SolveSettings:
    """The named tuple of one solve from the user's :class:`RobustRule`."""
    fixed = -1.0 if rule.degeneracy_ratio is None else float(rule.degeneracy_ratio)
    return SolveSettings(
        bool(robust),
        int(transform_mode),
        int(n_out_cols),
        int(n_channels),
        float(rule.min_a0_weight),
        fixed,
        float(rule.zero_tol),
        float(rule.min_output_weight),
    )


# ------------------------------------------------------------------ statistics and verdicts
@register_jitable(error_model="numpy")
def likelihood_variance(noise_variance: float, lambda_max: float, n_rows: float) -> float:
    """``sigma_r^2`` floored at the rounding level of the window's own scale."""
    floor = ROUNDING_VARIANCE_FACTOR * _EPS * max(lambda_max, 0.0) / max(n_rows, 1.0)
    return max(noise_variance, floor, _TINY)


@register_jitable(error_model="numpy")
def index_j(variance: float, n_rows: float) -> float:
    """The paper's index ``J`` (eq. 22) at the solution: ``n/2 log sigma^2 + n/2``."""
    return 0.5 * n_rows * (math.log(variance) + 1.0)


@register_jitable(error_model="numpy")
def log_likelihood(variance: float, n_rows: float) -> float:
    """Gaussian log-likelihood at its maximum: ``-n/2 (log(2 pi sigma^2) + 1)``.

    The paper's eq. 21 writes ``-log(2 pi)`` per sample where the density gives
    ``-1/2 log(2 pi)``.
    """
    return -0.5 * n_rows * (_LOG_2PI + math.log(variance) + 1.0)


@register_jitable(error_model="numpy")
def eig_ratio(lambda_min: float, lambda_max: float) -> float:
    """Scale-free ``lambda_min / lambda_max`` (1 when nothing varies)."""
    return lambda_min / lambda_max if lambda_max > 0 else 1.0


@register_jitable(error_model="numpy")
def is_determined(
    n_null: int, n_input: int, separation: float, degenerate: bool, separation_tol: float
) -> bool:
    """The data determine the solution.

    One near-null direction, separated from the next by ``separation_tol``, no input-only
    relation, nothing degenerate.
    """
    return n_null == 1 and n_input == 0 and separation <= separation_tol and not degenerate


def trust_rows(p: int, window: int) -> int:
    """Lag vectors a window needs to be trusted: ``max(10 p, W / 2)``, at most ``W``."""
    need = max(TRUST_ROWS_PER_PARAMETER * p, math.ceil(TRUST_WINDOW_FRACTION * window))
    return int(min(need, window))


@register_jitable(error_model="numpy")
def is_excited(scat: np.ndarray, n_rows: float, step: float, n_out_cols: int) -> bool:
    """The output varies by at least :data:`EXCITATION_QUANTA` quantization steps.

    ``step`` is the output's quantization step in the window: its smallest nonzero change
    between consecutive samples (``inf`` when it never changes). Only the output columns
    (the first ``n_out_cols``) are checked: the output is the measured, quantized signal (a
    resolver or encoder at rest jitters by a step or two), while an input is often a
    command with few levels on purpose (a PRBS changes by its whole amplitude, and is
    exciting).
    """
    n_safe = max(n_rows, 1.0)
    for a in range(n_out_cols):
        std = math.sqrt(max(scat[a, a], 0.0) / n_safe)
        if not std >= EXCITATION_QUANTA * step:
            return False
    return True


@register_jitable(error_model="numpy")
def is_trusted(n_rows: float, need_rows: int, excited: bool, determined: bool) -> bool:
    """A window the guard trusts: enough rows, excited above quantization, determined.

    ``determined`` is :func:`is_determined` with the rule's separation (0.1 by default).
    A looser separation was measured to let wrong models through: a window holding only a
    ramp of the input (``u`` exactly linear, ``y`` with 1e-3 noise) has separation 0.30
    and its solution has ``A = [1, 1.66, 1.61]`` for a true ``[1, -1.5, 0.7]``; the closed
    servo loop of the experiment at N = 2 has 0.30-0.35 too (its unmodelled dynamics), so
    no threshold between them separates a right model from a wrong one.
    """
    return n_rows >= need_rows and excited and determined


@register_jitable(error_model="numpy")
def is_input_relation(a0_weight: float, min_a0_weight: float) -> bool:
    """The solution hardly involves ``y(n)``: a relation the input (or past) satisfies.

    ``a0_weight`` is the solution's unit-free ``y(n)`` weight
    (:func:`clpc.core.near_null.unit_free_weights`), ``min_a0_weight`` the rule's
    threshold (:class:`RobustRule`, where its value is argued). Such a solution (e.g.
    ``u(n) ~ u(n-1)`` for a smooth input) is not the plant: its monic form divides by a
    ``y(n)`` coefficient near 0 and has arbitrary poles.
    """
    return not a0_weight >= min_a0_weight


@register_jitable(error_model="numpy")
def accepts(
    not_enough: bool,
    degenerate: bool,
    weights: tuple[float, float],
    guard: bool,
    trusted: bool,
) -> bool:
    """The appraiser takes a window's estimate (else it holds the last one).

    ``weights = (a0_weight, min_a0_weight)``: a solution that is an input relation
    (:func:`is_input_relation`) is never taken, guard or not. Otherwise, without the
    guard (the paper's appraiser) every computable estimate is taken; with it only trusted
    windows (:func:`is_trusted`).
    """
    a0_weight, min_a0_weight = weights
    ok = not not_enough and not degenerate and not is_input_relation(a0_weight, min_a0_weight)
    return ok and (trusted or not guard)
