"""``clpc.MultiModel``: local linear models blended by validity functions of one variable.

>>> import numpy as np, clpc
>>> rng = np.random.default_rng(0)
>>> u = rng.standard_normal(3000)
>>> y = clpc.simulate_arx([1, -0.5], [0, 1.0], u)
>>> mm = clpc.MultiModel(order=1).fit(u, y, dt=0.01)   # a linear plant: one model suffices
>>> mm.n_models, round(float(clpc.fit_percent(y, mm.simulate(u))), 3)
(1, 100.0)

The one-step equation is ``y(n) = sum_i phi_i(psi(n)) yhat_i(n)``: each local model's
monic one-step output (:class:`clpc.LinearModel` conventions) weighted by its validity
(:mod:`clpc.multimodel.validity`) at the scheduling value ``psi(n)``
(:mod:`clpc.multimodel.schedule`). Fitting: :mod:`clpc.multimodel.fitting`; local models
and their stability guard: :mod:`clpc.multimodel.local`; saving: :mod:`clpc.multimodel.store`.
"""

from __future__ import annotations

import html
from typing import Any

import numpy as np

from clpc.core.compact import html_table, summarise
from clpc.data import as_iodata
from clpc.model import LinearModel
from clpc.model.structure import Structure
from clpc.multimodel.files import ModelFiles
from clpc.multimodel.fitting import Fitted, Windows, fit_all, own_windows, trace_windows
from clpc.multimodel.free_run import free_run
from clpc.multimodel.linearization import linearize
from clpc.multimodel.prediction import predict_measured
from clpc.multimodel.schedule import Schedule, parse_schedule
from clpc.multimodel.settings import check_settings
from clpc.multimodel.validity import validity

__all__ = ["MultiModel"]


