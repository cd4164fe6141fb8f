"""Digital filters of the drive: Tustin (bilinear) transforms with pre-warping.

The torque low-pass, the notch and the velocity-estimate filter are the bilinear transforms
of their continuous prototypes, pre-warped at their characteristic frequency (the cut-off
frequency, the notch centre); the loop runs them as biquads in transposed direct form II.
"""

from __future__ import annotations

import math

import numpy as np

from clpc_paper.plants.servo_parameters import ServoParameters

__all__ = ["_IDENTITY", "_filter_coefficients", "_tustin"]


def _tustin(num: list[float], den: list[float], rate: float, f_warp: float) -> np.ndarray:
    """Bilinear transform of ``num(s)/den(s)`` (descending powers, order <= 2).

    Pre-warped at ``f_warp`` [Hz]. Returns ``[b0, b1, b2, a1, a2]`` of
    ``(b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)``.
    """
    order = len(den) - 1
    w = 2.0 * math.pi * f_warp
    k = w / math.tan(w / (2.0 * rate))
    pnum = np.zeros(order + 1)
    pden = np.zeros(order + 1)
    minus = np.array([1.0, -1.0])  # 1 - q, ascending powers of q = z^-1
    plus = np.array([1.0, 1.0])
    for i in range(order + 1):
        power = order - i  # power of s of coefficient i
        term = np.array([k**power])
        for _ in range(power):
            term = np.convolve(term, minus)
        for _ in range(order - power):
            term = np.convolve(term, plus)
        pnum += num[i] * term
        pden += den[i] * term
    b = np.zeros(3)
    a = np.zeros(3)
    b[: order + 1] = pnum / pden[0]
    a[: order + 1] = pden / pden[0]
    return np.array([b[0], b[1], b[2], a[1], a[2]])


_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0, 0.0])


def _filter_coefficients(params: ServoParameters, rate: float) -> np.ndarray:
    """Biquad coefficients, shape (3, 5): torque low-pass, notch, velocity filter."""
    nyquist = rate / 2.0
    checks = {
        "torque_lowpass_frequency": params.torque_lowpass_frequency,
        "notch frequency (notch_frequency or the mechanical resonance)": (
            params.effective_notch_frequency
        ),
        "velocity_filter_frequency": params.velocity_filter_frequency,
    }
    for name, f in checks.items():
        if f is not None and f >= nyquist:
            raise ValueError(
                f"The {name} must be below the Nyquist frequency of the controller "
                f"({nyquist:g} Hz at inner_rate={rate:g} Hz); got {f:g} Hz. Raise inner_rate "
                "(or ServoParameters.controller_rate) or lower the frequency."
            )
    out = np.tile(_IDENTITY, (3, 1))
    f_lp = params.torque_lowpass_frequency
    if f_lp is not None:
        w = 2.0 * math.pi * f_lp
        if params.torque_lowpass_order == 1:
            out[0] = _tustin([0.0, w], [1.0, w], rate, f_lp)
        else:
            z = params.torque_lowpass_damping
            out[0] = _tustin([0.0, 0.0, w * w], [1.0, 2.0 * z * w, w * w], rate, f_lp)
    f_n = params.effective_notch_frequency
    if f_n is not None:
        w = 2.0 * math.pi * f_n
        zp = params.notch_damping
        zz = params.notch_depth * zp
        out[1] = _tustin([1.0, 2.0 * zz * w, w * w], [1.0, 2.0 * zp * w, w * w], rate, f_n)
    f_v = params.velocity_filter_frequency
    if f_v is not None:
        w = 2.0 * math.pi * f_v
        out[2] = _tustin([0.0, w], [1.0, w], rate, f_v)
    return out
