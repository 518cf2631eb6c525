"""Motor mounts: one plate per motor on top of its mounting face, fixed to the hull wall (body frame, mm).

Numbers first (:func:`mount_numbers`), solid second (:func:`mount_solid`).

The plate (``swiftfin.layout.geometry.plate_thickness_mm`` thick) lies on the motor's face, z_face .. z_face + plate, over the
motor's frame along x and out to the hull's inner wall (less the assembly clearance) along y. It has the
NEMA hole pattern (clearance holes for the motor screws, heads on top), the hole for the motor's pilot boss
(a sliding fit: it centres the motor, so the spool axis lies exactly on ``motor_placements()``), and the
spool above it is free (its hub starts ``spool_dims().hub_bottom_mm`` above the face). Two tabs reach the
wall at ``swiftfin.layout.geometry.mount_fixings_mm``: a boss along the fixing normal with a pilot hole for the screw
through the hull wall (``hull.screw_diameter_mm``). Posts with pilot holes carry the guide blocks at the
points :func:`cad.guide.guide_blocks` gives (motor_mount_1 reaches aft under the bay guide for that).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from swiftfin.cad.kernel import Plane, Polygon, Solid, extrude

from swiftfin.cad.bought import pilot_hole_diameter_mm
from swiftfin.cad.guide import POST_RADIUS_FACTOR, assembly_gap_mm, guide_blocks
from swiftfin.layout.geometry import interior_half_width_at_height_mm, motor_placements, mount_fixings_mm, spool_dims
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params

TAB_DEPTH_FACTOR = 4.0
"""Depth of the wall screw's pilot hole / screw diameter [-] (thread engagement ~2 d plus the tip).
Engineering default."""
BOSS_BELOW_FACTOR = 3.0
"""Length of the boss under the plate at guide screws outside the motor's frame / guide screw diameter [-].
Engineering default (with the plate, >= 2 d of thread in an M2 pilot)."""
PLATE_OUTLINE_SAMPLES = 9
"""Stations along x at which the plate's edge follows the hull's inner wall (a polygon through them lies
inside the wall, whose half-width is concave in x)."""


@dataclass(frozen=True)
class Tab:
    axis_start_mm: tuple[float, float, float]   # inner end of the tab's axis
    axis_end_mm: tuple[float, float, float]     # end face centre, just inside the hull wall
    direction: tuple[float, float, float]       # outward (the fixing normal)
    radius_mm: float
    pilot_diameter_mm: float
    pilot_depth_mm: float
    fixing_point_mm: tuple[float, float, float]


@dataclass(frozen=True)
class Post:
    x_mm: float
    y_mm: float
    z_bottom_mm: float        # bottom of the boss below the plate, or the plate's bottom
    z_top_mm: float           # the guide block's underside
    radius_mm: float
    pilot_diameter_mm: float
    guide: str


@dataclass(frozen=True)
class MountNumbers:
    joint: int                                 # 1-based
    axis_xy_mm: tuple[float, float]
    z_bottom_mm: float                         # motor face
    z_top_mm: float
    outline_xy_mm: tuple[tuple[float, float], ...]   # plate outline (counter-clockwise)
    motor_holes_xy_mm: tuple[tuple[float, float], ...]
    motor_hole_diameter_mm: float
    pilot_hole_diameter_mm: float
    tabs: tuple[Tab, ...]
    posts: tuple[Post, ...]
    bed_face: str             # "bottom" (the motor face side) or "top": the flat face to print on

    @property
    def print_rotation(self) -> tuple[float, float, float]:
        return (0.0, 0.0, 0.0) if self.bed_face == "bottom" else (180.0, 0.0, 0.0)


def _inside_margin(p: Params, q) -> float:
    """How far the point q lies inside the hull's inner wall, measured along y [mm] (negative: outside)."""
    return interior_half_width_at_height_mm(p, -float(q[0]), float(q[2])) - abs(float(q[1]))


