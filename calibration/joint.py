"""The ``joint`` family: a capstan-driven tail joint on the bench (or in the water).

Data: CSV ``time_s,motor_angle_rad,joint_angle_rad`` (motor angle as commanded to the stepper, joint angle as
measured by a sensor on the hinge; extra columns ignored).

Base model (paper §3.4, eq. 48, and §2.3.2): a rigid capstan. The stepper moves in microsteps
q = full_step / microsteps, so the motor angle is q round(phi / q); the spool of radius r_spool pays out
r_spool phi of cable and the tendon sector of radius d_mount (the tendon moment arm) turns by

    theta_rigid = (r_spool / d_mount) q round(phi / q).

The staircase drives the link through the design's drive: the stepper's stiffness in series with the cable pair,
the link's inertia and its bearing's damping (``J theta'' + c theta' + K theta = K theta_rigid``), so the base
model rings after each microstep as the link does. No coefficient is fitted: the radii and stiffness come from
the design file, the link on the hinge is the design's own (the links behind the joint and the fin, held straight,
in air; in water with their added mass and the water they carry: :func:`swiftfin.layout.loads.hinge_inertia`) unless
a bench file says the bench holds another (:mod:`swiftfin.calibration.bench`); ``added_mass`` identifies the
inertia's ratio to that prior, both ways. Where within a sample the logged command acts is identified
(:func:`column_lag_s`, half a sample either side of the declared read-then-command convention) and reported as a
base term.

Physics of the departures (what the effects model). The stepper is position-commanded and the cable is stiff,
so joint-side loads (friction, drag, inertia) reach the joint angle only through the cable's compliance:
theta = theta_rigid - tau_load / K, with K = (k_a + k_b) d_mount^2 the pull-pull stiffness at the joint and
k = E A / L of each side (E, A from ``cable.*``, L the route length of :func:`swiftfin.layout.geometry.cable_routes`).
This fixes what can and cannot be told apart from the joint angle alone:

* ``cable_compliance`` and ``added_mass`` both change J / K, the only inertial quantity visible in a
  position log. They differ only through the bench link's bearing damping, which a softer cable makes visible
  (T1 = c0 / K grows with 1/K) and added mass does not; the effect's ``gain`` (1 when the mechanism's shape is
  right) then rejects the wrong one. On the default bench both are identified; with a heavily damped link they
  would not be.
* ``coulomb_friction`` seen through the cable holds the joint in a band of half-width tau_c / K (a play
  operator, to first order); a ``backlash`` dead band held by friction (spool loose on the shaft flat, set screw)
  is the play operator of half-width gap / 2 on the staircase. The friction acts on the link, so it is simulated
  in the drive (:func:`op.deadzone_drive`) and damps the link's ringing after each microstep, which play at the
  spool does not: that alone tells them apart on a lightly damped link, and the engine reports the other as
  ``indistinguishable_from`` where it cannot. An inline load cell on one cable side (the optional column
  ``cable_tension_n``) separates them for certain: friction holds the joint by torque, so the tension steps by
  tau_c / (2 d_mount) at each reversal; a dead band passes no torque and leaves no step (:func:`tension_step_n`,
  used as each one's plausibility check).
* ``viscous_friction`` (first-order lag c / K) and ``sensor_delay`` (pure delay) agree to first order in
  frequency; the bench command's small high-frequency components (up to 14 Hz) separate them through the
  second-order term (a lag loses gain, a delay does not).
* ``lost_steps`` are predicted from the commanded acceleration crossing a threshold; peaks within ~2 % of it
  cannot be classified from a quantised command log, and each misclassified one leaves a 4-full-step offset.

Every dynamic effect is modelled with the bare link's own dynamics (J0, c0 below and K from the design), so a
fitted parameter is the physical one (an inertia, a damping, a stiffness factor) and not a lumped lag.

The bare printed arm of the project's own synthetic suite (:data:`BENCH_LINK_INERTIA_KG_M2`, used through
:data:`swiftfin.calibration.bench.BARE_ARM`) and the hinge's bearing damping (:data:`BENCH_BEARING_DAMPING_NM_S_RAD`,
the default of every bench) are estimates, not design parameters: a bench file gives yours.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swiftfin.layout.geometry import spool_dims
from swiftfin.layout.loads import hinge_inertia
from swiftfin.layout.servo import (cable_route_length_m, cable_side_stiffness_n_m, drive_stiffness_nm_rad, in_series,
                                   joint_stiffness_nm_rad)
from swiftfin.calibration import effects as op
from swiftfin.calibration.model import Context, Effect, Family, Param
from swiftfin.calibration.io import Column, read_log
from swiftfin.physics.kinematics import joint_resolution_rad
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params

#: Inertia of the bare bench link about the hinge [kg m^2]: a 10 g printed arm with the sensor magnet,
#: centre of mass 24 mm from the hinge (0.010 x 0.024^2 = 5.8e-6). Estimate; weigh yours.
BENCH_LINK_INERTIA_KG_M2 = 6.0e-6
#: Viscous damping of the hinge bearing in air [N m s/rad] (steel pin in a printed bore, greased).
#: Estimate giving a damping ratio ~0.03 on the default design (caudal joint).
BENCH_BEARING_DAMPING_NM_S_RAD = 2.0e-4
#: A stepper that loses synchronism slips by one electrical cycle, 4 full steps.
SLIP_FULL_STEPS = 4
#: A slip is not instantaneous: the rotor swings through one electrical cycle against the load in about 10 ms
#: (an estimate: a quarter period of a ~25 Hz pull-in oscillation of rotor plus reflected link). Modelled as a
#: raised-cosine ramp of this duration, in the simulator and in the ``lost_steps`` effect alike. The slip times
#: the model infers from the commanded acceleration are off by up to ~0.7 ms on the bench log, which leaves
#: structure after each slip (reported as unexplained structure).
SLIP_DURATION_S = 0.010


#: Peaks of the estimated motor acceleration within this fraction of the slip threshold are ambiguous: the estimate
#: from a microstep-quantised command log has ~1.9 rad/s^2 rms of noise (1.2 % of a 160 rad/s^2 threshold), so a
#: peak within +-5 % (4 sigma) cannot be put on the right side of the threshold from the command alone.
AMBIGUOUS_BAND = 0.05
#: Windows before / after an ambiguous peak in which the measured joint angle is compared (s): a slip moves it by a
#: whole quantum (4 full steps x r/d_mount, 84 mrad on the default design, ~60 x the sensor noise).
JUDGE_BEFORE_S = (-0.06, -0.01)
JUDGE_AFTER_S = (0.03, 0.08)


def slip_events(ctx: Context, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """Times and signs of the slips of the ``lost_steps`` model over the whole record ``ctx``: every episode where
    the estimated motor acceleration rises above ``threshold``.

    Episodes whose peak lies within :data:`AMBIGUOUS_BAND` of the threshold cannot be classified from the command
    alone. Where such an episode lies wholly inside the fit's *training* rows (``meta['train_rows']``, set by the
    engine; never on held-out rows), the measured joint angle decides it: a slip if the residual of the rigid
    model jumps by more than half a quantum against the acceleration. On held-out rows, and on a record the fit
    never saw, the threshold alone decides (a prediction)."""
    a = ctx.signals["motor_acceleration"]
    times, signs = op.threshold_crossings(ctx.t, a, threshold)
    train = ctx.meta.get("train_rows")
    if train is None or times.size == 0 and not np.any(np.abs(a) > threshold * (1 - AMBIGUOUS_BAND)):
        return times, signs
    t = ctx.t
    q = _d(ctx).slip_quantum_rad
    lo, hi = threshold * (1 - AMBIGUOUS_BAND), threshold * (1 + AMBIGUOUS_BAND)
    over = np.abs(a) > lo
    starts = np.flatnonzero(over & ~np.r_[False, over[:-1]])
    ends = np.flatnonzero(over & ~np.r_[over[1:], False])
    keep = np.ones(times.size, bool)
    add_t, add_s = [], []
    cached = ctx.meta.get("_held_cumsum")              # (the mask it was made from, cumulative held-out count)
    if cached is not None and cached[0] is train:
        held = cached[1]
    else:
        held = np.r_[0, np.cumsum(~np.asarray(train, bool))]
        ctx.meta["_held_cumsum"] = (train, held)
    for i0, i1 in zip(starts, ends):
        seg = np.abs(a[i0:i1 + 1])
        if float(seg.max()) > hi:
            continue                                   # clear: the threshold decides
        t0, t1 = t[i0], t[i1]
        b0, b1 = np.searchsorted(t, t0 + JUDGE_BEFORE_S[0]), np.searchsorted(t, t0 + JUDGE_BEFORE_S[1], "right")
        a0, a1 = np.searchsorted(t, t1 + JUDGE_AFTER_S[0]), np.searchsorted(t, t1 + JUDGE_AFTER_S[1], "right")
        if b1 <= b0 or a1 <= a0 or held[a1] - held[b0] > 0:
            continue                                   # touches held-out rows (or the record's ends): threshold
        r_before = ctx.y[b0:b1] - ctx.base[b0:b1]
        r_after = ctx.y[a0:a1] - ctx.base[a0:a1]
        sg = float(np.sign(a[i0]))
        slipped = (np.median(r_after) - np.median(r_before)) * -sg > 0.5 * q
        inside = (times >= t0 - 1e-12) & (times <= t1 + 1e-12)
        keep &= ~inside
        if slipped:
            add_t.append(times[inside][0] if inside.any() else t[i0 + int(np.argmax(seg))])
            add_s.append(sg)
    times = np.r_[times[keep], add_t]
    signs = np.r_[signs[keep], add_s]
    order = np.argsort(times, kind="stable")
    return times[order], signs[order]


def slip_signal(t: np.ndarray, acceleration: np.ndarray, threshold: float, at: np.ndarray | None = None) -> np.ndarray:
    """Signed cumulative slip count (in slips) with each slip a raised-cosine ramp over :data:`SLIP_DURATION_S`
    starting where |acceleration| crosses ``threshold`` (interpolated between samples), evaluated at times ``at``
    (default ``t``)."""
    times, signs = op.threshold_crossings(t, acceleration, threshold)
    return op.ramped_steps(t if at is None else at, times, signs, SLIP_DURATION_S)


COLUMNS = (
    Column("time_s", "s", "time", doc="time"),
    Column("motor_angle_rad", "rad", "angle", 4 * math.pi, "commanded motor angle"),
    # a full turn, not the fish's quarter: a bench link has no hard stops, and a motor that loses steps walks it
    # off (18 slips took the independent bench's link to -1.67 rad); degrees within a turn are caught by the swing
    # against the capstan's (57.3 x, check_excitation)
    Column("joint_angle_rad", "rad", "angle", 2 * math.pi, "joint angle"),
    Column("cable_tension_n", "N", "value", 5000.0, "tension of one cable side (inline load cell)", optional=True),
)


@dataclass(frozen=True)
class JointDesign:
    """The design numbers the joint family needs, in SI."""

    joint: int                     # 0-based joint index
    spool_radius_m: float
    moment_arm_m: float
    ratio: float                   # r_spool / d_mount: joint rad per motor rad
    full_step_rad: float
    microstep_rad: float           # motor angle of one microstep
    joint_microstep_rad: float
    route_length_m: float          # mean free length of the two cables
    side_stiffness_n_m: float      # E A / L of one side
    stiffness_nm_rad: float        # K at the joint, the whole drive's: the cable pair 2 k d^2 in series with the motor
    pretension_n: float
    youngs_modulus_gpa: float
    link_inertia_kg_m2: float = BENCH_LINK_INERTIA_KG_M2
    bearing_damping_nm_s_rad: float = BENCH_BEARING_DAMPING_NM_S_RAD
    link_inertia_source: str = "the bare bench arm (BENCH_LINK_INERTIA_KG_M2)"
    motor_stiffness_nm_rad: float = math.inf    # the stepper held at its step, seen at the joint
    holding_torque_nm: float = 0.0              # the catalogue's, at the motor (0: unknown)
    rotor_inertia_kg_m2: float = 0.0            # the catalogue's, at the motor

    @property
    def cable_stiffness_nm_rad(self) -> float:
        """The cable pair's share of the drive's stiffness at the joint, 2 k d^2 [N m/rad]."""
        return 2.0 * self.side_stiffness_n_m * self.moment_arm_m ** 2

    def cable_share(self, drive_stiffness_nm_rad: float) -> float:
        """The cable pair's stiffness [N m/rad] that, in series with the motor's, gives ``drive_stiffness_nm_rad``
        (inf where the motor alone is that soft)."""
        inv = 1.0 / drive_stiffness_nm_rad - 1.0 / self.motor_stiffness_nm_rad
        return math.inf if inv <= 0 else 1.0 / inv

    @property
    def slip_quantum_rad(self) -> float:
        """Joint angle lost in one slip of 4 full steps [rad]."""
        return SLIP_FULL_STEPS * self.full_step_rad * self.ratio


def joint_design(p: Params, joint: int | None = None, medium: str = "air") -> JointDesign:
    """Design constants of joint ``joint`` (0-based; default the last, the caudal joint with the longest cable).
    The link on the hinge is the design's own (the links behind the joint and the fin, held straight; in water with
    their added mass and the water they carry: :func:`swiftfin.layout.loads.hinge_inertia`): the prior of the base
    model, which a bench file replaces (:mod:`swiftfin.calibration.bench`)."""
    n = p.joints.count
    j = n - 1 if joint is None else joint
    if not 0 <= j < n:
        raise UserError(f"--joint {j + 1}: the design has joints 1..{n}")
    hi = hinge_inertia(p, j, medium)
    r = spool_dims(p).drum_radius_mm / 1000.0
    m = p.joints.tendon_moment_arm_mm / 1000.0
    full = math.radians(p.motor.full_step_deg)
    q = full / p.motor.microsteps
    L = cable_route_length_m(p, j + 1)
    return JointDesign(j, r, m, r / m, full, q, joint_resolution_rad(full, p.motor.microsteps, m, r), L,
                       cable_side_stiffness_n_m(p, L), drive_stiffness_nm_rad(p, j + 1), p.cable.pretension_n,
                       p.cable.youngs_modulus_gpa, motor_stiffness_nm_rad=joint_stiffness_nm_rad(p),
                       holding_torque_nm=p.motor.holding_torque_nm, rotor_inertia_kg_m2=p.motor.rotor_inertia_kg_m2,
                       link_inertia_kg_m2=hi.total_kg_m2, link_inertia_source=hi.describe(j + 1))


def rigid_joint_angle(motor_angle_rad: np.ndarray, d: JointDesign) -> np.ndarray:
    """Base model: (r_spool / d_mount) q round(phi / q) [rad] (eq. 48 inverted)."""
    return d.ratio * d.microstep_rad * np.rint(np.asarray(motor_angle_rad, float) / d.microstep_rad)


def joint_context(t: np.ndarray, motor: np.ndarray, joint: np.ndarray, d: JointDesign, source: str = "<memory>",
                  tension: np.ndarray | None = None, align: bool = True) -> Context:
    """Context for the joint family from arrays (the loader's second half; synthetic tests use it directly).
    ``tension``: the optional load-cell column (tension of one cable side [N]). ``align``: identify the columns'
    timing within a sample (:func:`column_lag_s`) and shift the base model by it."""
    t = np.asarray(t, float)
    base = rigid_joint_angle(motor, d)
    dt = op.uniform_dt(t)
    smooth_motor = op.derivative(t, motor, window_s=0.03, order=0, polyorder=3) if t.size > 40 else motor
    vel = op.derivative(t, base, window_s=0.02, order=1)
    acc = op.derivative(t, base, window_s=0.03, order=2)
    macc = op.lowpass_derivative(t, np.asarray(motor, float), cutoff_hz=25.0, order=2)
    K = d.stiffness_nm_rad
    motion = op.second_order(t, base, d.bearing_damping_nm_s_rad / K, d.link_inertia_kg_m2 / K)
    y = np.asarray(joint, float)
    lag = column_lag_s(t, y, motion, dt) if align else 0.0
    if lag:
        shift = lambda x: np.interp(t - lag, t, x)      # noqa: E731  (the model seen lag seconds later)
        base, motion, vel, acc = shift(base), shift(motion), shift(vel), shift(acc)
    signals = {"input": np.asarray(motor, float), "position": base, "velocity": vel, "acceleration": acc,
               "motion": motion,
               "motor_acceleration": macc, "travel": op.travel(d.ratio * smooth_motor), "time": t - t[0]}
    if tension is not None:
        signals["tension"] = np.asarray(tension, float)
    # the base model is the design's drive: the rigid capstan's staircase through the drive stiffness and the link's
    # inertia and damping (its ringing after each microstep is in every log); "position" keeps the staircase
    terms = (f"the link on the hinge: {d.link_inertia_source}; drive stiffness {d.stiffness_nm_rad:.3g} N m/rad, "
             f"bearing damping {d.bearing_damping_nm_s_rad:.3g} N m s/rad (resonance "
             f"{math.sqrt(K / d.link_inertia_kg_m2) / (2 * math.pi):.3g} Hz)",)
    if lag:
        terms += (f"columns aligned within a sample: the joint reading {1e3 * lag:+.3f} ms behind the motor column "
                  f"(identified)",)
    return Context(t, y, motion, np.zeros((t.size, 0)), signals, source,
                   meta={"design": d, "dt_s": dt, "column_lag_s": lag, "base_terms": terms})


#: Where within a sample the logged command acts, relative to the joint reading of the same row, in sample periods
#: of the base model (which ramps the command between samples: a change centred half a sample before its row).
#: The convention the base model declares is a loop that reads the sensor at t_i, then commands: the row's command
#: acts from t_i on and its reading saw only the rows before, +0.5. A loop that commands, then reads, logs a
#: reading the row's command has already moved: up to one sample earlier, -0.5. Neither is physics and a log does
#: not say which, so the lag is identified in this window; no physical effect makes the joint lead its command,
#: while friction, compliance and a sensor delay all make it lag, so the window ends at the declared convention
#: and any lag beyond it is left to the effects.
COLUMN_LAG_SAMPLES = (-0.5, 0.5)


def column_lag_s(t: np.ndarray, y: np.ndarray, motion: np.ndarray, dt: float) -> float:
    """The base model's alignment of the two columns [s]: the lag within :data:`COLUMN_LAG_SAMPLES` sample periods
    minimising the variance of ``y - motion(t - lag)`` (least squares, bounded; a constant offset does not move
    it), snapped to 0 or a bound within 2 % of a sample of it."""
    from scipy.optimize import minimize_scalar

    def cost(lag):
        return float(np.var(y - np.interp(t - lag, t, motion)))
    lo, hi = COLUMN_LAG_SAMPLES[0] * dt, COLUMN_LAG_SAMPLES[1] * dt
    res = minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 0.01 * dt})
    lag = float(res.x)
    for snap in (lo, 0.0, hi):               # the bounded search never lands on a bound exactly
        if abs(lag - snap) < 0.02 * dt:
            return snap
    return lag


def check_excitation(ctx: Context, path: str) -> None:
    """Refuse logs that cannot identify anything: too short, motor barely moving, or joint not following."""
    d: JointDesign = ctx.meta["design"]
    motor = ctx.signals["input"]
    dt = float(np.median(np.diff(ctx.t)))
    if dt > JOINT_MAX_SAMPLE_INTERVAL_S * 1.01:
        raise UserError(f"{path}: column 'time_s': sample interval {dt:.4g} s ({1 / dt:.3g} Hz), expected at most "
                        f"{JOINT_MAX_SAMPLE_INTERVAL_S:g} s (a joint bench logs at 10 Hz-10 kHz, 1 kHz by default; its "
                        f"program moves at 0.37-14.3 Hz); the log spans {ctx.t[-1] - ctx.t[0]:.4g} s; likely cause: "
                        f"time in milliseconds (then dt {dt / 1000:.4g} s over {(ctx.t[-1] - ctx.t[0]) / 1000:.4g} s) "
                        f"- convert to seconds")
    if ctx.t[-1] - ctx.t[0] < 2.0:
        raise UserError(f"{path}: column 'time_s' spans {ctx.t[-1] - ctx.t[0]:.3g} s (rows 2-{ctx.n + 1}); "
                        f"at least 2 s of motion are needed to identify anything")
    steps = np.ptp(motor) / d.microstep_rad
    if steps < 20:
        raise UserError(f"{path}: column 'motor_angle_rad' moves over {steps:.1f} microsteps only "
                        f"({np.ptp(motor):.3g} rad); at least 20 microsteps ({20 * d.microstep_rad:.3g} rad) of "
                        f"motion are needed: the log is too poorly excited to identify anything")
    v = ctx.signals["velocity"]
    moving = np.abs(v) > 0.05 * np.max(np.abs(v))
    reversals = int(np.sum(np.diff(np.sign(v[moving])) != 0))
    if reversals < 4:
        raise UserError(f"{path}: column 'motor_angle_rad' reverses {reversals} time(s); at least 4 reversals "
                        f"are needed (friction, backlash and offsets need motion both ways)")
    rigid = ctx.signals["position"]
    jy = ctx.y
    copy = _copied_motor_column(jy, motor, rigid)
    if copy:
        raise UserError(f"{path}: column 'joint_angle_rad' {copy}: expected the joint angle, about "
                        f"{d.ratio:.3g} x the motor angle (r_spool / d_mount); likely cause: the motor (command) "
                        f"column was logged twice instead of the joint sensor - check which column was logged")
    ratio = np.ptp(jy) / max(np.ptp(rigid), 1e-300)
    if 40.0 < 1.0 / max(ratio, 1e-300) < 80.0:
        i = int(np.argmax(np.abs(motor)))
        raise UserError(f"{path}: column 'motor_angle_rad' row {i + 2}: value {motor[i]:.4g}; the motor commands "
                        f"{1 / ratio:.1f} x the joint swing the capstan predicts (57.3 = degrees per radian): the "
                        f"motor column looks like degrees - convert it to radians")
    if 40.0 < ratio < 80.0:
        i = int(np.argmax(np.abs(jy)))
        raise UserError(f"{path}: column 'joint_angle_rad' row {i + 2}: the joint swings {ratio:.1f} x the rigid "
                        f"capstan prediction (57.3 = degrees per radian): the column looks like degrees")
    if ratio < 0.2 or ratio > 5.0:
        raise UserError(f"{path}: column 'joint_angle_rad' swings {np.ptp(jy):.3g} rad while the motor commands "
                        f"{np.ptp(rigid):.3g} rad at the joint (ratio {ratio:.2f}): wrong column, wrong design "
                        f"(--design, --joint) or a joint that does not follow its motor")


#: Slowest sample rate a joint log can have [s]: 0.1 s (10 Hz, the lowest rate ``swiftfin synth`` writes); a bench
#: logs at 1 kHz (dt 0.001 s). Time stamps in milliseconds make dt 1000 x too large (1 "s" at 1 kHz).
JOINT_MAX_SAMPLE_INTERVAL_S = 0.1
#: A joint column closer to the motor column than this fraction of its distance to the capstan prediction is a copy
#: of the motor column (with a transmission ratio off 1 by more than :data:`COPY_RATIO_MARGIN`). On a real log the
#: joint follows the capstan (r / d_mount x motor) within the sensor noise and effects: the ratio is near 1 / 0.
COPY_CLOSENESS = 0.05
COPY_RATIO_MARGIN = 0.05


def _copied_motor_column(joint: np.ndarray, motor: np.ndarray, rigid: np.ndarray) -> str:
    """Why ``joint`` looks like a copy of ``motor`` ("" if it does not): equal to it within 1e-9 of its swing, or
    (when the capstan ratio differs from 1, so the two can be told apart) much closer to it than to the capstan."""
    joint, motor = np.asarray(joint, float), np.asarray(motor, float)
    scale = max(float(np.ptp(motor)), 1e-300)
    if np.max(np.abs(joint - motor)) <= 1e-9 * scale:
        return "is an exact copy of column 'motor_angle_rad'"
    ratio = np.ptp(rigid) / scale
    to_motor = float(np.sqrt(np.mean((joint - motor) ** 2)))
    to_rigid = float(np.sqrt(np.mean((joint - rigid) ** 2)))
    if abs(ratio - 1.0) > COPY_RATIO_MARGIN and to_motor < COPY_CLOSENESS * to_rigid:
        return (f"equals column 'motor_angle_rad' within {to_motor:.3g} rad rms (it is {to_rigid:.3g} rad rms "
                f"from the capstan prediction)")
    return ""


def load(path: str | Path, design: Params, joint: int | None = None, notes: list | None = None,
         bench=None) -> Context:
    """Read and check a joint log; build its context. Warnings (filled gaps) are appended to ``notes``.
    ``bench``: the bench's link and bearing (calibration.bench.Bench; default: this module's constants)."""
    log = read_log(path, COLUMNS, family="joint")
    if notes is not None:
        notes.extend(log.notes)
    d = joint_design(design, joint) if bench is None else bench.design(design, joint)
    ctx = joint_context(log["time_s"], log["motor_angle_rad"], log["joint_angle_rad"], d, str(path),
                        tension=log.columns.get("cable_tension_n"))
    check_excitation(ctx, str(path))
    return ctx


# --------------------------------------------------------------------------------------------------- effects


def _d(ctx: Context) -> JointDesign:
    return ctx.meta["design"]


def _unit_coef(name: str = "gain") -> Param:
    return Param(name, "-", 0.7, 1.3, "amplitude of the mechanism's predicted shape (1 if the mechanism is right)")


def _dyn(ctx: Context, t1: float, t2: float) -> np.ndarray:
    return op.second_order(ctx.t, ctx.signals["position"], t1, t2) - ctx.base


class _E(Effect):
    pass


def _context_memo(ctx: Context) -> dict:
    """Values kept on this context object alone. Not in ``ctx.meta``: :meth:`Context.select` copies ``meta`` into
    every window, where a value of the whole record has the wrong length."""
    return ctx.__dict__.setdefault("_memo", {})


def _drive(ctx: Context, **load) -> np.ndarray:
    """The link's angle with ``load`` (:func:`op.deadzone_drive`'s ``drag`` or ``friction``) acting on it in the
    drive, minus the same integration without it (kept per context), so the column is that load's effect alone."""
    d = _d(ctx)
    run = lambda **kw: op.deadzone_drive(ctx.t, ctx.signals["position"], d.stiffness_nm_rad,  # noqa: E731
                                         d.link_inertia_kg_m2, d.bearing_damping_nm_s_rad, 0.0, **kw)
    memo = _context_memo(ctx)
    if "free_drive" not in memo:
        memo["free_drive"] = run()
    return run(**load) - memo["free_drive"]


