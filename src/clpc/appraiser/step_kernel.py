"""The kernel entry of one streaming update: few arguments, written into a row of a block.

A call of a ``numba`` function unboxes every array it is given, about 0.1 us each on this
machine, and a nested or mixed tuple costs several times more (``benchmarks/README.md``,
issue 26). :func:`clpc.appraiser.kernel.update_windows` takes some 45 arrays, which is most
of the cost of one ``step`` update. :func:`update_row` takes seven arrays and three
integers: the record's fixed settings, its carried state and its block cache packed once
per record into one array per type (:func:`pack_state`), and the outputs of a block of
:data:`ROWS` updates packed into one array per type (:func:`new_outputs`); it rebuilds the
kernel's named tuples from views of them (no copies) and runs
:func:`~clpc.appraiser.window_solve.solve_chained` and
:func:`~clpc.appraiser.kernel.fsm_output` on one window, as ``update_windows`` does: the
same functions on the same numbers, so the same bits; the packed state also keeps the
chained sums (:mod:`clpc.appraiser.window_chains`) from one update to the next.

Layout: every part is a contiguous run of one of the packed arrays; the integer array starts
with the record's sizes and settings (``_H_*``) and a table of each part's offset and size
per row (:func:`_layout`).
"""

from __future__ import annotations

import numba
import numpy as np

from clpc.appraiser.blocks import BlockCache
from clpc.appraiser.kernel import (
    FsmOutput,
    FsmSettings,
    FsmState,
    KernelSetup,
    Solved,
    WindowPlan,
    fsm_output,
)
from clpc.appraiser.window_chains import chain_floats, chain_sizes, chains_in
from clpc.appraiser.window_solve import solve_chained
from clpc.core.rules import SolveSettings

__all__ = [
    "BOOL_OUT",
    "FLOAT_OUT",
    "INT_OUT",
    "ROWS",
    "new_outputs",
    "pack_state",
    "state_views",
    "update_row",
]

#: updates per block of outputs (a block is allocated once per ROWS updates)
ROWS = 256

# the header of the integer array: sizes, then the plan's, solve's and FSM's settings
(_H_E, _H_P, _H_RING, _H_NA, _H_NB, _H_NK, _H_NIN) = range(7)
(_H_WINDOW, _H_CLUSTER, _H_MIN_ROWS, _H_BLOCK) = range(7, 11)
(_H_ROBUST, _H_TMODE, _H_OUT_COLS, _H_CHANNELS) = range(11, 15)
(_H_FSM_MIN_ROWS, _H_GUARD, _H_TRUST, _H_PAIRED) = range(15, 19)
_HEADER = 19
# the parts of the packed state, each (offset, size) in the table after the header
(_CHAN, _LAG, _COL, _SPAN, _CHAIN_AT) = range(5)  # in the integer array
(_FLOATS, _TRANSFORM, _THETA, _C, _C_MEAN, _C_SCAT, _C_STEP, _CHAINS) = range(5, 13)  # floats
_HAS_MODEL = 13  # in the bool array
_N_STATE = 14
# the outputs of a block, by type (update_row maps them onto Solved's and FsmOutput's fields)
FLOAT_OUT = (
    "theta_estimate", "eigenvalues", "theta", "c_solved", "noise_variance", "separation",
    "a0_weight", "c", "lambda_min", "lambda_max", "D", "eig_ratio", "J", "den", "num",
)  # fmt: skip
INT_OUT = ("n_null", "n_input_relations", "rows")
BOOL_OUT = (
    "degenerate", "excited", "accepted", "has_model", "determined", "trusted", "stable",
    "not_enough",
)  # fmt: skip
_F0 = _N_STATE
_I0 = _F0 + len(FLOAT_OUT)
_B0 = _I0 + len(INT_OUT)
_N_PARTS = _B0 + len(BOOL_OUT)


def _out_shapes(setup: KernelSetup) -> dict[str, tuple[int, ...]]:
    """The shape of one row of every output (without the row axis)."""
    e, p = setup.plan.chan.shape
    fs = setup.fsm
    shapes: dict[str, tuple[int, ...]] = {}
    for key in (*FLOAT_OUT, *INT_OUT, *BOOL_OUT):
        shapes[key] = (e,)
    for key in ("theta_estimate", "eigenvalues", "theta"):
        shapes[key] = (e, p)
    shapes["den"] = (e, fs.na + 1)
    shapes["num"] = (e, setup.n_inputs, fs.nk + fs.nb + 1)
    for key in ("rows", "not_enough"):
        shapes[key] = ()
    return shapes


def _layout(sizes: list[int], table: np.ndarray, first: int) -> int:
    """Offsets of consecutive parts of ``sizes`` entries into ``table``; the total size."""
    offset = 0
    for k, size in enumerate(sizes):
        table[2 * (first + k)] = offset
        table[2 * (first + k) + 1] = size
        offset += size
    return offset


