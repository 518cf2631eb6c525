"""Replay a measured joint log through an exported MJCF in MuJoCo (issue 14, item 4: "the fit report replays the
measured command through the calibrated MJCF in MuJoCo and shows simulation vs measurement, error before and
after calibration").

The joint's drive is read from the MJCF by MuJoCo itself (its hinge damping, dry friction and armature, its
position servo's kp and kv), not from our files, and put on a one-hinge bench in MuJoCo: the bench's link
(:mod:`swiftfin.calibration.bench`) on the hinge, no gravity about the hinge axis, the servo driven by the
joint angle the stepper commands (the rigid capstan's microstep staircase, paper eq. 48). MuJoCo integrates it
(implicit-fast, :data:`SUBSTEPS` steps per sample); its joint angle is compared with the measured one.

* **before**: the joint as the MJCF exports it;
* **after**: the same joint with the fit's calibration applied by :func:`swiftfin.layout.servo.joint_servo`,
  the function ``swiftfin build --calibration`` writes the MJCF with, plus what the calibration measured of
  the bench itself: a fitted added inertia on the link, the spool-to-arm ratio on the command, and the
  sensor's zero offset and delay on the simulated reading.

What a MuJoCo joint cannot carry (a dead band, capstan creep, lost steps, quadratic drag on a bench with no
fluid) stays in the replay's error: the report says so.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from swiftfin.calibration.joint import JointDesign, rigid_joint_angle
from swiftfin.core.errors import UserError

SUBSTEPS = 5
"""MuJoCo steps per log sample (0.2 ms at 1 kHz: omega h ~ 0.1 on the stiffest bench the defaults give)."""


@dataclass(frozen=True)
class ReplayJoint:
    """A joint's drive as MuJoCo reads it from an MJCF."""
    damping_nm_s_rad: float
    friction_nm: float
    armature_kg_m2: float
    kp_nm_rad: float
    kv_nm_s_rad: float
    friction_timeconst_s: float = 0.02       # MuJoCo's solreffriction time constant (its default 0.02 s)


def joint_from_mjcf(path: str, joint: int) -> ReplayJoint:
    """Joint ``joint`` (1-based, ``joint_N``) of an exported MJCF and its position actuator, as MuJoCo loads them."""
    import mujoco

    try:
        m = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as exc:
        raise UserError(f"--mjcf {path}: MuJoCo cannot load it ({str(exc).splitlines()[0]})") from None
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, f"joint_{joint}")
    if jid < 0:
        raise UserError(f"--mjcf {path}: has no joint_{joint} (the log's joint)")
    acts = [a for a in range(m.nu) if m.actuator_trnid[a][0] == jid]
    if len(acts) != 1:
        raise UserError(f"--mjcf {path}: joint_{joint} has {len(acts)} actuators, expected its one position servo")
    a, dof = acts[0], m.jnt_dofadr[jid]
    return ReplayJoint(float(m.dof_damping[dof]), float(m.dof_frictionloss[dof]), float(m.dof_armature[dof]),
                       float(m.actuator_gainprm[a][0]), float(-m.actuator_biasprm[a][2]), float(m.dof_solref[dof][0]))


def bench_mjcf(rj: ReplayJoint, link_inertia_kg_m2: float, timestep_s: float) -> str:
    """A one-hinge bench in MJCF: the link's inertia about the hinge axis, the joint's drive."""
    root = ET.Element("mujoco", model="swiftfin_joint_bench")
    ET.SubElement(root, "option", timestep=repr(timestep_s), integrator="implicitfast", gravity="0 0 0")
    body = ET.SubElement(ET.SubElement(root, "worldbody"), "body", name="link")
    attrs = {"name": "hinge", "type": "hinge", "axis": "0 0 1", "damping": repr(rj.damping_nm_s_rad),
             "armature": repr(rj.armature_kg_m2)}
    if rj.friction_nm > 0:
        attrs["frictionloss"] = repr(rj.friction_nm)
        attrs["solreffriction"] = f"{max(rj.friction_timeconst_s, 2 * timestep_s)!r} 1"
    ET.SubElement(body, "joint", attrs)
    i = link_inertia_kg_m2
    ET.SubElement(body, "inertial", pos="0 0 0", mass="0.01", diaginertia=f"{i!r} {i!r} {i!r}")
    ET.SubElement(ET.SubElement(root, "actuator"), "position", name="servo", joint="hinge",
                  kp=repr(rj.kp_nm_rad), kv=repr(rj.kv_nm_s_rad))
    ET.SubElement(ET.SubElement(root, "sensor"), "jointpos", name="angle", joint="hinge")
    return ET.tostring(root, encoding="unicode")