def ringing_frequency_hz(ctx: Context) -> float | None:
    """The link's resonance as the log shows it [Hz]: the peak of |H(f)| = |P_uy / P_uu| (Welch, 4096-sample
    segments) from the rigid staircase u to the reading y, between 1 Hz and 1.5 x the design's resonance, refined
    by a parabola through the three bins at the peak (in log |H|). The microstep staircase excites every frequency,
    so the link rings at its own resonance after each step whatever the program. None on a short log or where the
    peak stands less than 3x above the band's median (no resonance to see). Computed on the whole record
    (``meta['parent']``)."""
    from scipy import signal
    ctx = ctx.meta.get("parent", ctx)
    if "_ringing_hz" in ctx.meta:
        return ctx.meta["_ringing_hz"]
    out = None
    d = _d(ctx)
    fs = 1.0 / ctx.meta["dt_s"]
    nper = 4096
    if ctx.n >= 4 * nper:
        u = ctx.signals["position"]
        f, Puu = signal.welch(u, fs=fs, nperseg=nper, detrend="linear")
        _, Puy = signal.csd(u, ctx.y, fs=fs, nperseg=nper, detrend="linear")
        with np.errstate(divide="ignore", invalid="ignore"):
            H = np.abs(Puy / Puu)
        f_design = math.sqrt(d.stiffness_nm_rad / d.link_inertia_kg_m2) / (2 * math.pi)
        band = np.flatnonzero((f > 1.0) & (f < min(1.5 * f_design, 0.4 * fs)) & np.isfinite(H))
        if band.size > 4:
            i = band[np.argmax(H[band])]
            if H[i] > 3.0 * np.median(H[band]) and band[0] < i < band[-1]:
                a, b, c = np.log(H[i - 1: i + 2])
                shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
                out = float(f[i] + shift * (f[1] - f[0]))
    ctx.meta["_ringing_hz"] = out
    return out


