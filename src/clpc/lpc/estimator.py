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
from scipy.linalg import lapack

from clpc.core import rules
from clpc.data import DataError, IOData
from clpc.data.samples import check_spread
from clpc.lpc.problem import FitProblem
from clpc.lpc.reduction import reduce_model
from clpc.lpc.regressors import MimoMode, Structure, regressors
from clpc.lpc.solve import RobustRule, SolveResult, noise_covariance, solve_scatter
from clpc.lpc.uncertainty import covariance_entries, jackknife_blocks, lpc_jackknife, monic_map
from clpc.model import LinearModel, ModelError
from clpc.model.structure import input_blocks

__all__ = ["LPC", "fit_info", "lpc_solve", "r_factor", "structure_blocks"]


def structure_blocks(structure: Structure, n_input_blocks: int) -> list[slice]:
    """Column slices of one lag vector: the output block, then one block per input."""
    na1, nb1 = structure.na + 1, structure.nb + 1
    return [slice(0, na1)] + [
        slice(na1 + i * nb1, na1 + (i + 1) * nb1) for i in range(n_input_blocks)
    ]


def lpc_solve(
    matrices: np.ndarray,
    *,
    n_output_cols: int,
    blocks: list[slice],
    method: str = "robust",
    noise_cov: np.ndarray | None = None,
    rule: RobustRule | None = None,
    scaling: str = "none",
) -> SolveResult:
    """LPC of one or more lag matrices (rows are lag vectors ``z_n``).

    Parameters
    ----------
    matrices : ndarray, shape (k, n_rows, p)
        Lag matrices (paper eq. 36), e.g. from :func:`clpc.lpc.regressors.regressors`.
    n_output_cols, blocks, method, noise_cov, rule, scaling
        See :func:`clpc.lpc.solve.solve_scatter`.

    Returns
    -------
    SolveResult
        The centering (eqs. 24-25) is two-pass and the decomposition is the SVD of the
        centered data (through its QR factor, :func:`r_factor`), so large offsets (e.g.
        positions around 1e4 rad) lose no digits.
    """
    mats = np.asarray(matrices, dtype=np.float64)
    k, n, p = mats.shape
    mean = mats.mean(axis=1)
    scatter = np.empty((k, p, p))
    factors = np.empty((k, p, p)) if n >= p else None  # the SVD needs n >= p
    for i in range(k):
        centered = np.subtract(mats[i], mean[i], order="F")  # eq. 25, two-pass (a copy)
        scatter[i] = centered.T @ centered  # eq. 27
        if factors is not None:
            factors[i] = r_factor(centered)
    return solve_scatter(
        scatter,
        mean,
        np.full(k, n),
        n_output_cols=n_output_cols,
        blocks=blocks,
        method=method,
        noise_cov=noise_cov,
        rule=rule,
        data=factors,
        scaling=scaling,
    )


def r_factor(centered: np.ndarray) -> np.ndarray:
    """``R`` of ``M = Q R`` (Householder QR): ``M``'s singular values and right vectors.

    Parameters
    ----------
    centered : ndarray, shape (n, p), n >= p, Fortran order
        Centered lag matrix; overwritten (LAPACK ``dgeqrf`` in place).

    Returns
    -------
    ndarray, shape (p, p)
        Upper triangular; ``R^T R = M^T M`` and ``svd(R)`` gives ``svd(M)``'s ``s`` and
        ``V`` (backward stable like the SVD of ``M``, in O(n p^2) time with no n x p
        ``U``: 6x less time than ``numpy.linalg.svd(M, full_matrices=False)`` at 1e6 rows).
    """
    packed, _, _, info = lapack.dgeqrf(centered, overwrite_a=True)
    if info != 0:  # pragma: no cover - LAPACK argument errors only
        raise np.linalg.LinAlgError(f"QR of the lag matrix failed (LAPACK info {info}).")
    p = centered.shape[1]
    return np.triu(packed[:p])


