"""Subspace identification (PO-MOESP) in O(T) memory, returned as a :class:`LinearModel`.

:class:`Subspace` estimates a state-space model ``x(t+1) = A x(t) + B u(t - nk)``,
``y(t) = C x(t) + D u(t - nk)`` of order ``n`` from one record, in three steps, and writes it
as the difference equations every clpc model is.

1. **Data.** Every channel is centred and divided by its standard deviation (the means go
   into the model's offset, the scales back into ``B``, ``C``, ``D``); the input is delayed
   by ``nk`` samples.
2. **A, C: the projection.** Column ``j`` of the stacked block-Hankel data matrix is

       [u(j+i) .. u(j+2i-1) | 1 | u(j) .. u(j+i-1) | y(j) .. y(j+i-1) | y(j+i) .. y(j+2i-1)]

   (future inputs ``U_f``, a constant, past inputs and outputs ``W_p``, future outputs
   ``Y_f``; ``i`` block rows, :attr:`Subspace.horizon`). Its R factor (``H^T = Q R``, the
   transposed LQ factor of PO-MOESP, Verhaegen 1994) is built chunk by chunk: the R of the
   columns so far is stacked on the next chunk of columns and factored again (LAPACK
   ``dgeqrf``), so the peak memory is one chunk and the time is linear in ``T``; no ``T x T``
   or ``N x N`` matrix is formed. The block ``L32`` (``Y_f`` on ``W_p``, ``U_f`` and the
   constant projected out) spans the extended observability matrix ``Gamma_i``: its ``n``
   leading left singular vectors give ``Gamma``, ``C`` its first block row and ``A`` the
   least-squares solution of the shift ``Gamma_up A = Gamma_down``. The constant row takes
   the record's offset out exactly (a record that does not start at rest has one after
   centring).
3. **B, D: least squares over the record.** With ``A`` and ``C`` fixed the output is linear
   in ``B``, ``D`` (when :attr:`Subspace.feedthrough`), the initial state of each experiment
   and the constant input ``1`` (its column of ``B``, ``x_bias``: what drives an integrator
   with the input's mean; its ``D``, ``y_bias``: the output's offset):
   ``y_j(t) = sum_k (M_k B)_j v(t-k) + D u(t) + sum_k (M_k x0)_j r(t+1-k) + ...``, with
   ``v = u / det(zI - A)`` (the input filtered by the characteristic polynomial,
   :func:`clpc.core.filters.all_pole`), ``r`` that filter's impulse response and
   ``M_k = sum_{q<k} a_q C A^(k-1-q)`` (Cayley-Hamilton: the numerators of
   ``C (zI - A)^-1``). The fit minimises the simulation error (the output-error
   criterion, consistent under output noise of any colour); its R factor is accumulated
   chunk by chunk like step 2's. When the estimated ``A`` has a pole so far outside the unit
   circle that the filtered input would grow more than :data:`MAX_GROWTH` over the record,
   the equation-error form ``det(zI - A)(q) y = N(q) u + const`` (FIR filters only, no
   initial state, still consistent for inputs independent of the noise) is solved instead
   (``info["bd_form"]``).

**The difference equations.** Output ``j`` is ``A(q) y_j = sum_i N_ji(q) u_i + k_j`` with
the common denominator ``A(z) = det(zI - A)`` (``np.poly``) and the numerators
``N_ji = A(z) (D_ji + sum_k C_j A^(k-1) B_i z^-k)`` (the Markov parameters convolved with
the denominator, exact at order ``n``): ``na = n``, and ``nb = n, nk = nk`` with
feedthrough, ``nb = n - 1, nk = nk + 1`` without (the model's ``b0`` multiplies
``u(t - nk - 1)``). ``theta`` is in the paper's convention (unit norm, ``a0 > 0``,
``G = -B/A``) and :meth:`LinearModel.simulate` with ``include_offset=False`` reproduces the
state-space model from rest exactly (``scipy.signal.dlsim``). The offset is that of the
fitted affine model ``x(t+1) = A x + B (u(t-nk) - u_mean) + x_bias``,
``y = C x + D (u(t-nk) - u_mean) + y_bias``: ``k = A(1) y_bias + N_bias(1) - N(1) u_mean``
(``N_bias`` the constant input's numerator), ``c = k / ||theta||``. For a stable model with
``x_bias = 0`` this is ARX's ``c = mean(lag vector) . theta`` plus ``sum(theta_a)`` times
the fitted output offset; a noise-free record that starts at rest gives ``c = 0``, and an
integrator keeps the drift its input's mean gives it. ``info["state_space"]`` keeps ``A``,
``B``, ``C``, ``D`` (original units; the input delayed by ``nk``), ``x0`` (the initial state
of each experiment), ``u_mean``, ``x_bias``, ``y_bias`` and ``a_form``.
The model is an output-error model (``info["noise_model"]``: its ``k``-step prediction is
the free run, :meth:`LinearModel.predict`): no noise model is estimated.

**Order** (``order="auto"``). The singular values ``s_1 >= s_2 >= ...`` of ``L32`` (whole
record, ``max(ceil(2 max_order / l), 10)`` block rows) rank the orders ``1 .. max_order`` by
the gap ``s_n / s_(n+1)``. When the largest gap is clear (at least :data:`CLEAR_GAP`), the
orders of the :data:`GAPS` largest gaps and their neighbours (``n - 1``, ``n``, ``n + 1``
within ``1 .. max_order``) are the candidates; otherwise every order is. Each candidate is
fitted (steps 2-3, at its own horizon, the R factor of the first part a by-product of the
whole record's) on the first ``1 - HELDOUT_FRACTION`` (two thirds) of the record and scored
by the free-run fit % (mean over the outputs) on the last third, the free run continued from
the fitted initial state. The order is the lowest candidate within :data:`PARSIMONY` points
of the best candidate's score (the gap alone when every candidate diverges). The model is
then exactly ``Subspace(order=n)``'s on the whole record. ``info["singular_values"]``
(divided by the largest), ``info["order_scores"]`` and ``info["order_reason"]`` say how.

**Horizon** (block rows ``i``). Default ``max(ceil(2 n / l), 10)`` for the order ``n``
(``l`` outputs), lowered while the record (its first two thirds for ``"auto"``) has fewer
Hankel columns than the data matrix has rows (``2 i (m + l) + 1`` for ``m`` inputs); never
below ``ceil(n / l) + 1`` (the shift of ``Gamma`` needs ``(i - 1) l >= n``): a record too
short for that raises :class:`DataError`.

**Stability.** PO-MOESP does not guarantee a stable ``A``; with ``stable=True`` (default) an
``A`` with a pole outside the unit circle by more than
:data:`~clpc.core.polynomials.UNIT_CIRCLE_TOL` is replaced by Maciejowski's estimate
``Gamma A = [Gamma_down; 0]``, whose poles are inside (``info["state_space"]["a_form"]``).

A record of several experiments gives Hankel columns inside each experiment only and one
initial state per experiment. ``mimo="paired"`` fits each output on its own input as a
separate SISO model (its own order for ``"auto"``; the model is written at the largest, the
others padded with poles and zeros at ``z = 0`` that cancel exactly).

The steps live in their own modules: step 1 in :mod:`clpc.lpc.subspace_record`, step 2 and
the horizon in :mod:`clpc.lpc.subspace_projection`, step 3 in :mod:`clpc.lpc.subspace_bd`
(``A``, ``C`` with their characteristic polynomial and maps ``M_k`` in
:mod:`clpc.lpc.subspace_dynamics`), the difference equations in
:mod:`clpc.lpc.subspace_model` and the order in :mod:`clpc.lpc.subspace_order`.

References: M. Verhaegen, "Identification of the deterministic part of MIMO state space
models given in innovations form from input-output data", Automatica 30(1), 1994;
P. Van Overschee and B. De Moor, *Subspace Identification for Linear Systems*, Kluwer, 1996;
J. M. Maciejowski, "Guaranteed stability with subspace methods", Systems & Control Letters
26(2), 1995.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np

from clpc.core.checks import check_bool, check_int
from clpc.data import IOData
from clpc.lpc.assessment import HELDOUT_FRACTION
from clpc.lpc.problem import Covariance, FitProblem
from clpc.lpc.subspace_bd import fit_bd
from clpc.lpc.subspace_dynamics import MAX_GROWTH, StateDynamics
from clpc.lpc.subspace_model import SubspaceFit
from clpc.lpc.subspace_order import CLEAR_GAP, GAPS, PARSIMONY, choose_order
from clpc.lpc.subspace_projection import Projections, block_rows, hankel_r
from clpc.lpc.subspace_record import ScaledRecord, paired_record
from clpc.model import LinearModel
from clpc.model.structure import MimoMode, Structure

__all__ = ["CLEAR_GAP", "GAPS", "MAX_GROWTH", "PARSIMONY", "Subspace"]


@dataclass
class Subspace:
    """Subspace identification (PO-MOESP): a state-space fit written as a :class:`LinearModel`.

    Parameters
    ----------
    order : int or "auto"
        State dimension ``n`` (>= 1), or ``"auto"`` (default): chosen among
        ``1 .. max_order`` by the singular-value gaps, checked on held-out data
        (:mod:`clpc.lpc.subspace`).
    max_order : int
        Largest order ``"auto"`` considers (default 10).
    nk : int
        Pure input delay in samples (>= 0, default 0): the input is delayed by ``nk``
        before identification.
    horizon : int, optional
        Block rows ``i`` of the Hankel matrices (past and future). Default
        ``max(ceil(2 n / n_outputs), 10)`` for the order ``n``, lowered to fit the record
        (see the module); at least ``ceil(n / n_outputs) + 1``.
    feedthrough : bool
        Estimate ``D`` (default ``False``: ``D = 0``, a sampled physical plant, held by a
        zero-order hold, does not pass ``u(t)`` to ``y(t)``; the model's ``b0`` then
        multiplies ``u(t - nk - 1)``).
    stable : bool
        Keep the poles inside the unit circle (default ``True``): when the shift estimate of
        ``A`` has a pole outside it by more than
        :data:`~clpc.core.polynomials.UNIT_CIRCLE_TOL` (an integrator is on the circle and
        kept), ``A`` is estimated by Maciejowski's stable shift instead
        (``info["state_space"]["a_form"]``). ``False``: the plain shift estimate, as
        unstable as the data make it (``B``, ``D`` then by the equation-error form when a
        free run would grow past :data:`MAX_GROWTH`).
    mimo : {"siso", "paired", "miso"}, optional
        Multi-channel structure; default ``"siso"`` for 1x1 data, else ``"miso"`` (one joint
        state space, every output with the common denominator ``det(zI - A)`` and a
        numerator per input). ``"paired"``: output ``j`` on input ``j`` only, one SISO
        state space per pair (each at its own order for ``"auto"``, the model written at the
        largest with zeros at ``z = 0`` that cancel).
    uncertainty : bool
        Accepted for interface parity (default ``True``): subspace identification has no
        closed-form parameter covariance, so ``info["covariance_note"]`` says so.
    assess : bool
        Offer the held-out fit and residual tests on demand (default ``True``; as
        :class:`clpc.LPC`), the refit at the fitted order.
    """

    order: int | Literal["auto"] = "auto"
    max_order: int = 10
    nk: int = 0
    horizon: int | None = None
    feedthrough: bool = False
    stable: bool = True
    mimo: MimoMode | None = None
    uncertainty: bool = True
    assess: bool = True

    def _largest_order(self) -> int:
        if isinstance(self.order, str):
            if self.order != "auto":
                raise ValueError(f"order must be an int >= 1 or 'auto'; got {self.order!r}.")
            return check_int(self.max_order, "max_order", 1)
        return check_int(self.order, "order", 1)

    def structure(self) -> Structure:
        """The :class:`Structure` of a fit at ``order`` (``max_order`` for ``"auto"``)."""
        n = self._largest_order()
        nk = check_int(self.nk, "nk", 0)
        return Structure(n, n, nk) if self.feedthrough else Structure(n, n - 1, nk + 1)

    def fit(self, u: Any, y: Any | None = None, dt: float | None = None) -> LinearModel:
        """Subspace fit; returns a :class:`LinearModel` (``theta`` unit norm, ``a0 > 0``).

        Parameters
        ----------
        u : IOData or array_like, shape (T,) or (T, n_inputs)
            The record, or its inputs.
        y : array_like, shape (T,) or (T, n_outputs), optional
            Outputs (when ``u`` is not an :class:`IOData`).
        dt : float, optional
            Sample time [s] (when ``u`` is not an :class:`IOData`).

        Returns
        -------
        LinearModel
            ``info`` holds ``order``, ``horizon``, ``singular_values``, ``order_reason``,
            ``order_scores`` (``"auto"``), ``state_space`` and ``bd_form``.

        Raises
        ------
        DataError
            Invalid or non-finite data, a constant channel, or a record too short for the
            horizon and the order.
        ValueError
            Invalid settings (e.g. a horizon too small for the order).
        """
        check_bool(self.feedthrough, "feedthrough")
        check_bool(self.stable, "stable")
        check_bool(self.uncertainty, "uncertainty")
        check_bool(self.assess, "assess")
        n_max = self._largest_order()
        if self.horizon is not None:
            check_int(self.horizon, "horizon", 2)
        problem = FitProblem.prepare(self, (u, y, dt), "A subspace fit")
        data, mode = problem.data, problem.mode
        auto = self.order == "auto"
        if mode == "paired":
            pairs = [paired_record(data, j) for j in range(data.n_outputs)]
            fits = [self._identify(p, n_max, auto) for p in pairs]
        else:
            fits = [self._identify(data, n_max, auto)]
        order = max(f.order for f in fits)
        structure = replace(self, order=order).structure()
        thetas, cs = [], []
        for j in range(data.n_outputs):
            fit, jj = (fits[j], 0) if mode == "paired" else (fits[0], j)
            theta, c = fit.equation(jj, self.feedthrough, order)
            thetas.append(theta)
            cs.append(c)
        info: dict[str, Any] = {
            "method": "subspace",
            "noise_model": "output-error",
            "order": order,
            "feedthrough": bool(self.feedthrough),
        }
        keys = ("horizon", "singular_values", "order_reason", "order_scores", "state_space",
                "bd_form")  # fmt: skip
        for key in keys:
            values = [getattr(f, key) for f in fits]
            info[key] = values[0] if mode != "paired" else values
        covariance = None
        if self.uncertainty:
            covariance = Covariance(
                note="subspace identification has no closed-form parameter covariance (A "
                "and C come from an SVD of projected data, B and D from a least-squares "
                "fit given them); none is computed"
            )
        problem = replace(problem, structure=structure)
        settings = replace(self, order=order)
        return problem.model(settings, np.array(thetas), np.array(cs), info, covariance)

    def _identify(self, data: IOData, n_max: int, auto: bool) -> SubspaceFit:
        """The state-space fit of one record (all its channels), at ``n_max`` or chosen."""
        rec = ScaledRecord(data, self.nk)
        segs = rec.segments()
        scores: dict[str, float] = {}
        if auto:
            split = round(data.n_samples * (1.0 - HELDOUT_FRACTION))
            first = rec.segments(split)
            i = block_rows(rec, first, n_max, True, self.horizon)
            r_full, r_first = hankel_r(rec, segs, i, first)
            assert r_first is not None
            full = Projections(r_full, i, rec.m, rec.ny)
            order, reason, scores = choose_order(
                rec, first, Projections(r_first, i, rec.m, rec.ny), full.at(i)[1], n_max,
                lambda n: block_rows(rec, first, n, True, self.horizon), self.stable,
                self.feedthrough, split,
            )  # fmt: skip
            sv = full.at(i)[1]
            i_fit = block_rows(rec, segs, order, False, self.horizon)
            if i_fit != i:  # the model is Subspace(order=order)'s: its own horizon, exactly
                full = Projections(hankel_r(rec, segs, i_fit, None)[0], i_fit, rec.m, rec.ny)
        else:
            order = n_max
            reason = f"order {order} given"
            i_fit = block_rows(rec, segs, order, False, self.horizon)
            full = Projections(hankel_r(rec, segs, i_fit, None)[0], i_fit, rec.m, rec.ny)
            sv = full.at(i_fit)[1]
        model = StateDynamics(*full.a_c(i_fit, order, self.stable))
        bd = fit_bd(rec, segs, model, self.feedthrough)
        sv = sv / sv[0] if sv.size and sv[0] > 0 else sv
        return SubspaceFit.make(rec, model, bd, i_fit, order, reason, scores, sv)
