"""The joint family on synthetic bench logs with undeclared effects (issue 5, items 4a-4d).

The confusion matrix (true effect -> effect named first) is written to the test report (``record_property`` and
a report section: ``pytest -rP`` prints it) and into every assertion message.
"""
from __future__ import annotations

import numpy as np
import pytest

from swiftfin.calibration.engine import Calibrator, Context
from swiftfin.calibration.bench import BARE_ARM
from swiftfin.calibration.joint import EQUIVALENT, FAMILY, joint_context
from swiftfin.calibration.synth import EFFECT_DEFAULTS, LIBRARY_EFFECTS, simulate_joint

FLOOR_FACTOR = 1.5   # "near the noise level": held-out RMSE within 1.5 x that of a clean log (noise + floor)


@pytest.fixture(scope="module")
def d(default_params):
    return BARE_ARM.design(default_params)     # the bare printed arm: a light link ringing at 93 Hz


def run(d, effects: dict, seed: int, load_cell: bool = True) -> Calibrator:
    """The engine on a simulated bench log; ``load_cell``: with the optional cable_tension_n column (the default
    bench has one)."""
    log = simulate_joint(d, effects, seed=seed)
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, source=f"synthetic {effects}",
                        tension=log.cable_tension_n if load_cell else None)
    return Calibrator(FAMILY).fit(ctx)


def twins(a: str, b: str) -> bool:
    return any({a, b} <= g for g in EQUIVALENT)


def named_correctly(truth: str, cal: Calibrator) -> bool:
    """The first effect named is the truth, or its physical twin with the ambiguity reported."""
    if not cal.added_effects_:
        return False
    first = cal.added_effects_[0]
    return first.name == truth or (twins(first.name, truth) and truth in first.indistinguishable_from)


# ----------------------------------------------------------------------------------------- confusion matrix


@pytest.fixture(scope="module")
def suite(d):
    """Every library effect alone at its default size, a clean log, two pairs and two effects outside the
    library. Seeds differ per case (different command phases and noise)."""
    cases = {"none": {}}
    for k, name in enumerate(LIBRARY_EFFECTS):
        cases[name] = {name: EFFECT_DEFAULTS[name][0]}
    cases["effective_radius+sensor_delay"] = {"effective_radius": 1.05, "sensor_delay": 0.010}
    cases["quadratic_drag+capstan_creep"] = {"quadratic_drag": 0.003, "capstan_creep": 0.001}
    cases["cogging (outside library)"] = {"cogging": 0.1}
    cases["radius_drift (outside library)"] = {"radius_drift": 0.03}
    return {name: run(d, eff, seed=11 + i) for i, (name, eff) in enumerate(cases.items())}


def confusion_text(suite) -> str:
    floor = suite["none"].final_["rmse_holdout"]
    lines = [f"{'injected':32s} {'named (in order)':44s} {'rmse base':>10s} {'final':>9s} {'/floor':>6s} unexpl.",
             "-" * 112]
    for case, cal in suite.items():
        named = []
        for fe in cal.added_effects_:
            s = fe.name + ("?" if fe.confidence == "low" else "")
            if fe.indistinguishable_from:
                s += "~" + "/".join(fe.indistinguishable_from)
            named.append(s)
        lines.append(f"{case:32s} {', '.join(named) or '(nothing)':44s} {cal.baseline_['rmse_holdout']:10.3g} "
                     f"{cal.final_['rmse_holdout']:9.3g} {cal.final_['rmse_holdout'] / floor:6.2f} "
                     f"{'yes' if cal.unexplained_structure_ else 'no'}")
    lines.append("'?' = low confidence; '~x' = indistinguishable from x in these data; floor = final RMSE on the "
                 f"clean log ({floor:.3g} rad)")
    return "\n".join(lines)


@pytest.fixture(scope="module")
def matrix(suite):
    return confusion_text(suite)


