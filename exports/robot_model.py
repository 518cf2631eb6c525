"""The one intermediate robot description every simulator file is written from (house style rule 11).

A frozen :class:`Robot` of :class:`Link`, :class:`Joint` and :class:`Tendon`, in SI units. Frames:

* the base link ``head`` has its frame at the nose (the body frame of layout/geometry.py: +x forward, +z up);
* link j's frame has its origin on joint j's axis at z = 0 and axes parallel to the body frame at rest;
  ``Joint.T_parent_child`` is the pose of the child's frame in the parent's at zero joint angle (a pure
  translation along -x);
* inertials are about the link COM in link axes (:class:`exports.massprops.Inertial`, COM in the link frame).

Joint axis: ``(0, 0, -1)``, so that a positive joint angle turns the child's tail toward +y (layout/geometry.py).

Water: every swimming link carries a ``fluid`` ellipsoid (centre and semi-axes in the link frame; the head's
of its hull envelope, the hull links' slender, see :func:`fluid_ellipsoid`), plus a thin-plate ellipsoid for
the caudal fin (:func:`fin_ellipsoid`); MuJoCo's ellipsoid fluid model uses them, the hull's without the Kutta
lift (``Geometry.fluid_coef``), the fin's with MuJoCo's defaults.
Buoyancy (``Link.displaced_volume_m3``, ``Link.cob_m``): the exporters that can express it do so.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.layout import geometry as layout
from swiftfin.core import units
from swiftfin.exports.hydro import link_hydrodynamics
from swiftfin.exports.massprops import Inertial, MassReport, combine, link_origin_mm
from swiftfin.core.calibration import Calibration
from swiftfin.core.schema import Params
from swiftfin.layout.servo import joint_servo, joint_torque_limit_nm
from swiftfin.physics.swim_sim import FLUIDCOEF_HULL

JOINT_AXIS = (0.0, 0.0, -1.0)


@dataclass(frozen=True)
class Pose:
    """A rigid transform: translation [m] and roll-pitch-yaw [rad] (fixed axes X, Y, Z)."""
    xyz_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Geometry:
    """``kind``: "mesh" (``mesh_file`` relative to the robot folder, metres), "box" (full sizes),
    "ellipsoid" (semi-axes), "cylinder" (radius, length), "sphere" (radius,)."""
    name: str
    kind: str
    size_m: tuple[float, ...] = ()
    mesh_file: str = ""
    T_link_geom: Pose = Pose()
    fluid_coef: tuple[float, ...] = ()   # a fluid ellipsoid's MuJoCo fluidcoef; () = the simulator's defaults


@dataclass(frozen=True)
class Link:
    name: str
    inertial: Inertial                  # COM in the link frame, inertia about the COM in link axes
    visuals: tuple[Geometry, ...]
    collisions: tuple[Geometry, ...]
    fluid: tuple[Geometry, ...]         # ellipsoids for the fluid model
    displaced_volume_m3: float
    cob_m: tuple[float, float, float]   # centre of buoyancy, link frame
    entrained_water: Inertial | None = None   # water inside a flooded link, link frame (moves with it in water)
    hydro: object = None                # exports.hydro.LinkHydro: added mass and damping, Fossen's notation

    def in_water(self, water_density_kg_m3: float) -> tuple[Inertial, float, tuple[float, float, float]]:
        """(inertial, displaced volume, centre of buoyancy) of the link as it moves in water: with the water it
        carries (neutrally buoyant: its volume is added to the displacement, at its centroid)."""
        w = self.entrained_water
        if w is None:
            return self.inertial, self.displaced_volume_m3, self.cob_m
        V_w = w.mass_kg / water_density_kg_m3
        V = self.displaced_volume_m3 + V_w
        cob = (self.displaced_volume_m3 * np.asarray(self.cob_m) + V_w * w.com) / V
        return combine([self.inertial, w]), V, tuple(float(v) for v in cob)


@dataclass(frozen=True)
class Joint:
    name: str
    parent: str
    child: str
    T_parent_child: Pose
    axis: tuple[float, float, float]
    lower_rad: float
    upper_rad: float
    effort_nm: float
    velocity_rad_s: float
    damping_nm_s_rad: float
    armature_kg_m2: float               # motor rotor inertia reflected through the capstan
    friction_nm: float = 0.0            # the hinge's dry friction (measured: core.calibration), 0 unless calibrated


@dataclass(frozen=True)
class Tendon:
    """A capstan cable as a fixed tendon: length change = coef * joint angle (coef = tendon moment arm)."""
    name: str
    joint: str
    coef_m: float


@dataclass(frozen=True)
class Actuator:
    """A position servo on a joint (the stepper's closed step loop), torque limited to the motor's."""
    name: str
    joint: str
    kp_nm_rad: float
    kv_nm_s_rad: float
    torque_limit_nm: float


@dataclass(frozen=True)
class Medium:
    density_kg_m3: float
    viscosity_pa_s: float
    gravity_m_s2: float


@dataclass(frozen=True)
class Robot:
    name: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    tendons: tuple[Tendon, ...]
    actuators: tuple[Actuator, ...]
    medium: Medium

    def link(self, name: str) -> Link:
        return next(lk for lk in self.links if lk.name == name)


# ----------------------------------------------------------------------------------------------- from a design
def fluid_ellipsoid(p: Params, report: MassReport, j: int) -> Geometry:
    """Fluid ellipsoid of link j over its span of stations [s0, s1] (MuJoCo's ellipsoid fluid model).

    * The head (j = 0), the leading body, is the ellipsoid of its hull envelope: its length, volume = the
      displaced hull volume, height/width ratio of the hull.
    * A hull link (j >= 1) is a slice of a continuous, skinned body, and its ellipsoid keeps what the water
      sees of it: its length (a_x = (s1 - s0) / 2) and its mean hull height (a_z), so the side area and the
      lateral added mass per length rho pi (h/2)^2 of slender-body theory; its frontal area is only the
      ring by which the body's cross-section changes over the link (the rest is shadowed by the body ahead),
      a_y = |A(s0) - A(s1)| / (pi a_z), between half the wall thickness and the link's mean half-width. A
      volume-matched ellipsoid of a 39 mm link of a 75 mm wide body would be a disk facing the flow (its
      thinnest axis x), which MuJoCo treats as a plate across the stream.

    Every hull ellipsoid carries :data:`physics.swim_sim.FLUIDCOEF_HULL`: no Kutta lift (a slice of a smooth
    closed body sheds no vorticity of its own; the fin does).
    """
    js = layout.joint_stations_mm(p)
    bounds = [0.0, *js, layout.hull_end_mm(p)]
    s0, s1 = bounds[j], bounds[j + 1]
    ax = (s1 - s0) / 2
    if j == 0:
        from swiftfin.exports.massprops import envelope_volume_mm3
        V, s_c = envelope_volume_mm3(p, s0, s1)
        # a_y * a_z = 3 V / (4 pi a_x), a_z = k a_y
        k = p.body.height_to_width
        ay = math.sqrt(3 * V / (4 * math.pi * ax) / k)
        az = k * ay
    else:
        s = np.linspace(s0, s1, 401)
        az = float(np.mean(layout.half_height_mm(p, s)))
        half_width = float(np.mean(layout.naca_half_width_mm(p, s)))

        def area(x):
            return math.pi * float(layout.naca_half_width_mm(p, x)) * float(layout.half_height_mm(p, x))
        ay = min(max(abs(area(s0) - area(s1)) / (math.pi * az), p.hull.wall_thickness_mm / 2), half_width)
    origin = link_origin_mm(p, j)
    centre = units.length_m(np.array([-(s0 + s1) / 2 - origin[0], 0.0, 0.0]))
    return Geometry(f"{report.links[j].name}_fluid", "ellipsoid",
                    tuple(float(v) for v in units.length_m(np.array([ax, ay, az]))), "",
                    Pose(tuple(float(v) for v in centre)), FLUIDCOEF_HULL)


def fin_ellipsoid(p: Params, parts, last_link: int) -> Geometry | None:
    """The caudal fin as a thin-plate ellipsoid: span (z) and planform area of cad.fin.planform (chord semi-axis
    ``S / (pi b / 2)``, so the ellipse has the fin's area), centred at the planform's area centroid; thickness
    (y) and height of the centre from the fin parts' bounding box behind the hull end (the blade's thickest
    section). The bounding box's x extent is not the chord: the swept, lunate fin spans ~3 chords in x."""
    from swiftfin.layout.fin_plan import planform
    x_end = -layout.hull_end_mm(p)
    lo, hi = None, None
    for part in parts:
        if part.family != "fin":
            continue
        bb = part.solid.bounding_box()
        a = np.array([bb.min.X, bb.min.Y, bb.min.Z])
        b = np.array([min(bb.max.X, x_end), bb.max.Y, bb.max.Z])
        lo = a if lo is None else np.minimum(lo, a)
        hi = b if hi is None else np.maximum(hi, b)
    if lo is None or hi[0] <= lo[0]:
        return None
    pf = planform(p)
    eta = np.linspace(-1.0, 1.0, 4001)
    c = pf.chord_mm(eta)
    s_centroid = float(np.trapezoid((pf.s_le_mm(eta) + c / 2) * c, eta) / np.trapezoid(c, eta))
    semi_mm = np.array([pf.area_mm2 / (math.pi * pf.span_mm / 2), (hi[1] - lo[1]) / 2, pf.span_mm / 2])
    centre_mm = np.array([-s_centroid, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2])
    origin = np.asarray(link_origin_mm(p, last_link))
    centre = units.length_m(centre_mm - origin)
    return Geometry("caudal_fin_fluid", "ellipsoid", tuple(float(v) for v in units.length_m(semi_mm)), "",
                    Pose(tuple(float(v) for v in centre)))


def robot_from_design(p: Params, parts, report: MassReport, name: str = "swiftfin",
                      calibration: Calibration | None = None) -> Robot:
    """The Robot of a design: links and inertials from ``report``, joints from swiftfin.layout.geometry.

    Mesh file names follow :func:`visual_mesh_file` / :func:`collision_mesh_file` (written by exports.robot).
    """
    n = p.joints.count
    stops = layout.joint_stop_angles_rad(p)
    links = []
    waters = [None if w is None else w.shifted(lk.origin_m)            # link frame
              for lk, w in zip(report.links, report.link_entrained_water or (None,) * len(report.links))]
    hydro = link_hydrodynamics(p, [lk.name for lk in report.links], waters)
    labels = {part.label for part in parts}
    for lk, V, cob, water, hd in zip(report.links, report.link_displaced_volume_m3, report.link_cob_m, waters, hydro):
        fluid = [fluid_ellipsoid(p, report, lk.index)]
        if lk.index == n:
            fin = fin_ellipsoid(p, parts, n)
            if fin is not None:
                fluid.append(fin)
        visual = Geometry(f"{lk.name}_visual", "mesh", (), visual_mesh_file(lk.name))
        n_solid = sum(1 for label in lk.parts if label in labels)           # cables and tubes have no solid
        collisions = tuple(Geometry(f"{lk.name}_collision_{k}", "mesh", (), collision_mesh_file(lk.name, k))
                           for k in range(n_solid))
        cob_link = tuple(float(v) for v in np.asarray(cob) - np.asarray(lk.origin_m))
        links.append(Link(lk.name, lk.inertial, (visual,), collisions, tuple(fluid), float(V), cob_link, water, hd))
    joints, tendons, actuators = [], [], []
    tau = joint_torque_limit_nm(p)
    # max joint speed: the wave's peak relative angle times omega (x2 margin)
    w_max = 2.0 * 2 * math.pi * p.swimming.tail_beat_frequency_hz * max(stops)
    for j in range(1, n + 1):
        parent, child = report.links[j - 1], report.links[j]
        d = np.asarray(child.origin_m) - np.asarray(parent.origin_m)
        jn = f"joint_{j}"
        s = joint_servo(p, j, calibration.joint(j) if calibration is not None else None)
        joints.append(Joint(jn, parent.name, child.name, Pose(tuple(float(v) for v in d)), JOINT_AXIS,
                            -stops[j - 1], stops[j - 1], tau, w_max, s.damping_nm_s_rad, s.armature_kg_m2,
                            s.friction_nm))
        tendons.append(Tendon(f"cable_{j}", jn, units.length_m(p.joints.tendon_moment_arm_mm)))
        actuators.append(Actuator(f"motor_{j}", jn, s.kp_nm_rad, s.kv_nm_s_rad, tau))
    env = p.environment
    return Robot(name, tuple(links), tuple(joints), tuple(tendons), tuple(actuators),
                 Medium(env.water_density_kg_m3, env.water_viscosity_pa_s, env.gravity_m_s2))


def visual_mesh_file(link: str) -> str:
    return f"meshes/{link}_visual.obj"


def collision_mesh_file(link: str, k: int) -> str:
    """The k-th collision mesh of a link (one convex hull per part, in the order of the link's parts)."""
    return f"meshes/{link}_collision_{k}.obj"
