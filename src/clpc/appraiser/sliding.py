r"""Exact sliding-window scatter matrices, vectorised over windows.

CLPC (section V) updates every ``C`` lag vectors on the last ``W`` of them. The update that
closes after lag vector ``m = C j`` uses rows ``[max(0, m - W), m)``. Write ``W = q C + r``
and cut the lag rows into blocks ``[l C, (l + 1) C)``; a window then is::

    tail of block j-q-1 (its last r rows)  +  blocks j-q, ..., j-1 (full)
    \________ r rows ____________________/    \_______ q C rows ________/

(while the window is still growing, blocks 0..j-1 only). Each piece is summarised by its
count, mean and centered scatter (two-pass, exact), and pieces are merged with the parallel
formula of Chan, Golub and LeVeque::

    n = sum n_b,   mean = sum n_b mean_b / n,
    A = sum A_b + sum n_b (mean_b - mean)(mean_b - mean)^T

Every term is centered, so large offsets (positions around 1e4 rad) and long records (the
statistics are never accumulated over the record) lose no digits. Cost per window is
``O((q + 1) p^2)`` plus ``O(C p^2)`` per block, instead of ``O(W p^2)``.
"""

from __future__ import annotations

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

__all__ = ["block_stats", "window_scatter"]

# with more pieces than this per window (small clusters, e.g. an update every sample) the
# windows come from prefix sums re-centered on each batch of windows instead of merged blocks
_PREFIX_ABOVE_PIECES = 32