@pytest.mark.slow
def test_confusion_matrix_single_effects(suite, matrix, record_property, request):
    """(a) every library effect alone: named first (or its physical twin, with the ambiguity reported), and the
    held-out error drops to near the noise level."""
    record_property("confusion_matrix", matrix)
    request.node.add_report_section("call", "confusion matrix", matrix)
    print("\n" + matrix)
    floor = suite["none"].final_["rmse_holdout"]
    wrong = [n for n in LIBRARY_EFFECTS if not named_correctly(n, suite[n])]
    assert not wrong, f"misnamed: {wrong}\n{matrix}"
    high = [n for n in LIBRARY_EFFECTS if suite[n].final_["rmse_holdout"] > FLOOR_FACTOR * floor]
    assert not high, f"held-out error not near the noise level: {high}\n{matrix}"
    # with the bench's load cell the twins are told apart: every effect is named exactly, with high confidence
    inexact = [n for n in LIBRARY_EFFECTS if suite[n].added_effects_[0].name != n]
    assert not inexact, f"named only as a twin: {inexact}\n{matrix}"
    for n in ("coulomb_friction", "backlash"):
        first = suite[n].added_effects_[0]
        assert first.confidence == "high" and not first.indistinguishable_from, matrix


@pytest.mark.slow
@pytest.mark.parametrize("name", ["coulomb_friction", "backlash"])
@pytest.mark.parametrize("seed", [15, 19])
def test_without_a_load_cell_friction_and_backlash_are_told_apart_by_the_ringing(d, name, seed):
    """From the joint angle alone both are a hysteresis of the same width, but dry friction acts on the link and
    damps its ringing after each microstep while play at the spool does not: the engine names the right one, capped
    at "medium" (the other alone removes most of the same residual). With the friction modelled as a play operator
    on the staircase (before 2026-11-26) the two were the same model and were reported as twins at "low"."""
    cal = run(d, {name: EFFECT_DEFAULTS[name][0]}, seed=seed, load_cell=False)
    first = cal.added_effects_[0]
    assert first.name == name and first.confidence == "medium", (first.name, first.confidence)


@pytest.mark.slow
def test_clean_log_adds_nothing(suite, matrix):
    """(b)"""
    cal = suite["none"]
    assert cal.added_effects_ == [], matrix
    assert not cal.unexplained_structure_, matrix


@pytest.mark.slow
def test_effect_outside_library(suite, matrix):
    """(c) a periodic microstep error (cogging) is not in the library: structure flagged, no confident claim."""
    cal = suite["cogging (outside library)"]
    assert cal.unexplained_structure_, matrix
    assert all(fe.confidence == "low" for fe in cal.added_effects_), matrix


@pytest.mark.slow
def test_radius_drift_is_flagged(suite, matrix):
    """(c') a radius drifting in time: the mean radius error is a real part of it (effective_radius may be
    named), but the drift itself is unexplained and must be flagged."""
    cal = suite["radius_drift (outside library)"]
    assert cal.unexplained_structure_, matrix
    assert {fe.name for fe in cal.added_effects_} <= {"effective_radius"}, matrix


@pytest.mark.slow
@pytest.mark.parametrize("case", ["effective_radius+sensor_delay", "quadratic_drag+capstan_creep"])
def test_two_effects_both_found(suite, matrix, case):
    """(d)"""
    cal = suite[case]
    found = {fe.name for fe in cal.added_effects_}
    assert set(case.split("+")) <= found, matrix
    assert cal.final_["rmse_holdout"] < FLOOR_FACTOR * suite["none"].final_["rmse_holdout"], matrix


@pytest.mark.slow
@pytest.mark.parametrize("name,param,true", [
    ("offset", "offset_rad", 0.02),
    ("effective_radius", "ratio_error", 0.05),
    ("viscous_friction", "damping_nm_s_rad", 0.02),
])
def test_physical_recovery_within_uncertainty(suite, name, param, true):
    """Where the effect model is the simulator's physics, the true value lies within 3 sigma."""
    fe = suite[name].added_effects_[0]
    assert abs(fe.values[param] - true) < 3 * fe.stds[param], (fe.values[param], fe.stds[param])


