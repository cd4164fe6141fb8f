"""The CLPC kernel against an independent per-window SVD reference; its eigen-solver.

The reference (``tests/lpc_reference.py``) builds each window's lag matrix, centers it and
takes its SVD, with array formulas for the rules; the kernel merges block statistics and
runs :mod:`clpc.core.rules` in compiled loops. The module runs as it is (compiled) and, in
CI, once more with ``NUMBA_DISABLE_JIT=1`` (the same functions as plain Python);
:func:`test_uncompiled_kernels_equal_the_compiled_ones` compares the two in one run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import clpc
from clpc import CLPC, DataError, Trace
from clpc.appraiser import kernel
from clpc.core.small_eigh import sym_eig
from lpc_reference import reference_clpc

pytest.importorskip("numba")

DEN = np.array([1.0, -1.5, 0.7])
NUM = np.array([0.2, 0.5, 0.1])
FLOAT_KEYS = ("theta", "theta_estimate", "c", "den", "num")
# eigenvalues carry an absolute error of a few eps * lambda_max (either solver)
EIGEN_KEYS = ("eigenvalues", "D", "lambda_min", "lambda_max")
FLAG_KEYS = (
    "accepted",
    "has_model",
    "degenerate",
    "determined",
    "trusted",
    "n_null",
    "n_input_relations",
    "stable",
)


# ---------------------------------------------------------------- the eigen-solver
@pytest.mark.parametrize("n", [1, 2, 3, 6, 9])
def test_small_eigh_matches_lapack(n):
    rng = np.random.default_rng(n)
    for trial in range(30):
        x = rng.standard_normal((40, n)) * 10.0 ** rng.uniform(-4, 4, n)
        a = x.T @ x
        if trial % 3 == 0 and n > 1:  # exactly rank-deficient: a zero row and column
            a[0, :] = a[:, 0] = 0.0
        d, v, e = np.empty(n), np.empty((n, n)), np.empty(n)
        assert sym_eig(a, d, v, e, True)
        ref = np.linalg.eigvalsh(a)
        scale = max(np.abs(ref).max(), 1e-300)
        np.testing.assert_allclose(d, ref, rtol=0, atol=1e-13 * scale)
        assert np.all(np.diff(d) >= 0)
        np.testing.assert_allclose(v.T @ v, np.eye(n), atol=1e-13)
        np.testing.assert_allclose(a @ v, v * d, rtol=0, atol=1e-13 * scale)
        values_only = np.empty(n)
        assert sym_eig(a, values_only, np.empty((n, n)), e, False)
        np.testing.assert_allclose(values_only, d, rtol=0, atol=1e-13 * scale)


def test_small_eigh_reports_non_finite_input():
    a = np.eye(4)
    a[1, 2] = a[2, 1] = np.nan
    assert not sym_eig(a, np.empty(4), np.empty((4, 4)), np.empty(4), True)


# ---------------------------------------------------------------- kernel parity
def _record(n, seed, n_in=1, n_out=1, offset=0.0):
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((n, n_in))
    y = np.empty((n, n_out))
    for j in range(n_out):
        y[:, j] = clpc.simulate_arx(DEN, NUM, u[:, j % n_in] + 0.5 * u[:, (j + 1) % n_in])
    y += 0.01 * rng.standard_normal(y.shape)
    return u + offset, y + offset


def _compare(a: Trace, ref: dict) -> None:
    assert len(a) == len(ref["rows"]) > 0
    np.testing.assert_array_equal(a.rows, ref["rows"])
    np.testing.assert_array_equal(a.not_enough_data, ref["not_enough"])
    usable = ~a.not_enough_data
    for key in FLOAT_KEYS:
        x, y = a.arrays[key][usable], ref[key][usable]
        scale = np.abs(y).max() if y.size else 1.0
        np.testing.assert_allclose(x, y, rtol=1e-10, atol=1e-10 * scale, err_msg=key)
    top = ref["eigenvalues"][usable].max()
    np.testing.assert_allclose(
        a.arrays["eigenvalues"][usable], ref["eigenvalues"][usable], rtol=0, atol=1e-12 * top
    )
    lam = a.arrays["eigenvalues"]
    np.testing.assert_array_equal(a.arrays["D"], lam[..., -1] - lam[..., 0])
    var_a, var_b = a.arrays["noise_variance"][usable], ref["noise_variance"][usable]
    np.testing.assert_allclose(var_a, var_b, rtol=0, atol=1e-12 * top / a.rows[usable].min())
    # J is the paper's eq. 22 at the solution, the variance floored at 1e3 eps of the largest
    # per-row variance (rounding, not noise)
    n = a.rows[:, None]
    floor = 1e3 * np.finfo(float).eps * a.arrays["lambda_max"] / n
    var = np.maximum(np.maximum(a.arrays["noise_variance"], floor), np.finfo(float).tiny)
    np.testing.assert_allclose(a.arrays["J"], 0.5 * n * (np.log(var) + 1), rtol=1e-13)
    for key in FLAG_KEYS:
        np.testing.assert_array_equal(a.arrays[key][usable], ref[key][usable], key)


PARITY_CASES = [
    ({}, 1, 1),
    ({"method": "paper"}, 1, 1),
    ({"noise_ratio": 3.0}, 1, 1),
    ({"method": "paper", "noise_cov": [1, 1.1, 1.2, 2, 2.1, 2.2]}, 1, 1),
    ({"noise_cov": np.diag([1, 1.1, 1.2, 2, 2.1, 2.2]) + 0.05}, 1, 1),
    ({"guard": True, "window_size": 60, "cluster_size": 7}, 1, 1),
    ({"na": 3, "nb": 1, "nk": 2, "window_size": 24, "cluster_size": 12}, 1, 1),
    ({"cluster_size": 1, "window_size": 40}, 1, 1),
    ({"mimo": "miso"}, 2, 2),
    ({"mimo": "paired", "method": "paper"}, 2, 2),
    # blocks of B > C rows (kernel.block_rows): tail, full blocks and a head piece
    ({"cluster_size": 1}, 1, 1),
    ({"cluster_size": 5, "method": "paper"}, 1, 1),
    ({"mimo": "miso", "cluster_size": 3, "window_size": 90}, 2, 2),
]


@pytest.mark.parametrize(("kwargs", "n_in", "n_out"), PARITY_CASES)
def test_kernel_equals_per_window_svd_reference(kwargs, n_in, n_out):
    u, y = _record(3000, seed=3, n_in=n_in, n_out=n_out, offset=1e3)
    settings = {"order": 2, "window_size": 201, "cluster_size": 12, **kwargs}
    appraiser = CLPC(**settings)
    _compare(appraiser.run(u, y), reference_clpc(u, y, appraiser))


UNCOMPILED_CASES = PARITY_CASES[::3]
UNCOMPILED_KEYS = ("theta", "eigenvalues", "c", "J", "accepted", "den", "stable")


def kernel_outputs(inputs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """What the kernels compute on ``inputs``: CLPC traces, a blended free run, monic forms.

    Run in this process (compiled) and by :func:`test_uncompiled_kernels_equal_the_compiled_ones`
    in a child with ``NUMBA_DISABLE_JIT=1`` (uncompiled).
    """
    from clpc.core.polynomials import monic_many, stable_many
    from clpc.multimodel.kernels import run_blend, run_varying

    out = {}
    for i, (kwargs, _, _) in enumerate(UNCOMPILED_CASES):
        settings = {"order": 2, "window_size": 101, "cluster_size": 12, **kwargs}
        trace = CLPC(**settings).run(inputs[f"clpc_u{i}"], inputs[f"clpc_y{i}"])
        out.update({f"clpc{i}_{key}": trace.arrays[key] for key in UNCOMPILED_KEYS})
    models = (inputs["den"], inputs["num"], inputs["icpt"])
    u, y0 = inputs["u"], inputs["y0"]
    sched = (0, 0, 1)  # scheduled on y(n - 1)
    out["blend"] = run_blend(models, inputs["centres"], inputs["widths"], sched, u, y0.copy(), 2)
    steps = np.arange(u.shape[0]) % models[0].shape[0]  # the models in turn
    picked = (models[0][steps], models[1][steps], models[2][steps])
    out["varying"] = run_varying(picked, u, y0.copy(), 2)
    out["den"], out["num"] = monic_many(inputs["theta"], 2, 2, 0, 1, False)
    out["stable"] = stable_many(out["den"])
    return out


def _kernel_inputs(rng: np.random.Generator) -> dict[str, np.ndarray]:
    inputs = {}
    for i, (_, n_in, n_out) in enumerate(UNCOMPILED_CASES):
        inputs[f"clpc_u{i}"], inputs[f"clpc_y{i}"] = _record(
            700, seed=4, n_in=n_in, n_out=n_out, offset=1e3
        )
    m = 3
    poles = rng.uniform(0.2, 0.9, (m, 2))
    inputs["den"] = np.stack([np.poly(p) for p in poles])
    inputs["num"] = rng.standard_normal((m, 1, 3))
    inputs["icpt"] = rng.standard_normal(m)
    inputs["centres"] = np.array([-1.0, 0.0, 1.0])
    inputs["widths"] = np.array([0.5, 0.7, 0.5])
    inputs["u"] = rng.standard_normal((400, 1))
    inputs["y0"] = np.r_[0.1, -0.2, np.zeros(398)]
    inputs["theta"] = rng.standard_normal((50, 1, 6))
    return inputs


@pytest.mark.skipif(
    os.environ.get("NUMBA_DISABLE_JIT", "0") != "0", reason="this process is uncompiled too"
)
def test_uncompiled_kernels_equal_the_compiled_ones(tmp_path):
    # the same functions run by the interpreter (NUMBA_DISABLE_JIT=1, a child process) and
    # compiled by numba (this process): the same numbers
    inputs = _kernel_inputs(np.random.default_rng(8))
    np.savez(tmp_path / "inputs.npz", **inputs)
    child = (
        "import sys, types, numpy as np\n"
        f"sys.path.insert(0, {str(Path(__file__).parent)!r})\n"
        "from clpc.appraiser import kernel\n"
        "assert isinstance(kernel.solve_windows, types.FunctionType), 'compiled'\n"
        "from test_window_kernel import kernel_outputs\n"
        "inputs = dict(np.load(sys.argv[1]))\n"
        "np.savez(sys.argv[2], **kernel_outputs(inputs))\n"
    )
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    cmd = [sys.executable, "-c", child, str(tmp_path / "inputs.npz"), str(tmp_path / "out.npz")]
    subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
    slow = dict(np.load(tmp_path / "out.npz"))
    assert not isinstance(kernel.solve_windows, types.FunctionType)  # compiled here
    fast = kernel_outputs(inputs)
    assert sorted(slow) == sorted(fast)
    for key, value in fast.items():
        np.testing.assert_allclose(slow[key], value, rtol=1e-13, atol=0, err_msg=key)


@pytest.mark.parametrize("kind", ["ramp", "constant", "zeros"])
def test_kernel_agrees_with_reference_on_poorly_excited_and_degenerate_windows(kind):
    rng = np.random.default_rng(5)
    u = rng.standard_normal(2000)
    if kind == "ramp":
        u[600:1400] = np.linspace(0.0, 4.0, 800)
    elif kind == "constant":
        u[600:1400] = 2.0
    else:
        u[:] = 0.0
    y = clpc.simulate_arx(DEN, NUM, u) + (0 if kind == "zeros" else 1e-3) * rng.standard_normal(
        2000
    )
    for gate in (False, True):
        appraiser = CLPC(order=2, window_size=101, cluster_size=12, guard=gate)
        fast = appraiser.run(u, y)
        ref = reference_clpc(u, y, appraiser)
        np.testing.assert_array_equal(fast.degenerate, ref["degenerate"][:, 0])
        np.testing.assert_array_equal(fast.accepted, ref["accepted"][:, 0])
        for key in ("theta", "den", "D", "J", "c"):
            assert np.all(np.isfinite(fast.arrays[key])), key
        np.testing.assert_allclose(fast.theta, ref["theta"][:, 0], atol=1e-9)
    if kind == "zeros":
        assert fast.degenerate.all() and not fast.has_model.any()


def test_block_rows_balance_pieces_and_merge():
    assert kernel.block_rows(201, 12) == 12  # the paper's settings: B = C, no head piece
    assert kernel.block_rows(201, 1) == 14
    assert kernel.block_rows(201, 5) == 15
    assert kernel.block_rows(40, 1) == 6
    assert kernel.block_rows(10, 12) == 12


@pytest.mark.parametrize(("window", "cluster"), [(201, 12), (201, 1), (150, 4)])
def test_compiled_stream_and_step_are_bit_identical_to_run(window, cluster):
    u, y = _record(2000, seed=9, offset=1e4)
    u, y = u[:, 0], y[:, 0]
    settings = {"order": 2, "window_size": window, "cluster_size": cluster}
    batch = CLPC(**settings).run(u, y)
    a = CLPC(**settings)
    pushed = Trace.concat([a.push(u[i : i + 97], y[i : i + 97]) for i in range(0, 2000, 97)])
    b = CLPC(**settings)
    # python and numpy scalars take the light path, arrays the general one
    feeds = [float, np.float64, lambda v: np.array([v])]
    stepped = [b.step(feeds[k % 3](u[k]), feeds[k % 3](y[k])) for k in range(2000)]
    stepped = Trace.concat(stepped)
    for key in ("theta", "D", "eigenvalues", "c", "den", "J"):
        np.testing.assert_array_equal(pushed.arrays[key], batch.arrays[key], key)
        np.testing.assert_array_equal(stepped.arrays[key], batch.arrays[key], key)
    assert b.counter == a.counter == (2000 - 2) % cluster


def test_step_with_integer_and_float32_samples():
    rng = np.random.default_rng(2)
    u = rng.integers(-5, 6, 400)
    y = clpc.simulate_arx(DEN, NUM, u.astype(float)).round(3).astype(np.float32)
    ref = CLPC(order=2, window_size=60, cluster_size=12).run(u.astype(float), y.astype(float))
    a = CLPC(order=2, window_size=60, cluster_size=12)
    stepped = Trace.concat([a.step(int(u[k]), y[k]) for k in range(400)])
    np.testing.assert_array_equal(stepped.theta, ref.theta)


def test_step_rejects_non_finite_scalars_with_the_sample_index():
    a = CLPC(order=2, window_size=60, cluster_size=12)
    for k in range(5):
        a.step(float(k), 1.0 + k)
    with pytest.raises(DataError, match="y channel 0 is not finite at sample 5"):
        a.step(1.0, float("nan"))
    assert a.n_samples == 5  # the bad sample was not taken


# ---------------------------------------------------------------- the input-relation trap
def _input_trap_record() -> tuple[np.ndarray, np.ndarray]:
    """A chirp input (smooth: ``u(n) - 2 u(n-1) + u(n-2) ~ 0`` over many windows) and an
    output 100 times the input's size: the paper's smallest eigenvector is then an input
    relation whose unit-free ``y(n)`` weight (0.07-0.09) passed the former 1e-3 rule."""
    rng = np.random.default_rng(2)
    t = np.arange(4000)
    u0 = np.sin(2 * np.pi * (t / 4000) ** 2 * 50)
    den = np.real(np.poly(0.97 * np.exp(1j * np.array([0.05, -0.05]))))
    u = u0 + 1e-4 * rng.standard_normal(t.size)
    y = 100 * clpc.simulate_arx(den, np.array([0.0, 0.01, 0.005]), u0)
    return u, y + 1e-2 * rng.standard_normal(t.size)


def test_a_solution_that_is_an_input_relation_is_never_accepted():
    """Issue 28 item 4: the guard accepted windows whose solution hardly involves y(n)."""
    u, y = _input_trap_record()
    rule = clpc.RobustRule()
    for guard in (True, False):
        tr = CLPC(method="paper", guard=guard).run(u, y)
        # the windows the former rule accepted: one separated, computable, excited solution
        trap = (
            (tr.a0_weight >= 1e-3)
            & (tr.a0_weight < rule.min_a0_weight)
            & ~tr.degenerate
            & ~tr.not_enough_data
        )
        assert trap.sum() >= 3
        assert not tr.accepted[trap].any()
        assert (tr.n_input_relations[trap] >= 1).all()
        assert not tr.determined[trap].any()
        # the other windows still decide as before: a plant relation is accepted
        assert tr.accepted[~trap].any()


def test_batch_lpc_flags_an_input_relation_solution_like_the_kernel():
    u, y = _input_trap_record()
    tr = CLPC(method="paper").run(u, y)
    j = int(np.flatnonzero((tr.a0_weight < 0.1) & ~tr.degenerate & ~tr.not_enough_data)[0])
    end = int(tr.index[j]) + 1
    start = end - int(tr.rows[j]) - 2  # the window's rows and the lags before them
    model = clpc.LPC(method="paper").fit(clpc.IOData(u[start:end], y[start:end]))
    info = model.info
    assert float(np.atleast_1d(info["a0_weight"])[0]) < 0.1
    assert int(np.atleast_1d(info["n_input_relations"])[0]) >= 1
    assert not bool(np.atleast_1d(info["determined"])[0])
    verdict = model.verdict()
    assert not verdict.determined
    assert any("not persistently exciting" in n for n in verdict.messages)


def test_robust_rule_refuses_a_zero_a0_threshold():
    with pytest.raises(ValueError, match=r"min_a0_weight must be a number in \(0, 1\]"):
        clpc.RobustRule(min_a0_weight=0.0)


def test_trace_of_needs_every_field_and_equals_the_dataclass_init():
    u, y = _record(400, seed=6)
    trace = CLPC(order=2, window_size=60, cluster_size=12).run(u, y)
    values = {name: getattr(trace, name) for name in trace.__dataclass_fields__}
    again = Trace.of(values)
    assert again.__dict__ == trace.__dict__ and len(again) == len(trace)
    del values["meta"]
    with pytest.raises(TypeError, match="meta"):
        Trace.of(values)


def test_trace_view_shares_rows_and_allocate_copies_meta():
    u, y = _record(400, seed=6)
    trace = CLPC(order=2, window_size=60, cluster_size=12).run(u, y)
    part = trace.view(3, 7)
    assert len(part) == 4
    np.testing.assert_array_equal(part.theta, trace.theta[3:7])
    part.arrays["D"][0, 0] = -1.0  # a view: writing it writes the trace
    assert trace.arrays["D"][3, 0] == -1.0
    fresh = Trace.allocate(trace, 5)
    fresh.meta["mark"] = 1
    assert "mark" not in trace.meta and len(fresh) == 5


@pytest.mark.parametrize("cluster", [1, 12])
def test_block_cache_reuse_is_bit_identical_across_a_saved_state(cluster):
    # step fills the block cache (statistics of the newest blocks, reused by later
    # updates); a restored state starts without it and recomputes: the same bits
    u, y = _record(900, seed=11, offset=50.0)
    u, y = u[:, 0], y[:, 0]
    settings = {"order": 2, "window_size": 101, "cluster_size": cluster}
    batch = CLPC(**settings).run(u, y)
    a = CLPC(**settings)
    first = [a.step(float(u[k]), float(y[k])) for k in range(500)]
    span = a._state.blocks.span.copy()
    assert span[1] > span[0]  # blocks were kept between the updates
    b = CLPC.from_state_dict(json.loads(json.dumps(a.state_dict())))
    rest = [b.step(float(u[k]), float(y[k])) for k in range(500, 900)]
    stepped = Trace.concat(first + rest)
    for key in ("theta", "theta_estimate", "eigenvalues", "D", "J", "excited", "accepted"):
        np.testing.assert_array_equal(stepped.arrays[key], batch.arrays[key], key)
