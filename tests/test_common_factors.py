"""Common pole/zero factors found and removed (``clpc.core.polynomials.cancel_common_factors``).

The polynomials are built as products of known factors, so the reduced ones are known in
closed form; the roots behind the search are solved in closed form at degrees 1 and 2 and by
companion eigenvalues above, across the degrees a fit produces.
"""

import numpy as np
import pytest

from clpc.core.polynomials import cancel_common_factors


def _poly(*roots: complex) -> np.ndarray:
    return np.real(np.poly(np.array(roots, dtype=complex))) if roots else np.array([1.0])


@pytest.mark.parametrize(
    ("common", "den_rest", "num_rest"),
    [
        ((0.9,), (0.5,), (-0.3,)),  # degree 2 both
        ((0.95 + 0.2j, 0.95 - 0.2j), (0.4,), (0.1,)),  # a complex pair, degree 3
        ((0.99,), (0.6 + 0.3j, 0.6 - 0.3j), ()),  # a numerator of degree 1
        ((0.8,), (0.5, -0.2, 0.1), (0.3, -0.7)),  # degree 4 and 3: companion eigenvalues
    ],
)
def test_a_common_factor_is_removed_and_the_rest_kept(common, den_rest, num_rest):
    den = _poly(*common, *den_rest)
    gain = 0.7
    num = np.concatenate([[0.0], gain * _poly(*common, *num_rest)])  # nk = 1 leading zero
    other = np.concatenate([[0.0], -1.3 * _poly(*common, *num_rest)])
    red_den, red_nums, removed = cancel_common_factors(den, np.array([num, other]))
    assert removed == len(common)
    np.testing.assert_allclose(red_den, _poly(*den_rest), atol=1e-10)
    np.testing.assert_allclose(
        red_nums[0], np.concatenate([[0.0], gain * _poly(*num_rest)]), atol=1e-10
    )
    np.testing.assert_allclose(
        red_nums[1], np.concatenate([[0.0], -1.3 * _poly(*num_rest)]), atol=1e-10
    )


def test_factors_further_apart_than_the_distance_stay():
    den = _poly(0.9, 0.5)
    num = np.concatenate([[0.0], _poly(0.9 + 0.05)])  # 0.05 apart, above 0.02
    red_den, red_nums, removed = cancel_common_factors(den, num[None, :])
    assert removed == 0
    np.testing.assert_array_equal(red_den, den)
    np.testing.assert_array_equal(red_nums[0], num)


def test_a_factor_must_be_common_to_every_input():
    den = _poly(0.9, 0.5)
    with_it = np.concatenate([[0.0], _poly(0.9, -0.3)])
    without = np.concatenate([[0.0], _poly(0.2, -0.3)])
    assert cancel_common_factors(den, np.array([with_it, without]))[2] == 0
    assert (
        cancel_common_factors(den, np.array([with_it, np.zeros(with_it.size)]))[2] == 1
    )  # unused input


def test_zero_roots_from_trailing_zeros_pair_like_any_other():
    den = _poly(0.0, 0.6)  # a pole at the origin: trailing zero coefficient
    num = np.concatenate([[0.0], _poly(0.0)])  # a zero at the origin
    red_den, _, removed = cancel_common_factors(den, num[None, :])
    assert removed == 1
    np.testing.assert_allclose(red_den, _poly(0.6), atol=1e-12)