def fit_info(res: SolveResult, n_rows: np.ndarray, rule: RobustRule) -> dict[str, Any]:
    """Statistics of a solve as plain arrays (one entry per equation).

    Keys: ``eigenvalues``, ``lambda_min``, ``lambda_max``, ``D`` (``lambda_max -
    lambda_min``, the paper's degree of linearity), ``eig_ratio`` (``lambda_min /
    lambda_max``, scale-free), ``separation``, ``a0_weight`` (the unit-free ``y(n)``
    weight of the solution), ``c``, ``noise_variance``,
    ``log_likelihood``, ``J`` (eq. 22), ``n_rows``, ``n_null``, ``n_input_relations``,
    ``degenerate``, ``determined``. Each number comes from :mod:`clpc.core.rules`, the
    functions the CLPC kernel compiles.
    """
    vals = res.eigenvalues
    n = np.asarray(n_rows, dtype=np.float64) * np.ones(vals.shape[0])
    lam_min, lam_max = vals[:, 0].copy(), vals[:, -1].copy()
    ll_var = [
        rules.likelihood_variance(float(v), float(hi), float(m))
        for v, hi, m in zip(res.noise_variance, lam_max, n, strict=True)
    ]
    determined = [
        rules.is_determined(int(a), int(b), float(c), bool(d), rule.separation)
        for a, b, c, d in zip(
            res.n_null, res.n_input_relations, res.separation, res.degenerate, strict=True
        )
    ]
    return {
        "eigenvalues": vals,
        "lambda_min": lam_min,
        "lambda_max": lam_max,
        "D": lam_max - lam_min,
        "eig_ratio": np.array(
            [rules.eig_ratio(lo, hi) for lo, hi in zip(lam_min, lam_max, strict=True)]
        ),
        "separation": res.separation,
        "a0_weight": res.a0_weight,
        "c": res.c,
        "noise_variance": res.noise_variance,
        "log_likelihood": np.array(
            [rules.log_likelihood(v, m) for v, m in zip(ll_var, n, strict=True)]
        ),
        "J": np.array([rules.index_j(v, m) for v, m in zip(ll_var, n, strict=True)]),
        "n_rows": np.asarray(n_rows),
        "n_null": res.n_null,
        "n_input_relations": res.n_input_relations,
        "degenerate": res.degenerate,
        "determined": np.array(determined, dtype=bool),
    }


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
            covariance = lambda fitted: self._covariance_entries(fitted, data, rule)  # noqa: E731
        model = problem.model(self, res.theta, res.c, info, covariance)
        return reduce_model(model, data) if self.cancel else model

    def _covariance_entries(
        self, model: LinearModel, data: IOData, rule: RobustRule
    ) -> dict[str, Any]:
        """The block-jackknife covariance of this solve at ``model``'s structure (entries)."""
        s, mode = model.structure, model.mode
        n_blocks_in = input_blocks(mode, data.n_inputs)
        mats = regressors(data, s, mode)  # type: ignore[arg-type]
        groups = jackknife_blocks(mats.shape[1], mats.shape[2])
        if not groups:
            return {"covariance_note": f"{mats.shape[1]} lag vectors are too few to split"}
        try:
            noise_cov = noise_covariance(self.noise_cov, self.noise_ratio, s, n_blocks_in)
        except ValueError:
            return {"covariance_note": "the noise covariance does not fit the reduced order"}

        def solve(scatter: np.ndarray, mean: np.ndarray, rows: np.ndarray) -> np.ndarray:
            return solve_scatter(
                scatter, mean, rows, n_output_cols=s.na + 1,
                blocks=structure_blocks(s, n_blocks_in), method=self.method,
                noise_cov=noise_cov, rule=rule, scaling=self.scaling,
            ).theta  # fmt: skip

        def to_monic(theta: np.ndarray, j: int) -> np.ndarray:
            a0 = theta[:, :1]
            if np.any(np.abs(a0) <= 1e-9 * np.linalg.norm(theta, axis=1, keepdims=True)):
                raise ModelError("a jackknife replicate has a0 about 0 (no monic form)")
            return (theta[:, 1:] / a0) @ monic_map(s, model.n_inputs, mode, j).T

        try:
            cov = lpc_jackknife(mats, solve, to_monic, groups)
        except (ModelError, ValueError) as exc:  # no monic replicate; a noise_cov of p entries
            return {"covariance_note": f"the jackknife could not run: {exc}"}
        how = f"block jackknife over {groups} segments"
        if model.info.get("cancelled"):
            how += " (LPC solve at the reduced order)"
        return covariance_entries(cov, groups - 1, how)


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