def mount_numbers(p: Params) -> tuple[MountNumbers, ...]:
    """The numbers of every mount (index j-1 for motor j). Raises UserError where a mount cannot fit."""
    d = spool_dims(p)
    m, pr = p.motor, p.print
    c = assembly_gap_mm(p)
    F = m.frame_size_mm
    wall = pr.perimeters * pr.line_width_mm
    fixings = mount_fixings_mm(p)
    blocks = guide_blocks(p)
    out = []
    for mp in motor_placements(p):
        label = f"motor_mount_{mp.joint + 1}"
        z0, z1 = mp.z_face_mm, mp.z_face_mm + d.plate_mm
        # posts for the guides this mount carries
        posts = []
        x_back = mp.x_mm - F / 2
        for b in blocks:
            if b.mount != label:
                continue
            r = POST_RADIUS_FACTOR * b.screw_diameter_mm
            for x, y in b.screw_points_mm:
                # a guide sitting on the plate gets bosses under the plate for thread length, where the motor
                # leaves room for them; a guide on posts has thread enough in its post
                outside_frame = x < mp.x_mm - F / 2 - r or x > mp.x_mm + F / 2 + r
                on_plate = b.seat_mm <= z1 + 1e-9
                zb = z0 - BOSS_BELOW_FACTOR * b.screw_diameter_mm if outside_frame and on_plate else z0
                posts.append(Post(x, y, zb, b.seat_mm, r, pilot_hole_diameter_mm(b.screw_diameter_mm), b.label))
                x_back = min(x_back, x - r - wall)
        x_front = mp.x_mm + F / 2
        xs = np.linspace(x_back, x_front, PLATE_OUTLINE_SAMPLES)
        hw = [min(interior_half_width_at_height_mm(p, -x, z0), interior_half_width_at_height_mm(p, -x, z1)) - c
              for x in xs]
        if min(hw) < F / 2:
            raise UserError(f"{label}: the hull is only {min(hw) + c:.1f} mm wide (half) at the mount plate, "
                            f"narrower than the motor frame ({F / 2:g} mm)")
        outline = [(float(x), -float(h)) for x, h in zip(xs, hw)] + \
                  [(float(x), float(h)) for x, h in zip(xs[::-1], hw[::-1])]
        hs = m.hole_spacing_mm / 2
        holes = tuple((mp.x_mm + sx * hs, sy * hs) for sx in (1, -1) for sy in (1, -1))
        # tabs at the wall fixings
        tabs = []
        sd = p.hull.screw_diameter_mm
        tr = POST_RADIUS_FACTOR * sd
        depth = TAB_DEPTH_FACTOR * sd
        for f in fixings:
            if f.part != label:
                continue
            P, n = np.asarray(f.point_mm), np.asarray(f.normal)
            e1 = np.array([1.0, 0.0, 0.0])
            e2 = np.cross(n, e1)
            gap = c
            for _ in range(400):
                end = P - gap * n
                rim = [end + tr * (math.cos(a) * e1 + math.sin(a) * e2) for a in np.linspace(0, 2 * math.pi, 37)]
                if min(_inside_margin(p, q) for q in rim) >= c:
                    break
                gap += 0.02
            else:
                raise UserError(f"{label}: no room for the wall-screw tab at {tuple(round(v, 1) for v in P)} mm: "
                                f"the hull wall curves away too fast for a {2 * tr:g} mm boss "
                                f"(hull.screw_diameter_mm = {sd:g})")
            end = P - gap * n
            start = end - (depth + 1.0) * n
            tabs.append(Tab(tuple(start), tuple(end), tuple(n), tr, pilot_hole_diameter_mm(sd), depth, f.point_mm))
        up = any(q.z_top_mm > z1 + 1e-9 for q in posts)
        down = any(q.z_bottom_mm < z0 - 1e-9 for q in posts)
        if up and down:
            raise UserError(f"{label}: the guide posts would stand both above and below the plate (no flat face "
                            f"to print it on); this layout of guides is not supported")
        out.append(MountNumbers(mp.joint + 1, (mp.x_mm, 0.0), z0, z1, tuple(outline), holes,
                                m.mount_screw_diameter_mm + 2 * pr.clearance_sliding_mm,
                                m.pilot_diameter_mm + pr.clearance_sliding_mm, tuple(tabs), tuple(posts),
                                "top" if down else "bottom"))
    return tuple(out)


