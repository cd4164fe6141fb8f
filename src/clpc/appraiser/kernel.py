r"""The CLPC kernel: block statistics, exact window merge, LPC solve and FSM output.

Plain ``numba.njit(cache=True)`` functions; with ``NUMBA_DISABLE_JIT=1`` numba leaves them
uncompiled and they run as plain Python (slow; for debugging and coverage). The rules of
the solution are :mod:`clpc.core.rules`, the eigen-solver :mod:`clpc.core.small_eigh`, the
monic form and the stability test :mod:`clpc.core.polynomials`: nothing here restates them.
The Python side at the end (:func:`window_plan`, :func:`solve_updates`, ...) builds a record's
plan and settings, allocates the output arrays of a call and cuts the updates into batches
(solved on threads with ``n_jobs``; the FSM output then runs in time order).

A window's numbers depend only on its own rows, never on how a record was chunked, so
``run``, ``push`` in any chunks and ``step`` give bit-identical results.

Windows (section V; ``docs/clpc.md``): update ``j`` closes after lag row ``e = C j`` and
uses rows ``[s, e)``, ``s = max(0, e - W)``: the window grows until it holds ``W`` rows,
then slides. Cut the lag rows into blocks ``[l B, (l + 1) B)`` of ``B`` rows, a multiple
of ``C`` (:func:`block_rows`: ``B = C`` unless ``C`` is small against ``sqrt(W)``); a
window is::

    tail: rows of s's block  +  the full blocks  +  head: rows of e's block before e
    \_ computed per window _/    \_ once per block _/   \_____ computed per window ____/

(with ``B = C`` the head is empty). The blocks are aligned to absolute row numbers, so
the pieces of a window do not depend on how the record was chunked either.

Each piece is summarised by its count, mean and centered scatter (two-pass), and pieces
are merged with the formula of Chan, Golub and LeVeque::

    n = sum n_k,   mean = sum n_k mean_k / n,
    A = sum A_k + sum n_k (mean_k - mean)(mean_k - mean)^T

Every term is centered, so offsets (positions around 1e4 rad) and long records lose no
digits.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numba
import numpy as np

from clpc.appraiser.blocks import (
    BlockCache,
    gather_blocks,
    merge,
    new_cache,
    piece_stats,
    piece_step,
)
from clpc.core.polynomials import monic, schur_stable
from clpc.core.rules import (
    NO_TRANSFORM,
    RobustRule,
    SolveSettings,
    accepts,
    eig_ratio,
    index_j,
    is_determined,
    is_excited,
    is_trusted,
    likelihood_variance,
    solve_settings,
    transform_mode,
    trust_rows,
)
from clpc.core.small_eigh import sym_eig
from clpc.core.solution import channel_scales, solve_from_eig, solved_matrix
from clpc.lpc.solve import fixed_transform, noise_covariance
from clpc.model.structure import Structure

if TYPE_CHECKING:
    from clpc.appraiser.settings import Settings

__all__ = [
    "BlockCache",
    "FsmOutput",
    "FsmSettings",
    "FsmState",
    "KernelSetup",
    "Solved",
    "WindowPlan",
    "batches",
    "cache_blocks",
    "fsm_output",
    "new_cache",
    "outputs",
    "record_setup",
    "settings_for",
    "solve_updates",
    "trace_outputs",
    "window_plan",
]


class WindowPlan(NamedTuple):
    """Where the lag rows come from, fixed per record.

    Column ``a`` of equation ``e`` is ``samples[k - lag[e, a], chan[e, a]]`` for the row
    whose newest sample is ``samples[k]``.
    """

    chan: np.ndarray  #: (E, p) int64
    lag: np.ndarray  #: (E, p) int64
    col_channel: np.ndarray  #: (p,) int64, channel block of each column (0 = output)
    transform: np.ndarray  #: (p, p), T of a FIXED_TRANSFORM solve (else unused)
    window: int  #: W, lag rows per window
    cluster: int  #: C, lag rows between updates
    min_rows: int  #: windows with fewer rows are "not enough data": no solve runs
    block: int  #: B, rows of a block summarised once (a multiple of C; see block_rows)


class Solved(NamedTuple):
    """Per-window solutions, shapes (count, E, ...) (``n_rows``: (count,))."""

    theta: np.ndarray
    eigenvalues: np.ndarray
    c: np.ndarray
    noise_variance: np.ndarray
    separation: np.ndarray
    a0_weight: np.ndarray
    n_null: np.ndarray
    n_input_relations: np.ndarray
    degenerate: np.ndarray
    excited: np.ndarray
    n_rows: np.ndarray


class FsmSettings(NamedTuple):
    """The FSM output's settings."""

    min_rows: int
    guard: bool  #: accept only trusted windows
    trust_rows: int  #: rows a trusted window needs
    separation_tol: float
    min_a0_weight: float  #: below it a solution is an input relation, never accepted
    na: int
    nb: int
    nk: int
    paired: bool


