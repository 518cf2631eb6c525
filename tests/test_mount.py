"""Motor mounts: hole pattern and pilot on the motor placement, plate inside the hull, wall screws into inserts in
bosses (pockets inside material, nothing through the print face), the wall screws' loads against their capacity,
the motor's screws reaching its thread, posts with inserts under the guides."""
from __future__ import annotations

import math

import numpy as np
import pytest
from build123d import Vector
from OCP.BRepAdaptor import BRepAdaptor_Surface

from swiftfin.layout import geometry as L
from swiftfin.catalogues.fasteners import fastener
from swiftfin.cad.fastening import all_fasteners
from swiftfin.layout.guide_plan import guide_blocks
from swiftfin.cad.mount import mount_solid
from swiftfin.layout.mount_plate_plan import mount_numbers
from swiftfin.layout.mount_plan import mount_wall_loads, motor_screw_fit, wall_fixings
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params
from tests.golden_check import check_golden
from tests.test_spool import mesh_of


@pytest.fixture(scope="session")
def mounts(default_parts):
    """The mounts as built, with their fasteners' holes (the registry's family function): the session's default
    build's."""
    return [ps for ps in default_parts if ps.family == "mount"]


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
                 if abs(r - fastener(m.mount_screw_diameter_mm).clearance_hole_mm / 2) < 1e-9}
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


def _probe_wall(solid, centre, direction, start_mm: float, step_mm: float = 0.25, limit_mm: float = 20.0) -> float:
    """Solid met along ``direction`` from ``centre + start * direction`` before the first air [mm] (coarse steps,
    then bisection to 0.01 mm)."""
    d, c = np.asarray(direction, dtype=float), np.asarray(centre, dtype=float)

    def solid_at(u):
        return solid.is_inside(Vector(*(c + u * d)))

    lo = start_mm
    if not solid_at(lo):
        return 0.0
    hi = lo + step_mm
    while solid_at(hi):
        lo, hi = hi, hi + step_mm
        if hi - start_mm > limit_mm:
            return limit_mm
    while hi - lo > 0.01:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if solid_at(mid) else (lo, mid)
    return lo - start_mm


def _pocket_walls(solid, f) -> tuple[float, float]:
    """(least wall round the insert pocket of fastener ``f``, least wall under it to the print face z = z_bed),
    measured on the solid by rays from the pocket's surface."""
    s = f.screw
    axis = np.asarray(f.axis)
    e1 = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 0.0, 1.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    r = s.insert_hole_mm / 2
    least = math.inf
    for u in np.linspace(0.2, s.insert_pocket_depth_mm - 0.2, 5):
        c = f.point_mm(f.grip_mm + u)
        assert not solid.is_inside(Vector(*c)), (f.label, "no pocket")
        for a in np.linspace(0, 2 * math.pi, 16, endpoint=False):
            d = math.cos(a) * e1 + math.sin(a) * e2
            least = min(least, _probe_wall(solid, c, d, r + 0.01))
    return least


def test_wall_screw_inserts_fully_inside_material(mounts):
    """Every wall screw's insert pocket is there, and the wall round it (measured by rays on the solid, the
    direction of the print face included) is at least the insert maker's wall and two lines; no pocket reaches the
    print face (the old pilot's floor thinned to nothing there)."""
    p = Params()
    lw = p.print.line_width_mm
    by_label = {m.label: m.solid for m in mounts}
    screws = [f for f in all_fasteners(p) if "_wall_" in f.label]
    assert len(screws) == 4 * p.joints.count
    worst = math.inf
    for f in screws:
        solid = by_label[f.thread_part]
        assert f.seat == "insert" and f.head_part.endswith("_upper") and not f.problems()
        wall = _pocket_walls(solid, f)
        need = max(2 * lw, f.screw.insert_wall_min_mm)
        assert wall >= need - 0.03, (f.label, wall, need)
        worst = min(worst, wall)
        # straight down from the pocket's lowest line to the print face: solid all the way
        n = next(q for q in mount_numbers(p) if f"motor_mount_{q.joint}" == f.thread_part)
        for u in np.linspace(0.2, f.screw.insert_pocket_depth_mm - 0.2, 4):
            c = f.point_mm(f.grip_mm + u)
            low = c[2] - f.screw.insert_hole_mm / 2 / math.sqrt(1 - f.axis[2] ** 2) - 0.05   # the tilted pocket's wall
            for z in np.linspace(n.z_bottom_mm + 0.02, low, 6):
                assert solid.is_inside(Vector(c[0], c[1], z)), (f.label, u, z)
    print(f"least wall round a wall-screw insert: {worst:.2f} mm")