def replay(t: np.ndarray, motor_angle_rad: np.ndarray, d: JointDesign, rj: ReplayJoint, link_inertia_kg_m2: float,
           ratio_scale: float = 1.0, offset_rad: float = 0.0, delay_s: float = 0.0) -> np.ndarray:
    """The joint angle MuJoCo gives at the log's times [rad]: the bench of :func:`bench_mjcf` driven by the
    commanded staircase (times ``ratio_scale``), each row's command acting from its time on and its reading taken
    before it (read, then command), read by a sensor with ``offset_rad`` and ``delay_s`` (negative: the log's
    reading leads that convention, as the fit's column alignment may have found)."""
    import mujoco
    from mujoco import rollout

    t = np.asarray(t, float)
    dt = float(np.median(np.diff(t)))
    m = mujoco.MjModel.from_xml_string(bench_mjcf(rj, link_inertia_kg_m2, dt / SUBSTEPS))
    data = mujoco.MjData(m)
    u = ratio_scale * rigid_joint_angle(motor_angle_rad, d)
    data.qpos[0] = u[0]
    mujoco.mj_forward(m, data)
    state = np.zeros(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(m, data, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.repeat(u, SUBSTEPS)[:, None]
    _, sens = rollout.rollout(m, data, state, ctrl[None])
    theta = sens[0, 0::SUBSTEPS, 0]         # a step's sensors see the state at its start: t_i, before u_i acts
    if delay_s:
        theta = np.interp(t - delay_s, t, theta)
    return theta + offset_rad


def replay_markdown(summary: dict, plot: bool) -> str:
    """The replay's section of ``fit_report.md``."""
    b, a = summary["before"], summary["after"]
    lines = ["## Replay in MuJoCo", "",
             f"The measured command replayed through `joint_{summary['joint']}` of `{summary['mjcf']}` (its drive read "
             f"by MuJoCo), on a one-hinge bench holding the bench's link ({summary['link_inertia_kg_m2']:.3g} kg m^2); "
             "simulated joint angle against the measured one over the whole log (the calibration was fitted on "
             "its training blocks).", "",
             "| | damping [N m s/rad] | friction [N m] | kp [N m/rad] | kv [N m s/rad] | RMSE [rad] |",
             "|---|---|---|---|---|---|"]
    for name, r in (("as exported", b), ("calibrated", a)):
        d = r["drive"]
        lines.append(f"| {name} | {d['damping_nm_s_rad']:.4g} | {d['friction_nm']:.4g} | {d['kp_nm_rad']:.4g} | "
                     f"{d['kv_nm_s_rad']:.4g} | {r['rmse_rad']:.4g} |")
    if summary["not_replayed"]:
        lines += ["", "Measured but not carried by a MuJoCo joint, so left in the calibrated replay's error: "
                  + ", ".join(summary["not_replayed"]) + "."]
    if plot:
        lines += ["", "![replay](replay.png)"]
    return "\n".join(lines) + "\n"


@dataclass
class Replay:
    """The replay before and after calibration: ``summary`` (the JSON's ``replay``: the drive each used, its RMSE
    against the measurement [rad], what the replay could not carry) and the traces it was computed from."""
    summary: dict
    t_s: np.ndarray
    measured_rad: np.ndarray
    sim_before_rad: np.ndarray
    sim_after_rad: np.ndarray


def plot_replay(res: Replay, path, window_s: float = 3.0) -> None:
    """The first ``window_s`` of the replay: measured, as exported, calibrated; and the two errors."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t, y, s = res.t_s, res.measured_rad, res.summary
    rows = np.flatnonzero(t - t[0] <= window_s)
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True, layout="constrained")
    ax[0].plot(t[rows], y[rows], ".", ms=2, color="0.4", label="measured")
    ax[0].plot(t[rows], res.sim_before_rad[rows], lw=1, color="tab:red", label="MuJoCo, MJCF as exported")
    ax[0].plot(t[rows], res.sim_after_rad[rows], lw=1, color="tab:blue", label="MuJoCo, calibrated")
    ax[0].set_ylabel("joint angle [rad]")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[0].set_title(f"replay through joint_{s['joint']} of {s['mjcf']}", fontsize=9)
    ax[1].plot(t[rows], (y - res.sim_before_rad)[rows], lw=0.8, color="tab:red",
               label=f"as exported (RMSE {s['before']['rmse_rad']:.3g} rad, whole log)")
    ax[1].plot(t[rows], (y - res.sim_after_rad)[rows], lw=0.8, color="tab:blue",
               label=f"calibrated (RMSE {s['after']['rmse_rad']:.3g} rad, whole log)")
    ax[1].set_xlabel("time [s]")
    ax[1].set_ylabel("measured - simulated [rad]")
    ax[1].legend(loc="upper right", fontsize=8)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def replay_report(ctx, mjcf: str, exported: ReplayJoint, params, joint_cal) -> Replay:
    """Replay a joint log's context ``ctx`` (its command, measurement and the bench's design constants) through
    ``exported`` (:func:`joint_from_mjcf` of ``mjcf``) and through the same joint calibrated with ``joint_cal``
    (a core.calibration.JointCalibration) on the design ``params`` (the calibration's revised design)."""
    from dataclasses import asdict

    from swiftfin.layout.servo import FRICTION_TIMECONST_S, joint_servo

    d: JointDesign = ctx.meta["design"]
    joint = d.joint + 1
    servo = joint_servo(params, joint, joint_cal)
    after = ReplayJoint(servo.damping_nm_s_rad, servo.friction_nm, servo.armature_kg_m2, servo.kp_nm_rad,
                        servo.kv_nm_s_rad, FRICTION_TIMECONST_S)

    def get(q: str, default: float) -> float:
        return default if joint_cal is None else joint_cal.get(q, default)
    inertia = d.link_inertia_kg_m2
    inertia_after = inertia + get("added_inertia_kg_m2", 0.0)
    motor = ctx.signals["input"]
    # the log's own timing, which the fit identified (calibration.joint.column_lag_s): how far its reading lags the
    # read-then-command convention the replay follows (half a sample past the base model's ramp); both replays
    # get it, as it belongs to the logger, not to the robot
    dt = float(np.median(np.diff(ctx.t)))
    timing = float(ctx.meta.get("column_lag_s", 0.5 * dt)) - 0.5 * dt
    sim_before = replay(ctx.t, motor, d, exported, inertia, delay_s=timing)
    sim_after = replay(ctx.t, motor, d, after, inertia_after, ratio_scale=get("spool_radius_ratio", 1.0),
                       offset_rad=get("sensor_offset_rad", 0.0), delay_s=get("sensor_delay_s", 0.0) + timing)
    y = np.asarray(ctx.y, float)

    def rmse(sim):
        return float(np.sqrt(np.mean((sim - y) ** 2)))
    left = [q for q in ("dead_band_rad", "creep_per_travel", "slip_rad", "drag_coefficient_nm_s2_rad2")
            if joint_cal is not None and q in joint_cal.values]
    summary = {"mjcf": str(mjcf), "joint": joint, "link_inertia_kg_m2": inertia,
               "before": {"drive": asdict(exported), "rmse_rad": rmse(sim_before)},
               "after": {"drive": asdict(after), "link_inertia_kg_m2": inertia_after, "rmse_rad": rmse(sim_after)},
               "not_replayed": left}
    return Replay(summary, np.asarray(ctx.t, float), y, sim_before, sim_after)
