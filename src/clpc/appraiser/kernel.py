r"""The compiled CLPC engine: block statistics, window merge and LPC solve in one kernel.

The numpy engine (:mod:`clpc.sliding` + :func:`clpc.solve.solve_scatter`) is vectorised over
windows but pays a LAPACK call (~4 us) per 6x6 matrix, two of them with the robust default,
plus numpy's per-call overhead on small arrays. This module does the same computation for
one window after the other inside numba-compiled loops (:mod:`clpc.small_eigh` for the
eigenproblems), with no temporaries: about 9-10x the plain per-window reference instead of
~4.5x (``benchmarks/bench_clpc.py``). It is used when numba is installed (``CLPC(engine=...)``).

The arithmetic is the numpy engine's, not its bit pattern (different eigen-solver, merge
order): the two agree to ~1e-12 (``tests/test_window_kernel.py``). Within this engine, a
window's numbers depend only on its own rows, never on how a record was chunked, so
``run``, ``push`` in any chunks and ``step`` give bit-identical results.

Per window ``[s, e)`` (``e = C j``, ``s = max(0, e - W)``) the pieces are the full blocks
``[l C, (l + 1) C)`` inside it (statistics computed once per block, two-pass) and, when
``s`` is not a block boundary, the tail of block ``s // C`` (its last ``e - s`` mod ``C``
rows, computed per window); they are merged with the formula of Chan, Golub and LeVeque
(:mod:`clpc.sliding`), so offsets and long records lose no digits.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from clpc.core import small_eigh
from clpc.lpc.solve import ROUNDING_VARIANCE_FACTOR

_ROUNDING_VARIANCE = ROUNDING_VARIANCE_FACTOR * float(np.finfo(np.float64).eps)

__all__ = ["solve_windows"]

_jit = numba.njit(cache=True, nogil=True, error_model="numpy")

_tred2 = _jit(small_eigh._tred2)
_tql2 = _jit(small_eigh._tql2)


@_jit
def _sym_eig(a, d, v, e, vectors):  # pragma: no cover - compiled
    """:func:`clpc.small_eigh.sym_eig` with the compiled pieces."""
    n = a.shape[0]
    for i in range(n):
        for j in range(n):
            v[i, j] = a[i, j]
    _tred2(v, d, e, n)
    return _tql2(v, d, e, n, vectors)


# transform modes of the solved problem T^T A T
NO_TRANSFORM, CHANNEL_SCALES, FIXED_TRANSFORM = 0, 1, 2
# layout of the float options vector
OPT_MIN_A0, OPT_RATIO, OPT_ZERO_TOL, OPT_MIN_OUTPUT = 0, 1, 2, 3


@_jit
def _piece_stats(samples, chan, lag, first, lo, hi, z, mean, scat):  # pragma: no cover
    """Mean and centered scatter (two-pass) of lag rows ``lo .. hi - 1`` of one equation.

    Row ``r`` is the lag vector whose newest sample is ``samples[first + r]``; its entry
    ``a`` is ``samples[first + r - lag[a], chan[a]]`` (built on the fly into ``z``).
    """
    p = mean.shape[0]
    n = hi - lo
    for a in range(p):
        mean[a] = 0.0
        for b in range(a + 1):
            scat[a, b] = 0.0
    for r in range(lo, hi):
        for a in range(p):
            mean[a] += samples[first + r - lag[a], chan[a]]
    for a in range(p):
        mean[a] /= n
    for r in range(lo, hi):
        for a in range(p):
            z[a] = samples[first + r - lag[a], chan[a]] - mean[a]
        for a in range(p):
            for b in range(a + 1):
                scat[a, b] += z[a] * z[b]
    for a in range(p):
        for b in range(a):
            scat[b, a] = scat[a, b]


@_jit
def _merge(b_mean, b_scat, lo, hi, size, t_size, t_mean, t_scat, dev, mean, scat):
    """Merge blocks ``lo .. hi - 1`` (``size`` rows each) and a tail piece into one window.

    The formula of Chan, Golub and LeVeque: ``mean = sum n_k mean_k / n`` and ``A = sum A_k
    + sum n_k (mean_k - mean)(mean_k - mean)^T``; the tail (``t_size`` rows, skipped when 0)
    is the first piece. ``dev`` is work space of shape (pieces, p). Returns ``n``.
    """  # pragma: no cover - compiled
    p = mean.shape[0]
    total = t_size + size * (hi - lo)
    for a in range(p):
        acc = t_size * t_mean[a] if t_size > 0 else 0.0
        for k in range(lo, hi):
            acc += size * b_mean[k, a]
        mean[a] = acc / total
    root = math.sqrt(size)
    t_root = math.sqrt(t_size)
    for a in range(p):
        dev[0, a] = t_root * (t_mean[a] - mean[a]) if t_size > 0 else 0.0
        for k in range(lo, hi):
            dev[k - lo + 1, a] = root * (b_mean[k, a] - mean[a])
    n_dev = hi - lo + 1
    for a in range(p):
        for b in range(a + 1):
            acc = t_scat[a, b] if t_size > 0 else 0.0
            for k in range(lo, hi):
                acc += b_scat[k, a, b]
            for k in range(n_dev):
                acc += dev[k, a] * dev[k, b]
            scat[a, b] = acc
            scat[b, a] = acc
    return float(total)


@_jit
def _solve_one(
    scat,
    mean,
    n_rows,
    col_channel,
    n_channels,
    n_out_cols,
    transform_mode,
    transform,
    robust,
    opts,
    work,
    out_theta,
    out_vals,
):  # pragma: no cover - compiled
    """LPC of one window (see :func:`clpc.solve.solve_scatter`, same rules).

    Returns ``(c, noise_variance, separation, a0_weight, n_null, n_input, degenerate)``.
    """
    p = scat.shape[0]
    mat, vals, vecs, ework, tmat, raw, phi, scales = work
    n_safe = max(n_rows, 1.0)
    finite = True
    for a in range(p):
        for b in range(p):
            if not math.isfinite(scat[a, b]):
                finite = False
    # ---- the solved problem T^T A T
    if transform_mode == CHANNEL_SCALES:
        for ch in range(n_channels):
            acc = 0.0
            cnt = 0
            for a in range(p):
                if col_channel[a] == ch:
                    acc += scat[a, a]
                    cnt += 1
            std = math.sqrt(max(acc / cnt, 0.0) / n_safe)
            for a in range(p):
                if col_channel[a] == ch:
                    scales[a] = std if std > 0 else 1.0
        for a in range(p):
            for b in range(p):
                tmat[a, b] = 0.0
            tmat[a, a] = 1.0 / scales[a]
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b] / (scales[a] * scales[b])
    elif transform_mode == FIXED_TRANSFORM:
        for a in range(p):
            for b in range(p):
                tmat[a, b] = transform[a, b]
        # mat = T^T A T, symmetrised
        for a in range(p):
            for b in range(p):
                acc = 0.0
                for k in range(p):
                    for m in range(p):
                        acc += tmat[k, a] * scat[k, m] * tmat[m, b]
                mat[a, b] = acc
        for a in range(p):
            for b in range(a):
                sym = 0.5 * (mat[a, b] + mat[b, a])
                mat[a, b] = sym
                mat[b, a] = sym
    else:
        for a in range(p):
            for b in range(p):
                mat[a, b] = scat[a, b]
    ok = finite and _sym_eig(mat, vals, vecs, ework, True)
    if transform_mode == NO_TRANSFORM:
        for a in range(p):
            raw[a] = vals[a]
    elif ok:
        ok = _sym_eig(scat, raw, mat, ework, False)  # the paper's eigenvalues, for D
    if not ok:
        for a in range(p):
            out_theta[a] = 0.0
            out_vals[a] = 0.0
        return 0.0, 0.0, 1.0, 0.0, 1, 0, True
    # ---- degenerate: nothing varies, or a channel is constant (relative to its own size)
    top = max(raw[p - 1], 0.0)
    degenerate = not top > 0
    for ch in range(n_channels):
        var = -1.0
        size = 0.0
        for a in range(p):
            if col_channel[a] == ch:
                var = max(var, scat[a, a])
                size = max(size, abs(mean[a]))
        if var <= 1e-28 * max(top, 1e-300) or var / n_safe <= (1e-12 * size) ** 2:
            degenerate = True
    # ---- the solution in the solved problem
    min_out = opts[OPT_MIN_OUTPUT]
    if not robust:
        for a in range(p):
            phi[a] = vecs[a, 0]
        n_null = 1
        wy = 0.0
        for a in range(n_out_cols):
            wy += vecs[a, 0] ** 2
        n_input = 1 if wy < min_out else 0
        separation = _ratio(vals[0], vals[1] if p > 1 else vals[0])
    else:
        ratio = opts[OPT_RATIO]
        if not ratio > 0:  # Marchenko-Pastur edge ratio, at most 4
            x = math.sqrt(p / n_safe)
            ratio = ((1 + x) / max(1 - x, 1e-12)) ** 2 if x < 1 else math.inf
            ratio = min(ratio, 4.0)
        first = -1
        for i in range(p):
            if abs(vecs[0, i]) >= opts[OPT_MIN_A0]:
                first = i
                break
        if first < 0:  # no candidate: the eigenvector with the largest y(n) component
            best = -1.0
            for i in range(p):
                if abs(vecs[0, i]) > best:
                    best = abs(vecs[0, i])
                    first = i
        lam_s = max(vals[first], opts[OPT_ZERO_TOL] * max(vals[p - 1], 0.0))
        last = p - 1
        for i in range(first + 1, p):
            if not max(vals[i], 0.0) <= ratio * lam_s:
                last = i - 1
                break
        for a in range(p):
            phi[a] = 0.0
        n_input = 0
        for i in range(last + 1):
            w = vecs[0, i]
            for a in range(p):
                phi[a] += vecs[a, i] * w
            wy = 0.0
            for a in range(n_out_cols):
                wy += vecs[a, i] ** 2
            if wy < min_out:
                n_input += 1
        n_null = last + 1
        separation = 1.0 if last + 1 >= p else _ratio(lam_s, vals[last + 1])
    norm = 0.0
    for a in range(p):
        norm += phi[a] * phi[a]
    norm = math.sqrt(norm)
    a0_weight = abs(phi[0]) / (norm if norm > 0 else 1.0)
    # ---- theta = T phi, unit norm, a0 > 0 (else the first nonzero entry > 0)
    for a in range(p):
        if transform_mode == NO_TRANSFORM:
            out_theta[a] = phi[a]
        else:
            acc = 0.0
            for b in range(p):
                acc += tmat[a, b] * phi[b]
            out_theta[a] = acc
    norm = 0.0
    for a in range(p):
        norm += out_theta[a] * out_theta[a]
    norm = math.sqrt(norm)
    sign = 1.0
    for a in range(p):
        out_theta[a] = out_theta[a] / norm if norm > 0 else 0.0
    for a in range(p):
        if abs(out_theta[a]) > 1e-14:
            sign = -1.0 if out_theta[a] < 0 else 1.0
            break
    for a in range(p):
        out_theta[a] = 0.0 if degenerate else sign * out_theta[a]
        out_vals[a] = max(raw[a], 0.0)
    c = 0.0
    quad = 0.0
    for a in range(p):
        c += mean[a] * out_theta[a]
        acc = 0.0
        for b in range(p):
            acc += scat[a, b] * out_theta[b]
        quad += out_theta[a] * acc
    noise_variance = max(quad, 0.0) / n_safe
    if degenerate:
        a0_weight = 0.0
    return c, noise_variance, separation, a0_weight, n_null, n_input, degenerate


@_jit
def _ratio(num, den):  # pragma: no cover - compiled
    num = max(num, 0.0)
    den = max(den, 0.0)
    if not den > 0:
        return 1.0
    return min(num / den, 1.0)


@_jit
def solve_windows(
    samples,
    first_row,
    col_chan,
    col_lag,
    j0,
    count,
    window,
    cluster,
    col_channel,
    n_channels,
    n_out_cols,
    transform_mode,
    transform,
    robust,
    opts,
    theta,
    eigenvalues,
    c,
    noise_variance,
    separation,
    a0_weight,
    n_null,
    n_input,
    degenerate,
    n_rows_out,
):  # pragma: no cover - compiled
    """Solve windows ``j = j0 .. j0 + count - 1`` of every equation; fill the outputs.

    Parameters
    ----------
    samples : ndarray, shape (n, channels)
        Samples; lag row ``r`` (absolute) has its newest sample at ``samples[r - first_row]``.
    first_row, j0, count, window, cluster : int
    col_chan, col_lag : ndarray of int64, shape (E, p)
        Column ``a`` of equation ``e`` is ``samples[k - col_lag[e, a], col_chan[e, a]]``.
    col_channel : ndarray of int64, shape (p,)
        Channel block (0 = output, 1.. = inputs) of each column, for the scaling.
    n_channels, n_out_cols, transform_mode : int
    transform : ndarray, shape (p, p)
        ``T`` for ``FIXED_TRANSFORM`` (else unused).
    robust : bool
    opts : ndarray, shape (4,)
        ``min_a0_weight``, ``degeneracy_ratio`` (<= 0: Marchenko-Pastur), ``zero_tol``,
        ``min_output_weight``.
    theta, eigenvalues : ndarray, shape (count, E, p)
    c, noise_variance, separation, a0_weight : ndarray, shape (count, E)
    n_null, n_input : ndarray of int64, shape (count, E)
    degenerate : ndarray of bool, shape (count, E)
    n_rows_out : ndarray of int64, shape (count,)
    """
    n_eq, p = col_chan.shape
    first = -first_row
    # blocks touched by the windows: from the one holding the first window's start
    s_first = max(0, cluster * j0 - window)
    b_lo = s_first // cluster
    n_blocks = j0 + count - 1 - b_lo  # block j-1 is the newest of window j
    max_pieces = window // cluster + 2
    b_mean = np.empty((n_blocks, p))
    b_scat = np.empty((n_blocks, p, p))
    t_mean = np.empty(p)
    t_scat = np.empty((p, p))
    dev = np.empty((max_pieces, p))
    mean = np.empty(p)
    scat = np.empty((p, p))
    z = np.empty(p)
    work = (
        np.empty((p, p)),
        np.empty(p),
        np.empty((p, p)),
        np.empty(p),
        np.empty((p, p)),
        np.empty(p),
        np.empty(p),
        np.empty(p),
    )
    for eq in range(n_eq):
        chan = col_chan[eq]
        lag = col_lag[eq]
        for b in range(n_blocks):
            lo = (b_lo + b) * cluster
            _piece_stats(samples, chan, lag, first, lo, lo + cluster, z, b_mean[b], b_scat[b])
        for w in range(count):
            j = j0 + w
            e = cluster * j
            s = max(0, e - window)
            full_lo = -(-s // cluster)
            t_size = full_lo * cluster - s  # the tail of the block holding s, if any
            if t_size > 0:
                _piece_stats(samples, chan, lag, first, s, full_lo * cluster, z, t_mean, t_scat)
            n_w = _merge(
                b_mean,
                b_scat,
                full_lo - b_lo,
                j - b_lo,
                cluster,
                t_size,
                t_mean,
                t_scat,
                dev,
                mean,
                scat,
            )
            out = _solve_one(
                scat,
                mean,
                n_w,
                col_channel,
                n_channels,
                n_out_cols,
                transform_mode,
                transform,
                robust,
                opts,
                work,
                theta[w, eq],
                eigenvalues[w, eq],
            )
            c[w, eq] = out[0]
            noise_variance[w, eq] = out[1]
            separation[w, eq] = out[2]
            a0_weight[w, eq] = out[3]
            n_null[w, eq] = out[4]
            n_input[w, eq] = out[5]
            degenerate[w, eq] = out[6]
            n_rows_out[w] = e - s


@_jit
def finish_updates(
    theta_est,
    c_est,
    eigenvalues,
    noise_variance,
    separation,
    a0_weight,
    n_null,
    n_input,
    degenerate,
    n_rows,
    min_rows,
    gate,
    min_a0_weight,
    separation_tol,
    na,
    nb,
    nk,
    paired,
    last_theta,
    last_c,
    has_model_state,
    theta,
    c,
    accepted,
    has_model,
    determined,
    not_enough,
    den,
    num,
    stable,
    lambda_min,
    lambda_max,
    D,
    eig_ratio,
    J,
):  # pragma: no cover - compiled
    """The FSM output of solved windows, in time order (``CLPC._finish_numpy``, compiled).

    Accepts or holds each estimate, updates the carried state (``last_theta``, ``last_c``,
    ``has_model_state``, in place), and fills the monic forms, the Schur stability flag and
    the per-window statistics (see :func:`clpc.lpc.solution_info`). Shapes as in
    :func:`solve_windows`; ``den`` (count, E, na + 1), ``num`` (count, E, inputs, nk + nb
    + 1).
    """
    count, n_eq, p = theta_est.shape
    n_blocks = (p - na - 1) // (nb + 1)
    tiny = np.finfo(np.float64).tiny
    work = np.empty(na + 1)
    for w in range(count):
        few = n_rows[w] < min_rows
        not_enough[w] = few
        for e in range(n_eq):
            lo = eigenvalues[w, e, 0]
            hi = eigenvalues[w, e, p - 1]
            lambda_min[w, e] = lo
            lambda_max[w, e] = hi
            D[w, e] = hi - lo
            eig_ratio[w, e] = lo / hi if hi > 0 else 1.0
            floor = _ROUNDING_VARIANCE * max(hi, 0.0) / max(n_rows[w], 1)
            var = max(noise_variance[w, e], floor, tiny)
            J[w, e] = 0.5 * n_rows[w] * (math.log(var) + 1.0)
            det = (
                n_null[w, e] == 1
                and n_input[w, e] == 0
                and separation[w, e] <= separation_tol
                and not degenerate[w, e]
            )
            determined[w, e] = det
            ok = not few and not degenerate[w, e] and a0_weight[w, e] >= min_a0_weight
            if gate:
                ok = ok and det
            accepted[w, e] = ok
            if ok:
                for a in range(p):
                    last_theta[e, a] = theta_est[w, e, a]
                last_c[e] = c_est[w, e]
                has_model_state[e] = True
            for a in range(p):
                theta[w, e, a] = last_theta[e, a]
            c[w, e] = last_c[e]
            model = has_model_state[e]
            has_model[w, e] = model
            for i in range(num.shape[2]):
                for k in range(num.shape[3]):
                    num[w, e, i, k] = 0.0
            if model:
                a0 = last_theta[e, 0]
                for k in range(na + 1):
                    den[w, e, k] = last_theta[e, k] / a0
                for i in range(n_blocks):
                    target = e if paired else i
                    for k in range(nb + 1):
                        num[w, e, target, nk + k] = -last_theta[e, na + 1 + i * (nb + 1) + k] / a0
                stable[w, e] = _schur_stable(den[w, e], work)
            else:
                den[w, e, 0] = 1.0
                for k in range(1, na + 1):
                    den[w, e, k] = 0.0
                stable[w, e] = False


@_jit
def _schur_stable(den, a):  # pragma: no cover - compiled
    """:func:`clpc.appraiser.schur_stable` for one polynomial (``a``: work space)."""
    n = den.shape[0]
    for i in range(n):
        a[i] = den[i]
    for m in range(n - 1, 0, -1):
        k = a[m] / a[0]
        if not abs(k) < 1.0:
            return False
        scale = 1.0 - k * k
        for i in range(m // 2 + 1):  # a_i and a_{m-i} together
            lo = a[i]
            hi = a[m - i]
            a[i] = (lo - k * hi) / scale
            a[m - i] = (hi - k * lo) / scale
    return True
