"""Parameter uncertainty of a fitted model: intervals, and the delta method for what follows.

The estimators store a covariance of the monic parameters of every output equation in the
model's ``info`` (:mod:`clpc.lpc.uncertainty` computes it: a block jackknife for LPC,
``sigma^2 (Phi^T Phi)^-1`` for least squares, ``sigma^2 (J^T J)^-1`` for a Jacobian):

* ``info["covariance"]``, shape (n_outputs, q, q), of the vector of output ``j``
  ``np.r_[denominators[j, 1:], numerators[j].ravel()]`` (``q = na + n_inputs (nk+nb+1)``;
  SISO: ``np.r_[den[1:], num]``). Structural zeros (the ``nk`` leading numerator zeros, the
  other inputs of a ``"paired"`` model) have zero variance.
* ``info["covariance_dof"]``, shape (n_outputs,): degrees of freedom of the variance
  estimate; intervals use Student's ``t`` quantile with them.
* ``info["covariance_method"]``: how it was obtained, in words.

Functions of the parameters (poles, DC gain, frequency response) get their standard
deviation by the delta method ``std g = sqrt(diag(J C J^T))``, with ``J`` the Jacobian of
``g`` by central differences, evaluated on a stack of perturbed parameter vectors at once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from clpc.model.dominant import companion_roots
from clpc.model.errors import ModelError
from clpc.model.simulation import noise_models

__all__ = [
    "confidence_interval",
    "covariance",
    "dc_gain_std",
    "delta_std",
    "frequency_response_std",
    "parameter_labels",
    "parameter_std",
    "parameter_vector",
    "pole_std",
    "summary",
]

#: Relative step of the central differences of the delta method.
DELTA_STEP = 1e-6


def parameter_vector(model: Any) -> np.ndarray:
    """The monic parameters per output, shape (n_outputs, q): ``np.r_[den[1:], num]`` rows."""
    nums = model.numerators
    return np.concatenate([model.denominators[:, 1:], nums.reshape(nums.shape[0], -1)], axis=1)


def covariance(model: Any) -> np.ndarray:
    """The stored covariance, shape (n_outputs, q, q) (see the module docstring).

    Raises
    ------
    ModelError
        The model has none (a hand-built, averaged or old loaded model, or a record too short
        for the jackknife; ``info["covariance_note"]`` then says why).
    """
    cov = model.info.get("covariance")
    if cov is None:
        why = model.info.get("covariance_note", "the model was not fitted by clpc's LPC/ARX")
        raise ModelError(
            f"this model has no parameter covariance ({why}). Fit it with clpc.LPC, "
            "clpc.ARX (or an estimator that stores info['covariance'])."
        )
    q = parameter_vector(model).shape[1]
    cov = np.asarray(cov, dtype=np.float64).reshape(model.n_outputs, q, q)
    if not np.all(np.isfinite(cov)):
        raise ModelError("the stored parameter covariance holds non-finite values.")
    return cov


def _dof(model: Any) -> np.ndarray:
    dof = np.atleast_1d(np.asarray(model.info.get("covariance_dof", np.inf), dtype=np.float64))
    return np.broadcast_to(dof, (model.n_outputs,))


def _quantile(level: float, dof: np.ndarray) -> np.ndarray:
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must be in (0, 1), e.g. 0.95; got {level!r}.")
    from scipy import special  # not scipy.stats, which costs 0.4 s to import

    tail = 0.5 + 0.5 * level  # Student's t quantile, the normal one for infinite dof
    student = special.stdtrit(np.maximum(dof, 1.0), tail)
    return np.where(np.isfinite(dof), student, special.ndtri(tail))


def _shape(model: Any, arr: np.ndarray) -> np.ndarray:
    return arr[0] if model.is_siso else arr


def _std(model: Any) -> np.ndarray:
    return np.sqrt(np.clip(np.diagonal(covariance(model), axis1=1, axis2=2), 0.0, None))


def parameter_std(model: Any) -> np.ndarray:
    """Standard deviations of the monic parameters: 1-D for a SISO model, else per output."""
    return _shape(model, _std(model))


def confidence_interval(model: Any, level: float = 0.95) -> tuple[np.ndarray, np.ndarray]:
    """``theta +- t_{dof}(1/2 + level/2) sigma`` (:meth:`LinearModel.confidence_interval`)."""
    half = _std(model) * _quantile(level, _dof(model))[:, None]
    theta = parameter_vector(model)
    return _shape(model, theta - half), _shape(model, theta + half)


def delta_std(
    fun: Callable[[np.ndarray], np.ndarray], theta: np.ndarray, cov: np.ndarray
) -> np.ndarray:
    """``sqrt(diag(J C J^T))`` of a real function by central differences.

    Parameters
    ----------
    fun : callable
        Maps a stack of parameter vectors, shape (k, q), to values, shape (k, m); called
        once on the ``2 q`` perturbed vectors.
    theta : ndarray, shape (q,)
        Nominal parameters.
    cov : ndarray, shape (q, q)
        Their covariance.

    Returns
    -------
    ndarray, shape (m,)
    """
    q = theta.size
    free = np.diagonal(cov) > 0  # structural zeros are not perturbed
    h = DELTA_STEP * np.maximum(np.abs(theta), 1.0)
    steps = np.diag(np.where(free, h, 0.0))
    values = fun(np.concatenate([theta + steps, theta - steps]))
    jac = (values[:q] - values[q:]) / np.where(free, 2.0 * h, 1.0)[:, None]  # (q, m)
    var = np.einsum("im,ij,jm->m", jac, cov, jac)
    return np.sqrt(np.clip(var, 0.0, None))


def _split(model: Any, stack: np.ndarray, output: int) -> tuple[np.ndarray, np.ndarray]:
    """Denominators (k, na+1) and numerators (k, n_in, nk+nb+1) of a stack of vectors."""
    na = model.structure.na
    den = np.concatenate([np.ones((stack.shape[0], 1)), stack[:, :na]], axis=1)
    return den, stack[:, na:].reshape(stack.shape[0], model.n_inputs, -1)


def _matched_poles(den: np.ndarray, nominal: np.ndarray) -> np.ndarray:
    """Roots of each row of ``den`` (companion eigenvalues), ordered like ``nominal``."""
    from scipy import optimize

    roots = companion_roots(den)
    out = np.empty_like(roots)
    for i, r in enumerate(roots):  # one small assignment per perturbation, not per sample
        _, col = optimize.linear_sum_assignment(np.abs(nominal[:, None] - r[None, :]))
        out[i] = r[col]
    return out


def pole_std(model: Any, output: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Poles of one output and the std of ``(Re p, Im p)``, :meth:`LinearModel.pole_std`.

    A double pole is not a differentiable function of the parameters: no meaningful std.
    """
    poles = model.poles(output)
    theta = parameter_vector(model)[output]

    def fun(stack: np.ndarray) -> np.ndarray:
        roots = _matched_poles(_split(model, stack, output)[0], poles)
        return np.concatenate([roots.real, roots.imag], axis=1)

    std = delta_std(fun, theta, covariance(model)[output])
    return poles, std.reshape(2, -1).T


