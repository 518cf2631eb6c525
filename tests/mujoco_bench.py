"""A second bench simulator for the joint fit, written apart from the engine (issue 14, item 3).

It shares no code with ``swiftfin.calibration`` (not its effect functions, not ``swiftfin synth``, not its
command program): only the design's numbers (spool and sector radii, cable size, modulus and route length, the
motor's catalogue values) come from the project. MuJoCo integrates a two-body bench:

* the **stepper** is a rotor of its catalogue inertia on a hinge, pulled toward the commanded microstep angle by
  the hybrid stepper's periodic torque ``T_hold sin((phi_cmd - phi) pi / (2 theta_fs))`` (one electrical
  cycle = 4 full steps), applied each step, so it has the finite stiffness of a real stepper and slips whole
  electrical cycles when its load passes the holding torque (that is how ``lost_steps`` arise here: a weak
  motor, not a threshold), plus a detent torque of period one full step (``cogging``: out of the library);
* the **cables** are two fixed tendons, ``r phi - d theta`` and its opposite, each a one-sided spring of stiffness
  E A / L in MuJoCo (``springlength`` range open below): each side pulls only when stretched, from its
  pretension, so a side goes slack when the load passes 2 T0 d, and a lost pretension leaves a dead band
  (``cable_slack``);
* the **link** is a body of the bench's inertia on a hinge with MuJoCo's viscous damping and dry friction
  (``frictionloss`` with a stiff ``solreffriction``), an optional ``b w |w|`` drag, a spring to its rest angle
  (a wire harness: out of the library);
* the **sensor** reads the link angle with an offset, a delay, a gain error (out of the library), noise and
  12-bit quantisation; an inline **load cell** reads side A's tension (MuJoCo's tendon length through the
  side's spring) with :data:`LOAD_CELL_NOISE_N` of noise, the log's optional ``cable_tension_n`` column.

The command is this module's own: four sines (0.5, 1.7, 4.1, 9.3 Hz) and smoothed random steps.
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

#: name -> (nominal size, what it is). Sizes scale these by 0.2x .. 5x in the confusion runs.
EFFECTS = {
    "viscous_friction": (0.02, "hinge viscous damping [N m s/rad]"),
    "coulomb_friction": (0.02, "hinge dry friction [N m]"),
    "cable_compliance": (9.0, "stiffness divided by (1 + size)"),
    "added_mass": (3e-4, "extra link inertia [kg m^2]"),
    "cable_slack": (0.15, "pretension lost: slack cable per side [mm]"),
    "offset": (0.02, "sensor zero error [rad]"),
    "sensor_delay": (0.006, "sensor latency [s]"),
    "effective_radius": (0.05, "spool radius error, relative"),
    "quadratic_drag": (0.003, "drag b of b w|w| [N m s^2/rad^2]"),
    "lost_steps": (1.0, "holding torque reduced to size x the peak load's"),
    # out of the library: the engine has no effect for these
    "hinge_spring": (0.05, "spring to the rest angle [N m/rad] (a wire harness)"),
    "cogging": (0.1, "the stepper's detent torque, a fraction of its holding torque, period one full step"),
    "sensor_gain": (0.04, "sensor scale error, relative"),
}
LIBRARY_NAMES = {"viscous_friction": ("viscous_friction",), "coulomb_friction": ("coulomb_friction",),
                 "cable_compliance": ("cable_compliance",), "added_mass": ("added_mass",),
                 "cable_slack": ("cable_slack",), "offset": ("offset",), "sensor_delay": ("sensor_delay",),
                 "effective_radius": ("effective_radius",), "quadratic_drag": ("quadratic_drag",),
                 "lost_steps": ("lost_steps", "stepper_torque")}
"""Each in-library effect of this bench and the engine's names for it. This bench's lost steps are a motor weaker
than its load (holding torque 0.06-0.3 % of the catalogue's: the bare link needs almost none), which slips where
the load passes it: the engine's ``lost_steps`` (slips at a threshold of the commanded acceleration) or
``stepper_torque`` (the weak stepper itself, slipping wherever its torque is passed) each name it."""
OUT_OF_LIBRARY = ("hinge_spring", "cogging", "sensor_gain")

RATE_HZ = 1000.0
SUBSTEPS = 5
NOISE_RAD = 1e-3
COUNTS = 4096
LOAD_CELL_NOISE_N = 0.05


@dataclass
class BenchDesign:
    """The design's numbers the bench is built from (SI)."""
    spool_radius_m: float
    arm_m: float
    side_stiffness_n_m: float
    pretension_n: float
    full_step_rad: float
    microsteps: int
    holding_torque_nm: float
    rotor_inertia_kg_m2: float
    link_inertia_kg_m2: float = 6e-6
    bearing_damping_nm_s_rad: float = 2e-4

    @classmethod
    def from_params(cls, p, joint: int | None = None) -> "BenchDesign":
        """From a design: the caudal joint's (default) spool, sector, cable and route."""
        from swiftfin.layout.geometry import cable_routes, spool_dims
        j = p.joints.count - 1 if joint is None else joint
        L = float(np.mean([rt.length_mm for rt in cable_routes(p) if rt.joint == j])) / 1000.0
        area = math.pi * (p.cable.diameter_mm / 2000.0) ** 2
        return cls(spool_dims(p).drum_radius_mm / 1000.0, p.joints.tendon_moment_arm_mm / 1000.0,
                   p.cable.youngs_modulus_gpa * 1e9 * area / L, p.cable.pretension_n,
                   math.radians(p.motor.full_step_deg), p.motor.microsteps, p.motor.holding_torque_nm,
                   p.motor.rotor_inertia_kg_m2)


@dataclass
class BenchLog:
    t: np.ndarray
    motor_angle_rad: np.ndarray        # commanded (microstep-quantised), the log's motor column
    joint_angle_rad: np.ndarray        # the sensor's reading
    true_joint_angle_rad: np.ndarray
    effects: dict = field(default_factory=dict)
    slips: int = 0
    cable_tension_n: np.ndarray | None = None


def command(t: np.ndarray, seed: int) -> np.ndarray:
    """Commanded joint angle [rad]: four sines and smoothed random steps (this bench's own program)."""
    rng = np.random.default_rng(seed + 1000)
    out = np.zeros_like(t)
    for f, a in ((0.5, 0.25), (1.7, 0.10), (4.1, 0.04), (9.3, 0.012)):
        out += a * np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi))
    steps = np.repeat(rng.uniform(-0.12, 0.12, int(t[-1] / 0.8) + 2), int(0.8 * RATE_HZ))[:t.size]
    k = int(0.08 * RATE_HZ)
    kernel = np.hanning(2 * k + 1)
    out += np.convolve(np.pad(steps, k, mode="edge"), kernel / kernel.sum(), mode="valid")
    return out


