"""URDF writer (xml.etree) for an :class:`exports.robot_model.Robot`.

Inertial origin at the link COM with ``rpy="0 0 0"`` and the full tensor in link axes; joint origins are
``T_parent_child``; meshes are OBJ files in metres, referenced relative to the URDF (or, with ``mesh_uri_prefix``,
by URI: ``package://<pkg>/`` for a ROS 2 description package, exports/ros_package.py). The cable tendons have no
URDF element (they live in the MJCF). Water: a ``<gazebo>`` extension block per link carries Gazebo's
Hydrodynamics system with the link's added mass and damping (exports/hydro.py), as gz-sim reads it when it
loads a URDF; buoyancy in Gazebo needs the collision volumes of the SDF (exports/sdf.py), since the URDF's
collisions are the links' convex hulls, the contact shapes PyBullet and Drake use.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

from swiftfin.exports.robot_model import Geometry, Pose, Robot


def num(value: float) -> str:
    """A float with every digit (repr of a Python float), so a small inertia never rounds to zero."""
    return repr(float(value))


def fmt(*values: float) -> str:
    return " ".join(num(v) for v in values)


def _origin(parent: ET.Element, pose: Pose) -> None:
    ET.SubElement(parent, "origin", xyz=fmt(*pose.xyz_m), rpy=fmt(*pose.rpy_rad))


def _geometry(parent: ET.Element, g: Geometry, mesh_uri_prefix: str = "") -> None:
    geo = ET.SubElement(parent, "geometry")
    if g.kind == "mesh":
        ET.SubElement(geo, "mesh", filename=mesh_uri_prefix + g.mesh_file)
    elif g.kind == "box":
        ET.SubElement(geo, "box", size=fmt(*g.size_m))
    elif g.kind == "cylinder":
        ET.SubElement(geo, "cylinder", radius=num(g.size_m[0]), length=num(g.size_m[1]))
    elif g.kind == "sphere":
        ET.SubElement(geo, "sphere", radius=num(g.size_m[0]))
    else:
        raise ValueError(f"URDF has no {g.kind} geometry ({g.name})")


def urdf_tree(robot: Robot, mesh_uri_prefix: str = "") -> ET.ElementTree:
    """The URDF of ``robot``. ``mesh_uri_prefix`` is put before every mesh file name (which is relative to the
    robot folder, ``meshes/<link>_visual.obj``): "" keeps them relative to the URDF; ``package://<pkg>/`` makes
    them ROS package URIs."""
    root = ET.Element("robot", name=robot.name)
    for lk in robot.links:
        el = ET.SubElement(root, "link", name=lk.name)
        inert = ET.SubElement(el, "inertial")
        _origin(inert, Pose(lk.inertial.com_m))
        ET.SubElement(inert, "mass", value=num(lk.inertial.mass_kg))
        I = lk.inertial.inertia
        ET.SubElement(inert, "inertia", ixx=num(I[0, 0]), ixy=num(I[0, 1]), ixz=num(I[0, 2]),
                      iyy=num(I[1, 1]), iyz=num(I[1, 2]), izz=num(I[2, 2]))
        for g in lk.visuals:
            v = ET.SubElement(el, "visual", name=g.name)
            _origin(v, g.T_link_geom)
            _geometry(v, g, mesh_uri_prefix)
        for g in lk.collisions:
            c = ET.SubElement(el, "collision", name=g.name)
            _origin(c, g.T_link_geom)
            _geometry(c, g, mesh_uri_prefix)
    for jt in robot.joints:
        el = ET.SubElement(root, "joint", name=jt.name, type="revolute")
        _origin(el, jt.T_parent_child)
        ET.SubElement(el, "parent", link=jt.parent)
        ET.SubElement(el, "child", link=jt.child)
        ET.SubElement(el, "axis", xyz=fmt(*jt.axis))
        ET.SubElement(el, "limit", lower=num(jt.lower_rad), upper=num(jt.upper_rad), effort=num(jt.effort_nm),
                      velocity=num(jt.velocity_rad_s))
        dyn = ET.SubElement(el, "dynamics", damping=num(jt.damping_nm_s_rad))
        if jt.friction_nm > 0:
            dyn.set("friction", num(jt.friction_nm))
    for lk in robot.links:
        if lk.hydro is None:
            continue
        gz = ET.SubElement(root, "gazebo")
        pl = ET.SubElement(gz, "plugin", filename="gz-sim-hydrodynamics-system",
                           name="gz::sim::systems::Hydrodynamics")
        ET.SubElement(pl, "link_name").text = lk.name
        ET.SubElement(pl, "water_density").text = num(robot.medium.density_kg_m3)
        for key, value in lk.hydro.as_fossen().items():
            ET.SubElement(pl, key).text = num(value)
    ET.indent(root)
    return ET.ElementTree(root)


def urdf_bytes(robot: Robot, mesh_uri_prefix: str = "") -> bytes:
    return ET.tostring(urdf_tree(robot, mesh_uri_prefix).getroot(), encoding="utf-8", xml_declaration=True) + b"\n"
