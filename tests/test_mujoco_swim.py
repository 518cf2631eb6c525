"""Swimming in MuJoCo: the REAL default design (exports.robot.write_robot from every part family of the default
parameter file), driven by the travelling wave (physics.kinematics, eq. 43-47, relative joint angles).

Checked here: the wave runs from head to tail in the simulated joints; a positive joint angle turns the tail
toward +y; the fluid geoms are the head's envelope, slender hull-link slices and a thin-plate caudal fin of
the fin's span and area, with MuJoCo's default coefficients on the fin and the hull's without their Kutta lift
(physics.swim_sim.FLUIDCOEF_HULL, argued there; test_free_fish_stays_level_for_30_s_and_why is its control). The
fish is trimmed by the mass model (flooded tail, lead ballast: neutral, COM under the COB) and swims forward free in
all six degrees of freedom, staying level, and held level (planar) for the speed table, at about a twenty-fifth of
the paper's speed. Why so slow (test_what_limits_the_speed_in_mujoco): MuJoCo's quasi-steady model has no reactive
(shed-wake) thrust - its Kutta lift on the fin is ~1/14 of Lighthill's elongated-body thrust for the same tail
motion - and its added-mass force keeps only (rho m_v v) x omega of the Kirchhoff force, dropping -rho m_v dv/dt:
the whole force has zero mean over a period, MuJoCo's half a backward one.

Slow: the default design's parts (~15-30 s, once per session) and its robot folder (~20-40 s) are built here.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from swiftfin.layout import geometry as layout
from swiftfin.physics.kinematics import relative_joint_angles_rad, wave_from_params
from tests.conftest import require_module

mujoco = require_module("mujoco", "MuJoCo (the mujoco package) runs the swimming model")
from swiftfin.physics.swim_sim import (FLUIDCOEF_DEFAULT, FLUIDCOEF_HULL, fluid_force_terms,  # noqa: E402
                                        load_model, swim)

pytestmark = pytest.mark.slow

PAPER_BL_PER_S_PER_HZ = 1.26          # SwiftFin paper, measured U* = 1.26 f body lengths per second
SPEED_RUN_S = 6.0                     # long enough for a steady mean speed (checked below)


@pytest.fixture(scope="module")
def real_robot(default_robot):
    out, res = default_robot
    return out / "robot" / "swiftfin.xml", res


@pytest.fixture(scope="module")
def speeds(real_robot, default_params):
    """Planar runs (surge, sway, yaw free) of SPEED_RUN_S at 1, 2 and 3 Hz: {f: SwimResult}."""
    path, _ = real_robot
    return {f: swim(path, default_params, frequency_hz=f, duration_s=SPEED_RUN_S, planar=True)
            for f in (1.0, 2.0, 3.0)}


def test_the_model_is_the_real_fish(real_robot, default_params, default_parts):
    """Every family of the default design is in the model, and its masses are those of the real parts."""
    path, res = real_robot
    families = {pt.family for pt in default_parts}
    assert {"hull", "link", "fin", "spool", "mount", "guide", "bought"} <= families
    model = load_model(path)
    total = sum(lk.inertial.mass_kg for lk in res["robot"].links)
    rho = default_params.environment.water_density_kg_m3
    water = sum(lk.entrained_water.mass_kg for lk in res["robot"].links if lk.entrained_water is not None)
    # in water the flooded tail links carry the water inside them
    assert model.body_mass[1:].sum() == pytest.approx(total + water, rel=1e-9)
    assert sum(lk.in_water(rho)[0].mass_kg for lk in res["robot"].links) == pytest.approx(total + water, rel=1e-12)
    assert total == pytest.approx(res["total_mass_kg"], rel=1e-9)
    assert total > 1.0                                   # the real fish (the box stand-in weighs ~0.1 kg)
    assert water > 0.1                                   # the flooded tail's water: ~0.33 kg


def test_mjcf_compiles_and_steps_with_no_warnings(real_robot):
    path, _ = real_robot
    for planar in (False, True):
        model = load_model(path, planar)
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        for _ in range(100):
            mujoco.mj_step(model, data)
        assert [mujoco.mjtWarning(i).name for i, w in enumerate(data.warning) if w.number] == []


def test_two_seconds_of_swimming_at_the_design_frequency(real_robot, default_params):
    path, _ = real_robot
    r = swim(path, default_params, duration_s=2.0)
    assert r.frequency_hz == default_params.swimming.tail_beat_frequency_hz
    assert r.finite
    assert r.warnings == {}
    assert np.all(np.isfinite(r.com_xyz_m))
    # the joints follow the wave (position servos at the stepper's stiffness, torque limited)
    late = r.time_s > 1.0
    err = np.abs(r.joint_rad[late] - r.command_rad[late]).max(axis=0)
    amp = np.abs(r.command_rad[late]).max(axis=0)
    assert np.all(err < 0.5 * amp), (err, amp)
    # the body wave is real: the tail swings
    assert np.ptp(r.joint_rad[late, -1]) > 0.5 * 2 * amp[-1]
    # the fish moves forward along its own heading, free in all six degrees of freedom, and stays level
    assert r.forward_speed_m_s() > 0
    assert np.degrees(np.abs(np.arcsin(r.head_axis[:, 2]))).max() < 10.0


def test_the_wave_runs_from_head_to_tail_in_the_sim(speeds, default_params):
    """The joints' phase lags at the wave frequency grow from joint 1 to joint 4 (each step in (0, pi)), in
    the simulated joint angles, and match the lags of the commanded wave computed here from eq. 43-47."""
    p = default_params
    L = p.body.length_mm / 1000
    for f, r in speeds.items():
        lag = r.joint_phase_lags_rad()
        steps = np.diff(lag)
        assert np.all((steps > 0) & (steps < np.pi)), (f, lag)
        # lags of the command, from the wave itself over one period
        wave = wave_from_params(p.swimming, L, f)
        t = np.linspace(0, 1 / f, 720, endpoint=False)
        q = relative_joint_angles_rad(wave, np.array(p.joints.stations_fraction) * L, L, t)
        z = (q * np.exp(-2j * np.pi * f * t)[:, None]).sum(axis=0)
        cmd_lag = np.mod(-np.angle(z) + np.angle(z[0]), 2 * np.pi)
        assert np.all(np.diff(cmd_lag) > 0)
        # the servos lag the command a little, joint by joint alike: relative lags agree within 0.35 rad
        assert np.allclose(lag, cmd_lag, atol=0.35), (f, lag, cmd_lag)


def test_positive_joint_angle_turns_the_tail_to_plus_y(real_robot):
    """Body frame +x forward, +y left: a positive joint angle turns the child's tail toward +y. Closed form
    for joint 4 at theta: the fin's centre, at (px, py) in link_4's frame, goes to y = -px sin theta +
    py cos theta (a turn about -z)."""
    path, _ = real_robot
    model = load_model(path, planar=True)
    data = mujoco.MjData(model)
    fin = model.geom("caudal_fin_fluid").id
    px, py = model.geom_pos[fin][:2]
    assert px < 0                                        # the fin is behind joint 4
    for j in (1, 2, 3, 4):
        data.qpos[:] = 0
        data.qpos[model.jnt_qposadr[model.joint(f"joint_{j}").id]] = 0.2
        mujoco.mj_kinematics(model, data)
        assert data.geom_xpos[fin][1] > 0.005, j
    data.qpos[:] = 0
    data.qpos[model.jnt_qposadr[model.joint("joint_4").id]] = 0.2
    mujoco.mj_kinematics(model, data)
    y0 = data.xpos[model.body("link_4").id][1]
    assert data.geom_xpos[fin][1] - y0 == pytest.approx(-px * np.sin(0.2) + py * np.cos(0.2), abs=1e-12)


def test_fluid_geoms(real_robot, default_params, default_parts):
    """Each link has its own fluid ellipsoid with MuJoCo's default coefficients (nothing tuned); the hull links'
    are slender (exports.robot_model.fluid_ellipsoid); the caudal fin has its own thin-plate ellipsoid on
    link_4: the fin's span, an ellipse of the fin's planform area (S = b^2 / aspect ratio, cad/fin.py)
    centred at the area centroid, and the blade's thickness."""
    from swiftfin.layout.fin_plan import planform
    p = default_params
    path, res = real_robot
    model = load_model(path)
    fluid = [g for g in range(model.ngeom) if model.geom_fluid[g, 0] > 0 and model.geom_fluid[g, 1:6].any()]
    names = {model.geom(g).name for g in fluid}
    assert names == {f"{lk.name}_fluid" for lk in res["robot"].links} | {"caudal_fin_fluid"}
    # the buoyancy bodies' specks are on the ellipsoid model with every coefficient zero: they add no force
    specks = [g for g in range(model.ngeom) if model.geom_fluid[g, 0] > 0 and g not in fluid]
    assert {model.geom(g).name for g in specks} == {f"{lk.name}_buoyancy" for lk in res["robot"].links}
    for g in specks:
        assert model.geom_size[g, 0] <= 1e-4 and not model.geom_fluid[g, 1:6].any()
    for g in fluid:
        assert model.geom_type[g] == mujoco.mjtGeom.mjGEOM_ELLIPSOID
        # MuJoCo's defaults on the fin; the hull's slices of a smooth body without the Kutta lift (FLUIDCOEF_HULL)
        want = FLUIDCOEF_DEFAULT if model.geom(g).name == "caudal_fin_fluid" else FLUIDCOEF_HULL
        assert np.allclose(model.geom_fluid[g, 1:6], want), model.geom(g).name
        assert np.all(model.geom_fluid[g, 6:12] > 0)     # MuJoCo's virtual mass and inertia of the ellipsoid
    # hull links: slender slices (length, mean height; thinner than long), not disks facing the flow
    bounds = [0.0, *layout.joint_stations_mm(p), layout.hull_end_mm(p)]
    for j in range(1, p.joints.count + 1):
        ax, ay, az = model.geom_size[model.geom(f"link_{j}_fluid").id] * 1000
        st = np.linspace(bounds[j], bounds[j + 1], 401)
        assert ax == pytest.approx((bounds[j + 1] - bounds[j]) / 2, rel=1e-9)
        assert az == pytest.approx(np.mean(layout.half_height_mm(p, st)), rel=1e-9)
        assert p.hull.wall_thickness_mm / 2 <= ay <= np.mean(layout.naca_half_width_mm(p, st)) * (1 + 1e-9)
        assert ay < ax, j
    fin = model.geom("caudal_fin_fluid").id
    assert model.geom_bodyid[fin] == model.body("link_4").id
    chord, thickness, span = model.geom_size[fin]
    b_m = p.caudal_fin.span_mm / 1000
    assert span == pytest.approx(b_m / 2, rel=1e-12)
    assert np.pi * chord * span == pytest.approx(b_m**2 / p.caudal_fin.aspect_ratio, rel=1e-9)
    assert planform(p).area_mm2 == pytest.approx(p.caudal_fin.span_mm**2 / p.caudal_fin.aspect_ratio)
    fins = [pt.solid.bounding_box() for pt in default_parts if pt.family == "fin"]
    assert thickness == pytest.approx((max(bb.max.Y for bb in fins) - min(bb.min.Y for bb in fins)) / 2000,
                                      rel=1e-9)
    assert thickness < 0.2 * chord and span > 3 * chord  # a thin lifting plate, span vertical
    # centre behind the hull end, inside the fin's bounding box in x
    centre_x = model.geom_pos[fin][0] + res["report"].links[-1].origin_m[0]
    assert min(bb.min.X for bb in fins) / 1000 < centre_x < -layout.hull_end_mm(p) / 1000


