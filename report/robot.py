"""The report's robot section: what the simulator files say, read back from them (robot/swiftfin.urdf, the
collision meshes, swiftfin_world.sdf), shown as a picture and a table. It reads files; it computes nothing
about the design.

The picture draws every link's collision shapes (one convex hull per part) at rest, each link in its own
colour, with each joint's axis as a dark bar through the hull and each link frame's origin as a small cube, so
a reader sees frames, axes and collision shapes where a simulator will put them.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from swiftfin.report.markup import esc, img, num, table

LINK_COLORS = ((0.16, 0.45, 0.70), (0.86, 0.50, 0.18), (0.22, 0.62, 0.34), (0.75, 0.24, 0.22), (0.52, 0.38, 0.70),
               (0.55, 0.34, 0.29), (0.85, 0.45, 0.70), (0.45, 0.45, 0.45), (0.70, 0.70, 0.20))
AXIS_COLOR = (0.10, 0.10, 0.12)


def _floats(text: str | None) -> np.ndarray:
    return np.array([float(v) for v in (text or "0 0 0").split()])


def _obj(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of the OBJ files our exporter writes (v and f lines only)."""
    v, f = [], []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:4]])
    return np.asarray(v, dtype=float), np.asarray(f, dtype=np.int64)


def _box(centre, size) -> tuple[np.ndarray, np.ndarray]:
    c, h = np.asarray(centre, dtype=float), np.asarray(size, dtype=float) / 2
    v = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float) * h + c
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
                  [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int64)
    return v, f


def read_robot(robot_dir: Path) -> dict:
    """Links (mass, COM, collision meshes), joints (origin, axis, range, effort) and each link's origin at rest in
    the model frame [m], from the URDF; each link's Gazebo derivatives and buoyancy volume from the world SDF."""
    urdf = ET.parse(robot_dir / "swiftfin.urdf").getroot()
    links = {}
    for el in urdf.findall("link"):
        inert = el.find("inertial")
        links[el.get("name")] = {
            "mass_kg": float(inert.find("mass").get("value")),
            "com_m": _floats(inert.find("origin").get("xyz")),
            "collisions": [robot_dir / c.find("geometry/mesh").get("filename")
                           for c in el.findall("collision") if c.find("geometry/mesh") is not None]}
    joints = []
    origin = {urdf.find("link").get("name"): np.zeros(3)}
    for el in urdf.findall("joint"):
        parent, child = el.find("parent").get("link"), el.find("child").get("link")
        xyz = _floats(el.find("origin").get("xyz"))
        origin[child] = origin[parent] + xyz
        lim = el.find("limit")
        joints.append({"name": el.get("name"), "parent": parent, "child": child, "origin_m": origin[child],
                       "axis": _floats(el.find("axis").get("xyz")), "lower": float(lim.get("lower")),
                       "upper": float(lim.get("upper")), "effort": float(lim.get("effort"))})
    world = robot_dir / "swiftfin_world.sdf"
    if world.is_file():
        root = ET.parse(world).getroot()
        for pl in root.iter("plugin"):
            name = pl.findtext("link_name")
            if name in links:
                links[name]["hydro"] = {c.tag: float(c.text) for c in pl if c.tag not in ("link_name", "water_density")}
        for el in root.iter("link"):
            col = el.find("collision/geometry/ellipsoid/radii")
            if el.get("name") in links and col is not None:
                links[el.get("name")]["buoyancy_volume_m3"] = 4 / 3 * np.pi * float(np.prod(_floats(col.text)))
    return {"links": links, "joints": joints, "origin_m": origin}


def robot_items(robot: dict):
    """MeshItems (body frame, mm) of the collision shapes, the joint axes and the link-frame origins."""
    from swiftfin.report.render import MeshItem

    items = []
    for k, (name, lk) in enumerate(robot["links"].items()):
        o = robot["origin_m"][name]
        for path in lk["collisions"]:
            v, f = _obj(path)
            items.append(MeshItem((v + o) * 1000.0, f, LINK_COLORS[k % len(LINK_COLORS)], f"{name}:{path.stem}"))
        items.append(MeshItem(*_box(o * 1000.0, (6.0, 6.0, 6.0)), AXIS_COLOR, f"{name}:frame"))
    for jt in robot["joints"]:
        a = jt["axis"] / (np.linalg.norm(jt["axis"]) or 1.0)
        size = np.abs(a) * 110.0 + (1 - np.abs(a)) * 2.5       # a bar 110 mm long along the axis
        items.append(MeshItem(*_box(jt["origin_m"] * 1000.0, size), AXIS_COLOR, f"{jt['name']}:axis"))
    return items