def mount_solid(n: MountNumbers) -> Solid:
    """The mount in the body frame at rest: plate, tabs, posts; motor holes, pilot bore and pilot holes."""
    z0, z1 = n.z_bottom_mm, n.z_top_mm
    plate = extrude(Polygon(*n.outline_xy_mm, align=None), z1 - z0).solids()[0].translate((0, 0, z0))
    adds = []
    for t in n.tabs:
        length = float(np.linalg.norm(np.subtract(t.axis_end_mm, t.axis_start_mm)))
        adds.append(Solid.make_cylinder(t.radius_mm, length, Plane(origin=t.axis_start_mm, z_dir=t.direction)))
    for q in n.posts:
        if q.z_top_mm > q.z_bottom_mm:
            adds.append(Solid.make_cylinder(q.radius_mm, q.z_top_mm - q.z_bottom_mm,
                                            Plane(origin=(q.x_mm, q.y_mm, q.z_bottom_mm))))
    body = plate.fuse(*adds) if adds else plate
    # the face that goes on the print bed is flat: the tabs (and nothing else) are cut off beyond it
    x_all = [x for x, _ in n.outline_xy_mm]
    z_cut = z0 - 20.0 if n.bed_face == "bottom" else z1
    beyond = Solid.make_box(max(x_all) - min(x_all) + 40, 200, 20.0).translate((min(x_all) - 20, -100, z_cut))
    for q in n.posts:   # keep the posts and bosses
        lo, hi = (q.z_bottom_mm, z0) if n.bed_face == "bottom" else (z1, q.z_top_mm)
        if hi > lo:
            beyond = beyond.cut(Solid.make_cylinder(q.radius_mm + 0.01, hi - lo + 0.01,
                                                    Plane(origin=(q.x_mm, q.y_mm, lo - 0.005))))
    cutters = [beyond]
    r_p = n.pilot_hole_diameter_mm / 2
    cutters.append(Solid.make_cylinder(r_p, z1 - z0 + 2, Plane(origin=(n.axis_xy_mm[0], n.axis_xy_mm[1], z0 - 1))))
    for x, y in n.motor_holes_xy_mm:
        cutters.append(Solid.make_cylinder(n.motor_hole_diameter_mm / 2, z1 - z0 + 2, Plane(origin=(x, y, z0 - 1))))
    for t in n.tabs:
        origin = np.asarray(t.axis_end_mm) - t.pilot_depth_mm * np.asarray(t.direction)
        cutters.append(Solid.make_cylinder(t.pilot_diameter_mm / 2, t.pilot_depth_mm + 1.0,
                                           Plane(origin=tuple(origin), z_dir=t.direction)))
    for q in n.posts:
        cutters.append(Solid.make_cylinder(q.pilot_diameter_mm / 2, q.z_top_mm - q.z_bottom_mm + 1.0,
                                           Plane(origin=(q.x_mm, q.y_mm, q.z_bottom_mm - 0.5))))
    body = body.cut(*cutters)
    solids = body.solids()
    if len(solids) != 1:
        raise RuntimeError(f"motor_mount_{n.joint}: expected one solid, got {len(solids)}")
    return solids[0]


def make_motor_mounts(p: Params) -> list[PartSpec]:
    """``motor_mount_<j>`` per motor, link 0, printed on its flat face (``MountNumbers.bed_face``)."""
    return [PartSpec(label=f"motor_mount_{n.joint}", solid=mount_solid(n), link=0, family="mount",
                     print_rotation=n.print_rotation,
                     meta={"joint": n.joint, "guides": sorted({q.guide for q in n.posts})})
            for n in mount_numbers(p)]