def _model(d: BenchDesign, e: dict, dt: float) -> str:
    k = d.side_stiffness_n_m / (1.0 + e.get("cable_compliance", 0.0))
    r = d.spool_radius_m * (1.0 + e.get("effective_radius", 0.0))
    slack = e.get("cable_slack", 0.0) / 1000.0
    t0 = 0.0 if slack > 0 else d.pretension_n
    # a side's length from alignment is +-(r phi - d theta); it pulls once longer than its free length
    free = slack - t0 / k
    root = ET.Element("mujoco", model="independent_joint_bench")
    ET.SubElement(root, "option", timestep=repr(dt), integrator="implicitfast", gravity="0 0 -9.81")
    wb = ET.SubElement(root, "worldbody")
    rotor = ET.SubElement(wb, "body", name="rotor", pos="0 0 0")
    ET.SubElement(rotor, "joint", name="motor", type="hinge", axis="0 0 1", damping="1e-4")
    ET.SubElement(rotor, "inertial", pos="0 0 0", mass="0.3",
                  diaginertia=" ".join([repr(d.rotor_inertia_kg_m2)] * 3))
    link = ET.SubElement(wb, "body", name="link", pos="0.1 0 0")
    attrs = {"name": "hinge", "type": "hinge", "axis": "0 0 1",
             "damping": repr(d.bearing_damping_nm_s_rad + e.get("viscous_friction", 0.0))}
    if e.get("coulomb_friction", 0.0) > 0:
        attrs |= {"frictionloss": repr(e["coulomb_friction"]), "solreffriction": f"{2 * dt!r} 1"}
    if e.get("hinge_spring", 0.0) > 0:
        attrs["stiffness"] = repr(e["hinge_spring"])
    ET.SubElement(link, "joint", attrs)
    J = d.link_inertia_kg_m2 + e.get("added_mass", 0.0)
    ET.SubElement(link, "inertial", pos="0 0 0", mass="0.01", diaginertia=" ".join([repr(J)] * 3))
    tendon = ET.SubElement(root, "tendon")
    for name, sgn in (("side_a", 1.0), ("side_b", -1.0)):
        f = ET.SubElement(tendon, "fixed", name=name, stiffness=repr(k), springlength=f"-10 {free!r}")
        ET.SubElement(f, "joint", joint="motor", coef=repr(sgn * r))
        ET.SubElement(f, "joint", joint="hinge", coef=repr(-sgn * d.arm_m))
    ET.SubElement(ET.SubElement(root, "contact"), "exclude", body1="rotor", body2="link")
    return ET.tostring(root, encoding="unicode")