def test_no_wave_no_motion(real_robot, default_params):
    """Control: joints held straight, no gravity or buoyancy: the fish stays put (no spurious forces)."""
    path, _ = real_robot
    r = swim(path, default_params, duration_s=1.0, amplitude_scale=0.0, gravity=False)
    assert r.finite
    assert np.linalg.norm(r.com_xyz_m[-1] - r.com_xyz_m[0]) < 1e-6


def test_trimmed_fish_rests_level_and_neutral(real_robot, default_params):
    """The mass model trims the design (flooded tail, lead ballast): buoyancy equals weight, and the COB lies above
    the COM, as nearly straight above it as the lead's fill can be put (it misses the level station by
    ``trim.fill_miss_x_m``: the static pitch ``atan(lead / height)``, within environment.max_static_pitch_deg).
    Free in still water, with no wave and no scaling of the buoyancy, the fish neither rises nor sinks, and it
    pitches no further than twice that angle (an undamped swing about it)."""
    path, res = real_robot
    data = json.loads((path.parent.parent / "mass_properties.json").read_text())
    t = data["total"]
    assert t["buoyancy_n"] == pytest.approx(t["weight_n"], rel=1e-9)
    assert t["cob_above_com_m"] > 0.005
    pitch = math.atan2(abs(t["com_ahead_of_cob_m"]), t["cob_above_com_m"])
    assert math.degrees(pitch) <= default_params.environment.max_static_pitch_deg
    assert data["trim"]["possible"] and data["trim"]["mass_kg"] > 0
    r = swim(path, default_params, duration_s=1.0, amplitude_scale=0.0, trim_neutral=False)
    assert np.linalg.norm(r.com_xyz_m[-1] - r.com_xyz_m[0]) < 1e-4
    assert np.abs(r.head_axis[:, 2]).max() < math.sin(2 * pitch) + 1e-4


