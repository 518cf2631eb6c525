"""The synthetic bench joint against closed forms: stiffness from the design, quasi-static lags at constant
speed, backlash width, slip size, sensor delay and quantisation; the CLI writes a joint-format log."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.calibration.bench import BARE_ARM
from swiftfin.calibration.joint import rigid_joint_angle
from swiftfin.calibration.synth import EFFECT_DEFAULTS, LIBRARY_EFFECTS, parse_effects, simulate_joint
from swiftfin.cli import main
from tests.conftest import DEFAULT_DESIGN


@pytest.fixture(scope="module")
def d(default_params):
    return BARE_ARM.design(default_params)     # the bare printed arm: a light link ringing at 93 Hz


def ramp(v):
    """Constant joint speed v [rad/s] from -0.3 rad (a ramp command)."""
    return lambda t: (-0.3 + v * t, np.zeros_like(t))


def test_design_stiffness_by_hand(d, default_params):
    from swiftfin.layout.geometry import cable_routes
    L = np.mean([r.length_mm for r in cable_routes(default_params) if r.joint == 3]) / 1000
    k = 2.0e9 * math.pi * 0.001**2 / 4 / L               # E A / L of one 1 mm nylon cable, E = 2 GPa
    assert d.side_stiffness_n_m == pytest.approx(k, rel=1e-12)
    assert d.cable_stiffness_nm_rad == pytest.approx(2 * k * 0.015**2, rel=1e-12)
    # the stepper held at its step (0.42 N m pi / (2 x 1.8 deg), times (15 / 10)^2 at the joint) in series
    motor = 0.42 * math.pi / (2 * math.radians(1.8)) * (15 / 10) ** 2
    assert d.motor_stiffness_nm_rad == pytest.approx(motor, rel=1e-12)
    assert d.stiffness_nm_rad == pytest.approx(1 / (1 / (2 * k * 0.015**2) + 1 / motor), rel=1e-12)
    assert d.cable_share(d.stiffness_nm_rad) == pytest.approx(d.cable_stiffness_nm_rad, rel=1e-9)
    assert d.ratio == pytest.approx(10 / 15)
    assert d.joint_microstep_rad == pytest.approx(math.radians(1.8) / 16 * 10 / 15)
    assert d.slip_quantum_rad == pytest.approx(4 * math.radians(1.8) * 10 / 15)


def test_library_names_match_the_issue():
    assert LIBRARY_EFFECTS == ("offset", "effective_radius", "cable_compliance", "coulomb_friction",
                               "viscous_friction", "quadratic_drag", "added_mass", "backlash", "capstan_creep",
                               "sensor_delay", "lost_steps")
    from swiftfin.calibration.joint import EFFECT_NAMES
    # the engine also knows a slack cable pair (cable_slack) and a stepper weaker than its catalogue
    # (stepper_torque), which the independent bench simulates (tests/mujoco_bench.py) and this one does not
    assert set(EFFECT_NAMES) == set(LIBRARY_EFFECTS) | {"cable_slack", "stepper_torque"}


def test_no_effect_follows_the_rigid_capstan(d):
    log = simulate_joint(d, {}, duration_s=10, noise_rad=0.0, encoder_counts=None, seed=4)
    # each row's command acts from its time on (read, then command): the reading saw the row before's
    rigid = rigid_joint_angle(log.motor_angle_rad, d)
    e = log.true_joint_angle_rad - 0.5 * (rigid + np.r_[rigid[0], rigid[:-1]])
    # only microstep-scale dynamics of the bare link remain: below one joint microstep (1.3e-3 rad) rms (its ringing
    # after microsteps bunched onto the 1 ms ticks: 0.67 of one)
    assert np.sqrt(np.mean(e**2)) < 0.75 * d.joint_microstep_rad
    assert abs(np.mean(e)) < 1e-4


def test_exact_linear_path_matches_integrator(d):
    eff = {"added_mass": 3e-4, "viscous_friction": 0.005}
    a = simulate_joint(d, eff, duration_s=4, noise_rad=0, encoder_counts=None)
    b = simulate_joint(d, eff, duration_s=4, noise_rad=0, encoder_counts=None, force_integrator=True)
    assert a.integrator.startswith("exact") and b.integrator.startswith("semi-implicit")
    assert np.sqrt(np.mean((a.true_joint_angle_rad - b.true_joint_angle_rad) ** 2)) < 2e-4


@pytest.mark.parametrize("name,value,lag", [
    ("viscous_friction", 0.02, lambda d, v, x: (d.bearing_damping_nm_s_rad + x) * v / d.stiffness_nm_rad),
    ("quadratic_drag", 0.003, lambda d, v, x: (d.bearing_damping_nm_s_rad * v + x * v * v) / d.stiffness_nm_rad),
    ("coulomb_friction", 0.02, lambda d, v, x: (d.bearing_damping_nm_s_rad * v + x) / d.stiffness_nm_rad),
])
def test_quasi_static_lag_at_constant_speed(d, name, value, lag):
    """At constant speed v the cable stretches by the load torque / K: theta = u - tau(v) / K."""
    v = 0.6
    # logged (and commanded) at 10 kHz: the microsteps come at their own times, not bunched onto 1 ms ticks, whose
    # uneven spacing (2 or 3 ticks per microstep at this speed) makes the link's speed ripple and b w|w| average high
    log = simulate_joint(d, {name: value}, duration_s=1.0, noise_rad=0, encoder_counts=None,
                         command=ramp(v), force_integrator=True, rate_hz=10000.0)
    u = d.ratio * np.rint((-0.3 + v * log.t) / d.ratio / d.microstep_rad) * d.microstep_rad
    # each row's command acts from its time on (read, then command): a held ramp is the ramp half a sample late
    u = 0.5 * (u + np.r_[u[0], u[:-1]])
    late = log.t > 0.5
    measured = np.mean((u - log.true_joint_angle_rad)[late])
    assert measured == pytest.approx(lag(d, v, value), rel=0.03, abs=2e-5)


def test_backlash_hysteresis_width(d):
    """A slow triangle: going up and coming down, the joint differs by the dead band at the same command."""
    gap = 0.01
    T = 4.0

    def tri(t):
        return 0.2 * (1 - 2 * np.abs((t / T) % 1 - 0.5) * 2), np.zeros_like(t)
    log = simulate_joint(d, {"backlash": gap}, duration_s=T, noise_rad=0, encoder_counts=None, command=tri)
    th = log.true_joint_angle_rad
    up = (log.t > 0.1 * T) & (log.t < 0.4 * T)
    down = (log.t > 0.6 * T) & (log.t < 0.9 * T)
    cmd = tri(log.t)[0]
    # joint vs command on each branch, compared at the same commanded angle
    c = np.linspace(-0.1, 0.1, 21)
    j_up = np.interp(c, cmd[up], th[up])
    order = np.argsort(cmd[down])
    j_down = np.interp(c, cmd[down][order], th[down][order])
    assert np.mean(j_down - j_up) == pytest.approx(gap, rel=0.08)


def test_lost_steps_are_four_full_steps(d):
    log = simulate_joint(d, {"lost_steps": 150.0}, duration_s=20, noise_rad=0, encoder_counts=None, seed=1)
    assert log.n_slips > 0
    e = log.true_joint_angle_rad - rigid_joint_angle(log.motor_angle_rad, d)
    # the change of e over a sliding 8 ms window (the slip ramps over 5 ms): each slip is one run of windows that
    # jump by more than half a quantum (fixed 50 ms windows could split a slip in two halves that both round to 0)
    w = 8
    de = (e[w:] - e[:-w]) / d.slip_quantum_rad
    big = np.abs(de) > 0.5
    starts = np.flatnonzero(big & ~np.r_[False, big[:-1]])
    ends = np.flatnonzero(big & ~np.r_[big[1:], False])
    # runs less than a window apart are one slip: the link's ringing after it can dip the change under the
    # threshold for a sample (seen with the drive's stiffness in series with the stepper's)
    apart = starts[1:] - ends[:-1] > w
    starts, ends = starts[np.r_[True, apart]], ends[np.r_[apart, True]]
    steps = np.round([de[a:b + 1][np.argmax(np.abs(de[a:b + 1]))] for a, b in zip(starts, ends)])
    assert steps.size == log.n_slips
    assert set(np.abs(steps)) == {1.0}


def test_sensor_delay_and_offset(d):
    log = simulate_joint(d, {"sensor_delay": 0.012, "offset": 0.02}, duration_s=5, noise_rad=0, encoder_counts=None)
    expect = np.interp(log.t - 0.012, log.t, log.true_joint_angle_rad) + 0.02
    assert np.max(np.abs(log.joint_angle_rad - expect)[100:]) < 2e-4


def test_encoder_quantisation_and_noise(d):
    log = simulate_joint(d, {}, duration_s=5, seed=3)
    q = 2 * math.pi / 4096
    assert np.allclose(log.joint_angle_rad / q, np.rint(log.joint_angle_rad / q), atol=1e-6)
    e = log.joint_angle_rad - log.true_joint_angle_rad
    assert np.std(e) == pytest.approx(math.sqrt(1e-6 + q**2 / 12), rel=0.1)


def test_effective_radius_scales(d):
    a = simulate_joint(d, {"effective_radius": 1.05}, duration_s=3, noise_rad=0, encoder_counts=None)
    b = simulate_joint(d, {}, duration_s=3, noise_rad=0, encoder_counts=None)
    assert np.allclose(a.true_joint_angle_rad, 1.05 * b.true_joint_angle_rad, atol=1e-6)


def test_parse_effects():
    assert parse_effects(["backlash", "sensor_delay=0.02"]) == {"backlash": EFFECT_DEFAULTS["backlash"][0],
                                                                 "sensor_delay": 0.02}
    with pytest.raises(ValueError, match="did you mean 'backlash'"):
        parse_effects(["backlsh"])
    with pytest.raises(ValueError, match="not a number"):
        parse_effects(["offset=abc"])
    with pytest.raises(ValueError, match="must be >= 0"):
        parse_effects(["sensor_delay=-1"])


def test_cli_writes_joint_log(tmp_path, capsys):
    out = tmp_path / "j.csv"
    code = main(["synth", "joint", "--effect", "backlash", "--effect", "offset=0.01", "--out", str(out),
                 "--seed", "5", "--duration", "3", "--design", str(DEFAULT_DESIGN)])
    assert code == 0
    lines = out.read_text().splitlines()
    assert lines[0] == "time_s,motor_angle_rad,joint_angle_rad,cable_tension_n"
    assert len(lines) == 3001
    assert "backlash=0.01" in capsys.readouterr().out
    tension = np.loadtxt(out, delimiter=",", skiprows=1)[:, 3]
    assert tension.mean() == pytest.approx(45.0, abs=0.5)        # the design's pretension, read by the load cell
    bare = tmp_path / "bare.csv"
    assert main(["synth", "joint", "--no-load-cell", "--out", str(bare), "--duration", "3",
                 "--design", str(DEFAULT_DESIGN)]) == 0
    assert bare.read_text().splitlines()[0] == "time_s,motor_angle_rad,joint_angle_rad"


def test_load_cell_sees_friction_torque_and_not_a_dead_band(d):
    """The load cell reads T0 + tau / (2 d_mount): hinge friction steps it by tau_c / (2 d_mount) with the
    direction of motion; a dead band at the spool hub passes no torque (step within noise)."""
    from swiftfin.calibration.joint import joint_context, tension_step_n
    tc = 0.02
    fr = simulate_joint(d, {"coulomb_friction": tc}, seed=3, duration_s=20)
    bl = simulate_joint(d, {"backlash": 0.01}, seed=3, duration_s=20)
    s_fr, se_fr = tension_step_n(joint_context(fr.t, fr.motor_angle_rad, fr.joint_angle_rad, d,
                                               tension=fr.cable_tension_n))
    s_bl, se_bl = tension_step_n(joint_context(bl.t, bl.motor_angle_rad, bl.joint_angle_rad, d,
                                               tension=bl.cable_tension_n))
    assert s_fr == pytest.approx(tc / (2 * d.moment_arm_m), rel=0.1)
    assert s_bl < 0.05 * s_fr and s_bl < 3 * se_bl + 0.01


def test_cli_bad_effect_exit_2(tmp_path, capsys):
    code = main(["synth", "joint", "--effect", "cogging_torque", "--out", str(tmp_path / "x.csv"),
                 "--design", str(DEFAULT_DESIGN)])
    err = capsys.readouterr().err
    assert code == 2 and "unknown effect 'cogging_torque'" in err and "did you mean 'cogging'" in err


def test_ambiguous_slips_are_judged_by_training_rows_only(d):
    """calibration.joint.slip_events: with every row a training row, the slips near the threshold are decided by
    the measured angle and match the simulator's; with none (a held-out record), the threshold alone decides."""
    from swiftfin.calibration import effects as op
    from swiftfin.calibration.joint import joint_context, slip_events
    from swiftfin.calibration.synth import bench_command
    log = simulate_joint(d, {"lost_steps": 160.0}, seed=22)
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d)
    _, acc = bench_command(log.t, 22)
    true_t, _ = op.threshold_crossings(log.t, acc / d.ratio, 160.0)
    ctx.meta["train_rows"] = np.ones(ctx.n, bool)
    judged, _ = slip_events(ctx, 160.0)
    ctx.meta["train_rows"] = np.zeros(ctx.n, bool)
    predicted, _ = slip_events(ctx, 160.0)
    plain, _ = op.threshold_crossings(ctx.t, ctx.signals["motor_acceleration"], 160.0)
    assert np.array_equal(predicted, plain)
    assert judged.size == true_t.size == log.n_slips
    assert np.abs(judged - true_t).max() < 0.005                  # the same events, to the slip ramp's timing
    assert predicted.size != true_t.size or np.abs(predicted - true_t).max() > 0.005   # the command alone errs