class _ResonanceEffect(Effect):
    """An effect that moves the link's resonance (its nonlinear parameter sets it): the grid adds dense values
    around the resonance the log shows (:func:`ringing_frequency_hz`), +-6 % in frequency. A lightly damped link
    (Q ~ 250 at 5 x the fin's added mass) keeps ringing for seconds after each microstep, so the misfit has a basin
    about 1 % wide in frequency: the log-spaced grid (50 % steps) falls beside it and the refinement does not
    climb in."""

    #: (ctx, f_hz) -> the nonlinear parameter's value that puts the link's resonance at f_hz (None: none does)
    at_frequency = None

    def grid(self, param, ctx):
        g = param.grid_values()
        f = ringing_frequency_hz(ctx)
        if f is None or self.at_frequency is None:
            return g
        dense = [self.at_frequency(ctx, f * (1.0 + k)) for k in np.linspace(-0.06, 0.06, 25)]
        dense = [v for v in dense if v is not None and param.lo <= v <= param.hi]
        return np.unique(np.r_[g, dense])


class _ThresholdEffect(Effect):
    """An effect whose nonlinear parameter is a threshold on ``motor_acceleration``: the model changes only when
    the threshold crosses a peak, so the grid is the midpoints between the largest distinct peaks."""

    max_events = 80

    def grid(self, param, ctx):
        from scipy.signal import find_peaks
        a = np.abs(ctx.meta.get("parent", ctx).signals["motor_acceleration"])
        idx, _ = find_peaks(a)
        peaks = np.unique(a[idx])[::-1][: self.max_events + 1]
        if peaks.size < 2:
            return param.grid_values()
        mids = 0.5 * (peaks[1:] + peaks[:-1])
        g = np.r_[mids, param.hi]
        return g[(g >= param.lo) & (g <= param.hi)]


