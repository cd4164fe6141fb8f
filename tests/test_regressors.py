"""Lag matrices (paper eq. 36) against naive loops; Structure and mode validation."""

from __future__ import annotations

import numpy as np
import pytest

from clpc import DataError, IOData, Structure
from clpc.lpc.regressors import (
    check_mode,
    column_labels,
    default_mode,
    lagged,
    miso_regressor,
    regressors,
    siso_regressor,
)


def naive_rows(y: np.ndarray, u: np.ndarray, s: Structure) -> np.ndarray:
    """Row n: [y(n) .. y(n-na), u_1(n-nk) .. u_1(n-nk-nb), ..., u_m(...)], by loops."""
    u = u.reshape(len(u), -1)
    rows = []
    for n in range(s.max_lag, len(y)):
        row = [y[n - i] for i in range(s.na + 1)]
        for c in range(u.shape[1]):
            row += [u[n - s.nk - i, c] for i in range(s.nb + 1)]
        rows.append(row)
    return np.array(rows)


STRUCTURES = [Structure(2, 2), Structure(3, 1, 2), Structure(1, 0), Structure(1, 4, 1)]


@pytest.mark.parametrize("s", STRUCTURES, ids=str)
def test_siso_regressor_equals_naive_loop(s):
    rng = np.random.default_rng(3)
    y, u = rng.standard_normal(40), rng.standard_normal(40)
    mat = siso_regressor(y, u, s)
    assert mat.shape == (s.n_rows(40), s.n_params(1))
    np.testing.assert_array_equal(mat, naive_rows(y, u, s))


@pytest.mark.parametrize("s", STRUCTURES, ids=str)
def test_miso_regressor_equals_naive_loop(s):
    rng = np.random.default_rng(4)
    y, u = rng.standard_normal(30), rng.standard_normal((30, 3))
    mat = miso_regressor(y, u, s)
    assert mat.shape == (s.n_rows(30), s.n_params(3))
    assert mat.flags.c_contiguous
    np.testing.assert_array_equal(mat, naive_rows(y, u, s))


def test_lagged_view():
    x = np.arange(10.0)
    view = lagged(x, order=2, delay=1, start=4)
    # entry [r, j] = x[start + r - delay - j]
    expected = np.array([[x[4 + r - 1 - j] for j in range(3)] for r in range(6)])
    np.testing.assert_array_equal(view, expected)
    with pytest.raises(ValueError, match="start=2 is too early for delay=1 and order=2"):
        lagged(x, order=2, delay=1, start=2)


def test_stacked_modes():
    rng = np.random.default_rng(5)
    u, y = rng.standard_normal((25, 2)), rng.standard_normal((25, 2))
    d = IOData(u, y)
    s = Structure(2, 1, 1)
    paired = regressors(d, s, "paired")
    miso = regressors(d, s, "miso")
    assert paired.shape == (2, 23, s.n_params(1))
    assert miso.shape == (2, 23, s.n_params(2))
    for j in range(2):
        np.testing.assert_array_equal(paired[j], naive_rows(y[:, j], u[:, j], s))
        np.testing.assert_array_equal(miso[j], naive_rows(y[:, j], u, s))
    siso = regressors(IOData(u[:, 0], y[:, 0]), s, "siso")
    np.testing.assert_array_equal(siso[0], paired[0])


def test_structure_properties():
    s = Structure(3, 1, 2)
    assert s.max_lag == 3
    assert Structure(1, 2, 4).max_lag == 6
    assert s.n_params() == 6 and s.n_params(3) == 4 + 3 * 2
    assert s.n_rows(10) == 7 and s.n_rows(2) == 0
    assert Structure.from_order(4) == Structure(4, 4, 0)
    assert Structure.from_order(2, nk=1) == Structure(2, 2, 1)
    assert Structure(np.int64(2), 1).na == 2


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"na": -1, "nb": 1}, r"na must be an int in the range \[1, inf\); got -1"),
        ({"na": 0, "nb": 1}, r"na must be an int in the range \[1, inf\); got 0"),
        ({"na": True, "nb": 1}, r"na must be an int in the range \[1, inf\); got True"),
        ({"na": 2.0, "nb": 1}, r"na must be an int in the range \[1, inf\); got 2.0"),
        ({"na": 2, "nb": -1}, r"nb must be an int in the range \[0, inf\); got -1"),
        ({"na": 2, "nb": False}, r"nb must be an int in the range \[0, inf\); got False"),
        ({"na": 2, "nb": 1.5}, r"nb must be an int in the range \[0, inf\); got 1.5"),
        ({"na": 2, "nb": 1, "nk": -2}, r"nk must be an int in the range \[0, inf\); got -2"),
        ({"na": 2, "nb": 1, "nk": 1.0}, r"nk must be an int in the range \[0, inf\); got 1.0"),
        ({"na": 2, "nb": 1, "nk": True}, r"nk must be an int .* got True"),
    ],
)
def test_structure_validation(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        Structure(**kwargs)


def test_from_order_validation():
    with pytest.raises(ValueError, match=r"order must be an int in the range \[1, inf\); got 0"):
        Structure.from_order(0)


def test_too_few_samples():
    d = IOData(np.arange(5.0), np.arange(5.0))
    with pytest.raises(DataError, match="A model with na=4, nb=4, nk=0 needs at least 6 samples"):
        regressors(d, Structure(4, 4), "siso")


def test_mode_errors():
    with pytest.raises(ValueError, match="mimo mode must be 'siso', 'paired' or 'miso'; got 'x'"):
        check_mode("x", 1, 1)
    with pytest.raises(DataError, match=r"mode 'siso' needs one input and one output; got 2"):
        check_mode("siso", 2, 1)
    with pytest.raises(DataError, match=r"mode 'paired' .* needs as many inputs as outputs; got 3"):
        check_mode("paired", 3, 2)
    check_mode("miso", 3, 2)
    assert default_mode(1, 1) == "siso" and default_mode(2, 2) == "miso"


def test_column_labels():
    assert column_labels(Structure(2, 1, 1)) == ["y(n)", "y(n-1)", "y(n-2)", "u(n-1)", "u(n-2)"]
    labels = column_labels(Structure(1, 0), "pos", ("a", "b"))
    assert labels == ["pos(n)", "pos(n-1)", "a(n)", "b(n)"]
