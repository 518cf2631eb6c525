"""Synthetic bench logs of a capstan joint, simulated physically (for testing the calibration engine).

Chain: commanded joint trajectory -> stepper microsteps (eq. 48, the controller uses the design ratio; updated once per
logged sample, after the sample's reading: read, then command) ->
rotor (slips 4 full steps, over 5 ms, when over-accelerated: ``lost_steps``; periodic microstep error: ``cogging``) ->
spool (loose on the shaft: ``backlash``; radius x ``effective_radius``; cable creeping on the drum: ``capstan_creep``) -> two pretensioned cables
of stiffness E A / L each (x ``cable_compliance``; a side goes slack when the load exceeds 2 T0 d_mount;
``_integrate`` also supports a dead band in the cable itself) -> joint: (J0 + J_added) theta'' = tau_cable - (c0 + c) theta' - b theta'|theta'|
- tau_c sign(theta') (stick when the cable torque is below tau_c) -> sensor (``sensor_delay``, ``offset``,
Gaussian noise then 12-bit quantisation, the AS5600 magnetic encoder's 4096 counts per turn). The bench also
has an inline load cell on cable side A: ``cable_tension_n`` = max(0, T0 + k m (u - theta)) with
:data:`LOAD_CELL_NOISE_N` of noise (the log's optional second sensor; ``swiftfin synth --no-load-cell`` leaves
it out).

Integration: semi-implicit Euler (damping terms implicit, stick-slip by Karnopp's rule) at a fixed step of
``1 / (rate_hz * substeps)`` (default 0.2 ms; the stiffest default mode, sqrt(K / J0) ~ 600 rad/s, gives
omega h = 0.12). When no nonlinear element is present (no friction, drag, backlash, and no side goes slack) the
linear ODE is solved exactly instead (zero-order-hold discretisation at the same step), which is how the
million-sample benchmark log is made quickly.

The command is a bench identification program: five sines (0.37, 1.13, 2.9, 6.7 and 14.3 Hz, joint
amplitudes 0.30, 0.12, 0.05, 0.02, 0.008 rad, random phases from the seed) under a slow envelope
(0.45-1.0 over 17 s) so each block of time holds several frequencies at several amplitudes; about 1 rad/s
rms and 40 rad/s^2 rms at the joint, peaks near 0.5 rad.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal

from swiftfin.calibration import effects as op
from swiftfin.calibration.joint import SLIP_FULL_STEPS, JointDesign, slip_signal

#: name -> (default value, unit, meaning of VALUE, why that size). Sizes are realistic for the default design.
EFFECT_DEFAULTS: dict[str, tuple[float, str, str, str]] = {
    "offset": (0.02, "rad", "sensor zero error", "a magnet glued 1.1 deg off"),
    "effective_radius": (1.05, "-", "actual / design spool radius",
                         "cable centreline at r + d/2 = 10.5 mm on the 10 mm drum"),
    "cable_compliance": (0.1, "-", "actual / design cable stiffness",
                         "braided cord at low tension plus printed-anchor flex: one tenth of E A / L"),
    "coulomb_friction": (0.02, "N m", "dry friction torque at the hinge",
                         "mu 0.15 x 90 N pin load (2 x 45 N pretension) x 1.5 mm pin radius"),
    "viscous_friction": (0.02, "N m s/rad", "viscous damping at the hinge",
                         "linear damping of a fin in water at low speed"),
    "quadratic_drag": (0.003, "N m s^2/rad^2", "form-drag coefficient b of tau = b w|w|",
                       "1/2 rho Cd A r^3: Cd 1.5, A 4.3e-3 m^2 (the default caudal fin), r 0.1 m"),
    "added_mass": (3e-4, "kg m^2", "extra inertia about the hinge",
                   "fin added mass: rho pi (c/2)^2 span r^2 with c 27 mm, span 160 mm, r 70 mm"),
    "backlash": (0.01, "rad", "total dead band, in joint angle",
                 "spool loose on the shaft flat: 0.86 deg of shaft play x 10/15"),
    "capstan_creep": (0.001, "rad/rad", "joint slip per radian travelled", "cable walking 0.1 % on the drum"),
    "sensor_delay": (0.010, "s", "sensor latency", "USB / serial encoder pipeline, 5-20 ms"),
    "lost_steps": (160.0, "rad/s^2", "motor acceleration beyond which the rotor slips 4 full steps",
                   "driver current turned down: a handful of slips over a 40 s program"),
    # outside the fitting library (for testing that the engine admits what it does not know)
    "cogging": (0.1, "full steps", "amplitude of the rotor's periodic microstep error (period 4 full steps)",
                "detent torque against the microstepping current: 5-10 % of a full step"),
    "radius_drift": (0.03, "-", "fractional change of the spool radius over the log",
                     "PLA drum warming up"),
}

LIBRARY_EFFECTS = ("offset", "effective_radius", "cable_compliance", "coulomb_friction", "viscous_friction",
                   "quadratic_drag", "added_mass", "backlash", "capstan_creep", "sensor_delay", "lost_steps")
EXTRA_EFFECTS = ("cogging", "radius_drift")

#: bench program: (frequency Hz, joint amplitude rad)
PROGRAM = ((0.37, 0.30), (1.13, 0.12), (2.9, 0.05), (6.7, 0.02), (14.3, 0.008))
ENVELOPE_PERIOD_S = 17.0
#: sensor: 12-bit magnetic encoder (AS5600) plus electrical noise
ENCODER_COUNTS = 4096
NOISE_RAD = 1.0e-3
#: inline load cell (5 kg S-beam, HX711 at 80 Hz): noise of the tension reading
LOAD_CELL_NOISE_N = 0.02


def bench_command(t: np.ndarray, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Commanded joint angle and its second derivative (analytic) [rad, rad/s^2] at times ``t``."""
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * np.pi, len(PROGRAM))
    we = 2 * np.pi / ENVELOPE_PERIOD_S
    pe = rng.uniform(0, 2 * np.pi)
    env = 0.725 + 0.275 * np.sin(we * t + pe)
    denv = 0.275 * we * np.cos(we * t + pe)
    ddenv = -0.275 * we**2 * np.sin(we * t + pe)
    s = np.zeros_like(t)
    ds = np.zeros_like(t)
    dds = np.zeros_like(t)
    for (f, a), ph in zip(PROGRAM, phases):
        w = 2 * np.pi * f
        s += a * np.sin(w * t + ph)
        ds += a * w * np.cos(w * t + ph)
        dds += -a * w * w * np.sin(w * t + ph)
    return env * s, ddenv * s + 2 * denv * ds + env * dds