@pytest.mark.slow
@pytest.mark.parametrize("name,param,true,tol", [
    ("sensor_delay", "delay_s", 0.010, 0.08),          # absorbs the bare link's ~0.3 ms lag
    ("added_mass", "inertia_ratio", 1 + 3e-4 / 6e-6, 0.05),     # 3e-4 kg m^2 on the bare arm's 6e-6
    ("cable_compliance", "stiffness_factor", 0.1, 0.1),
    ("lost_steps", "slip_rad", None, 0.02),              # 4 full steps x r / d_mount
    # the bench commands on 1 ms ticks, so the link moves in jerks (2-3 ticks per microstep): the effect simulates
    # b w|w| on the link's rippling speed in the drive (it was a quasi-static column on the mean speed that kept
    # 0.68 of b, with viscous friction named beside it for the rest)
    ("quadratic_drag", "drag_nm_s2_rad2", None, 0.10),
    # the creep estimate sits 0.09-0.23 % high on the bench simulator (z = +1.8 ... +4.5 over seeds 8-21, on the
    # 0.545 and 0.555 L designs alike), while the model-consistent recovery below is exact: the simulator's creep
    # is not quite the effect's model, and its sigma (0.05 %) does not cover that
    ("capstan_creep", "creep_per_travel", 0.001, 0.01),
])
def test_physical_recovery_with_model_error(suite, d, name, param, true, tol):
    """Where the effect model approximates the simulator (quasi-static drag, slip timing, the link's own lag),
    the statistical sigma is far below the model error: the value is checked against a stated tolerance."""
    if name == "lost_steps":
        true = -d.slip_quantum_rad
        # the threshold: the estimate of the motor acceleration is noisy (1.9 rad/s^2 rms), the slip-or-not
        # boundary between two peaks lies within the ambiguity band of the truth
        thr = suite[name].added_effects_[0].values["slip_acceleration_rad_s2"]
        assert thr == pytest.approx(EFFECT_DEFAULTS["lost_steps"][0], rel=0.05)
    if name == "quadratic_drag":
        true = EFFECT_DEFAULTS["quadratic_drag"][0]
    fe = suite[name].added_effects_[0]
    assert fe.values[param] == pytest.approx(true, rel=tol)


# --------------------------------------------------------------------------- model-consistent recovery (fast)

TRUE = {
    "offset": ({}, {"offset_rad": 0.02}),
    "effective_radius": ({}, {"ratio_error": 0.05}),
    "cable_compliance": ({"stiffness_factor": 0.1}, {"gain": 1.0}),
    "coulomb_friction": ({"friction_torque_nm": 0.02}, {"gain": 1.0}),
    "viscous_friction": ({"damping_nm_s_rad": 0.02}, {"gain": 1.0}),
    "quadratic_drag": ({"drag_nm_s2_rad2": 0.003}, {"gain": 1.0}),
    "added_mass": ({"inertia_ratio": 51.0}, {"gain": 1.0}),
    "backlash": ({"gap_rad": 0.01}, {"gain": 1.0}),
    "capstan_creep": ({}, {"creep_per_travel": 0.001}),
    "sensor_delay": ({"delay_s": 0.01}, {"gain": 1.0}),
    "lost_steps": ({"slip_acceleration_rad_s2": None}, {"slip_rad": -0.0837758}),
}


@pytest.fixture(scope="module")
def bench_ctx(d):
    log = simulate_joint(d, {}, duration_s=20, seed=5, noise_rad=0, encoder_counts=None)
    return joint_context(log.t, log.motor_angle_rad, log.motor_angle_rad * d.ratio, d)


@pytest.mark.parametrize("name", list(TRUE))
def test_model_consistent_recovery_within_uncertainty(bench_ctx, name):
    """Data made by the effect's own model plus white noise: every parameter within 3 sigma of the truth
    (this checks the estimator and its uncertainties, free of model error)."""
    eff = FAMILY.effect(name)
    nl, lin = TRUE[name]
    nl = dict(nl)
    if name == "lost_steps":   # a threshold between two peaks of the commanded acceleration
        g = eff.grid(eff.nonlinear[0], bench_ctx)
        nl["slip_acceleration_rad_s2"] = float(g[5])
    X = eff.columns(bench_ctx, nl)
    beta = np.array([lin[p.name] for p in eff.linear])
    rng = np.random.default_rng(9)
    y = bench_ctx.base + X @ beta + rng.normal(0, 1e-3, bench_ctx.n)
    ctx = Context(bench_ctx.t, y, bench_ctx.base, bench_ctx.base_columns, bench_ctx.signals, "model-consistent",
                  meta=bench_ctx.meta)
    cal = Calibrator(FAMILY, candidates=[name], max_effects=1).fit(ctx)
    assert [fe.name for fe in cal.added_effects_] == [name]
    fe = cal.added_effects_[0]
    for k, v in {**nl, **lin}.items():
        assert abs(fe.values[k] - v) <= 3 * fe.stds[k] + 1e-12, (k, fe.values[k], v, fe.stds[k])


