"""Motor mounts: the solids, made from the numbers of :mod:`swiftfin.layout.mount_plate_plan` (the plate's outline,
its guide posts and wall fixings; that module's docstring gives the arrangement and why): the plate extruded from
its outline on the motor's face, the wall screws' bosses, the posts, the spot faces under the motor screws' heads
and the pilot bore. The screws' holes are cut by the registry from the mounts' fastener records.
"""
from __future__ import annotations

import numpy as np
from swiftfin.cad.kernel import Plane, Polygon, Solid, extrude

from swiftfin.cad.part import PartSpec
from swiftfin.core.schema import Params
from swiftfin.layout.mount_plan import WallFixing
from swiftfin.layout.mount_plate_plan import MountNumbers, mount_numbers


def boss_solid(f: WallFixing, z_bed_mm: float) -> Solid:
    """A wall screw's boss: a cylinder along the screw's axis from the face, over a block down past the print face
    (cut flush with it by :func:`mount_solid`)."""
    axis = np.asarray(f.axis)
    x_dir = np.array([float(f.side), 0.0, 0.0])          # local y then points up on both sides
    y_dir = np.cross(axis, x_dir)
    face = np.asarray(f.face_mm)
    r, length = f.boss_radius_mm, f.boss_length_mm
    cyl = Solid.make_cylinder(r, length, Plane(origin=tuple(face), x_dir=tuple(x_dir), z_dir=tuple(axis)))
    h = (face[2] - z_bed_mm) / max(y_dir[2], 0.5) + 2.0
    corner = face - r * x_dir - h * y_dir
    block = Solid.make_box(2 * r, h, length, Plane(origin=tuple(corner), x_dir=tuple(x_dir), z_dir=tuple(axis)))
    return cyl.fuse(block)


def mount_solid(n: MountNumbers) -> Solid:
    """The mount in the body frame at rest: plate, wall-screw bosses, posts, spot faces; the pilot bore. The screws'
    holes (inserts, motor screw clearance) are cut by the registry from the fastener records."""
    z0, z1 = n.z_bottom_mm, n.z_top_mm
    plate = extrude(Polygon(*n.outline_xy_mm, align=None), z1 - z0).solids()[0].translate((0, 0, z0))
    adds = [boss_solid(f, z0) for f in n.fixings]
    for q in n.posts:
        if q.z_top_mm > q.z_bottom_mm:
            adds.append(Solid.make_cylinder(q.radius_mm, q.z_top_mm - q.z_bottom_mm,
                                            Plane(origin=(q.x_mm, q.y_mm, q.z_bottom_mm))))
    if n.spot_face_mm > 0:
        for x, y in n.motor_holes_xy_mm:
            adds.append(Solid.make_cylinder(n.spot_face_radius_mm, n.spot_face_mm + 0.01,
                                            Plane(origin=(x, y, z1 - 0.01))))
    body = plate.fuse(*adds)
    # the face that goes on the print bed is flat: the bosses' blocks (and nothing else) are cut off beyond it
    x_all = [x for x, _ in n.outline_xy_mm]
    beyond = Solid.make_box(max(x_all) - min(x_all) + 40, 200, 20.0).translate((min(x_all) - 20, -100, z0 - 20.0))
    for q in n.posts:   # keep posts reaching below the plate
        if q.z_bottom_mm < z0:
            beyond = beyond.cut(Solid.make_cylinder(q.radius_mm + 0.01, z0 - q.z_bottom_mm + 0.01,
                                                    Plane(origin=(q.x_mm, q.y_mm, q.z_bottom_mm - 0.005))))
    r_p = n.pilot_hole_diameter_mm / 2
    pilot = Solid.make_cylinder(r_p, z1 - z0 + 2, Plane(origin=(n.axis_xy_mm[0], n.axis_xy_mm[1], z0 - 1)))
    body = body.cut(beyond, pilot)
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