def _offset() -> Effect:
    return _E(name="offset", meaning="Sensor zero not at the joint's straight position (magnet or encoder mounting).",
              fingerprint="a constant residual, the same in both directions and at every position",
              linear=(Param("offset_rad", "rad", -0.5, 0.5, "sensor zero error"),), fingerprint_axis="position",
              columns_fn=lambda ctx, nl: np.ones(ctx.n))


#: The load cell's residual is not white (the link's dynamics): a coefficient's standard error is inflated as for
#: a correlation over about this many samples.
LOAD_CELL_CORRELATION_SAMPLES = 20.0


def _tension_coefficient(T: np.ndarray, X: np.ndarray, k: int) -> tuple[float, float]:
    """Least squares of the load cell's tension ``T`` on the columns ``X``: coefficient ``k`` and its standard
    error, inflated for the residual's correlation (:data:`LOAD_CELL_CORRELATION_SAMPLES`)."""
    coef, *_ = np.linalg.lstsq(X, T, rcond=None)
    r = T - X @ coef
    sigma = float(np.sqrt(r @ r / max(r.size - X.shape[1], 1)))
    se = sigma * float(np.sqrt(np.linalg.pinv(X.T @ X)[k, k])) * math.sqrt(LOAD_CELL_CORRELATION_SAMPLES)
    return float(coef[k]), se


