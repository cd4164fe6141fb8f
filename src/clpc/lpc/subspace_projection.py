"""Step 2 of :mod:`clpc.lpc.subspace`: the block-Hankel data, its R factor, ``A`` and ``C``.

Column ``j`` of the stacked data matrix is ``[U_f | 1 | W_p | Y_f]`` at ``i`` block rows
(:func:`block_rows`); its R factor is built chunk by chunk (:func:`hankel_r`: O(T) time, one
chunk of memory) and the SVD of the block ``L32`` (``Y_f`` on ``W_p``) gives the extended
observability matrix, ``C`` and ``A`` (:class:`Projections`), at any horizon up to the
factored one without another pass over the data.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy.linalg import lapack

from clpc.core.polynomials import UNIT_CIRCLE_TOL
from clpc.data import DataError
from clpc.lpc.subspace_record import CHUNK_ELEMENTS, ScaledRecord

__all__ = ["Projections", "block_rows", "data_rows", "hankel_columns", "hankel_r"]


def data_rows(i: int, m: int, ny: int) -> int:
    """Rows ``2 i (m + ny) + 1`` of the stacked data matrix (the R factor's size).

    Parameters
    ----------
    i : int
        Block rows (past and future).
    m, ny : int
        Inputs and outputs.
    """
    return 2 * i * (m + ny) + 1


def hankel_columns(segs: list[tuple[int, int]], i: int) -> int:
    """Hankel columns ``sum(max(0, samples - 2 i + 1))`` of ``segs`` (inside each experiment).

    Parameters
    ----------
    segs : list of (int, int)
        ``(experiment, samples)`` (:meth:`ScaledRecord.segments`).
    i : int
        Block rows.
    """
    return sum(max(0, n - 2 * i + 1) for _, n in segs)


def block_rows(
    rec: ScaledRecord, segs: list[tuple[int, int]], order: int, auto: bool, horizon: int | None
) -> int:
    """Block rows ``i`` for ``order`` (see :mod:`clpc.lpc.subspace`), checked against ``segs``.

    Parameters
    ----------
    rec : ScaledRecord
        The record (its inputs, outputs and delay).
    segs : list of (int, int)
        The part of the record the data matrix is built from (:meth:`ScaledRecord.segments`).
    order : int
        State dimension ``n``.
    auto : bool
        Whether ``segs`` is the first part of an ``order="auto"`` fit (the messages say so).
    horizon : int, optional
        Block rows asked for (:attr:`clpc.lpc.subspace.Subspace.horizon`); default: chosen.

    Returns
    -------
    int
        ``horizon`` when given; else ``max(ceil(2 n / l), 10)``, lowered while ``segs`` has
        fewer Hankel columns than the data matrix has rows.

    Raises
    ------
    ValueError
        ``horizon`` below ``ceil(n / l) + 1``.
    DataError
        ``segs`` too short for the horizon (given) or for ``ceil(n / l) + 1`` block rows.
    """
    m, ny = rec.m, rec.ny
    low = -(-order // ny) + 1
    what = "the first two thirds of the record (order='auto')" if auto else "the record"
    if horizon is not None:
        i = int(horizon)
        if i < low:
            raise ValueError(
                f"horizon={i} is too small for order {order} with {ny} output(s): the "
                f"shift of the observability matrix needs horizon >= {low} "
                "(ceil(order / n_outputs) + 1). Raise horizon or lower the order."
            )
        if hankel_columns(segs, i) < data_rows(i, m, ny):
            raise DataError(
                f"A subspace fit with horizon {i} needs at least {data_rows(i, m, ny)} Hankel "
                f"columns (2 i (m + l) + 1, m inputs, l outputs); {what} gives "
                f"{hankel_columns(segs, i)} (after the delay nk={rec.nk}). Use a longer record "
                "or a smaller horizon."
            )
        return i
    i = max(-(-2 * order // ny), 10)
    while i > low and hankel_columns(segs, i) < data_rows(i, m, ny):
        i -= 1
    if hankel_columns(segs, i) < data_rows(i, m, ny):
        used = sum(length for _, length in segs)
        need = 2 * low * (m + ny + 1)
        raise DataError(
            f"A subspace fit of order {order} needs horizon >= {low} and so about {need} "
            f"samples in {what} (after the delay nk={rec.nk}); there are {used}. Use a "
            "longer record or a lower order (max_order for order='auto')."
        )
    return i


def hankel_r(
    rec: ScaledRecord, segs: list[tuple[int, int]], i: int, first: list[tuple[int, int]] | None
) -> tuple[np.ndarray, np.ndarray | None]:
    """R factor of the transposed data matrix, chunk by chunk (and of its ``first`` part).

    The columns of ``first`` (a prefix of each experiment, experiments in order) come first,
    so their R is a by-product: copied when they are done, then the rest is added.

    Parameters
    ----------
    rec : ScaledRecord
        The record.
    segs : list of (int, int)
        The whole part used (:meth:`ScaledRecord.segments`).
    i : int
        Block rows.
    first : list of (int, int), optional
        A prefix of ``segs`` whose R factor is returned too.

    Returns
    -------
    r : numpy.ndarray, shape (K, K)
        Upper-triangular R of ``segs`` (``K`` = :func:`data_rows`).
    r_first : numpy.ndarray, shape (K, K), or None
        The R of ``first`` (None without ``first``).
    """
    m, ny = rec.m, rec.ny
    k = data_rows(i, m, ny)
    chunk = min(max(4 * k, CHUNK_ELEMENTS // k), max(hankel_columns(segs, i), 1))
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


def _fill(work: np.ndarray, rec: ScaledRecord, e: int, a: int, b: int, i: int, k: int) -> None:
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


class Projections:
    """The SVD of ``L32`` at each horizon, from one R factor (see :func:`_sub_r`).

    Parameters
    ----------
    r : numpy.ndarray, shape (K, K)
        R factor of the data matrix at ``i`` block rows (:func:`hankel_r`).
    i : int
        Its block rows.
    m, ny : int
        Inputs and outputs.
    """

    def __init__(self, r: np.ndarray, i: int, m: int, ny: int) -> None:
        self.r, self.i, self.m, self.ny = r, i, m, ny
        self.svds: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def at(self, i2: int) -> tuple[np.ndarray, np.ndarray]:
        """Left singular vectors and singular values of ``L32`` at ``i2`` block rows.

        Parameters
        ----------
        i2 : int
            Block rows, at most ``i``.

        Returns
        -------
        left : numpy.ndarray, shape (i2 l, i2 l)
            Left singular vectors.
        s : numpy.ndarray, shape (i2 l,)
            Singular values, descending (scaled units).
        """
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

        Parameters
        ----------
        i2 : int
            Block rows, at most ``i``.
        n : int
            Order.
        stable : bool
            Replace an unstable shift estimate by Maciejowski's.

        Returns
        -------
        a : numpy.ndarray, shape (n, n)
            ``A``.
        c : numpy.ndarray, shape (l, n)
            ``C`` (scaled outputs).
        how : str
            ``"shift"`` or ``"stabilised shift (Maciejowski)"``.
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
