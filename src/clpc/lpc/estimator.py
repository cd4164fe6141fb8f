"""The LPC estimator (paper sections II-IV): one solve over a whole record.

>>> import numpy as np, clpc
>>> rng = np.random.default_rng(0)
>>> u = rng.standard_normal(2000)
>>> y = clpc.simulate_arx([1, -0.5], [0, 1.0], u)            # y(n) = 0.5 y(n-1) + u(n-1)
>>> model = clpc.LPC(order=1).fit(u, y, dt=0.01)
>>> np.round(model.den, 6).tolist(), np.round(model.num, 6).tolist()
([1.0, -0.5], [0.0, 1.0])
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.data import DataError, IOData
from clpc.data.samples import check_spread
from clpc.lpc.fit_info import fit_info
from clpc.lpc.jackknife import jackknife_entries
from clpc.lpc.problem import FitProblem
from clpc.lpc.reduction import reduce_model
from clpc.lpc.regressors import MimoMode, Structure
from clpc.lpc.scatter import lpc_solve, r_factor, structure_blocks
from clpc.lpc.solve import RobustRule, SolveResult, noise_covariance
from clpc.model import LinearModel

__all__ = ["LPC", "fit_info", "lpc_solve", "r_factor", "structure_blocks"]


@dataclass
class LPC:
    """Last Principal Component estimator (paper sections II-IV).

    Parameters
    ----------
    order : int
        The paper's ``N`` (its ``parameters_size`` is ``N + 1``): ``na = nb = order``. Default 2.
    na, nb : int, optional
        Separate output / input orders (override ``order``): ``A`` has ``na + 1``
        coefficients ``a0..a_na`` and each ``B`` has ``nb + 1``, ``b0..b_nb`` applied to
        ``u(n - nk) .. u(n - nk - nb)``. MATLAB's ``arx([na nb nk])`` counts the ``b``
        coefficients instead: its ``nb`` is clpc's ``nb + 1`` (MATLAB ``[2 2 1]`` is
        clpc ``na=2, nb=1, nk=1``).
    nk : int
        Input delay in samples (default 0: ``b0`` present, as in the paper; a physical plant
        with no direct feed-through has ``nk >= 1``, as in MATLAB).
    method : {"robust", "paper"}
        ``"paper"``: the literal smallest eigenvector of the solved problem (the scatter
        matrix itself with the default ``scaling="none"``).
        ``"robust"`` (default): the excitation-aware nongeneric TLS solution - relations
        that do not involve ``y(n)`` (judged unit-free) are set aside and the minimum-norm
        ``a0 = 1`` vector of the near-null subspace is taken (:mod:`clpc.core.rules`).
    scaling : {"none", "std"}
        ``"none"`` (default): solve in the data's units - total least squares, consistent
        under errors-in-variables with equal noise variances on every lag entry.
        ``"std"``: divide each channel by its standard deviation first - unit-free, but
        consistent only when all channels have the same signal-to-noise ratio. For a known
        noise model use ``noise_ratio``/``noise_cov``; for exact inputs with noise on the
        output only, least squares (:class:`clpc.ARX`) is the right estimator.
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure; default ``"siso"`` for 1x1 data, else ``"miso"``.
        ``"paired"`` is the paper's eqs. 35-38 (output j on input j only).
    noise_ratio : float, optional
        Known ratio ``var(input noise) / var(output noise)`` (weighted LPC).
    noise_cov : array_like, shape (p,) or (p, p), optional
        Known noise covariance of the lag vector (weighted LPC; overrides
        ``noise_ratio``).
    rule : RobustRule, optional
        Thresholds of the robust solution.
    cancel : bool
        Remove pole/zero pairs closer than 0.02 (default ``True``): at an order above the
        system's, TLS puts the extra common factor near the unit circle. The model then
        has the reduced structure and ``info["cancelled"]`` counts the removed factors
        (:mod:`clpc.lpc.reduction`).
    uncertainty : bool
        Offer the parameter covariance of a block jackknife over the record
        (:func:`clpc.lpc.uncertainty.lpc_jackknife`; default ``True``), computed when
        first read (``info["covariance"]``, :meth:`LinearModel.confidence_interval`,
        :meth:`LinearModel.summary`; :mod:`clpc.model.evidence`).
    assess : bool
        Offer the evidence the verdict cites (default ``True``;
        :func:`clpc.lpc.assessment.evidence`), computed when first read
        (``info["heldout"]``, ``info["residual_test"]``, :meth:`LinearModel.assess`): the
        fit of a refit on the first two thirds scored on the last third, and the residual
        tests.

    Notes
    -----
    Constructor arguments are only stored; they are checked by :meth:`fit`.
    """

    order: int = 2
    na: int | None = None
    nb: int | None = None
    nk: int = 0
    method: str = "robust"
    scaling: str = "none"
    mimo: MimoMode | None = None
    noise_ratio: float | None = None
    noise_cov: Any = None
    rule: RobustRule | None = None
    cancel: bool = True
    uncertainty: bool = True
    assess: bool = True

    def structure(self) -> Structure:
        """The :class:`Structure` these settings describe."""
        return Structure.from_settings(self.order, self.na, self.nb, self.nk)

    def fit(self, u: Any, y: Any | None = None, dt: float | None = None) -> LinearModel:
        """Identify the model from a record.

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
            With ``info`` holding the statistics of :func:`fit_info` per output.

        Raises
        ------
        DataError
            Invalid data, too few samples, or a record in which nothing varies.
        """
        problem = FitProblem.prepare(self, (u, y, dt), "An LPC fit")
        data, structure, n_blocks = problem.data, problem.structure, problem.n_blocks
        if self.noise_cov is None and self.noise_ratio is None:
            check_spread(data.u, data.y, self.scaling)
        mats = problem.regressors()
        rule = self.rule or RobustRule()
        res = lpc_solve(
            mats,
            n_output_cols=structure.na + 1,
            blocks=structure_blocks(structure, n_blocks),
            method=self.method,
            noise_cov=noise_covariance(self.noise_cov, self.noise_ratio, structure, n_blocks),
            rule=rule,
            scaling=self.scaling,
        )
        _raise_if_degenerate(res, data)
        info = fit_info(res, np.full(mats.shape[0], mats.shape[1]), rule)
        info["method"] = self.method
        info["scaling"] = (
            self.scaling if self.noise_cov is None and self.noise_ratio is None else "noise"
        )
        covariance = None
        if self.uncertainty:
            settings = {
                "method": self.method,
                "scaling": self.scaling,
                "noise_cov": self.noise_cov,
                "noise_ratio": self.noise_ratio,
            }
            covariance = lambda fitted: jackknife_entries(fitted, data, rule, **settings)  # noqa: E731
        model = problem.model(self, res.theta, res.c, info, covariance)
        return reduce_model(model, data) if self.cancel else model


def _raise_if_degenerate(res: SolveResult, data: IOData) -> None:
    if not np.any(res.degenerate):
        return
    j = int(np.argmax(res.degenerate))
    const = [n for n, col in zip(data.input_names, data.u.T, strict=False) if np.ptp(col) == 0]
    const += [n for n, col in zip(data.output_names, data.y.T, strict=False) if np.ptp(col) == 0]
    what = f"constant channel(s) {const}" if const else "no variation in the lag vectors"
    raise DataError(
        f"nothing to identify for output {j}: {what}. LPC needs inputs and outputs that "
        "vary over the record."
    )
