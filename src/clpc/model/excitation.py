"""Persistent excitation: the order an input record excites, and the order a structure needs.

The input must be persistently exciting (PE) of the order the structure needs,
:func:`needed_order` ``= na + nb + 1`` (``nb + 1`` numerator coefficients per input in
clpc's convention). Two models ``B1/A1`` and ``B2/A2`` of the structure give the same
output for an input ``u`` when ``(B1 A2 - B2 A1) u = 0``; that polynomial has
``na + nb + 1`` coefficients, so only an input PE of that order tells every two models
apart (Ljung 1999, *System Identification*, 2nd ed., section 13.2, theorem 13.1: order
``nb + nf`` for ``G = B/F`` in open loop; Gevers, Bazanella, Bombois and Miskovic 2009,
IEEE TAC 54(12): the minimal richness per model structure). Least squares under white
*equation* noise needs only order ``nb + 1`` for consistency (Soderstrom and Stoica 1989,
*System Identification*, chapter 5), because that noise excites ``1/A`` as well; LPC's
errors-in-variables noise and OE's output noise do not pass through the system, so the
stricter rule applies to them, and clpc applies it to every estimator.

:func:`excitation_order` measures the order of a record (:data:`EXCITATION_RTOL`, its one
threshold); :func:`excitation_entries` is the evidence a fit offers its verdict
(:mod:`clpc.model.identifiability`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from clpc.core.solution import CONSTANT_CHANNEL_RELATIVE_STD

__all__ = [
    "EXCITATION_RTOL",
    "excitation_entries",
    "excitation_order",
    "excitation_ratios",
    "inputs_of",
    "needed_order",
    "stored_excitation",
]

#: An input is PE of order ``n`` when the smallest singular value of its centered ``n``-lag
#: vectors is at least this fraction of the largest (``sqrt`` of the eigenvalue ratio of
#: their covariance). Below it the least excited direction holds under 1e-10 of the
#: input's power (100 dB down): the quantization of a 16-bit converter at full scale
#: (98 dB), the rounding of a log written with 5-6 significant digits or in float32 - the
#: recording, not the experiment; and a measured input's noise does not excite the plant
#: (errors in variables). Forming the covariance resolves ratios down to about 1e-7 in
#: double precision, so a smaller threshold would judge rounding. The shipped records
#: (joint input, ``docs/method.md``): dryer, ball-beam, exchanger, winding, industrial
#: dryer and CD-player arm are PE of order 13 and more (N = 6 with ``na = nb = N``); the
#: robot arm (a band-limited periodic sweep) of order 12, cascaded tanks of order 8 (its
#: 1e-4 quantization floor lies at 0.8-1e-5).
EXCITATION_RTOL = 1e-5


def _lag_sums(x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Sums over the complete ``n``-lag vectors of one experiment ``x`` (T, m).

    Returns ``S`` (n, m, n, m), ``S[i, p, j, q] = sum_t x(t-i, p) x(t-j, q)``, the sums
    ``s`` (n, m) and the number of lag vectors (``t = n-1 .. T-1``). Each lag ``k`` costs
    one product of two views over the record, ``F_k = sum_s x(s) x(s-k)^T``, less the at
    most ``n`` terms at each end outside the rows: O(T n m^2) time, no lag matrix.
    """
    t_len, m = x.shape
    rows = t_len - n + 1
    big = np.zeros((n, m, n, m))
    if rows <= 0:
        return big, np.zeros((n, m)), 0
    for k in range(n):
        full = x[k:].T @ x[: t_len - k]
        for i in range(n - k):
            head = x[k : n - 1 - i].T @ x[: n - 1 - i - k]  # s = k .. n-2-i
            tail = x[t_len - i :].T @ x[t_len - i - k : t_len - k]  # s = T-i .. T-1
            block = full - head - tail
            big[i, :, i + k, :] = block
            big[i + k, :, i, :] = block.T
    sums = np.array([x[n - 1 - i : t_len - i].sum(axis=0) for i in range(n)])
    return big, sums, rows


def excitation_ratios(
    u: Any, max_order: int, experiments: Sequence[int] | None = None
) -> np.ndarray:
    """Smallest over largest singular value of the centered ``n``-lag input, n = 1..max_order.

    Parameters
    ----------
    u : array_like, shape (T,) or (T, m)
        Input samples (several columns: the joint input, lags of every column).
    max_order : int
        Largest number of lags ``n`` (>= 1).
    experiments : sequence of int, optional
        Samples of each experiment (summing to ``T``); lag vectors never cross a boundary.

    Returns
    -------
    ndarray, shape (max_order,)
        Entry ``n - 1``: ``sqrt(lambda_min / lambda_max)`` of the covariance of the lag
        vectors ``[u(t), .., u(t-n+1)]`` (every column) over the ``T - max_order + 1``
        complete ones of each experiment, centered by their mean; 0 for a constant input.
        Non-increasing in ``n`` (the covariances are nested).
    """
    x = np.asarray(u, dtype=np.float64)
    x = x.reshape(x.shape[0], -1)
    if int(max_order) < 1:
        raise ValueError(f"max_order must be >= 1; got {max_order!r}.")
    n, m = int(max_order), x.shape[1]
    parts = [x.shape[0]] if experiments is None else [int(e) for e in experiments]
    if sum(parts) != x.shape[0]:
        raise ValueError(f"experiments must sum to the {x.shape[0]} samples; got {parts}.")
    scale = float(np.max(np.abs(x))) if x.size else 0.0
    x = x - x.mean(axis=0)  # the sums below are of small, centered numbers
    big, sums, rows = np.zeros((n, m, n, m)), np.zeros((n, m)), 0
    for end, size in zip(np.cumsum(parts), parts, strict=True):
        b, s, r = _lag_sums(x[end - size : end], n)
        big, sums, rows = big + b, sums + s, rows + r
    out = np.zeros(n)
    if rows == 0:
        return out
    mean = sums.reshape(-1) / rows
    cov = big.reshape(n * m, n * m) / rows - np.outer(mean, mean)
    floor = (CONSTANT_CHANNEL_RELATIVE_STD * scale) ** 2  # a constant's rounding
    for k in range(1, n + 1):
        w = np.linalg.eigvalsh(cov[: k * m, : k * m])
        if not w[-1] > floor:
            break
        out[k - 1] = np.sqrt(max(w[0], 0.0) / w[-1])
    return out