def swim_table(swim: list[dict] | None) -> str:
    """The exported fish swimming in MuJoCo (handed in by the build), beside published stride lengths."""
    from swiftfin.physics.swim_sim import PUBLISHED_STRIDES
    from swiftfin.report.markup import notice

    if not swim:
        return notice("Swimming not run in this build (<code>swiftfin build --swim</code> runs the exported fish in "
                      "MuJoCo at 1, 2 and 3 Hz and shows it here).")
    rows = [[num(r["frequency_hz"], "g", "Hz"), num(r["quasi_steady_m_s"], ".3f", "m/s"),
             num(r["stride_quasi_steady"], ".2f"), num(r["reactive_m_s"], ".3f", "m/s"), num(r["stride_reactive"], ".2f"),
             num(r["slip_reactive"], ".2f")] for r in swim]
    refs = "".join(f"<li>{esc(name)}: {stride:.2f} body lengths per tail beat ({esc(src)})</li>"
                   for name, stride, src in PUBLISHED_STRIDES)
    return (f'<p class="lead">The exported fish, free in six degrees of freedom in MuJoCo, {swim[0]["duration_s"]:g} s '
            "per run, mean over the last half: with MuJoCo's quasi-steady fluid model alone, and with Lighthill's "
            "reactive force at the fin's trailing edge (stride U / (f L), slip U / (f &lambda;)).</p>"
            + table(["frequency", "quasi-steady speed", "stride", "with reactive force", "stride", "slip"], rows,
                    "robot-swim", None, {0, 1, 2, 3, 4, 5})
            + f"<p>Published, for comparison (nothing is fitted to them):</p><ul>{refs}</ul>")


def robot_section(robot_dir: Path | None, picture: bytes | None, swim: list[dict] | None = None) -> str:
    from swiftfin.report.markup import notice

    if robot_dir is None or not (robot_dir / "swiftfin.urdf").is_file():
        return notice("No simulator files in this folder: the robot section needs a build's <code>robot/</code>.")
    robot = read_robot(robot_dir)
    rows = []
    for name, lk in robot["links"].items():
        h = lk.get("hydro", {})
        rows.append([f"<code>{esc(name)}</code>", num(1000 * lk["mass_kg"], ".1f", "g"),
                     esc(", ".join(f"{1000 * c:+.1f}" for c in lk["com_m"])) + "&nbsp;mm",
                     num(1e6 * lk.get("buoyancy_volume_m3", float("nan")), ".1f", "cm\u00b3"),
                     str(len(lk["collisions"])),
                     num(-h.get("yDotV", float("nan")), ".3f", "kg"), num(-h.get("nDotR", float("nan")) * 1e4, ".2f",
                                                                        "kg&nbsp;cm\u00b2")])
    jrows = [[f"<code>{esc(j['name'])}</code>", esc(f"{j['parent']} \u2192 {j['child']}"),
              esc(", ".join(f"{1000 * c:+.1f}" for c in j["origin_m"])) + "&nbsp;mm",
              esc(" ".join(f"{c:g}" for c in j["axis"])),
              f"\u00b1{np.degrees(j['upper']):.1f}&nbsp;deg", num(j["effort"], ".3f", "N&middot;m")]
             for j in robot["joints"]]
    pic = (f'<figure>{img(picture, "collision shapes, joint axes and link frames")}<figcaption>What a simulator sees: '
           f"each link's collision shapes (one convex hull per part) in its own colour, each joint's axis as a dark "
           f"bar, each link frame's origin as a small cube; body frame, at rest, nose left.</figcaption></figure>"
           if picture else "")
    return (pic + '<p class="lead">Read back from <code>robot/swiftfin.urdf</code> and <code>swiftfin_world.sdf'
            '</code>: dry link masses and centres of mass (link frame), the volume Gazebo\'s buoyancy system sees, '
            'the collision shapes, and the lateral added mass and yaw added inertia of each link.</p>'
            + table(["link", "mass", "COM", "buoyancy volume", "collision shapes", "sway added mass",
                     "yaw added inertia"], rows, "robot-links", None, {1, 3, 5, 6})
            + table(["joint", "links", "origin (model frame)", "axis", "range", "effort"], jrows, "robot-joints",
                    None, {5})
            + "<h3>Swimming</h3>" + swim_table(swim))
