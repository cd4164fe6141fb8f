"""Output-error (OE) estimator: simulation-error least squares, stable by construction.

For each output ``j`` the model ``A(q) y_j = sum_i B_i(q) u_i + k`` (common monic ``A``, one
``B_i`` per input, ``nk`` leading zeros) is chosen to minimise the free-run simulation error

    sum_r sum_n (y_j(n) - y_hat_jr(n))^2,     n = first_r .. end_r - 1,

where each run ``y_hat_jr`` is simulated from the input alone, once over the whole record
and once more from each later start of up to four consecutive segments, every run started
from the measured outputs just before it (so a record that does not start at rest is fitted
exactly; why these runs: :mod:`clpc.lpc.simulation_error`, which holds the residual,
Jacobian and covariance). Least squares (:class:`clpc.ARX`) minimises the one-step equation
error instead; with white noise on the output only, that is biased and the simulation error
is not.

* **Stable by construction.** ``A`` is parametrised by its reflection coefficients
  ``kappa_m = MAX_KAPPA tanh(rho_m)`` (the Levinson step-up recursion): every ``rho`` gives a
  monic ``A`` with all roots strictly inside the unit circle, and every such ``A`` (with
  ``|kappa_m| < MAX_KAPPA``) has one ``rho``. An integrating process gets a pole just inside.
* **Two starts.** The search (``scipy.optimize.least_squares``, Levenberg-Marquardt) starts
  from the least-squares fit and from LPC (``cancel=False``, same structure); an unstable
  start is first made stable by reflecting its poles ``z -> 1/conj(z)``. The fit with the
  smaller simulation error is kept (``info["start"]``).
* **Analytic Jacobian.** ``d y_hat / d a_l = -y_hat(n-l) / A(q)``, ``d y_hat / d b_il =
  u_i(n-nk-l) / A(q)``, ``d y_hat / d k = 1 / A(q)``: one ``lfilter`` over all columns and
  runs of equal length, no loop over samples.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.lpc import oe_search
from clpc.lpc.arx import ARX
from clpc.lpc.estimator import LPC
from clpc.lpc.problem import Covariance, FitProblem
from clpc.lpc.regressors import MimoMode, Structure, lagged
from clpc.lpc.simulation_error import SEGMENTS, SimulationError
from clpc.lpc.uncertainty import monic_map
from clpc.model import LinearModel, ModelError

__all__ = ["OE"]


@dataclass
class OE:
    """Output-error estimator: minimise the free-run simulation error (stable models only).

    Parameters
    ----------
    order, na, nb, nk, mimo
        As for :class:`clpc.LPC` (same structure, same :class:`~clpc.model.LinearModel`).
    max_nfev : int
        Most residual evaluations per start (Levenberg-Marquardt).
    segments : int
        Most measured starts of the simulation error (default
        :data:`~clpc.lpc.simulation_error.SEGMENTS`; 1: one free run over the record). See
        :mod:`clpc.lpc.simulation_error` for why.
    full_run : bool
        The first run goes on over the whole record (default ``True``); ``False``: every
        segment is run on its own (multiple shooting), which lets a near-integrator that fits
        each segment drift over longer runs.
    cancel : bool
        Remove near pole/zero pairs after the fit (default ``True``): pairs common to every
        input's numerator and closer than :data:`~clpc.core.polynomials.CANCEL_DISTANCE`
        are cancelled, the search is run again at ``(na - m, nb - m)`` on the same runs, and
        the lower order is kept when its objective fit % is within
        :data:`~clpc.lpc.reduction.KEEP_FIT_POINTS` of the fitted order's (LPC's rule). It
        is written in the fitted structure, padded with zeros (a pole and a zero at
        ``z = 0``, an exact cancellation; their coefficients have zero variance).
        ``info["cancelled"]`` counts the factors removed per output. Why: a slow pair that
        nearly cancels is hardly driven by the input, but a free run started from measured
        outputs gives it an amplitude; fitted on the first 70 % of the dryer record at
        ``N = 4`` such a pair (a pole at 0.99999, its zero 1e-4 away) left a free run of
        -23.8 % on the rest of the record, where least squares fits 86.3 % (with the
        cancellation: 87.3 %).
    tolerance : float
        When the search stops: the cost's relative change, the step's relative size and the
        gradient below it (``scipy.optimize.least_squares``' ``ftol``, ``xtol`` and
        ``gtol``; ``0 < tolerance < 1``). The default, 1e-14, asks for the optimum to about
        machine precision; a fit that only feeds a comparison at a few per cent can stop
        earlier (``identify``'s errors-in-variables check uses 1e-10).
    starts : tuple of {"arx", "lpc"}
        The closed-form fits that start the search (default both).
    initial : LinearModel, optional
        An extra start (same structure and channels), tried beside ``starts``.
    uncertainty : bool
        Store the covariance of the monic parameters ``np.r_[den[1:], num]`` per output
        (default ``True``): ``s^2 (J^T J)^-1``, ``J`` the Jacobian of the simulation errors
        with respect to ``(a, b, k)`` at the optimum, ``s^2`` their sum of squares over
        ``N - P`` (:func:`clpc.lpc.uncertainty.covariance_from_jacobian`). Valid when the
        noise is white and on the output only (the output-error model); a rank-deficient
        Jacobian leaves ``info["covariance_note"]`` instead.
    assess : bool
        Store the held-out fit and residual tests (default ``True``; as :class:`clpc.LPC`;
        the residuals are the simulation errors).

    Notes
    -----
    The fit is local: it improves on the best of its starts and can stop in a local
    minimum. ``info`` holds per output ``start`` (which start won: ``"arx"``, ``"lpc"`` or
    ``"initial"``), ``cost`` (``sum of squared simulation errors of every run / 2``, at the
    fitted order),
    ``start_costs`` (the final cost from each start), ``nfev``, ``success`` and
    ``cancelled``;
    ``info["noise_model"] = "output-error"`` (white noise on the output: the model's
    ``k``-step predictor is its free run, :meth:`LinearModel.predict`).
    """

    order: int = 2
    na: int | None = None
    nb: int | None = None
    nk: int = 0
    mimo: MimoMode | None = None
    max_nfev: int = 200
    tolerance: float = 1e-14
    segments: int = SEGMENTS
    full_run: bool = True
    cancel: bool = True
    starts: tuple[str, ...] = ("arx", "lpc")
    initial: LinearModel | None = None
    uncertainty: bool = True
    assess: bool = True

    def structure(self) -> Structure:
        """The :class:`Structure` these settings describe."""
        return Structure.from_settings(self.order, self.na, self.nb, self.nk)

    def fit(self, u: Any, y: Any | None = None, dt: float | None = None) -> LinearModel:
        """Output-error fit; returns a stable :class:`LinearModel` (``theta`` unit norm).

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
            The record, or its inputs.
        y : array_like, shape (T,) or (T, n_outputs), optional
            Outputs (when ``u`` is not an :class:`IOData`).
        dt : float, optional
            Sample time [s].

        Returns
        -------
        LinearModel

        Raises
        ------
        DataError
            Invalid data or too few samples.
        """
        if not isinstance(self.max_nfev, int) or self.max_nfev < 1:
            raise ValueError(f"max_nfev must be an int >= 1; got {self.max_nfev!r}.")
        if not (isinstance(self.tolerance, float) and 0.0 < self.tolerance < 1.0):
            raise ValueError(
                f"tolerance must be a float in (0, 1), e.g. 1e-10; got {self.tolerance!r}."
            )
        if not isinstance(self.full_run, bool):
            raise ValueError(f"full_run must be True or False; got {self.full_run!r}.")
        if not isinstance(self.segments, int) or self.segments < 1:
            raise ValueError(f"segments must be an int >= 1; got {self.segments!r}.")
        unknown = set(self.starts) - {"arx", "lpc"}
        if unknown or not (self.starts or self.initial is not None):
            raise ValueError(
                f"starts must name 'arx' and/or 'lpc' (or pass initial=); got {self.starts!r}."
            )
        problem = FitProblem.prepare(self, (u, y, dt), "An OE fit", extra_samples=2)
        data, structure, mode = problem.data, problem.structure, problem.mode
        starts = self._starts(data, structure, mode)
        thetas, cs = [], []
        info: dict[str, Any] = {"method": "output-error", "noise_model": "output-error"}
        per_output: list[dict[str, Any]] = []
        covs: list[tuple[np.ndarray, int]] = []
        no_cov = ""
        for j in range(data.n_outputs):
            cols = range(data.n_inputs) if mode == "miso" else [j]
            prob = SimulationError(
                data.y[:, j],
                np.hstack(
                    [
                        lagged(data.u[:, i], structure.nb, structure.nk, structure.max_lag)
                        for i in cols
                    ]
                ),
                structure.na,
                structure.max_lag,
                self.segments,
                self.full_run,
            )
            fits = {}
            for name, model in starts.items():
                x0 = oe_search.start_vector(model, j, list(cols), structure)
                res = oe_search.search(prob, x0, (self.max_nfev, self.tolerance))
                if np.isfinite(res.cost):
                    fits[name] = res
            if not fits:
                raise DataError(
                    f"the output-error search diverged from every start for output {j}; "
                    "check the record (scaling, constant channels) or lower the order."
                )
            best = min(fits, key=lambda name: fits[name].cost)
            a, _, b, k = prob.split(fits[best].x)
            solved, x_opt, cancelled = prob, fits[best].x, 0
            if self.cancel:
                kept = oe_search.without_near_pairs(
                    prob, x_opt, data, list(cols), structure, (self.max_nfev, self.tolerance)
                )
                if kept is not None:
                    solved, x_opt, cancelled = kept
                    a, b, k = oe_search.padded(solved, x_opt, cancelled, len(cols))
            if self.uncertainty and not no_cov:
                try:
                    low = Structure(
                        structure.na - cancelled, structure.nb - cancelled, structure.nk
                    )
                    lmap = monic_map(low, data.n_inputs, mode, j)
                    cov_j, dof_j = solved.covariance(x_opt, lmap)
                    emb = oe_search.embedding(low, structure, data.n_inputs)
                    covs.append((emb @ cov_j @ emb.T, dof_j))
                except ValueError as exc:
                    no_cov = f"output {data.output_names[j]}: {exc}"
            theta = np.concatenate([a, -b])
            scale = np.linalg.norm(theta)
            thetas.append(theta / scale)
            cs.append(k / scale)
            per_output.append(
                {
                    "start": best,
                    "cost": float(fits[best].cost),
                    "start_costs": {n: float(r.cost) for n, r in fits.items()},
                    "nfev": int(fits[best].nfev),
                    "cancelled": cancelled,
                    "success": bool(fits[best].success),
                }
            )
        for key in ("start", "cost", "nfev", "success", "cancelled"):
            info[key] = np.array([row[key] for row in per_output])
        info["start_costs"] = [row["start_costs"] for row in per_output]
        covariance = None
        if no_cov:
            covariance = Covariance(note=no_cov)
        elif self.uncertainty:
            cov = np.stack([c for c, _ in covs])
            dof = np.array([d for _, d in covs])
            covariance = Covariance(cov, dof, "Jacobian of the simulation error")
        return problem.model(self, np.array(thetas), np.array(cs), info, covariance)

    def _starts(self, data: IOData, structure: Structure, mode: str) -> dict[str, LinearModel]:
        """The least-squares and LPC fits (and ``initial``) that start the search."""
        kw: dict[str, Any] = {
            "order": self.order,
            "na": self.na,
            "nb": self.nb,
            "nk": self.nk,
            "mimo": mode,
            "uncertainty": False,
            "assess": False,
        }
        starts: dict[str, LinearModel] = {}
        if "arx" in self.starts:
            starts["arx"] = ARX(**kw).fit(data)
        if "lpc" in self.starts:
            try:
                lpc = LPC(**kw, cancel=False).fit(data)
                lpc.denominators  # a0 must be nonzero  # noqa: B018
                starts["lpc"] = lpc
            except (ModelError, DataError):
                pass  # LPC found no relation with y(n) in it: the others start alone
        if self.initial is not None:
            init = self.initial
            if (
                init.structure != structure
                or init.n_inputs != data.n_inputs
                or (init.n_outputs != data.n_outputs)
            ):
                raise ValueError(
                    f"initial must have the structure {structure} and {data.n_inputs} "
                    f"input(s), {data.n_outputs} output(s); got {init!r}."
                )
            starts["initial"] = init
        return starts
