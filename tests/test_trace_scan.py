"""A trace scanned in parts (clpc track's summary, bounded memory) says what the whole says.

:class:`clpc.appraiser.scanned.ScannedTrace` is fed a trace cut at arbitrary points (parts
of one update included) and must give the in-memory trace's convergence, steady-state
model (bit for bit: the sums run in numpy's order), findings and summary; its rows after
the convergence point go to a scratch file that is removed at the end.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math

import numpy as np
import pytest

import clpc
from clpc.appraiser.scanned import ScannedTrace
from clpc.model.trace_findings import SHOWN_RUNS, RunTracker
from clpc.report import trace_summary


def _cut(trace, bounds):
    """``trace`` as parts ``[b0:b1], [b1:b2], ...``."""
    edges = [0, *bounds, len(trace)]
    for lo, hi in itertools.pairwise(edges):
        yield dataclasses.replace(
            trace,
            index=trace.index[lo:hi],
            time=trace.time[lo:hi],
            rows=trace.rows[lo:hi],
            not_enough_data=trace.not_enough_data[lo:hi],
            arrays={k: v[lo:hi] for k, v in trace.arrays.items()},
        )


def _traces():
    rng = np.random.default_rng(30)
    n = 6000
    u = rng.standard_normal(n)
    gain = np.where(np.arange(n) < n // 2, 1.0, 1.6)  # a plant that changes half-way
    y = clpc.simulate_arx([1, -1.5, 0.7], [0, 0.5, 0.3], gain * u) + 0.02 * rng.standard_normal(n)
    changing = clpc.CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    sine = np.sin(2 * np.pi * 0.01 * np.arange(3000))
    ys = clpc.simulate_arx([1, -1.5, 0.7], [0, 0.5, 0.3], sine) + 1e-3 * rng.standard_normal(3000)
    rejected = clpc.CLPC(order=2, guard=False).run(sine, ys)  # a sine: none trusted
    return {"changing": changing, "rejected": rejected}


TRACES = _traces()


def _same(a, b):
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return a == b


@pytest.mark.parametrize("name", list(TRACES))
@pytest.mark.parametrize("cuts", [[], [1, 2, 3], [7, 8, 100, 101, 250], "every 37"])
def test_parts_give_the_whole_traces_numbers(name, cuts, tmp_path):
    trace = TRACES[name]
    bounds = list(range(37, len(trace), 37)) if cuts == "every 37" else cuts
    scanned = ScannedTrace(tmp_path)
    for part in _cut(trace, bounds):
        scanned.add(part)
    whole, parts = trace.convergence(), scanned.convergence()
    for field in dataclasses.fields(whole):
        assert _same(getattr(whole, field.name), getattr(parts, field.name)), field.name
    assert scanned.findings.lines() == clpc.describe_trace(trace)
    summary_whole = json.dumps(trace_summary(trace), sort_keys=True)
    assert json.dumps(trace_summary(scanned), sort_keys=True) == summary_whole
    allow = not whole.converged
    model = trace.steady_state_model(whole, allow_unconverged=allow)
    from_parts = scanned.steady_state_model(allow_unconverged=allow)
    np.testing.assert_array_equal(from_parts.theta, model.theta)  # bit for bit
    np.testing.assert_array_equal(from_parts.c, model.c)
    assert from_parts.info["updates_used"] == model.info["updates_used"]
    last = scanned.last
    np.testing.assert_array_equal(last.index, trace.index[-20:])
    if whole.converged:
        assert any(tmp_path.iterdir())  # the rows after convergence went to disk
    scanned.close()
    assert not any(tmp_path.iterdir())


def test_the_changing_plant_converges_and_the_sine_does_not():
    # the cases above cover both branches of the scan
    assert TRACES["changing"].convergence().converged
    rejected = TRACES["rejected"]
    assert not rejected.convergence().converged
    with pytest.raises(ValueError, match="never became quasi-constant"):
        ScannedTrace.of(rejected).steady_state_model()


def _runs(mask):
    """Independent reference: inclusive runs of a bool sequence, by a plain loop."""
    runs, start = [], None
    for i, v in enumerate(mask):
        if v and start is None:
            start = i
        if not v and start is not None:
            runs.append((start, i - 1))
            start = None
    if start is not None:
        runs.append((start, len(mask) - 1))
    return runs


@pytest.mark.parametrize("seed", range(6))
def test_run_tracker_keeps_the_first_runs_and_counts_all(seed):
    rng = np.random.default_rng(seed)
    mask = rng.random(500) < rng.uniform(0.05, 0.95)
    tracker = RunTracker()
    cuts = np.sort(rng.choice(np.arange(1, 500), size=rng.integers(0, 40), replace=False))
    for part in np.split(mask, cuts):
        tracker.add(part)
    runs = _runs(mask.tolist())
    assert tracker.count == len(runs)
    assert [tuple(r) for r in tracker.shown] == runs[:SHOWN_RUNS]