class FsmState(NamedTuple):
    """The carried part of the FSM state (updated in place)."""

    last_theta: np.ndarray  #: (E, p)
    last_c: np.ndarray  #: (E,)
    has_model: np.ndarray  #: (E,) bool


class FsmOutput(NamedTuple):
    """What the FSM outputs per update, shapes (count, E, ...) (``not_enough``: (count,))."""

    theta: np.ndarray
    c: np.ndarray
    accepted: np.ndarray
    has_model: np.ndarray
    determined: np.ndarray
    trusted: np.ndarray
    not_enough: np.ndarray
    den: np.ndarray
    num: np.ndarray
    stable: np.ndarray
    lambda_min: np.ndarray
    lambda_max: np.ndarray
    D: np.ndarray
    eig_ratio: np.ndarray
    J: np.ndarray


class Work(NamedTuple):
    """Work space of :func:`solve_one`, allocated once per batch of windows."""

    mat: np.ndarray  #: (p, p)
    tmat: np.ndarray  #: (p, p)
    vecs: np.ndarray  #: (p, p)
    vals: np.ndarray  #: (p,)
    raw: np.ndarray  #: (p,)
    ework: np.ndarray  #: (p,)
    phi: np.ndarray  #: (p,)
    scales: np.ndarray  #: (p,)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def new_work(p: int) -> Work:
    """Work space for problems of size ``p``."""
    return Work(
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty((p, p)),
        np.empty(p),
        np.empty(p),
        np.empty(p),
        np.empty(p),
        np.ones(p),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_one(
    scat: np.ndarray,
    mean: np.ndarray,
    n_rows: float,
    plan: WindowPlan,
    s: SolveSettings,
    work: Work,
    out: tuple[np.ndarray, np.ndarray],
) -> tuple[float, float, float, float, int, int, bool]:
    """LPC of one window: the solved problem, its eigenpairs, then :func:`solve_from_eig`.

    ``out = (theta (p,), eigenvalues (p,))``; ``work`` from :func:`new_work`. A
    non-finite window is degenerate.
    """
    theta, eigenvalues = out
    p = scat.shape[0]
    mat, tmat, vecs, vals, raw, ework, phi, scales = work
    finite = True
    for a in range(p):
        for b in range(p):
            if not math.isfinite(scat[a, b]):
                finite = False
    channel_scales(scat, n_rows, plan.col_channel, s.n_channels, scales)
    if s.transform_mode == NO_TRANSFORM:  # the solved problem is A itself (T = I, unused)
        ok = finite and sym_eig(scat, vals, vecs, ework, True)
        if ok:
            for a in range(p):
                raw[a] = vals[a]
    else:
        solved_matrix(scat, s.transform_mode, plan.transform, scales, tmat, mat)
        ok = finite and sym_eig(mat, vals, vecs, ework, True)
        if ok:
            ok = sym_eig(scat, raw, mat, ework, False)  # the paper's eigenvalues, for D
    if not ok:
        for a in range(p):
            theta[a] = 0.0
            eigenvalues[a] = 0.0
        return 0.0, 0.0, 1.0, 0.0, 1, 0, True
    return solve_from_eig(
        scat,
        mean,
        n_rows,
        (vals, vecs, raw),
        (tmat, scales),
        s,
        plan.col_channel,
        (phi, theta, eigenvalues),
    )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def solve_windows(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    plan: WindowPlan,
    s: SolveSettings,
    out: Solved,
    cache: BlockCache,
) -> None:
    """Solve windows ``j0 .. j0 + count - 1`` (``windows = (j0, count)``) of every equation.

    ``samples`` (n, channels): lag row ``r`` (absolute) has its newest sample at
    ``samples[r - first_row]``. Windows with fewer than ``plan.min_rows`` rows are not
    solved (their outputs are zero and flagged degenerate). A channel's quantization step
    in a window (for :func:`clpc.core.rules.is_excited`) is its smallest nonzero change
    between consecutive samples of the window. ``cache`` (:class:`BlockCache`) supplies the
    blocks an earlier call summarised and keeps the newest (updated in place).
    """
    j0, count = windows
    n_eq, p = plan.chan.shape
    window, cluster, size = plan.window, plan.cluster, plan.block
    first = -first_row
    b_lo = -(-max(0, cluster * j0 - window) // size)  # the first full block of any window
    n_blocks = max(0, cluster * (j0 + count - 1) // size - b_lo)
    b_mean = np.empty((n_blocks, p))
    b_scat = np.empty((n_blocks, p, p))
    b_step = np.empty(n_blocks)
    t_mean = np.empty(p)
    t_scat = np.empty((p, p))
    h_mean = np.empty(p)
    h_scat = np.empty((p, p))
    dev = np.empty((window // size + 3, p))
    mean = np.empty(p)
    scat = np.empty((p, p))
    z = np.empty((size, p))  # the rows of one piece
    work = new_work(p)
    c_lo, c_hi = cache.span[0], cache.span[1]
    for eq in range(n_eq):
        chan = plan.chan[eq]
        lag = plan.lag[eq]
        gather_blocks(
            samples,
            (chan, lag, first, b_lo, n_blocks, size),
            (cache.mean[eq], cache.scat[eq], cache.step[eq], c_lo, c_hi),
            z,
            (b_mean, b_scat, b_step),
        )
        for w in range(count):
            j = j0 + w
            e = cluster * j
            start = max(0, e - window)
            out.n_rows[w] = e - start
            if e - start < plan.min_rows:
                for a in range(p):
                    out.theta[w, eq, a] = 0.0
                    out.eigenvalues[w, eq, a] = 0.0
                out.c[w, eq] = 0.0
                out.noise_variance[w, eq] = 0.0
                out.separation[w, eq] = 1.0
                out.a0_weight[w, eq] = 0.0
                out.n_null[w, eq] = 0
                out.n_input_relations[w, eq] = 0
                out.degenerate[w, eq] = True
                out.excited[w, eq] = False
                continue
            # rows [start, e) = tail [start, full_lo B) + blocks + head [full_hi B, e)
            full_lo = -(-start // size)
            full_hi = max(e // size, full_lo)
            t_end = min(full_lo * size, e)
            h_start = min(max(full_hi * size, t_end), e)
            t_size = t_end - start
            h_size = e - h_start
            if t_size > 0:
                piece_stats(samples, chan, lag, first, (start, t_end), z, (t_mean, t_scat))
            if h_size > 0:
                piece_stats(samples, chan, lag, first, (h_start, e), z, (h_mean, h_scat))
            # the output's quantization step in the window (column 0 is y(n))
            step = piece_step(samples, chan[0], first, (start, t_end))
            step = min(step, piece_step(samples, chan[0], first, (h_start, e)))
            for b in range(full_lo - b_lo, full_hi - b_lo):
                step = min(step, b_step[b])
            n_w = merge(
                (b_mean, b_scat, full_lo - b_lo, full_hi - b_lo, size),
                (t_size, t_mean, t_scat, h_size, h_mean, h_scat),
                dev,
                (mean, scat),
            )
            res = solve_one(
                scat, mean, n_w, plan, s, work, (out.theta[w, eq], out.eigenvalues[w, eq])
            )
            out.c[w, eq] = res[0]
            out.noise_variance[w, eq] = res[1]
            out.separation[w, eq] = res[2]
            out.a0_weight[w, eq] = res[3]
            out.n_null[w, eq] = res[4]
            out.n_input_relations[w, eq] = res[5]
            out.degenerate[w, eq] = res[6]
            out.excited[w, eq] = is_excited(scat, n_w, step, s.n_out_cols)
    if cache.mean.shape[1] > 0 and n_blocks > 0:
        cache.span[0] = b_lo + max(0, n_blocks - cache.mean.shape[1])
        cache.span[1] = b_lo + n_blocks


@numba.njit(cache=True, nogil=True, error_model="numpy")
def fsm_output(solved: Solved, fs: FsmSettings, state: FsmState, out: FsmOutput) -> None:
    """The FSM output of solved windows, in time order.

    Accepts or holds each estimate (:func:`clpc.core.rules.accepts`), updates the carried
    ``state`` in place, and fills the monic forms, the Schur stability flag and the
    per-window statistics (``D = lambda_max - lambda_min``, ``J`` of eq. 22).
    """
    count, n_eq, p = solved.theta.shape
    work = np.empty(fs.na + 1)
    for w in range(count):
        n_rows = solved.n_rows[w]
        few = n_rows < fs.min_rows
        out.not_enough[w] = few
        for e in range(n_eq):
            lo = solved.eigenvalues[w, e, 0]
            hi = solved.eigenvalues[w, e, p - 1]
            out.lambda_min[w, e] = lo
            out.lambda_max[w, e] = hi
            out.D[w, e] = hi - lo
            out.eig_ratio[w, e] = eig_ratio(lo, hi)
            var = likelihood_variance(solved.noise_variance[w, e], hi, n_rows)
            out.J[w, e] = index_j(var, n_rows)
            det = is_determined(
                solved.n_null[w, e],
                solved.n_input_relations[w, e],
                solved.separation[w, e],
                solved.degenerate[w, e],
                fs.separation_tol,
            )
            out.determined[w, e] = det
            trusted = is_trusted(n_rows, fs.trust_rows, solved.excited[w, e], det)
            out.trusted[w, e] = trusted
            weights = (solved.a0_weight[w, e], fs.min_a0_weight)
            ok = accepts(few, solved.degenerate[w, e], weights, fs.guard, trusted)
            out.accepted[w, e] = ok
            if ok:
                for a in range(p):
                    state.last_theta[e, a] = solved.theta[w, e, a]
                state.last_c[e] = solved.c[w, e]
                state.has_model[e] = True
            for a in range(p):
                out.theta[w, e, a] = state.last_theta[e, a]
            out.c[w, e] = state.last_c[e]
            out.has_model[w, e] = state.has_model[e]
            if state.has_model[e]:
                target = e if fs.paired else -1
                monic(
                    state.last_theta[e], fs.na, fs.nb, fs.nk, target, out.den[w, e], out.num[w, e]
                )
                out.stable[w, e] = schur_stable(out.den[w, e], work)
            else:
                out.den[w, e, 0] = 1.0
                for k in range(1, fs.na + 1):
                    out.den[w, e, k] = 0.0
                for i in range(out.num.shape[2]):
                    for k in range(out.num.shape[3]):
                        out.num[w, e, i, k] = 0.0
                out.stable[w, e] = False


@numba.njit(cache=True, nogil=True, error_model="numpy")
def update_windows(
    samples: np.ndarray,
    first_row: int,
    windows: tuple[int, int],
    settings: tuple[Any, ...],
    state: tuple[Any, ...],
    out: tuple[Any, ...],
    cache: tuple[np.ndarray, ...],
) -> None:
    """:func:`solve_windows` then :func:`fsm_output` in one call (one dispatch per update).

    The containers arrive as plain tuples - ``settings = (plan, solve settings, FSM
    settings)``, ``state``, ``out = (solved, output)``, ``cache`` - in the fields' order of
    :class:`WindowPlan`, :class:`SolveSettings`, :class:`FsmSettings`, :class:`FsmState`,
    :class:`Solved`, :class:`FsmOutput` and :class:`BlockCache`: numba types plain tuples
    of arrays several times faster than named tuples at the call, which is most of the cost
    of one update.
    """
    plan = WindowPlan(*settings[0])
    s = SolveSettings(*settings[1])
    fs = FsmSettings(*settings[2])
    solved = Solved(*out[0])
    solve_windows(samples, first_row, windows, plan, s, solved, BlockCache(*cache))
    fsm_output(solved, fs, FsmState(*state), FsmOutput(*out[1]))


# ================================================================= the Python side
# The appraiser's calls into the compiled functions above: the plan and settings of a
# record, the output arrays of a call, batches of windows (on threads with ``n_jobs``).

#: windows solved per kernel call (bounds the temporaries of one call)
WINDOWS_PER_BATCH = 2048


@dataclass(frozen=True)
class KernelSetup:
    """What the kernel needs, fixed for a record: the plan and the settings."""

    plan: WindowPlan
    settings: SolveSettings
    fsm: FsmSettings
    n_inputs: int
    plain: tuple[tuple[Any, ...], ...] = ()  #: (plan, settings, fsm) as plain tuples

    def __post_init__(self) -> None:
        # what the kernel's entry point takes (fast to type at every call)
        plain = (tuple(self.plan), tuple(self.settings), tuple(self.fsm))
        object.__setattr__(self, "plain", plain)


def record_setup(
    settings: Settings, channels: tuple[int, int, bool], p: int, min_rows: int
) -> KernelSetup:
    """The plan and settings of a record.

    ``channels = (n_inputs, n_outputs, miso)``; ``p`` parameters per equation; windows of
    fewer than ``min_rows`` rows are not solved.
    """
    st, s = settings, settings.structure
    n_in, _, miso = channels
    cov = noise_covariance(st.noise_cov, st.noise_ratio, s, n_in if miso else 1)
    plan, n_channels = window_plan(s, channels, (st.window_size, st.cluster_size, min_rows), cov)
    trusted = trust_rows(p, st.window_size) if st.trust_rows is None else st.trust_rows
    return KernelSetup(
        plan=plan,
        settings=settings_for((st.method, st.scaling), st.rule, cov, s.na, n_channels),
        fsm=FsmSettings(
            min_rows,
            st.guard,
            trusted,
            st.rule.separation,
            float(st.rule.min_a0_weight),
            s.na,
            s.nb,
            s.nk,
            not miso,
        ),
        n_inputs=n_in,
    )


def window_plan(
    structure: Structure,
    channels: tuple[int, int, bool],
    sizes: tuple[int, int, int],
    noise: np.ndarray | None,
) -> tuple[WindowPlan, int]:
    """Column maps of the lag rows and the transform of the solved problem.

    Parameters
    ----------
    structure : Structure
    channels : (n_inputs, n_outputs, miso)
        ``miso``: every equation uses every input (else the paper's pairing).
    sizes : (window, cluster, min_rows)
    noise : ndarray, shape (p,) or (p, p), optional
        Known noise covariance of the lag vector (weighted LPC).

    Returns
    -------
    plan : WindowPlan
    n_channels : int
        Channel blocks of a lag vector (the output, then one per input block).
    """
    n_in, n_out, miso = channels
    s = structure
    n_blocks = n_in if miso else 1
    p = s.n_params(n_blocks)
    col_channel = np.zeros(p, dtype=np.int64)
    for blk in range(n_blocks):
        col_channel[s.na + 1 + blk * (s.nb + 1) : s.na + 1 + (blk + 1) * (s.nb + 1)] = blk + 1
    # column a of equation e is buf[k - lag, chan] (buffer columns: inputs, then outputs)
    chan = np.empty((n_out, p), dtype=np.int64)
    lag = np.empty((n_out, p), dtype=np.int64)
    for e in range(n_out):
        chan[e, : s.na + 1] = n_in + e
        lag[e, : s.na + 1] = np.arange(s.na + 1)
        for i, inp in enumerate(range(n_in) if miso else [e]):
            cols = slice(s.na + 1 + i * (s.nb + 1), s.na + 1 + (i + 1) * (s.nb + 1))
            chan[e, cols] = inp
            lag[e, cols] = s.nk + np.arange(s.nb + 1)
    transform = np.eye(p) if noise is None else fixed_transform(noise, p)
    window, cluster, min_rows = sizes
    plan = WindowPlan(
        chan,
        lag,
        col_channel,
        np.ascontiguousarray(transform),
        window,
        cluster,
        min_rows,
        block_rows(window, cluster),
    )
    return plan, n_blocks + 1


def cache_blocks(plan: WindowPlan) -> int:
    """Blocks a :class:`BlockCache` holds: those of one window, and one more."""
    return plan.window // plan.block + 2


def block_rows(window: int, cluster: int) -> int:
    """Rows ``B`` of a block: ``C``, or a multiple of it near ``sqrt(W)`` when ``C`` is small.

    A window costs its tail and head pieces (up to ``B`` rows each, summarised per window)
    plus a merge over its ``W / B`` full blocks; ``B ~ sqrt(W)`` balances the two. With
    ``C >= sqrt(W) / 1.5`` (the paper's ``C = 12``, ``W = 201``) ``B = C`` and windows have
    no head piece.
    """
    return cluster * max(1, round(math.sqrt(window) / cluster))


def settings_for(
    method: tuple[str, str],
    rule: RobustRule,
    noise: np.ndarray | None,
    na: int,
    n_channels: int,
) -> SolveSettings:
    """The solve settings of an appraiser: ``method = (method, scaling)``.

    See :func:`clpc.core.rules.solve_settings` and :func:`clpc.core.rules.transform_mode`.
    """
    name, scaling = method
    mode = transform_mode(scaling, noise is not None)
    return solve_settings(rule, name == "robust", mode, na + 1, n_channels)


#: a kernel call's outputs as plain tuples, in the fields' order of Solved and FsmOutput
Plain = tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]


def outputs(count: int, setup: KernelSetup) -> Plain:
    """Uninitialised output arrays of ``count`` updates, as plain tuples (see :data:`Plain`).

    Fields of the same shape and type share one allocation.
    """
    e, p = setup.plan.chan.shape
    fs = setup.fsm
    f = np.empty((3, count, e, p))
    g = np.empty((10, count, e))
    i = np.empty((2, count, e), np.int64)
    b = np.empty((7, count, e), np.bool_)
    solved = (f[0], f[1], g[0], g[1], g[2], g[3], i[0], i[1], b[0], b[1])
    den = np.empty((count, e, fs.na + 1))
    num = np.empty((count, e, setup.n_inputs, fs.nk + fs.nb + 1))
    out = (f[2], g[4], b[2], b[3], b[4], b[5], np.empty(count, np.bool_), den, num, b[6])
    return (*solved, np.empty(count, np.int64)), (*out, g[5], g[6], g[7], g[8], g[9])


def batches(j_first: int, j_last: int, n_jobs: int) -> list[tuple[int, int]]:
    """``(j0, count)`` pairs covering updates ``j_first .. j_last`` (equal thread shares)."""
    n_new = j_last - j_first + 1
    n_batches = -(-n_new // WINDOWS_PER_BATCH)
    if n_jobs > 1:
        n_batches = -(-n_batches // n_jobs) * n_jobs
    size = -(-n_new // n_batches)
    return [(j0, min(size, j_last + 1 - j0)) for j0 in range(j_first, j_last + 1, size)]


def solve_updates(
    setup: KernelSetup,
    samples: tuple[np.ndarray, int],
    updates: tuple[int, int],
    state: tuple[FsmState, BlockCache],
    dest: Plain,
    threads: tuple[int, Callable[..., Any]] = (1, map),
) -> None:
    """Solve updates ``updates = (j_first, j_last)`` and run the FSM output over them.

    Parameters
    ----------
    setup : KernelSetup
    samples : (buffer, first_row)
        Buffered samples (n, channels) and the absolute lag row of ``buffer[0]`` minus
        ``max_lag`` (see :func:`solve_windows`).
    updates : (j_first, j_last)
    state : (FsmState, BlockCache)
        The carried FSM state and the record's block cache, updated in place (the threads
        use no cache: their batches run at once).
    dest : Plain
        Where the outputs go, one row per update (e.g. :func:`outputs`, or
        :func:`trace_outputs` to write straight into a trace); each batch writes its rows.
    threads : (n_jobs, map)
        Thread count and ``map`` or a thread pool's ``map`` (batches are independent).
    """
    buf, first_row = samples
    n_jobs, mapper = threads
    fsm, cache = state
    j_first = updates[0]
    parts = batches(j_first, updates[1], n_jobs)
    views = [_rows(dest, j0 - j_first, j0 - j_first + c) for j0, c in parts]
    if n_jobs == 1 or len(parts) == 1:  # solve and output in one kernel call per batch
        plain_state, plain_cache = tuple(fsm), tuple(cache)
        for batch, (solved, out) in zip(parts, views, strict=True):
            update_windows(
                buf, first_row, batch, setup.plain, plain_state, (solved, out), plain_cache
            )
        return
    off = new_cache(setup.plan.chan.shape, 0)

    def solve_batch(k: int) -> int:
        solved = Solved(*views[k][0])
        solve_windows(buf, first_row, parts[k], setup.plan, setup.settings, solved, off)
        return k

    # windows are independent: threads; the FSM output runs in time order, each batch's as
    # soon as it is solved (while the threads solve the next ones)
    for k in mapper(solve_batch, range(len(parts))):
        fsm_output(Solved(*views[k][0]), setup.fsm, fsm, FsmOutput(*views[k][1]))


def trace_outputs(arrays: dict[str, np.ndarray], rows: np.ndarray, not_enough: np.ndarray) -> Plain:
    """The kernel's outputs as the arrays of a trace (see :data:`Plain`): no copies.

    ``arrays`` holds the per-equation arrays of :data:`clpc.appraiser.trace.PER_EQUATION`,
    ``rows`` and ``not_enough`` the rows and flags (all with the same number of rows);
    the solved ``c`` (not in a trace) gets a scratch array.
    """
    scratch = np.empty(arrays["c"].shape)
    solved = tuple(
        scratch if key is None else rows if key == "n_rows" else arrays[key] for key in _SOLVED_KEYS
    )
    out = tuple(not_enough if key == "not_enough" else arrays[key] for key in _FSM_KEYS)
    return solved, out


def _rows(plain: Plain, lo: int, hi: int) -> Plain:
    """Rows ``lo .. hi - 1`` of every output (views, C-contiguous)."""
    return tuple(a[lo:hi] for a in plain[0]), tuple(a[lo:hi] for a in plain[1])


#: trace keys of the fields of Solved (None: not in the trace) and of FsmOutput
_SOLVED_KEYS = (
    "theta_estimate",
    "eigenvalues",
    None,
    "noise_variance",
    "separation",
    "a0_weight",
    "n_null",
    "n_input_relations",
    "degenerate",
    "excited",
    "n_rows",
)
_FSM_KEYS = tuple(FsmOutput._fields)
