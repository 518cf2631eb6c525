"""MJCF (MuJoCo) writer (xml.etree) for an :class:`exports.robot_model.Robot`: a swimming model.

* ``<inertial fullinertia>`` in MuJoCo's order ``ixx iyy izz ixy ixz iyz`` (not URDF's), at the COM;
  ``inertiafromgeom="false"`` so that no geom adds mass.
* The head carries a free joint; joints are hinges with the hard-stop limits; ``armature`` is the motor rotor
  inertia reflected through the capstan; each joint has a ``position`` actuator (the stepper's step loop)
  limited to the joint torque the motor's holding torque gives.
* The capstan cables are fixed tendons ``cable_j`` (length change = moment arm x joint angle): they report
  the cable excursion each side, and hence the spool's turn (excursion / spool radius).
* Water: ``<option density viscosity>``; every link has an ellipsoid geom with ``fluidshape="ellipsoid"``
  (MuJoCo's ellipsoid fluid model: added mass, viscous and quadratic drag, Kutta and Magnus lift, default
  coefficients), the tail link a thin-plate one of the caudal fin's span and planform area. These ellipsoids
  are also the collision primitives (all self-contacts excluded: the hard stops are joint limits).
  Caveat (tests/test_mujoco_swim.py): MuJoCo's added-mass force keeps only ``(rho m_v v) x omega`` and drops
  ``-rho m_v dv/dt``; on an undulating fish that half has a backward mean, and the model has no reactive
  (shed-wake) thrust, so the paper's wave drives this fish slowly backward in MuJoCo.
* **Flooded links** (``hull.flooded_from_joint``) carry the water inside them: the body's inertial is the link's
  plus that water's (``Link.in_water``), and the water's volume is added to the displaced volume at its centroid
  (it is neutrally buoyant). URDF and SDF describe the dry robot and leave it out.
* **Buoyancy.** MuJoCo's fluid models add no buoyancy, so each body gets ``gravcomp = rho_w V_link / m_link``:
  an upward force equal to the weight of the water the link displaces, applied at the link's COM. The
  righting couple (buoyancy acts at the centre of buoyancy, not the COM) is not expressible in the file;
  ``physics.swim_sim`` adds it at run time through ``xfrc_applied`` from the ``<link>_cob`` sites.
Visual meshes (OBJ, metres) are in group 1, fluid/collision ellipsoids in group 3.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from swiftfin.exports.robot_model import Robot
from swiftfin.exports.urdf import fmt, num

TIMESTEP_S = 5e-4


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
        m = inertial.mass_kg
        gravcomp = med.density_kg_m3 * V / m
        b = ET.SubElement(parent_el, "body", name=name, pos=fmt(*pos), gravcomp=num(gravcomp))
        if name == robot.links[0].name and free:
            ET.SubElement(b, "freejoint", name="root")
        jt = joints_by_child.get(name)
        if jt is not None:
            ET.SubElement(b, "joint", name=jt.name, type="hinge", axis=fmt(*jt.axis),
                          range=fmt(jt.lower_rad, jt.upper_rad), limited="true",
                          damping=num(jt.damping_nm_s_rad), armature=num(jt.armature_kg_m2))
        I = inertial.inertia
        ET.SubElement(b, "inertial", pos=fmt(*inertial.com_m), mass=num(m),
                      fullinertia=fmt(I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
        for g in lk.visuals:
            ET.SubElement(b, "geom", name=g.name, type="mesh", mesh=g.name, group="1",
                          pos=fmt(*g.T_link_geom.xyz_m), rgba="0.75 0.78 0.82 1")
        for g in lk.fluid:
            ET.SubElement(b, "geom", name=g.name, type="ellipsoid", size=fmt(*g.size_m),
                          pos=fmt(*g.T_link_geom.xyz_m), group="3", contype="1", conaffinity="1",
                          fluidshape="ellipsoid", rgba="0.2 0.5 0.9 0.3")
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
