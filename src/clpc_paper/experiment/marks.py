"""What the per-cluster figures (Figs. 6-12) mark, computed once from the identification.

The convergence marker and the steady-state line come from ``ident.convergence`` and
``ident.model``: the :meth:`clpc.Trace.convergence` verdict and the
:meth:`~clpc.Trace.steady_state_model` that the report's claims read
(:func:`clpc_paper.experiment.statistics.parameter_statistics`), over the same trusted updates
(:func:`clpc.appraiser.usable`). Nothing here draws; :mod:`.figures` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from clpc.appraiser import usable
from clpc_paper.experiment.analysis import constant_windows
from clpc_paper.experiment.results import Identification
from clpc_paper.experiment.settings import TOLERANCES

__all__ = ["ParameterMarks", "WindowStates", "estimate_series", "parameter_marks", "window_states"]


@dataclass(frozen=True)
class ParameterMarks:
    """Convergence marker and steady state of one identification.

    Attributes
    ----------
    cluster : int or None
        1-based cluster where the quasi-constant phase starts (None: never).
    used : ndarray of bool, shape (n_updates,)
        Updates averaged into the steady state (trusted, accepted, from ``cluster`` on).
    steady : ndarray, shape (p,)
        Steady-state theta (the model's, unit norm).
    low, high : ndarray, shape (p,)
        Per entry, the smallest and largest theta of the ``used`` updates (the band the
        curve stays in after the marker, by construction).
    rule : str
        The convergence rule in words, with the tolerances that held.
    """

    cluster: int | None
    used: np.ndarray
    steady: np.ndarray
    low: np.ndarray
    high: np.ndarray
    rule: str


@dataclass(frozen=True)
class WindowStates:
    """Which windows the figures shade, per update (bool arrays, shape (n_updates,)).

    ``at_rest``: the window's command is exactly constant - not excited, undetermined.
    ``untrusted``: not at rest but not trusted by the appraiser (too few rows while the
    window fills, not excited above quantisation, or not determined).
    """

    at_rest: np.ndarray
    untrusted: np.ndarray


def estimate_series(ident: Identification, values: np.ndarray) -> np.ndarray:
    """``values`` per update with NaN (a gap) where the update holds no accepted estimate."""
    trace = ident.trace
    ok = np.asarray(trace.accepted & trace.has_model, dtype=bool)
    out = np.array(values, dtype=float, copy=True)
    out[~ok] = np.nan
    return out


def parameter_marks(ident: Identification) -> ParameterMarks:
    """The marker, steady state and band that Figs. 6-12 draw (see the module docstring)."""
    conv, trace = ident.convergence, ident.trace
    theta = np.asarray(trace.theta, dtype=float)
    steady = np.atleast_2d(ident.model.theta)[0]
    ok = usable(trace)
    if conv.converged:
        used = ok & (np.arange(len(trace)) >= conv.update)
        theta_tol, d_tol, consecutive = TOLERANCES[ident.level]
        strict = "" if ident.level == 0 else " (relaxed tolerances)"
        rule = (
            f"{consecutive} trusted updates in a row with |d theta| < {theta_tol:g} and "
            f"|dD|/D < {d_tol:.0%}{strict}"
        )
        cluster: int | None = int(conv.update) + 1
    else:
        used = np.zeros(len(trace), dtype=bool)
        if ok.any():
            used[np.flatnonzero(ok)[-1]] = True
        rule = "never quasi-constant under any tolerance: the last trusted update"
        cluster = None
    sel = theta[used] if used.any() else steady[None, :]
    return ParameterMarks(cluster, used, steady, sel.min(axis=0), sel.max(axis=0), rule)


def window_states(ident: Identification) -> WindowStates:
    """Windows at rest and other untrusted windows of an identification."""
    trace = ident.trace
    rest = constant_windows(trace, ident.u)
    untrusted = ~np.asarray(trace.trusted, dtype=bool) & ~rest
    return WindowStates(rest, untrusted)