def simulate(d: BenchDesign, effects: dict[str, float] | None = None, duration_s: float = 40.0,
             seed: int = 0) -> BenchLog:
    """A bench log with the ``effects`` (EFFECTS' names, values in their units)."""
    import mujoco

    e = dict(effects or {})
    n = int(duration_s * RATE_HZ)
    t = np.arange(n) / RATE_HZ
    dt = 1.0 / (RATE_HZ * SUBSTEPS)
    ratio = d.spool_radius_m / d.arm_m
    q = d.full_step_rad / d.microsteps
    theta_cmd = command(t, seed)
    phi_cmd = q * np.rint(theta_cmd / ratio / q)          # the controller's microsteps (design ratio)
    m = mujoco.MjModel.from_xml_string(_model(d, e, dt))
    data = mujoco.MjData(m)
    jm, jl = m.jnt_dofadr[0], m.jnt_dofadr[1]
    data.qpos[0] = phi_cmd[0]
    data.qpos[1] = phi_cmd[0] * ratio * (1 + e.get("effective_radius", 0.0))
    mujoco.mj_forward(m, data)
    hold = d.holding_torque_nm
    if "lost_steps" in e:       # a weak motor: size x the torque the bare bench needs at its peaks
        hold = e["lost_steps"] * _peak_motor_torque(d, theta_cmd, t)
    cyc = 4.0 * d.full_step_rad
    detent = e.get("cogging", 0.0) * d.holding_torque_nm
    b = e.get("quadratic_drag", 0.0)
    c_hinge = float(m.dof_damping[jl])
    theta = np.empty(n)
    motor = np.empty(n)
    length_a = np.empty(n)
    for i in range(n):
        # the row's reading is taken at t_i, before the row's command acts (a controller reads, then commands)
        theta[i] = data.qpos[1]
        motor[i] = data.qpos[0]
        length_a[i] = data.ten_length[0]
        for _ in range(SUBSTEPS):
            err = phi_cmd[i] - data.qpos[0]
            data.qfrc_applied[jm] = (hold * math.sin(2 * math.pi * err / cyc)
                                     - detent * math.sin(2 * math.pi * data.qpos[0] / d.full_step_rad))
            if b:       # b w|w| as a damping b|w| that MuJoCo integrates implicitly (explicit, it blows up at 5x)
                m.dof_damping[jl] = c_hinge + b * abs(data.qvel[jl])
            mujoco.mj_step(m, data)
    slips = int(round(abs(np.mean(motor[-2000:] - phi_cmd[-2000:])) / cyc))
    rng = np.random.default_rng(seed)
    read = theta * (1.0 + e.get("sensor_gain", 0.0))
    if e.get("sensor_delay", 0.0) > 0:
        read = np.interp(t - e["sensor_delay"], t, read)
    read = read + e.get("offset", 0.0) + rng.normal(0, NOISE_RAD, n)
    lsb = 2 * np.pi / COUNTS
    read = lsb * np.rint(read / lsb)
    k = m.tendon_stiffness[0]
    free = m.tendon_lengthspring[0][1]
    tension = np.maximum(0.0, k * (length_a - free)) + rng.normal(0, LOAD_CELL_NOISE_N, n)
    return BenchLog(t, phi_cmd, read, theta, e, slips, tension)


