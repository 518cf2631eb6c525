"""SDFormat 1.9 writer (xml.etree) for an :class:`exports.robot_model.Robot`, with its water for Gazebo (gz-sim).

Each link's pose is given relative to the model frame (the body frame at rest: link origins on the joint
axes); the inertial pose is the COM in the link frame (the dry link: a flooded link's water is not its mass);
joints sit at the child link's origin with the axis expressed in the model frame. Visual meshes are OBJ files
in metres, referenced relative to the SDF file.

Water (Gazebo's maritime pattern, gz-sim "theory_buoyancy"):

* **Buoyancy.** Gazebo's Buoyancy system (a world system) takes each link's displaced volume from its
  ``<collision>`` shapes and pushes at their centre of volume. So each link's one collision is an ellipsoid
  ``<link>_buoyancy`` of exactly the volume the link displaces (the mass model's: the closed envelope of a
  sealed link, the solids of a flooded one), shaped like the link's fluid ellipsoid and centred at its centre
  of buoyancy; it is also the link's contact shape. The convex-hull collision meshes stay in the URDF and the
  MJCF. ``swiftfin_world.sdf`` is a world with the Buoyancy system (``uniform_fluid_density``) and this model.
* **Hydrodynamics.** One Gazebo Hydrodynamics system per link, with its added mass and quadratic damping in
  Fossen's notation from strip theory (:mod:`swiftfin.exports.hydro`), a flooded link's water included, in
  ``swiftfin_world.sdf`` (``swiftfin.sdf`` stays free of plugins, which strict parsers such as Drake's refuse).
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


WORLD_NAME = "swiftfin_water"


def buoyancy_collision(lk) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(radii [m], centre in the link frame [m]) of the ellipsoid whose volume is the link's displaced volume,
    shaped like its (first) fluid ellipsoid, centred at its centre of buoyancy."""
    shape = np.asarray(lk.fluid[0].size_m, dtype=float) if lk.fluid else np.ones(3)
    k = (lk.displaced_volume_m3 / (4.0 / 3.0 * np.pi * float(np.prod(shape)))) ** (1.0 / 3.0)
    return tuple(float(v) for v in k * shape), tuple(float(v) for v in lk.cob_m)


def _hydrodynamics_plugin(parent: ET.Element, lk, water_density_kg_m3: float) -> None:
    pl = ET.SubElement(parent, "plugin", filename="gz-sim-hydrodynamics-system",
                       name="gz::sim::systems::Hydrodynamics")
    ET.SubElement(pl, "link_name").text = lk.name
    ET.SubElement(pl, "water_density").text = num(water_density_kg_m3)
    for key, value in lk.hydro.as_fossen().items():
        ET.SubElement(pl, key).text = num(value)


def _model(parent: ET.Element, robot: Robot, water: bool = False) -> ET.Element:
    """The model; ``water``: with the links' Hydrodynamics systems (Gazebo only: other parsers, Drake's strict
    one among them, refuse unknown plugins, so the plain model file leaves them to the world file)."""
    model = ET.SubElement(parent, "model", name=robot.name)
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
        if lk.displaced_volume_m3 > 0:
            radii, centre = buoyancy_collision(lk)
            c = ET.SubElement(el, "collision", name=f"{lk.name}_buoyancy")
            _pose(c, Pose(centre))
            ET.SubElement(ET.SubElement(ET.SubElement(c, "geometry"), "ellipsoid"), "radii").text = fmt(*radii)
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
        dyn = ET.SubElement(ax, "dynamics")
        ET.SubElement(dyn, "damping").text = num(jt.damping_nm_s_rad)
        if jt.friction_nm > 0:
            ET.SubElement(dyn, "friction").text = num(jt.friction_nm)
    if water:
        for lk in robot.links:
            if lk.hydro is not None:
                _hydrodynamics_plugin(model, lk, robot.medium.density_kg_m3)
    return model


def sdf_tree(robot: Robot) -> ET.ElementTree:
    root = ET.Element("sdf", version=SDF_VERSION)
    _model(root, robot)
    ET.indent(root)
    return ET.ElementTree(root)


def world_tree(robot: Robot) -> ET.ElementTree:
    """A world of water holding the model: gravity, Gazebo's Buoyancy system at the water's density, and the
    systems a user needs to run it (physics, scene broadcaster, user commands)."""
    root = ET.Element("sdf", version=SDF_VERSION)
    world = ET.SubElement(root, "world", name=WORLD_NAME)
    ET.SubElement(world, "gravity").text = fmt(0.0, 0.0, -robot.medium.gravity_m_s2)
    for filename, name in (("gz-sim-physics-system", "gz::sim::systems::Physics"),
                           ("gz-sim-user-commands-system", "gz::sim::systems::UserCommands"),
                           ("gz-sim-scene-broadcaster-system", "gz::sim::systems::SceneBroadcaster")):
        ET.SubElement(world, "plugin", filename=filename, name=name)
    b = ET.SubElement(world, "plugin", filename="gz-sim-buoyancy-system", name="gz::sim::systems::Buoyancy")
    ET.SubElement(b, "uniform_fluid_density").text = num(robot.medium.density_kg_m3)
    _model(world, robot, water=True)
    ET.indent(root)
    return ET.ElementTree(root)


def sdf_bytes(robot: Robot) -> bytes:
    return ET.tostring(sdf_tree(robot).getroot(), encoding="utf-8", xml_declaration=True) + b"\n"


def world_bytes(robot: Robot) -> bytes:
    return ET.tostring(world_tree(robot).getroot(), encoding="utf-8", xml_declaration=True) + b"\n"