@dataclass
class SynthLog:
    """A simulated log and its truth."""

    t: np.ndarray
    motor_angle_rad: np.ndarray
    joint_angle_rad: np.ndarray
    true_joint_angle_rad: np.ndarray
    effects: dict[str, float]
    n_slips: int
    integrator: str
    cable_tension_n: np.ndarray | None = None    # load cell on cable side A [N]


def parse_effects(specs: list[str] | None) -> dict[str, float]:
    """``["backlash", "sensor_delay=0.02"]`` -> {"backlash": 0.01, "sensor_delay": 0.02} (defaults filled in).
    Raises ValueError naming the bad item."""
    out: dict[str, float] = {}
    for spec in specs or []:
        name, _, val = spec.partition("=")
        name = name.strip()
        if name not in EFFECT_DEFAULTS:
            import difflib
            close = difflib.get_close_matches(name, list(EFFECT_DEFAULTS), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            raise ValueError(f"unknown effect '{name}'{hint}; known: {', '.join(EFFECT_DEFAULTS)}")
        if val.strip():
            try:
                v = float(val)
            except ValueError:
                raise ValueError(f"effect '{name}': value '{val}' is not a number "
                                 f"({EFFECT_DEFAULTS[name][2]} [{EFFECT_DEFAULTS[name][1]}])") from None
            if not math.isfinite(v):
                raise ValueError(f"effect '{name}': value {val} is not finite")
        else:
            v = EFFECT_DEFAULTS[name][0]
        if name in ("cable_compliance", "effective_radius") and v <= 0:
            raise ValueError(f"effect '{name}': value {v} must be > 0 ({EFFECT_DEFAULTS[name][2]})")
        if name in ("coulomb_friction", "viscous_friction", "quadratic_drag", "added_mass", "backlash",
                    "sensor_delay", "lost_steps") and v < 0:
            raise ValueError(f"effect '{name}': value {v} must be >= 0 ({EFFECT_DEFAULTS[name][2]})")
        out[name] = v
    return out


def simulate_joint(d: JointDesign, effects: dict[str, float] | None = None, *, duration_s: float = 40.0,
                   rate_hz: float = 1000.0, noise_rad: float = NOISE_RAD, seed: int = 0, substeps: int = 5,
                   encoder_counts: int | None = ENCODER_COUNTS, command=None,
                   force_integrator: bool = False) -> SynthLog:
    """Simulate the bench joint (module docstring) with the given effects (name -> value, see EFFECT_DEFAULTS).

    ``command(t) -> (theta, theta_ddot)`` replaces the bench program (joint angle [rad] and its second derivative);
    ``force_integrator`` uses the fixed-step integrator even where the exact linear solution applies."""
    eff = dict(effects or {})
    n = int(round(duration_s * rate_hz))
    h = 1.0 / (rate_hz * substeps)
    tf = np.arange(n * substeps) * h
    th_cmd, th_acc = bench_command(tf, seed) if command is None else command(tf)
    # controller: eq. 48 with the design ratio; integer microsteps, updated once per logged sample (a loop that reads
    # the sensor at t_i, then commands: the row's command acts from t_i on, its reading saw the rows before)
    steps = np.repeat(np.rint(th_cmd[::substeps] / d.ratio / d.microstep_rad), substeps)[: tf.size]
    phi_cmd_acc = th_acc / d.ratio
    rotor = steps * d.microstep_rad
    n_slips = 0
    if "lost_steps" in eff:
        ev = slip_signal(tf, phi_cmd_acc, eff["lost_steps"])
        n_slips = int(op.threshold_crossings(tf, phi_cmd_acc, eff["lost_steps"])[0].size)
        rotor = rotor - SLIP_FULL_STEPS * d.full_step_rad * ev
    if "cogging" in eff:
        period = SLIP_FULL_STEPS * d.full_step_rad
        rotor = rotor + eff["cogging"] * d.full_step_rad * np.sin(2 * np.pi * rotor / period)
    if eff.get("backlash", 0.0) > 0:
        # dead band at the spool hub (set screw on the shaft flat): the spool stays where friction holds it
        # until the shaft takes up the gap (motor-side gap = joint gap / ratio)
        rotor = op.play(rotor, 0.5 * eff["backlash"] / d.ratio)
    ratio = d.ratio * eff.get("effective_radius", 1.0)
    if "radius_drift" in eff:
        ratio = ratio * (1.0 + eff["radius_drift"] * tf / tf[-1])
    u = ratio * rotor                                     # joint angle the cable would impose if rigid
    if "capstan_creep" in eff:
        u = u + eff["capstan_creep"] * op.travel(u)
    K = d.stiffness_nm_rad * eff.get("cable_compliance", 1.0)
    J = d.link_inertia_kg_m2 + eff.get("added_mass", 0.0)
    c = d.bearing_damping_nm_s_rad + eff.get("viscous_friction", 0.0)
    b = eff.get("quadratic_drag", 0.0)
    tc = eff.get("coulomb_friction", 0.0)
    gap = 0.0  # the backlash dead band sits at the spool hub (above), not in the cable
    m = d.moment_arm_m
    t0 = d.pretension_n
    tau_slack = 2.0 * t0 * m

    theta = None
    integrator = "exact linear (ZOH)"
    if b == 0 and tc == 0 and gap == 0 and not force_integrator:
        # J th'' + c th' + K th = K u, exact for u piecewise constant over h
        sysd = signal.cont2discrete(([K], [J, c, K]), h, method="zoh")
        num = np.squeeze(sysd[0])
        den = sysd[1]
        zi = signal.lfilter_zi(num, den) * u[0]
        theta, _ = signal.lfilter(num, den, u, zi=zi)
        if np.max(np.abs(K * (u - theta))) > tau_slack:
            theta = None
    if theta is None:
        integrator = f"semi-implicit Euler, h = {h:.3g} s"
        theta = _integrate(u, h, K, J, c, b, tc, gap, m, t0)
    # sensor: delay, offset, noise, quantisation; sampled at rate_hz
    ts = tf[::substeps]
    true = theta[::substeps]
    delay_s = eff.get("sensor_delay", 0.0)
    meas = np.interp(ts - delay_s, tf, theta) if delay_s > 0 else true.copy()
    rng = np.random.default_rng(seed + 7919)
    meas = meas + eff.get("offset", 0.0) + rng.normal(0.0, noise_rad, ts.size)
    if encoder_counts:
        qenc = 2 * np.pi / encoder_counts
        meas = qenc * np.rint(meas / qenc)
    motor_log = steps[::substeps] * d.microstep_rad
    # load cell on side A: pretension plus the cable's share of the joint torque (k m (u - theta)), never < 0
    k_side = K / (2.0 * m * m)
    tension = np.maximum(0.0, t0 + k_side * m * (u[::substeps] - true))
    tension = tension + np.random.default_rng(seed + 104729).normal(0.0, LOAD_CELL_NOISE_N, ts.size)
    return SynthLog(ts, motor_log, meas, true, eff, n_slips, integrator, tension)


def _integrate(u, h, K, J, c, b, tc, gap, m, t0) -> np.ndarray:
    """Fixed-step semi-implicit Euler of the nonlinear joint (see module docstring). Pure Python loop."""
    n = u.size
    out = np.empty(n)
    th = float(u[0])
    w = 0.0
    half = 0.5 * gap
    k_side = K / (2.0 * m * m)                           # N/m per side
    mk = m * k_side
    for i, ui in enumerate(u.tolist()):
        out[i] = th                                       # state at t_i; u_i is held over [t_i, t_i+1) (ZOH)
        dlt = ui - th
        if half > 0.0:
            if dlt > half:
                dlt -= half
            elif dlt < -half:
                dlt += half
            else:
                dlt = 0.0
        # pull-pull: side tensions T0 +/- k m delta, none below zero
        ta = t0 + mk * dlt
        tb = t0 - mk * dlt
        if ta < 0.0:
            ta = 0.0
        if tb < 0.0:
            tb = 0.0
        tau = m * (ta - tb)
        if tc > 0.0:
            if w == 0.0:
                if -tc <= tau <= tc:
                    continue
                fr = tc if tau > 0 else -tc
            else:
                fr = tc if w > 0 else -tc
        else:
            fr = 0.0
        wn = (w + h * (tau - fr) / J) / (1.0 + h * (c + b * abs(w)) / J)
        if tc > 0.0 and w != 0.0 and (wn > 0.0) != (w > 0.0):
            wn = 0.0
        w = wn
        th += h * w
    return out
