"""Swimming run of the generated MJCF in MuJoCo: joints driven by the travelling wave.

The MJCF (exports/mjcf.py) carries water (``<option density viscosity>``, ellipsoid fluid model) and each
link's buoyancy at its centre of buoyancy (a welded ``<link>_buoyancy`` body with ``gravcomp``), so by default
nothing is added at run time: the fish floats, rights itself and swims as the file says.

``reactive=True`` adds the one force the file cannot carry: Lighthill's (1971) large-amplitude elongated-body
reactive force at the trailing edge of the caudal fin (:func:`lighthill_edge_force_n`), applied each step through
``data.xfrc_applied`` beside MuJoCo's own quasi-steady drag, lift and added mass. MuJoCo's fluid model is
quasi-steady: it has no wake, so it has no shed-momentum (reactive) thrust.

Joint commands: the relative joint angles of the travelling wave (physics.kinematics, eq. 43-47 in relative
form), faded in over ``ramp_s`` (the paper's start-up transient is 0.5-1 s), fed to the position actuators.

Root: ``planar=False`` keeps the file's free joint. ``planar=True`` replaces it (in memory, ``mujoco.MjSpec``)
by surge x, sway y and yaw z, the way a fish is held level in a swimming test. The default design is trimmed
by its mass model (flooded tail, lead ballast: neutral, COM straight under the COB), so it also swims free and
level; a design whose COM lies ahead of its COB would hang nose-down. Speeds are measured along the fish's mean
heading.

:func:`fluid_force_terms` splits MuJoCo's fluid force on one geom into the terms of its ellipsoid model, gives
the part of the added-mass force MuJoCo leaves out, and Lighthill's elongated-body reactive thrust for the
geom's trailing-edge motion (the reference for sign and size, meaningful for the caudal fin). SI units.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swiftfin.physics.kinematics import relative_joint_angles_rad, wave_from_params

FLUIDCOEF_DEFAULT = (0.5, 0.25, 1.5, 1.0, 1.0)
"""MuJoCo's default fluidcoef: blunt drag, slender drag, angular drag, Kutta lift, Magnus lift."""

FLUIDCOEF_HULL = (0.5, 0.25, 1.5, 0.0, 1.0)
"""The hull's ellipsoids (head and hull links): MuJoCo's defaults without the Kutta lift.

MuJoCo's Kutta term is the circulation lift of a wing whose sharp trailing edge sheds vorticity. The caudal fin is
such a wing and keeps it. The hull is not: its ellipsoids are slices of one closed, smooth body, and slender-body
theory (Munk 1924; Lighthill 1960) gives such a body no lift of its own: the lateral momentum one section gives the
water the next takes back, and only the trailing edge (the fin's) sheds it. What a body of revolution at incidence
does feel, the destabilising Munk moment, is in MuJoCo's added-mass term, which stays. Measured on the default design
(MuJoCo, free in six degrees of freedom, 30 s at 3 Hz): with the Kutta lift on every hull ellipsoid the fish
porpoises, a 0.22 Hz pitch oscillation that grows to +-20 deg (the lift of the head's ellipsoid, ahead of the centre
of mass, is a weathercock turned round); a 6 s run had hidden it (7.8 deg, still growing). Without it: level, pitch
within 1 deg, from the second second to the thirtieth. The same lift gave 40 % of MuJoCo's mean thrust at 3 Hz
(0.84 N on the four hull links against the fin's 1.29 N), thrust that slender-body theory does not have
(tests/test_mujoco_swim.py)."""


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
    planar: bool = False
    reactive_force_n: np.ndarray | None = None   # Lighthill's force at the fin's edge (world), per sample; None: off

    def window(self, t0_s: float | None = None) -> np.ndarray:
        """Samples from ``t0_s`` (default: half the run) to the end."""
        t0 = self.duration_s / 2 if t0_s is None else t0_s
        return self.time_s >= t0

    def forward_speed_m_s(self, t0_s: float | None = None) -> float:
        """Mean speed of the fish's COM along its mean heading (the head's +x axis averaged over the window),
        from ``t0_s`` (default: half the run) to the end. Positive = forward."""
        w = np.flatnonzero(self.window(t0_s))
        i, k = w[0], w[-1]
        heading = self.head_axis[w].mean(axis=0)
        heading /= np.linalg.norm(heading)
        return float((self.com_xyz_m[k] - self.com_xyz_m[i]) @ heading / (self.time_s[k] - self.time_s[i]))

    def joint_phase_lags_rad(self, t0_s: float | None = None) -> np.ndarray:
        """Phase lag of each joint's motion at the wave frequency, behind joint 1 [rad], in [0, 2 pi).

        A wave running from head to tail reaches each joint later than the one ahead of it, so the lags of
        successive joints increase (each step in (0, pi))."""
        w = self.window(t0_s)
        t = self.time_s[w]
        z = (self.joint_rad[w] * np.exp(-2j * np.pi * self.frequency_hz * t)[:, None]).sum(axis=0)
        # q_j = a cos(w t - lag_j)  ->  sum q_j e^{-i w t} ~ e^{-i lag_j}
        lag = -np.angle(z)
        return np.mod(lag - lag[0], 2 * np.pi)