def test_wall_screws_carry_the_cables(mounts):
    """The cables' design tension (pretension + what the motor can hold) through every mount's wall screws:
    per screw, shear / bearing capacity + axial / pull-out capacity <= 1 in the hull's pad and in the mount's boss
    (sustained-load allowables of catalogues/printed_strength.toml). Closed form for a mount whose cables leave
    straight aft and level (mounts 2-4): the bolt group's shear is F/n aft plus M / (n dx) vertical."""
    p = Params()
    loads = {m.mount: m for m in mount_wall_loads(p)}
    for ml in loads.values():
        assert ml.usage <= 1.0 + 1e-9, (ml.mount, ml.usage)
        assert len(ml.shear_n) == 4
    ml = loads["motor_mount_3"]
    fx = [f for f in wall_fixings(p) if f.mount == "motor_mount_3"]
    F = -ml.force_n[0]
    T = p.cable.pretension_n + p.motor.holding_torque_nm / (p.spool.drum_diameter_mm * 1e-3)
    assert F == pytest.approx(2 * T, rel=1e-6)
    dx = abs(fx[0].point_mm[0] - fx[1].point_mm[0]) / 2 * 1e-3
    shear = math.hypot(F / 4, abs(ml.moment_nm[1]) / (4 * dx))
    assert max(ml.shear_n) == pytest.approx(shear, rel=0.05)


@pytest.fixture(scope="session")
def rear_head_half():
    """The upper half of the hull piece that holds motor_mount_1's wall screws, with its holes."""
    from swiftfin.cad.fastening import apply_fasteners
    from swiftfin.cad.hull import hull_pieces, piece_parts
    p = Params()
    x = wall_fixings(p)[0].point_mm[0]
    pc = next(q for q in hull_pieces(p) if q.s_start_mm <= -x <= q.s_end_mm)
    return next(s for s in apply_fasteners(p, piece_parts(p, pc)) if s.label.endswith("_upper"))


def test_wall_screw_heads_sunk_in_the_hull_pads(rear_head_half):
    """On the hull's solid: the counterbore open over the head, the head's bearing floor (the pad under it) as thick as
    the load needs (measured off the clearance hole), the clearance hole open through the pad."""
    p = Params()
    hull = rear_head_half.solid
    for fx in wall_fixings(p):
        f = next(q for q in all_fasteners(p) if q.label == fx.label)
        if f.head_part != rear_head_half.label:
            continue
        s = f.screw
        axis = np.asarray(f.axis)
        assert not hull.is_inside(Vector(*f.point_mm(-0.3)))             # counterbore above the head
        assert not hull.is_inside(Vector(*f.point_mm(fx.floor_mm / 2)))   # clearance hole
        side = np.array([1.0, 0.0, 0.0])
        off = s.clearance_hole_mm / 2 + 0.3
        floor = _probe_wall(hull, np.asarray(f.head_mm) + off * side, axis, 0.01)
        assert floor >= fx.floor_mm - 0.05, (f.label, floor, fx.floor_mm)
        # the pad stands the assembly gap off the mount's boss face
        assert f.grip_mm == pytest.approx(fx.floor_mm + p.print.clearance_assembly_mm
                                          + 2 * p.export.mesh_tolerance_mm)


def test_motor_screws_reach_the_motors_thread(mounts):
    """The NEMA screws: a catalogue length, the head on its spot face (solid under it, air over it), the clearance
    hole through the plate, the tip in the motor's tapped hole between 1 d deep and the thread's end less the
    margin (measured from the motor's face on the built motor)."""
    from swiftfin.cad.bought import make_bought_parts
    from swiftfin.layout.fastening import TAPPED_TIP_MARGIN_MM
    p = Params()
    motors = {b.label: b.solid for b in make_bought_parts(p) if b.label.startswith("motor_")}
    by_label = {m.label: m.solid for m in mounts}
    fit = motor_screw_fit(p)
    screws = [f for f in all_fasteners(p) if "_motor_" in f.label and f.label.startswith("motor_mount_")]
    assert len(screws) == 4 * p.joints.count
    for f in screws:
        assert f.seat == "tapped" and not f.problems()
        assert f.length_mm in f.screw.lengths_mm
        mount, motor = by_label[f.head_part], motors[f.thread_part]
        face = motor.bounding_box().max.Z - p.motor.shaft_length_mm     # the shaft stands on the face
        tip = np.asarray(f.tip_mm)
        depth = face - tip[2]
        assert f.screw.nominal_diameter_mm - 1e-9 <= depth <= p.motor.mount_hole_depth_mm - TAPPED_TIP_MARGIN_MM + 1e-9
        assert motor.is_inside(Vector(*(tip + [0, 0, 0.1])))             # the tip is in the motor's body
        head = np.asarray(f.head_mm)
        rim = head + np.array([f.screw.clearance_hole_mm / 2 + 0.3, 0, 0])
        assert mount.is_inside(Vector(*(rim - [0, 0, 0.05]))) and not mount.is_inside(Vector(*(rim + [0, 0, 0.05])))
        assert not mount.is_inside(Vector(*(head - [0, 0, fit.grip_mm / 2])))


