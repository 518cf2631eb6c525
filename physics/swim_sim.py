"""Swimming run of the generated MJCF in MuJoCo: joints driven by the travelling wave, buoyancy couple added.

The MJCF (exports/mjcf.py) carries water (``<option density viscosity>``, ellipsoid fluid model) and the
buoyant force of each link as ``gravcomp`` at its COM. What the file cannot say is that buoyancy acts at the
centre of buoyancy: :func:`swim` adds, every step, the couple ``(r_cob - r_com) x F_b`` of each link through
``xfrc_applied`` (world frame, at the COM), from the ``<link>_cob`` sites.

Joint commands: the relative joint angles of the travelling wave (physics.kinematics, eq. 43-47 in relative
form), faded in over ``ramp_s`` (the paper's start-up transient is 0.5-1 s), fed to the position actuators.
SI units throughout.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from physics.kinematics import relative_joint_angles_rad, wave_from_params


@dataclass(frozen=True)
class SwimResult:
    frequency_hz: float
    duration_s: float
    time_s: np.ndarray            # sample times
    head_xyz_m: np.ndarray        # head body origin (the nose) in the world, per sample
    com_xyz_m: np.ndarray         # whole-fish COM in the world, per sample
    head_axis: np.ndarray         # the head's +x axis (forward) in the world, per sample
    joint_rad: np.ndarray         # joint angles, per sample
    command_rad: np.ndarray       # commanded joint angles, per sample
    finite: bool                  # no NaN/inf in the state at any step
    warnings: dict                # MuJoCo warning counters that fired {name: count}

    def forward_speed_m_s(self, t0_s: float | None = None) -> float:
        """Mean +x speed of the fish's COM from ``t0_s`` (default: half the run) to the end."""
        t0 = self.duration_s / 2 if t0_s is None else t0_s
        i = int(np.searchsorted(self.time_s, t0))
        dt = self.time_s[-1] - self.time_s[i]
        return float((self.com_xyz_m[-1, 0] - self.com_xyz_m[i, 0]) / dt)


def buoyancy_couple(model, data, rho_w: float, g: float, volumes_m3: dict[int, float], cob_site: dict[int, int]):
    """Torque (world frame) of each body's buoyant force about its COM."""
    for b, V in volumes_m3.items():
        F = np.array([0.0, 0.0, rho_w * V * g])
        r = data.site_xpos[cob_site[b]] - data.xipos[b]
        data.xfrc_applied[b, 3:6] = np.cross(r, F)


def swim(model_path: str, params, frequency_hz: float | None = None, duration_s: float = 2.0,
         ramp_s: float = 0.5, amplitude_scale: float = 1.0, sample_every: int = 10, trim_neutral: bool = True,
         phase_lag_rad=None, initial_speed_m_s: float = 0.0, gravity: bool = True) -> SwimResult:
    """Run the fish in MuJoCo for ``duration_s`` with the wave at ``frequency_hz`` (default: design).

    ``trim_neutral``: scale every link's buoyancy by one factor so that buoyancy equals weight, as ballast
    trimming the fish neutral would (the design itself may be positively buoyant: mass_properties.json says by
    how much). ``phase_lag_rad``: optional per-joint phase lag added to the wave's command (joint j is fed
    the angle of time ``t - lag_j / omega``); None = the paper's wave. ``initial_speed_m_s``: start moving
    forward (+x) at this speed. ``gravity`` False: no gravity and no buoyancy (a control run).
    """
    import mujoco
    model = mujoco.MjModel.from_xml_path(str(model_path))
    data = mujoco.MjData(model)
    if trim_neutral:
        lift = float((model.body_gravcomp * model.body_mass).sum())
        if lift > 0:
            model.body_gravcomp[:] *= float(model.body_mass.sum()) / lift
    if not gravity:
        model.opt.gravity[:] = 0.0
    if initial_speed_m_s:
        data.qvel[0] = initial_speed_m_s
    f = params.swimming.tail_beat_frequency_hz if frequency_hz is None else frequency_hz
    L = params.body.length_mm / 1000.0
    wave = wave_from_params(params.swimming, L, f)
    stations = np.asarray([s * L for s in params.joints.stations_fraction])
    n = params.joints.count
    act = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"motor_{j}") for j in range(1, n + 1)]
    jid = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"joint_{j}") for j in range(1, n + 1)]
    qadr = [model.jnt_qposadr[j] for j in jid]
    lo = model.actuator_ctrlrange[act, 0]
    hi = model.actuator_ctrlrange[act, 1]
    rho_w = float(model.opt.density)
    g = float(-model.opt.gravity[2])
    volumes, cob = {}, {}
    for b in range(1, model.nbody):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b)
        s = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{name}_cob")
        if s >= 0:
            # gravcomp * m * g = rho_w V g  ->  V
            volumes[b] = float(model.body_gravcomp[b] * model.body_mass[b] / rho_w)
            cob[b] = s
    head = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "head")
    steps = int(round(duration_s / model.opt.timestep))
    ts, head_x, com_x, q, cmd, axis = [], [], [], [], [], []
    finite = True
    M = model.body_mass[1:].sum()
    for k in range(steps + 1):
        t = data.time
        if phase_lag_rad is None:
            u = relative_joint_angles_rad(wave, stations, L, [t])[0]
        else:
            lag_t = t - np.asarray(phase_lag_rad, dtype=float) / wave.omega_rad_s
            u = np.array([relative_joint_angles_rad(wave, stations, L, [tj])[0][j] for j, tj in enumerate(lag_t)])
        u = u * amplitude_scale * (min(1.0, t / ramp_s) if ramp_s > 0 else 1.0)
        data.ctrl[act] = np.clip(u, lo, hi)
        if k % sample_every == 0:
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            ts.append(t)
            head_x.append(data.xpos[head].copy())
            axis.append(data.xmat[head].reshape(3, 3)[:, 0].copy())
            com_x.append((model.body_mass[1:, None] * data.xipos[1:]).sum(axis=0) / M)
            q.append(data.qpos[qadr].copy())
            cmd.append(data.ctrl[act].copy())
        if k == steps:
            break
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        buoyancy_couple(model, data, rho_w, g, volumes, cob)
        mujoco.mj_step(model, data)
        if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
            finite = False
            break
    warn = {mujoco.mjtWarning(i).name: int(data.warning[i].number) for i in range(len(data.warning))
            if data.warning[i].number}
    return SwimResult(f, duration_s, np.asarray(ts), np.asarray(head_x), np.asarray(com_x), np.asarray(axis),
                      np.asarray(q),
                      np.asarray(cmd), finite, warn)