#: Published thunniform swimmers' stride lengths U / (f L) [body lengths per tail-beat cycle], for comparison
#: only (nothing in the model is fitted to them): (swimmer, stride, source).
PUBLISHED_STRIDES = (
    ("Tunabot, 255 mm robot", 4.0 / 15.0, "Zhu et al. 2019, Sci. Robot. 4:eaax4615: 4.0 BL/s at 15 Hz"),
    ("Atlantic bluefin tuna, wild", 0.6 / 1.0, "Gleiss et al. 2019, R. Soc. Open Sci. 6:190203: 0.6 BL/s at ~1 Hz"),
    ("SwiftFin paper", 1.26, "SwiftFin paper: U* = 1.26 f BL/s"),
)


def free_swim_speed_m_s(model_path, params, frequency_hz: float, reactive: bool = False,
                        duration_s: float = 6.0) -> float:
    """Mean forward speed of the free fish (six degrees of freedom) over the second half of a run."""
    return swim(model_path, params, frequency_hz=frequency_hz, duration_s=duration_s, planar=False,
                reactive=reactive).forward_speed_m_s()


def load_model(model_path, planar: bool = False):
    """The MJCF as an MjModel; ``planar``: the head's free joint replaced by surge x, sway y and yaw z."""
    import mujoco
    if not planar:
        return mujoco.MjModel.from_xml_path(str(model_path))
    spec = mujoco.MjSpec.from_file(str(model_path))
    head = spec.worldbody.first_body()
    for jt in list(head.joints):
        if jt.type == mujoco.mjtJoint.mjJNT_FREE:
            spec.delete(jt)
    head.add_joint(name="root_x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0])
    head.add_joint(name="root_y", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0.0, 1.0, 0.0])
    head.add_joint(name="root_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0.0, 0.0, 1.0])
    return spec.compile()


class WaveDrive:
    """Commands of the travelling wave for the position actuators ``motor_1..n`` of a model."""

    def __init__(self, model, params, frequency_hz: float | None = None, ramp_s: float = 0.5,
                 amplitude_scale: float = 1.0, phase_lag_rad=None):
        import mujoco
        self.frequency_hz = params.swimming.tail_beat_frequency_hz if frequency_hz is None else frequency_hz
        self.L = params.body.length_mm / 1000.0
        self.wave = wave_from_params(params.swimming, self.L, self.frequency_hz)
        self.stations = np.asarray([s * self.L for s in params.joints.stations_fraction])
        n = params.joints.count
        self.act = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"motor_{j}") for j in range(1, n + 1)]
        jid = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"joint_{j}") for j in range(1, n + 1)]
        self.qadr = [model.jnt_qposadr[j] for j in jid]
        self.lo = model.actuator_ctrlrange[self.act, 0]
        self.hi = model.actuator_ctrlrange[self.act, 1]
        self.ramp_s, self.scale = ramp_s, amplitude_scale
        self.lag = None if phase_lag_rad is None else np.asarray(phase_lag_rad, dtype=float)

    def command(self, t: float) -> np.ndarray:
        if self.lag is None:
            u = relative_joint_angles_rad(self.wave, self.stations, self.L, [t])[0]
        else:
            lag_t = t - self.lag / self.wave.omega_rad_s
            u = np.array([relative_joint_angles_rad(self.wave, self.stations, self.L, [tj])[0][j]
                          for j, tj in enumerate(lag_t)])
        u = u * self.scale * (min(1.0, t / self.ramp_s) if self.ramp_s > 0 else 1.0)
        return np.clip(u, self.lo, self.hi)