def dc_gain_std(model: Any) -> np.ndarray:
    """Standard deviation of :meth:`LinearModel.dc_gain`, shape (n_outputs, n_inputs)."""
    cov = covariance(model)
    theta = parameter_vector(model)
    out = np.empty((model.n_outputs, model.n_inputs))
    for j in range(model.n_outputs):

        def fun(stack: np.ndarray, j: int = j) -> np.ndarray:
            den, num = _split(model, stack, j)
            with np.errstate(divide="ignore", invalid="ignore"):
                return num.sum(axis=2) / den.sum(axis=1)[:, None]

        out[j] = delta_std(fun, theta[j], cov[j])
    return out


def frequency_response_std(
    model: Any, freqs: np.ndarray | int = 512, output: int = 0, input: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Frequency response and the std of ``|G|`` and ``arg G`` [rad] (delta method).

    See :meth:`LinearModel.frequency_response_std`.
    """
    f, h = model.frequency_response(freqs, output, input)
    theta = parameter_vector(model)[output]
    w = 2.0 * np.pi * np.asarray(f) * model.dt
    zinv = np.exp(-1j * w)

    def fun(stack: np.ndarray) -> np.ndarray:
        den, num = _split(model, stack, output)
        powers_d = zinv[None, :] ** np.arange(den.shape[1])[:, None]
        powers_n = zinv[None, :] ** np.arange(num.shape[2])[:, None]
        g = (num[:, input, :] @ powers_n) / (den @ powers_d)
        return np.concatenate([np.abs(g), np.angle(g / h[None, :])], axis=1)

    std = delta_std(fun, theta, covariance(model)[output])
    return f, h, std[: f.size], std[f.size :]


def parameter_labels(model: Any) -> list[str]:
    """Names of the entries of a row of :func:`parameter_vector`: ``den1``, ``num0[u]``...

    The coefficients of ``G(z) = num(z)/den(z)`` (``a`` and ``b`` name the paper's
    ``theta``, see ``docs/method.md``).
    """
    labels = [f"den{k}" for k in range(1, model.structure.na + 1)]
    width = model.structure.nk + model.structure.nb + 1
    return labels + [f"num{k}[{name}]" for name in model.input_names for k in range(width)]


def _equation(model: Any) -> str:
    """The model's equation with its noise model (white ``e``)."""
    forms = {
        "equation-error": "den(z) y = num(z) u + e",
        "output-error": "y = num(z)/den(z) u + e",
    }
    kinds = noise_models(model)
    if len(set(kinds)) == 1:
        return forms[kinds[0]]
    return "; ".join(
        f"{name}: {forms[k]}" for name, k in zip(model.output_names, kinds, strict=True)
    )


def summary(model: Any) -> str:
    """The coefficients of every output with ``+- 1 sigma``, poles and DC gains, as text."""
    theta = parameter_vector(model)
    try:
        sigma = np.atleast_2d(parameter_std(model))
        gain_std: np.ndarray | None = dc_gain_std(model)
        how = (
            f"+- one standard deviation\n({model.info.get('covariance_method', 'stored')}, "
            f"{float(_dof(model)[0]):.4g} degrees of freedom)"
        )
    except ModelError as exc:
        sigma, gain_std, how = np.full(theta.shape, np.nan), None, str(exc)
    lines = [f"{model!r}", f"{_equation(model)}, monic den, coefficient k of z^-k; {how}"]
    gains = model.dc_gain()
    for j, name in enumerate(model.output_names):
        lines.append(f"output {name}:")
        for label, v, sd in zip(parameter_labels(model), theta[j], sigma[j], strict=True):
            unc = "" if not np.isfinite(sd) else f" +- {sd:.3g}"
            lines.append(f"  {label:<12} {v: .6g}{unc}")
        try:
            poles, pstd = pole_std(model, j) if gain_std is not None else (model.poles(j), None)
        except ModelError:
            poles, pstd = model.poles(j), None
        for i, p in enumerate(poles):
            unc = "" if pstd is None else f" (+- {pstd[i, 0]:.2g} re, +- {pstd[i, 1]:.2g} im)"
            lines.append(f"  pole {i + 1:<7} {p.real: .5g}{p.imag:+.5g}j  |p|={abs(p):.4g}{unc}")
        for i, inp in enumerate(model.input_names):
            unc = "" if gain_std is None else f" +- {gain_std[j, i]:.3g}"
            lines.append(f"  DC gain {inp} -> {name}: {gains[j, i]:.6g}{unc}")
    return "\n".join(lines)