def tension_angle_slope(ctx: Context) -> tuple[float, float] | None:
    """From the optional load cell: how side A's tension follows the joint angle [N/rad] and its standard error
    (least squares of tension on angle, with the direction of motion, the speed and the acceleration as nuisance
    terms: the link's inertia pulls a side by J theta'' / (2 d_mount), which a motion that rings back and forth
    makes look like a negative spring), or None without a load cell. A torque that grows with the angle (a spring
    at the hinge: a wire harness, a seal) pulls one side by k theta / (2 d_mount); a transmission-ratio error moves
    the joint without any torque. Computed on the whole record (``meta['parent']``)."""
    full = ctx.meta.get("parent", ctx)
    T = full.signals.get("tension")
    if T is None:
        return None
    cached = full.meta.get("_tension_angle")
    if cached is not None:
        return cached
    w = op.derivative(full.t, full.y, window_s=0.03, order=1)
    acc = op.derivative(full.t, full.y, window_s=0.03, order=2)
    out = _tension_coefficient(T, np.column_stack([np.ones(full.n), full.y, np.sign(w), w, acc]), 1)
    full.meta["_tension_angle"] = out
    return out


def _effective_radius() -> Effect:
    def plaus(v, ctx):
        meas = tension_angle_slope(ctx)
        if meas is None:
            return []
        d = _d(ctx)
        # the same residual made by a spring at the hinge: theta lags by k theta / K, so k = -ratio_error K
        spring = -v["ratio_error"] * d.stiffness_nm_rad / (2.0 * d.moment_arm_m)      # its tension slope [N/rad]
        s, se = meas
        if abs(spring) < 3.0 * se:
            return []
        if s * spring > 0 and abs(s) > 0.5 * abs(spring):
            return [f"the load cell's tension follows the joint angle by {s:.3g} N/rad, as a spring of "
                    f"{-v['ratio_error'] * d.stiffness_nm_rad:.3g} N m/rad at the hinge would ({spring:.3g} N/rad): "
                    f"the scale error is a torque growing with the angle, not the spool's radius"]
        return []

    def phys(v, s, ctx):
        d = _d(ctx)
        return {"spool_radius_mm": (1000 * d.spool_radius_m * (1 + v["ratio_error"]),
                                    1000 * d.spool_radius_m * s["ratio_error"], "mm")}
    return _E(name="effective_radius",
              meaning="The cable wraps at its centreline (r_spool + d/2), or the groove or tendon sector is off "
                      "size: the transmission ratio differs from r_spool / d_mount.",
              fingerprint="a residual proportional to the joint angle (a scale error): a straight line in residual "
                          "vs position through the origin",
              linear=(Param("ratio_error", "-", -0.5, 1.0, "relative error of r_spool / d_mount"),),
              fingerprint_axis="position", columns_fn=lambda ctx, nl: ctx.base, physical_fn=phys,
              plausible_fn=plaus,
              twins_outside="a sensor scale error (the sensor reads a fixed multiple of the angle) leaves the same "
                            "residual and the same tension: a second angle reference (the link photographed or set "
                            "against a protractor at two angles) tells the spool from the sensor")


def _cable_compliance() -> Effect:
    def cols(ctx, nl):
        d = _d(ctx)
        K = d.stiffness_nm_rad * nl["stiffness_factor"]
        return _dyn(ctx, d.bearing_damping_nm_s_rad / K, d.link_inertia_kg_m2 / K)

    def phys(v, s, ctx):
        d = _d(ctx)
        f, sf = v["stiffness_factor"], s["stiffness_factor"]
        K, sK = f * d.stiffness_nm_rad, sf * d.stiffness_nm_rad
        # the cable's share, the motor's stiffness taken as the design's (its error propagated to first order)
        kc = d.cable_share(K)
        skc = sK * (kc / K) ** 2 if math.isfinite(kc) else math.inf
        e = d.youngs_modulus_gpa / d.cable_stiffness_nm_rad
        return {"joint_stiffness_nm_rad": (K, sK, "N m/rad"),
                "effective_modulus_gpa": (kc * e, skc * e, "GPa")}

    def plaus(v, ctx):
        return [] if v["stiffness_factor"] < 0.9 else ["stiffness within 10 % of the design: no compliance effect"]
    def at_f(ctx, f_hz):
        d = _d(ctx)
        return (2 * math.pi * f_hz) ** 2 * d.link_inertia_kg_m2 / d.stiffness_nm_rad
    return _ResonanceEffect(name="cable_compliance", at_frequency=at_f,
              meaning="The cable (and its anchors, guides, printed sector) is softer than E A / L of the design: the "
                      "joint's own inertia and bearing damping stretch it.",
              fingerprint="a lag growing with frequency and ringing after fast moves (resonance sqrt(K/J) drops): "
                          "residual against acceleration and velocity",
              linear=(_unit_coef(),),
              nonlinear=(Param("stiffness_factor", "-", 0.003, 1.0, "joint stiffness / design stiffness",
                               scale="log", grid=24),),
              fingerprint_axis="acceleration", columns_fn=cols, physical_fn=phys, plausible_fn=plaus)


