"""An independent numpy formulation of the LPC solution, for tests only.

This is the vectorised numpy/LAPACK solve that clpc used before its rules were written once
in :mod:`clpc.core.rules` (array formulas over a stack of problems, LAPACK ``svd``/``eigh``
instead of clpc's own eigen-solver). Tests compare the package's single-source engine with
it window by window; it is never imported by the package.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from clpc.core.rules import RobustRule
from clpc.lpc.solve import SolveResult  # the container only; every number is computed here

_LOG_2PI = float(np.log(2.0 * np.pi))


def channel_scales(scatter: np.ndarray, n_rows: np.ndarray, blocks: list[slice]) -> np.ndarray:
    """Per-column scale: the standard deviation of each channel, repeated over its lags.

    Parameters
    ----------
    scatter : ndarray, shape (k, p, p)
    n_rows : ndarray, shape (k,)
    blocks : list of slice
        Column blocks of one channel each (output block first).

    Returns
    -------
    ndarray, shape (k, p)
        Positive scales; a constant channel gets scale 1 (it is flagged degenerate).
    """
    diag = np.diagonal(scatter, axis1=-2, axis2=-1)
    scales = np.empty_like(diag)
    n = np.maximum(n_rows, 1)[:, None]
    for block in blocks:
        std = np.sqrt(np.maximum(diag[:, block].mean(axis=1, keepdims=True), 0.0) / n)
        scales[:, block] = std
    bad = ~(scales > 0)
    scales[bad] = 1.0
    return scales


def solve_scatter(
    scatter: np.ndarray,
    mean: np.ndarray,
    n_rows: np.ndarray,
    *,
    n_output_cols: int,
    blocks: list[slice],
    method: str = "robust",
    noise_cov: np.ndarray | None = None,
    rule: RobustRule | None = None,
    data: np.ndarray | None = None,
    scaling: str = "none",
) -> SolveResult:
    """The old vectorised solve (arguments as :func:`clpc.lpc.solve.solve_scatter`)."""
    if method not in ("robust", "paper"):
        raise ValueError(f"method must be 'robust' or 'paper'; got {method!r}.")
    rule = rule or RobustRule()
    scatter = np.asarray(scatter, dtype=np.float64)
    k, p, _ = scatter.shape
    n_rows = np.asarray(n_rows)
    n_safe = np.maximum(n_rows, 1).astype(np.float64)

    transform = _whitening(scatter, n_rows, blocks, scaling, noise_cov)  # (k,p,p) or None
    vals, vecs = _decompose(scatter, transform, data)
    # unit-free weights: each eigenvector as a relation theta = T v, in units of the
    # channels' spreads s: w = s * theta
    tmat = np.broadcast_to(np.eye(p), (k, p, p)) if transform is None else transform
    s_col = channel_scales(scatter, n_rows, blocks)
    w = s_col[:, :, None] * (tmat @ vecs)  # (k, p, p): column i is eigenvector i
    w2 = np.sum(w**2, axis=1)
    a0w = np.abs(w[:, 0, :]) / np.sqrt(np.where(w2 > 0, w2, 1.0))
    outw = np.sum(w[:, :n_output_cols, :] ** 2, axis=1) / np.where(w2 > 0, w2, 1.0)
    if transform is None:
        raw_vals = vals
    elif data is not None:
        raw_vals = np.linalg.svd(data, compute_uv=False)[:, ::-1] ** 2
    else:  # only the paper's eigenvalues (for D) are needed from the raw matrix
        raw_vals = np.linalg.eigvalsh(0.5 * (scatter + np.swapaxes(scatter, -1, -2)))

    # degenerate: nothing varies in the window, or a channel is constant
    diag = np.diagonal(scatter, axis1=-2, axis2=-1)
    # a channel is constant when its spread is at rounding level relative to its own size
    # (|mean| * 1e-12) or to the whole matrix; merged statistics of a constant channel are
    # ~1e-29, not 0
    channel_var = np.stack([diag[:, b].max(axis=1) for b in blocks], axis=1)
    channel_size = np.stack([np.abs(mean[:, b]).max(axis=1) for b in blocks], axis=1)
    per_row = channel_var / n_safe[:, None]
    top = np.maximum(raw_vals[:, -1], 0.0)
    degenerate = ~(top > 0) | np.any(
        (channel_var <= 1e-28 * np.maximum(top, 1e-300)[:, None])
        | (per_row <= (1e-12 * channel_size) ** 2),
        axis=1,
    )

    if method == "paper":
        phi = vecs[:, :, 0]
        n_null = np.ones(k, dtype=np.int64)
        n_input = (outw[:, 0] < rule.min_output_weight).astype(np.int64)
        nxt = vals[:, 1] if p > 1 else vals[:, 0]
        separation = _ratio(vals[:, 0], nxt)
    else:
        ratio = degeneracy_ratio(rule, n_rows, p)
        phi, n_null, n_input, separation = _robust_vector(vals, vecs, (a0w, outw), rule, ratio)

    theta = phi if transform is None else np.einsum("kij,kj->ki", transform, phi)
    wt = s_col * theta
    wt_norm = np.linalg.norm(wt, axis=1)
    a0_weight = np.abs(wt[:, 0]) / np.where(wt_norm > 0, wt_norm, 1.0)
    # a solution that hardly involves y(n) is itself an input relation
    n_input = np.where(
        ~degenerate & ~(a0_weight >= rule.min_a0_weight), np.maximum(n_input, 1), n_input
    )
    theta = _normalise(theta)
    theta[degenerate] = 0.0
    c = np.einsum("kp,kp->k", mean, theta)
    noise_variance = np.maximum(np.einsum("ki,kij,kj->k", theta, scatter, theta), 0.0) / n_safe
    return SolveResult(
        theta=theta,
        eigenvalues=np.maximum(raw_vals, 0.0),
        solved_eigenvalues=np.maximum(vals, 0.0),
        c=c,
        noise_variance=noise_variance,
        n_null=n_null,
        n_input_relations=n_input,
        separation=separation,
        degenerate=degenerate,
        a0_weight=np.where(degenerate, 0.0, a0_weight),
    )


def _ratio(num: np.ndarray, den: np.ndarray) -> np.ndarray:
    num = np.maximum(num, 0.0)
    den = np.maximum(den, 0.0)
    out = np.ones_like(num)
    ok = den > 0
    out[ok] = num[ok] / den[ok]
    return np.minimum(out, 1.0)


def _whitening(
    scatter: np.ndarray,
    n_rows: np.ndarray,
    blocks: list[slice],
    scaling: str,
    noise_cov: np.ndarray | None,
) -> np.ndarray | None:
    """Transform ``T`` with ``T^T W T = I``: the solved problem is ``T^T A T``."""
    k, p, _ = scatter.shape
    if noise_cov is None:
        if scaling == "none":
            return None
        scales = channel_scales(scatter, n_rows, blocks)
        return np.einsum("kp,pq->kpq", 1.0 / scales, np.eye(p))
    return np.broadcast_to(fixed_transform(noise_cov, p), (k, p, p))


def fixed_transform(noise_cov: np.ndarray, p: int) -> np.ndarray:
    cov = np.asarray(noise_cov, dtype=np.float64)
    if cov.shape == (p,):
        return np.diag(1.0 / np.sqrt(cov))
    return np.linalg.inv(np.linalg.cholesky(cov)).T


def _decompose(
    scatter: np.ndarray, transform: np.ndarray | None, data: np.ndarray | None
) -> tuple[np.ndarray, np.ndarray]:
    """Ascending eigenvalues and eigenvectors of ``T^T A T`` (SVD of ``M T`` when given)."""
    if data is not None:
        mat = data if transform is None else data @ transform
        _, s, vt = np.linalg.svd(mat, full_matrices=False)
        return s[:, ::-1] ** 2, np.swapaxes(vt, -1, -2)[:, :, ::-1]
    mat = scatter if transform is None else np.swapaxes(transform, -1, -2) @ scatter @ transform
    mat = 0.5 * (mat + np.swapaxes(mat, -1, -2))
    return np.linalg.eigh(mat)


def degeneracy_ratio(rule: RobustRule, n_rows: np.ndarray, p: int) -> np.ndarray:
    """Eigenvalue ratio within which directions are indistinguishable (see RobustRule)."""
    if rule.degeneracy_ratio is not None:
        return np.full(np.shape(n_rows), float(rule.degeneracy_ratio))
    x = np.sqrt(p / np.maximum(np.asarray(n_rows, dtype=float), 1.0))
    with np.errstate(divide="ignore"):
        mp = np.where(x < 1, ((1 + x) / np.maximum(1 - x, 1e-12)) ** 2, np.inf)
    return np.minimum(mp, 4.0)


def _robust_vector(
    vals: np.ndarray,
    vecs: np.ndarray,
    weights: tuple[np.ndarray, np.ndarray],
    rule: RobustRule,
    ratio: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Minimum-norm ``a0 = 1`` vector in the near-null subspace, vectorised over windows."""
    k, p = vals.shape
    idx = np.arange(p)
    a0 = vecs[:, 0, :]  # (k, p): y(n) component of each eigenvector
    a0w, out_w = weights  # unit-free weights (k, p)
    cand = a0w >= rule.min_a0_weight
    # first candidate; if none qualifies, the eigenvector with the largest y(n) weight
    first = np.where(cand.any(axis=1), np.argmax(cand, axis=1), np.argmax(a0w, axis=1))
    floor = rule.zero_tol * np.maximum(vals[:, -1], 0.0)
    lam_s = np.maximum(vals[np.arange(k), first], floor)
    within = (np.maximum(vals, 0.0) <= ratio[:, None] * lam_s[:, None]) | (
        idx[None, :] <= first[:, None]
    )
    # the near-null subspace is a leading block of the ascending spectrum
    last = np.where(within.all(axis=1), p - 1, np.argmin(within, axis=1) - 1)
    member = idx[None, :] <= last[:, None]
    # projection of e_a0 onto span(v_0..v_last): sum_i v_i v_i[a0]
    phi = np.einsum("kpi,ki->kp", vecs, np.where(member, a0, 0.0))
    n_null = (last + 1).astype(np.int64)
    n_input = np.sum(member & (out_w < rule.min_output_weight), axis=1).astype(np.int64)
    nxt = np.where(last + 1 < p, vals[np.arange(k), np.minimum(last + 1, p - 1)], np.inf)
    separation = np.where(
        np.isfinite(nxt), _ratio(lam_s, np.where(np.isfinite(nxt), nxt, 1.0)), 1.0
    )
    return phi, n_null, n_input, separation


