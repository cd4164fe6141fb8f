"""The time-domain methods of :class:`clpc.LinearModel` (a base class of it).

Each delegates to :mod:`clpc.model.simulation`, which runs the model through its public
conventions (monic ``denominators``, ``numerators``, ``intercept``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.model import simulation

__all__ = ["TimeDomain"]


class TimeDomain:
    """Free run, ``k``-step prediction and input inference of a model on data."""

    def simulate(
        self,
        u: Any,
        *,
        y_init: Any | None = None,
        u_init: Any | None = None,
        include_offset: bool = True,
    ) -> np.ndarray:
        """Free-run simulation from the input alone.

        Parameters
        ----------
        u : array_like, shape (T,) or (T, n_inputs), or IOData
            Input samples, or a record (its inputs; a record of several experiments is
            simulated one experiment at a time, each from zero initial conditions, and
            stacked).
        y_init : array_like, shape (na,) or (na, n_outputs), optional
            The ``na`` outputs just before ``u[0]``, oldest first. Default: zeros.
        u_init : array_like, shape (nk+nb,) or (nk+nb, n_inputs), optional
            The inputs just before ``u[0]``, oldest first. Default: zeros.
        include_offset : bool
            Add the identified constant ``c/a0`` (default). ``False`` simulates the
            deviation model ``lfilter(num, den, u)`` exactly.

        Returns
        -------
        ndarray, shape (T,) for a SISO model given 1-D ``u``, else (T, n_outputs)
            (a record's ``y`` shape).
        """
        return simulation.simulate(
            self, u, y_init=y_init, u_init=u_init, include_offset=include_offset
        )

    def predict(self, u: Any, y: Any = None, k: int = 1) -> np.ndarray:
        """``k``-step-ahead prediction ``y_hat(n | n-k)`` from measured data.

        Each prediction uses measured outputs up to ``n - k`` and the model for the rest
        (for ``k = 1`` the one-step-ahead predictor of the equation). An output-error
        model (``info["noise_model"] == "output-error"``, :class:`clpc.OE`; per output
        for a list) assumes white noise on the output: its ``k``-step predictor is the free
        run from the input for every ``k``, started from the measured samples before
        ``max_lag`` (:func:`clpc.model.simulation.noise_models`). The first
        ``max_lag`` samples have no complete past and are returned as measured; the next
        ``k - 1`` can only use the measured start of the record, so they are predictions
        over fewer than ``k`` steps (:func:`clpc.kstep_fit` skips them).

        Parameters
        ----------
        u : array_like, shape (T,) or (T, n_inputs), or IOData
            Measured inputs, or a record (its inputs and outputs; then leave ``y`` out and
            give ``k`` by keyword: ``predict(data, k=10)``). A record of several experiments
            is predicted one experiment at a time, and stacked.
        y : array_like, shape (T,) or (T, n_outputs)
            Measured outputs (required with array inputs).
        k : int
            Prediction horizon in samples (>= 1).

        Returns
        -------
        ndarray, same shape as ``y`` (a record's ``y`` shape)
        """
        return simulation.predict(self, u, y, k)

    def infer_input(
        self, y: Any, *, y_init: Any | None = None, allow_unstable: bool = False
    ) -> np.ndarray:
        """The input that explains a measured output (SISO): ``u = (den y - intercept) / num``.

        This is the paper's estimated torque command (Figs. 13-14).

        Parameters
        ----------
        y : array_like, shape (T,), or IOData
            Measured output, or a record of one experiment (its output).
        y_init : array_like, shape (na,), optional
            Outputs before ``y[0]`` (oldest first). Default: ``y[0]`` repeated (rest).
        allow_unstable : bool
            Compute even when ``num(z)`` has zeros outside the unit circle (the inverse
            then diverges); default raises :class:`ModelError`.

        Returns
        -------
        ndarray, shape (T - nk,)
            ``u_hat[m]`` estimates ``u[m]`` for ``m = 0 .. T-nk-1`` (zero initial state of
            the inverse filter).
        """
        return simulation.infer_input(self, y, y_init=y_init, allow_unstable=allow_unstable)
