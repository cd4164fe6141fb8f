"""The CLPC engine against an independent per-window SVD reference; its eigen-solver.

The reference (``tests/lpc_reference.py``) builds each window's lag matrix, centers it and
takes its SVD, with array formulas for the rules; the engine merges block statistics and
runs :mod:`clpc.core.rules` in compiled loops. Both engines of the one source (compiled and
plain Python) are checked against it.
"""

from __future__ import annotations

import numpy as np
import pytest

import clpc
from clpc import CLPC, DataError, Trace
from clpc.core import jit as engine_module
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


# ---------------------------------------------------------------- engine parity
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
    ({"gate": True, "window_size": 60, "cluster_size": 7}, 1, 1),
    ({"na": 3, "nb": 1, "nk": 2, "window_size": 24, "cluster_size": 12}, 1, 1),
    ({"cluster_size": 1, "window_size": 40}, 1, 1),
    ({"mimo": "miso"}, 2, 2),
    ({"mimo": "paired", "method": "paper"}, 2, 2),
]


@pytest.mark.parametrize(("kwargs", "n_in", "n_out"), PARITY_CASES)
def test_engine_equals_per_window_svd_reference(kwargs, n_in, n_out):
    u, y = _record(3000, seed=3, n_in=n_in, n_out=n_out, offset=1e3)
    settings = {"parameters_size": 3, "window_size": 201, "cluster_size": 12, **kwargs}
    appraiser = CLPC(**settings, engine="compiled")
    _compare(appraiser.run(u, y), reference_clpc(u, y, appraiser))


@pytest.mark.parametrize(("kwargs", "n_in", "n_out"), PARITY_CASES[::3])
def test_python_engine_runs_the_same_source(kwargs, n_in, n_out):
    # the uncompiled engine: the very same functions, run by the interpreter (coverage)
    u, y = _record(700, seed=4, n_in=n_in, n_out=n_out, offset=1e3)
    settings = {"parameters_size": 3, "window_size": 101, "cluster_size": 12, **kwargs}
    appraiser = CLPC(**settings, engine="python")
    slow = appraiser.run(u, y)
    _compare(slow, reference_clpc(u, y, appraiser))
    fast = CLPC(**settings, engine="compiled").run(u, y)
    for key in ("theta", "eigenvalues", "c", "J", "accepted"):
        np.testing.assert_allclose(slow.arrays[key], fast.arrays[key], rtol=1e-13, atol=0)


@pytest.mark.parametrize("kind", ["ramp", "constant", "zeros"])
def test_engine_agrees_with_reference_on_poorly_excited_and_degenerate_windows(kind):
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
        appraiser = CLPC(3, 101, 12, gate=gate, engine="compiled")
        fast = appraiser.run(u, y)
        ref = reference_clpc(u, y, appraiser)
        np.testing.assert_array_equal(fast.degenerate, ref["degenerate"][:, 0])
        np.testing.assert_array_equal(fast.accepted, ref["accepted"][:, 0])
        for key in ("theta", "den", "D", "J", "c"):
            assert np.all(np.isfinite(fast.arrays[key])), key
        np.testing.assert_allclose(fast.theta, ref["theta"][:, 0], atol=1e-9)
    if kind == "zeros":
        assert fast.degenerate.all() and not fast.has_model.any()


def test_compiled_stream_and_step_are_bit_identical_to_run():
    u, y = _record(2000, seed=9, offset=1e4)
    u, y = u[:, 0], y[:, 0]
    batch = CLPC(3, 201, 12, engine="compiled").run(u, y)
    a = CLPC(3, 201, 12, engine="compiled")
    pushed = Trace.concat([a.push(u[i : i + 97], y[i : i + 97]) for i in range(0, 2000, 97)])
    b = CLPC(3, 201, 12, engine="compiled")
    # python and numpy scalars take the light path, arrays the general one
    feeds = [float, np.float64, lambda v: np.array([v])]
    stepped = [b.step(feeds[k % 3](u[k]), feeds[k % 3](y[k])) for k in range(2000)]
    stepped = Trace.concat(stepped)
    for key in ("theta", "D", "eigenvalues", "c", "den", "J"):
        np.testing.assert_array_equal(pushed.arrays[key], batch.arrays[key], key)
        np.testing.assert_array_equal(stepped.arrays[key], batch.arrays[key], key)
    assert b.counter == a.counter == (2000 - 2) % 12


def test_step_with_integer_and_float32_samples():
    rng = np.random.default_rng(2)
    u = rng.integers(-5, 6, 400)
    y = clpc.simulate_arx(DEN, NUM, u.astype(float)).round(3).astype(np.float32)
    ref = CLPC(3, 60, 12).run(u.astype(float), y.astype(float))
    a = CLPC(3, 60, 12)
    stepped = Trace.concat([a.step(int(u[k]), y[k]) for k in range(400)])
    np.testing.assert_array_equal(stepped.theta, ref.theta)


def test_step_rejects_non_finite_scalars_with_the_sample_index():
    a = CLPC(3, 60, 12)
    for k in range(5):
        a.step(float(k), 1.0 + k)
    with pytest.raises(DataError, match="y channel 0 is not finite at sample 5"):
        a.step(1.0, float("nan"))
    assert a.n_samples == 5  # the bad sample was not taken


def test_engine_choice_and_errors(monkeypatch):
    assert CLPC(engine="python").engine == "python"
    monkeypatch.setenv("CLPC_ENGINE", "python")
    assert CLPC().engine == "python"
    assert CLPC(engine="compiled").engine == "compiled"  # an explicit choice wins
    monkeypatch.setenv("CLPC_ENGINE", "fast")
    with pytest.raises(ValueError, match="CLPC_ENGINE"):
        CLPC()
    with pytest.raises(ValueError, match="engine must be"):
        CLPC(engine="gpu")
    with pytest.raises(ValueError, match="engine must be"):
        CLPC(engine="numpy")  # the numpy engine is gone: one source, two ways to run it
    monkeypatch.setattr(engine_module, "numba_available", lambda: False)
    with pytest.raises(ValueError, match="needs numba"):
        CLPC(engine="compiled")
    monkeypatch.delenv("CLPC_ENGINE")
    assert CLPC().engine == "python"  # auto without numba