def _normalise(theta: np.ndarray) -> np.ndarray:
    """Unit norm and a deterministic sign: ``a0 > 0`` (else the first nonzero entry > 0)."""
    norm = np.linalg.norm(theta, axis=-1, keepdims=True)
    theta = np.divide(theta, norm, out=np.zeros_like(theta), where=norm > 0)
    nz = np.abs(theta) > 1e-14
    first = np.argmax(nz, axis=-1)
    pivot = np.take_along_axis(theta, first[:, None], axis=-1)[:, 0]
    sign = np.where(pivot < 0, -1.0, 1.0)
    return theta * sign[:, None]


def reference_clpc(u: np.ndarray, y: np.ndarray, appraiser: Any) -> dict[str, np.ndarray]:
    """A plain per-window CLPC: for each update, the window's lag matrix, centered, SVD.

    No block statistics, no merge, no compiled code: window ``j`` is rows
    ``[max(0, C j - W), C j)`` of the lag matrix built by :mod:`clpc.lpc.regressors`,
    solved by :func:`solve_scatter` above with the centered data (SVD), then the FSM's
    accept-or-hold and the monic forms in array formulas.
    """
    from clpc.lpc.regressors import miso_regressor

    a = appraiser
    u2 = u.reshape(len(u), -1)
    y2 = y.reshape(len(y), -1)
    n_in, n_out = u2.shape[1], y2.shape[1]
    mode = a.mimo or ("siso" if n_in == n_out == 1 else "miso")
    s = a.structure
    mats = np.stack(
        [
            miso_regressor(y2[:, j], u2 if mode == "miso" else u2[:, j : j + 1], s)
            for j in range(n_out)
        ]
    )
    n_blocks = n_in if mode == "miso" else 1
    na1, nb1 = s.na + 1, s.nb + 1
    blocks = [slice(0, na1)] + [slice(na1 + i * nb1, na1 + (i + 1) * nb1) for i in range(n_blocks)]
    p = mats.shape[2]
    noise = a.noise_cov
    if noise is None and a.noise_ratio is not None:
        noise = np.concatenate([np.ones(na1), np.full(n_blocks * nb1, float(a.noise_ratio))])
    n_updates = mats.shape[1] // a.cluster_size
    # each channel's quantization step in a window: its smallest nonzero change between
    # consecutive samples of the window (the newest sample of each row)
    samples = np.hstack([u2, y2])
    change = np.abs(np.diff(samples, axis=0, prepend=samples[:1]))
    change[~(change > 0)] = np.inf
    col_chan = []
    for e in range(n_out):
        cols = [n_in + e] * na1
        for i in range(n_in) if mode == "miso" else [e]:
            cols += [i] * nb1
        col_chan.append(cols)
    excited = []
    out: dict[str, list[Any]] = {k: [] for k in ("theta_estimate", "eigenvalues", "c", "rows")}
    for key in ("noise_variance", "separation", "a0_weight", "n_null", "n_input", "degenerate"):
        out[key] = []
    for j in range(1, n_updates + 1):
        end = a.cluster_size * j
        rows = mats[:, max(0, end - a.window_size) : end]
        mean = rows.mean(axis=1)
        centered = rows - mean[:, None, :]
        scatter = np.swapaxes(centered, 1, 2) @ centered
        res = solve_scatter(
            scatter,
            mean,
            np.full(n_out, rows.shape[1]),
            n_output_cols=na1,
            blocks=blocks,
            method=a.method,
            noise_cov=noise,
            rule=a.rule,
            data=centered if rows.shape[1] >= p else None,  # SVD needs rows >= columns
            scaling=a.scaling,
        )
        std = np.sqrt(np.diagonal(scatter, axis1=1, axis2=2) / rows.shape[1])
        first_sample = s.max_lag + max(0, end - a.window_size)
        window_step = change[first_sample : s.max_lag + end].min(axis=0)
        quanta = np.array([window_step[col_chan[e]] for e in range(n_out)])
        excited.append(np.all((std >= 3.0 * quanta)[:, :na1], axis=1))  # the output only
        out["theta_estimate"].append(res.theta)
        out["eigenvalues"].append(res.eigenvalues)
        out["c"].append(res.c)
        out["rows"].append(rows.shape[1])
        out["noise_variance"].append(res.noise_variance)
        out["separation"].append(res.separation)
        out["a0_weight"].append(res.a0_weight)
        out["n_null"].append(res.n_null)
        out["n_input"].append(res.n_input_relations)
        out["degenerate"].append(res.degenerate)
    arr = {k: np.array(v) for k, v in out.items()}
    min_rows = a.min_rows if a.min_rows is not None else 2 * p
    not_enough = arr["rows"] < min_rows
    determined = (
        (arr["n_null"] == 1)
        & (arr["n_input"] == 0)
        & (arr["separation"] <= a.rule.separation)
        & ~arr["degenerate"]
    )
    need = a.trust_rows or min(max(10 * p, int(np.ceil(0.5 * a.window_size))), a.window_size)
    trusted = (arr["rows"][:, None] >= need) & np.array(excited) & determined
    accepted = (
        ~not_enough[:, None] & ~arr["degenerate"] & (arr["a0_weight"] >= a.rule.min_a0_weight)
    )
    if a.guard:
        accepted &= trusted
    idx = np.where(accepted, np.arange(n_updates)[:, None], -1)
    last = np.maximum.accumulate(idx, axis=0)
    have = last >= 0
    e_idx = np.arange(n_out)[None, :]
    theta = np.where(have[..., None], arr["theta_estimate"][np.maximum(last, 0), e_idx], 0.0)
    c = np.where(have, arr["c"][np.maximum(last, 0), e_idx], 0.0)
    a0 = np.where(have, theta[:, :, 0], 1.0)
    den = np.where(have[..., None], theta[:, :, :na1] / a0[..., None], np.eye(1, na1)[0])
    b = theta[:, :, na1:].reshape(n_updates, n_out, -1, nb1)
    num = np.zeros((n_updates, n_out, n_in, s.nk + nb1))
    if mode == "miso":
        num[:, :, :n_blocks, s.nk :] = -b / a0[..., None, None]
    else:
        for e in range(n_out):
            num[:, e, e, s.nk :] = -b[:, e, 0] / a0[:, e, None]
    num[~have] = 0.0
    stable = have & np.array(
        [[np.all(np.abs(np.roots(d)) < 1) for d in row] for row in den.reshape(-1, n_out, na1)]
    ).reshape(have.shape)
    return {
        "theta": theta,
        "theta_estimate": arr["theta_estimate"],
        "c": c,
        "den": den,
        "num": num,
        "eigenvalues": arr["eigenvalues"],
        "noise_variance": arr["noise_variance"],
        "accepted": accepted,
        "has_model": have,
        "degenerate": arr["degenerate"],
        "determined": determined,
        "trusted": trusted,
        "n_null": arr["n_null"],
        "n_input_relations": arr["n_input"],
        "stable": stable,
        "not_enough": not_enough,
        "rows": arr["rows"],
    }