def swim(model_path: str, params, frequency_hz: float | None = None, duration_s: float = 2.0,
         ramp_s: float = 0.5, amplitude_scale: float = 1.0, sample_every: int = 10, trim_neutral: bool = True,
         phase_lag_rad=None, initial_speed_m_s: float = 0.0, gravity: bool = True,
         planar: bool = False, added_mass: bool = True, initial_quat=None, reactive: bool = False,
         reactive_geom: str = "caudal_fin_fluid") -> SwimResult:
    """Run the fish in MuJoCo for ``duration_s`` with the wave at ``frequency_hz`` (default: design).

    ``trim_neutral``: scale every link's buoyancy by one factor so that buoyancy equals weight, as ballast
    trimming the fish neutral would (the design itself may be positively buoyant: mass_properties.json says by
    how much). ``phase_lag_rad``: optional per-joint phase lag added to the wave's command (joint j is fed
    the angle of time ``t - lag_j / omega``); None = the paper's wave. ``initial_speed_m_s``: start moving
    forward (+x) at this speed. ``initial_quat``: the free fish's starting orientation (w, x, y, z). ``gravity`` False: no gravity and no buoyancy (a control run). ``planar``: see
    the module docstring. ``added_mass`` False: a diagnosis only, never a result: the virtual mass of every
    fluid geom zeroed, which removes MuJoCo's half of the added-mass force (see :func:`fluid_force_terms`).

    ``reactive``: add Lighthill's reactive force at the trailing edge of ``reactive_geom`` (the caudal fin's thin
    fluid ellipsoid) every step (:class:`ReactiveFin`), beside MuJoCo's own fluid forces. Off by default, so that
    :func:`swim` is the exported file as any MuJoCo user runs it (the file cannot carry a state-dependent force);
    on, it is this project's swimming model, stated by the caller.
    """
    import mujoco
    model = load_model(model_path, planar)
    data = mujoco.MjData(model)
    if trim_neutral:
        lift = float((model.body_gravcomp * model.body_mass).sum())
        if lift > 0:
            model.body_gravcomp[:] *= float(model.body_mass.sum()) / lift
    if not gravity:
        model.opt.gravity[:] = 0.0
    if not added_mass:
        model.geom_fluid[:, 6:] = 0.0
    if initial_speed_m_s:
        data.qvel[0] = initial_speed_m_s
    if initial_quat is not None:
        if planar:
            raise ValueError("initial_quat needs the free joint (planar=False)")
        data.qpos[3:7] = np.asarray(initial_quat, dtype=float)
    drive = WaveDrive(model, params, frequency_hz, ramp_s, amplitude_scale, phase_lag_rad)
    fin = ReactiveFin(model, reactive_geom) if reactive else None
    head = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "head")
    steps = int(round(duration_s / model.opt.timestep))
    ts, head_x, com_x, q, cmd, axis, fr = [], [], [], [], [], [], []
    force = np.zeros(3)
    finite = True
    M = model.body_mass[1:].sum()
    for k in range(steps + 1):
        t = data.time
        data.ctrl[drive.act] = drive.command(t)
        if k % sample_every == 0:
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            ts.append(t)
            head_x.append(data.xpos[head].copy())
            axis.append(data.xmat[head].reshape(3, 3)[:, 0].copy())
            com_x.append((model.body_mass[1:, None] * data.xipos[1:]).sum(axis=0) / M)
            q.append(data.qpos[drive.qadr].copy())
            cmd.append(data.ctrl[drive.act].copy())
            fr.append(force.copy())
        if k == steps:
            break
        if fin is None:
            mujoco.mj_step(model, data)
        else:
            # the force of this step's state: positions and velocities first, then the force, then the step
            mujoco.mj_step1(model, data)
            force = fin.apply(model, data)
            mujoco.mj_step2(model, data)
        if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
            finite = False
            break
    warn = {mujoco.mjtWarning(i).name: int(data.warning[i].number) for i in range(len(data.warning))
            if data.warning[i].number}
    return SwimResult(drive.frequency_hz, duration_s, np.asarray(ts), np.asarray(head_x), np.asarray(com_x),
                      np.asarray(axis), np.asarray(q), np.asarray(cmd), finite, warn, planar,
                      np.asarray(fr) if reactive else None)


