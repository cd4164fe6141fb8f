"""Tests of the simulated servo (clpc_paper.plants.servo) and the command generators."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from clpc_paper.plants import (
    ServoParameters,
    chirp,
    multisine,
    prbs,
    ramp_with_saturation,
    servo_filters,
    servo_layout,
    servo_loop,
    servo_run,
    simulate_motor_open_loop,
    simulate_servo,
    steps,
    time_grid,
    trapezoid_moves,
)

# a parameter set without any noise, quantisation or friction: the loop is linear
LINEAR = dict(
    resolution=0.0,
    position_noise_std=0.0,
    motor_coulomb_friction=0.0,
    load_coulomb_friction=0.0,
)
# every noise source on, so that the comparisons below exercise all the code paths
NOISY = dict(
    position_noise_std=5e-5,
    disturbance_torque_std=0.02,
    command_noise_std=1e-3,
    torque_noise_std=0.01,
)


def _step(n_before: int = 10, n_after: int = 140, level: float = 1.0) -> np.ndarray:
    return np.r_[np.zeros(n_before), np.full(n_after, level)]


def _fields(rec) -> dict[str, np.ndarray]:
    return rec.to_dict()


# --------------------------------------------------------------------------------------
# compiled vs pure Python, determinism
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "changes",
    [
        NOISY,
        dict(NOISY, coupling_stiffness=math.inf),
        dict(NOISY, feedback_on_load=True, torque_lowpass_order=1, velocity_filter_frequency=None),
    ],
    ids=["two-mass", "rigid", "load-feedback"],
)
def test_jit_and_python_loops_agree(changes):
    pytest.importorskip("numba")
    params = ServoParameters(**changes)
    cmd = _step(5, 35, 2.0)
    fast = simulate_servo(cmd, params=params, seed=7, engine="numba")
    slow = simulate_servo(cmd, params=params, seed=7, engine="python")
    for name, a in _fields(fast).items():
        np.testing.assert_allclose(a, getattr(slow, name), rtol=1e-12, atol=1e-12, err_msg=name)


def test_loop_functions_agree_directly():
    pytest.importorskip("numba")
    params = ServoParameters(**NOISY)
    rate = params.controller_rate
    steps_per_sample = round(rate * 0.01)
    rng = np.random.default_rng(0)
    cmd = np.r_[np.zeros(3), np.ones(17)]
    noise = 1e-4 * rng.standard_normal(cmd.size * steps_per_sample)
    dist = 0.05 * rng.standard_normal(cmd.size * steps_per_sample)
    p = servo_layout._pack(params, rate, open_loop=False)
    filt = servo_filters._filter_coefficients(params, rate)
    config = servo_layout.LoopConfig(steps_per_sample, 2, p, filt)
    inputs = servo_layout.LoopInputs(cmd, noise, dist)
    outs = []
    for loop in (servo_loop._servo_loop_py, servo_loop._servo_loop_jit):
        state = np.zeros(servo_layout._N_S)
        out = np.empty((cmd.size, servo_layout._N_OUT))
        loop(config, inputs, state, out)
        outs.append((out, state))
    np.testing.assert_allclose(outs[0][0], outs[1][0], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(outs[0][1], outs[1][1], rtol=1e-12, atol=1e-12)


def test_deterministic_for_a_seed_and_different_for_another():
    params = ServoParameters(**NOISY)
    cmd = _step(5, 45)
    a = simulate_servo(cmd, params=params, seed=1)
    b = simulate_servo(cmd, params=params, seed=1)
    c = simulate_servo(cmd, params=params, seed=2)
    for name, x in _fields(a).items():
        np.testing.assert_array_equal(x, getattr(b, name), err_msg=name)
    assert not np.array_equal(a.position, c.position)
    assert not np.array_equal(a.torque_command, c.torque_command)
    gen = simulate_servo(cmd, params=params, seed=np.random.default_rng(1))
    assert np.all(np.isfinite(gen.position))


def test_chunking_does_not_change_the_result(monkeypatch):
    params = ServoParameters(**NOISY)
    cmd = _step(5, 40)
    whole = simulate_servo(cmd, params=params, seed=3)
    monkeypatch.setattr(servo_run, "_CHUNK", 7)
    pieces = simulate_servo(cmd, params=params, seed=3)
    for name, x in _fields(whole).items():
        np.testing.assert_array_equal(x, getattr(pieces, name), err_msg=name)


def test_logging_noise_only_touches_the_logged_signals():
    cmd = _step(5, 95)
    clean = simulate_servo(cmd, seed=4)
    noisy = simulate_servo(
        cmd, params=ServoParameters(command_noise_std=0.01, torque_noise_std=0.05), seed=4
    )
    # the loop is untouched (independent noise streams) ...
    np.testing.assert_array_equal(clean.position, noisy.position)
    np.testing.assert_array_equal(clean.true_torque_command, noisy.true_torque_command)
    np.testing.assert_array_equal(noisy.true_position_command, cmd)
    # ... the logs carry the errors in variables
    assert 0.03 < np.std(noisy.torque_command - noisy.true_torque_command) < 0.07
    assert 0.006 < np.std(noisy.position_command - cmd) < 0.014


# --------------------------------------------------------------------------------------
# closed-loop behaviour
# --------------------------------------------------------------------------------------


def test_step_is_tracked_with_default_parameters():
    cmd = _step(10, 190)  # 1 rad step at t = 0.1 s, 2 s in all
    rec = simulate_servo(cmd, seed=0)
    err = rec.true_position - cmd
    after = rec.time >= 0.1
    # settles to 2 % within 0.3 s of the step (about 0.1 s in practice)
    late = rec.time >= 0.4
    assert np.all(np.abs(err[late]) < 0.02)
    # steady state: within a few resolver counts (integrator removes the friction offset)
    tol = 6 * ServoParameters().resolution  # about 6e-4 rad
    assert np.all(np.abs(err[rec.time >= 1.0]) < tol)
    assert np.all(np.abs(rec.position - cmd)[rec.time >= 1.0] < tol)
    # well damped: overshoot below 5 %; stable: the error stays bounded by tol (above) and
    # the load is essentially at rest at the end
    assert rec.true_position[after].max() < 1.05
    assert np.abs(rec.velocity[rec.time >= 1.5]).max() < 0.05
    assert np.abs(rec.torque_command[rec.time >= 1.0]).max() < 0.2


def test_integrator_removes_the_friction_offset():
    cmd = _step(10, 140)
    params = ServoParameters(resolution=0.0, position_noise_std=0.0)
    with_i = simulate_servo(cmd, params=params, seed=0)
    without_i = simulate_servo(cmd, params=params.replace(velocity_integrator=0.0), seed=0)
    # measured (motor) position: the offset of a P-P loop is F / (Kp Kv) ~ 2 mrad
    offset_p = abs(without_i.position[-1] - 1.0)
    assert offset_p > 1e-3
    assert abs(with_i.position[-1] - 1.0) < 1e-6
    # the load lags the motor by the coupling twist F_l / k
    twist = params.load_coulomb_friction / params.coupling_stiffness
    assert abs(with_i.true_position[-1] - 1.0) <= twist + 1e-9


def test_linear_loop_is_stable_without_the_notch_too_and_rigid():
    cmd = _step(10, 90, 0.01)
    for params in (
        ServoParameters(**LINEAR),
        ServoParameters(notch_enabled=False, **LINEAR),
        ServoParameters(coupling_stiffness=math.inf, **LINEAR),
    ):
        rec = simulate_servo(cmd, params=params, seed=0)
        assert abs(rec.true_position[-1] - 0.01) < 1e-9
        assert np.abs(rec.motor_velocity[-20:]).max() < 1e-6


def test_torque_stays_within_the_current_limit_on_a_huge_step():
    params = ServoParameters()
    cmd = _step(10, 290, 100.0)
    rec = simulate_servo(cmd, params=params, seed=0)
    limit = params.torque_limit
    assert np.abs(rec.true_torque_command).max() <= limit + 1e-12
    assert np.isclose(np.abs(rec.true_torque_command).max(), limit)  # it does saturate
    assert np.abs(rec.velocity_command).max() <= params.velocity_limit + 1e-12
    # anti-windup: no integrator-driven oscillation, the move settles
    assert np.abs(rec.true_position[-50:] - 100.0).max() < 1e-3


def test_measured_position_is_quantised_without_noise():
    params = ServoParameters(position_noise_std=0.0)
    cmd = np.r_[np.zeros(5), np.linspace(0, 0.7, 60)]
    rec = simulate_servo(cmd, params=params, seed=0)
    counts = rec.position / params.resolution
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)
    assert np.abs(rec.position - rec.motor_position).max() <= params.resolution / 2 + 1e-12


def test_notch_is_centred_on_the_resonance_by_default():
    params = ServoParameters()
    assert params.effective_notch_frequency == pytest.approx(params.resonance_frequency)
    assert 200 < params.resonance_frequency < 320
    assert ServoParameters(coupling_stiffness=math.inf).effective_notch_frequency is None
    assert ServoParameters(notch_enabled=False).effective_notch_frequency is None
    assert params.torque_limit == pytest.approx(3.0)


def test_record_is_read_only_and_complete():
    cmd = _step(3, 7)
    rec = simulate_servo(cmd, seed=0)
    assert len(rec) == cmd.size
    d = rec.to_dict()
    assert set(d) >= {"time", "position_command", "position", "true_position", "velocity"}
    assert all(v.shape == cmd.shape and v.dtype == np.float64 for v in d.values())
    np.testing.assert_allclose(rec.time, np.arange(cmd.size) * 0.01)
    with pytest.raises(ValueError):
        rec.position[0] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        rec.sample_time = 1.0  # type: ignore[misc]
    np.testing.assert_allclose(rec.current_command * 0.5, rec.torque_command)


# --------------------------------------------------------------------------------------
# physics (open loop)
# --------------------------------------------------------------------------------------


def test_constant_torque_on_a_rigid_frictionless_inertia():
    params = ServoParameters(
        coupling_stiffness=math.inf,
        motor_viscous_friction=0.0,
        load_viscous_friction=0.0,
        motor_coulomb_friction=0.0,
        load_coulomb_friction=0.0,
        resolution=0.0,
        position_noise_std=0.0,
    )
    torque = np.full(31, 0.5)
    rec = simulate_motor_open_loop(torque, params=params, sample_time=0.01)
    a = 0.5 / params.total_inertia
    t = rec.time
    h = 1.0 / (params.controller_rate * params.mechanical_substeps)
    # symplectic Euler: theta_n = a h^2 n (n + 1) / 2 = 0.5 a t^2 + 0.5 a h t (O(h) error)
    np.testing.assert_allclose(rec.true_position, 0.5 * a * t**2 + 0.5 * a * h * t, rtol=1e-10)
    assert np.all(np.abs(rec.true_position - 0.5 * a * t**2) <= 0.5 * a * h * t + 1e-12)
    np.testing.assert_allclose(rec.velocity, a * t, rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(rec.position, rec.true_position)


def test_two_mass_conserves_momentum_and_coulomb_friction_sticks():
    frictionless = ServoParameters(
        motor_viscous_friction=0.0,
        load_viscous_friction=0.0,
        motor_coulomb_friction=0.0,
        load_coulomb_friction=0.0,
    )
    torque = np.r_[np.full(10, 1.0), np.full(10, -0.4)]
    rec = simulate_motor_open_loop(torque, params=frictionless)
    impulse = np.r_[0.0, np.cumsum(torque[:-1]) * 0.01]
    momentum = (
        frictionless.motor_inertia * rec.motor_velocity + frictionless.load_inertia * rec.velocity
    )
    np.testing.assert_allclose(momentum, impulse, rtol=1e-9, atol=1e-12)

    # below the breakaway level nothing moves; above, it accelerates with (T - F) / J
    rigid = ServoParameters(
        coupling_stiffness=math.inf, motor_viscous_friction=0.0, load_viscous_friction=0.0
    )
    friction = rigid.motor_coulomb_friction + rigid.load_coulomb_friction
    stuck = simulate_motor_open_loop(np.full(20, 0.9 * friction), params=rigid)
    assert np.all(stuck.true_position == 0.0) and np.all(stuck.velocity == 0.0)
    moving = simulate_motor_open_loop(np.full(21, friction + 0.1), params=rigid)
    np.testing.assert_allclose(moving.velocity[-1], 0.1 / rigid.total_inertia * 0.2, rtol=1e-9)


def test_open_loop_torque_is_clipped_to_the_limit():
    rec = simulate_motor_open_loop(np.array([10.0, -10.0, 1.0]))
    np.testing.assert_allclose(rec.torque, [3.0, -3.0, 1.0])


# --------------------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(command=[0.0, np.nan]), "must be finite"),
        (dict(command=[[0.0, 1.0]]), "must be 1-D"),
        (dict(command=[]), "at least one sample"),
        (dict(command=[0.0], sample_time=0.0), "sample_time must be finite and > 0"),
        (dict(command=[0.0], sample_time=-0.01), "sample_time must be finite and > 0"),
        (dict(command=[0.0], inner_rate=1234.5), "integer multiple of 1/sample_time"),
        (dict(command=[0.0], inner_rate=500.0), "inner_rate must be >= 1000"),
        (dict(command=[0.0], inner_rate=1000.0), "below the Nyquist frequency"),
        (dict(command=[0.0], params="fast"), "params must be a ServoParameters"),
        (dict(command=[0.0], seed=-3), "seed must be"),
        (dict(command=[0.0], engine="gpu"), "engine must be"),
    ],
)
def test_simulate_servo_validates_its_inputs(kwargs, match):
    command = kwargs.pop("command")
    with pytest.raises(ValueError, match=match):
        simulate_servo(command, **kwargs)


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        (dict(motor_inertia=0.0), "motor_inertia must be > 0"),
        (dict(velocity_gain=math.nan), "velocity_gain must be finite"),
        (dict(motor_coulomb_friction=-1.0), "must be >= 0"),
        (dict(coupling_stiffness=0.0), "coupling_stiffness must be > 0"),
        (dict(load_inertia=0.0), "load_inertia must be > 0 with a compliant coupling"),
        (dict(torque_lowpass_order=3), "torque_lowpass_order must be 1 or 2"),
        (dict(notch_depth=1.0), r"notch_depth must be in \[0, 1\)"),
        (dict(mechanical_substeps=0), "mechanical_substeps must be an integer >= 1"),
        (dict(notch_frequency=-5.0), "notch_frequency must be None or a finite frequency"),
    ],
)
def test_servo_parameters_are_validated(changes, match):
    with pytest.raises(ValueError, match=match):
        ServoParameters(**changes)
    assert ServoParameters(coupling_stiffness=math.inf, load_inertia=0.0).rigid


# --------------------------------------------------------------------------------------
# command generators
# --------------------------------------------------------------------------------------


def test_time_grid_includes_both_ends():
    t = time_grid(2.0, 0.01)
    assert t.shape == (201,)  # Table 1: a 2 s window holds 201 samples
    assert t[-1] == pytest.approx(2.0)
    assert time_grid(0.0, 0.01).shape == (1,)


def test_ramp_with_saturation_matches_fig5():
    u = ramp_with_saturation(3.0, 0.01, start=0.5, ramp_time=0.9, level=2.0)
    t = time_grid(3.0, 0.01)
    assert u.shape == t.shape
    assert np.all(np.diff(u) >= -1e-15)  # monotone
    assert np.all(u[t <= 0.5] == 0.0)
    np.testing.assert_allclose(u[t >= 1.4 - 1e-9], 2.0)
    assert u.max() == pytest.approx(2.0)
    inside = (t > 0.5) & (t < 1.4)
    np.testing.assert_allclose(np.diff(u[inside]), 2.0 / 0.9 * 0.01, rtol=1e-9)


def test_ramp_with_saturation_cycles_up_and_down():
    u = ramp_with_saturation(
        6.0, 0.01, start=0.5, ramp_time=0.5, level=1.0, cycles=2, hold_time=1.0
    )
    t = time_grid(6.0, 0.01)
    # up 0.5-1.0, hold to 2.0, down to 2.5, hold to 3.5, up to 4.0, hold
    assert u[np.argmin(np.abs(t - 1.5))] == pytest.approx(1.0)
    assert u[np.argmin(np.abs(t - 3.0))] == pytest.approx(0.0)
    assert u[-1] == pytest.approx(1.0)
    assert np.abs(np.diff(u)).max() <= 0.01 / 0.5 + 1e-12
    with pytest.raises(ValueError, match="last ramp must end within the duration"):
        ramp_with_saturation(3.0, 0.01, cycles=3)
    with pytest.raises(ValueError, match="ramp_time must be > 0"):
        ramp_with_saturation(3.0, 0.01, ramp_time=0.0)


def test_steps_and_their_validation():
    u = steps(1.0, 0.01, times=[0.1, 0.5], levels=[1.0, -0.5], initial=0.2)
    assert u.shape == (101,)
    assert u[9] == 0.2 and u[10] == 1.0 and u[49] == 1.0 and u[50] == -0.5
    with pytest.raises(ValueError, match="same length"):
        steps(1.0, times=[0.1], levels=[1.0, 2.0])
    with pytest.raises(ValueError, match="non-decreasing"):
        steps(1.0, times=[0.5, 0.1], levels=[1.0, 2.0])


def test_trapezoid_moves_respect_the_limits():
    dt = 0.001
    u = trapezoid_moves(
        4.0, dt, positions=(0.0, 2.0, -1.0), max_velocity=4.0, max_acceleration=20.0, dwell=0.3
    )
    assert u.shape == (4001,)
    v = np.diff(u) / dt
    assert np.abs(v).max() <= 4.0 + 1e-9
    assert np.abs(np.diff(v) / dt).max() <= 20.0 * (1 + 1e-6) + 1e-6
    assert u.max() == pytest.approx(2.0) and u.min() == pytest.approx(-1.0)
    # first move: 2 rad at 4 rad/s, 20 rad/s^2: 0.2 s ramps + 0.3 s cruise = 0.7 s
    assert u[700] == pytest.approx(2.0) and u[699] < 2.0
    with pytest.raises(ValueError, match="cycle of moves must take time"):
        trapezoid_moves(1.0, positions=(1.0, 1.0), dwell=0.0)
    with pytest.raises(ValueError, match="max_velocity must be > 0"):
        trapezoid_moves(1.0, max_velocity=0.0)


def test_chirp():
    u = chirp(10.0, 0.01, amplitude=0.3, f0=0.2, f1=4.0, offset=1.0)
    assert u.shape == (1001,)
    assert u[0] == pytest.approx(1.0)
    assert np.abs(u - 1.0).max() <= 0.3 + 1e-12
    lin = chirp(10.0, 0.01, amplitude=0.3, f0=0.2, f1=4.0, method="linear")
    assert lin.shape == (1001,)
    with pytest.raises(ValueError, match="below the Nyquist frequency"):
        chirp(1.0, 0.01, f1=60.0)
    with pytest.raises(ValueError, match="method must be"):
        chirp(1.0, 0.01, method="cubic")  # type: ignore[arg-type]


def test_prbs_is_deterministic_binary_and_holds():
    a = prbs(20.0, 0.01, amplitude=0.4, min_hold=0.15, seed=5)
    b = prbs(20.0, 0.01, amplitude=0.4, min_hold=0.15, seed=5)
    c = prbs(20.0, 0.01, amplitude=0.4, min_hold=0.15, seed=6)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert a.shape == (2001,)
    assert set(np.unique(a)) <= {-0.4, 0.4}
    change = np.flatnonzero(np.diff(a) != 0) + 1
    runs = np.diff(np.r_[0, change])
    assert runs.min() >= 15 and change.size > 10
    m = prbs(20.0, 0.01, amplitude=0.4, min_hold=0.15, levels="uniform", seed=5, offset=1.0)
    assert np.abs(m - 1.0).max() <= 0.4 and np.unique(m).size > 5
    with pytest.raises(ValueError, match="switch_probability must be in"):
        prbs(1.0, switch_probability=0.0)


def test_multisine():
    u = multisine(10.0, 0.01, amplitude=0.5, f_min=0.2, f_max=5.0, n_tones=12)
    assert u.shape == (1001,)
    assert np.abs(u).max() == pytest.approx(0.5)
    r1 = multisine(10.0, 0.01, phases="random", seed=1)
    np.testing.assert_array_equal(r1, multisine(10.0, 0.01, phases="random", seed=1))
    with pytest.raises(ValueError, match="f_min <= f_max < Nyquist"):
        multisine(1.0, 0.01, f_min=1.0, f_max=50.0)


def test_generators_feed_the_servo():
    u = ramp_with_saturation(3.0, 0.01)
    rec = simulate_servo(u, seed=0)
    assert len(rec) == u.size
    # a slow ramp is followed within a few mrad (type-1 position loop: lag = slope / Kp)
    slope = 1.0 / 0.9
    assert np.abs(rec.true_position - u).max() < 2 * slope / ServoParameters().position_gain
