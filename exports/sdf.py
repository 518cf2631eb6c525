"""SDFormat 1.9 writer (xml.etree) for an :class:`exports.robot_model.Robot`.

Each link's pose is given relative to the model frame (the body frame at rest: link origins on the joint
axes); the inertial pose is the COM in the link frame; joints sit at the child link's origin with the axis
expressed in the model frame. Meshes are OBJ files in metres, referenced relative to the SDF file.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from swiftfin.exports.robot_model import Geometry, Pose, Robot
from swiftfin.exports.urdf import fmt, num

SDF_VERSION = "1.9"


def _pose(parent: ET.Element, pose: Pose, relative_to: str | None = None) -> None:
    el = ET.SubElement(parent, "pose")
    if relative_to:
        el.set("relative_to", relative_to)
    el.text = fmt(*pose.xyz_m, *pose.rpy_rad)


def _geometry(parent: ET.Element, g: Geometry) -> None:
    geo = ET.SubElement(parent, "geometry")
    if g.kind == "mesh":
        ET.SubElement(ET.SubElement(geo, "mesh"), "uri").text = g.mesh_file
    elif g.kind == "box":
        ET.SubElement(ET.SubElement(geo, "box"), "size").text = fmt(*g.size_m)
    elif g.kind == "ellipsoid":
        ET.SubElement(ET.SubElement(geo, "ellipsoid"), "radii").text = fmt(*g.size_m)
    elif g.kind == "cylinder":
        c = ET.SubElement(geo, "cylinder")
        ET.SubElement(c, "radius").text = num(g.size_m[0])
        ET.SubElement(c, "length").text = num(g.size_m[1])
    elif g.kind == "sphere":
        ET.SubElement(ET.SubElement(geo, "sphere"), "radius").text = num(g.size_m[0])
    else:
        raise ValueError(f"SDF writer has no {g.kind} geometry ({g.name})")


def link_poses_m(robot: Robot) -> dict[str, np.ndarray]:
    """Origin of every link frame in the model (base) frame at rest: the chain of T_parent_child."""
    out = {robot.links[0].name: np.zeros(3)}
    for jt in robot.joints:   # joints are listed parent before child
        out[jt.child] = out[jt.parent] + np.asarray(jt.T_parent_child.xyz_m)
    return out


def sdf_tree(robot: Robot) -> ET.ElementTree:
    root = ET.Element("sdf", version=SDF_VERSION)
    model = ET.SubElement(root, "model", name=robot.name)
    poses = link_poses_m(robot)
    for lk in robot.links:
        el = ET.SubElement(model, "link", name=lk.name)
        _pose(el, Pose(tuple(float(v) for v in poses[lk.name])))
        inert = ET.SubElement(el, "inertial")
        _pose(inert, Pose(lk.inertial.com_m))
        ET.SubElement(inert, "mass").text = num(lk.inertial.mass_kg)
        I = lk.inertial.inertia
        ie = ET.SubElement(inert, "inertia")
        for tag, (a, b) in (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)), ("iyy", (1, 1)), ("iyz", (1, 2)),
                            ("izz", (2, 2))):
            ET.SubElement(ie, tag).text = num(float(I[a, b]))
        for g in lk.visuals:
            v = ET.SubElement(el, "visual", name=g.name)
            _pose(v, g.T_link_geom)
            _geometry(v, g)
        for g in lk.collisions:
            c = ET.SubElement(el, "collision", name=g.name)
            _pose(c, g.T_link_geom)
            _geometry(c, g)
    for jt in robot.joints:
        el = ET.SubElement(model, "joint", name=jt.name, type="revolute")
        ET.SubElement(el, "parent").text = jt.parent
        ET.SubElement(el, "child").text = jt.child
        ax = ET.SubElement(el, "axis")
        xyz = ET.SubElement(ax, "xyz", expressed_in="__model__")
        xyz.text = fmt(*jt.axis)
        lim = ET.SubElement(ax, "limit")
        ET.SubElement(lim, "lower").text = num(jt.lower_rad)
        ET.SubElement(lim, "upper").text = num(jt.upper_rad)
        ET.SubElement(lim, "effort").text = num(jt.effort_nm)
        ET.SubElement(lim, "velocity").text = num(jt.velocity_rad_s)
        ET.SubElement(ET.SubElement(ax, "dynamics"), "damping").text = num(jt.damping_nm_s_rad)
    ET.indent(root)
    return ET.ElementTree(root)


def sdf_bytes(robot: Robot) -> bytes:
    return ET.tostring(sdf_tree(robot).getroot(), encoding="utf-8", xml_declaration=True) + b"\n"