def test_posts_carry_the_guides_on_inserts(mounts):
    """Each guide screw point has a post whose top is the guide's underside, with the guide screw's insert pocket
    in it: the pocket open on the axis, the insert maker's wall round it (measured on the solid)."""
    p = Params()
    blocks = guide_blocks(p)
    by_label = {m.label: m.solid for m in mounts}
    screws = {(round(f.head_mm[0], 6), round(f.head_mm[1], 6)): f for f in all_fasteners(p)
              if f.label.startswith("guide_")}
    for b in blocks:
        mm = by_label[b.mount]
        for x, y in b.screw_points_mm:
            f = screws[(round(x, 6), round(y, 6))]
            assert f.thread_part == b.mount and f.seat == "insert"
            r = f.screw.insert_hole_mm / 2
            q = (x + r + 0.3, y)
            assert mm.is_inside(Vector(q[0], q[1], b.seat_mm - 0.01))
            assert not mm.is_inside(Vector(q[0], q[1], b.seat_mm + 0.01))
            wall = _pocket_walls(mm, f)
            assert wall >= max(2 * p.print.line_width_mm, f.screw.insert_wall_min_mm) - 0.03, (f.label, wall)
    assert {b.mount for b in blocks} <= {m.label for m in mounts}


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
        holes = math.pi * (n.pilot_hole_diameter_mm**2 + 4 * fastener(p.motor.mount_screw_diameter_mm).clearance_hole_mm**2) / 4
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
    # mount-motor, spool-motor, spool upper half-motor, spool upper half-lower half (4 each), exit guides, bay guide
    assert stats["contact_pairs"] == 4 + 4 + 4 + 4 + 3 + 1


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


def test_a_mount_pulled_harder_than_its_wall_screws_hold_is_refused_naming_the_screw():
    """A 6 N m motor on the default 20 mm drum pulls each cable side with 45 + 6 / 0.02 = 345 N: an M2's bearing
    on the pad's floor needs ~19 mm of floor, longer than any M2 in the catalogue. The loader refuses the design
    under hull.screw_diameter_mm with the load and the remedies (no traceback, no half-built part); an M3 holds.
    (A 4 N m motor was refused until the lanes dropped in the bay guide: its bends now pull the rear mount lower
    and its M2s need 13.6 mm.)"""
    from swiftfin.core.params import ParamError, replace_key
    from swiftfin.core.schema import Params
    from swiftfin.layout.design import check_design
    from swiftfin.layout.mount_plan import design_tension_n, wall_fixings
    strong = replace_key(Params(), "motor.holding_torque_nm", 6.0)
    assert design_tension_n(strong) == pytest.approx(345.0)
    with pytest.raises(ParamError) as err:
        check_design(strong, "strong.toml")
    text = str(err.value)
    assert "hull.screw_diameter_mm = 2.0: no M2 screw of" in text and "design tension of 345 N" in text
    assert "1 problem(s)" in text
    m3 = replace_key(strong, "hull.screw_diameter_mm", 3.0)
    assert all(f.length_mm <= 40 for f in wall_fixings(m3))


@pytest.mark.parametrize("name, key, words, also", [
    ("seeded_mount_narrow", "motor.frame_size_mm",
     # the pads follow joint 1's turn in the bay guide: 15.8 mm, 16.3 when its cable rose over the lanes, 15.1 when
     # its pair was lifted over the passing cables (2026-11-29) and its cable came down less
     ("motor_mount_1: the hull is only 36.2 mm wide (half) at the mount plate", "wall screws' pads (15.1 mm)"),
     "components[1].station_fraction"),
    ("seeded_guide_posts", "spool.drum_diameter_mm",
     ("guide_exit_2: its posts", "would sit on the motor's screw heads", "spool.drum_diameter_mm"),
     "components[0].station_fraction"),
])
def test_the_loader_refuses_a_mount_or_guide_the_build_could_not_make(name, key, words, also, tmp_path):
    """Two seeded designs the loader accepted and the build refused at its start (of 200 drawn with seeds 16 and
    2027, 27 did: 7 a mount plate, 20 a guide's posts): the guides' and the mounts' numbers are made without the CAD
    kernel now (layout/guide_plan.py, layout/mount_plate_plan.py), so ``swiftfin check`` refuses them, exit 2, under
    a key, with the build's own words; and ``swiftfin build`` writes nothing. (Both also have a component within the
    assembly clearance of a motor, which the loader has found too since 2026-11-30: a second problem, ``also``.)"""
    import subprocess
    import sys
    import tomllib
    from pathlib import Path

    from swiftfin.layout.design import design_problems
    path = Path(__file__).parent / "data" / f"{name}.toml"
    _, problems = design_problems(tomllib.loads(path.read_text(encoding="utf-8")))
    # drawn whole, read split since the loader refuses a whole hull (2026-12-07): seeded_mount_narrow's gland then
    # crosses the seam gasket, a problem of its own under hull.drive_bay_length_mm, ahead of these
    problems = [pr for pr in problems if pr.key != "hull.drive_bay_length_mm"]
    assert [pr.key for pr in problems] == [key, also], [str(pr) for pr in problems]
    assert all(w in problems[0].expected for w in words), problems[0].expected
    for cmd in (["check", str(path)], ["build", str(path), "--out", str(tmp_path / "out")]):
        run = subprocess.run([sys.executable, "-m", "swiftfin", *cmd], capture_output=True, text=True, timeout=300)
        assert run.returncode == 2 and "Traceback" not in run.stderr, run.stderr
        assert name in run.stderr and key in run.stderr
    assert not (tmp_path / "out").exists()
