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
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from scipy import signal

from clpc.core.filters import frequency_response
from clpc.core.polynomials import monic, pole_class
from clpc.model import display, simulation
from clpc.model import uncertainty as _unc
from clpc.model.errors import ModelError
from clpc.model.evidence import FitInfo, FitRecord
from clpc.model.structure import Structure

__all__ = ["LinearModel", "ModelError"]


@dataclass(frozen=True, eq=False)
class LinearModel:
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
        """Pickle without the record: the entries computed so far, nothing pending.

        A pickled model does not carry its record (which would send the data along, e.g.
        to or from a Dask worker); call :meth:`assess` first to keep all the evidence.
        """
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

    # ----------------------------------------------------------------- conventions
    @property
    def n_outputs(self) -> int:
        """Number of outputs (equations)."""
        return int(self.theta_matrix.shape[0])

    @property
    def is_siso(self) -> bool:
        """One input and one output."""
        return self.n_outputs == 1 and self.n_inputs == 1

    def _a0(self) -> np.ndarray:
        theta = self.theta_matrix
        a0 = theta[:, 0]
        scale = np.linalg.norm(theta, axis=1)
        if np.any(np.abs(a0) <= 1e-12 * np.maximum(scale, 1e-300)):
            j = int(np.argmin(np.abs(a0)))
            raise ModelError(
                f"a0 of output {j} is about 0 (theta={theta[j].round(6).tolist()}): the "
                "data do not determine y(n), so the monic transfer function does not exist. "
                "Check the excitation or lower the order."
            )
        return a0

    def _monic(self) -> tuple[np.ndarray, np.ndarray]:
        """Both monic polynomials of every output (copies of :meth:`_monic_once`'s)."""
        den, num = self._monic_once
        return den.copy(), num.copy()

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
        return self._monic()[0]

    @property
    def numerators(self) -> np.ndarray:
        """``-B_ji(z)/a0`` with ``nk`` leading zeros: shape (n_out, n_in, nk+nb+1)."""
        return self._monic()[1]

    @property
    def intercept(self) -> np.ndarray:
        """Constant term ``c/a0`` of the monic equation, shape (n_outputs,)."""
        return self.c / self._a0()

    def _siso(self, what: str) -> None:
        if not self.is_siso:
            raise ModelError(
                f"{what} is defined for single-input single-output models; this model has "
                f"{self.n_inputs} input(s) and {self.n_outputs} output(s). "
                "Use numerators/denominators or to_control()."
            )

    @property
    def num(self) -> np.ndarray:
        """SISO numerator ``-B(z)/a0``, ascending powers of ``z^-1``, shape (nk+nb+1,)."""
        self._siso("num")
        return self.numerators[0, 0]

    @property
    def den(self) -> np.ndarray:
        """SISO monic denominator ``A(z)/a0``, ascending powers of ``z^-1``, shape (na+1,)."""
        self._siso("den")
        return self.denominators[0]

    # ----------------------------------------------------------------- analysis
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

    # ------------------------------------------- uncertainty (clpc.model.uncertainty)
    @property
    def covariance(self) -> np.ndarray:
        """Covariance of ``np.r_[den[1:], num]`` per output, shape (n_outputs, q, q)."""
        return _unc.covariance(self)

    def confidence_interval(self, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
        """``(lo, hi)`` ordered like ``np.r_[den[1:], num]`` (rows per output if several).

        Parameters
        ----------
        level : float
            Two-sided confidence level in (0, 1) (default 0.95; Student's ``t`` quantile).

        Returns
        -------
        lo, hi : ndarray, shape (q,) for a SISO model, else (n_outputs, q)
            See :func:`clpc.model.uncertainty.confidence_interval`.
        """
        return _unc.confidence_interval(self, level)

    def pole_std(self, output: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Poles and the std of their real and imaginary parts, shape (na, 2).

        Parameters
        ----------
        output : int
            Output index (default 0).

        Returns
        -------
        poles : ndarray of complex, shape (na,)
        std : ndarray, shape (na, 2)
            Standard deviation of ``(Re p, Im p)`` per pole (delta method).
        """
        return _unc.pole_std(self, output)

    def dc_gain_std(self) -> np.ndarray:
        """Standard deviation of :meth:`dc_gain`, shape (n_outputs, n_inputs)."""
        return _unc.dc_gain_std(self)

    def frequency_response_std(
        self, freqs: np.ndarray | int = 512, output: int = 0, input: int = 0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(freqs_hz, response, std of |G|, std of arg G [rad])`` (delta method).

        Parameters
        ----------
        freqs : int or ndarray
            Number of frequencies up to Nyquist, or frequencies [Hz] (default 512).
        output, input : int
            Channel pair (default 0, 0).

        Returns
        -------
        freqs_hz : ndarray, shape (n_freqs,)
            Frequencies [Hz].
        response : ndarray of complex, shape (n_freqs,)
        magnitude_std : ndarray, shape (n_freqs,)
            Standard deviation of ``|G|`` (same units as ``|G|``).
        phase_std : ndarray, shape (n_freqs,)
            Standard deviation of ``arg G`` [rad].
        """
        return _unc.frequency_response_std(self, freqs, output, input)

    def summary(self) -> str:
        """Coefficients with +- one standard deviation, poles and DC gains, as text."""
        return _unc.summary(self)

    # ----------------------------------------------------------------- time domain
    def _forced(self, u: np.ndarray, u_init: np.ndarray | None) -> np.ndarray:
        """``x_j(n) = sum_i num_ji * u_i + intercept_j``, shape (T, n_out)."""
        return simulation.forced(self, u, u_init)

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

    def _padded(self, output: int, input: int) -> tuple[np.ndarray, np.ndarray]:
        """Numerator and denominator in descending powers of ``z`` (equal length)."""
        num = self.numerators[output, input]
        den = self.denominators[output]
        n = max(num.size, den.size)
        return np.pad(num, (0, n - num.size)), np.pad(den, (0, n - den.size))

    def to_scipy(self, output: int = 0, input: int = 0) -> signal.dlti:
        """Export one channel pair as :class:`scipy.signal.dlti` (``dt`` = sample time).

        Parameters
        ----------
        output, input : int
            Channel pair (default 0, 0).

        Returns
        -------
        scipy.signal.dlti
            ``num / den`` in descending powers of ``z``; the constant ``intercept`` is not
            exported.
        """
        num, den = self._padded(output, input)
        # leading zeros (input delay nk) are zero high-power coefficients: dropping them keeps
        # G(z) and spares scipy's "badly conditioned numerator" warning
        num = np.trim_zeros(num, "f") if np.any(num) else num[-1:]
        from scipy import signal  # imported when used: scipy.signal costs ~0.8 s

        return signal.dlti(num, den, dt=self.dt)

    def to_control(self, *, include_offset: bool = False) -> Any:
        """Export as a python-control ``StateSpace`` system with the channel names.

        Each output equation is realised in observer canonical form (its inputs share the
        denominator ``A_j``; ``n = max(na, nk + nb)`` states), the outputs stacked block by
        block. A state-space system simulates without slycot (a MIMO transfer function
        does not); ``control.ss2tf`` gives the transfer function of a SISO export.

        Parameters
        ----------
        include_offset : bool
            ``False`` (default): the system from the inputs alone, ``G = num/den`` per
            channel (the deviation model, like ``simulate(..., include_offset=False)``), so
            ``control.dcgain`` and ``control.step_response`` are ``n_outputs x n_inputs``
            and equal :meth:`dc_gain` and the model's step. ``True`` adds an input named
            ``"offset"`` (last) through which the constant ``intercept_j`` enters output
            ``j`` as ``intercept_j / A_j(z)``: driven with ones, ``control.forced_response``
            equals :meth:`simulate` (zero initial conditions, offset included).

        Returns
        -------
        control.StateSpace
            Inputs named after :attr:`input_names` (and ``"offset"``), outputs after
            :attr:`output_names`, ``dt`` the sample time [s]. Needs the optional
            dependency ``control`` (``pip install ".[control]"`` from the source tree).
        """
        try:
            import control
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError(
                "to_control() needs python-control: pip install control (or, in the clpc "
                "source tree, pip install '.[control]')"
            ) from None
        blocks = []
        for j in range(self.n_outputs):
            pairs = [self._padded(j, i) for i in range(self.n_inputs)]
            if include_offset:
                den = pairs[0][1]
                pairs.append((np.r_[self.intercept[j], np.zeros(den.size - 1)], den))
            blocks.append(simulation.observer_form([p[0] for p in pairs], pairs[0][1]))
        n_in = self.n_inputs + int(include_offset)
        sizes = [blk[0].shape[0] for blk in blocks]
        a = np.zeros((sum(sizes), sum(sizes)))
        b = np.zeros((sum(sizes), n_in))
        c = np.zeros((self.n_outputs, sum(sizes)))
        d = np.zeros((self.n_outputs, n_in))
        at = 0
        for j, (aj, bj, cj, dj) in enumerate(blocks):
            sl = slice(at, at + sizes[j])
            a[sl, sl], b[sl], c[j, sl], d[j] = aj, bj, cj, dj
            at += sizes[j]
        inputs = [*self.input_names, *(["offset"] if include_offset else [])]
        return control.ss(a, b, c, d, self.dt, inputs=inputs, outputs=list(self.output_names))

    def __repr__(self) -> str:
        return display.model_repr(self)

    def _repr_html_(self) -> str:
        """The model as an HTML table (Jupyter)."""
        return display.model_html(self)
