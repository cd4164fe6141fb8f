"""Step 3 of :mod:`clpc.lpc.subspace`: ``B``, ``D``, initial states and offset by least squares.

With ``A`` and ``C`` fixed (:class:`~clpc.lpc.subspace_dynamics.StateDynamics`: their
characteristic polynomial and the maps ``M_k`` of Cayley-Hamilton) the output is linear in
``B``, ``D``, the initial state of each experiment and the constant input's columns;
:func:`fit_bd` minimises the simulation error over the record (the R factor of the
regressors accumulated chunk by chunk), or the equation error when a free run would grow
past :data:`~clpc.lpc.subspace_dynamics.MAX_GROWTH`. :func:`free_run` runs the fitted model
over an experiment from a given initial state; :func:`initial_state` fits that state with
``B``, ``D`` fixed.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from scipy.linalg import lapack

from clpc.core.filters import all_pole
from clpc.lpc.subspace_dynamics import StateDynamics
from clpc.lpc.subspace_record import ScaledRecord

__all__ = [
    "LS_CHUNK",
    "RCOND",
    "BDFit",
    "fit_bd",
    "free_run",
    "initial_state",
]

#: Samples per chunk of the least-squares pass for B and D.
LS_CHUNK = 8192
#: Relative singular-value cut of the small least-squares solve (initial state and offset
#: are collinear for an integrating model).
RCOND = 1e-10


@dataclass
class BDFit:
    """The least-squares solution of step 3 (scaled units).

    Attributes
    ----------
    b : numpy.ndarray, shape (n, m + 1)
        ``B``, then the constant input's column (the state's bias).
    d : numpy.ndarray, shape (l, m)
        ``D`` (zeros without feedthrough).
    x0 : numpy.ndarray, shape (n_experiments, n)
        Initial state of each experiment (zeros where not fitted).
    offset : numpy.ndarray, shape (l,)
        The output's bias (the constant input's ``D``).
    form : str
        ``"simulation error"`` or ``"equation error"``.
    fitted : set of int
        The experiments whose initial state was fitted.
    """

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
    rec: ScaledRecord, e: int, length: int, model: StateDynamics, feedthrough: bool, simulated: bool
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


def fit_bd(
    rec: ScaledRecord, segs: list[tuple[int, int]], model: StateDynamics, feedthrough: bool
) -> BDFit:
    """``B``, ``D``, initial states and offset by least squares over ``segs`` (step 3).

    Parameters
    ----------
    rec : ScaledRecord
        The record.
    segs : list of (int, int)
        ``(experiment, samples)`` fitted (:meth:`ScaledRecord.segments`).
    model : StateDynamics
        ``A`` and ``C``.
    feedthrough : bool
        Estimate ``D`` (else ``D = 0``).

    Returns
    -------
    BDFit
        The solution, in the simulation-error form when :meth:`StateDynamics.simulated`
        over the longest segment, else the equation-error form (no initial states).
    """
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
    return BDFit(
        b=x[:nb].reshape(m + 1, n).T,
        d=x[nb : nb + nd].reshape(ny, m) if feedthrough else np.zeros((ny, m)),
        x0=x0 if simulated else np.zeros_like(x0),
        offset=x[nb + nd : nfix],
        form="simulation error" if simulated else "equation error",
        fitted={e for e, _ in segs} if simulated else set(),
    )


def free_run(
    rec: ScaledRecord, e: int, length: int, model: StateDynamics, bd: BDFit, x0: np.ndarray
) -> Iterator[tuple[int, np.ndarray, np.ndarray]]:
    """The model's output over experiment ``e`` from the initial state ``x0``, in chunks.

    Parameters
    ----------
    rec : ScaledRecord
        The record (its inputs drive the run).
    e : int
        Experiment index.
    length : int
        Samples run from the experiment's start.
    model : StateDynamics
        ``A`` and ``C``.
    bd : BDFit
        ``B``, ``D`` and the offset.
    x0 : numpy.ndarray, shape (n,)
        Initial state.

    Yields
    ------
    at : int
        First sample of the chunk.
    simulated : numpy.ndarray, shape (rows, l)
        The scaled output the model gives.
    basis : numpy.ndarray, shape (l, rows, n)
        The regressors of ``x0`` (the output is linear in it).
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


def initial_state(
    rec: ScaledRecord, e: int, length: int, model: StateDynamics, bd: BDFit
) -> np.ndarray:
    """Least-squares initial state of experiment ``e`` with ``B``, ``D``, offset fixed.

    Parameters
    ----------
    rec : ScaledRecord
        The record.
    e : int
        Experiment index.
    length : int
        Samples fitted from the experiment's start.
    model : StateDynamics
        ``A`` and ``C``.
    bd : BDFit
        ``B``, ``D`` and the offset.

    Returns
    -------
    numpy.ndarray, shape (n,)
        The initial state (scaled units).
    """
    n = model.n
    gram, rhs = np.zeros((n, n)), np.zeros(n)
    for at, sim, basis in free_run(rec, e, length, model, bd, np.zeros(n)):
        rows = sim.shape[0]
        resid = (rec.outputs(e, at, at + rows) - sim).T.reshape(-1)
        flat = basis.reshape(-1, n)
        gram += flat.T @ flat
        rhs += flat.T @ resid
    return np.linalg.lstsq(gram, rhs, rcond=RCOND)[0]
