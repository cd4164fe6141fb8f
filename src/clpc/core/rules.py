"""Every rule of the LPC solution, written once (plain Python in numba's subset).

The batch estimator (:class:`clpc.LPC`) calls these functions per equation after its numpy
SVD; the CLPC kernel (:mod:`clpc.appraiser.kernel`) compiles them into its per-window loop
(see :mod:`clpc.core.jit`). Thresholds are named constants or fields of
:class:`RobustRule`; none is written as a bare literal in the logic.

Paper (section III): with lag vectors ``z_n`` (eq. 36), mean ``Z`` (eq. 25) and scatter
``A = sum (z_n - Z)(z_n - Z)^T`` (eq. 27), the maximum-likelihood ``theta`` under
``||theta|| = 1`` is the eigenvector of the smallest eigenvalue of ``A`` (eqs. 28-32),
``c = Z^T theta`` (eq. 24) and ``sigma_r^2 = theta^T A theta / n``.

The problem actually solved is ``T^T A T`` for a transform ``T`` (:data:`NO_TRANSFORM`:
``T = I``, the paper; :data:`CHANNEL_SCALES`: each channel divided by its standard
deviation; :data:`FIXED_TRANSFORM`: ``T^T W T = I`` for a known noise covariance ``W``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from clpc.core.jit import kernel

__all__ = [
    "CHANNEL_SCALES",
    "FIXED_TRANSFORM",
    "NO_TRANSFORM",
    "RobustRule",
    "SolveSettings",
    "accepts",
    "degeneracy_ratio",
    "is_determined",
    "is_excited",
    "is_trusted",
    "solve_from_eig",
    "transform_mode",
]

# ------------------------------------------------------------------ named thresholds
#: The solved problem ``T^T A T``: the paper's ``A`` itself.
NO_TRANSFORM = 0
#: ... each channel scaled to unit standard deviation (its lags share the scale).
CHANNEL_SCALES = 1
#: ... whitened by a known noise covariance (weighted LPC).
FIXED_TRANSFORM = 2

#: A channel is constant when its largest lag variance (summed over the window) is at
#: most this fraction of ``lambda_max``: merged statistics of a constant channel are about
#: 1e-29 of the signal, not exactly 0.
CONSTANT_CHANNEL_FRACTION = 1e-28
#: ... or when its per-row standard deviation is at most this fraction of its own size
#: ``max |mean|`` (a constant offset of 1e4 with rounding noise).
CONSTANT_CHANNEL_RELATIVE_STD = 1e-12
#: Largest eigenvalue ratio of one near-null subspace (cap of the Marchenko-Pastur ratio).
MAX_DEGENERACY_RATIO = 4.0
#: An estimate whose ``y(n)`` weight in the solved problem is below this does not
#: determine ``y(n)``: it has no monic form and the appraiser never accepts it.
MIN_A0_WEIGHT_ACCEPT = 1e-3
#: Entries of a unit vector below this are zero when the sign convention picks its pivot.
SIGN_PIVOT_TOL = 1e-14
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
        its ``y(n)`` component ``|v[a0]|`` is at least this (0..1). Smaller eigenvectors
        below the first candidate are relations that do not determine ``y(n)``.
    degeneracy_ratio : float, optional
        Eigenvalues within this factor of the candidate's belong to the same near-null
        subspace (the noise cannot tell them apart); the solution is then the minimum-norm
        vector with ``a0 = 1`` in that subspace. Default: the ratio of the edges of the
        Marchenko-Pastur law, ``((1 + sqrt(p/n)) / (1 - sqrt(p/n)))^2`` (the spread of the
        eigenvalues of pure noise with ``n`` rows and ``p`` columns; 2.0 for ``p = 6, n = 200``
        and 1.03 for ``n = 1e5``), at most :data:`MAX_DEGENERACY_RATIO`.
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


# ------------------------------------------------------------------ the solved problem
@kernel
def channel_scales(
    scat: np.ndarray, n_rows: float, col_channel: np.ndarray, n_channels: int, scales: np.ndarray
) -> None:
    """Per-column scale: the standard deviation of each channel (mean over its lags).

    A constant channel gets scale 1 (it is flagged degenerate by :func:`is_degenerate`).
    """
    p = scat.shape[0]
    n_safe = max(n_rows, 1.0)
    for ch in range(n_channels):
        acc = 0.0
        cnt = 0
        for a in range(p):
            if col_channel[a] == ch:
                acc += scat[a, a]
                cnt += 1
        std = math.sqrt(max(acc / max(cnt, 1), 0.0) / n_safe)
        for a in range(p):
            if col_channel[a] == ch:
                scales[a] = std if std > 0 else 1.0


@kernel
def solved_matrix(
    scat: np.ndarray,
    mode: int,
    fixed: np.ndarray,
    scales: np.ndarray,
    tmat: np.ndarray,
    mat: np.ndarray,
) -> None:
    """Fill ``tmat`` with ``T`` and ``mat`` with the symmetric ``T^T A T``."""
    p = scat.shape[0]
    for a in range(p):
        for b in range(p):
            if mode == FIXED_TRANSFORM:
                tmat[a, b] = fixed[a, b]
            elif mode == CHANNEL_SCALES:
                tmat[a, b] = 1.0 / scales[a] if a == b else 0.0
            else:
                tmat[a, b] = 1.0 if a == b else 0.0
    if mode == CHANNEL_SCALES:
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b] / (scales[a] * scales[b])
    elif mode == FIXED_TRANSFORM:
        for a in range(p):
            for b in range(p):
                acc = 0.0
                for k in range(p):
                    for m in range(p):
                        acc += tmat[k, a] * scat[k, m] * tmat[m, b]
                mat[a, b] = acc
        for a in range(p):
            for b in range(a):
                sym = 0.5 * (mat[a, b] + mat[b, a])
                mat[a, b] = sym
                mat[b, a] = sym
    else:
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b]


@kernel
def is_degenerate(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    top: float,
    col_channel: np.ndarray,
    n_channels: int,
) -> bool:
    """Nothing varies (``lambda_max <= 0``) or a channel is constant."""
    if not top > 0:
        return True
    p = scat.shape[0]
    n_safe = max(n_rows, 1.0)
    for ch in range(n_channels):
        var = -1.0
        size = 0.0
        for a in range(p):
            if col_channel[a] == ch:
                var = max(var, scat[a, a])
                size = max(size, abs(mean[a]))
        if var <= CONSTANT_CHANNEL_FRACTION * max(top, 1e-300):
            return True
        if var / n_safe <= (CONSTANT_CHANNEL_RELATIVE_STD * size) ** 2:
            return True
    return False


@kernel
def degeneracy_ratio(fixed: float, p: int, n_rows: float) -> float:
    """``fixed`` if > 0, else the Marchenko-Pastur edge ratio for ``p`` columns, ``n`` rows."""
    if fixed > 0:
        return fixed
    x = math.sqrt(p / max(n_rows, 1.0))
    if not x < 1:
        return MAX_DEGENERACY_RATIO
    return min(((1 + x) / max(1 - x, 1e-12)) ** 2, MAX_DEGENERACY_RATIO)


@kernel
def ratio(num: float, den: float) -> float:
    """``num / den`` clipped to [0, 1]; 1 when ``den`` is not positive."""
    num = max(num, 0.0)
    den = max(den, 0.0)
    if not den > 0:
        return 1.0
    return min(num / den, 1.0)


# ------------------------------------------------------------------ picking the vector
@kernel
def unit_free_weights(
    vec: np.ndarray, tmat: np.ndarray, scales: np.ndarray, n_out_cols: int
) -> tuple[float, float]:
    """The ``y(n)`` weight and the output-block weight of ``theta = T v``, free of units.

    With ``s`` the channels' standard deviations (per column), ``w = diag(s) T v`` is the
    relation in units of each channel's own spread: ``|w_0| / ||w||`` (the ``y(n)``
    weight) and ``||w_y||^2 / ||w||^2`` (the output block's share) do not change when a
    channel is rescaled. An input-only relation has ``y(n)`` weight 0 in any units.
    """
    p = vec.shape[0]
    total = 0.0
    out = 0.0
    first = 0.0
    for a in range(p):
        acc = 0.0
        for b in range(p):
            acc += tmat[a, b] * vec[b]
        w = scales[a] * acc
        total += w * w
        if a < n_out_cols:
            out += w * w
        if a == 0:
            first = abs(w)
    if not total > 0:
        return 0.0, 0.0
    return first / math.sqrt(total), out / total


@kernel
def pick_paper(
    eig: tuple[np.ndarray, np.ndarray],
    weights: tuple[np.ndarray, np.ndarray],
    s: SolveSettings,
    phi: np.ndarray,
) -> tuple[int, int, float]:
    """The literal last principal component; returns ``(n_null, n_input, separation)``."""
    vals, vecs = eig
    p = vals.shape[0]
    for a in range(p):
        phi[a] = vecs[a, 0]
    n_input = 1 if weights[1][0] < s.min_output_weight else 0
    return 1, n_input, ratio(vals[0], vals[1] if p > 1 else vals[0])


@kernel
def pick_robust(
    eig: tuple[np.ndarray, np.ndarray],
    weights: tuple[np.ndarray, np.ndarray],
    s: SolveSettings,
    n_rows: float,
    phi: np.ndarray,
) -> tuple[int, int, float]:
    """Minimum-norm ``a0 = 1`` vector in the near-null subspace of the solved problem.

    ``weights = (a0_weights, output_weights)`` of each eigenvector, unit-free
    (:func:`unit_free_weights`). The first eigenvector (ascending) whose ``y(n)`` weight
    is at least ``min_a0_weight`` is the candidate (none: the one with the largest); the
    near-null subspace runs from the smallest eigenvalue through every eigenvalue within
    the degeneracy ratio of the candidate's; ``phi`` is the projection of ``e_a0`` onto it.
    Returns ``(n_null, n_input, separation)``.
    """
    vals, vecs = eig
    a0w, outw = weights
    p = vals.shape[0]
    lim = degeneracy_ratio(s.degeneracy_ratio, p, n_rows)
    first = -1
    for i in range(p):
        if a0w[i] >= s.min_a0_weight:
            first = i
            break
    if first < 0:
        best = -1.0
        for i in range(p):
            if a0w[i] > best:
                best = a0w[i]
                first = i
    lam_s = max(vals[first], s.zero_tol * max(vals[p - 1], 0.0))
    last = p - 1
    for i in range(first + 1, p):
        if not max(vals[i], 0.0) <= lim * lam_s:
            last = i - 1
            break
    for a in range(p):
        phi[a] = 0.0
    n_input = 0
    for i in range(last + 1):
        w = vecs[0, i]
        for a in range(p):
            phi[a] += vecs[a, i] * w
        if outw[i] < s.min_output_weight:
            n_input += 1
    separation = 1.0 if last + 1 >= p else ratio(lam_s, vals[last + 1])
    return last + 1, n_input, separation


@kernel
def normalise(theta: np.ndarray) -> None:
    """Unit norm and a deterministic sign: ``a0 > 0`` (else the first nonzero entry > 0)."""
    p = theta.shape[0]
    norm = 0.0
    for a in range(p):
        norm += theta[a] * theta[a]
    norm = math.sqrt(norm)
    for a in range(p):
        theta[a] = theta[a] / norm if norm > 0 else 0.0
    sign = 1.0
    for a in range(p):
        if abs(theta[a]) > SIGN_PIVOT_TOL:
            sign = -1.0 if theta[a] < 0 else 1.0
            break
    for a in range(p):
        theta[a] = sign * theta[a]


@kernel
def solve_from_eig(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    eig: tuple[np.ndarray, np.ndarray, np.ndarray],
    transform: tuple[np.ndarray, np.ndarray],
    s: SolveSettings,
    col_channel: np.ndarray,
    out: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> tuple[float, float, float, float, int, int, bool]:
    """The LPC solution of one equation from the eigen-decomposition of its solved problem.

    Parameters
    ----------
    scat, mean : ndarray, shape (p, p), (p,)
        The paper's scatter ``A`` (eq. 27) and mean ``Z`` (eq. 25).
    n_rows : float
        Lag vectors behind them.
    eig : (vals, vecs, raw)
        Ascending eigenvalues (p,) and eigenvectors (columns, (p, p)) of ``T^T A T``, and
        the ascending eigenvalues of ``A`` itself (the paper's, for ``D``).
    transform : (tmat, scales)
        ``T`` (p, p), and the channels' standard deviations per column (p,) that make the
        weights of :func:`unit_free_weights` unit-free.
    s : SolveSettings
    col_channel : ndarray of int, shape (p,)
        Channel block of each column (0 = output).
    out : (phi, theta, eigenvalues)
        Work vector (p,), and outputs: unit-norm ``theta`` with ``a0 >= 0`` (zero when
        degenerate) and the clipped eigenvalues of ``A``.

    Returns
    -------
    tuple
        ``(c, noise_variance, separation, a0_weight, n_null, n_input, degenerate)``.
    """
    vals, vecs, raw = eig
    tmat, scales = transform
    phi, theta, eigenvalues = out
    p = scat.shape[0]
    degenerate = is_degenerate(scat, mean, n_rows, max(raw[p - 1], 0.0), col_channel, s.n_channels)
    a0w = np.empty(p)
    outw = np.empty(p)
    for i in range(p):
        a0w[i], outw[i] = unit_free_weights(vecs[:, i], tmat, scales, s.n_out_cols)
    if s.robust:
        n_null, n_input, separation = pick_robust((vals, vecs), (a0w, outw), s, n_rows, phi)
    else:
        n_null, n_input, separation = pick_paper((vals, vecs), (a0w, outw), s, phi)
    a0_weight = 0.0 if degenerate else unit_free_weights(phi, tmat, scales, s.n_out_cols)[0]
    for a in range(p):  # theta = T phi
        acc = 0.0
        for b in range(p):
            acc += tmat[a, b] * phi[b]
        theta[a] = acc
    normalise(theta)
    c = 0.0
    quad = 0.0
    for a in range(p):
        if degenerate:
            theta[a] = 0.0
        eigenvalues[a] = max(raw[a], 0.0)
    for a in range(p):
        c += mean[a] * theta[a]  # eq. 24
        acc = 0.0
        for b in range(p):
            acc += scat[a, b] * theta[b]
        quad += theta[a] * acc
    noise_variance = max(quad, 0.0) / max(n_rows, 1.0)
    return c, noise_variance, separation, a0_weight, n_null, n_input, degenerate


# ------------------------------------------------------------------ statistics and verdicts
@kernel
def likelihood_variance(noise_variance: float, lambda_max: float, n_rows: float) -> float:
    """``sigma_r^2`` floored at the rounding level of the window's own scale."""
    floor = ROUNDING_VARIANCE_FACTOR * _EPS * max(lambda_max, 0.0) / max(n_rows, 1.0)
    return max(noise_variance, floor, _TINY)


@kernel
def index_j(variance: float, n_rows: float) -> float:
    """The paper's index ``J`` (eq. 22) at the solution: ``n/2 log sigma^2 + n/2``."""
    return 0.5 * n_rows * (math.log(variance) + 1.0)


@kernel
def log_likelihood(variance: float, n_rows: float) -> float:
    """Gaussian log-likelihood at its maximum: ``-n/2 (log(2 pi sigma^2) + 1)``.

    The paper's eq. 21 writes ``-log(2 pi)`` per sample where the density gives
    ``-1/2 log(2 pi)``.
    """
    return -0.5 * n_rows * (_LOG_2PI + math.log(variance) + 1.0)


@kernel
def eig_ratio(lambda_min: float, lambda_max: float) -> float:
    """Scale-free ``lambda_min / lambda_max`` (1 when nothing varies)."""
    return lambda_min / lambda_max if lambda_max > 0 else 1.0


@kernel
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


@kernel
def is_excited(scat: np.ndarray, n_rows: float, step: np.ndarray, n_out_cols: int) -> bool:
    """The output varies by at least :data:`EXCITATION_QUANTA` quantization steps.

    ``step[a]`` is the quantization step of column ``a``'s channel in the window: its
    smallest nonzero change between consecutive samples (``inf`` when it never changes).
    Only the output columns (the first ``n_out_cols``) are checked: the output is the
    measured, quantized signal (a resolver or encoder at rest jitters by a step or two),
    while an input is often a command with few levels on purpose (a PRBS changes by its
    whole amplitude, and is exciting).
    """
    n_safe = max(n_rows, 1.0)
    for a in range(n_out_cols):
        std = math.sqrt(max(scat[a, a], 0.0) / n_safe)
        if not std >= EXCITATION_QUANTA * step[a]:
            return False
    return True


@kernel
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


@kernel
def accepts(
    not_enough: bool, degenerate: bool, a0_weight: float, guard: bool, trusted: bool
) -> bool:
    """The appraiser takes a window's estimate (else it holds the last one).

    Without the guard (the paper's appraiser) every computable estimate is taken; with
    it only trusted windows (:func:`is_trusted`).
    """
    ok = not not_enough and not degenerate and a0_weight >= MIN_A0_WEIGHT_ACCEPT
    return ok and (trusted or not guard)