def _added_mass() -> Effect:
    """The link's inertia about the hinge differs from the base model's prior (the design's link, or the bench
    file's): identified as the ratio to the prior, both ways (issue 14 item 1: a bench holding a lighter link than
    the design's tail is as common as the water's added mass on a heavier one)."""
    def cols(ctx, nl):
        d = _d(ctx)
        K = d.stiffness_nm_rad
        return _dyn(ctx, d.bearing_damping_nm_s_rad / K, d.link_inertia_kg_m2 * nl["inertia_ratio"] / K)

    def at_f(ctx, f_hz):
        d = _d(ctx)
        return d.stiffness_nm_rad / (2 * math.pi * f_hz) ** 2 / d.link_inertia_kg_m2

    def phys(v, s, ctx):
        J0 = _d(ctx).link_inertia_kg_m2
        r, sr = v["inertia_ratio"], s["inertia_ratio"]
        return {"link_inertia_kg_m2": (r * J0, sr * J0, "kg m^2"),
                "added_inertia_kg_m2": ((r - 1.0) * J0, sr * J0, "kg m^2")}

    def plaus(v, ctx):
        return ([] if abs(v["inertia_ratio"] - 1.0) >= 0.1
                else ["inertia within 10 % of the prior: no inertia effect"])
    return _ResonanceEffect(name="added_mass", at_frequency=at_f,
              meaning="The inertia about the hinge differs from the base model's (the design's link, or the bench "
                      "file's): the water the link accelerates (added mass), a payload, or a link heavier or lighter "
                      "than assumed.",
              fingerprint="a residual proportional to -acceleration at low frequency, the resonance sqrt(K/J) "
                          "moving (down for a heavier link): residual against acceleration",
              linear=(_unit_coef(),),
              nonlinear=(Param("inertia_ratio", "-", 1e-3, 1e4, "inertia about the hinge / the prior's",
                               scale="log", grid=40),),
              fingerprint_axis="acceleration", columns_fn=cols, physical_fn=phys, plausible_fn=plaus)


def _viscous() -> Effect:
    def cols(ctx, nl):
        d = _d(ctx)
        K = d.stiffness_nm_rad
        return _dyn(ctx, (d.bearing_damping_nm_s_rad + nl["damping_nm_s_rad"]) / K, d.link_inertia_kg_m2 / K)

    def phys(v, s, ctx):
        K = _d(ctx).stiffness_nm_rad
        return {"lag_time_constant_s": (v["damping_nm_s_rad"] / K, s["damping_nm_s_rad"] / K, "s")}
    return _E(name="viscous_friction",
              meaning="Torque proportional to joint speed (lubricated bearing, seals, linear hydrodynamic damping), "
                      "stretching the cable: a first-order lag c / K.",
              fingerprint="a residual proportional to -velocity whose phase lag grows as atan(omega c / K) "
                          "(gain drops at high frequency, unlike a delay): residual against velocity",
              linear=(_unit_coef(),),
              nonlinear=(Param("damping_nm_s_rad", "N m s/rad", 1e-4, 1.0, "viscous damping at the hinge",
                               scale="log", grid=16),),
              fingerprint_axis="velocity", columns_fn=cols, physical_fn=phys)


def _quadratic_drag() -> Effect:
    def cols(ctx, nl):
        # the drag acts on the link's own speed, its ringing after each microstep included, and damps that ringing
        # as it grows: a link that moves in jerks sees b w|w| partly linear in its mean speed, so the drag is
        # simulated in the drive
        return _drive(ctx, drag=nl["drag_nm_s2_rad2"])

    def phys(v, s, ctx):
        return {"drag_coefficient_nm_s2_rad2": (v["drag_nm_s2_rad2"], s["drag_nm_s2_rad2"], "N m s^2/rad^2")}
    return _E(name="quadratic_drag",
              meaning="Hydrodynamic (form) drag of the fin and link, tau = b omega |omega|, stretching the cable.",
              fingerprint="a residual proportional to -velocity |velocity|: a parabola in residual vs velocity, "
                          "flat at low speed",
              linear=(_unit_coef(),),
              nonlinear=(Param("drag_nm_s2_rad2", "N m s^2/rad^2", 1e-6, 1.0, "form-drag coefficient b",
                               scale="log", grid=19),),
              fingerprint_axis="velocity", columns_fn=cols, physical_fn=phys)


def tension_step_n(ctx: Context) -> tuple[float, float] | None:
    """From the optional load cell: the step of the cable tension with the direction of the joint's motion [N]
    and its standard error: |s| of the fit T = T0 + s sign(w) + c w over the samples where the joint moves
    (w = measured joint speed, Savitzky-Golay over 30 ms, moving = above 10 % of its 95th percentile). Friction at
    the hinge shows as s = tau_c / (2 d_mount); a dead band passes no torque and leaves s ~ 0. Computed on the
    whole record (``meta['parent']``); the standard error is inflated for the residual's correlation
    (:func:`_tension_coefficient`). None without a load cell."""
    ctx = ctx.meta.get("parent", ctx)
    T = ctx.signals.get("tension")
    if T is None:
        return None
    cached = ctx.meta.get("_tension_step")
    if cached is not None:
        return cached
    w = op.derivative(ctx.t, ctx.y, window_s=0.03, order=1)
    moving = np.abs(w) > 0.1 * np.percentile(np.abs(w), 95)
    step, se = _tension_coefficient(T[moving], np.column_stack([np.ones(moving.sum()), np.sign(w[moving]),
                                                                w[moving]]), 1)
    out = (abs(step), se)
    ctx.meta["_tension_step"] = out
    return out


def _hysteresis_by_load_cell(kind: str, half_width_of):
    """Plausibility from the load cell: the fitted hysteresis (half-width h in joint angle) carried by friction
    steps the tension by h K / (2 d_mount); a dead band does not. ``kind``: "friction" or "dead band"."""
    def check(v, ctx):
        meas = tension_step_n(ctx)
        if meas is None:
            return []
        d = _d(ctx)
        s_friction = half_width_of(v, ctx) * d.stiffness_nm_rad / (2.0 * d.moment_arm_m)
        s, se = meas
        if s_friction < 3.0 * se:
            return []       # too small a hysteresis for the load cell to judge
        if kind == "friction" and s < 0.5 * s_friction:
            return [f"the load cell shows a tension step of {s:.3g} N at reversals where friction of this size would "
                    f"give {s_friction:.3g} N: the hysteresis passes no torque (a dead band, not friction)"]
        if kind == "dead band" and s > 0.5 * s_friction:
            return [f"the load cell shows a tension step of {s:.3g} N at reversals ({s_friction:.3g} N if this "
                    f"hysteresis were friction): the joint is held by torque, so it is friction, not a dead band"]
        return []
    return check


def _play_effect(name, meaning, fingerprint, pname, unit, lo, hi, to_half_width, phys, kind, columns_fn=None):
    """A hysteresis of half-width ``to_half_width(ctx, value)``: by default play on the drive's input (the
    staircase); ``columns_fn`` for one that acts elsewhere (dry friction on the link)."""
    def cols(ctx, nl):
        h = to_half_width(ctx, nl[pname])
        d = _d(ctx)
        K = d.stiffness_nm_rad
        # the play acts on the drive's input (the staircase), the link then follows through its own dynamics
        return op.second_order(ctx.t, op.play(ctx.signals["position"], h), d.bearing_damping_nm_s_rad / K,
                               d.link_inertia_kg_m2 / K) - ctx.base
    return _E(name=name, meaning=meaning, fingerprint=fingerprint, linear=(_unit_coef(),),
              nonlinear=(Param(pname, unit, lo, hi, "", scale="log", grid=16),), fingerprint_axis="velocity",
              columns_fn=columns_fn or cols, physical_fn=phys,
              plausible_fn=_hysteresis_by_load_cell(kind, lambda v, ctx: to_half_width(ctx, v[pname]) * v["gain"]))


