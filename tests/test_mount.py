"""Motor mounts: hole pattern and pilot on the motor placement, plate inside the hull, tabs on the fixings,
posts under the guides."""
from __future__ import annotations

import math

import numpy as np
import pytest
from build123d import Vector
from OCP.BRepAdaptor import BRepAdaptor_Surface

from swiftfin.layout import geometry as L
from swiftfin.cad.bought import pilot_hole_diameter_mm
from swiftfin.cad.guide import guide_blocks
from swiftfin.cad.mount import make_motor_mounts, mount_numbers, mount_solid
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params
from tests.golden_check import check_golden
from tests.test_spool import mesh_of


@pytest.fixture(scope="session")
def mounts():
    return make_motor_mounts(Params())


def _cylinders(solid):
    out = []
    for f in solid.faces():
        if f.geom_type.name == "CYLINDER":
            c = BRepAdaptor_Surface(f.wrapped).Cylinder()
            o, d = c.Axis().Location(), c.Axis().Direction()
            out.append((c.Radius(), np.array([o.X(), o.Y(), o.Z()]), np.array([d.X(), d.Y(), d.Z()])))
    return out


def _on_axis(q, origin, direction) -> float:
    w = np.asarray(q) - origin
    return float(np.linalg.norm(w - (w @ direction) * direction))


def test_labels_and_validity(mounts):
    p = Params()
    assert [m.label for m in mounts] == [f"motor_mount_{j}" for j in range(1, p.joints.count + 1)]
    tol = p.export.mesh_tolerance_mm
    for m in mounts:
        assert m.link == 0 and m.family == "mount" and m.printed
        assert m.solid.is_valid and len(m.solid.solids()) == 1
        mesh = mesh_of(m.solid, tol)
        assert mesh.is_watertight
        assert mesh.volume == pytest.approx(m.solid.volume, abs=m.solid.area * tol)


@pytest.mark.parametrize("label", [f"motor_mount_{j}" for j in range(1, 5)])
def test_golden(mounts, label, update_golden):
    check_golden(label, next(m for m in mounts if m.label == label).solid, update_golden)


def test_hole_pattern_and_pilot_on_the_motor_axis(mounts):
    """Measured on the solid: four screw holes on the NEMA square and the pilot bore centred on the motor
    placement, so the motor (and the spool on its shaft) stands exactly on the layout's axis."""
    p = Params()
    m, clr = p.motor, p.print.clearance_sliding_mm
    for mm, mp in zip(mounts, L.motor_placements(p)):
        cyl = _cylinders(mm.solid)
        vertical = [(r, o) for r, o, d in cyl if abs(abs(d[2]) - 1) < 1e-9]
        holes = {(round(o[0] - mp.x_mm, 6), round(o[1], 6)) for r, o in vertical
                 if abs(r - (m.mount_screw_diameter_mm / 2 + clr)) < 1e-9}
        hs = m.hole_spacing_mm / 2
        assert holes == {(sx * hs, sy * hs) for sx in (1, -1) for sy in (1, -1)}
        pilot = [o for r, o in vertical if abs(r - (m.pilot_diameter_mm + clr) / 2) < 1e-9]
        assert pilot and all(math.hypot(o[0] - mp.x_mm, o[1]) < 1e-9 for o in pilot)


def test_plate_on_the_motor_face(mounts):
    p = Params()
    t = L.plate_thickness_mm(p)
    assert t == pytest.approx(max(3.0, 8 * 0.45))
    for mm, mp in zip(mounts, L.motor_placements(p)):
        x = mp.x_mm + p.motor.frame_size_mm / 2 - 1.0   # a spot of plain plate near the front edge
        for z, inside in ((mp.z_face_mm - 0.01, False), (mp.z_face_mm + 0.01, True),
                          (mp.z_face_mm + t - 0.01, True), (mp.z_face_mm + t + 0.01, False)):
            assert mm.solid.is_inside(Vector(x, 0.0, z)) == inside
        if mm.label != "motor_mount_1":   # only the rear mount has bosses under its plate (aft of its motor)
            assert mm.solid.bounding_box().min.Z == pytest.approx(mp.z_face_mm, abs=1e-9)


def test_inside_the_hull_with_clearance(mounts):
    p = Params()
    c = p.print.clearance_assembly_mm
    for mm in mounts:
        verts, _ = mm.solid.tessellate(0.01, 0.1)
        for q in verts:
            assert L.interior_half_width_at_height_mm(p, -q.X, q.Z) - abs(q.Y) >= c - 0.05, mm.label


def test_tabs_on_the_fixings(mounts):
    """The wall screw's pilot hole lies on the fixing's normal through the fixing point, and the tab's end
    stands off the wall by at least the assembly clearance and by little more."""
    p = Params()
    r_pilot = pilot_hole_diameter_mm(p.hull.screw_diameter_mm) / 2
    for mm in mounts:
        fixings = [f for f in L.mount_fixings_mm(p) if f.part == mm.label]
        assert len(fixings) == 2
        pilots = [(o, d) for r, o, d in _cylinders(mm.solid) if abs(r - r_pilot) < 1e-9]
        for f in fixings:
            assert any(_on_axis(f.point_mm, o, d) < 1e-6 and abs(abs(d @ f.normal) - 1) < 1e-9 for o, d in pilots)
        for t in next(n for n in mount_numbers(p) if f"motor_mount_{n.joint}" == mm.label).tabs:
            gap = float(np.linalg.norm(np.subtract(t.fixing_point_mm, t.axis_end_mm)))
            assert p.print.clearance_assembly_mm <= gap < p.print.clearance_assembly_mm + 1.0


