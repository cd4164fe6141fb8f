"""What a trace concludes: the held parameters, when they settled, the model they settle on.

:class:`TraceVerdict` is a base class of :class:`~clpc.appraiser.trace.Trace`: its methods
read the trace's public arrays (``index``, ``arrays``) and delegate the verdict to
:mod:`clpc.appraiser.convergence`.
"""

from __future__ import annotations

import numpy as np

from clpc.appraiser import convergence
from clpc.appraiser.convergence import Convergence
from clpc.appraiser.convergence import steady_state_model as steady_state
from clpc.model import LinearModel

__all__ = ["TraceVerdict"]


class TraceVerdict:
    """The held parameters, the convergence and the steady-state model of a trace."""

    index: np.ndarray
    arrays: dict[str, np.ndarray]

    def held(self, n_samples: int) -> np.ndarray:
        """Held output parameters at every sample ``k = 0 .. n_samples - 1``.

        Parameters
        ----------
        n_samples : int
            Samples of the (decimated) record.

        Returns
        -------
        ndarray, shape (n_samples, n_equations, p)
            Zeros before the first update (no model yet).
        """
        k = np.arange(n_samples)
        last = np.searchsorted(self.index, k, side="right") - 1
        theta = self.arrays["theta"]
        out = np.zeros((n_samples, *theta.shape[1:]))
        ok = last >= 0
        out[ok] = theta[last[ok]]
        return out

    def convergence(
        self, theta_tol: float = 0.02, D_tol: float = 0.1, consecutive: int = 5
    ) -> Convergence:
        """First update after which ``theta`` and ``D`` stay quasi-constant.

        ``consecutive`` updates in a row within the tolerances below, and at least
        :data:`~clpc.appraiser.convergence.MIN_TRUSTED_FRACTION` of the windows trusted
        (:func:`clpc.appraiser.convergence.convergence`).

        Parameters
        ----------
        theta_tol : float
            Largest move of ``theta`` between updates (Euclidean, unit vectors).
        D_tol : float
            Largest relative move of ``D`` between updates.
        consecutive : int
            Quasi-constant updates in a row that make convergence.
        """
        return convergence.convergence(self, theta_tol, D_tol, consecutive)

    def steady_state_model(
        self, convergence: Convergence | None = None, *, allow_unconverged: bool = False
    ) -> LinearModel:
        """The identified black box: the mean accepted ``theta`` of the quasi-constant phase.

        Parameters
        ----------
        convergence : Convergence, optional
            Default: :meth:`convergence` with its default tolerances.
        allow_unconverged : bool
            If the trace never converged, use the last accepted update instead of raising.

        Returns
        -------
        LinearModel
            With ``info["convergence"]``.
        """
        return steady_state(self, convergence, allow_unconverged=allow_unconverged)