def _peak_motor_torque(d: BenchDesign, theta_cmd: np.ndarray, t: np.ndarray) -> float:
    """The motor torque the bare bench needs at its largest acceleration [N m]: the link's J a through the cable
    (tension difference J a / d, times r at the spool) and the rotor's own J_r a / ratio (cable ideal)."""
    a = float(np.max(np.abs(np.gradient(np.gradient(theta_cmd, t), t))))
    ratio = d.spool_radius_m / d.arm_m
    return a * (d.link_inertia_kg_m2 * d.spool_radius_m / d.arm_m + d.rotor_inertia_kg_m2 / ratio) + 1e-6


def sized(name: str, size: float) -> dict[str, float]:
    """The effect ``name`` at ``size`` x its nominal value, in simulate()'s terms."""
    nominal = EFFECTS[name][0]
    if name == "lost_steps":
        return {name: 1.0 / (1.0 + size)}        # larger size: a weaker motor, more slips
    return {name: nominal * size}


# ------------------------------------------------------------------------------------------- the confusion runs
@dataclass
class Case:
    label: str                      # e.g. "viscous_friction x1 seed 0"
    kind: str                       # "single", "pair", "control", "outside"
    truth: tuple[str, ...]          # this bench's effect names
    effects: dict
    seed: int


def cases(seeds=(0, 1, 2), sizes=(0.2, 1.0, 5.0)) -> list[Case]:
    """Single library effects at every size and seed, pairs, controls and out-of-library effects."""
    out = [Case(f"control seed {s}", "control", (), {}, s) for s in seeds]
    for name in LIBRARY_NAMES:
        for k in sizes:
            out += [Case(f"{name} x{k:g} seed {s}", "single", (name,), sized(name, k), s) for s in seeds]
    for a, b in (("viscous_friction", "offset"), ("coulomb_friction", "sensor_delay"),
                 ("added_mass", "effective_radius"), ("cable_slack", "viscous_friction")):
        out += [Case(f"{a} + {b} seed {s}", "pair", (a, b), sized(a, 1.0) | sized(b, 1.0), s) for s in seeds]
    for name in OUT_OF_LIBRARY:
        out += [Case(f"{name} x1 seed {s}", "outside", (name,), sized(name, 1.0), s) for s in seeds]
    return out


def visible(d: BenchDesign, case: Case, duration_s: float) -> float:
    """How far the case's effects move the sensor's reading, over the noise [-]: rms(reading with - without) / noise
    (noise-free readings). Below ~1 an effect is not in the log to be found."""
    if not case.effects:
        return 0.0
    base = simulate(d, {}, duration_s, case.seed)
    withe = simulate(d, case.effects, duration_s, case.seed)
    clean = lambda log: log.true_joint_angle_rad * (1 + log.effects.get("sensor_gain", 0.0))   # noqa: E731
    a, b = clean(base), clean(withe)
    if case.effects.get("sensor_delay", 0.0) > 0:
        b = np.interp(withe.t - case.effects["sensor_delay"], withe.t, b)
    b = b + case.effects.get("offset", 0.0)
    return float(np.sqrt(np.mean((b - a) ** 2)) / NOISE_RAD)