def block_stats(rows: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and centered scatter of consecutive blocks of rows.

    Parameters
    ----------
    rows : ndarray, shape (E, n_blocks * size, p)
        Lag rows of ``E`` equations.
    size : int
        Rows per block (> 0).

    Returns
    -------
    mean : ndarray, shape (E, n_blocks, p)
    scatter : ndarray, shape (E, n_blocks, p, p)
    """
    e, n, p = rows.shape
    blocks = rows.reshape(e, n // size, size, p)
    mean = blocks.mean(axis=2)
    centered = blocks - mean[:, :, None, :]
    scatter = np.swapaxes(centered, -1, -2) @ centered
    return mean, scatter


def window_scatter(
    rows: np.ndarray, first_row: int, first_window: int, n_windows: int, window: int, cluster: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Scatter matrices of consecutive CLPC windows.

    Parameters
    ----------
    rows : ndarray, shape (E, n, p)
        Lag rows with absolute row indices ``first_row .. first_row + n - 1``; they must
        cover every requested window ``[max(0, C j - W), C j)``.
    first_row : int
        Absolute index of ``rows[:, 0]``.
    first_window, n_windows : int
        The windows closing after rows ``C j`` for ``j = first_window .. first_window +
        n_windows - 1`` (``first_window >= 1``).
    window, cluster : int
        ``W`` and ``C``.

    Returns
    -------
    scatter : ndarray, shape (E, n_windows, p, p)
    mean : ndarray, shape (E, n_windows, p)
    n_rows : ndarray of int, shape (n_windows,)
    """
    e, n, p = rows.shape
    q, r = divmod(window, cluster)
    if q > _PREFIX_ABOVE_PIECES:
        return _prefix_windows(rows, first_row, first_window, n_windows, window, cluster)
    j0, j1 = first_window, first_window + n_windows
    lo_block = max(j0 - q - (1 if r else 0), 0)
    start = lo_block * cluster - first_row
    if start < 0 or (j1 - 1) * cluster - first_row > n:
        raise ValueError("rows do not cover the requested windows")  # internal misuse
    span = rows[:, start : start + (j1 - 1 - lo_block) * cluster]
    f_mean, f_scat = block_stats(span, cluster)  # (E, n_blocks, p), (E, n_blocks, p, p)
    pieces = [(-q + o, cluster, f_mean, f_scat) for o in range(q)]
    if r:
        tails = span.reshape(e, -1, cluster, p)[:, :, cluster - r :, :]
        t_mean, t_scat = block_stats(tails.reshape(e, -1, p), r)
        pieces.append((-q - 1, r, t_mean, t_scat))
    # windows whose pieces all exist (the window has stopped growing) ...
    j_full = max(j0, q + (1 if r else 0))
    out_s = np.empty((e, n_windows, p, p))
    out_m = np.empty((e, n_windows, p))
    out_n = np.empty(n_windows, dtype=np.int64)
    if j_full < j1:
        sel = slice(j_full - j0, n_windows)
        tail = (t_mean, t_scat) if r else None
        out_s[:, sel], out_m[:, sel] = _merge_full(
            f_mean, f_scat, tail, j_full - lo_block, j1 - j_full, q, cluster, r
        )
        out_n[sel] = window
    # ... and the first ones, still growing (at most q + 1 of them): pieces may not exist
    for jj in range(j0, min(j_full, j1)):
        use = [pc for pc in pieces if jj + pc[0] >= 0]
        s_, m_, n_ = _merge_slices(use, jj - lo_block, 1)
        out_s[:, jj - j0], out_m[:, jj - j0], out_n[jj - j0] = s_[:, 0], m_[:, 0], n_[0]
    return out_s, out_m, out_n


def _merge_full(
    f_mean: np.ndarray,
    f_scat: np.ndarray,
    tail: tuple[np.ndarray, np.ndarray] | None,
    first: int,
    count: int,
    q: int,
    cluster: int,
    r: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Merge ``q`` full blocks (+ a tail) for ``count`` consecutive full windows at once.

    Window ``w`` uses full blocks ``first + w - q .. first + w - 1`` and the tail of block
    ``first + w - q - 1``; strided views stack the pieces without copying the scatters.
    """
    lo = first - q
    means = sliding_window_view(f_mean[:, lo : lo + count + q - 1], q, axis=1)  # (E,k,p,q)
    within = f_scat[:, lo : lo + count].copy()
    for o in range(1, q):  # a loop over the q blocks of a window, vectorised over windows
        within += f_scat[:, lo + o : lo + o + count]
    weights = np.full(q, float(cluster))
    if tail is not None:
        t_mean, t_scat = tail
        means = np.concatenate([means, t_mean[:, lo - 1 : lo - 1 + count, :, None]], axis=-1)
        within += t_scat[:, lo - 1 : lo - 1 + count]
        weights = np.append(weights, float(r))
    mean = means @ (weights / weights.sum())  # (E, k, p)
    dev = means - mean[..., None]
    dev *= np.sqrt(weights)  # in place: large temporaries cost more than the arithmetic
    within += dev @ np.swapaxes(dev, -1, -2)
    return within, mean


def _merge_slices(
    pieces: list[tuple[int, int, np.ndarray, np.ndarray]], first: int, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Merge pieces for ``count`` consecutive windows (parallel formula of the module docstring).

    Piece offset ``o`` of window ``w`` is block ``first + w + o``.
    """
    n_rows = float(sum(size for _, size, _, _ in pieces))
    total = sum(size * means[:, first + o : first + o + count] for o, size, means, _ in pieces)
    mean = total / n_rows
    scatter = sum(scats[:, first + o : first + o + count] for o, _, _, scats in pieces)
    for o, size, means, _ in pieces:
        dev = means[:, first + o : first + o + count] - mean
        scatter = scatter + size * (dev[..., :, None] * dev[..., None, :])
    return scatter, mean, np.full(count, int(n_rows), dtype=np.int64)


def _prefix_windows(
    rows: np.ndarray, first_row: int, first_window: int, n_windows: int, window: int, cluster: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Windows from prefix sums of the rows re-centered on the batch's own mean.

    ``A = S2 - S1 S1^T / n`` with ``S1``, ``S2`` the sums of ``z - shift`` and of its outer
    products over the window. The shift is the mean of the rows the batch spans, so the
    cancellation costs about ``eps (spread of the batch / spread of a window)^2`` - the
    periodic re-centering that keeps long records and large offsets exact to ~1e-12, at
    ``O(p^2)`` per window whatever the cluster size (for small clusters, where merging
    ``W / C`` blocks would cost ``O(W p^2 / C)``).
    """
    e, _n, p = rows.shape
    ends = (first_window + np.arange(n_windows)) * cluster  # exclusive, absolute
    starts = np.maximum(ends - window, 0)
    lo, hi = int(starts[0]), int(ends[-1])
    span = rows[:, lo - first_row : hi - first_row]
    shift = span.mean(axis=1, keepdims=True)
    z = span - shift
    c1 = np.zeros((e, z.shape[1] + 1, p))
    np.cumsum(z, axis=1, out=c1[:, 1:])
    c2 = np.zeros((e, z.shape[1] + 1, p, p))
    np.cumsum(z[..., :, None] * z[..., None, :], axis=1, out=c2[:, 1:])
    a, b = starts - lo, ends - lo
    n_rows = (ends - starts).astype(np.float64)
    s1 = c1[:, b] - c1[:, a]
    s2 = c2[:, b] - c2[:, a]
    mean_dev = s1 / n_rows[None, :, None]
    scatter = s2 - s1[..., :, None] * mean_dev[..., None, :]
    scatter = 0.5 * (scatter + np.swapaxes(scatter, -1, -2))
    return scatter, shift + mean_dev, (ends - starts).astype(np.int64)
