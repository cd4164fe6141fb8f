"""The servo logs the torque the mechanics integrate: its mean over each logging period."""

from __future__ import annotations

import numpy as np

from clpc_paper.plants import ServoParameters, ramp_with_saturation, simulate_servo


def _pair(params: ServoParameters) -> tuple[object, object]:
    """The same run logged at every controller step (0.2 ms) and every 5th (1 ms)."""
    slow_cmd = ramp_with_saturation(0.4, 0.001, start=0.05, ramp_time=0.2, level=0.5)
    fast_cmd = np.repeat(slow_cmd, 5)  # the same command, held over each 1 ms
    fast = simulate_servo(fast_cmd, sample_time=0.0002, params=params, seed=7)
    slow = simulate_servo(slow_cmd, sample_time=0.001, params=params, seed=7)
    return fast, slow


def test_logged_torque_is_the_mean_over_the_logging_period() -> None:
    fast, slow = _pair(ServoParameters())
    # the drive ran the same steps: the 1 ms positions are every 5th controller-step reading
    np.testing.assert_array_equal(slow.position, fast.position[::5])
    means = fast.true_torque_command.reshape(-1, 5).mean(axis=1)
    np.testing.assert_allclose(slow.true_torque_command, means, rtol=0, atol=1e-15)
    # the noise-driven torque varies within a period: one sample is not the mean
    assert np.abs(fast.true_torque_command[::5] - means).max() > 1e-3


def test_mean_torque_explains_the_motion_of_a_frictionless_inertia() -> None:
    """J (w(i+1) - w(i)) / T equals the logged torque minus viscous friction, per period."""
    params = ServoParameters(
        coupling_stiffness=float("inf"),
        motor_coulomb_friction=0.0,
        load_coulomb_friction=0.0,
        motor_viscous_friction=0.0,
        load_viscous_friction=0.0,
    )
    _, slow = _pair(params)
    dt = 0.001
    accel_torque = params.total_inertia * np.diff(slow.velocity) / dt
    np.testing.assert_allclose(accel_torque, slow.true_torque_command[:-1], rtol=1e-6, atol=1e-9)