class MultiModel(ModelFiles):
    """A multi-model of local LPC models (single output, one or more inputs).

    Parameters
    ----------
    order : int
        ``na = nb = order`` of every local model (default 2, the paper's ``N``).
    na, nb, nk : int, optional
        Separate orders and input delay.
    n_models : int, optional
        Number of local models; default chosen by held-out free-run fit.
    max_models : int
        Largest number tried by the automatic choice (default 8).
    schedule : {"y", "u"}, int or callable
        Scheduling variable (default ``"y"``: ``y(n-1)``), see :mod:`clpc.multimodel.schedule`.
    estimator : {"auto", "lpc", "ls"}
        Local estimator: validity-weighted LPC with the stability guard (an unstable local
        LPC model is refitted by weighted least squares and flagged), weighted least
        squares, or ``"auto"`` (default): both are scored on the held-out part and LPC is
        kept unless least squares free-runs better by more than ``tolerance``.
    window_size, cluster_size : int
        Windows whose operating points place the centres in :meth:`fit` (Table 1: 201, 12);
        :meth:`from_trace` uses the trace's own windows.
    holdout : float
        Share of the record held out to choose ``n_models`` (default 0.3).
    tolerance : float
        Points of held-out fit within which fewer models are preferred (default 0.5).
    method : {"robust", "paper"}
        LPC solution (see :class:`clpc.LPC`).
    """

    def __init__(
        self,
        order: int = 2,
        *,
        na: int | None = None,
        nb: int | None = None,
        nk: int = 0,
        n_models: int | None = None,
        max_models: int = 8,
        schedule: Any = "y",
        estimator: str = "auto",
        window_size: int = 201,
        cluster_size: int = 12,
        holdout: float = 0.3,
        tolerance: float = 0.5,
        method: str = "robust",
    ) -> None:
        self.structure = Structure.from_settings(order, na, nb, nk)
        self.settings: dict[str, Any] = check_settings(
            n_models=n_models,
            max_models=max_models,
            estimator=estimator,
            window_size=window_size,
            cluster_size=cluster_size,
            holdout=holdout,
            tolerance=tolerance,
            method=method,
        )
        self.schedule_spec = schedule
        self._fitted: Fitted | None = None
        self.n_inputs = 1
        self.dt = 1.0

    # ----------------------------------------------------------------- fitting
    def _schedule(self) -> Schedule:
        return parse_schedule(self.schedule_spec, self.structure, self.n_inputs)

    def _fit(self, u: Any, y: Any, dt: Any, windows: Windows | None) -> MultiModel:
        data = as_iodata(u, y, dt)
        if data.n_outputs != 1:
            raise ValueError(
                f"MultiModel fits one output; got {data.n_outputs}. Fit one per output."
            )
        self.n_inputs, self.dt = data.n_inputs, float(data.dt)
        sched = self._schedule()
        start = max(self.structure.max_lag, sched.lag)
        p = self.structure.n_params(self.n_inputs)
        data.require_samples(start + 10 * p, f"A multi-model with {p} parameters per model")
        if windows is None:
            s = self.settings
            windows = own_windows(start, data.n_samples, s["window_size"], s["cluster_size"])
        cfg = dict(self.settings, structure=self.structure, n_inputs=self.n_inputs, dt=self.dt)
        self._fitted = fit_all(data.u, data.y[:, 0], sched, windows, cfg)
        return self

    def fit(self, u: Any, y: Any | None = None, dt: float | None = None) -> MultiModel:
        """Fit centres, local models and (unless given) their number; returns ``self``.

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
        y : array_like, shape (T,)
        dt : float, optional
            Sample time [s].
        """
        return self._fit(u, y, dt, None)

    @classmethod
    def from_trace(cls, trace: Any, u: Any, y: Any, **settings: Any) -> MultiModel:
        """A multi-model whose centres come from a CLPC trace's windows (when they are local).

        The structure is the trace's; the windows are its trusted ones. Further keyword
        arguments (``settings``) are the other constructor arguments (not the orders).

        Parameters
        ----------
        trace : Trace
            A CLPC trace (:class:`clpc.Trace`) with at least one trusted window.
        u : array_like, shape (T,) or (T, n_inputs)
            Inputs of the record the trace was computed on.
        y : array_like, shape (T,)
            Its output; the sample time is the trace's.

        Returns
        -------
        MultiModel
            Fitted.
        """
        s = trace.structure
        mm = cls(na=s.na, nb=s.nb, nk=s.nk, **settings)
        windows = trace_windows(trace)
        return mm._fit(u, y, trace.sample_time, windows)

    # ----------------------------------------------------------------- views
    def _require(self) -> Fitted:
        if self._fitted is None:
            raise ValueError("the multi-model is not fitted: call fit() or from_trace() first.")
        return self._fitted

    @property
    def local_models(self) -> list[LinearModel]:
        """The local models (``info``: ``estimator``, ``replaced``, ``weight``)."""
        return list(self._require().local_models)

    @property
    def warmup(self) -> int:
        """Samples before the first full prediction: ``max(max_lag, the schedule's lag)``.

        :meth:`simulate` needs this many measured samples as initial conditions and
        :meth:`predict` returns them as measured.
        """
        return max(self.structure.max_lag, self._schedule().lag)

    @property
    def n_models(self) -> int:
        """Number of local models."""
        return len(self._require().local_models)

    @property
    def centres(self) -> np.ndarray:
        """Centres of the validity functions (scheduling-variable units), shape (M,)."""
        return self._require().centres.copy()

    @property
    def widths(self) -> np.ndarray:
        """Widths of the validity functions, shape (M,) (inf for a single model)."""
        return self._require().widths.copy()

    @property
    def diagnostics(self) -> dict[str, Any]:
        """How the model was built: centre source and why, selection table, replaced models."""
        return dict(self._require().diagnostics)

    def validity(self, psi: Any) -> np.ndarray:
        """Validities of every local model at ``psi``: shape ``psi.shape + (M,)``, rows sum to 1.

        Parameters
        ----------
        psi : float or array_like
            Values of the scheduling variable (its units, e.g. those of ``y``).

        Returns
        -------
        ndarray, shape ``psi.shape + (M,)``
            Normalised Gaussian validities.
        """
        f = self._require()
        return validity(psi, f.centres, f.widths)

    # ----------------------------------------------------------------- time domain
    def simulate(
        self, u: Any, *, y_init: Any | None = None, u_init: Any | None = None
    ) -> np.ndarray:
        """Free-run simulation from the input alone (compiled loop).

        Parameters
        ----------
        u : array_like, shape (T,) or (T, n_inputs), or IOData
            Input samples, or a record of one experiment (its inputs).
        y_init : array_like, optional
            Outputs before ``u[0]``, oldest first (at least ``na``; more are used only by a
            schedule on an older lag). Default zeros.
        u_init : array_like, optional
            Inputs before ``u[0]``, oldest first. Default zeros.

        Returns
        -------
        ndarray, shape (T,)
        """
        f, sched = self._require(), self._schedule()
        return free_run(f, sched, self.structure, self.n_inputs, u, y_init, u_init)

    def predict(self, u: Any, y: Any = None, k: int = 1) -> np.ndarray:
        """``k``-step-ahead prediction ``y_hat(n | n-k)`` from measured data (vectorised).

        The first ``max(max_lag, schedule lag)`` samples are returned as measured; each
        step feeds the previous step's predictions into the output lags and the schedule.

        Parameters
        ----------
        u : array_like, shape (T,) or (T, n_inputs), or IOData
            Input samples, or a record of one experiment (then leave ``y`` out and give
            ``k`` by keyword).
        y : array_like, shape (T,)
            Measured output (required with array inputs).
        k : int
            Prediction horizon in samples (>= 1, default 1).

        Returns
        -------
        ndarray, shape (T,)
        """
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ValueError(f"k must be an int >= 1; got {k!r}.")
        f, sched = self._require(), self._schedule()
        return predict_measured(f, sched, self.structure, self.n_inputs, u, y, k)

    def linearize(self, operating_point: float) -> LinearModel:
        """The frozen-validity local model at a scheduling value (a :class:`LinearModel`).

        Its monic coefficients are the validity-weighted means of the local models' at
        ``psi = operating_point`` (the scheduling variable held there; the derivative of
        the validities is left out).

        Parameters
        ----------
        operating_point : float
            Value of the scheduling variable (its units) to freeze the validities at.

        Returns
        -------
        LinearModel
            Single output, ``dt`` the multi-model's; ``info["operating_point"]`` records it.
        """
        return linearize(self._require(), self.structure, self.n_inputs, self.dt, operating_point)

    def __repr__(self) -> str:
        s = self.structure
        m = "unfitted" if self._fitted is None else f"n_models={self.n_models}"
        return f"MultiModel(na={s.na}, nb={s.nb}, nk={s.nk}, {m}, schedule={self.schedule_spec!r})"

    def _repr_html_(self) -> str:
        """The multi-model as an HTML table (Jupyter): its validity functions, its models."""
        rows = [("multi-model", html.escape(repr(self)))]
        if self._fitted is not None:
            rows += [(n, html.escape(summarise(getattr(self, n)))) for n in ("centres", "widths")]
            rows += [(f"model {i}", m._repr_html_()) for i, m in enumerate(self.local_models)]
        return html_table("MultiModel", rows)
