"""The LPC estimator: exact recovery, errors-in-variables consistency, TLS and SVD references,
invariances, determinism, validation.

Conventions checked here (see ``clpc.model``): ``theta = [a; b]`` is unit norm with
``a0 > 0``; the monic model is ``den = a / a0`` and ``num = -b / a0`` (``G = -B/A``).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import signal

import clpc
from clpc import ARX, LPC, DataError, IOData, lpc_solve
from clpc.lpc import structure_blocks
from clpc.lpc.regressors import Structure, regressors

METHODS = ["paper", "robust"]


def monic_error(model, truth):
    return float(np.linalg.norm(np.concatenate([model.den, model.num]) - truth))


def check_conventions(model):
    """theta is unit norm, a0 > 0, den = a/a0, num = -b/a0 (per output and input)."""
    s = model.structure
    theta = model.theta_matrix
    assert model.theta.shape == ((theta.shape[1],) if model.n_outputs == 1 else theta.shape)
    np.testing.assert_allclose(np.linalg.norm(theta, axis=1), 1.0, rtol=1e-12)
    assert np.all(theta[:, 0] > 0)
    a = theta[:, : s.na + 1]
    a0 = theta[:, :1]
    np.testing.assert_allclose(model.denominators, a / a0, rtol=1e-12, atol=1e-15)
    for j in range(model.n_outputs):
        b = theta[j, s.na + 1 :].reshape(-1, s.nb + 1)
        inputs = [j] if model.mode == "paired" else range(model.n_inputs)
        for blk, i in enumerate(inputs):
            np.testing.assert_allclose(
                model.numerators[j, i, s.nk :], -b[blk] / a0[j, 0], rtol=1e-12, atol=1e-15
            )
            assert np.all(model.numerators[j, i, : s.nk] == 0)


# ============================================================================ exact recovery


@pytest.mark.parametrize("method", METHODS)
def test_exact_recovery_siso(method, siso2, rich_input):
    u = rich_input(2000, seed=1)
    y = siso2.output(u)
    model = LPC(order=2, method=method).fit(u, y)
    np.testing.assert_allclose(model.den, siso2.den, atol=1e-9)
    np.testing.assert_allclose(model.num, siso2.num, atol=1e-9)
    check_conventions(model)
    assert model.info["determined"] is True
    assert model.info["lambda_min"] < 1e-18 * model.info["lambda_max"]


@pytest.mark.parametrize("method", METHODS)
def test_exact_recovery_unequal_orders_and_delay(method, siso_delay, rich_input):
    u = rich_input(2000, seed=2)
    y = siso_delay.output(u)
    model = LPC(na=3, nb=1, nk=2, method=method).fit(u, y)
    assert model.structure == Structure(3, 1, 2)
    assert model.num.shape == (4,)
    np.testing.assert_allclose(model.den, siso_delay.den, atol=1e-9)
    np.testing.assert_allclose(model.num, siso_delay.num, atol=1e-9)
    check_conventions(model)


@pytest.mark.parametrize("method", METHODS)
def test_exact_recovery_with_offsets_gives_the_intercept(method, siso2, rich_input):
    u0 = rich_input(1500, seed=3)
    y0 = siso2.output(u0)
    model = LPC(order=2, method=method).fit(u0 + 3.0, y0 - 7.0)
    np.testing.assert_allclose(model.den, siso2.den, atol=1e-9)
    np.testing.assert_allclose(model.num, siso2.num, atol=1e-9)
    # A (y0 - 7) = B (u - 3) - 7 A(1)  ->  intercept = -7 A(1) - 3 B(1)
    expected = -7.0 * siso2.den.sum() - 3.0 * siso2.num.sum()
    np.testing.assert_allclose(model.intercept, [expected], atol=1e-8)


@pytest.mark.parametrize("method", METHODS)
def test_exact_recovery_paired_mimo(method, rich_input):
    # the paper's eqs. 35-38: output j driven by input j only
    dens = np.array([[1.0, -1.5, 0.7], [1.0, -0.3, -0.1]])
    nums = np.array([[0.5, 1.0, 0.3], [0.0, 2.0, -0.5]])
    u = rich_input(3000, seed=4, m=2)
    y = np.column_stack([signal.lfilter(nums[j], dens[j], u[:, j]) for j in range(2)])
    model = LPC(order=2, method=method, mimo="paired").fit(u, y)
    assert model.mode == "paired" and model.numerators.shape == (2, 2, 3)
    np.testing.assert_allclose(model.denominators, dens, atol=1e-9)
    for j in range(2):
        np.testing.assert_allclose(model.numerators[j, j], nums[j], atol=1e-9)
        assert np.all(model.numerators[j, 1 - j] == 0.0)
    check_conventions(model)


@pytest.mark.parametrize("method", METHODS)
def test_exact_recovery_miso(method, rich_input):
    # y_j = (B_j1 u_1 + B_j2 u_2) / A_j: one equation per output over both inputs
    dens = np.array([[1.0, -1.2, 0.5], [1.0, 0.4, 0.1]])
    nums = np.array([[[1.0, 0.5, 0.2], [0.3, -0.7, 0.1]], [[0.2, 0.0, 1.0], [-1.0, 0.5, 0.5]]])
    u = rich_input(3000, seed=5, m=2)
    y = np.column_stack(
        [sum(signal.lfilter(nums[j, i], dens[j], u[:, i]) for i in range(2)) for j in range(2)]
    )
    model = LPC(order=2, method=method, mimo="miso").fit(u, y)
    assert model.mode == "miso"
    np.testing.assert_allclose(model.denominators, dens, atol=1e-9)
    np.testing.assert_allclose(model.numerators, nums, atol=1e-9)
    check_conventions(model)
    # 2 x 2 data default to "miso"
    np.testing.assert_allclose(LPC(order=2, method=method).fit(u, y).numerators, nums, atol=1e-9)


@pytest.mark.parametrize("method", METHODS)
def test_overparametrised_noise_free_keeps_the_transfer_function(method, eiv_system):
    # order 3 on an order-2 system: the null space holds theta * (alpha + beta q^-1); any
    # member with alpha != 0 has the same G = -B/A
    u = np.random.default_rng(0).standard_normal(3000)
    model = LPC(order=3, method=method).fit(u, eiv_system.output(u))
    _, h_model = model.frequency_response(64)
    _, h_true = signal.freqz(eiv_system.num, eiv_system.den, worN=64, fs=1.0)
    np.testing.assert_allclose(h_model, h_true, atol=1e-9)


def test_robust_detects_the_noise_free_null_subspace(eiv_system):
    verdicts = []
    for seed in range(4):
        u = np.random.default_rng(seed).standard_normal(3000)
        model = LPC(order=3).fit(u, eiv_system.output(u))
        verdicts.append((model.info["n_null"], model.is_stable))
    assert verdicts == [(2, True)] * 4


def test_info_statistics_match_the_paper_formulas(siso2, rich_input):
    rng = np.random.default_rng(6)
    u = rich_input(800, seed=6) + 0.05 * rng.standard_normal(800)
    y = siso2.output(u) + 0.05 * rng.standard_normal(800)
    model = LPC(order=2, method="paper").fit(u, y)
    mat = regressors(IOData(u, y), Structure(2, 2), "siso")[0]
    n = mat.shape[0]
    z_mean = mat.mean(axis=0)  # eq. 25
    centered = mat - z_mean
    scatter = centered.T @ centered  # eq. 27
    theta = model.theta
    lam = np.linalg.eigvalsh(scatter)
    info = model.info
    assert info["method"] == "paper"
    np.testing.assert_allclose(info["eigenvalues"], lam, rtol=1e-9, atol=1e-9 * lam[-1])
    np.testing.assert_allclose(scatter @ theta, lam[0] * theta, atol=1e-8 * lam[-1])  # eq. 29
    assert isinstance(info["D"], float) and isinstance(info["n_rows"], int)  # SISO: scalars
    np.testing.assert_allclose(info["c"], z_mean @ theta, rtol=1e-12)  # eq. 24
    var = lam[0] / n
    np.testing.assert_allclose(info["noise_variance"], var, rtol=1e-8)
    np.testing.assert_allclose(info["D"], lam[-1] - lam[0], rtol=1e-12)
    np.testing.assert_allclose(info["eig_ratio"], lam[0] / lam[-1], rtol=1e-8)
    np.testing.assert_allclose(
        info["log_likelihood"], -0.5 * n * (np.log(2 * np.pi * var) + 1), rtol=1e-10
    )
    np.testing.assert_allclose(info["J"], 0.5 * n * (np.log(var) + 1), rtol=1e-10)
    assert info["n_rows"] == n


# ============================================================================ errors in variables


def eiv_record(system, n, seed, sigma_u, sigma_y):
    gen = np.random.default_rng(seed)
    u0 = gen.standard_normal(n)
    y0 = system.output(u0)
    return u0 + sigma_u * gen.standard_normal(n), y0 + sigma_y * gen.standard_normal(n)


SEEDS = (0, 1, 2)
LENGTHS = (1_000, 10_000, 100_000)


@pytest.fixture(scope="module")
def eiv_equal_errors(eiv_system):
    """Median monic error over SEEDS per T: equal white noise (std 0.1, ~20 dB) on u and y."""
    table = {}
    for n in LENGTHS:
        errs = {"paper": [], "robust": [], "ls": []}
        for seed in SEEDS:
            u, y = eiv_record(eiv_system, n, seed, 0.1, 0.1)
            truth = eiv_system.truth
            errs["paper"].append(monic_error(LPC(order=2, method="paper").fit(u, y), truth))
            errs["robust"].append(monic_error(LPC(order=2).fit(u, y), truth))
            errs["ls"].append(monic_error(ARX(order=2).fit(u, y), truth))
        table[n] = {k: float(np.median(v)) for k, v in errs.items()}
    return table


@pytest.mark.parametrize("method", METHODS)
def test_eiv_lpc_error_falls_with_length(eiv_equal_errors, method):
    errs = [eiv_equal_errors[n][method] for n in LENGTHS]
    assert errs[0] > errs[1] > errs[2]
    # roughly 1/sqrt(T): at least a factor 2 per decade, and small at 1e5
    assert errs[1] < errs[0] / 2 and errs[2] < errs[1] / 2
    assert errs[2] < 5e-3


@pytest.mark.parametrize("method", METHODS)
def test_eiv_lpc_beats_least_squares(eiv_equal_errors, method):
    ls = [eiv_equal_errors[n]["ls"] for n in LENGTHS]
    # least squares is biased: its error does not fall with T
    assert min(ls) > 0.25
    assert eiv_equal_errors[100_000][method] < ls[-1] / 3


def test_eiv_weighted_lpc_is_consistent_where_plain_lpc_is_biased(eiv_system):
    # var_u = 10 var_y: input SNR ~10 dB, output SNR ~20 dB
    sigma_u = 0.3
    sigma_y = sigma_u / np.sqrt(10.0)
    variances = np.r_[np.full(3, sigma_y**2), np.full(3, sigma_u**2)]
    plain, weighted, weighted_cov = {}, {}, {}
    for n in (10_000, 100_000):
        p, w, wc = [], [], []
        for seed in SEEDS:
            u, y = eiv_record(eiv_system, n, seed, sigma_u, sigma_y)
            p.append(monic_error(LPC(order=2, method="paper").fit(u, y), eiv_system.truth))
            w.append(
                monic_error(
                    LPC(order=2, method="paper", noise_ratio=10.0).fit(u, y), eiv_system.truth
                )
            )
            wc.append(
                monic_error(
                    LPC(order=2, method="paper", noise_cov=variances).fit(u, y), eiv_system.truth
                )
            )
        plain[n], weighted[n], weighted_cov[n] = np.median(p), np.median(w), np.median(wc)
    assert plain[10_000] > 0.15 and plain[100_000] > 0.15  # biased: does not shrink
    assert weighted[100_000] < 1e-2
    assert weighted[100_000] < plain[100_000] / 20
    assert weighted[100_000] < weighted[10_000]
    # a diagonal noise_cov with the same ratio is the same generalized eigenproblem
    np.testing.assert_allclose(weighted_cov[100_000], weighted[100_000], rtol=1e-6)


def test_eiv_weighted_robust_consistent_at_milder_input_noise(eiv_system):
    sigma_u = 0.2
    sigma_y = sigma_u / np.sqrt(10.0)
    errs, plain = [], []
    for seed in SEEDS:
        u, y = eiv_record(eiv_system, 100_000, seed, sigma_u, sigma_y)
        errs.append(monic_error(LPC(order=2, noise_ratio=10.0).fit(u, y), eiv_system.truth))
        plain.append(monic_error(LPC(order=2).fit(u, y), eiv_system.truth))
    assert np.median(errs) < 5e-3
    assert np.median(plain) > 0.1


def test_eiv_weighted_robust_consistent_at_strong_input_noise(eiv_system):
    sigma_u = 0.4
    sigma_y = sigma_u / np.sqrt(10.0)
    errs = []
    for seed in SEEDS:
        u, y = eiv_record(eiv_system, 100_000, seed, sigma_u, sigma_y)
        errs.append(monic_error(LPC(order=2, noise_ratio=10.0).fit(u, y), eiv_system.truth))
    assert np.median(errs) < 2e-2


# ============================================================================ TLS references


def orthogonal_regression(x, y):
    """Closed-form total least squares line y = slope x + intercept (equal error variances)."""
    sxx = np.mean((x - x.mean()) ** 2)
    syy = np.mean((y - y.mean()) ** 2)
    sxy = np.mean((x - x.mean()) * (y - y.mean()))
    slope = (syy - sxx + np.sqrt((syy - sxx) ** 2 + 4 * sxy**2)) / (2 * sxy)
    return slope, y.mean() - slope * x.mean()


@pytest.fixture
def noisy_line():
    gen = np.random.default_rng(7)
    x0 = np.linspace(-3.0, 3.0, 400)
    x = x0 + 0.3 * gen.standard_normal(400)
    y = -1.7 * x0 + 0.8 + 0.3 * gen.standard_normal(400)
    return x, y


def lpc_line(x, y):
    mat = np.column_stack([y, x])
    res = lpc_solve(mat[None], n_output_cols=1, blocks=[slice(0, 1), slice(1, 2)], method="paper")
    a, b = res.theta[0]
    # a y + b x = c  ->  y = -b/a x + c/a
    return -b / a, res.c[0] / a, res


def test_static_line_equals_closed_form_tls(noisy_line):
    x, y = noisy_line
    slope, intercept, res = lpc_line(x, y)
    ref_slope, ref_intercept = orthogonal_regression(x, y)
    np.testing.assert_allclose([slope, intercept], [ref_slope, ref_intercept], rtol=1e-12)
    # the least-squares slope is attenuated towards 0, TLS is not
    ls_slope = np.polyfit(x, y, 1)[0]
    assert abs(ls_slope) < abs(slope)
    # the minimum eigenvalue is the sum of squared orthogonal distances (eq. 9)
    d = (y - slope * x - intercept) / np.sqrt(1 + slope**2)
    np.testing.assert_allclose(res.eigenvalues[0, 0], np.sum(d**2), rtol=1e-10)


def test_static_line_equals_scipy_odr(noisy_line):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        odr = pytest.importorskip("scipy.odr")  # deprecated in scipy 1.17, removed in 1.19
    x, y = noisy_line
    slope, intercept, _ = lpc_line(x, y)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        fit = odr.ODR(
            odr.RealData(x, y), odr.unilinear, beta0=[0.0, 0.0], sstol=1e-15, partol=1e-15
        ).run()
    np.testing.assert_allclose([slope, intercept], fit.beta, rtol=1e-6)


def test_static_line_is_symmetric_in_x_and_y(noisy_line):
    # TLS treats both variables alike: swapping them inverts the line
    x, y = noisy_line
    slope, intercept, _ = lpc_line(x, y)
    inv_slope, inv_intercept, _ = lpc_line(y, x)
    np.testing.assert_allclose(inv_slope, 1 / slope, rtol=1e-10)
    np.testing.assert_allclose(inv_intercept, -intercept / slope, rtol=1e-10)


# ============================================================================ SVD / numerics


def reference_svd(mat):
    """Independent reference: mean by math.fsum (exactly rounded), then LAPACK SVD."""
    mean = np.array([math.fsum(col) / mat.shape[0] for col in mat.T])
    _, s, vt = np.linalg.svd(mat - mean, full_matrices=False)
    v = vt[-1] * np.sign(vt[-1, 0])
    return v, s[::-1] ** 2


def raw_moment_lpc(mat):
    """The naive route: raw sums of products minus n Z Z^T (loses digits with offsets)."""
    n = mat.shape[0]
    z = mat.sum(axis=0)
    vals, vecs = np.linalg.eigh(mat.T @ mat - np.outer(z, z) / n)
    return vecs[:, 0] * np.sign(vecs[0, 0]), vals


def dynamic_matrix(offset, seed=8):
    gen = np.random.default_rng(seed)
    u = gen.standard_normal(4000)
    y = signal.lfilter([0.5, 1.0, 0.3], [1.0, -1.5, 0.7], u) + 1e-3 * gen.standard_normal(4000)
    return regressors(IOData(u + offset, y + offset), Structure(2, 2), "siso")[0]


def ill_conditioned_matrix():
    gen = np.random.default_rng(9)
    x = gen.standard_normal(4000)
    cols = [x, x + 1e-5 * gen.standard_normal(4000), 2 * x + 1e-7 * gen.standard_normal(4000)]
    return np.column_stack([*cols, gen.standard_normal(4000)]) + 1e4


@pytest.mark.parametrize(
    "mat",
    [dynamic_matrix(0.0), dynamic_matrix(1e4), ill_conditioned_matrix()],
    ids=["dynamic", "dynamic-offset-1e4", "ill-conditioned-offset-1e4"],
)
def test_agrees_with_svd_of_centered_data(mat):
    p = mat.shape[1]
    res = lpc_solve(
        mat[None], n_output_cols=1, blocks=[slice(i, i + 1) for i in range(p)], method="paper"
    )
    v, s2 = reference_svd(mat)
    np.testing.assert_allclose(res.theta[0], v, rtol=0, atol=1e-10)
    # eigenvalues of the scatter matrix are the squared singular values (eq. 11)
    np.testing.assert_allclose(res.eigenvalues[0], s2, rtol=0, atol=1e-10 * s2[-1])


def test_naive_raw_moments_lose_digits_that_lpc_keeps():
    # why the references above matter: with offsets ~1e4 the raw-moment route is ~1e-7 off
    mat = dynamic_matrix(1e4)
    res = lpc_solve(mat[None], n_output_cols=3, blocks=[slice(0, 3), slice(3, 6)], method="paper")
    v, _ = reference_svd(mat)
    naive, _ = raw_moment_lpc(mat)
    assert np.max(np.abs(res.theta[0] - v)) < 1e-12
    assert np.max(np.abs(naive - v)) > 1e-9


def test_eigenvalues_equal_naive_loop_scatter():
    # a plain double loop over rows (two-pass centering) for eq. 27
    mat = dynamic_matrix(0.0)[:300]
    n, p = mat.shape
    mean = [math.fsum(mat[:, j]) / n for j in range(p)]
    scatter = np.zeros((p, p))
    for row in mat:
        d = row - mean
        for i in range(p):
            for j in range(p):
                scatter[i, j] += d[i] * d[j]
    res = lpc_solve(mat[None], n_output_cols=3, blocks=[slice(0, 3), slice(3, 6)], method="paper")
    lam = np.linalg.eigvalsh(scatter)
    np.testing.assert_allclose(res.eigenvalues[0], lam, rtol=0, atol=1e-10 * lam[-1])


# ============================================================================ invariances


@pytest.fixture
def noisy_siso(siso2, rich_input):
    gen = np.random.default_rng(10)
    u0 = rich_input(3000, seed=10)
    y0 = siso2.output(u0)
    return u0 + 0.2 * gen.standard_normal(3000), y0 + 0.2 * gen.standard_normal(3000)


@pytest.mark.parametrize("k", [1e-3, 7.5, -2.0])
def test_std_scaling_u_scales_the_numerator_by_one_over_k(noisy_siso, k):
    # scaling="std" is the unit-free option: rescaling u rescales b, nothing else
    u, y = noisy_siso
    base = LPC(order=2, scaling="std").fit(u, y)
    scaled = LPC(order=2, scaling="std").fit(k * u, y)
    np.testing.assert_allclose(scaled.den, base.den, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(scaled.num, base.num / k, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("k", [1e-3, 7.5, -2.0])
def test_default_is_unit_free_on_noise_free_data(k):
    # the raw-units default is TLS: it depends on units only through the noise; without
    # noise every scaling gives the exact system
    rng = np.random.default_rng(11)
    u = rng.standard_normal(3000)
    y = clpc.simulate_arx([1.0, -1.5, 0.7], [0.2, 0.5, 0.1], u)
    scaled = LPC(order=2).fit(k * u, y)
    np.testing.assert_allclose(scaled.den, [1.0, -1.5, 0.7], atol=1e-9)
    np.testing.assert_allclose(scaled.num * k, [0.2, 0.5, 0.1], atol=1e-9)


@pytest.mark.parametrize("k", [1e-3, 7.5, -2.0])
def test_std_scaling_y_scales_the_numerator_by_k(noisy_siso, k):
    u, y = noisy_siso
    base = LPC(order=2, scaling="std").fit(u, y)
    scaled = LPC(order=2, scaling="std").fit(u, k * y)
    np.testing.assert_allclose(scaled.den, base.den, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(scaled.num, base.num * k, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(scaled.intercept, base.intercept * k, rtol=1e-9, atol=1e-12)


def test_paper_method_is_not_unit_free(noisy_siso):
    # documented difference: the literal eigenvector depends on the units of u and y
    u, y = noisy_siso
    base = LPC(order=2, method="paper").fit(u, y)
    scaled = LPC(order=2, method="paper").fit(100 * u, y)
    assert np.max(np.abs(scaled.num * 100 - base.num)) > 1e-3


def test_offsets_change_only_the_intercept(noisy_siso):
    u, y = noisy_siso
    base = LPC(order=2).fit(u, y)
    moved = LPC(order=2).fit(u + 1e4, y - 5e3)
    np.testing.assert_allclose(moved.den, base.den, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(moved.num, base.num, rtol=1e-8, atol=1e-10)
    shift = -5e3 * base.den.sum() - 1e4 * base.num.sum()
    np.testing.assert_allclose(moved.intercept, base.intercept + shift, rtol=1e-8)


@pytest.mark.parametrize("method", METHODS)
def test_sign_and_repeat_determinism(noisy_siso, method):
    u, y = noisy_siso
    first = LPC(order=2, method=method).fit(u, y)
    second = LPC(order=2, method=method).fit(u, y)
    assert first.theta[0] > 0
    np.testing.assert_array_equal(first.theta, second.theta)
    # -y flips the sign of b (num -> -num) but a0 stays positive
    flipped = LPC(order=2, method=method).fit(u, -y)
    assert flipped.theta[0] > 0
    np.testing.assert_allclose(flipped.num, -first.num, rtol=1e-9)


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.float32, np.float64])
def test_same_result_for_any_dtype_of_the_same_values(dtype):
    gen = np.random.default_rng(11)
    u = gen.integers(-50, 50, size=600)
    y = np.round(signal.lfilter([1.0, 0.5], [1.0, -0.5], u) + gen.integers(-3, 4, size=600))
    ref = LPC(order=2).fit(u.astype(np.float64), y.astype(np.float64))
    got = LPC(order=2).fit(u.astype(dtype), y.astype(dtype))
    np.testing.assert_array_equal(got.theta, ref.theta)


def test_pandas_lists_and_arrays_give_the_same_model(noisy_siso):
    u, y = noisy_siso
    ref = LPC(order=2).fit(u, y)
    frame = pd.DataFrame({"u": u, "y": y})
    for uu, yy in [
        (frame["u"], frame["y"]),
        (frame[["u"]], frame[["y"]]),
        (u.tolist(), y.tolist()),
        (IOData(u, y), None),
    ]:
        got = LPC(order=2).fit(uu, yy)
        np.testing.assert_array_equal(got.theta, ref.theta)
        np.testing.assert_array_equal(got.c, ref.c)
    named = LPC(order=2).fit(frame["u"], frame["y"], dt=0.01)
    assert named.input_names == ("u",) and named.output_names == ("y",) and named.dt == 0.01


def test_methods_agree_on_clean_well_scaled_data(eiv_system):
    # equal noise and equal channel variances: the per-channel scaling is ~identity
    u, y = eiv_record(eiv_system, 20_000, 12, 0.05, 0.05)
    paper = LPC(order=2, method="paper").fit(u, y)
    robust = LPC(order=2).fit(u, y)
    assert monic_error(paper, eiv_system.truth) < 0.02
    np.testing.assert_allclose(robust.den, paper.den, atol=5e-3)
    np.testing.assert_allclose(robust.num, paper.num, atol=5e-3)


def test_structure_from_settings():
    assert LPC(order=3).structure() == Structure(3, 3, 0)
    assert LPC(order=3, na=1).structure() == Structure(1, 3, 0)
    assert LPC(nb=0, nk=2).structure() == Structure(2, 0, 2)
    assert structure_blocks(Structure(2, 1), 2) == [slice(0, 3), slice(3, 5), slice(5, 7)]


# ============================================================================ validation


def test_constant_input_is_degenerate():
    y = np.random.default_rng(13).standard_normal(200)
    with pytest.raises(
        DataError,
        match=r"nothing to identify for output 0: constant channel\(s\) "
        r"\['u'\]",
    ):
        LPC().fit(np.full(200, 0.1), y)
    with pytest.raises(DataError, match=r"constant channel\(s\) \['y'\]"):
        LPC(method="paper").fit(y, np.full(200, 3.0))


def test_too_few_samples():
    with pytest.raises(
        DataError, match="An LPC fit with 8 parameters needs at least 12 samples; the record has 10"
    ):
        LPC(order=3).fit(np.arange(10.0), np.arange(10.0) ** 2)


def test_mode_errors_through_fit():
    u = np.random.default_rng(14).standard_normal((100, 3))
    with pytest.raises(DataError, match=r"mode 'paired' .* needs as many inputs as outputs"):
        LPC(mimo="paired").fit(u, u[:, :2])
    with pytest.raises(DataError, match="mode 'siso' needs one input and one output; got 2"):
        LPC(mimo="siso").fit(u[:, :2], u[:, 0])
    with pytest.raises(ValueError, match="mimo mode must be 'siso', 'paired' or 'miso'; got 'x'"):
        LPC(mimo="x").fit(u, u)  # type: ignore[arg-type]


@pytest.mark.parametrize("ratio", [0, -1.0, float("nan"), float("inf")])
def test_noise_ratio_must_be_positive(noisy_siso, ratio):
    with pytest.raises(
        ValueError, match=r"noise_ratio \(input/output noise variance\) must be (> 0|finite)"
    ):
        LPC(noise_ratio=ratio).fit(*noisy_siso)


def test_noise_cov_validation(noisy_siso):
    with pytest.raises(
        ValueError,
        match=r"noise_cov must have shape \(6,\) .* or \(6, 6\) .* got "
        r"shape \(5,\)",
    ):
        LPC(noise_cov=np.ones(5)).fit(*noisy_siso)
    with pytest.raises(ValueError, match=r"got shape \(6, 5\)"):
        LPC(noise_cov=np.ones((6, 5))).fit(*noisy_siso)
    with pytest.raises(ValueError, match="noise_cov must be positive definite"):
        LPC(noise_cov=np.ones((6, 6))).fit(*noisy_siso)
    with pytest.raises(ValueError, match="noise_cov must be positive definite"):
        LPC(noise_cov=-np.eye(6)).fit(*noisy_siso)
    with pytest.raises(ValueError, match="noise_cov must be a finite symmetric matrix"):
        LPC(noise_cov=np.triu(np.ones((6, 6)))).fit(*noisy_siso)
    with pytest.raises(ValueError, match="noise_cov must hold positive finite variances"):
        LPC(noise_cov=np.r_[np.ones(5), 0.0]).fit(*noisy_siso)


def test_bad_method(noisy_siso):
    with pytest.raises(ValueError, match="method must be 'robust' or 'paper'; got 'tls'"):
        LPC(method="tls").fit(*noisy_siso)


def test_constructor_only_stores(noisy_siso):
    est = LPC(order=-5, method="nope", noise_ratio=-1)  # no error until fit
    assert est.order == -5
    with pytest.raises(ValueError, match="order must be an int"):
        est.fit(*noisy_siso)


def test_exports():
    assert clpc.lpc_solve is lpc_solve


def test_default_is_consistent_under_eiv_with_unequal_channel_spreads():
    # equal white noise (std 0.3) on u (std 1) and on y (std 4.3): per-channel scaling
    # would assume equal signal-to-noise ratios and stay biased; the raw-unit default is TLS
    true = np.array([-1.5, 0.7, 0.0, 1.0, 0.5])

    def errors(n, seed):
        rng = np.random.default_rng(seed)
        u0 = rng.standard_normal(n)
        y0 = signal.lfilter([0.0, 1.0, 0.5], [1.0, -1.5, 0.7], u0)
        u, y = u0 + 0.3 * rng.standard_normal(n), y0 + 0.3 * rng.standard_normal(n)
        out = []
        for est in (LPC(order=2), LPC(order=2, scaling="std"), ARX(order=2)):
            m = est.fit(u, y)
            out.append(np.linalg.norm(np.r_[m.den[1:], m.num] - true))
        return np.array(out)

    short = np.mean([errors(10_000, s) for s in range(3)], axis=0)
    long = np.mean([errors(100_000, s) for s in range(3)], axis=0)
    lpc, std, ls = long
    assert long[0] < 0.45 * short[0]  # falls like 1/sqrt(T) (0.32 for 10x the samples)
    assert lpc < ls / 10  # a tenth of least squares' error at T = 1e5
    assert std > 0.08 and ls > 0.08  # both biased: they do not fall with T


def test_lpc_solve_with_fewer_rows_than_parameters_stays_finite():
    mats = np.random.default_rng(0).standard_normal((1, 4, 6))
    res = lpc_solve(mats, n_output_cols=3, blocks=[slice(0, 3), slice(3, 6)])
    assert res.theta.shape == (1, 6) and np.all(np.isfinite(res.theta))


def test_robust_rule_thresholds_are_checked():
    with pytest.raises(ValueError, match=r"RobustRule.separation must be a number in \[0, 1\]"):
        clpc.RobustRule(separation="x")
    with pytest.raises(ValueError, match="degeneracy_ratio"):
        clpc.RobustRule(degeneracy_ratio=0.5)