def pack_state(
    setup: KernelSetup, fsm: FsmState, cache: BlockCache
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The record's settings, carried state and block cache packed as (floats, ints, bools).

    The values of ``fsm`` and ``cache`` are copied in; :func:`state_views` gives the arrays
    to use from then on (views of the packed arrays, so the batched path and
    :func:`update_row` update the same memory).
    """
    plan, s, fs = setup.plan, setup.settings, setup.fsm
    n_eq, p = plan.chan.shape
    ring = cache.mean.shape[1]
    table = np.zeros(2 * _N_PARTS, np.int64)
    head = [n_eq, p, ring, fs.na, fs.nb, fs.nk, setup.n_inputs]
    head += [plan.window, plan.cluster, plan.min_rows, plan.block]
    head += [int(s.robust), s.transform_mode, s.n_out_cols, s.n_channels]
    head += [fs.min_rows, int(fs.guard), fs.trust_rows, int(fs.paired)]
    floats = [s.min_a0_weight, s.degeneracy_ratio, s.zero_tol, s.min_output_weight]
    floats += [fs.separation_tol, fs.min_a0_weight]
    shapes = _out_shapes(setup)
    _layout([n_eq * p, n_eq * p, p, 2, 7 * n_eq], table, _CHAN)
    cached = n_eq * ring * p
    chained = chain_floats((n_eq, p), chain_sizes(plan.window, plan.block, plan.cluster))
    fixed = [len(floats), p * p, n_eq * p, n_eq, cached, cached * p, n_eq * ring, chained]
    _layout(fixed, table, _FLOATS)  # the chains hold nothing yet (at = -1)
    _layout([n_eq], table, _HAS_MODEL)
    for first, keys in ((_F0, FLOAT_OUT), (_I0, INT_OUT), (_B0, BOOL_OUT)):
        _layout([int(np.prod(shapes[k], dtype=np.int64)) for k in keys], table, first)
    chain_at = np.full(7 * n_eq, -1, np.int64)
    int_parts = [plan.chan.ravel(), plan.lag.ravel(), plan.col_channel, cache.span, chain_at]
    ints = np.concatenate(
        [np.array(head + [0] * (_HEADER - len(head)), np.int64), table, *int_parts]
    ).astype(np.int64)
    float_parts = [plan.transform.ravel(), fsm.last_theta.ravel(), fsm.last_c]
    cache_parts = [cache.mean.ravel(), cache.scat.ravel(), cache.step.ravel()]
    fl = np.concatenate([np.array(floats), *float_parts, *cache_parts, np.zeros(chained)])
    return fl, ints, fsm.has_model.astype(np.bool_)


def _table(ints: np.ndarray, part: int) -> tuple[int, int]:
    """(offset, size) of ``part``; offsets of the state's integer parts count from the table."""
    at = _HEADER + 2 * part
    return int(ints[at]), int(ints[at + 1])


def state_views(packed: tuple[np.ndarray, np.ndarray, np.ndarray]) -> tuple[FsmState, BlockCache]:
    """The carried FSM state and the block cache as views of the packed arrays."""
    fl, ints, flags = packed
    n_eq, p, ring = (int(v) for v in ints[:3])
    base = _HEADER + 2 * _N_PARTS

    def part(arr: np.ndarray, k: int, shape: tuple[int, ...], skip: int = 0) -> np.ndarray:
        offset, size = _table(ints, k)
        return arr[skip + offset : skip + offset + size].reshape(shape)

    fsm = FsmState(part(fl, _THETA, (n_eq, p)), part(fl, _C, (n_eq,)), flags)
    cache = BlockCache(
        part(fl, _C_MEAN, (n_eq, ring, p)),
        part(fl, _C_SCAT, (n_eq, ring, p, p)),
        part(fl, _C_STEP, (n_eq, ring)),
        part(ints, _SPAN, (2,), base),
    )
    return fsm, cache


def new_outputs(
    setup: KernelSetup, ints: np.ndarray
) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], dict[str, np.ndarray]]:
    """A block of :data:`ROWS` rows of outputs: (floats, ints, bools) and their named views.

    The views have shape (ROWS, *row shape) (e.g. ``theta`` (ROWS, E, p)).
    """
    shapes = _out_shapes(setup)
    views: dict[str, np.ndarray] = {}
    arrays = []
    for first, keys, dtype in (
        (_F0, FLOAT_OUT, np.float64),
        (_I0, INT_OUT, np.int64),
        (_B0, BOOL_OUT, np.bool_),
    ):
        total = sum(_table(ints, first + k)[1] for k in range(len(keys)))
        arr = np.empty(ROWS * total, dtype)
        for k, key in enumerate(keys):
            offset, size = _table(ints, first + k)
            lo = ROWS * offset
            views[key] = arr[lo : lo + ROWS * size].reshape((ROWS, *shapes[key]))
        arrays.append(arr)
    return (arrays[0], arrays[1], arrays[2]), views


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _part(arr: np.ndarray, ints: np.ndarray, k: int, skip: int) -> np.ndarray:
    """Part ``k`` of ``arr`` (1-d, contiguous): the run the table gives, from ``skip`` on."""
    offset = skip + ints[_HEADER + 2 * k]
    return arr[offset : offset + ints[_HEADER + 2 * k + 1]]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _row(arr: np.ndarray, ints: np.ndarray, k: int, row: int) -> np.ndarray:
    """Row ``row`` of output ``k`` of a block (1-d, contiguous)."""
    size = ints[_HEADER + 2 * k + 1]
    offset = ints[_HEADER + 2 * k] * ROWS + row * size
    return arr[offset : offset + size]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def update_row(
    samples: np.ndarray,
    first_row: int,
    j: int,
    row: int,
    fl: np.ndarray,
    ints: np.ndarray,
    flags: np.ndarray,
    fout: np.ndarray,
    iout: np.ndarray,
    bout: np.ndarray,
) -> None:
    """Update ``j`` (one window of every equation) written into row ``row`` of a block.

    ``samples``, ``first_row`` as for :func:`clpc.appraiser.kernel.solve_windows`;
    ``fl``, ``ints``, ``flags``: the packed state of :func:`pack_state` (the carried state
    and the cache are updated in place); ``fout``, ``iout``, ``bout``: a block of
    :func:`new_outputs`. Flat arguments: a tuple of arrays of different types costs more
    to pass than its arrays one by one.
    """
    h = ints
    n_eq, p, ring = h[_H_E], h[_H_P], h[_H_RING]
    base = _HEADER + 2 * _N_PARTS
    plan = WindowPlan(
        _part(ints, ints, _CHAN, base).reshape((n_eq, p)),
        _part(ints, ints, _LAG, base).reshape((n_eq, p)),
        _part(ints, ints, _COL, base),
        _part(fl, ints, _TRANSFORM, 0).reshape((p, p)),
        h[_H_WINDOW],
        h[_H_CLUSTER],
        h[_H_MIN_ROWS],
        h[_H_BLOCK],
    )
    f = _part(fl, ints, _FLOATS, 0)
    s = SolveSettings(
        h[_H_ROBUST] != 0, h[_H_TMODE], h[_H_OUT_COLS], h[_H_CHANNELS], f[0], f[1], f[2], f[3]
    )
    fs = FsmSettings(
        h[_H_FSM_MIN_ROWS], h[_H_GUARD] != 0, h[_H_TRUST], f[4], f[5], h[_H_NA], h[_H_NB],
        h[_H_NK], h[_H_PAIRED] != 0,
    )  # fmt: skip
    cache = BlockCache(
        _part(fl, ints, _C_MEAN, 0).reshape((n_eq, ring, p)),
        _part(fl, ints, _C_SCAT, 0).reshape((n_eq, ring, p, p)),
        _part(fl, ints, _C_STEP, 0).reshape((n_eq, ring)),
        _part(ints, ints, _SPAN, base),
    )
    ep = (1, n_eq, p)
    solved = Solved(
        _row(fout, ints, _F0, row).reshape(ep),
        _row(fout, ints, _F0 + 1, row).reshape(ep),
        _row(fout, ints, _F0 + 3, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 4, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 5, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 6, row).reshape((1, n_eq)),
        _row(iout, ints, _I0, row).reshape((1, n_eq)),
        _row(iout, ints, _I0 + 1, row).reshape((1, n_eq)),
        _row(bout, ints, _B0, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 1, row).reshape((1, n_eq)),
        _row(iout, ints, _I0 + 2, row),
    )
    chained = (_part(fl, ints, _CHAINS, 0), _part(ints, ints, _CHAIN_AT, base))
    sizes = chain_sizes(h[_H_WINDOW], h[_H_BLOCK], h[_H_CLUSTER])
    chains = chains_in(*chained, (n_eq, p), sizes)
    solve_chained(samples, first_row, (j, 1), (plan, s), solved, cache, chains)
    n_in, n_num = h[_H_NIN], h[_H_NK] + h[_H_NB] + 1
    out = FsmOutput(
        _row(fout, ints, _F0 + 2, row).reshape(ep),
        _row(fout, ints, _F0 + 7, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 2, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 3, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 4, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 5, row).reshape((1, n_eq)),
        _row(bout, ints, _B0 + 7, row),
        _row(fout, ints, _F0 + 13, row).reshape((1, n_eq, h[_H_NA] + 1)),
        _row(fout, ints, _F0 + 14, row).reshape((1, n_eq, n_in, n_num)),
        _row(bout, ints, _B0 + 6, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 8, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 9, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 10, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 11, row).reshape((1, n_eq)),
        _row(fout, ints, _F0 + 12, row).reshape((1, n_eq)),
    )
    last = FsmState(_part(fl, ints, _THETA, 0).reshape((n_eq, p)), _part(fl, ints, _C, 0), flags)
    fsm_output(solved, fs, last, out)