def run_case(d: BenchDesign, case: Case, folder, design_file: str, duration_s: float = 40.0) -> dict:
    """Simulate the case, fit it with `swiftfin fit joint` as a user would, and score it."""
    import contextlib
    import io
    import json
    from pathlib import Path

    from swiftfin.calibration.io import write_log
    from swiftfin.cli import main

    folder = Path(folder)
    log = simulate(d, case.effects, duration_s, case.seed)
    csv = folder / "log.csv"
    write_log(csv, {"time_s": log.t, "motor_angle_rad": log.motor_angle_rad, "joint_angle_rad": log.joint_angle_rad,
                    "cable_tension_n": log.cable_tension_n})
    # this bench holds its own light arm, not the design's tail: a bench file says so, as a user's would
    bench = folder / "bench.toml"
    bench.write_text(f"link_inertia_kg_m2 = {d.link_inertia_kg_m2!r}\n"
                     f"bearing_damping_nm_s_rad = {d.bearing_damping_nm_s_rad!r}\n")
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        rc = main(["fit", "joint", str(csv), "--design", design_file, "--bench", str(bench), "--out",
                   str(folder / "fit"), "--no-plots"])
    if rc != 0:
        return {"case": case, "refused": err.getvalue().strip().splitlines()[-1:], "named": [], "first": None,
                "confidence": None, "flagged": False, "slips": log.slips}
    rep = json.loads((folder / "fit" / "fit_report.json").read_text())
    named = [e["name"] for e in rep["added_effects"]]
    return {"case": case, "refused": None, "named": named, "first": named[0] if named else None,
            "confidence": rep["added_effects"][0]["confidence"] if named else None,
            "confidences": {e["name"]: e["confidence"] for e in rep["added_effects"]},
            "flagged": bool(rep["unexplained_structure"]), "slips": log.slips,
            "twin_declared": bool(named) and bool(rep["added_effects"][0].get("twins_outside")),
            "rmse_final": rep["final"]["rmse_holdout"]}


def score(results: list[dict]) -> dict:
    """The issue's measures: single library effects named first; controls with nothing named; pairs with both
    found; out-of-library effects flagged (unexplained structure) or left unnamed; wrong names at high confidence."""
    def right(r):
        return [n for t in r["case"].truth if t in LIBRARY_NAMES for n in LIBRARY_NAMES[t]]
    single = [r for r in results if r["case"].kind == "single"]
    out = {
        "single_first": sum(r["first"] in right(r) for r in single), "single_n": len(single),
        "controls_clean": sum(not r["named"] for r in results if r["case"].kind == "control"),
        "controls_n": sum(r["case"].kind == "control" for r in results),
        "pairs_both": sum(set(right(r)) <= set(r["named"]) for r in results if r["case"].kind == "pair"),
        "pairs_n": sum(r["case"].kind == "pair" for r in results),
        # flagged: structure left unexplained, or named as an effect whose report says what outside the library
        # leaves the same fingerprint (a sensor scale error is the effective radius's twin in these columns)
        "outside_flagged": sum(r["flagged"] or r.get("twin_declared", False)
                               for r in results if r["case"].kind == "outside"),
        "outside_n": sum(r["case"].kind == "outside" for r in results),
    }
    wrong_high = []
    for r in results:
        for name, conf in r.get("confidences", {}).items():
            if conf == "high" and name not in right(r):
                wrong_high.append((r["case"].label, name))
    out["wrong_high"] = wrong_high
    return out
