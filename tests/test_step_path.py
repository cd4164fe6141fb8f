"""``CLPC.step``'s lean path (issue 26): packed kernel state, blocks of rows, lazy rows.

Every check compares ``step`` with ``run`` and ``push`` of the same samples bit for bit
(``np.array_equal`` on every array of the traces), across block boundaries (a block holds
:data:`clpc.appraiser.step_block.ROWS` updates), with ``step`` and ``push`` interleaved,
through a saved state, and with the kernels uncompiled (``NUMBA_DISABLE_JIT=1``).
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import clpc
from clpc import CLPC, Trace
from clpc.appraiser import kernel
from clpc.appraiser.step_block import ROWS
from clpc.appraiser.step_kernel import pack_state, state_views

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.0, 0.5, 0.3])
ROW_FIELDS = ("index", "time", "rows", "not_enough_data")


def _record(n: int, seed: int, n_in: int = 1) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, n_in))
    y = clpc.simulate_arx(DEN, NUM, u[:, 0])
    for i in range(1, n_in):
        y = y + clpc.simulate_arx(DEN, 0.3 * NUM, u[:, i])
    return u, y + 0.01 * rng.standard_normal(n)


def assert_same(a: Trace, b: Trace) -> None:
    """Every row field and every array of two traces equal bit for bit (and their keys)."""
    assert len(a) == len(b)
    for f in ROW_FIELDS:
        assert np.array_equal(getattr(a, f), getattr(b, f)), f
        assert getattr(a, f).dtype == getattr(b, f).dtype, f
    assert list(a.arrays) == list(b.arrays)
    for key, value in a.arrays.items():
        assert value.dtype == b.arrays[key].dtype, key
        assert np.array_equal(value, b.arrays[key]), key
    assert (a.structure, a.n_inputs, a.mode, a.sample_time) == (
        b.structure,
        b.n_inputs,
        b.mode,
        b.sample_time,
    )
    assert (a.input_names, a.output_names) == (b.input_names, b.output_names)
    # run alone adds the windows' levels (attach_levels) to meta
    assert _meta(a) == _meta(b)


def _meta(trace: Trace) -> dict:
    return {k: v for k, v in trace.meta.items() if k != "window_level"}


def _steps(appraiser: CLPC, u: np.ndarray, y: np.ndarray, lo: int, hi: int) -> list[Trace]:
    """``step`` over samples ``lo .. hi - 1``: Python floats for SISO, else arrays."""
    if u.shape[1] == 1:
        us, ys = u[lo:hi, 0].tolist(), y[lo:hi].tolist()
        return [appraiser.step(a, b) for a, b in zip(us, ys, strict=True)]
    return [appraiser.step(u[k], y[k]) for k in range(lo, hi)]


CASES = [
    ({"order": 2, "cluster_size": 12}, 1),
    ({"order": 2, "cluster_size": 1}, 1),
    ({"order": 1, "cluster_size": 5}, 1),
    ({"order": 3, "cluster_size": 12}, 1),
    ({"order": 2, "cluster_size": 3}, 2),  # MISO: two inputs, arrays fed
    ({"order": 2, "cluster_size": 1, "method": "paper", "scaling": "std"}, 1),
]


@pytest.mark.parametrize(("settings", "n_in"), CASES)
def test_step_push_and_run_are_bit_identical_across_blocks(settings, n_in):
    n = 2 * ROWS * settings["cluster_size"] + 300  # more than two blocks of updates
    u, y = _record(n, seed=3, n_in=n_in)
    kw = {"window_size": 61, **settings}
    batch = CLPC(**kw).run(u, y)
    assert len(batch) > 2 * ROWS
    pushed = CLPC(**kw)
    parts = [pushed.push(u[i : i + 501], y[i : i + 501]) for i in range(0, n, 501)]
    assert_same(Trace.concat(parts), batch)
    stepped = CLPC(**kw)
    assert_same(Trace.concat(_steps(stepped, u, y, 0, n)), batch)
    assert stepped.counter == pushed.counter


def test_step_and_push_interleaved_equal_run():
    # pushes in between solve updates in batches: step starts new blocks after them
    u, y = _record(9000, seed=4)
    kw = {"order": 2, "window_size": 101, "cluster_size": 4}
    batch = CLPC(**kw).run(u, y)
    a = CLPC(**kw)
    parts: list[Trace] = []
    cuts = [0, 37, 1500, 1503, 4000, 4400, 7777, 9000]
    for k, (lo, hi) in enumerate(itertools.pairwise(cuts)):
        if k % 2:
            parts.append(a.push(u[lo:hi], y[lo:hi]))
        else:
            parts.extend(_steps(a, u, y, lo, hi))
    assert_same(Trace.concat(parts), batch)


def test_a_returned_update_stays_unchanged_after_later_steps():
    u, y = _record(12 * (2 * ROWS + 40), seed=5)
    a = CLPC(order=2, window_size=101, cluster_size=12)
    kept = []
    for k, part in enumerate(_steps(a, u, y, 0, u.shape[0])):
        if len(part) and k % 97 == 0:
            snapshot = {f: getattr(part, f).copy() for f in ROW_FIELDS}
            snapshot.update({key: v.copy() for key, v in part.arrays.items()})
            kept.append((part, snapshot))
        elif len(part) and k % 89 == 0:
            kept.append((part, None))  # read only at the end (its arrays sliced then)
    assert len(kept) > 10
    batch = CLPC(order=2, window_size=101, cluster_size=12).run(u, y)
    for part, snapshot in kept:
        row = int(np.searchsorted(batch.index, part.index[0]))
        assert_same(part, batch.take(slice(row, row + 1)))
        if snapshot is not None:
            for key, value in snapshot.items():
                got = getattr(part, key) if key in ROW_FIELDS else part.arrays[key]
                assert np.array_equal(got, value), key


def test_a_lazy_row_reads_like_a_view_and_pickles_alone():
    u, y = _record(1000, seed=6)
    a = CLPC(order=2, window_size=101, cluster_size=12)
    parts = [p for p in _steps(a, u, y, 0, 1000) if len(p)]
    first, last = parts[0], parts[-1]
    assert "_view_of" in first.__dict__  # nothing sliced yet (len does not slice)
    assert len(first) == 1 and "_view_of" in first.__dict__
    assert first.theta.shape == (1, 6)  # (rows, p) as for any one-row trace
    assert "_view_of" in first.__dict__  # a per-equation array is sliced alone
    theta, d = first.theta.copy(), first.D.copy()
    assert first.index.shape == (1,)  # any other field slices the whole row
    assert "_view_of" not in first.__dict__
    assert np.array_equal(first.theta, theta) and np.array_equal(first.D, d)
    copied = copy.copy(last)
    assert np.array_equal(copied.D, last.D)
    replaced = dataclasses.replace(parts[1], meta={"x": 1})
    assert replaced.meta == {"x": 1} and np.array_equal(replaced.theta, parts[1].theta)
    assert "theta" in repr(parts[2])
    blob = pickle.dumps(parts[3])
    assert len(blob) < 20000  # the row, not its block of ROWS rows
    assert_same(pickle.loads(blob), parts[3])
    first.meta["note"] = "mine"  # every returned update has its own meta
    assert "note" not in parts[1].meta


def test_state_saved_while_stepping_continues_identically(tmp_path):
    u, y = _record(6000, seed=7)
    kw = {"order": 2, "window_size": 101, "cluster_size": 1}
    batch = CLPC(**kw).run(u, y)
    a = CLPC(**kw)
    first = _steps(a, u, y, 0, 2345)
    state = json.loads(json.dumps(a.state_dict()))
    a.save(str(tmp_path / "state.json"))
    b = CLPC.from_state_dict(state)
    c = CLPC.load(str(tmp_path / "state.json"))
    rest_a = _steps(a, u, y, 2345, 6000)
    rest_b = _steps(b, u, y, 2345, 6000)
    rest_c = Trace.concat([c.push(u[2345:4000], y[2345:4000]), *_steps(c, u, y, 4000, 6000)])
    assert_same(Trace.concat(first + rest_a), batch)
    assert_same(Trace.concat(first + rest_b), batch)
    assert_same(Trace.concat([*first, rest_c]), batch)


def test_step_with_decimation_equals_run():
    u, y = _record(4000, seed=8)
    kw = {"order": 2, "window_size": 61, "cluster_size": 3, "decimate_to": 0.004, "dt": 0.001}
    batch = CLPC(**kw).run(u, y)
    stepped = Trace.concat(_steps(CLPC(**kw), u, y, 0, 4000))
    assert len(batch) > 100
    assert_same(stepped, batch)


def test_packed_state_views_hold_the_values_and_share_memory():
    u, y = _record(800, seed=9)
    a = CLPC(order=3, window_size=61, cluster_size=5)
    a.push(u, y)
    state = a._state  # the test looks inside: the packing is internal
    setup = state.kernel_setup()
    fsm, cache = state._fsm_state()
    packed = pack_state(setup, fsm, cache)
    fsm2, cache2 = state_views(packed)
    for x, z in zip((*fsm, *cache), (*fsm2, *cache2), strict=True):
        assert x.shape == z.shape and x.dtype == z.dtype and np.array_equal(x, z)
        assert z.flags.c_contiguous
    fsm2.last_theta[0, 0] = 42.0
    cache2.scat[0, 0, 0, 0] = -1.0
    assert state_views(packed)[0].last_theta[0, 0] == 42.0
    assert state_views(packed)[1].scat[0, 0, 0, 0] == -1.0
    assert kernel.cache_blocks(setup.plan) == cache2.mean.shape[1]


STEP_CHILD = """
import sys, types, numpy as np
sys.path.insert(0, {tests!r})
from clpc.appraiser import step_kernel
assert isinstance(step_kernel.update_row, types.FunctionType) == {python}
from clpc import CLPC, Trace
from test_step_path import _record, _steps
out = {{}}
cases = (({{"order": 2, "cluster_size": 12}}, 1), ({{"order": 2, "cluster_size": 1}}, 2))
for i, (kw, n_in) in enumerate(cases):
    u, y = _record(500, seed=10, n_in=n_in)
    t = Trace.concat(_steps(CLPC(window_size=41, **kw), u, y, 0, 500))
    out.update({{f"{{i}}_{{k}}": v for k, v in t.arrays.items()}})
    out[f"{{i}}_rows"] = t.rows
np.savez(sys.argv[1], **out)
"""


@pytest.mark.skipif(
    os.environ.get("NUMBA_DISABLE_JIT", "0") != "0", reason="this process is uncompiled too"
)
def test_uncompiled_step_equals_the_compiled_one(tmp_path):
    got = {}
    for python in (True, False):
        child = STEP_CHILD.format(tests=str(Path(__file__).parent), python=python)
        env = {**os.environ, "NUMBA_DISABLE_JIT": "1" if python else "0"}
        path = tmp_path / f"{python}.npz"
        subprocess.run([sys.executable, "-c", child, str(path)], env=env, check=True)
        got[python] = dict(np.load(path))
    assert sorted(got[True]) == sorted(got[False]) and len(got[True]) > 40
    for key, value in got[False].items():
        assert np.array_equal(got[True][key], value), key