@pytest.mark.parametrize("effects,seed", [({"effective_radius": 1.05, "sensor_delay": 0.010}, 31),
                                          ({"lost_steps": 160.0}, 1)])
def test_windowed_selection_on_long_logs(d, effects, seed):
    """Above ``max_search_samples`` the selection runs on contiguous windows (slip counts taken from the whole
    record) and the values are refined on all rows: the same effects and values as a selection on all rows."""
    log = simulate_joint(d, effects, seed=seed)
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d)
    full = Calibrator(FAMILY).fit(ctx)
    win = Calibrator(FAMILY, max_search_samples=12000).fit(ctx)
    assert win.search_rows_ <= 20000 < full.search_rows_     # at least one 2500-row window per block
    assert sorted(fe.name for fe in win.added_effects_) == sorted(fe.name for fe in full.added_effects_)
    vf = {k: (v, fe.stds[k]) for fe in full.added_effects_ for k, v in fe.values.items()}
    for fe in win.added_effects_:
        for k, v in fe.values.items():
            assert v == pytest.approx(vf[k][0], rel=0.02, abs=3 * vf[k][1]), k


# ------------------------------------------------------------------------- the base model's timing and twins

@pytest.mark.parametrize("lag_samples", [-0.5, -0.3, 0.0, 0.2, 0.5])
def test_column_lag_recovered_within_its_window(d, lag_samples):
    """A reading whose motion is the base model's ``lag`` later (noise-free, plus an offset that must not move it)
    gives back that lag to 2 % of a sample; the window is half a sample either side of read-then-command."""
    from swiftfin.calibration.joint import COLUMN_LAG_SAMPLES, column_lag_s
    assert COLUMN_LAG_SAMPLES == (-0.5, 0.5)
    log = simulate_joint(d, {}, duration_s=6.0, seed=3, noise_rad=0.0, encoder_counts=None)
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, align=False)
    dt = float(np.median(np.diff(log.t)))
    y = np.interp(log.t - lag_samples * dt, log.t, ctx.base) + 0.01
    assert column_lag_s(log.t, y, ctx.base, dt) == pytest.approx(lag_samples * dt, abs=0.02 * dt)


def test_column_lag_stops_at_its_window(d):
    """A lag beyond the window (a sensor delay of 2 ms) is left to the effects: the alignment stops at the bound."""
    from swiftfin.calibration.joint import column_lag_s
    log = simulate_joint(d, {}, duration_s=6.0, seed=3, noise_rad=0.0, encoder_counts=None)
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, align=False)
    dt = float(np.median(np.diff(log.t)))
    assert column_lag_s(log.t, np.interp(log.t - 0.002, log.t, ctx.base), ctx.base, dt) == 0.5 * dt
    assert column_lag_s(log.t, np.interp(log.t + 0.002, log.t, ctx.base), ctx.base, dt) == -0.5 * dt


def test_a_spring_at_the_hinge_is_not_an_effective_radius(d):
    """The same position-proportional residual, told apart by the load cell: a spring k at the hinge pulls side A
    by k theta / (2 d_mount); a ratio error pulls nothing. The effective radius is then implausible."""
    from swiftfin.calibration.joint import EFFECTS, tension_angle_slope
    eff = next(e for e in EFFECTS if e.name == "effective_radius")
    log = simulate_joint(d, {}, seed=5)
    k = 0.05                                   # N m/rad, the independent bench's wire harness
    ratio_error = -k / d.stiffness_nm_rad      # the residual it leaves: -k theta / K
    spring = log.cable_tension_n + k * log.true_joint_angle_rad / (2 * d.moment_arm_m)
    with_spring = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, tension=spring)
    plain = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, tension=log.cable_tension_n)
    s, se = tension_angle_slope(with_spring)
    assert s == pytest.approx(k / (2 * d.moment_arm_m), rel=0.1) and se < 0.1 * s
    assert eff.plausible({"ratio_error": ratio_error}, with_spring)
    assert not eff.plausible({"ratio_error": ratio_error}, plain)
    assert eff.twins_outside and "sensor" in eff.twins_outside


