"""The identified model: a linear difference equation in two conventions.

Paper convention (eqs. 17, 35): the unit-norm parameter vector ``theta = [a; b]`` with

    a0 y(n) + a1 y(n-1) + ... + a_na y(n-na) + b0 u(n-nk) + ... + b_nb u(n-nk-nb) = r(n),

``E[r] = c``. Moving the input to the right-hand side gives ``A(z) Y = -B(z) U + c``, so the
transfer function is ``G(z) = -B(z)/A(z)`` (the paper's eq. 34 drops this minus sign).

Engineering convention (monic, ascending powers of ``z^-1``, ready for
``scipy.signal.lfilter(num, den, u)``)::

    den = [1, a1/a0, ..., a_na/a0]
    num = [0]*nk + [-b0/a0, ..., -b_nb/a0]
    intercept = c/a0                      # y(n) + ... = num * u + intercept + e(n)

One output per equation; equation ``j`` has one numerator per input (``"paired"`` MIMO
models keep only input ``j``; the others are zero).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from clpc.core.filters import frequency_response
from clpc.core.polynomials import monic, pole_class
from clpc.model import display
from clpc.model.errors import ModelError, require_siso
from clpc.model.evidence import FitInfo, FitRecord
from clpc.model.export import Exports
from clpc.model.structure import Structure
from clpc.model.time_domain import TimeDomain
from clpc.model.uncertainty_methods import UncertaintyMethods

__all__ = ["LinearModel", "ModelError"]


@dataclass(frozen=True, eq=False)
class LinearModel(TimeDomain, UncertaintyMethods, Exports):
    """A (multi-)output linear model ``A_j(q) y_j = sum_i Bn_ji(q) u_i + k_j + e_j``.

    Parameters
    ----------
    theta : ndarray, shape (p,) for one output, else (n_outputs, p)
        Unit-norm parameter vectors, one per output (paper convention). A single-output
        model keeps ``theta`` 1-D (and its per-output ``info`` statistics scalar); the
        2-D form of every model is :attr:`theta_matrix`.
    structure : Structure
        Orders and delay.
    n_inputs : int
        Number of inputs.
    mode : {"siso", "paired", "miso"}
        How outputs relate to inputs.
    c : ndarray, shape (n_outputs,)
        Mean of the equation error ``r`` (eq. 24).
    dt : float
        Sample time [s].
    input_names, output_names : tuple of str
        Channel names.
    info : dict
        Fit statistics (eigenvalues, D, noise variance, J, verdict...) per output.
    record : FitRecord, optional
        The record the model was fitted on and how to compute its evidence (held-out fit,
        residual tests, jackknife covariance) on demand: then ``info`` is a
        :class:`clpc.model.evidence.FitInfo` that computes those entries when first read
        (:meth:`assess` computes them all). ``None`` for hand-built and loaded models.
    """

    theta: np.ndarray
    structure: Structure
    n_inputs: int
    mode: str
    c: np.ndarray
    dt: float = 1.0
    input_names: tuple[str, ...] = ("u",)
    output_names: tuple[str, ...] = ("y",)
    info: dict[str, Any] = field(default_factory=dict)
    record: FitRecord | None = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        theta = np.atleast_2d(np.asarray(self.theta, dtype=np.float64))
        object.__setattr__(self, "_theta2", theta)
        object.__setattr__(self, "theta", theta[0] if theta.shape[0] == 1 else theta)
        object.__setattr__(self, "c", np.atleast_1d(np.asarray(self.c, dtype=np.float64)))
        given = self.info
        if theta.shape[0] == 1:
            object.__setattr__(self, "info", display.squeeze_info(given))
        if self.record is not None:
            object.__setattr__(self, "info", FitInfo(self.info, self, self.record, given))

    def __getstate__(self) -> dict[str, Any]:
        """Pickle without the record (its data): :meth:`assess` first keeps all evidence."""
        state = dict(self.__dict__)
        state["record"] = None
        state["info"] = dict(self.info)
        return state

    def assess(self) -> LinearModel:
        """Compute every piece of evidence still pending (see :mod:`clpc.model.evidence`).

        Returns
        -------
        LinearModel
            ``self``, whose ``info`` then holds ``heldout``, ``residual_test`` and the
            covariance entries its estimator provides.
        """
        if isinstance(self.info, FitInfo):
            self.info.compute_all()
        return self

    @property
    def theta_matrix(self) -> np.ndarray:
        """``theta`` of every output as rows: shape (n_outputs, p), also for one output."""
        return self._theta2  # type: ignore[attr-defined]

    @property
    def n_outputs(self) -> int:
        """Number of outputs (equations)."""
        return int(self.theta_matrix.shape[0])

    @property
    def warmup(self) -> int:
        """Samples before the first full prediction: the largest lag (``structure.max_lag``)."""
        return int(self.structure.max_lag)

    @property
    def is_siso(self) -> bool:
        """One input and one output."""
        return self.n_outputs == 1 and self.n_inputs == 1

    def _a0(self) -> np.ndarray:
        theta = self.theta_matrix
        a0 = theta[:, 0]
        if np.any(np.abs(a0) <= 1e-12 * np.maximum(np.linalg.norm(theta, axis=1), 1e-300)):
            j = int(np.argmin(np.abs(a0)))
            raise ModelError(
                f"a0 of output {j} is about 0 (theta={theta[j].round(6).tolist()}): the "
                "data do not determine y(n), so the monic transfer function does not exist. "
                "Check the excitation or lower the order."
            )
        return a0

    @functools.cached_property
    def _monic_once(self) -> tuple[np.ndarray, np.ndarray]:
        """Both monic polynomials of every output (:func:`clpc.core.polynomials.monic`)."""
        self._a0()  # a0 must be nonzero
        s = self.structure
        den = np.empty((self.n_outputs, s.na + 1))
        num = np.empty((self.n_outputs, self.n_inputs, s.nk + s.nb + 1))
        for j in range(self.n_outputs):
            pair = j if self.mode == "paired" else -1
            monic(self.theta_matrix[j], s.na, s.nb, s.nk, pair, den[j], num[j])
        return den, num

    @property
    def denominators(self) -> np.ndarray:
        """Monic ``A_j(z)`` coefficients, ascending powers of ``z^-1``: shape (n_out, na+1)."""
        return self._monic_once[0].copy()

    @property
    def numerators(self) -> np.ndarray:
        """``-B_ji(z)/a0`` with ``nk`` leading zeros: shape (n_out, n_in, nk+nb+1)."""
        return self._monic_once[1].copy()

    @property
    def intercept(self) -> np.ndarray:
        """Constant term ``c/a0`` of the monic equation, shape (n_outputs,)."""
        return self.c / self._a0()

    @property
    def num(self) -> np.ndarray:
        """SISO numerator ``-B(z)/a0``, ascending powers of ``z^-1``, shape (nk+nb+1,)."""
        require_siso(self, "num")
        return self.numerators[0, 0]

    @property
    def den(self) -> np.ndarray:
        """SISO monic denominator ``A(z)/a0``, ascending powers of ``z^-1``, shape (na+1,)."""
        require_siso(self, "den")
        return self.denominators[0]

    def poles(self, output: int = 0) -> np.ndarray:
        """Poles (roots of ``z^na A(z)``) of output ``output``'s equation.

        Parameters
        ----------
        output : int
            Output index (default 0).

        Returns
        -------
        ndarray of complex, shape (na,)
        """
        return np.roots(self.denominators[output])

    def zeros(self, output: int = 0, input: int = 0) -> np.ndarray:
        """Finite zeros of ``G_{output,input}(z)`` (leading zero coefficients dropped).

        Parameters
        ----------
        output, input : int
            Channel pair (default 0, 0).

        Returns
        -------
        ndarray of complex
            Empty when the numerator has at most one coefficient after its leading zeros.
        """
        num = np.trim_zeros(self.numerators[output, input], "f")
        return np.roots(num) if num.size > 1 else np.array([])

    @property
    def is_stable(self) -> bool:
        """All poles strictly inside the unit circle."""
        return all(np.all(np.abs(self.poles(j)) < 1.0) for j in range(self.n_outputs))

    @property
    def stability(self) -> str:
        """``"stable"``, ``"integrating"`` (a pole at z = 1), ``"marginal"`` or ``"unstable"``.

        The worst over the outputs (:func:`clpc.core.polynomials.pole_class`); an integrator
        (voltage -> position) is ``"integrating"``, not ``"unstable"``.
        """
        order = ("stable", "marginal", "integrating", "unstable")
        kinds = [pole_class(self.poles(j)) for j in range(self.n_outputs)]
        return max(kinds, key=order.index)

    def dc_gain(self) -> np.ndarray:
        """Static gains ``G(1)``, shape (n_outputs, n_inputs).

        ``A(1) = 0`` (an integrator) gives ``+-inf`` (the sign of ``B(1)``), or 0 for a
        channel whose numerator is identically zero (e.g. the off-diagonal channels of a
        ``"paired"`` model); ``nan`` when ``B(1) = A(1) = 0`` (a cancelled pole at 1).
        """
        nums = self.numerators
        den_sum = np.broadcast_to(self.denominators.sum(axis=1)[:, None], nums.shape[:2])
        num_sum = nums.sum(axis=2)
        integ = np.abs(den_sum) < 1e-12
        gain = np.divide(num_sum, den_sum, out=np.full(num_sum.shape, np.nan), where=~integ)
        at_pole = np.where(num_sum != 0, np.copysign(np.inf, num_sum), np.nan)
        at_pole[~np.any(nums != 0, axis=2)] = 0.0
        return np.where(integ, at_pole, gain)

    def frequency_response(
        self, freqs: np.ndarray | int = 512, output: int = 0, input: int = 0
    ) -> tuple[np.ndarray, np.ndarray]:
        """Frequency response ``G(e^{j w dt})``.

        Parameters
        ----------
        freqs : int or ndarray
            Number of frequencies up to Nyquist, or frequencies [Hz].
        output, input : int
            Channel pair.

        Returns
        -------
        freqs_hz : ndarray, shape (n_freqs,)
            Frequencies [Hz] (per sample when ``dt = 1``).
        response : ndarray of complex, shape (n_freqs,)
        """
        return frequency_response(
            self.numerators[output, input], self.denominators[output], freqs, 1.0 / self.dt
        )

    def verdict(self, output: int = 0) -> Any:
        """Identifiability of the fit in plain words (:func:`clpc.model.verdict.fit_verdict`).

        Parameters
        ----------
        output : int
            Output index whose equation is judged (default 0).

        Returns
        -------
        Verdict
        """
        from clpc.model.verdict import fit_verdict

        return fit_verdict(self, output)

    def __repr__(self) -> str:
        return display.model_repr(self)

    def _repr_html_(self) -> str:
        """The model as an HTML table (Jupyter)."""
        return display.model_html(self)
