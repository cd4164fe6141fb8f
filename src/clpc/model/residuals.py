"""Residual analysis of a model on a record, like MATLAB SITB's ``resid``.

Residuals ``e(t)`` (from sample ``max_lag`` on, mean removed) are the one-step prediction
errors of the model's equation (``"prediction"``; the equation error for LPC and least
squares) or, for an output-error model, the free-run errors ``y - G u`` (``"simulation"``;
chosen by ``"auto"`` when ``info["noise_model"] == "output-error"``). A model that mixes
noise models over its outputs gets ``"prediction"``: :meth:`LinearModel.predict` is the free
run for its output-error outputs. With ``N`` residuals, ``M`` lags and ``rho`` the normalised
sample autocorrelations (``rho_e(k) = sum_t e(t) e(t-k) / sum_t e(t)^2``):

**Whiteness**: Ljung-Box ``Q = N (N+2) sum_{k=1}^{M} rho_e(k)^2 / (N-k)``, passed when
``Q <= chi2_level(M)``.

**Independence** (nothing of the input's effect left): with ``r(tau) = sum_t e(t) u(t-tau) /
sqrt(sum e^2 sum u^2)`` for ``tau = 0..M``, ``zeta = N r^T P^-1 r``, where ``P_ab =
sum_{|k|<=M} rho_e(k) rho_u(k + tau_b - tau_a)`` is the covariance of ``sqrt(N) r`` for ``e``
independent of ``u`` (Bartlett; it holds for colored residuals too); passed when ``zeta <=
chi2_level(M+1)``.

The per-lag bands are ``+- z / sqrt(N)`` for ``rho_e`` and ``+- z sqrt(P_aa / N)`` for ``r``,
``z`` the two-sided normal quantile of ``level`` (2.58 for the default 0.99, as SITB). Under
errors-in-variables noise the input noise is in the residual too, so even the true model's
residuals correlate with the measured input (at lags ``nk .. nk+nb``): on long records with
noisy inputs the independence test then fails for LPC models and says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.core.compact import compact_repr
from clpc.data.signals import signals
from clpc.model.simulation import noise_models

__all__ = ["MAX_LAGS", "ResidualAnalysis", "ResidualTest", "ljung_box", "residual_analysis"]

#: Lags of the tests (SITB's default ``M``); fewer on records shorter than 4 M.
MAX_LAGS = 25
#: Confidence level of the tests and bands (SITB's default: 99 %).
LEVEL = 0.99
#: Fewest residuals a test is made on.
MIN_RESIDUALS = 20
#: Ridge of the independence test's covariance, relative to its diagonal: the estimated
#: correlations make ``P`` noisy, and its smallest eigenvalues must not blow ``zeta`` up.
RIDGE = 1e-3


@dataclass(frozen=True)
class ResidualTest:
    """One portmanteau test: its statistic against the ``chi2`` threshold.

    Attributes
    ----------
    name : str
        ``"whiteness of y"`` or ``"independence of y from u"``.
    statistic, threshold : float
        ``Q`` or ``zeta``, and ``chi2`` quantile at ``level`` with ``dof`` degrees.
    dof : int
    lags_outside : int
        Lags whose correlation is outside its band (of ``n_lags``).
    n_lags : int
    passed : bool
        ``statistic <= threshold``.
    """

    name: str
    statistic: float
    threshold: float
    dof: int
    lags_outside: int
    n_lags: int
    passed: bool

    def __str__(self) -> str:
        sym = "Q" if self.name.startswith("whiteness") else "zeta"
        verdict, rel = ("passed", "<=") if self.passed else ("FAILED", ">")
        return (
            f"{self.name}: {sym} = {self.statistic:.3g} {rel} {self.threshold:.3g} "
            f"(chi2 with {self.dof} dof), {self.lags_outside} of {self.n_lags} lags outside "
            f"the band - {verdict}"
        )


@compact_repr
@dataclass(frozen=True)
class ResidualAnalysis:
    """Correlations of the residuals, their bands and the tests (see the module).

    Attributes
    ----------
    kind : {"prediction", "simulation"}
    n_samples : int
        Residuals ``N`` the statistics use.
    level : float
    lags : ndarray of int, shape (M + 1,)
        ``0 .. M`` (autocorrelation).
    autocorrelation : ndarray, shape (n_outputs, M + 1)
        ``rho_e(k)``; ``[:, 0] = 1``.
    auto_band : float
        ``z / sqrt(N)``.
    cross_lags : ndarray of int, shape (2 M + 1,)
        ``-M .. M`` (negative: the residual leads the input, a sign of feedback).
    cross_correlation : ndarray, shape (n_outputs, n_inputs, 2 M + 1)
    cross_band : ndarray, shape (n_outputs, n_inputs, 2 M + 1)
    whiteness : tuple of ResidualTest
        One per output.
    independence : tuple of ResidualTest
        One per output and input (output-major).
    residuals : ndarray, shape (N, n_outputs)
    """

    kind: str
    n_samples: int
    level: float
    lags: np.ndarray
    autocorrelation: np.ndarray
    auto_band: float
    cross_lags: np.ndarray
    cross_correlation: np.ndarray
    cross_band: np.ndarray
    whiteness: tuple[ResidualTest, ...]
    independence: tuple[ResidualTest, ...]
    residuals: np.ndarray

    @property
    def tests(self) -> tuple[ResidualTest, ...]:
        """Every test: the whiteness ones, then the independence ones."""
        return (*self.whiteness, *self.independence)

    @property
    def passed(self) -> bool:
        """Every test passed."""
        return all(t.passed for t in self.tests)

    def __str__(self) -> str:
        head = (
            f"residual analysis ({self.kind} errors, N = {self.n_samples}, "
            f"{self.lags.size - 1} lags, level {self.level:g}): "
            f"{'passed' if self.passed else 'FAILED'}"
        )
        return "\n".join([head, *(f"  {t}" for t in self.tests)])


def ljung_box(rho: np.ndarray, n: int) -> float:
    """``Q = n (n+2) sum_{k=1}^{M} rho(k)^2 / (n-k)`` of autocorrelations ``rho(1..M)``."""
    k = np.arange(1, rho.size + 1)
    return float(n * (n + 2) * np.sum(rho**2 / (n - k)))


def _correlations(x: np.ndarray, y: np.ndarray, max_lag: int) -> np.ndarray:
    """``sum_t x(t) y(t-k) / sqrt(sum x^2 sum y^2)`` for ``k = -max_lag .. max_lag`` (FFT)."""
    n = x.shape[0]
    size = 1 << int(np.ceil(np.log2(2 * n)))
    full = np.fft.irfft(np.fft.rfft(x, size) * np.conj(np.fft.rfft(y, size)), size)
    den = np.sqrt(np.dot(x, x) * np.dot(y, y))
    return full[np.arange(-max_lag, max_lag + 1) % size] / (den if den > 0 else 1.0)


def _residuals(model: Any, u: np.ndarray, y: np.ndarray, kind: str) -> np.ndarray:
    start = model.structure.max_lag
    with np.errstate(all="ignore"):
        if kind == "prediction":
            y_hat = np.asarray(model.predict(u, y, k=1))[start:]
        else:
            y_hat = np.asarray(model.simulate(u[start:], y_init=y[:start], u_init=u[:start]))
    e = y[start:] - y_hat.reshape(y[start:].shape)
    if not np.all(np.isfinite(e)):
        raise ValueError(
            f"the model's {kind} errors diverge on this record (the model is unstable "
            "there), so the residuals cannot be analysed; use kind='prediction' or a "
            "stable model."
        )
    return e - e.mean(axis=0)


def residual_analysis(
    model: Any,
    u: Any,
    y: Any = None,
    *,
    max_lag: int = MAX_LAGS,
    level: float = LEVEL,
    kind: str = "auto",
) -> ResidualAnalysis:
    """Whiteness and input-independence tests of a model's residuals on a record.

    Parameters
    ----------
    model : LinearModel
        The model.
    u : array_like, shape (T,) or (T, n_inputs), or IOData
        Measured inputs, or a record of one experiment (its inputs and outputs).
    y : array_like, shape (T,) or (T, n_outputs)
        Measured outputs (required with array inputs).
    max_lag : int
        ``M``, the lags tested (reduced to ``N // 4`` on short records).
    level : float
        Confidence level of the tests and bands, in (0, 1).
    kind : {"auto", "prediction", "simulation"}
        Which errors are the residuals (see the module).

    Returns
    -------
    ResidualAnalysis
        ``.passed`` is true when every test passes.

    Raises
    ------
    ValueError
        Bad arguments, fewer than :data:`MIN_RESIDUALS` residuals, or diverging errors.
    """
    if kind == "auto":
        kind = "simulation" if set(noise_models(model)) == {"output-error"} else "prediction"
    if kind not in ("prediction", "simulation"):
        raise ValueError(f"kind must be 'auto', 'prediction' or 'simulation'; got {kind!r}.")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), e.g. 0.99; got {level!r}.")
    if isinstance(max_lag, bool) or not isinstance(max_lag, (int, np.integer)) or max_lag < 1:
        raise ValueError(f"max_lag must be an int >= 1; got {max_lag!r}.")
    u, y = signals(u, y, what="residual_analysis")
    u2 = np.asarray(u, dtype=np.float64).reshape(len(u), -1)
    y2 = np.asarray(y, dtype=np.float64).reshape(len(y), -1)
    if u2.shape[1] != model.n_inputs or y2.shape[1] != model.n_outputs or len(u2) != len(y2):
        raise ValueError(
            f"u and y must have shapes (T, {model.n_inputs}) and (T, {model.n_outputs}) with "
            f"the same T for this model; got {u2.shape} and {y2.shape}."
        )
    e = _residuals(model, u2, y2, kind)
    n = e.shape[0]
    if n < MIN_RESIDUALS:
        raise ValueError(
            f"residual analysis needs at least {MIN_RESIDUALS} residuals after the model's "
            f"{model.structure.max_lag} initial samples; the record gives {n}."
        )
    m = int(min(max_lag, n // 4))
    uu = u2[-n:] - u2[-n:].mean(axis=0)
    from scipy import special  # not scipy.stats, which costs 0.4 s to import

    z = float(special.ndtri(0.5 + 0.5 * level))  # the normal quantile
    auto = np.empty((y2.shape[1], m + 1))
    cross = np.empty((y2.shape[1], u2.shape[1], 2 * m + 1))
    band = np.empty_like(cross)
    white, indep = [], []
    for j, name in enumerate(model.output_names):
        rho_e = _correlations(e[:, j], e[:, j], 2 * m)  # lags -2M..2M
        auto[j] = rho_e[2 * m : 3 * m + 1]
        outside = np.abs(auto[j, 1:]) > z / np.sqrt(n)
        white.append(_count(f"whiteness of {name}", ljung_box(auto[j, 1:], n), m, level, outside))
        for i, inp in enumerate(model.input_names):
            cross[j, i] = _correlations(e[:, j], uu[:, i], m)
            cov = _bartlett(rho_e, _correlations(uu[:, i], uu[:, i], 2 * m), m)
            # the truncated Bartlett sum can dip below 0 for periodic records: no variance
            var = np.maximum(np.diag(cov), 0.0)[np.abs(np.arange(-m, m + 1))]
            band[j, i] = z * np.sqrt(var / n)
            r = cross[j, i, m:]  # tau = 0..M
            zeta = n * _quadratic(cov, r)
            outside = np.abs(r) > band[j, i, m:]
            indep.append(_count(f"independence of {name} from {inp}", zeta, m + 1, level, outside))
    return ResidualAnalysis(
        kind, n, level, np.arange(m + 1), auto, z / np.sqrt(n), np.arange(-m, m + 1), cross, band,
        tuple(white), tuple(indep), e,
    )  # fmt: skip


def _bartlett(rho_e: np.ndarray, rho_u: np.ndarray, m: int) -> np.ndarray:
    """``P_ab = sum_{|k|<=M} rho_e(k) rho_u(k + b - a)`` for ``a, b = 0..M``."""
    k = np.arange(-m, m + 1)  # also the values of b - a
    p_of_d = (rho_e[2 * m + k][None, :] * rho_u[2 * m + k[None, :] + k[:, None]]).sum(axis=1)
    idx = np.arange(m + 1)
    return p_of_d[m + idx[None, :] - idx[:, None]]


def _quadratic(cov: np.ndarray, r: np.ndarray) -> float:
    """``r^T (P + eps I)^-1 r`` with ``eps = RIDGE max diag P`` (estimation noise in ``P``).

    A Cholesky factorisation; a ``P`` that is not positive definite even then (estimated
    correlations can make it so) has its eigenvalues clipped at ``eps`` instead.
    """
    from scipy import linalg  # imported when used: every command imports this module

    eps = RIDGE * max(float(np.max(np.diag(cov))), np.finfo(float).tiny)
    reg = 0.5 * (cov + cov.T) + eps * np.eye(cov.shape[0])
    try:
        factor = linalg.cho_factor(reg)
    except linalg.LinAlgError:
        vals, vecs = np.linalg.eigh(reg)
        proj = vecs.T @ r
        with np.errstate(over="ignore"):  # a tiny P (residuals about 0): inf, the test fails
            return float(np.sum(proj**2 / np.maximum(vals, eps)))
    return float(r @ linalg.cho_solve(factor, r))


def _count(name: str, stat: float, dof: int, level: float, outside: np.ndarray) -> ResidualTest:
    from scipy import special

    limit = float(special.chdtri(dof, 1.0 - level))  # the chi-square quantile
    return ResidualTest(name, stat, limit, dof, int(outside.sum()), outside.size, stat <= limit)