def excitation_order(u: Any, max_order: int, experiments: Sequence[int] | None = None) -> int:
    """The order of persistent excitation of an input record, up to ``max_order``.

    The largest ``n <= max_order`` whose centered ``n``-lag covariance is numerically
    nonsingular: its singular-value ratio (:func:`excitation_ratios`) at least
    :data:`EXCITATION_RTOL`. A sine is PE of order 2, two sines of order 4, white noise of
    every order (``max_order``), a constant of order 0. Cost O(T max_order m^2).

    Parameters
    ----------
    u : array_like, shape (T,) or (T, m)
        Input samples; several columns are judged jointly (the joint input of a MISO
        model: ``m n`` lag columns).
    max_order : int
        Largest order checked (>= 1), e.g. :func:`needed_order`.
    experiments : sequence of int, optional
        Samples of each experiment (``IOData.experiments``).

    Returns
    -------
    int
        In ``0 .. max_order``.
    """
    ratios = excitation_ratios(u, max_order, experiments)
    return int(np.argmin(np.r_[ratios, 0.0] >= EXCITATION_RTOL))


def needed_order(structure: Any) -> int:
    """The order of persistent excitation a structure needs: ``na + nb + 1``.

    ``na`` denominator coefficients and ``nb + 1`` numerator coefficients per input (see
    the module for the rule and its sources); a MISO equation needs it of the joint input.

    Parameters
    ----------
    structure : Structure
        Orders ``na``, ``nb`` (the delay ``nk`` does not count).

    Returns
    -------
    int
    """
    return int(structure.na + structure.nb + 1)


def inputs_of(model: Any, output: int) -> list[int]:
    """The inputs output ``output``'s equation uses (``"paired"``: its own one).

    Parameters
    ----------
    model : LinearModel
        The model (its MIMO mode and number of inputs).
    output : int
        Output index.

    Returns
    -------
    list of int
    """
    return [output] if model.mode == "paired" else list(range(model.n_inputs))


def excitation_entries(model: Any, data: Any) -> dict[str, Any]:
    """The ``info`` entries of the excitation of ``model``'s record (its evidence producer).

    Parameters
    ----------
    model : LinearModel
        A model fitted on ``data`` (its structure and MIMO mode).
    data : IOData
        The record.

    Returns
    -------
    dict
        ``excitation_order`` (per output, up to the needed order), ``excitation_needed``
        (:func:`needed_order`), ``excitation_ratio`` (per output, the singular-value ratio
        at the needed order), ``excitation_threshold`` (:data:`EXCITATION_RTOL`), and
        ``output_std`` (n_outputs,) and ``input_std`` (n_inputs,), the record's channels'
        standard deviations: ``output_std[j] / input_std[i]`` is the gain that would explain
        all of an output's variation by one input
        (:func:`clpc.model.gain.assess_gain` measures a gain's sigma against it).
    """
    need = needed_order(model.structure)
    orders, ratios = [], []
    for j in range(model.n_outputs):
        r = excitation_ratios(data.u[:, inputs_of(model, j)], need, data.experiments)
        orders.append(int(np.argmin(np.r_[r, 0.0] >= EXCITATION_RTOL)))
        ratios.append(float(r[-1]))
    return {
        "excitation_order": np.array(orders),
        "excitation_needed": need,
        "excitation_ratio": np.array(ratios),
        "excitation_threshold": EXCITATION_RTOL,
        "output_std": np.std(data.y, axis=0),
        "input_std": np.std(data.u, axis=0),
    }


def stored_excitation(info: Any, output: int) -> tuple[int, int, float, float] | None:
    """What a fit's ``info`` says of its record's excitation, for one output.

    Parameters
    ----------
    info : mapping
        A model's ``info`` (reading ``"excitation_order"`` computes the entries of
        :func:`excitation_entries` when the model keeps its record).
    output : int
        Output index.

    Returns
    -------
    tuple or None
        ``(order, needed, ratio, threshold)``, or ``None`` when ``info`` has none.
    """
    if "excitation_order" not in info:
        return None
    return (
        int(np.atleast_1d(info["excitation_order"])[output]),
        int(info["excitation_needed"]),
        float(np.atleast_1d(info["excitation_ratio"])[output]),
        float(info.get("excitation_threshold", EXCITATION_RTOL)),
    )