# ------------------------------------------------------------------------------------ reactive (Lighthill)
def added_mass_per_length_kg_m(density_kg_m3: float, span_m: float) -> float:
    """Lateral added mass per unit length of a flat cross-section of span ``span_m`` [kg/m]: rho pi (s/2)^2,
    the mass of water in the circle circumscribing the section (Lighthill 1960 and 1971; the potential-flow added
    mass of a flat plate moving normal to itself)."""
    return float(density_kg_m3) * np.pi * (float(span_m) / 2.0) ** 2


def lighthill_edge_force_n(added_mass_kg_m: float, velocity_m_s, tangent, span_axis=(0.0, 0.0, 1.0)):
    """Lighthill's large-amplitude reactive force on the fish at its trailing edge [N] (world vectors).

    Lighthill, M. J. (1971) Large-amplitude elongated-body theory of fish locomotion. Proc. R. Soc. Lond. B
    179, 125-138 (eq. 8-9 in vector form). Derivation: the water beside each cross-section carries the
    momentum m w n per unit length (m the lateral added mass per length, n the unit normal to the body in the
    plane of the motion, w = V . n the body's velocity relative to the water along n). Take the momentum
    balance of the water in a volume that ends in a plane through the trailing edge, normal to the body
    (tangent tau, pointing forward). That plane moves forward relative to the water at the edge's tangential
    speed u = V . tau, so it leaves the momentum m w n behind in the wake at the rate u: a force -m w u n on
    the fish. The pressure of the lateral flow on that plane (Bernoulli, -1/2 rho |grad phi|^2 integrated over
    the section: 1/2 m w^2) pushes the fish along +tau. Hence, at the edge,

        F = m w (1/2 w tau - u n),      m = rho pi (s/2)^2,   w = V . n,   u = V . tau,

    the momentum shed into the wake, with Lighthill's third term -d/dt int m w n ds (the rate of change of the
    momentum the water holds beside the body) left to MuJoCo's added-mass model (its mean over a period of a
    periodic motion is zero). F is even in n, so either normal will do. For a small travelling wave
    h(x, t) (x from the nose back, swimming forward at U): w = dh/dt + U dh/dx and the mean along the swimming
    direction is Lighthill's (1960) T = 1/2 m [<(dh/dt)^2> - U^2 <(dh/dx)^2>] at the edge; F = 0 when the
    wave runs back at the swimming speed (w = 0).

    Parameters
    ----------
    added_mass_kg_m : float  m at the trailing edge [kg/m] (:func:`added_mass_per_length_kg_m`).
    velocity_m_s : (3,) or (N, 3)  velocity of the trailing edge relative to the water far away [m/s].
    tangent : (3,) or (N, 3)  the body's tangent at the edge, pointing forward (toward the head) [-].
    span_axis : (3,) or (N, 3)  the span direction of the edge (vertical for a caudal fin) [-]; the motion
        along it is outside the theory (a 2-D cross-flow in each section) and gives no force.

    Returns
    -------
    (3,) or (N, 3)  the force on the fish [N], to be applied at the trailing edge.
    """
    V = np.asarray(velocity_m_s, dtype=float)
    e = np.asarray(span_axis, dtype=float)
    e = e / np.linalg.norm(e, axis=-1, keepdims=True)
    tau = np.asarray(tangent, dtype=float)
    tau = tau - (tau * e).sum(axis=-1, keepdims=True) * e            # in the plane of the motion
    tau = tau / np.linalg.norm(tau, axis=-1, keepdims=True)
    n = np.cross(e, tau)
    w = (V * n).sum(axis=-1, keepdims=True)
    u = (V * tau).sum(axis=-1, keepdims=True)
    return added_mass_kg_m * w * (0.5 * w * tau - u * n)