def _coulomb() -> Effect:
    def phys(v, s, ctx):
        K = _d(ctx).stiffness_nm_rad
        return {"stuck_band_rad": (2 * v["friction_torque_nm"] / K, 2 * s["friction_torque_nm"] / K, "rad")}

    def cols(ctx, nl):
        # the friction acts on the link in the drive: it holds the link until the cable has wound up tau_c / K, and
        # it damps the link's ringing after each microstep (a play operator on the staircase, then the linear
        # drive, left that ringing undamped: on the design's own link, 35 x the bare arm's inertia and ringing at
        # 16 Hz, friction was named viscous)
        return _drive(ctx, friction=nl["friction_torque_nm"])
    return _play_effect(
        "coulomb_friction",
        "Dry friction at the hinge (pin loaded by the cable pretension): a constant torque against the motion, "
        "stretching the cable; the joint sticks at each reversal until the cable has wound up 2 tau_c / K.",
        "a step in the residual at zero velocity (residual = -tau_c/K sign(velocity)), hysteresis after each "
        "reversal: residual against velocity",
        "friction_torque_nm", "N m", 1e-4, 0.5, lambda ctx, x: x / _d(ctx).stiffness_nm_rad, phys, "friction",
        columns_fn=cols)


def _backlash() -> Effect:
    def phys(v, s, ctx):
        d = _d(ctx)
        return {"cable_slack_mm": (1000 * v["gap_rad"] * d.moment_arm_m, 1000 * s["gap_rad"] * d.moment_arm_m, "mm")}
    return _play_effect(
        "backlash",
        "A dead band held by friction: play of the spool on the shaft flat or of the hinge pin, with the cables "
        "still pretensioned (a slack cable is cable_slack); the motor turns through the gap before the joint "
        "follows (paper eq. 37).",
        "the residual jumps by the gap at each reversal and stays at +-gap/2 against the motion: concentrated "
        "after reversals, residual against velocity",
        "gap_rad", "rad", 2e-4, 0.2, lambda ctx, x: 0.5 * x, phys, "dead band")


def _slack() -> Effect:
    """A pull-pull pair that has lost its pretension (issue 14 item 2): each cable pulls only once stretched past
    its slack, so inside a dead band of +- s the link floats on its own inertia and damping, and outside it one
    side pulls alone (half the pair's stiffness, in series with the stepper's)."""
    def cols(ctx, nl):
        d = _d(ctx)
        one_side = in_series(d.cable_stiffness_nm_rad / 2.0, d.motor_stiffness_nm_rad)
        return op.deadzone_drive(ctx.t, ctx.signals["position"], one_side, d.link_inertia_kg_m2,
                                 d.bearing_damping_nm_s_rad, nl["slack_rad"]) - ctx.base

    def phys(v, s, ctx):
        d = _d(ctx)
        return {"slack_per_side_mm": (1000 * v["slack_rad"] * d.moment_arm_m, 1000 * s["slack_rad"] * d.moment_arm_m,
                                      "mm"),
                "dead_band_rad": (2 * v["slack_rad"], 2 * s["slack_rad"], "rad")}

    def plaus(v, ctx):
        T = ctx.meta.get("parent", ctx).signals.get("tension")
        if T is None:
            return []
        t0 = _d(ctx).pretension_n
        med = float(np.median(T))
        return [] if med < 0.5 * t0 else [f"the load cell reads {med:.3g} N of the {t0:g} N pretension: the cables "
                                          f"are not slack"]
    return _E(name="cable_slack",
              meaning="The cables have lost their pretension (creep, a slipped anchor): inside a dead band the link "
                      "floats free between them, outside it one side pulls alone. The failure the design rules "
                      "predict when a side goes slack (physics.no_slack_side).",
              fingerprint="the residual jumps at each reversal, with the link's own ringing inside the band (not "
                          "held by friction, unlike backlash); a load cell reads about zero tension",
              linear=(_unit_coef(),),
              nonlinear=(Param("slack_rad", "rad", 2e-4, 0.1, "half-width of the dead band in joint angle",
                               scale="log", grid=16),),
              fingerprint_axis="velocity", columns_fn=cols, physical_fn=phys, plausible_fn=plaus)


#: Damping ratio of the stepper's rotor on its own holding stiffness at the catalogue torque (bearings, iron
#: losses; a chopper driver's current loop adds little). An estimate: the fit's stepper_torque is not sensitive to
#: it where the motor is weak enough to matter.
ROTOR_DAMPING_RATIO = 0.02


def _stepper_torque() -> Effect:
    """A stepper weaker than its catalogue (issue 14 item 2): the rotor on the hybrid stepper's periodic torque,
    with its inertia, behind the cable pair; it lags by its own compliance and slips whole electrical cycles where
    the load passes its torque, anywhere in the log (not only at acceleration peaks)."""
    def sim(ctx, fraction):
        d = _d(ctx)
        cyc = SLIP_FULL_STEPS * d.full_step_rad
        k_motor = d.holding_torque_nm * 2 * math.pi / cyc
        c_rotor = 2 * ROTOR_DAMPING_RATIO * math.sqrt(k_motor * d.rotor_inertia_kg_m2)
        # substeps: the fastest mode (the rotor on the weakened stepper and the cable, or the link on the cable)
        # at <= 0.5 rad a step (semi-implicit Euler is stable to 2)
        w_rotor = math.sqrt((fraction * k_motor + d.cable_stiffness_nm_rad * d.ratio ** 2) / d.rotor_inertia_kg_m2)
        w_link = math.sqrt(d.cable_stiffness_nm_rad / d.link_inertia_kg_m2)
        n_sub = max(2, math.ceil(max(w_rotor, w_link) * op.uniform_dt(ctx.t) / 0.5))
        return op.stepper_drive(ctx.t, ctx.signals["position"] / d.ratio, d.ratio, fraction * d.holding_torque_nm,
                                cyc, d.rotor_inertia_kg_m2, c_rotor, d.cable_stiffness_nm_rad, d.link_inertia_kg_m2,
                                d.bearing_damping_nm_s_rad, substeps=n_sub)

    def cols(ctx, nl):
        if _d(ctx).holding_torque_nm <= 0 or _d(ctx).rotor_inertia_kg_m2 <= 0:
            return np.zeros(ctx.n)
        full = ctx.meta.get("parent", ctx)          # slips carry over: simulate the whole record (once per value:
        cached = full.meta.get("_stepper_sim")      # a windowed selection asks for it window by window)
        if cached is not None and cached[0] == nl["torque_fraction"]:
            theta = cached[1]
        else:
            theta = sim(full, nl["torque_fraction"])
            full.meta["_stepper_sim"] = (nl["torque_fraction"], theta)
        if full is not ctx:
            theta = theta[np.searchsorted(full.t, ctx.t)]
        return theta - ctx.base

    def phys(v, s, ctx):
        T = _d(ctx).holding_torque_nm
        return {"holding_torque_nm": (v["torque_fraction"] * T, s["torque_fraction"] * T, "N m")}

    def plaus(v, ctx):
        return [] if v["torque_fraction"] < 0.9 else ["holding torque within 10 % of the catalogue's: no effect"]
    return _E(name="stepper_torque",
              meaning="The stepper gives less torque than its catalogue holding torque (driver current set low, a "
                      "weak supply, a hot motor): its stiffness falls with it, the joint swings behind the command, "
                      "and it loses whole electrical cycles (4 full steps) wherever the load passes its torque.",
              fingerprint="a lag and ringing far beyond the cable's (the motor's spring is the soft one), with "
                          "permanent jumps of 4 full steps x r / d_mount where the load peaks: residual against time",
              linear=(_unit_coef(),),
              nonlinear=(Param("torque_fraction", "-", 1e-4, 1.0, "holding torque / the catalogue's",
                               scale="log", grid=13),),
              fingerprint_axis="time", columns_fn=cols, physical_fn=phys, plausible_fn=plaus)