def test_buoyancy_at_the_cob_rights_a_pitched_fish(real_robot, default_params):
    """The couple of buoyancy at the COB and weight at the COM is a restoring one: a fish started 20 deg nose
    down comes back toward level (COB above COM)."""
    path, _ = real_robot
    import mujoco as mj
    q = np.zeros(4)
    mj.mju_axisAngle2Quat(q, np.array([0.0, 1.0, 0.0]), np.radians(20.0))    # +y rotation: nose (+x) down
    r = swim(path, default_params, duration_s=3.0, amplitude_scale=0.0, initial_quat=q)
    pitch = np.degrees(np.arcsin(r.head_axis[:, 2]))
    assert pitch[0] == pytest.approx(-20.0, abs=0.1)
    assert abs(pitch[-1]) < 0.5 * abs(pitch[0])


def test_free_fish_swims_forward_and_level_at_1_2_3_hz(real_robot, default_params, capsys):
    """Free in all six degrees of freedom (no planar constraint), SPEED_RUN_S at 1, 2 and 3 Hz: forward, faster
    with frequency, pitch within +-10 deg, depth within 5 cm (printed with -s)."""
    path, _ = real_robot
    rows = []
    for f in (1.0, 2.0, 3.0):
        r = swim(path, default_params, frequency_hz=f, duration_s=SPEED_RUN_S, planar=False)
        assert r.finite and r.warnings == {}
        pitch = np.degrees(np.arcsin(r.head_axis[:, 2]))
        dz = r.com_xyz_m[:, 2] - r.com_xyz_m[0, 2]
        u = r.forward_speed_m_s()
        assert u > 0, f
        assert np.abs(pitch).max() < 10.0, (f, pitch.min(), pitch.max())
        assert np.abs(dz).max() < 0.05, f
        rows.append((f, u, pitch.min(), pitch.max(), np.abs(dz).max()))
    assert rows[0][1] < rows[1][1] < rows[2][1]
    L = default_params.body.length_mm / 1000
    with capsys.disabled():
        print(f"\n  MuJoCo, real default design, FREE (6 DOF), {SPEED_RUN_S:.0f} s runs (mean over the last half):")
        for f, u, pmin, pmax, dz in rows:
            print(f"  f = {f:.0f} Hz: {u:+.3f} m/s = {u / L:+.3f} BL/s; pitch {pmin:+.1f}..{pmax:+.1f} deg; "
                  f"depth change <= {1000 * dz:.0f} mm; paper {PAPER_BL_PER_S_PER_HZ * f:.2f} BL/s")