class ReactiveFin:
    """Lighthill's reactive force at the trailing edge of one thin fluid ellipsoid (the caudal fin's), applied
    to its body each step through ``data.xfrc_applied`` (world frame, at the body's COM: the force, and the
    moment of its offset from the COM to the edge).

    The ellipsoid's axes are the fin's: +x the chord toward the head (its -x end is the trailing edge), y the
    thickness, z the span (its full span 2 size_z sets m). Needs the positions and velocities of the current
    state (after ``mj_step1`` or ``mj_forward``)."""

    def __init__(self, model, geom: str = "caudal_fin_fluid"):
        import mujoco
        self.gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
        if self.gid < 0:
            raise ValueError(f"no geom {geom!r} in the model for the reactive force")
        self.body = int(model.geom_bodyid[self.gid])
        self.chord_half_m = float(model.geom_size[self.gid, 0])
        self.added_mass_kg_m = added_mass_per_length_kg_m(model.opt.density, 2.0 * model.geom_size[self.gid, 2])

    def edge(self, model, data):
        """Trailing edge: position, velocity [m, m/s], forward tangent and span axis, in the world."""
        import mujoco
        R = data.geom_xmat[self.gid].reshape(3, 3)
        c = data.geom_xpos[self.gid]
        te = c - R[:, 0] * self.chord_half_m
        v = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, self.gid, v, 0)   # [ang, lin] at c, world
        return te, v[3:] + np.cross(v[:3], te - c), R[:, 0].copy(), R[:, 2].copy()

    def apply(self, model, data) -> np.ndarray:
        """Set the body's ``xfrc_applied`` to the force at the edge; returns the force [N] (world)."""
        te, v, tau, span = self.edge(model, data)
        f = lighthill_edge_force_n(self.added_mass_kg_m, v, tau, span)
        data.xfrc_applied[self.body, :3] = f
        data.xfrc_applied[self.body, 3:] = np.cross(te - data.xipos[self.body], f)
        return f


# ----------------------------------------------------------------------------------------------- diagnosis
FLUID_TERMS = {
    # name: (which of the geom's own fluidcoef it keeps, keep the virtual mass/inertia of the added-mass term)
    "added_mass": ((0, 0, 0, 0, 0), True),
    "drag": ((1, 1, 1, 0, 0), False),
    "kutta_lift": ((0, 0, 0, 1, 0), False),
    "magnus_lift": ((0, 0, 0, 0, 1), False),
}


@dataclass(frozen=True)
class ThrustTerms:
    """Mean fluid force along the fish's heading on one geom, per term of MuJoCo's ellipsoid model [N],
    over the whole periods of the second half of a planar run with gravity off, and Lighthill's reactive
    thrust for the same trailing-edge motion."""
    frequency_hz: float
    speed_m_s: float                  # mean forward speed over the window
    total_n: float                    # MuJoCo, all terms together
    terms_n: dict                     # MuJoCo, one term at a time (FLUID_TERMS)
    lighthill_n: float                # 1/2 m_a <(dh/dt)^2 - U^2 h'^2> at the trailing edge (Lighthill 1960)
    te_lateral_rms_m_s: float         # rms lateral speed of the trailing edge
    added_mass_per_length_kg_m: float  # m_a = rho pi (span/2)^2
    pitch_heave_correlation: float    # corr(sin yaw of the geom, its lateral speed)
    omitted_added_mass_n: float       # mean of the added-mass term MuJoCo leaves out, -R rho m_v dv/dt


