"""The CLPC appraiser: semantics, streaming == batch, persistence, exactness, tracking.

The tests run the compiled kernel (or, with ``NUMBA_DISABLE_JIT=1``, the same functions
uncompiled); ``tests/test_window_kernel.py`` compares the two against a reference.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import signal

import clpc
from clpc import CLPC, DataError, Trace

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])


def record(n: int, seed: int = 0, noise: float = 0.0, offset: float = 0.0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = clpc.simulate_arx(DEN, NUM, u)
    if noise:
        y = y + noise * rng.standard_normal(n)
    return u + offset, y + offset


def exact_window(u, y, end_row, window, order=2):
    """Independent reference: lag matrix of the window, centered, SVD."""
    rows = np.array(
        [
            np.concatenate([y[k - np.arange(order + 1)], u[k - np.arange(order + 1)]])
            for k in range(order + max(0, end_row - window), order + end_row)
        ]
    )
    centered = rows - rows.mean(axis=0)
    _, s, vt = np.linalg.svd(centered, full_matrices=False)
    return centered.T @ centered, s[::-1] ** 2, vt[::-1]


# ---------------------------------------------------------------- semantics
@pytest.mark.parametrize(("window", "cluster"), [(201, 12), (30, 7), (24, 12), (12, 1)])
def test_updates_every_cluster_growing_then_sliding(window, cluster):
    u, y = record(600)
    trace = CLPC(order=2, window_size=window, cluster_size=cluster).run(u, y)
    max_lag = 2
    j = np.arange(1, (600 - max_lag) // cluster + 1)
    assert len(trace) == j.size
    np.testing.assert_array_equal(trace.index, max_lag + cluster * j - 1)
    np.testing.assert_array_equal(trace.rows, np.minimum(cluster * j, window))
    # the window grows first, then slides at exactly window_size rows
    assert np.all(np.diff(trace.rows[trace.rows < window]) == cluster)


def test_paper_names_and_time():
    u, y = record(500)
    a = CLPC(order=2, window_size=201, cluster_size=12, dt=0.01)
    trace = a.run(u, y)
    assert a.cluster_size == 12
    np.testing.assert_allclose(trace.time, trace.index * 0.01)
    for old in ("parameters_size", "data_cluster_dimension", "sample_time", "gate"):
        with pytest.raises(TypeError, match=old):
            CLPC(**{old: 3})  # the paper's and former names are not settings
    with pytest.raises(TypeError):
        CLPC(3, 201, 12)  # type: ignore[misc]  # settings are named


def test_outputs_hold_between_updates():
    u, y = record(400, noise=0.05)
    trace = CLPC(order=2, window_size=50, cluster_size=12).run(u, y)
    held = trace.held(400)
    for k in (0, 13, 14, 25, 26, 100, 399):
        last = np.flatnonzero(trace.index <= k)
        expect = np.zeros(6) if last.size == 0 else trace.theta[last[-1]]
        np.testing.assert_array_equal(held[k, 0], expect)


def test_not_enough_data_is_flagged_and_not_used():
    u, y = record(300)
    # the paper's appraiser: no guard
    trace = CLPC(order=2, window_size=201, cluster_size=4, guard=False).run(u, y)
    p = 6
    assert np.all(trace.not_enough_data == (trace.rows < 2 * p))
    first_ok = np.flatnonzero(~trace.not_enough_data)[0]
    assert not trace.has_model[:first_ok].any()
    assert np.all(trace.theta[:first_ok] == 0)
    assert trace.has_model[first_ok]
    trace2 = CLPC(order=2, window_size=201, cluster_size=4, min_rows=40).run(u, y)
    assert np.all(trace2.not_enough_data == (trace2.rows < 40))


def test_noise_free_recovery_and_steady_state():
    u, y = record(3000)
    trace = CLPC(order=2, window_size=201, cluster_size=12, dt=0.01).run(u, y)
    ok = trace.accepted
    np.testing.assert_allclose(trace.den[ok], np.broadcast_to(DEN, (ok.sum(), 3)), atol=1e-9)
    np.testing.assert_allclose(trace.num[ok][:, 0], np.broadcast_to(NUM, (ok.sum(), 3)), atol=1e-9)
    conv = trace.convergence()
    # D grows with the window (Fig. 6) and is quasi-constant once the window is full
    assert conv.converged and conv.update <= 201 // 12 + 1
    model = trace.steady_state_model()
    np.testing.assert_allclose(model.den, DEN, atol=1e-9)
    np.testing.assert_allclose(model.num, NUM, atol=1e-9)
    assert model.dt == 0.01 and model.is_stable


def test_unconverged_steady_state_raises():
    rng = np.random.default_rng(3)
    u = rng.standard_normal(800)
    y = rng.standard_normal(800)  # no relation at all: parameters wander
    trace = CLPC(order=2, window_size=30, cluster_size=6, guard=False).run(u, y)
    conv = trace.convergence(theta_tol=1e-6, D_tol=1e-6)
    assert not conv.converged
    with pytest.raises(ValueError, match="never became quasi-constant"):
        trace.steady_state_model(conv)
    model = trace.steady_state_model(conv, allow_unconverged=True)
    np.testing.assert_allclose(model.theta, trace.theta[np.flatnonzero(trace.accepted)[-1]])


# ---------------------------------------------------------------- streaming == batch
@settings(
    max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(st.lists(st.integers(min_value=1, max_value=300), min_size=1, max_size=40))
def test_push_any_chunking_equals_run(chunks):
    u, y = record(2500, seed=1, noise=0.01)
    batch = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    a = CLPC(order=2, window_size=201, cluster_size=12)
    parts, i = [], 0
    sizes = itertools.cycle(chunks)
    while i < u.size:
        n = next(sizes)
        parts.append(a.push(u[i : i + n], y[i : i + n]))
        i += n
    streamed = Trace.concat(parts)
    assert len(streamed) == len(batch)
    for key in ("theta", "D", "eigenvalues", "c", "den", "num", "accepted"):
        np.testing.assert_allclose(
            np.asarray(streamed.arrays[key], float),
            np.asarray(batch.arrays[key], float),
            rtol=1e-12,
            atol=1e-12 * np.abs(np.asarray(batch.arrays[key], float)).max(),
        )
    np.testing.assert_array_equal(streamed.index, batch.index)


def test_step_equals_run_and_exposes_state():
    u, y = record(700, seed=2, noise=0.01)
    batch = CLPC(order=2, window_size=60, cluster_size=12).run(u, y)
    a = CLPC(order=2, window_size=60, cluster_size=12)
    parts = [a.step(u[k], y[k]) for k in range(700)]
    streamed = Trace.concat(parts)
    np.testing.assert_allclose(streamed.theta, batch.theta, rtol=0, atol=1e-12)
    assert a.counter == (700 - 2) % 12
    assert a.window.shape == (60, 6)
    np.testing.assert_array_equal(a.theta, batch.theta[-1])
    with pytest.raises(ValueError):
        a.window[0, 0] = 1.0  # read-only view


def test_save_restore_mid_record_continues_identically(tmp_path):
    u, y = record(1500, seed=4, noise=0.02)
    full = CLPC(order=2, window_size=101, cluster_size=12, dt=0.01).run(u, y)
    a = CLPC(order=2, window_size=101, cluster_size=12, dt=0.01)
    first = a.push(u[:777], y[:777])
    state = json.loads(json.dumps(a.state_dict()))
    b = CLPC.from_state_dict(state)
    second = b.push(u[777:], y[777:])
    both = Trace.concat([first, second])
    np.testing.assert_array_equal(both.theta, full.theta)
    np.testing.assert_array_equal(both.D, full.D)
    a.save(str(tmp_path / "state.json"))
    c = CLPC.load(str(tmp_path / "state.json"))
    np.testing.assert_array_equal(c.push(u[777:], y[777:]).theta, second.theta)
    with pytest.raises(ValueError, match="not a clpc appraiser state"):
        CLPC.from_state_dict({"format": "other"})


# ---------------------------------------------------------------- exactness
def test_fast_path_equals_exact_recomputation_with_offsets():
    u, y = record(4000, seed=5, noise=0.05, offset=1e4)
    trace = CLPC(order=2, window_size=201, cluster_size=12, method="paper").run(u, y)
    for t in range(0, len(trace), 7):
        end_row = (t + 1) * 12
        _scatter, vals, vecs = exact_window(u, y, end_row, 201)
        np.testing.assert_allclose(trace.eigenvalues[t], vals, rtol=1e-9, atol=1e-9 * vals[-1])
        np.testing.assert_allclose(trace.D[t], vals[-1] - vals[0], rtol=1e-9)
        if vals[0] < 0.1 * vals[1]:
            ref = vecs[0] * np.sign(vecs[0][0])
            np.testing.assert_allclose(trace.theta_estimate[t], ref, atol=1e-9)


def test_no_drift_over_a_million_samples():
    rng = np.random.default_rng(6)
    n = 1_000_000
    u = rng.standard_normal(n) + 1e4
    y = clpc.simulate_arx(DEN, NUM, u - 1e4) + 0.05 * rng.standard_normal(n) + 1e4
    trace = CLPC(order=2, window_size=201, cluster_size=12, method="paper").run(u, y)
    for t in (len(trace) - 1, len(trace) // 2, len(trace) - 1000):
        _scatter, vals, vecs = exact_window(u, y, (t + 1) * 12, 201)
        np.testing.assert_allclose(trace.eigenvalues[t], vals, rtol=1e-9, atol=1e-9 * vals[-1])
        ref = vecs[0] * np.sign(vecs[0][0])
        assert vals[0] < 0.1 * vals[1]
        np.testing.assert_allclose(trace.theta_estimate[t], ref, atol=1e-9)


# ---------------------------------------------------------------- behaviour
def test_tracks_a_parameter_jump_within_one_window():
    rng = np.random.default_rng(7)
    u = rng.standard_normal(4000)
    den2, num2 = np.array([1.0, -0.9, 0.2]), np.array([1.0, -0.3, 0.4])
    y1 = clpc.simulate_arx(DEN, NUM, u[:2000])
    # continue with the new system from the state of the old one: simulate the new
    # difference equation directly
    y = np.concatenate([y1, np.zeros(2000)])
    for n in range(2000, 4000):
        y[n] = -den2[1] * y[n - 1] - den2[2] * y[n - 2] + num2 @ u[n - np.arange(3)]
    trace = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    after = trace.index >= 2000 + 201 + 12
    np.testing.assert_allclose(trace.den[after], np.broadcast_to(den2, (after.sum(), 3)), atol=1e-8)
    before = (trace.index < 2000) & trace.accepted
    np.testing.assert_allclose(
        trace.den[before], np.broadcast_to(DEN, (before.sum(), 3)), atol=1e-8
    )


@pytest.mark.parametrize("kind", ["constant", "zeros", "repeated"])
def test_degenerate_windows_are_flagged_not_crashed(kind):
    rng = np.random.default_rng(8)
    u, y = record(1200, seed=8, noise=0.01)
    if kind == "constant":
        u[400:800] = 3.0
        y[400:800] = 1.0
    elif kind == "zeros":
        u[:] = 0.0
        y[:] = 0.0
    else:
        u[400:800] = np.repeat(rng.standard_normal(100), 4)
        y[400:800] = np.repeat(rng.standard_normal(100), 4)
    trace = CLPC(order=2, window_size=100, cluster_size=12).run(u, y)
    for key in ("theta", "den", "num", "D", "eigenvalues", "J", "c", "noise_variance"):
        assert np.all(np.isfinite(trace.arrays[key])), key
    if kind == "zeros":
        assert trace.degenerate.all() and not trace.has_model.any()
        assert np.all(trace.theta == 0)
    elif kind == "constant":
        flat = (trace.index - 2 - 100 >= 400) & (trace.index < 800)
        assert trace.degenerate[flat].all()
        assert not trace.accepted[flat].any()
        # the output holds the last good parameters through the flat part
        first_flat = np.flatnonzero(flat)[0]
        last_good = np.flatnonzero(trace.accepted[:first_flat])[-1]
        np.testing.assert_array_equal(
            trace.theta[flat], np.broadcast_to(trace.theta[last_good], (flat.sum(), 6))
        )


def test_gate_holds_parameters_when_excitation_is_lost():
    # a ramp that saturates: once flat, the window no longer determines the model
    n = 3000
    rng = np.random.default_rng(9)
    u = np.concatenate([rng.standard_normal(1000), np.linspace(0, 5, 500), np.full(1500, 5.0)])
    y = clpc.simulate_arx(DEN, NUM, u) + 1e-3 * rng.standard_normal(n)
    gated = CLPC(order=2, window_size=201, cluster_size=12, guard=True).run(u, y)
    flat = gated.index > 1500 + 201 + 12
    assert not gated.accepted[flat].any()
    good = gated.accepted & (gated.index < 1000)
    np.testing.assert_allclose(gated.den[flat], np.broadcast_to(DEN, (flat.sum(), 3)), atol=1e-3)
    assert good.sum() > 50


def test_mimo_paired_and_miso():
    rng = np.random.default_rng(10)
    u = rng.standard_normal((3000, 2))
    y = np.column_stack(
        [
            clpc.simulate_arx(DEN, NUM, u[:, 0]),
            clpc.simulate_arx([1, -0.5, 0.1], [1, 0.2, 0], u[:, 1]),
        ]
    )
    paired = CLPC(order=2, window_size=201, cluster_size=12, mimo="paired").run(u, y)
    assert paired.theta.shape == (len(paired), 2, 6)
    np.testing.assert_allclose(paired.den[-1], [DEN, [1, -0.5, 0.1]], atol=1e-9)
    np.testing.assert_allclose(paired.num[-1, 0, 0], NUM, atol=1e-9)
    np.testing.assert_allclose(paired.num[-1, 0, 1], 0.0)
    y2 = y[:, 0] + clpc.simulate_arx(DEN, [0.3, 0, 0], u[:, 1])
    miso = CLPC(order=2, window_size=201, cluster_size=12, mimo="miso").run(u, y2)
    assert miso.theta.shape == (len(miso), 9)
    np.testing.assert_allclose(miso.den[-1], DEN, atol=1e-9)
    np.testing.assert_allclose(miso.num[-1], [NUM, [0.3, 0, 0]], atol=1e-9)


def test_decimation_by_sample_time():
    rng = np.random.default_rng(11)
    u_fast = np.repeat(rng.standard_normal(800), 10) + 0.01 * rng.standard_normal(8000)
    y_fast = signal.lfilter([0.05], [1, -0.95], u_fast)
    data = clpc.IOData(u_fast, y_fast, dt=0.001)
    trace = CLPC(order=2, window_size=101, cluster_size=12, decimate_to=0.01).run(data)
    # reference: the same causal filter started at rest at the first sample, every 10th
    sos = signal.butter(4, 0.08, output="sos")
    x = np.column_stack([u_fast, y_fast])
    zi = signal.sosfilt_zi(sos)[:, :, None] * x[0][None, None, :]
    filt, _ = signal.sosfilt(sos, x, axis=0, zi=zi)
    ref = CLPC(order=2, window_size=101, cluster_size=12).run(filt[::10, 0], filt[::10, 1], 0.01)
    np.testing.assert_allclose(trace.theta, ref.theta, atol=1e-12)
    np.testing.assert_array_equal(trace.index, ref.index)
    # streaming with the data's sample time gives the same
    a = CLPC(order=2, window_size=101, cluster_size=12, decimate_to=0.01, dt=0.001)
    streamed = Trace.concat(
        [a.push(u_fast[i : i + 333], y_fast[i : i + 333]) for i in range(0, 8000, 333)]
    )
    np.testing.assert_allclose(streamed.theta, trace.theta, atol=1e-12)
    with pytest.raises(DataError, match="integer multiple"):
        CLPC(order=2, window_size=101, cluster_size=12, decimate_to=0.015).run(
            clpc.IOData(u_fast, y_fast, dt=0.01)
        )
    with pytest.raises(DataError, match="integer multiple"):
        CLPC(order=2, window_size=101, cluster_size=12, decimate_to=0.01).run(
            clpc.IOData(u_fast, y_fast, dt=0.02)
        )


@pytest.mark.parametrize(("cluster", "chunk"), [(12, 65536), (12, 5000), (1, 3000)])
def test_threads_give_the_same_result(cluster, chunk):
    # several chunks and batches per chunk: every array, bit for bit, run and push
    u, y = record(20000, seed=12, noise=0.01)
    settings = {"order": 2, "window_size": 201, "cluster_size": cluster, "chunk_samples": chunk}
    one = CLPC(**settings).run(u, y)
    two = CLPC(**settings, n_jobs=2).run(u, y)
    pushed = CLPC(**settings, n_jobs=2)
    parts = Trace.concat([pushed.push(u[i : i + 7000], y[i : i + 7000]) for i in (0, 7000, 14000)])
    for other in (two, parts):
        assert other.arrays.keys() == one.arrays.keys()
        for key in one.arrays:
            np.testing.assert_array_equal(other.arrays[key], one.arrays[key], key)
        for key in ("index", "time", "rows", "not_enough_data"):
            np.testing.assert_array_equal(getattr(other, key), getattr(one, key), key)


def test_to_frame_columns():
    u, y = record(500, noise=0.01)
    frame = CLPC(order=2, window_size=101, cluster_size=12).run(u, y).to_frame()
    for col in ("index", "time", "rows", "a0", "a1", "a2", "b0", "b1", "b2", "D", "accepted"):
        assert col in frame.columns


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"order": 0}, "order must be an int"),
        ({"window_size": 0}, "window_size must be an int"),
        ({"cluster_size": 0}, "cluster_size must be an int"),
        ({"cluster_size": 2.5}, "cluster_size must be an int"),
        ({"decimate_to": -1.0}, "decimate_to must be > 0"),
        ({"method": "lsq"}, "method must be"),
        ({"min_rows": 1}, "min_rows must be an int"),
        # None is "the default" only for the optional counts (a saved state may carry it)
        ({"n_jobs": None}, "n_jobs must be an int"),
        ({"chunk_samples": None}, "chunk_samples must be an int"),
        ({"window_size": None}, "window_size must be an int"),
    ],
)
def test_constructor_validation(kwargs, match):
    with pytest.raises(ValueError, match=match):
        CLPC(**kwargs)


def test_data_validation():
    a = CLPC(order=2, window_size=50, cluster_size=12)
    with pytest.raises(DataError, match="same length"):
        a.push(np.zeros(5), np.zeros(4))
    with pytest.raises(DataError, match="not finite at sample 3"):
        a.push([1.0, 2, 3, np.nan], [1.0, 2, 3, 4])
    a.reset()
    a.push(np.zeros((5, 1)), np.zeros((5, 1)))
    with pytest.raises(DataError, match="reset"):
        a.push(np.zeros((5, 2)), np.zeros((5, 1)))
    with pytest.raises(DataError, match="not finite"):
        CLPC(order=2, window_size=50, cluster_size=12).step(np.inf, 1.0)


def test_constant_command_after_a_ramp_is_degenerate():
    # merged statistics of a constant channel are ~1e-29, not 0: still flagged
    rng = np.random.default_rng(13)
    u = np.r_[np.linspace(0, 1, 100), np.ones(900)]
    y = u + 1e-5 * rng.standard_normal(1000)
    trace = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    late = trace.index > 400
    assert trace.degenerate[late].all()
    assert not trace.accepted[late].any()


def test_estimates_without_y_are_never_accepted():
    # paper method on a ramp: the smallest eigenvector is the ramp's own relation (a0 ~ 0)
    rng = np.random.default_rng(14)
    u = np.clip(np.arange(3000) / 1500.0, 0, 1) + 1e-7 * rng.standard_normal(3000)
    y = clpc.simulate_arx(DEN, NUM, u) + 1e-3 * rng.standard_normal(3000)
    trace = CLPC(order=2, window_size=201, cluster_size=12, method="paper").run(u, y)
    weak = trace.arrays["a0_weight"][:, 0] < 1e-3
    assert weak.any()
    assert not trace.accepted[weak].any()
    assert np.all(np.isfinite(trace.den)) and np.abs(trace.den).max() < 1e3


def test_time_uses_the_records_sample_time_without_decimation():
    u, y = record(400, noise=0.01)
    trace = CLPC(order=2, window_size=101, cluster_size=12).run(clpc.IOData(u, y, dt=0.08))
    np.testing.assert_allclose(trace.time, trace.index * 0.08)
    assert trace.sample_time == 0.08
    model = trace.steady_state_model(allow_unconverged=True)
    assert model.dt == 0.08
    assert "no fit statistics" in str(clpc.fit_verdict(model))


def test_schur_stability_matches_roots():
    from clpc.core.polynomials import stable_many as schur_stable

    rng = np.random.default_rng(15)
    dens = np.concatenate([np.ones((2000, 1)), rng.uniform(-1.5, 1.5, (2000, 3))], axis=1)
    expect = np.array([np.all(np.abs(np.roots(d)) < 1.0) for d in dens])
    np.testing.assert_array_equal(schur_stable(dens), expect)
    assert 100 < expect.sum() < 1900  # both outcomes are exercised


@pytest.mark.parametrize("cluster", [1, 3])
def test_small_clusters_prefix_path_is_exact_and_streams(cluster):
    # W / C > 32 pieces: windows come from prefix sums re-centered per batch
    u, y = record(3000, seed=16, noise=0.05, offset=1e4)
    trace = CLPC(order=2, window_size=201, cluster_size=cluster, method="paper").run(u, y)
    for t in range(12, len(trace), 97):  # windows with at least 12 rows (full spectrum)
        _scatter, vals, vecs = exact_window(u, y, (t + 1) * cluster, 201)
        np.testing.assert_allclose(trace.eigenvalues[t], vals, rtol=1e-9, atol=1e-9 * vals[-1])
        if vals[0] < 0.1 * vals[1]:
            ref = vecs[0] * np.sign(vecs[0][0])
            np.testing.assert_allclose(trace.theta_estimate[t], ref, atol=1e-9)
    a = CLPC(order=2, window_size=201, cluster_size=cluster, method="paper")
    parts = [a.push(u[i : i + 777], y[i : i + 777]) for i in range(0, 3000, 777)]
    streamed = Trace.concat(parts)
    np.testing.assert_allclose(streamed.theta, trace.theta, atol=1e-10)
    np.testing.assert_allclose(streamed.D, trace.D, rtol=1e-10)


# ---------------------------------------------------------------- the guard
def test_guard_accepts_only_trusted_windows():
    u, y = record(3000, seed=21, noise=0.01)
    guarded = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    assert guarded.meta["guard"]
    accepted = guarded.arrays["accepted"][:, 0]
    trusted = guarded.arrays["trusted"][:, 0]
    assert accepted.any() and not (accepted & ~trusted).any()
    # a trusted window holds max(10 p, W / 2) = 101 rows here
    assert not (trusted & (guarded.rows < 101)).any()
    determined = guarded.arrays["determined"][:, 0]
    assert (trusted == (guarded.rows >= 101) & determined).all()


def test_guard_never_holds_a_model_from_a_quantized_start_up_window():
    # a quantized output that moves by one step in the first windows: a handful of values
    # satisfy exact relations (eigenvalue ~ 0, "determined"); the guard refuses them
    rng = np.random.default_rng(22)
    u = rng.standard_normal(2000)
    y = clpc.simulate_arx(DEN, NUM, u)
    y[:300] = 0.0
    y[150:300] = 1.0  # one quantization step, then the real signal
    step = 1e-2
    y = np.round(y / step) * step
    paper = CLPC(order=2, window_size=201, cluster_size=12, guard=False).run(u, y)
    guarded = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    early = guarded.index < 300
    assert paper.arrays["accepted"][early].any()
    assert not guarded.arrays["accepted"][early].any()
    assert not guarded.arrays["excited"][early].any() or not guarded.arrays["trusted"][early].any()


def test_no_relation_nothing_trusted_and_no_convergence():
    rng = np.random.default_rng(23)
    u, y = rng.standard_normal(3000), rng.standard_normal(3000)
    trace = CLPC(order=2, window_size=201, cluster_size=12).run(u, y)
    assert not trace.arrays["trusted"].any() and not trace.has_model.any()
    conv = trace.convergence(theta_tol=10.0, D_tol=10.0)  # tolerances that anything meets
    assert not conv.converged and conv.trusted_fraction == 0.0
    assert "windows are trusted" in conv.reason
    with pytest.raises(ValueError, match="trusted"):
        trace.steady_state_model(conv)
    words = clpc.describe_trace(trace)
    assert any("0 of" in w and "trusted" in w for w in words)


def test_guard_settings_are_checked_and_saved(tmp_path):
    with pytest.raises(ValueError, match="guard must be True or False"):
        CLPC(guard="no")
    a = CLPC(order=2, window_size=60, cluster_size=6, guard=False, trust_rows=30)
    assert CLPC.from_state_dict(a.state_dict()).trust_rows == 30
    assert not CLPC.from_state_dict(a.state_dict()).guard


@pytest.mark.parametrize("name", ["dryer", "robot_arm", "ballbeam", "exchanger"])
def test_default_guard_never_holds_an_untrusted_model_on_real_records(name):
    from clpc import datasets

    data = datasets.load(name)
    trace = CLPC(order=2, window_size=201, cluster_size=12).run(data)
    acc, trusted = trace.arrays["accepted"], trace.arrays["trusted"]
    assert not (acc & ~trusted).any()
    # every held parameter vector is one a trusted window produced
    ok = trace.arrays["has_model"][:, 0]
    est = trace.arrays["theta_estimate"][:, 0][trusted[:, 0]]
    for row in trace.arrays["theta"][:, 0][ok]:
        assert np.any(np.all(est == row, axis=1))


def test_convergence_of_a_trace_without_updates():
    # 8 lag rows: no update
    trace = CLPC(order=2, window_size=201, cluster_size=12).run(np.arange(10.0), np.arange(10.0))
    assert len(trace) == 0
    conv = trace.convergence()
    assert not conv.converged and conv.reason


def test_complex_samples_are_refused_not_truncated():
    u = np.ones(300, dtype=complex)
    y = np.ones(300)
    for feed in (lambda a: a.run(u, y), lambda a: a.push(u, y)):
        with pytest.raises(DataError, match="u must hold real numbers; got complex"):
            feed(CLPC())


def test_windows_that_can_never_hold_a_model_are_refused_up_front():
    with pytest.raises(ValueError, match="window_size=3 cannot hold the 12 lag vectors"):
        CLPC(window_size=3)
    with pytest.raises(ValueError, match="1000 parameters need"):
        CLPC(order=499)
    # 12 parameters with 3 inputs: known at the data
    miso = CLPC(order=2, window_size=13, cluster_size=1, mimo="miso")
    with pytest.raises(ValueError, match="window_size=13 cannot hold the 24"):
        miso.run(np.ones((100, 3)), np.ones(100))
