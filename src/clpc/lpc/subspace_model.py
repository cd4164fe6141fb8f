"""A subspace fit written as difference equations (:mod:`clpc.lpc.subspace`).

The state space fitted in scaled units is written in the record's units, and output ``j``
as ``A(q) y_j = sum_i N_ji(q) u_i + k_j`` with the common denominator ``A(z) = det(zI - A)``,
the numerators ``N_ji = A(z) (D_ji + sum_k C_j A^(k-1) B_i z^-k)`` (the maps ``M_k`` of
:class:`~clpc.lpc.subspace_dynamics.StateDynamics`) and the offset ``k_j`` of the fitted
affine model; :meth:`SubspaceFit.equation` gives the unit-norm ``theta`` and ``c``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from clpc.lpc.subspace_bd import BDFit
from clpc.lpc.subspace_dynamics import StateDynamics
from clpc.lpc.subspace_record import ScaledRecord

__all__ = ["SubspaceFit"]


@dataclass
class SubspaceFit:
    """A fitted state space in original units, and how its order was found.

    Attributes
    ----------
    den : numpy.ndarray, shape (n + 1,)
        ``det(zI - A)``, ascending powers of ``z^-1`` (``den[0] = 1``).
    num : numpy.ndarray, shape (l, m, n + 1)
        Numerators ``N_ji``, ascending powers of ``z^-1``, original units.
    intercept : numpy.ndarray, shape (l,)
        ``k_j`` of ``A(q) y_j = sum_i N_ji(q) u_i + k_j`` (output units).
    horizon, order : int
        Block rows and order of the fit.
    order_reason : str
        How the order was found.
    order_scores : dict of str to float
        Held-out fit % per candidate order (``order="auto"``; else empty).
    singular_values : list of float
        Singular values of ``L32``, divided by the largest.
    state_space : dict
        ``A``, ``B``, ``C``, ``D`` (original units), ``x0``, ``a_form``, ``nk``, ``u_mean``,
        ``x_bias``, ``y_bias``.
    bd_form : str
        ``"simulation error"`` or ``"equation error"`` (:func:`clpc.lpc.subspace_bd.fit_bd`).
    """

    den: np.ndarray
    num: np.ndarray  # (l, m, n + 1): ascending powers of z^-1, original units
    intercept: np.ndarray  # (l,): k_j of A(q) y_j = sum_i N_ji(q) u_i + k_j
    horizon: int
    order: int
    order_reason: str
    order_scores: dict[str, float]
    singular_values: list[float]
    state_space: dict[str, Any]
    bd_form: str

    @classmethod
    def make(
        cls,
        rec: ScaledRecord,
        model: StateDynamics,
        bd: BDFit,
        horizon: int,
        order: int,
        reason: str,
        scores: dict[str, float],
        sv: np.ndarray,
    ) -> SubspaceFit:
        """The fit of scaled data written in the record's units.

        In the record's units the model is ``x(t+1) = A x + B (u(t-nk) - u_mean) + x_bias``,
        ``y = C x + D (u(t-nk) - u_mean) + y_bias``; multiplying by ``A(q)`` gives
        ``A(q) y = N(q) u + k`` with ``k = A(1) y_bias + N_bias(1) - N(1) u_mean``
        (``N_bias = sum_k C M_k x_bias z^-k``, the constant input's numerator).

        Parameters
        ----------
        rec : ScaledRecord
            The record (its means and scales).
        model : StateDynamics
            ``A``, ``C`` (scaled units).
        bd : BDFit
            ``B``, ``D``, initial states and offset (scaled units).
        horizon, order : int
            Block rows and order of the fit.
        reason : str
            How the order was found.
        scores : dict of str to float
            Held-out fit % per candidate order.
        sv : numpy.ndarray, shape (i l,)
            Singular values of ``L32``, divided by the largest.

        Returns
        -------
        SubspaceFit
            The fit in the record's units.
        """
        n, a, c = model.n, model.a, model.c
        su, sy = rec.u_scale, rec.y_scale
        b, x_bias = bd.b[:, :-1], bd.b[:, -1]
        num = np.empty((rec.ny, rec.m, n + 1))
        num[:, :, 0] = bd.d
        for k in range(1, n + 1):
            num[:, :, k] = model.maps[k - 1] @ b + model.den[k] * bd.d
        num *= sy[:, None, None] / su[None, :, None]
        y_bias = rec.y_mean + sy * bd.offset
        n_bias = sy * (model.maps.sum(axis=0) @ x_bias) if n else np.zeros(rec.ny)
        intercept = model.den.sum() * y_bias + n_bias - num.sum(axis=2) @ rec.u_mean
        state = {
            "A": a,
            "B": b / su,
            "C": sy[:, None] * c,
            "D": sy[:, None] * bd.d / su[None, :],
            "x0": bd.x0,
            "a_form": model.a_form,
            "nk": rec.nk,
            "u_mean": rec.u_mean,
            "x_bias": x_bias,
            "y_bias": y_bias,
        }
        return cls(model.den, num, intercept, horizon, order, reason, scores,
                   [float(v) for v in sv], state, bd.form)  # fmt: skip

    def equation(self, j: int, feedthrough: bool, order: int) -> tuple[np.ndarray, float]:
        """Unit-norm ``theta`` and ``c`` of output ``j`` (paper convention, ``G = -B/A``).

        Written at ``order >= self.order`` by zeros at the end of both polynomials (poles and
        zeros at ``z = 0`` that cancel exactly: a paired model's lower-order pairs).

        Parameters
        ----------
        j : int
            Output index.
        feedthrough : bool
            Whether ``b0`` multiplies ``u(t - nk)`` (else ``u(t - nk - 1)``: ``N_ji``'s
            leading zero dropped).
        order : int
            Order written (>= ``self.order``).

        Returns
        -------
        theta : numpy.ndarray, shape (order + 1 + m (order + 1),) or (order + 1 + m order,)
            ``[a_0 .. a_order, -N_j1, .., -N_jm]`` (with, without feedthrough) divided by its
            norm.
        c : float
            ``k_j`` divided by the same norm.
        """
        start = 0 if feedthrough else 1
        pad = (0, order - self.order)
        nums = [-np.pad(self.num[j, i, start:], pad) for i in range(self.num.shape[1])]
        theta = np.concatenate([np.pad(self.den, pad), *nums])
        scale = float(np.linalg.norm(theta))
        return theta / scale, float(self.intercept[j]) / scale