def test_free_fish_stays_level_for_30_s_and_why(real_robot, default_params, tmp_path, capsys):
    """A 6 s run cannot tell a level fish from one whose pitch oscillation is slowly growing. Free in six degrees
    of freedom for 30 s at the design frequency, the exported fish keeps its pitch within 5 deg throughout, and
    it does not grow: the last 10 s swing no more than the 10 s before them (+0.5 deg).

    The control, the reason the hull's ellipsoids carry no Kutta lift (physics.swim_sim.FLUIDCOEF_HULL): the
    same file with MuJoCo's default coefficients on every ellipsoid (the fluidcoef attributes taken out) porpoises,
    a slow pitch oscillation that grows past 10 deg within the 30 s (measured: +-20 deg, 0.22 Hz)."""
    import shutil
    from swiftfin.exports.urdf import fmt
    path, _ = real_robot
    f = default_params.swimming.tail_beat_frequency_hz
    seconds = 30.0
    text = path.read_text()
    hull = f' fluidcoef="{fmt(*FLUIDCOEF_HULL)}"'
    assert text.count(hull) == default_params.joints.count + 1
    plain = tmp_path / "robot" / path.name
    shutil.copytree(path.parent, plain.parent)
    plain.write_text(text.replace(hull, ""))
    rows = {}
    for label, file in (("exported", path), ("hull with Kutta lift", plain)):
        r = swim(file, default_params, frequency_hz=f, duration_s=seconds, planar=False)
        assert r.finite and r.warnings == {}
        pitch = np.degrees(np.arcsin(r.head_axis[:, 2]))
        n = len(pitch)
        late, before = pitch[n * 2 // 3:], pitch[n // 3:n * 2 // 3]
        rows[label] = (np.abs(pitch).max(), np.ptp(before), np.ptp(late), r.forward_speed_m_s())
    big, swing_before, swing_late, _ = rows["exported"]
    assert big < 5.0 and swing_late <= swing_before + 0.5, rows["exported"]
    assert rows["hull with Kutta lift"][0] > 10.0, rows["hull with Kutta lift"]
    with capsys.disabled():
        print(f"\n  MuJoCo, FREE, {seconds:.0f} s at {f:g} Hz: largest pitch, pitch swing over 10-20 s and "
              "20-30 s, speed")
        for label, (big, b, late, u) in rows.items():
            print(f"  {label:22s}: {big:5.1f} deg, {b:5.1f} / {late:5.1f} deg, {u:+.3f} m/s")


def test_speeds_at_1_2_3_hz(speeds, default_params, capsys):
    """MuJoCo's speed of the real fish at 1, 2, 3 Hz (planar, SPEED_RUN_S each, mean over the second half)
    beside the paper's U* = 1.26 f BL/s and the wave speed f lambda (printed with -s)."""
    p = default_params
    L = p.body.length_mm / 1000
    lam = p.swimming.wavelength_body_lengths * L
    rows = []
    for f, r in speeds.items():
        assert r.finite and r.warnings == {}
        u = r.forward_speed_m_s()
        # near-steady: the last third agrees with the second half
        u_late = r.forward_speed_m_s(t0_s=2 * SPEED_RUN_S / 3)
        assert abs(u_late - u) < 0.15 * abs(u) + 0.005, (f, u, u_late)
        assert 0 < u < f * lam                          # forward, slower than the body wave
        rows.append((f, u, u / L, PAPER_BL_PER_S_PER_HZ * f, u / (f * lam)))
    assert rows[0][1] < rows[1][1] < rows[2][1]         # faster with frequency
    paper_slip = PAPER_BL_PER_S_PER_HZ / p.swimming.wavelength_body_lengths
    with capsys.disabled():
        print(f"\n  MuJoCo, real default design, planar, {SPEED_RUN_S:.0f} s runs (mean over the last half):")
        for f, u, ustar, paper, slip in rows:
            print(f"  f = {f:.0f} Hz: {u:+.3f} m/s = {ustar:+.3f} BL/s (U/(f lambda) = {slip:+.3f}); "
                  f"paper {paper:.2f} BL/s (U/(f lambda) = {paper_slip:.2f})")


def test_what_limits_the_speed_in_mujoco(real_robot, default_params):
    """The evidence for the module docstring's 'why so slow', at the design frequency: the mean force along
    the heading on every fluid geom, term by term, over whole periods of a planar run at steady speed."""
    path, _ = real_robot
    p = default_params
    model = load_model(path)
    geoms = [model.geom(g).name for g in range(model.ngeom) if model.geom_fluid[g, 0] > 0]
    terms = {g: fluid_force_terms(path, p, duration_s=4.0, geom=g) for g in geoms}
    fin = terms["caudal_fin_fluid"]
    total = {k: sum(t.terms_n[k] for t in terms.values()) for k in fin.terms_n}
    for g, t in terms.items():
        # the terms of MuJoCo's model add up to its total on the geom (each probe adds the geom's Stokes drag,
        # ~1e-3 N: 3 extra copies)
        assert sum(t.terms_n.values()) == pytest.approx(t.total_n, abs=0.01), g
        # the added-mass force MuJoCo leaves out (-rho m_v dv/dt) cancels the mean of the part it keeps: the
        # whole potential-flow force, -dP/dt of a periodic impulse, has zero mean
        assert abs(t.terms_n["added_mass"] + t.omitted_added_mass_n) < 0.05 * abs(t.terms_n["added_mass"]) + 1e-3
    thrust = total["kutta_lift"] + total["magnus_lift"]
    # steady forward speed: thrust (Kutta and Magnus lift) balances drag and the spurious added-mass mean
    assert fin.speed_m_s > 0
    assert thrust > 0 and total["drag"] < 0 and total["added_mass"] < 0
    assert abs(sum(t.total_n for t in terms.values())) < 0.05 * thrust
    # the spurious added-mass mean sits mostly on the fin
    assert fin.terms_n["added_mass"] < 0.5 * total["added_mass"]
    # the reference: Lighthill's reactive thrust for the fin's trailing-edge motion is forward and several
    # times MuJoCo's lift on the fin; the wave is a thrust wave (fin pitch and heave velocity in phase)
    assert fin.lighthill_n > 5 * (fin.terms_n["kutta_lift"] + fin.terms_n["magnus_lift"]) > 0
    assert fin.pitch_heave_correlation > 0.2
    # diagnosis only (not a result): without MuJoCo's half of the added-mass force the fish is faster, and
    # still far below the paper's speed
    L = p.body.length_mm / 1000
    f = p.swimming.tail_beat_frequency_hz
    ablated = swim(path, p, duration_s=SPEED_RUN_S, planar=True, added_mass=False).forward_speed_m_s()
    assert fin.speed_m_s < ablated < 0.25 * PAPER_BL_PER_S_PER_HZ * f * L


def test_fish_swims_forward_at_the_design_frequency(speeds, default_params):
    r = speeds[default_params.swimming.tail_beat_frequency_hz]
    assert r.forward_speed_m_s() > 0.0


# ------------------------------------------------------------------------------------ plain MuJoCo, no callback
def _plain_attitude_run(path, axis: int, start_deg: float, seconds: float = 6.0):
    """The exported file alone in MuJoCo (no code of ours: no swim loop, no forces applied), zero commands,
    started rotated by ``start_deg`` about the body's x (0: roll) or y (1: pitch) axis. Returns the pitch and
    roll of the head [deg] every 0.1 s and the COM's displacement [m]."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    q = np.zeros(4)
    mujoco.mju_axisAngle2Quat(q, np.eye(3)[axis], np.radians(start_deg))
    data.qpos[3:7] = q
    mujoco.mj_forward(model, data)
    m = model.body_mass[1:]
    c0 = (m[:, None] * data.xipos[1:]).sum(axis=0) / m.sum()
    head = model.body("head").id
    att = []
    every = int(round(0.1 / model.opt.timestep))
    for k in range(int(round(seconds / model.opt.timestep)) + 1):
        if k % every == 0:
            R = data.xmat[head].reshape(3, 3)
            att.append((np.degrees(np.arcsin(np.clip(R[2, 0], -1, 1))), np.degrees(np.arctan2(R[2, 1], R[2, 2]))))
        mujoco.mj_step(model, data)
    c1 = (m[:, None] * data.xipos[1:]).sum(axis=0) / m.sum()
    warnings = [mujoco.mjtWarning(i).name for i in range(len(data.warning)) if data.warning[i].number]
    return np.array(att), c1 - c0, warnings


def test_plain_mujoco_keeps_the_fish_level_and_rights_it(real_robot, capsys):
    """Issue 15: buoyancy acts at each link's centre of buoyancy in the MJCF itself. Loaded by MuJoCo alone
    (no callback), the trimmed fish at rest stays within 5 deg of level and in place over 6 s, and started at
    30 deg of roll or of pitch it rights itself (within 5 deg over the last 2 s)."""
    path, _ = real_robot
    rows = []
    for label, axis, start in (("rest", 0, 0.0), ("roll 30 deg", 0, 30.0), ("pitch 30 deg", 1, 30.0)):
        att, dc, warnings = _plain_attitude_run(path, axis, start)
        assert warnings == []
        if start == 0.0:
            assert np.abs(att).max() < 5.0, att
            assert np.linalg.norm(dc) < 0.01
        else:
            assert abs(att[0, 1 - axis]) == pytest.approx(start, abs=0.5)        # it did start tilted
            assert np.abs(att[-20:]).max() < 5.0, (label, att[-20:])
        rows.append((label, att[-1, 0], att[-1, 1], np.abs(att[-20:]).max(), 1000 * np.linalg.norm(dc)))
    with capsys.disabled():
        print("\n  plain MuJoCo, the exported MJCF alone, zero commands, 6 s:")
        for label, pitch, roll, late, dc in rows:
            print(f"  from {label:13s}: pitch {pitch:+.2f} deg, roll {roll:+.2f} deg at 6 s; "
                  f"largest tilt over the last 2 s {late:.2f} deg; COM moved {dc:.1f} mm")


def test_the_mjcf_bodies_sum_to_the_mass_model(real_robot, default_params):
    """Each link is a link body and a welded buoyancy body at its COB; together they have exactly the link's
    mass, COM and inertia (with the water a flooded link carries), and the buoyancy body's gravcomp lifts the
    weight of the water the link displaces."""
    from tests.robot_helpers import mujoco_link_inertial

    path, res = real_robot
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rho = default_params.environment.water_density_kg_m3
    g = default_params.environment.gravity_m_s2
    for lk in res["robot"].links:
        want, V, cob = lk.in_water(rho)
        got = mujoco_link_inertial(mujoco, model, lk.name)
        assert got.mass_kg == pytest.approx(want.mass_kg, rel=1e-9)
        assert np.allclose(got.com, want.com, atol=1e-9)
        assert np.allclose(got.inertia, want.inertia, rtol=1e-6, atol=1e-6 * np.abs(want.inertia).max())
        buoy = model.body(f"{lk.name}_buoyancy")
        assert np.allclose(buoy.pos, cob, atol=1e-12)
        assert model.body_gravcomp[buoy.id] * buoy.mass[0] * g == pytest.approx(rho * V * g, rel=1e-9)
        assert model.body_gravcomp[model.body(lk.name).id] == 0.0


def test_build_swim_results_go_into_the_report(real_robot, default_params, tmp_path):
    """`swiftfin build --swim`: the app swims the exported file (quasi-steady and reactive) and the report's
    robot section shows speed, stride and slip beside the published strides (short runs here)."""
    from swiftfin.pipeline import swim_results
    from swiftfin.report.robot import swim_table

    path, _ = real_robot
    rows = swim_results(path, default_params, jobs=2, duration_s=3.0)
    assert [r["frequency_hz"] for r in rows] == [1.0, 2.0, 3.0]
    for r in rows:
        assert r["quasi_steady_m_s"] > 0 and r["reactive_m_s"] > r["quasi_steady_m_s"]
        L = default_params.body.length_mm / 1000
        assert r["stride_reactive"] == pytest.approx(r["reactive_m_s"] / (r["frequency_hz"] * L))
        assert 0 < r["slip_reactive"] < 1
    html = swim_table(rows)
    assert "Tunabot" in html and "Gleiss" in html and f"{rows[2]['reactive_m_s']:.3f}" in html
    assert "--swim" in swim_table(None)


def test_build_has_a_swim_option(monkeypatch, tmp_path):
    from swiftfin import pipeline
    from swiftfin.cli import main

    seen = {}
    monkeypatch.setattr(pipeline, "build", lambda *a, **k: (seen.update(k), (_ for _ in ()).throw(SystemExit(0))))
    with pytest.raises(SystemExit):
        main(["build", "--out", str(tmp_path / "o"), "--swim"])
    assert seen.get("swim") is True
