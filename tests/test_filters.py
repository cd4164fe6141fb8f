"""clpc.core.filters against scipy.signal (the reference they replace on the model's paths)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from clpc.core import filters
from clpc.core.filters import all_pole, fir, frequency_response


@pytest.fixture
def rng():
    """The same samples for every test, whatever ran before it (tests run in any order)."""
    return np.random.default_rng(11)


@pytest.mark.parametrize("b", [[0.2], [0.2, 0.5, -0.1], [0.0, 0.0, 1.5, 0.3]])
def test_fir_is_lfilter_from_rest(b, rng):
    x = rng.standard_normal(5000)
    np.testing.assert_allclose(fir(np.array(b), x), signal.lfilter(b, [1.0], x), rtol=0, atol=1e-13)


def test_fir_of_empty_signal_or_coefficients_is_zeros():
    assert fir(np.array([1.0, 2.0]), np.array([])).shape == (0,)
    np.testing.assert_array_equal(fir(np.array([]), np.ones(3)), np.zeros(3))


@pytest.mark.parametrize(
    "den", [[1.0, -1.5, 0.7], [1.0, -0.95], [1.0, -2.2, 1.85, -0.6], [2.0, -1.0, 0.3]]
)
def test_all_pole_is_lfilter_started_from_past_outputs(den, rng):
    x = rng.standard_normal(4000)
    past = rng.standard_normal(len(den) - 1)
    zi = signal.lfiltic([1.0], den, past)
    ref = signal.lfilter([1.0], den, x, zi=zi)[0]
    got = all_pole(np.array(den), x, past)
    np.testing.assert_allclose(got, ref, rtol=1e-11, atol=1e-11 * np.max(np.abs(ref)))
    # rounding: relative to the signal's scale, as above (a sample near 0 has no own scale)
    rest = signal.lfilter([1.0], den, x)
    np.testing.assert_allclose(
        all_pole(np.array(den), x), rest, rtol=1e-11, atol=1e-11 * np.max(np.abs(rest))
    )


@pytest.mark.parametrize("block", [1, 2, 7, 4000])
def test_all_pole_carries_the_outputs_across_blocks(block, monkeypatch, rng):
    den = np.array([1.0, -2.2, 1.85, -0.6])
    x = rng.standard_normal(1000)
    past = rng.standard_normal(3)
    whole = all_pole(den, x, past)
    monkeypatch.setattr(filters, "BLOCK", block)
    np.testing.assert_allclose(all_pole(den, x, past), whole, rtol=1e-13, atol=1e-13)


def test_all_pole_without_poles_returns_the_input(rng):
    x = rng.standard_normal(10)
    np.testing.assert_array_equal(all_pole(np.array([1.0]), x), x)


def test_all_pole_says_what_is_wrong():
    with pytest.raises(ValueError, match="den\\[0\\] must be a non-zero number"):
        all_pole(np.array([0.0, 1.0]), np.ones(3))
    with pytest.raises(ValueError, match="past must hold the last 2 outputs"):
        all_pole(np.array([1.0, -0.5, 0.1]), np.ones(3), np.ones(3))


@pytest.mark.parametrize("freqs", [512, 7, np.geomspace(1e-3, 50.0, 300)])
def test_frequency_response_is_freqz(freqs):
    b, a, fs = [0.1, 0.4, 0.2], [1.0, -1.2, 0.5], 100.0
    f, h = frequency_response(np.array(b), np.array(a), freqs, fs)
    f_ref, h_ref = signal.freqz(b, a, worN=freqs, fs=fs)
    np.testing.assert_allclose(f, f_ref, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(h, h_ref, rtol=1e-12)
