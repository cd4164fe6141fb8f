"""Residual analysis figure: autocorrelation and input cross-correlation with their bands."""

from __future__ import annotations

from os import PathLike
from typing import Any

import numpy as np

from clpc.core.figure import COLORS, new_figure, save_figure

__all__ = ["plot_residuals"]


def plot_residuals(
    analysis: Any, path: str | PathLike[str] | None = None, *, ax: Any = None
) -> Any:
    """Residual autocorrelation and input-residual cross-correlation with their bands.

    One row per output: the autocorrelation ``rho_e(k)``, ``k = 0..M``, then the
    cross-correlation with each input, ``tau = -M..M``; the shaded bands are the per-lag
    limits of :func:`clpc.residual_analysis` and each title gives the test's outcome.

    Parameters
    ----------
    analysis : ResidualAnalysis
        From :func:`clpc.residual_analysis`.
    path : str or path-like, optional
        Also write the figure as PNG here.
    ax : sequence of matplotlib Axes, optional
        ``n_outputs * (1 + n_inputs)`` axes (row-major) to draw on; default a new figure.

    Returns
    -------
    matplotlib.figure.Figure
        The figure the axes belong to.
    """
    n_out, n_in = analysis.cross_correlation.shape[:2]
    if ax is None:
        fig, axes = new_figure(n_out, 1 + n_in, height=2.6, width=max(8.0, 4.0 * (1 + n_in)))
        flat = list(axes.ravel())
    else:
        flat = list(np.ravel(np.asarray(ax, dtype=object)))
        if len(flat) != n_out * (1 + n_in):
            raise ValueError(
                f"plot_residuals needs {n_out * (1 + n_in)} axes (outputs x (1 + inputs)); "
                f"got {len(flat)}. Pass ax=None for a new figure."
            )
        fig = flat[0].get_figure()
    tests = list(analysis.independence)
    auto_color, cross_color = COLORS["residual"], COLORS["input"]
    for j in range(n_out):
        a = flat[j * (1 + n_in)]
        lags, band = analysis.lags, analysis.auto_band
        a.fill_between(lags, -band, band, color=auto_color, alpha=0.15, lw=0)
        a.vlines(lags[1:], 0, analysis.autocorrelation[j, 1:], color=auto_color, lw=1.5)
        a.axhline(0, color="0.5", lw=0.6)
        a.set_xlabel("lag k [samples]")
        a.set_ylabel("autocorrelation [-]")
        a.set_title(_test_title(analysis.whiteness[j]), fontsize="small")
        for i in range(n_in):
            b = flat[j * (1 + n_in) + 1 + i]
            tau = analysis.cross_lags
            bnd = analysis.cross_band[j, i]
            b.fill_between(tau, -bnd, bnd, color=cross_color, alpha=0.15, lw=0)
            b.vlines(tau, 0, analysis.cross_correlation[j, i], color=cross_color, lw=1.5)
            b.axhline(0, color="0.5", lw=0.6)
            b.set_xlabel("lag tau [samples] (u leads for tau > 0)")
            b.set_ylabel("cross-correlation [-]")
            b.set_title(_test_title(tests[j * n_in + i]), fontsize="small")
    save_figure(fig, path)
    return fig


def _test_title(test: Any) -> str:
    sym = "Q" if test.name.startswith("whiteness") else "zeta"
    rel = "<=" if test.passed else ">"
    outcome = "passed" if test.passed else "FAILED"
    return f"{test.name}\n{sym} = {test.statistic:.3g} {rel} {test.threshold:.3g}: {outcome}"
