"""What every estimator shares: the preamble (record, structure, MIMO mode) and the tail.

LPC, least squares and output error differ in the solver only. Each ``fit`` starts with
:meth:`FitProblem.prepare` (the record validated once, the structure, the MIMO mode checked
against the channels, enough samples for the parameters) and ends with
:meth:`FitProblem.model` (the :class:`~clpc.model.LinearModel` with the record's names, its
covariance or why there is none, and the evidence offered on demand:
:func:`clpc.lpc.assessment.fit_record`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data import IOData, as_iodata
from clpc.lpc import assessment
from clpc.lpc.regressors import regressors
from clpc.lpc.uncertainty import covariance_entries
from clpc.model import LinearModel
from clpc.model.structure import MimoMode, Structure, check_mode, default_mode, input_blocks

__all__ = ["Covariance", "FitProblem"]


@dataclass(frozen=True)
class Covariance:
    """A fit's covariance of ``np.r_[den[1:], num]`` per output, or why it has none.

    Parameters
    ----------
    cov : ndarray, shape (n_outputs, q, q), optional
        The covariance (``None`` with ``note``).
    dof : ndarray, shape (n_outputs,), optional
        Degrees of freedom of its variance estimate.
    method : str
        How it was obtained, in words.
    note : str
        Why there is none (empty when there is one).
    """

    cov: np.ndarray | None = None
    dof: np.ndarray | None = None
    method: str = ""
    note: str = ""


@dataclass(frozen=True)
class FitProblem:
    """One fit's record, structure and MIMO mode, validated once.

    Parameters
    ----------
    data : IOData
        The record.
    structure : Structure
        Orders and delay.
    mode : {"siso", "paired", "miso"}
        How outputs relate to inputs (checked against the record's channels).
    """

    data: IOData
    structure: Structure
    mode: MimoMode

    @classmethod
    def prepare(
        cls,
        estimator: Any,
        args: tuple[Any, Any, float | None],
        what: str,
        extra_samples: int = 1,
    ) -> FitProblem:
        """The preamble of ``estimator.fit(u, y, dt)``.

        Parameters
        ----------
        estimator : LPC, ARX or OE
            Settings with ``structure()`` and ``mimo``.
        args : tuple
            ``(u, y, dt)`` as given to ``fit``.
        what : str
            The estimator's name for the error, e.g. ``"An LPC fit"``.
        extra_samples : int
            Samples needed beyond ``max_lag + p`` (``p`` parameters).

        Raises
        ------
        DataError
            Invalid data, a mode that does not fit the channels, or too few samples.
        """
        data = as_iodata(*args)
        structure = estimator.structure()
        mode = estimator.mimo or default_mode(data.n_inputs, data.n_outputs)
        check_mode(mode, data.n_inputs, data.n_outputs)
        problem = cls(data, structure, mode)
        p = problem.n_params
        data.require_samples(structure.max_lag + p + extra_samples, f"{what} with {p} parameters")
        return problem

    @property
    def n_blocks(self) -> int:
        """Input blocks of a lag vector (:func:`clpc.model.structure.input_blocks`)."""
        return input_blocks(self.mode, self.data.n_inputs)

    @property
    def n_params(self) -> int:
        """Entries of one lag vector, ``p = na + 1 + n_blocks (nb + 1)``."""
        return self.structure.n_params(self.n_blocks)

    def regressors(self) -> np.ndarray:
        """Lag matrices of every equation, shape (n_outputs, n_rows, p) (paper eq. 36)."""
        return regressors(self.data, self.structure, self.mode)

    def model(
        self,
        estimator: Any,
        theta: np.ndarray,
        c: np.ndarray,
        info: dict[str, Any],
        covariance: Covariance | Callable[[LinearModel], dict[str, Any]] | None = None,
    ) -> LinearModel:
        """The tail of every fit: the model, its covariance, its evidence on demand.

        Parameters
        ----------
        estimator : LPC, ARX or OE
            The settings (``assess``: offer the held-out refit and residual tests).
        theta : ndarray, shape (n_outputs, p)
            Unit-norm parameter vectors (paper convention).
        c : ndarray, shape (n_outputs,)
            Means of the equation errors.
        info : dict
            The solve's statistics.
        covariance : Covariance or callable, optional
            A covariance computed with the fit, or ``f(model) -> dict`` of its entries
            computed when first read (LPC's jackknife); ``None``: none offered.
        """
        data = self.data
        produce = None
        if callable(covariance):
            produce = covariance
        elif covariance is not None and covariance.cov is not None:
            info = {**info, **covariance_entries(covariance.cov, covariance.dof, covariance.method)}
        elif covariance is not None:
            info = {**info, "covariance_note": covariance.note}
        return LinearModel(
            theta=theta,
            structure=self.structure,
            n_inputs=data.n_inputs,
            mode=self.mode,
            c=c,
            dt=data.dt,
            input_names=data.input_names,
            output_names=data.output_names,
            info=info,
            record=assessment.fit_record(data, estimator, produce),
        )