def test_an_effective_radius_is_named_below_high_confidence(suite):
    """A sensor scale error leaves the same residual and tension as a ratio error: never "high", and the capped
    confidence says why."""
    fe = suite["effective_radius"].added_effects_[0]
    assert fe.name == "effective_radius" and fe.confidence == "medium"
    assert "sensor scale error" in fe.evidence["confidence_capped"]


# ----------------------------------------------------------------------------- the stepper's own torque

def test_stepper_drive_rings_at_the_stepper_and_cable_in_series(d):
    """A small command step, a heavy link: the link rings at sqrt(K / J) with K the cable pair in series with the
    stepper's small-signal stiffness T_hold 2 pi / cycle (at the motor; / ratio^2 at the joint)."""
    from swiftfin.calibration import effects as op
    dt = 1e-4
    t = np.arange(0, 0.6, dt)
    cyc = 4 * d.full_step_rad
    cmd = np.where(t > 0.05, 2 * d.microstep_rad, 0.0)
    J = 2e-4
    th = op.stepper_drive(t, cmd, d.ratio, d.holding_torque_nm, cyc, 1e-7, 0.0, d.cable_stiffness_nm_rad, J, 0.0)
    x = th[600:] - np.mean(th[600:])
    zc = np.flatnonzero(np.diff(np.sign(x)) != 0)
    omega = np.pi / (np.mean(np.diff(zc)) * dt)
    k_motor = d.holding_torque_nm * 2 * np.pi / cyc / d.ratio ** 2
    K = 1 / (1 / d.cable_stiffness_nm_rad + 1 / k_motor)
    assert omega == pytest.approx(np.sqrt(K / J), rel=0.02)
    assert k_motor == pytest.approx(d.motor_stiffness_nm_rad, rel=1e-9)   # the same stepper as the base model's


def test_stepper_drive_slips_whole_electrical_cycles(d):
    """A motor at 2 % of its torque asked to throw a heavy link 0.5 rad in 30 ms: it loses synchronism, and where
    it settles the joint is off the command by whole electrical cycles (4 full steps x ratio)."""
    from swiftfin.calibration import effects as op
    dt = 1e-4
    t = np.arange(0, 3.0, dt)
    cyc = 4 * d.full_step_rad
    cmd = 0.5 / d.ratio * np.clip((t - 0.1) / 0.03, 0.0, 1.0)
    th = op.stepper_drive(t, cmd, d.ratio, 0.02 * d.holding_torque_nm, cyc, d.rotor_inertia_kg_m2, 1e-4,
                          d.cable_stiffness_nm_rad, 2e-4, 1e-3)
    end = np.mean(th[-2000:]) - 0.5
    cycles = end / (d.ratio * cyc)
    assert abs(end) > 0.5 * d.ratio * cyc
    assert abs(cycles - round(cycles)) < 0.05


@pytest.mark.parametrize("seed", [3, 4])
def test_a_late_sensor_delays_every_effect_it_reports(d, seed):
    """A sensor delay delays what the sensor sees, friction included: the delay's value is shared by every effect's
    columns, so the model is the delayed prediction. With the effects added to a delayed base (before 2026-11-26)
    this pair was named Coulomb friction and viscous friction or drag, and fitted together the delay came out
    2.5 x too long at a gain of 0.38."""
    cal = run(d, {"coulomb_friction": 0.02, "sensor_delay": 0.006}, seed=seed)
    got = {fe.name: fe for fe in cal.added_effects_}
    assert set(got) == {"coulomb_friction", "sensor_delay"}, list(got)
    assert got["coulomb_friction"].values["friction_torque_nm"] == pytest.approx(0.02, rel=0.03)
    assert got["sensor_delay"].values["delay_s"] == pytest.approx(0.006, rel=0.03)
    assert all(abs(fe.values["gain"] - 1.0) < 0.05 for fe in got.values())
