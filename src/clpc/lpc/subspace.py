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

References: M. Verhaegen, "Identification of the deterministic part of MIMO state space
models given in innovations form from input-output data", Automatica 30(1), 1994;
P. Van Overschee and B. De Moor, *Subspace Identification for Linear Systems*, Kluwer, 1996;
J. M. Maciejowski, "Guaranteed stability with subspace methods", Systems & Control Letters
26(2), 1995.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy.linalg import lapack

from clpc.core.checks import check_bool, check_int
from clpc.core.filters import all_pole
from clpc.core.polynomials import UNIT_CIRCLE_TOL
from clpc.data import DataError, IOData
from clpc.lpc.assessment import HELDOUT_FRACTION
from clpc.lpc.problem import Covariance, FitProblem
from clpc.model import LinearModel
from clpc.model.structure import MimoMode, Structure

__all__ = ["CLEAR_GAP", "GAPS", "MAX_GROWTH", "PARSIMONY", "Subspace"]

#: Points of held-out free-run fit a higher order must gain over a lower one (as
#: :data:`clpc.lpc.reduction.KEEP_FIT_POINTS` and ``identify``'s parsimony).
PARSIMONY = 1.0
#: How many of the largest singular-value gaps have their orders checked on held-out data.
GAPS = 2
#: A gap ``s_n / s_(n+1)`` at least this large is clear; without one every order is checked.
CLEAR_GAP = 10.0
#: Largest growth of the filtered input over a record for the simulation-error fit of B, D.
MAX_GROWTH = 1e8
#: Elements of one chunk of a data matrix whose R factor is updated chunk by chunk (2 MiB).
CHUNK_ELEMENTS = 1 << 18
#: Samples per chunk of the least-squares pass for B and D.
LS_CHUNK = 8192
#: Relative singular-value cut of the small least-squares solve (initial state and offset
#: are collinear for an integrating model).
RCOND = 1e-10


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
            pairs = [_pair(data, j) for j in range(data.n_outputs)]
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

    def _identify(self, data: IOData, n_max: int, auto: bool) -> _Fit:
        """The state-space fit of one record (all its channels), at ``n_max`` or chosen."""
        rec = _Record(data, self.nk)
        segs = rec.segments()
        scores: dict[str, float] = {}
        if auto:
            split = round(data.n_samples * (1.0 - HELDOUT_FRACTION))
            first = rec.segments(split)
            i = self._horizon(rec, first, n_max, True)
            r_full, r_first = _hankel_r(rec, segs, i, first)
            assert r_first is not None
            full = _Projections(r_full, i, rec.m, rec.ny)
            order, reason, scores = _choose_order(
                rec, first, _Projections(r_first, i, rec.m, rec.ny), full.at(i)[1], n_max,
                lambda n: self._horizon(rec, first, n, True), self, split,
            )  # fmt: skip
            sv = full.at(i)[1]
            i_fit = self._horizon(rec, segs, order, False)
            if i_fit != i:  # the model is Subspace(order=order)'s: its own horizon, exactly
                full = _Projections(_hankel_r(rec, segs, i_fit, None)[0], i_fit, rec.m, rec.ny)
        else:
            order = n_max
            reason = f"order {order} given"
            i_fit = self._horizon(rec, segs, order, False)
            full = _Projections(_hankel_r(rec, segs, i_fit, None)[0], i_fit, rec.m, rec.ny)
            sv = full.at(i_fit)[1]
        model = _Model(*full.a_c(i_fit, order, self.stable))
        bd = _fit_bd(rec, segs, model, self.feedthrough)
        sv = sv / sv[0] if sv.size and sv[0] > 0 else sv
        return _Fit.make(rec, model, bd, i_fit, order, reason, scores, sv)

    def _horizon(self, rec: _Record, segs: list[tuple[int, int]], n_max: int, auto: bool) -> int:
        """Block rows ``i`` (see the module), checked against the record (``segs``)."""
        m, ny = rec.m, rec.ny
        low = -(-n_max // ny) + 1
        what = "the first two thirds of the record (order='auto')" if auto else "the record"
        if self.horizon is not None:
            i = int(self.horizon)
            if i < low:
                raise ValueError(
                    f"horizon={i} is too small for order {n_max} with {ny} output(s): the "
                    f"shift of the observability matrix needs horizon >= {low} "
                    "(ceil(order / n_outputs) + 1). Raise horizon or lower the order."
                )
            if _columns(segs, i) < _rows(i, m, ny):
                raise DataError(
                    f"A subspace fit with horizon {i} needs at least {_rows(i, m, ny)} Hankel "
                    f"columns (2 i (m + l) + 1, m inputs, l outputs); {what} gives "
                    f"{_columns(segs, i)} (after the delay nk={self.nk}). Use a longer record "
                    "or a smaller horizon."
                )
            return i
        i = max(-(-2 * n_max // ny), 10)
        while i > low and _columns(segs, i) < _rows(i, m, ny):
            i -= 1
        if _columns(segs, i) < _rows(i, m, ny):
            used = sum(length for _, length in segs)
            need = 2 * low * (m + ny + 1)
            raise DataError(
                f"A subspace fit of order {n_max} needs horizon >= {low} and so about {need} "
                f"samples in {what} (after the delay nk={self.nk}); there are {used}. Use a "
                "longer record or a lower order (max_order for order='auto')."
            )
        return i


# --------------------------------------------------------------------------------- record
class _Record:
    """A record's channels centred, scaled and the input delayed by ``nk``, read in chunks."""

    def __init__(self, data: IOData, nk: int) -> None:
        self.u, self.y, self.nk = data.u, data.y, nk
        self.m, self.ny = data.n_inputs, data.n_outputs
        lengths = np.asarray(data.experiments)
        self.starts = np.cumsum(lengths) - lengths
        self.lengths = [int(n) - nk for n in lengths]  # samples after the delay
        self.u_mean, self.u_scale = _mean_scale(self.u)
        self.y_mean, self.y_scale = _mean_scale(self.y)
        const = [n for n, s in zip(data.input_names, self.u_scale, strict=True) if s == 0]
        const += [n for n, s in zip(data.output_names, self.y_scale, strict=True) if s == 0]
        if const:
            raise DataError(
                f"nothing to identify: constant channel(s) {const}. A subspace fit needs "
                "inputs and outputs that vary over the record."
            )
        if max(self.lengths) < 1:
            raise DataError(f"the delay nk={nk} leaves no sample of the record.")

    def segments(self, stop: int | None = None) -> list[tuple[int, int]]:
        """``(experiment, samples)`` used, from each experiment's start, ``y`` before ``stop``."""
        out = []
        for e, (start, length) in enumerate(zip(self.starts, self.lengths, strict=True)):
            n = length if stop is None else min(length, stop - int(start) - self.nk)
            if n > 0:
                out.append((e, n))
        return out

    def inputs(self, e: int, a: int, b: int) -> np.ndarray:
        """Scaled inputs ``u(t - nk)`` of experiment ``e``, ``t = a .. b-1``: (b-a, m)."""
        s = int(self.starts[e])
        return (self.u[s + a : s + b] - self.u_mean) / self.u_scale

    def outputs(self, e: int, a: int, b: int) -> np.ndarray:
        """Scaled outputs ``y(t)`` of experiment ``e`` (``t`` after the delay): (b-a, l)."""
        s = int(self.starts[e]) + self.nk
        return (self.y[s + a : s + b] - self.y_mean) / self.y_scale


def _mean_scale(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Column means and standard deviations, two passes in chunks (no copy of ``x``)."""
    n = x.shape[0]
    mean = x.sum(axis=0) / n
    ss = np.zeros(x.shape[1])
    step = max(1, CHUNK_ELEMENTS // max(x.shape[1], 1))
    for a in range(0, n, step):
        d = x[a : a + step] - mean
        ss += np.einsum("ij,ij->j", d, d)
    return mean, np.sqrt(ss / n)


def _pair(data: IOData, j: int) -> IOData:
    """Input ``j`` and output ``j`` of a record (its experiments kept)."""
    return IOData(
        data.u[:, j],
        data.y[:, j],
        data.dt,
        [data.input_names[j]],
        [data.output_names[j]],
        data.experiments,
    )


# --------------------------------------------------------------------- step 2: A and C
def _rows(i: int, m: int, ny: int) -> int:
    """Rows of the stacked data matrix (columns of its transpose, the R factor's size)."""
    return 2 * i * (m + ny) + 1


def _columns(segs: list[tuple[int, int]], i: int) -> int:
    """Hankel columns of the segments (each inside its experiment)."""
    return sum(max(0, n - 2 * i + 1) for _, n in segs)


def _hankel_r(
    rec: _Record, segs: list[tuple[int, int]], i: int, first: list[tuple[int, int]] | None
) -> tuple[np.ndarray, np.ndarray | None]:
    """R factor of the transposed data matrix, chunk by chunk (and of its ``first`` part).

    The columns of ``first`` (a prefix of each experiment, experiments in order) come first,
    so their R is a by-product: copied when they are done, then the rest is added.
    """
    m, ny = rec.m, rec.ny
    k = _rows(i, m, ny)
    chunk = min(max(4 * k, CHUNK_ELEMENTS // k), max(_columns(segs, i), 1))
    work = np.zeros((k + chunk, k), order="F")  # rows 0..k-1: the R so far
    runs: list[tuple[int, int, int, bool]] = []  # experiment, first column, end, copy after
    done = dict(first) if first is not None else {}
    last_first = first[-1][0] if first else -1
    for e, n in segs:
        cols = max(0, n - 2 * i + 1)
        c1 = min(cols, max(0, done.get(e, 0) - 2 * i + 1))
        if first is not None and e <= last_first:
            runs.append((e, 0, c1, e == last_first))
            runs.append((e, c1, cols, False))
        else:
            runs.append((e, 0, cols, False))
    r_first = np.zeros((k, k)) if first is not None and not first else None
    for e, j0, j1, copy_after in runs:
        for a in range(j0, j1, chunk):
            b = min(a + chunk, j1)
            _fill(work, rec, e, a, b, i, k)
            rows = k + b - a
            block = work if rows == work.shape[0] else work[:rows]
            qr, _, _, info = lapack.dgeqrf(block, overwrite_a=True)
            if info != 0:  # pragma: no cover - LAPACK argument errors only
                raise np.linalg.LinAlgError(f"QR of the data matrix failed (info {info}).")
            work[:k] = np.triu(qr[:k])
        if copy_after:
            r_first = work[:k].copy()
    return np.array(work[:k]), r_first


def _fill(work: np.ndarray, rec: _Record, e: int, a: int, b: int, i: int, k: int) -> None:
    """Rows ``k ..`` of ``work``: the data-matrix columns ``a .. b-1`` of experiment ``e``."""
    m, ny, nc = rec.m, rec.ny, b - a
    out = work[k : k + nc]
    u = sliding_window_view(rec.inputs(e, a, b + 2 * i - 1), 2 * i, axis=0)  # (nc, m, 2i)
    y = sliding_window_view(rec.outputs(e, a, b + 2 * i - 1), 2 * i, axis=0)
    im, il = i * m, i * ny
    for ch in range(m):
        out[:, ch:im:m] = u[:, ch, i:]  # future inputs u(j+i) .. u(j+2i-1)
        out[:, im + 1 + ch : 2 * im + 1 : m] = u[:, ch, :i]  # past inputs
    out[:, im] = 1.0
    for ch in range(ny):
        out[:, 2 * im + 1 + ch : 2 * im + 1 + il : ny] = y[:, ch, :i]  # past outputs
        out[:, 2 * im + 1 + il + ch :: ny] = y[:, ch, i:]  # future outputs


def _l32(r: np.ndarray, i: int, m: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    """Left singular vectors and singular values of ``L32`` (``Y_f`` on ``W_p``)."""
    im, il = i * m, i * ny
    wp = slice(im + 1, 2 * im + 1 + il)
    yf = slice(2 * im + 1 + il, 2 * im + 1 + 2 * il)
    l32 = r[wp, yf].T  # L = R^T
    left, s, _ = np.linalg.svd(l32, full_matrices=False)
    return left, s


def _sub_r(r: np.ndarray, i: int, i2: int, m: int, ny: int) -> np.ndarray:
    """The R factor at ``i2 < i`` block rows from the one at ``i`` (no pass over the data).

    Column ``j`` of the data matrix at ``i2`` is a subset of the entries of column
    ``j - (i - i2)`` at ``i`` (the blocks next to the past/future boundary): ``H2^T = Q R[:,
    sel]``, so its R is that of the ``K x K2`` matrix ``R[:, sel]`` (the ``2 (i - i2)`` edge
    columns the shorter horizon would add are left out).
    """
    im, il = i * m, i * ny
    d = i - i2
    sel = np.r_[
        np.arange(i2 * m),  # future inputs: the first i2 blocks
        im,  # the constant
        im + 1 + d * m + np.arange(i2 * m),  # past inputs: the last i2 blocks
        2 * im + 1 + d * ny + np.arange(i2 * ny),  # past outputs: the last i2 blocks
        2 * im + 1 + il + np.arange(i2 * ny),  # future outputs: the first i2 blocks
    ]
    packed, _, _, info = lapack.dgeqrf(np.asfortranarray(r[:, sel]))
    if info != 0:  # pragma: no cover - LAPACK argument errors only
        raise np.linalg.LinAlgError(f"QR of the data matrix failed (info {info}).")
    return np.triu(packed[: sel.size])


class _Projections:
    """The SVD of ``L32`` at each horizon, from one R factor (see :func:`_sub_r`)."""

    def __init__(self, r: np.ndarray, i: int, m: int, ny: int) -> None:
        self.r, self.i, self.m, self.ny = r, i, m, ny
        self.svds: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def at(self, i2: int) -> tuple[np.ndarray, np.ndarray]:
        """Left singular vectors and singular values of ``L32`` at ``i2`` block rows."""
        if i2 not in self.svds:
            r = self.r if i2 == self.i else _sub_r(self.r, self.i, i2, self.m, self.ny)
            self.svds[i2] = _l32(r, i2, self.m, self.ny)
        return self.svds[i2]

    def a_c(self, i2: int, n: int, stable: bool) -> tuple[np.ndarray, np.ndarray, str]:
        """``A``, ``C`` of order ``n`` from ``Gamma = U_n S_n^(1/2)``, and how ``A`` was got.

        ``A`` solves the shift ``Gamma_up A = Gamma_down`` (least squares). With ``stable``,
        when that ``A`` has a pole outside the unit circle by more than
        :data:`~clpc.core.polynomials.UNIT_CIRCLE_TOL`, it solves ``Gamma A = [Gamma_down;
        0]`` instead, whose poles are inside (Maciejowski 1995).
        """
        left, s = self.at(i2)
        ny = self.ny
        gamma = left[:, :n] * np.sqrt(s[:n])
        a = np.linalg.lstsq(gamma[:-ny], gamma[ny:], rcond=None)[0]
        how = "shift"
        if stable and np.max(np.abs(np.linalg.eigvals(a))) > 1.0 + UNIT_CIRCLE_TOL:
            down = np.vstack([gamma[ny:], np.zeros((ny, n))])
            a = np.linalg.lstsq(gamma, down, rcond=None)[0]
            how = "stabilised shift (Maciejowski)"
        return a, gamma[:ny].copy(), how


# ---------------------------------------------------------------- step 3: B, D, x0, d
@dataclass
class _Model:
    """``A``, ``C``, the characteristic polynomial and the maps ``M_k`` of one order."""

    a: np.ndarray
    c: np.ndarray
    a_form: str = "shift"
    den: np.ndarray = field(init=False)
    maps: np.ndarray = field(init=False)  # (n, l, n): M_k for k = 1 .. n
    radius: float = field(init=False)

    def __post_init__(self) -> None:
        n = self.a.shape[0]
        poles = np.linalg.eigvals(self.a)
        self.radius = float(np.max(np.abs(poles))) if n else 0.0
        self.den = np.real(np.poly(poles)) if n else np.ones(1)
        powers = np.empty((n, *self.c.shape))  # C A^p, p = 0 .. n-1
        cur = self.c
        for p in range(n):
            powers[p] = cur
            cur = cur @ self.a
        self.maps = np.empty((n, *self.c.shape))
        for k in range(1, n + 1):
            self.maps[k - 1] = sum(self.den[q] * powers[k - 1 - q] for q in range(k))

    @property
    def n(self) -> int:
        """The order."""
        return int(self.a.shape[0])

    def simulated(self, longest: int) -> bool:
        """Whether the simulation form is used: growth at most :data:`MAX_GROWTH`."""
        return self.radius <= 1.0 or longest * math.log(self.radius) <= math.log(MAX_GROWTH)


@dataclass
class _BD:
    """The least-squares solution of step 3 (scaled units)."""

    b: np.ndarray  # (n, m + 1): B, then the constant input's column (the state's bias)
    d: np.ndarray  # (l, m)
    x0: np.ndarray  # (n_experiments, n): zeros where not fitted
    offset: np.ndarray  # (l,): the output's bias (the constant input's D)
    form: str
    fitted: set[int]


def _layout(n: int, m: int, ny: int, feedthrough: bool) -> tuple[int, int, int]:
    """Sizes of ``[vec B | vec D | offset]`` (``B`` with the constant input's column)."""
    nb, nd = n * (m + 1), (ny * m if feedthrough else 0)
    return nb, nd, nb + nd + ny


def _equation_rows(
    rec: _Record, e: int, length: int, model: _Model, feedthrough: bool, simulated: bool
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Chunks of one experiment's regressors, output by output (local layout).

    Yields ``(phi, y)``: ``phi`` shape (l, rows, nB + nD + l + n) with columns ``[vec B |
    vec D | offset | x0]`` (``vec B`` input by input, the last input the constant 1: a
    constant that drives the state, the drift of an integrator), ``y`` shape (l, rows).
    """
    n, m, ny = model.n, rec.m + 1, rec.ny
    nb, nd, nfix = _layout(n, rec.m, ny, feedthrough)
    den = model.den
    hist_v = np.zeros((n, m))  # v(t-n) .. v(t-1) (simulation) or u (equation error)
    hist_r = np.zeros(n)
    hist_y = np.zeros((n, ny))
    skip = 0 if simulated else n  # equation error: no row before the n-th sample
    den1 = float(den.sum())
    for a in range(0, length, LS_CHUNK):
        b = min(a + LS_CHUNK, length)
        rows = b - a
        uc = np.hstack([rec.inputs(e, a, b), np.ones((rows, 1))])
        yc = rec.outputs(e, a, b)
        phi = np.zeros((ny, rows, nfix + n))
        if simulated:
            v = np.empty((rows, m))
            for ch in range(m):
                v[:, ch] = all_pole(den, uc[:, ch], hist_v[::-1, ch])
            impulse = np.zeros(rows)
            if a == 0:
                impulse[0] = 1.0
            r = all_pole(den, impulse, hist_r[::-1]) if n else impulse
            r_ext = np.concatenate([hist_r, r])
            r_lags = np.stack([r_ext[n + 1 - k : n + 1 - k + rows] for k in range(1, n + 1)], 1)
            target = yc
        else:
            v = uc
            y_ext = np.vstack([hist_y, yc])
            target = sum(den[k] * y_ext[n - k : n - k + rows] for k in range(n + 1))
        v_ext = np.vstack([hist_v, v])
        for ch in range(m):
            lags = np.stack([v_ext[n - k : n - k + rows, ch] for k in range(1, n + 1)], 1)
            for j in range(ny):
                phi[j, :, ch * n : (ch + 1) * n] = lags @ model.maps[:, j, :]
            if feedthrough and ch < m - 1:
                direct = uc[:, ch] if simulated else lags @ den[1:] + den[0] * uc[:, ch]
                for j in range(ny):
                    phi[j, :, nb + j * (m - 1) + ch] = direct
        for j in range(ny):
            phi[j, :, nb + nd + j] = 1.0 if simulated else den1
            if simulated:
                phi[j, :, nfix:] = r_lags @ model.maps[:, j, :]
        if n:
            hist_v = v_ext[-n:]
            if simulated:
                hist_r = r_ext[-n:]
            else:
                hist_y = np.vstack([hist_y, yc])[-n:]
        lo = max(0, skip - a)
        yield phi[:, lo:], np.ascontiguousarray(target.T[:, lo:])


def _fit_bd(rec: _Record, segs: list[tuple[int, int]], model: _Model, feedthrough: bool) -> _BD:
    """``B``, ``D``, initial states and offset by least squares over ``segs`` (step 3)."""
    n, m, ny = model.n, rec.m, rec.ny
    nb, nd, nfix = _layout(n, m, ny, feedthrough)
    simulated = model.simulated(max(length for _, length in segs))
    p = nfix + n * len(segs) + 1  # the last column: the target
    chunk = min(LS_CHUNK, max(length for _, length in segs)) * ny
    work = np.zeros((p + chunk, p), order="F")
    for s, (e, length) in enumerate(segs):
        for phi, y in _equation_rows(rec, e, length, model, feedthrough, simulated):
            rows = phi.shape[0] * phi.shape[1]
            if rows == 0:
                continue
            block = work[: p + rows] if rows != chunk else work
            block[p:] = 0.0
            block[p:, :nfix] = phi[:, :, :nfix].reshape(rows, nfix)
            block[p:, nfix + s * n : nfix + (s + 1) * n] = phi[:, :, nfix:].reshape(rows, n)
            block[p:, -1] = y.reshape(rows)
            qr, _, _, info = lapack.dgeqrf(block, overwrite_a=True)
            if info != 0:  # pragma: no cover - LAPACK argument errors only
                raise np.linalg.LinAlgError(f"QR of the regressors failed (info {info}).")
            work[:p] = np.triu(qr[:p])
    r = work[:p]
    x = np.linalg.lstsq(r[:-1, :-1], r[:-1, -1], rcond=RCOND)[0]
    x0 = np.zeros((len(rec.lengths), n))
    for s, (e, _) in enumerate(segs):
        x0[e] = x[nfix + s * n : nfix + (s + 1) * n]
    return _BD(
        b=x[:nb].reshape(m + 1, n).T,
        d=x[nb : nb + nd].reshape(ny, m) if feedthrough else np.zeros((ny, m)),
        x0=x0 if simulated else np.zeros_like(x0),
        offset=x[nb + nd : nfix],
        form="simulation error" if simulated else "equation error",
        fitted={e for e, _ in segs} if simulated else set(),
    )


def _free_run(
    rec: _Record, e: int, length: int, model: _Model, bd: _BD, x0: np.ndarray
) -> Iterator[tuple[int, np.ndarray, np.ndarray]]:
    """The model's output over experiment ``e`` from the initial state ``x0``, in chunks.

    Yields ``(first sample, simulated (rows, l), the regressors of x0 (l, rows, n))``.
    """
    feed = bool(np.any(bd.d))
    parts = [bd.b.T.reshape(-1), bd.d.reshape(-1) if feed else np.zeros(0), bd.offset, x0]
    coef = np.concatenate(parts)
    at = 0
    for phi, _ in _equation_rows(rec, e, length, model, feed, True):
        rows = phi.shape[1]
        with np.errstate(all="ignore"):
            yield at, np.einsum("jrp,p->rj", phi, coef), phi[:, :, -model.n :]
        at += rows


def _heldout_fit(rec: _Record, model: _Model, bd: _BD, split: int) -> float:
    """Free-run fit % on the samples from ``split`` on (mean over outputs; see the module).

    An experiment in the fit runs on from its fitted initial state; one that starts after
    ``split`` from the initial state fitted to its own samples (``B``, ``D`` fixed). The
    sums are accumulated chunk by chunk (no copy of the record).
    """
    if not model.simulated(max(rec.lengths)):
        return -math.inf
    sse, total, sq, count = np.zeros(rec.ny), np.zeros(rec.ny), np.zeros(rec.ny), 0
    for e, length in rec.segments():
        lo = max(0, split - int(rec.starts[e]) - rec.nk)
        if lo >= length:
            continue
        x0 = bd.x0[e] if e in bd.fitted else _initial_state(rec, e, length, model, bd)
        for at, sim, _ in _free_run(rec, e, length, model, bd, x0):
            first = max(lo, at)
            if first >= at + sim.shape[0]:
                continue
            y = rec.outputs(e, first, at + sim.shape[0])
            with np.errstate(all="ignore"):
                sse += np.sum((y - sim[first - at :]) ** 2, axis=0)
            total += y.sum(axis=0)
            sq += np.einsum("ij,ij->j", y, y)
            count += y.shape[0]
    if count == 0:
        return -math.inf
    spread = sq - total**2 / count
    with np.errstate(all="ignore"):
        fits = 100.0 * (1.0 - np.sqrt(sse) / np.sqrt(spread))
    fits[~np.isfinite(fits) | (spread <= 0)] = -math.inf
    return float(np.mean(fits))


def _initial_state(rec: _Record, e: int, length: int, model: _Model, bd: _BD) -> np.ndarray:
    """Least-squares initial state of experiment ``e`` with ``B``, ``D``, offset fixed."""
    n = model.n
    gram, rhs = np.zeros((n, n)), np.zeros(n)
    for at, sim, basis in _free_run(rec, e, length, model, bd, np.zeros(n)):
        rows = sim.shape[0]
        resid = (rec.outputs(e, at, at + rows) - sim).T.reshape(-1)
        flat = basis.reshape(-1, n)
        gram += flat.T @ flat
        rhs += flat.T @ resid
    return np.linalg.lstsq(gram, rhs, rcond=RCOND)[0]


# -------------------------------------------------------------------------- the order
def _choose_order(
    rec: _Record,
    first: list[tuple[int, int]],
    projections: _Projections,
    s_full: np.ndarray,
    n_max: int,
    horizon: Callable[[int], int],
    settings: Subspace,
    split: int,
) -> tuple[int, str, dict[str, float]]:
    """The order by the singular-value gaps, checked on held-out data (see the module).

    ``projections`` are of the first part; each candidate ``n`` is fitted there at its own
    horizon ``horizon(n)`` (what ``Subspace(order=n)`` would use).
    """
    top = min(n_max, s_full.size - 1)
    floor = s_full[0] * np.finfo(float).eps if s_full.size and s_full[0] > 0 else 1e-300
    s = np.maximum(s_full[: top + 1], floor)
    gaps = np.log(s[:-1] / s[1:])  # gaps[n-1]: s_n / s_(n+1)
    ranked = [int(g) + 1 for g in np.argsort(-gaps, kind="stable")[:GAPS]]
    clear = bool(gaps[ranked[0] - 1] >= math.log(CLEAR_GAP))
    candidates = sorted({o for n in ranked for o in (n - 1, n, n + 1) if 1 <= o <= top})
    if not clear:
        candidates = list(range(1, top + 1))
    scores: dict[str, float] = {}
    for order in candidates:
        try:
            model = _Model(*projections.a_c(horizon(order), order, settings.stable))
            bd = _fit_bd(rec, first, model, settings.feedthrough)
            score = _heldout_fit(rec, model, bd, split)
        except (np.linalg.LinAlgError, ValueError):
            score = -math.inf
        scores[str(order)] = score if math.isfinite(score) else -math.inf
    best = max(scores.values())
    gap_text = ", ".join(f"s{n}/s{n + 1} = {math.exp(gaps[n - 1]):.3g}" for n in ranked)
    where = (
        f"around the largest singular-value gaps, {gap_text}"
        if clear
        else f"every order: no gap reaches {CLEAR_GAP:g} ({gap_text})"
    )
    if not math.isfinite(best):
        order = ranked[0]
        why = (
            f"order {order}: the largest singular-value gap ({gap_text}); every candidate "
            f"{candidates} diverged on the held-out third, so the gap alone decides"
        )
        return order, why, scores
    order = min(int(o) for o, v in scores.items() if v >= best - PARSIMONY)
    best_order = max(scores, key=lambda o: scores[o])
    why = (
        f"order {order}: the lowest of the candidates {candidates} ({where}) whose free-run "
        f"fit on the held-out last third ({scores[str(order)]:.2f} %) is within "
        f"{PARSIMONY:g} point(s) of the best (order {best_order}: {best:.2f} %), each fitted "
        "on the first two thirds"
    )
    return order, why, scores


# ---------------------------------------------------------------------------- the model
@dataclass
class _Fit:
    """A fitted state space in original units, and how its order was found."""

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
        rec: _Record,
        model: _Model,
        bd: _BD,
        horizon: int,
        order: int,
        reason: str,
        scores: dict[str, float],
        sv: np.ndarray,
    ) -> _Fit:
        """The fit of scaled data written in the record's units.

        In the record's units the model is ``x(t+1) = A x + B (u(t-nk) - u_mean) + x_bias``,
        ``y = C x + D (u(t-nk) - u_mean) + y_bias``; multiplying by ``A(q)`` gives
        ``A(q) y = N(q) u + k`` with ``k = A(1) y_bias + N_bias(1) - N(1) u_mean``
        (``N_bias = sum_k C M_k x_bias z^-k``, the constant input's numerator).
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
        """
        start = 0 if feedthrough else 1
        pad = (0, order - self.order)
        nums = [-np.pad(self.num[j, i, start:], pad) for i in range(self.num.shape[1])]
        theta = np.concatenate([np.pad(self.den, pad), *nums])
        scale = float(np.linalg.norm(theta))
        return theta / scale, float(self.intercept[j]) / scale
