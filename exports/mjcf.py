"""MJCF (MuJoCo) writer (xml.etree) for an :class:`exports.robot_model.Robot`: a swimming model.

* ``<inertial fullinertia>`` in MuJoCo's order ``ixx iyy izz ixy ixz iyz`` (not URDF's), at the COM;
  ``inertiafromgeom="false"`` so that no geom adds mass.
* The head carries a free joint; joints are hinges with the hard-stop limits; ``armature`` is the motor rotor
  inertia reflected through the capstan; each joint has a ``position`` actuator (the stepper's step loop)
  limited to the joint torque the motor's holding torque gives.
* The capstan cables are fixed tendons ``cable_j`` (length change = moment arm x joint angle): they report
  the cable excursion each side, and hence the spool's turn (excursion / spool radius).
* Water: ``<option density viscosity>``; every link has an ellipsoid geom with ``fluidshape="ellipsoid"``
  (MuJoCo's ellipsoid fluid model: added mass, viscous and quadratic drag, Kutta and Magnus lift), the tail link
  a thin-plate one of the caudal fin's span and planform area. The fin's has MuJoCo's default coefficients; the
  hull's ``fluidcoef`` drops the Kutta lift (``physics.swim_sim.FLUIDCOEF_HULL``: a slice of a smooth body is no
  wing; with it the free fish porpoises). These ellipsoids
  are also the collision primitives (all self-contacts excluded: the hard stops are joint limits).
  Caveat (tests/test_mujoco_swim.py): MuJoCo's added-mass force keeps only ``(rho m_v v) x omega`` and drops
  ``-rho m_v dv/dt``; on an undulating fish that half has a backward mean, and the model has no reactive
  (shed-wake) thrust, so the paper's wave drives this fish slowly backward in MuJoCo.
* **Flooded links** (``hull.flooded_from_joint``) carry the water inside them: the body's inertial is the link's
  plus that water's (``Link.in_water``), and the water's volume is added to the displaced volume at its centroid
  (it is neutrally buoyant). URDF and SDF describe the dry robot and leave it out.
* **Buoyancy, at the centre of buoyancy, in the file alone.** MuJoCo's fluid models add no buoyancy, and
  ``gravcomp`` lifts a body at its own COM. So each link is two bodies: the link itself, and a welded child
  ``<link>_buoyancy`` at the link's centre of buoyancy that carries a small share ``mu`` of its mass
  (:data:`BUOY_MASS_FRACTION`) with ``gravcomp = rho_w V / mu``, an upward force equal to the weight of the
  water the link displaces, applied at the COB. The link body keeps the rest, with its COM and inertia chosen
  so that the two together have exactly the link's mass, COM and inertia (:func:`buoyancy_split`). Plain
  MuJoCo (no callback) then feels gravity at the COM and buoyancy at the COB: the trimmed fish floats level and
  rights itself. ``<link>_cob`` sites mark the centres of buoyancy.
Visual meshes (OBJ, metres) are in group 1, fluid/collision ellipsoids in group 3.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from swiftfin.exports.robot_model import Robot
from swiftfin.layout.servo import FRICTION_TIMECONST_S
from swiftfin.exports.urdf import fmt, num

TIMESTEP_S = 5e-4
BUOY_MASS_FRACTION = 0.05     # share of a link's mass moved to its buoyancy body (halved until the rest is valid)
BUOY_RADIUS_M = 0.004         # the buoyancy body's inertia: a solid sphere of this radius
BUOY_GEOM_RADIUS_M = 1e-4     # its only geom: a massless fluid-inert speck (see mjcf_tree)


def buoyancy_split(inertial, cob_m, volume_m3: float, density_kg_m3: float):
    """(link body, buoyancy body, buoyancy body's gravcomp) for a link of ``inertial`` (link frame) whose
    displaced ``volume_m3`` has its centroid at ``cob_m``: the two bodies sum exactly to ``inertial``, and
    ``gravcomp x mu x g = rho_w V g`` on the buoyancy body at the COB."""
    from swiftfin.exports.inertia import combine, make_inertial

    frac = BUOY_MASS_FRACTION
    for _ in range(30):
        mu = frac * inertial.mass_kg
        buoy = make_inertial(mu, cob_m, np.eye(3) * 0.4 * mu * BUOY_RADIUS_M ** 2)
        main = combine([inertial, buoy.scaled_mass(-1.0)])
        ev = np.sort(np.linalg.eigvalsh(main.inertia))
        if ev[0] > 1e-12 * ev[2] and ev[0] + ev[1] >= ev[2] * (1 + 1e-9):
            return main, buoy, density_kg_m3 * volume_m3 / mu
        frac /= 2
    raise ValueError(f"no valid split of a link of {inertial.mass_kg!r} kg for its buoyancy body")


def _children(robot: Robot) -> dict[str, list]:
    out: dict[str, list] = {lk.name: [] for lk in robot.links}
    for jt in robot.joints:
        out[jt.parent].append(jt)
    return out


def mjcf_tree(robot: Robot, free: bool = True) -> ET.ElementTree:
    root = ET.Element("mujoco", model=robot.name)
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    med = robot.medium
    ET.SubElement(root, "option", timestep=num(TIMESTEP_S), integrator="implicitfast",
                  density=num(med.density_kg_m3), viscosity=num(med.viscosity_pa_s),
                  gravity=fmt(0.0, 0.0, -med.gravity_m_s2))
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="0", conaffinity="0")
    asset = ET.SubElement(root, "asset")
    for lk in robot.links:
        for g in lk.visuals:
            if g.kind == "mesh":
                ET.SubElement(asset, "mesh", name=g.name, file=g.mesh_file, inertia="shell")
    world = ET.SubElement(root, "worldbody")
    children = _children(robot)
    by_name = {lk.name: lk for lk in robot.links}
    joints_by_child = {jt.child: jt for jt in robot.joints}

    def body(parent_el: ET.Element, name: str, pos) -> None:
        lk = by_name[name]
        inertial, V, cob = lk.in_water(med.density_kg_m3)     # a flooded link carries its water
        main, buoy, gravcomp = buoyancy_split(inertial, cob, V, med.density_kg_m3)
        b = ET.SubElement(parent_el, "body", name=name, pos=fmt(*pos))
        if name == robot.links[0].name and free:
            ET.SubElement(b, "freejoint", name="root")
        jt = joints_by_child.get(name)
        if jt is not None:
            el = ET.SubElement(b, "joint", name=jt.name, type="hinge", axis=fmt(*jt.axis),
                               range=fmt(jt.lower_rad, jt.upper_rad), limited="true",
                               damping=num(jt.damping_nm_s_rad), armature=num(jt.armature_kg_m2))
            if jt.friction_nm > 0:          # measured (a calibration file): MuJoCo's dry friction of the dof
                el.set("frictionloss", num(jt.friction_nm))
                el.set("solreffriction", f"{num(FRICTION_TIMECONST_S)} 1")
        I = main.inertia
        ET.SubElement(b, "inertial", pos=fmt(*main.com_m), mass=num(main.mass_kg),
                      fullinertia=fmt(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
        float_el = ET.SubElement(b, "body", name=f"{name}_buoyancy", pos=fmt(*buoy.com_m), gravcomp=num(gravcomp))
        Ib = buoy.inertia
        ET.SubElement(float_el, "inertial", pos=fmt(0.0, 0.0, 0.0), mass=num(buoy.mass_kg),
                      diaginertia=fmt(Ib[0, 0], Ib[1, 1], Ib[2, 2]))
        # a body with no fluid geom would get MuJoCo's inertia-box fluid model (drag on a box the size of its
        # inertia): a 0.1 mm sphere with zero fluid coefficients keeps it on the ellipsoid model, with nothing
        ET.SubElement(float_el, "geom", name=f"{name}_buoyancy", type="sphere", size=num(BUOY_GEOM_RADIUS_M),
                      group="4", fluidshape="ellipsoid", fluidcoef="0 0 0 0 0", rgba="0 0 1 0")
        for g in lk.visuals:
            ET.SubElement(b, "geom", name=g.name, type="mesh", mesh=g.name, group="1",
                          pos=fmt(*g.T_link_geom.xyz_m), rgba="0.75 0.78 0.82 1")
        for g in lk.fluid:
            el = ET.SubElement(b, "geom", name=g.name, type="ellipsoid", size=fmt(*g.size_m),
                               pos=fmt(*g.T_link_geom.xyz_m), group="3", contype="1", conaffinity="1",
                               fluidshape="ellipsoid", rgba="0.2 0.5 0.9 0.3")
            if g.fluid_coef:
                el.set("fluidcoef", fmt(*g.fluid_coef))
        ET.SubElement(b, "site", name=f"{name}_cob", pos=fmt(*cob), size="0.004", group="4")
        for child in children[name]:
            body(b, child.child, child.T_parent_child.xyz_m)

    body(world, robot.links[0].name, (0.0, 0.0, 0.0))
    names = [lk.name for lk in robot.links]
    contact = ET.SubElement(root, "contact")
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            ET.SubElement(contact, "exclude", body1=names[i], body2=names[j])
    if robot.tendons:
        tendon = ET.SubElement(root, "tendon")
        for t in robot.tendons:
            f = ET.SubElement(tendon, "fixed", name=t.name)
            ET.SubElement(f, "joint", joint=t.joint, coef=num(t.coef_m))
    if robot.actuators:
        act = ET.SubElement(root, "actuator")
        jmap = {jt.name: jt for jt in robot.joints}
        for a in robot.actuators:
            jt = jmap[a.joint]
            ET.SubElement(act, "position", name=a.name, joint=a.joint, kp=num(a.kp_nm_rad), kv=num(a.kv_nm_s_rad),
                          ctrlrange=fmt(jt.lower_rad, jt.upper_rad), forcerange=fmt(-a.torque_limit_nm,
                                                                                     a.torque_limit_nm))
    ET.indent(root)
    return ET.ElementTree(root)


def mjcf_bytes(robot: Robot, free: bool = True) -> bytes:
    return ET.tostring(mjcf_tree(robot, free).getroot(), encoding="utf-8", xml_declaration=True) + b"\n"


def fullinertia_order(I) -> list[float]:
    """MuJoCo's fullinertia order (ixx iyy izz ixy ixz iyz) of a 3x3 tensor."""
    I = np.asarray(I, dtype=float)
    return [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]