def fluid_force_terms(model_path, params, frequency_hz: float | None = None, duration_s: float = 3.0,
                     geom: str = "caudal_fin_fluid", sample_every: int = 5) -> ThrustTerms:
    """Split MuJoCo's fluid force on ``geom`` into its model's terms along the run of :func:`swim` (planar,
    no gravity), and give Lighthill's elongated-body mean thrust for the same motion as the reference.

    Each term is evaluated on a copy of the model in which ``geom`` keeps only that term and every other
    fluid geom keeps its interaction flag with zero coefficients (so that its body stays on the ellipsoid
    model and adds only the negligible Stokes term): the force of the run's own state, step by step.

    Lighthill (1960; 1971 for large amplitude), mean reactive thrust of an elongated body at the trailing edge:
    T = 1/2 m_a <(dh/dt)^2 - U^2 h'^2> (U forward, h' the edge's slope toward the tail), with
    m_a = rho pi (s/2)^2 the lateral added mass per unit length of the edge of span s: the mean along the
    heading of :func:`lighthill_edge_force_n`, m_a w (1/2 w - U h') with w = dh/dt + U h' for small slopes.
    (Until issue 15 this read 1/2 m_a <w^2 - U^2 h'^2>, which is short by m_a U <dh/dt h'>.)
    """
    import mujoco
    model = load_model(model_path, planar=True)
    model.opt.gravity[:] = 0.0
    data = mujoco.MjData(model)
    gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom)
    fluid = [g for g in range(model.ngeom) if model.geom_fluid[g, 0] > 0]
    probes = {}
    for name, (keep, keep_virtual) in {"total": ((1, 1, 1, 1, 1), True), **FLUID_TERMS}.items():
        coef = model.geom_fluid[gid, 1:6] * np.asarray(keep, dtype=float)
        m2 = load_model(model_path, planar=True)
        m2.opt.gravity[:] = 0.0
        for g in fluid:
            if g != gid:
                m2.geom_fluid[g, 1:] = 0.0
        m2.geom_fluid[gid, 1:6] = coef
        if not keep_virtual:
            m2.geom_fluid[gid, 6:] = 0.0
        probes[name] = (m2, mujoco.MjData(m2))
    drive = WaveDrive(model, params, frequency_hz)
    head = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "head")
    steps = int(round(duration_s / model.opt.timestep))
    period = 1.0 / drive.frequency_hz
    t_start = duration_s - period * np.floor(duration_s / 2 / period)      # whole periods to the end
    forces = {k: [] for k in probes}
    rows, v_local, R_geom, heads, t_s = [], [], [], [], []
    for k in range(steps):
        data.ctrl[drive.act] = drive.command(data.time)
        mujoco.mj_step(model, data)
        if data.time < t_start or k % sample_every:
            continue
        heading = data.xmat[head].reshape(3, 3)[:, 0]
        for name, (m2, d2) in probes.items():
            d2.qpos[:] = data.qpos
            d2.qvel[:] = data.qvel
            mujoco.mj_forward(m2, d2)
            # world force on the fish = generalized forces of surge and sway (planar root: x, y slides)
            forces[name].append(d2.qfrc_fluid[:2].copy())
        R = data.geom_xmat[gid].reshape(3, 3)
        v = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, gid, v, 0)   # world frame
        te = data.geom_xpos[gid] - R[:, 0] * model.geom_size[gid, 0]                 # trailing edge (-x end)
        v_te = v[3:] + np.cross(v[:3], te - data.geom_xpos[gid])
        lateral = np.cross(np.array([0.0, 0.0, 1.0]), heading)                        # fish's +y
        v_geom = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, gid, v_geom, 1)     # geom axes
        v_local.append(v_geom[3:].copy())
        R_geom.append(R.copy())
        heads.append(heading.copy())
        t_s.append(data.time)
        rows.append((v_te @ lateral, R[:, 0] @ lateral, data.qvel[0] * heading[0] + data.qvel[1] * heading[1],
                     v[3:] @ lateral))
    # forces along the mean heading of the window (a fixed direction: a periodic impulse then has no mean rate)
    e = np.asarray(heads)[:, :2].mean(axis=0)
    e /= np.linalg.norm(e)
    forces = {k: np.asarray(v) @ e for k, v in forces.items()}
    rows = np.asarray(rows)
    hdot, slope, U = rows[:, 0], rows[:, 1], float(rows[:, 2].mean())
    # h' = dh/dx along the body toward the tail; the geom's +x points to the head, so the slope toward the
    # tail is -(sin of its yaw) in the fish's lateral direction
    h_prime = -slope
    m_a = added_mass_per_length_kg_m(model.opt.density, 2.0 * float(model.geom_size[gid, 2]))
    # The added-mass (Kirchhoff) force of a rigid body in potential flow is F = -dP/dt with P = R (rho m_v v)
    # its fluid impulse (world frame): -R (rho m_v dv/dt) + R ((rho m_v v) x omega). MuJoCo keeps the second
    # term only (its passive forces cannot depend on accelerations); the first, omitted, is -dP/dt minus the
    # kept one. Over whole periods of a periodic motion -dP/dt averages to zero.
    P = np.einsum("kij,kj->ki", np.asarray(R_geom), float(model.opt.density) * model.geom_fluid[gid, 6:9]
                  * np.asarray(v_local))
    full = -np.gradient(P, np.asarray(t_s), axis=0)[:, :2] @ e
    omitted = full - forces["added_mass"]
    return ThrustTerms(drive.frequency_hz, U, float(np.mean(forces["total"])),
                       {k: float(np.mean(v)) for k, v in forces.items() if k != "total"},
                       float(0.5 * m_a * np.mean(hdot**2 - U**2 * h_prime**2)), float(np.sqrt(np.mean(hdot**2))),
                       m_a, correlation(slope, rows[:, 3]), float(np.mean(omitted)))


def correlation(a, b) -> float:
    """Pearson correlation of two samples; 0 where either does not vary."""
    a, b = np.asarray(a, dtype=float) - np.mean(a), np.asarray(b, dtype=float) - np.mean(b)
    den = float(np.sqrt((a @ a) * (b @ b)))
    return float(a @ b / den) if den > 0 else 0.0