def test_posts_carry_the_guides(mounts):
    p = Params()
    blocks = guide_blocks(p)
    r_pilot = pilot_hole_diameter_mm(p.guides.screw_diameter_mm) / 2
    for b in blocks:
        mm = next(m for m in mounts if m.label == b.mount)
        pilots = [o for r, o, d in _cylinders(mm.solid) if abs(r - r_pilot) < 1e-9 and abs(abs(d[2]) - 1) < 1e-9]
        for x, y in b.screw_points_mm:
            assert any(math.hypot(o[0] - x, o[1] - y) < 1e-9 for o in pilots), (b.label, x, y)
            # the post's top is the guide's underside: solid just below it, air just above
            q = (x + 2 * r_pilot, y)
            assert mm.solid.is_inside(Vector(q[0], q[1], b.seat_mm - 0.01))
            assert not mm.solid.is_inside(Vector(q[0], q[1], b.seat_mm + 0.01))
    assert {b.mount for b in blocks} == {m.label for m in mounts}


@pytest.mark.parametrize("changes", [
    {"spool.drum_diameter_mm": 30.0, "spool.wraps": 3.0},
    {"joints.count": 3, "joints.stations_fraction": (0.55, 0.65, 0.75)},
])
def test_other_designs_build_valid_mounts(changes):
    p = Params()
    for k, v in changes.items():
        p = replace_key(p, k, v)
    numbers = mount_numbers(p)
    assert len(numbers) == p.joints.count
    for n in (numbers[0], numbers[-1]):
        s = mount_solid(n)
        assert s.is_valid and len(s.solids()) == 1


def test_print_orientation_puts_the_plate_on_the_bed(mounts):
    from build123d import Axis
    p = Params()
    for mm, n in zip(mounts, mount_numbers(p)):
        rx, ry, rz = mm.print_rotation
        rotated = mm.solid.rotate(Axis.X, rx).rotate(Axis.Y, ry).rotate(Axis.Z, rz)
        zmin = rotated.bounding_box().min.Z
        bed = sum(f.area for f in rotated.faces() if f.geom_type.name == "PLANE" and abs(f.center().Z - zmin) < 1e-6
                  and abs(abs(f.normal_at().Z) - 1) < 1e-9)
        xy = np.asarray(n.outline_xy_mm)
        outline = 0.5 * abs(np.dot(xy[:, 0], np.roll(xy[:, 1], 1)) - np.dot(xy[:, 1], np.roll(xy[:, 0], 1)))
        holes = math.pi * (n.pilot_hole_diameter_mm**2 + 4 * n.motor_hole_diameter_mm**2) / 4
        assert bed > 0.95 * (outline - holes), mm.label


@pytest.fixture(scope="session")
def drive_train(mounts):
    from swiftfin.cad.bought import make_bought_parts
    from tests.test_guide import default_guides
    from tests.test_spool import default_spools
    motors = [b for b in make_bought_parts(Params()) if b.label.startswith("motor_")]
    return list(default_spools()) + list(mounts) + list(default_guides()) + motors


def test_drive_train_parts_keep_their_clearances(drive_train):
    """The assembly's own check on spools, mounts, guides and motors: inside the hull, and every pair at least
    print.clearance_assembly_mm apart (on the meshes) except the pairs meant to touch."""
    from swiftfin.cad.assembly import CONTACTS, Contact, Placed, check_assembly
    from swiftfin.exports.files import tessellate
    p = Params()
    meant = (Contact("motor_mount_*", "motor_[0-9]*", "motor face screwed to its plate", 0),
             Contact("spool_*", "motor_[0-9]*", "spool on its motor's shaft (sliding fit, set screw)", 0),
             Contact("guide_exit_*", "motor_mount_*", "exit guide screwed onto its mount's posts", 0),
             Contact("guide_bay", "motor_mount_1", "bay guide screwed onto the rear mount"))
    placed = []
    for s in drive_train:
        m = tessellate(s.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        placed.append(Placed(s.label, s.link, s.family, m.vertices, m.faces))
    stats = check_assembly(p, placed, contacts=tuple(CONTACTS) + meant)
    n = len(placed)
    assert stats["pairs"] + stats["contact_pairs"] == n * (n - 1) // 2
    assert stats["contact_pairs"] == 4 + 4 + 3 + 1


def test_a_spool_moved_into_its_guide_is_caught(drive_train):
    """The clearance test above can fail: shift spool 2 by 1 mm toward the exit guide behind it."""
    from swiftfin.cad.assembly import Placed, check_assembly
    from swiftfin.exports.files import tessellate
    from swiftfin.core.errors import BuildError
    p = Params()
    spool = next(s for s in drive_train if s.label == "spool_2")
    guide = next(s for s in drive_train if s.label == "guide_exit_2")
    placed = []
    for s, dx in ((spool, -1.0), (guide, 0.0)):
        m = tessellate(s.solid.translate((dx, 0, 0)), p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        placed.append(Placed(s.label, s.link, s.family, m.vertices, m.faces))
    with pytest.raises(BuildError, match="spool_2 and guide_exit_2"):
        check_assembly(p, placed, contacts=())