def _creep() -> Effect:
    return _E(name="capstan_creep",
              meaning="The cable slowly slides around the drum (or walks along the groove) in one direction: a "
                      "small slip for every radian of travel, accumulating.",
              fingerprint="a drift that does not reverse with the motion and grows with the distance travelled "
                          "(not with time): residual against cumulative travel",
              linear=(Param("creep_per_travel", "rad/rad", -0.02, 0.02, "joint slip per joint radian travelled"),),
              fingerprint_axis="travel", columns_fn=lambda ctx, nl: ctx.signals["travel"])


def _delay() -> Effect:
    def cols(ctx, nl):
        # the sensor sees the joint's motion, which follows the microstep staircase through the bare link's own
        # dynamics; delaying that smooth motion (not the staircase) keeps the fit smooth in the delay
        return op.delay(ctx.t, ctx.signals["motion"], nl["delay_s"]) - ctx.base

    return _E(name="sensor_delay",
              meaning="The joint sensor reports late (filtering, bus latency, frame time) by a constant delay.",
              fingerprint="a cross-correlation peak of residual and input rate at a lag; a phase lag growing in "
                          "proportion to frequency with no loss of gain: residual against velocity",
              linear=(_unit_coef(),),
              nonlinear=(Param("delay_s", "s", 2e-4, 0.1, "sensor latency", scale="log", grid=28),),
              fingerprint_axis="velocity",
              columns_fn=cols)


def _lost_steps() -> Effect:
    def cols(ctx, nl):
        d = _d(ctx)
        K = d.stiffness_nm_rad
        full = ctx.meta.get("parent", ctx)       # slips counted since the start of the record
        times, signs = slip_events(full, nl["slip_acceleration_rad_s2"])
        ev = op.ramped_steps(ctx.t, times, signs, SLIP_DURATION_S)
        # a slip is a step of the cable's far end: the link rings after it at sqrt(K / J0)
        return op.second_order(ctx.t, ev, d.bearing_damping_nm_s_rad / K, d.link_inertia_kg_m2 / K)

    def plaus(v, ctx):
        q = _d(ctx).slip_quantum_rad
        s = -v["slip_rad"] / q
        k = round(s)
        if k < 1 or abs(s - k) > 0.25 * k:
            return [f"slip of {v['slip_rad']:.4g} rad per event is not a whole number of 4-full-step slips "
                    f"against the acceleration ({-q:.4g} rad each)"]
        return []

    def phys(v, s, ctx):
        q = _d(ctx).slip_quantum_rad
        return {"full_steps_per_slip": (-v["slip_rad"] / q * SLIP_FULL_STEPS, s["slip_rad"] / q * SLIP_FULL_STEPS,
                                        "full steps")}
    return _ThresholdEffect(name="lost_steps",
              meaning="The stepper loses synchronism when the torque demanded (mostly acceleration) exceeds what it "
                      "can give: the rotor slips by 4 full steps against the acceleration and the controller never "
                      "knows.",
              fingerprint="sudden permanent jumps of the residual by multiples of 4 full steps x r/d at moments "
                          "of peak acceleration: residual against time",
              linear=(Param("slip_rad", "rad", -1.0, 1.0, "joint angle lost per slip event"),),
              nonlinear=(Param("slip_acceleration_rad_s2", "rad/s^2", 5.0, 5000.0,
                               "motor acceleration beyond which it slips", scale="log", grid=48),),
              fingerprint_axis="time", columns_fn=cols, plausible_fn=plaus, physical_fn=phys)


def _seen_late(columns_fn):
    """The columns as a late sensor reports them: with ``sensor_delay`` in the model its ``delay_s`` (a family-shared
    parameter) delays every other effect's columns as it delays the base, so the model is the delayed prediction
    and not the sum of a delayed base and undelayed effects (Coulomb friction with a 6 ms delay on the independent
    bench: the sum fitted only at gains 0.66 and 0.45, the delay 2.5 x too long)."""
    def cols(ctx, nl):
        tau = nl.get("delay_s", 0.0)
        # the undelayed columns, kept per context while the delay alone changes (a simulated drive costs 65 ms on
        # a million rows; the search asks for it again at every delay it tries, and once the delay is in the model
        # at every step after)
        memo = _context_memo(ctx)
        key = (id(columns_fn), tuple(sorted((k, v) for k, v in nl.items() if k != "delay_s")))
        X = memo.get(key)
        if X is None:
            X = np.asarray(columns_fn(ctx, nl), float).reshape(ctx.n, -1)
            used = sum(v.nbytes for v in memo.values() if isinstance(v, np.ndarray))
            if used + X.nbytes <= UNDELAYED_MEMO_BYTES:
                X.setflags(write=False)             # shared by every later call: nobody may change it
                memo[key] = X
        if not tau:
            return X
        return np.column_stack([op.delay(ctx.t, X[:, k], tau) for k in range(X.shape[1])])
    return cols


#: Memory for the undelayed columns of one context (:func:`_seen_late`, in :func:`_context_memo`).
UNDELAYED_MEMO_BYTES = 200_000_000


def _as_reported(eff: Effect) -> Effect:
    """The effect as the sensor reports it: late by the model's sensor delay (the delay itself excepted)."""
    if eff.name != "sensor_delay":
        eff.columns_fn = _seen_late(eff.columns_fn)
    return eff


EFFECTS: tuple[Effect, ...] = tuple(_as_reported(e) for e in (
    _offset(), _effective_radius(), _cable_compliance(), _coulomb(), _viscous(), _quadratic_drag(), _added_mass(),
    _backlash(), _slack(), _creep(), _delay(), _lost_steps(), _stepper_torque()))

EFFECT_NAMES = tuple(e.name for e in EFFECTS)

#: Effects whose fingerprints the physics makes (near-)identical in a joint-angle log (see module docstring).
EQUIVALENT = (frozenset({"coulomb_friction", "backlash"}), frozenset({"cable_compliance", "added_mass"}))

FAMILY = Family(
    name="joint",
    description="capstan-driven joint: commanded motor angle -> measured joint angle (rigid capstan, eq. 48)",
    columns=COLUMNS,
    target="joint_angle_rad",
    target_unit="rad",
    base_terms=("rigid capstan: theta = (r_spool / d_mount) q round(phi / q)  (paper eq. 48 inverted)",
                "through the design's drive: J theta'' + c theta' + K theta = K theta_rigid",),
    effects=EFFECTS,
    load=load,
    equivalent_effects=EQUIVALENT,
    shared_params=("delay_s",),
    units={"motor_angle": "rad", "joint_angle": "rad", "velocity": "rad/s", "acceleration": "rad/s^2"},
)
