"""PTFE guides: channel geometry against the cable routes, measured on the numbers and on the solids."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepTools import BRepTools

from swiftfin.layout import geometry as L
from swiftfin.cad.guide import channel_path, guide_solid, make_guides
from swiftfin.layout.guide_plan import guide_blocks
from swiftfin.core.errors import UserError
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params
from tests.golden_check import check_golden
from tests.test_spool import mesh_of


@functools.lru_cache(maxsize=None)
def default_guides() -> tuple:
    """The default design's guides, built once per test session (shared with test_mount)."""
    return tuple(make_guides(Params()))


@pytest.fixture(scope="session")
def guides():
    return list(default_guides())


def _line_distance(q, a, b) -> float:
    a, b, q = (np.asarray(v, dtype=float) for v in (a, b, q))
    u = (b - a) / np.linalg.norm(b - a)
    w = q - a
    return float(np.linalg.norm(w - (w @ u) * u))


def _route_bends(p):
    """(block label, route, index of the bend's point) for every exit, drop and bay bend."""
    out = []
    for r in L.cable_routes(p):
        for k, b in enumerate(r.bends, start=1):
            if b.kind == "exit":
                out.append((f"guide_exit_{r.joint + 1}", r, k))
            elif b.kind in ("drop", "bay"):
                out.append(("guide_bay", r, k))
    return out


def _channel_at(block, r, k):
    """The block's bent channel through the route's k-th point."""
    (ch,) = [c for c in block.channels if c.joint == r.joint + 1 and c.side == r.side and c.angle_rad > 0
             and np.linalg.norm(np.subtract(c.bend_point, r.points_mm[k])) < 1e-9]
    return ch


def test_labels_and_validity(guides):
    p = Params()
    n = p.joints.count
    assert [g.label for g in guides] == [f"guide_exit_{j}" for j in range(2, n + 1)] + ["guide_bay"]
    tol = p.export.mesh_tolerance_mm
    for g in guides:
        assert g.link == 0 and g.family == "guide" and g.printed
        assert g.solid.is_valid and len(g.solid.solids()) == 1
        mesh = mesh_of(g.solid, tol)
        assert mesh.is_watertight
        assert mesh.volume == pytest.approx(g.solid.volume, abs=g.solid.area * tol)


@pytest.mark.parametrize("label", [f"guide_exit_{j}" for j in range(2, 5)] + ["guide_bay"])
def test_golden(guides, label, update_golden):
    check_golden(label, next(g for g in guides if g.label == label).solid, update_golden)


def test_every_exit_and_bay_bend_has_its_channel():
    p = Params()
    blocks = {b.label: b for b in guide_blocks(p)}
    bends = _route_bends(p)
    assert len(bends) == 2 * p.joints.count + 4 * (p.joints.count - 1)      # bay or drop + bay; exit
    R = p.guides.min_bend_radius_mm
    for label, r, k in bends:
        ch = _channel_at(blocks[label], r, k)
        prev, corner, nxt = r.points_mm[k - 1], r.points_mm[k], r.points_mm[k + 1]
        assert ch.angle_rad == pytest.approx(r.bends[k - 1].angle_rad, rel=1e-9)
        assert ch.radius_mm == R
        # the straight parts lie on the route's segments (the axis passes through the route's points)
        for q in (prev, corner):
            assert _line_distance(q, ch.p_in, ch.t1) < 1e-9
        for q in (corner, nxt):
            assert _line_distance(q, ch.t2, ch.p_out) < 1e-9
        # the arc built as an edge: radius and swept angle equal the route's bend
        arc = channel_path(ch).edges()[1]
        assert arc.radius == pytest.approx(R, rel=1e-9)
        assert arc.length / R == pytest.approx(r.bends[k - 1].angle_rad, rel=1e-9)
        # tangent to both segments: centre at R from both tangent points, perpendicular to the segments
        c = np.asarray(ch.centre)
        u = np.subtract(corner, prev) / np.linalg.norm(np.subtract(corner, prev))
        v = np.subtract(nxt, corner) / np.linalg.norm(np.subtract(nxt, corner))
        assert np.linalg.norm(np.subtract(ch.t1, c)) == pytest.approx(R, rel=1e-12)
        assert np.linalg.norm(np.subtract(ch.t2, c)) == pytest.approx(R, rel=1e-12)
        assert abs(np.subtract(ch.t1, c) @ u) < 1e-9 and abs(np.subtract(ch.t2, c) @ v) < 1e-9
        # a hand check of the closed form: corner to tangent point = R tan(theta / 2)
        assert np.linalg.norm(np.subtract(corner, ch.t1)) == pytest.approx(R * math.tan(ch.angle_rad / 2), rel=1e-9)


def test_channels_measured_on_the_solids(guides):
    """Torus faces: major radius = bend radius, minor = tube OD + clearance, swept angle = the route's bend,
    centred on the arc's centre, in the plane of the two segments; cylinder faces on the route's segments."""
    p = Params()
    blocks = {b.label: b for b in guide_blocks(p)}
    solids = {g.label: g.solid for g in guides}
    r_ch = (p.guides.ptfe_tube_od_mm + p.print.clearance_sliding_mm) / 2
    for label, r, k in _route_bends(p):
        ch = _channel_at(blocks[label], r, k)
        angle = 0.0
        for f in solids[label].faces():
            if f.geom_type.name != "TORUS":
                continue
            t = BRepAdaptor_Surface(f.wrapped).Torus()
            loc = t.Location()
            if np.linalg.norm(np.subtract((loc.X(), loc.Y(), loc.Z()), ch.centre)) > 1e-6:
                continue
            assert t.MajorRadius() == pytest.approx(p.guides.min_bend_radius_mm, rel=1e-9)
            assert t.MinorRadius() == pytest.approx(r_ch, rel=1e-9)
            ax = t.Axis().Direction()
            u = np.subtract(r.points_mm[k], r.points_mm[k - 1])
            v = np.subtract(r.points_mm[k + 1], r.points_mm[k])
            nrm = np.cross(u, v) / np.linalg.norm(np.cross(u, v))
            assert abs(abs(nrm @ (ax.X(), ax.Y(), ax.Z())) - 1) < 1e-9
            umin, umax, _, _ = BRepTools.UVBounds_s(f.wrapped)
            angle = max(angle, umax - umin)
        assert angle == pytest.approx(r.bends[k - 1].angle_rad, rel=1e-6), (label, r.joint, r.side)
        # the straight channel out of the bend: a cylinder whose axis holds the corner and the next point
        found = False
        for f in solids[label].faces():
            if f.geom_type.name == "CYLINDER":
                c = BRepAdaptor_Surface(f.wrapped).Cylinder()
                if abs(c.Radius() - r_ch) > 1e-9:
                    continue
                o, d = c.Axis().Location(), c.Axis().Direction()
                a = (o.X(), o.Y(), o.Z())
                b = (o.X() + d.X(), o.Y() + d.Y(), o.Z() + d.Z())
                if _line_distance(r.points_mm[k], a, b) < 1e-6 and _line_distance(r.points_mm[k + 1], a, b) < 1e-6:
                    found = True
        assert found, (label, r.joint, r.side)


def test_lanes_ahead_pass_through_exit_guides(guides):
    p = Params()
    for b in guide_blocks(p)[:-1]:
        j = int(b.label.rsplit("_", 1)[1])
        passing = [c for c in b.channels if c.angle_rad == 0]
        assert sorted((c.joint, c.side) for c in passing) == sorted(
            (k, s) for k in range(j + 1, p.joints.count + 1) for s in (1, -1))
        solid = next(g.solid for g in guides if g.label == b.label)
        for c in passing:   # air on the lane's axis across the whole block
            from build123d import Vector
            for x in np.linspace(b.x_mm[0] + 0.1, b.x_mm[1] - 0.1, 7):
                assert not solid.is_inside(Vector(x, c.t1[1], c.t1[2]))


def test_screw_holes_miss_the_channels():
    p = Params()
    for b in guide_blocks(p):
        hole_r = b.screw_hole_diameter_mm / 2
        for x, y in b.screw_points_mm:
            assert b.x_mm[0] < x < b.x_mm[1]
            for ch in b.channels:
                pts = np.concatenate([np.linspace(ch.p_in, ch.t1, 400), np.linspace(ch.t1, ch.mid, 50),
                                      np.linspace(ch.mid, ch.t2, 50), np.linspace(ch.t2, ch.p_out, 400)])
                inside = (pts[:, 0] > b.x_mm[0]) & (pts[:, 0] < b.x_mm[1])
                dist = np.hypot(pts[inside, 0] - x, pts[inside, 1] - y)
                assert dist.min() > ch.diameter_mm / 2 + hole_r, (b.label, ch.joint, ch.side)


@pytest.fixture(scope="session")
def holed_guides(default_parts):
    """The guides as built with their fastener holes (the registry's family function): the session's default
    build's."""
    return [ps for ps in default_parts if ps.family == "guide"]


def test_guide_screws_on_the_solids(holed_guides):
    """Each guide screw: a catalogue length that fills its post's insert (>= 1.5 d), the clearance hole open along
    its axis through the guide, two lines of wall round that hole (no channel broken into), the head's seat (the
    top face, or a counterbore's floor) solid under the head and open above it."""
    from build123d import Vector
    from swiftfin.catalogues.fasteners import fastener
    from swiftfin.cad.fastening import all_fasteners
    p = Params()
    lw = p.print.line_width_mm
    solids = {g.label: g.solid for g in holed_guides}
    screws = [f for f in all_fasteners(p) if f.label.startswith("guide_")]
    assert {f.head_part for f in screws} == set(solids)
    for f in screws:
        s = fastener(f.size)
        assert not f.problems() and f.engagement_mm >= s.engagement_min_mm
        g = solids[f.head_part]
        head = np.asarray(f.head_mm)
        for u in np.linspace(0.2, f.grip_mm - 0.2, 9):
            q = head + u * np.asarray(f.axis)
            assert not g.is_inside(Vector(*q)), (f.label, u)
            for a in np.linspace(0, 2 * math.pi, 12, endpoint=False):
                w = q + (s.clearance_hole_mm / 2 + 2 * lw) * np.array([math.cos(a), math.sin(a), 0.0])
                assert g.is_inside(Vector(*w)), (f.label, u, a)
        rim = head + (s.clearance_hole_mm / 2 + 0.4) * np.array([1.0, 0.0, 0.0])
        assert g.is_inside(Vector(*(rim + [0, 0, -0.1]))) and not g.is_inside(Vector(*(rim + [0, 0, 0.1])))


def test_guides_inside_the_hull(guides):
    p = Params()
    c = p.print.clearance_assembly_mm
    for g in guides:
        verts = np.array([tuple(v) for v in g.solid.vertices()])
        for q in verts:
            assert L.interior_half_width_at_height_mm(p, -q[0], q[2]) - abs(q[1]) >= c - 1e-6, g.label


def test_bend_too_tight_for_the_space_is_refused():
    p = replace_key(Params(), "guides.min_bend_radius_mm", 60.0)
    with pytest.raises(UserError, match=r"guide_exit_2: the 7\.2 deg bend .*min_bend_radius_mm = 60 mm"):
        guide_blocks(p)


@pytest.mark.parametrize("changes", [
    {"spool.drum_diameter_mm": 30.0, "spool.wraps": 3.0},
    {"joints.count": 3, "joints.stations_fraction": (0.55, 0.65, 0.75)},
])
def test_other_designs_build_valid_guides(changes):
    p = Params()
    for k, v in changes.items():
        p = replace_key(p, k, v)
    blocks = guide_blocks(p)
    assert [b.label for b in blocks] == [f"guide_exit_{j}" for j in range(2, p.joints.count + 1)] + ["guide_bay"]
    for b in (blocks[0], blocks[-1]):
        s = guide_solid(b)
        assert s.is_valid and len(s.solids()) == 1


def test_print_orientation_puts_a_flat_face_on_the_bed(guides):
    from build123d import Axis
    for gd in guides:
        rx, ry, rz = gd.print_rotation
        rotated = gd.solid.rotate(Axis.X, rx).rotate(Axis.Y, ry).rotate(Axis.Z, rz)
        bb = rotated.bounding_box()
        bed = sum(f.area for f in rotated.faces() if f.geom_type.name == "PLANE" and abs(f.center().Z - bb.min.Z) < 1e-6
                  and abs(abs(f.normal_at().Z) - 1) < 1e-9)
        # at least half the footprint (the rest: the hull clip's corners, the spool cut-outs, channel grooves)
        assert bed > 0.5 * (bb.max.X - bb.min.X) * (bb.max.Y - bb.min.Y), gd.label


def test_bay_guide_seat_and_notch():
    """The bay guide sits on the rear mount's posts above the motor screws' heads, is cut away over the mount's
    plate, and reaches below its seat behind the plate (where its channels descend)."""
    p = Params()
    bay = guide_blocks(p)[-1]
    rear = L.motor_placements(p)[0]
    plate_top = rear.z_face_mm + L.plate_thickness_mm(p)
    from swiftfin.layout.mount_plan import motor_screw_fit
    fit = motor_screw_fit(p)
    assert bay.seat_mm == pytest.approx(plate_top + fit.spot_face_mm + fit.head_height_mm
                                        + p.print.clearance_assembly_mm + 2 * p.export.mesh_tolerance_mm)
    assert bay.notch_mm is not None and bay.notch_mm[1] == bay.seat_mm
    assert bay.z_mm[0] < bay.seat_mm
    assert all(x > bay.notch_mm[0] for x, _ in bay.screw_points_mm)


SWEEP_RANGES = {"spool.drum_diameter_mm": (12.0, 40.0), "spool.wraps": (1.0, 4.0), "spool.groove_pitch_mm": (1.5, 3.0),
                "spool.groove_depth_mm": (0.2, 0.9), "spool.flange_height_mm": (1.0, 6.0),
                "spool.hub_length_mm": (5.0, 12.0), "cable.diameter_mm": (0.5, 1.05),
                "guides.ptfe_tube_od_mm": (3.0, 5.0), "guides.min_bend_radius_mm": (8.0, 35.0),
                "motor.shaft_diameter_mm": (4.0, 6.0), "print.clearance_sliding_mm": (0.1, 0.5)}


@pytest.mark.slow
def test_seeded_sweep_builds_or_refuses_clearly():
    """Random designs around the default (seeded): each one the schema and layout accept either builds valid
    single-solid spools, mounts and guides, or is refused with a UserError naming the part and a parameter."""
    import random

    from swiftfin.layout.geometry import layout_problems
    from swiftfin.cad.mount import mount_solid
    from swiftfin.layout.mount_plate_plan import mount_numbers
    from swiftfin.cad.spool import spool_solid
    from swiftfin.layout.spool_plan import spool_numbers
    from swiftfin.core.params import cross_field_problems
    rng = random.Random(20261121)
    built = refused = 0
    while built + refused < 6:
        p = Params()
        for k, (lo, hi) in SWEEP_RANGES.items():
            if rng.random() < 0.5:
                p = replace_key(p, k, round(rng.uniform(lo, hi), 2))
        if rng.random() < 0.3:
            p = replace_key(replace_key(p, "joints.count", 3), "joints.stations_fraction", (0.55, 0.65, 0.75))
        if cross_field_problems(p) or layout_problems(p):
            continue
        try:
            sn, mn, gb = spool_numbers(p), mount_numbers(p), guide_blocks(p)
        except UserError as e:
            assert any(w in str(e) for w in ("spool_", "motor_mount_", "guide_")) and "_mm" in str(e), str(e)
            refused += 1
            continue
        for s in [spool_solid(sn[0]), mount_solid(mn[0]), mount_solid(mn[-1])] + [guide_solid(b) for b in gb]:
            assert s.is_valid and len(s.solids()) == 1
        built += 1
    assert built >= 3


LARGE_DRUM = __import__("pathlib").Path(__file__).parent / "data" / "seeded_large_drum.toml"


def test_a_large_drums_posts_and_guide_screws_stay_clear_of_its_spools():
    """A seeded design (tests/data/seeded_large_drum.toml): a 28 mm drum (flange radius 17.0 mm) on a 42.3 mm frame
    puts the exit guides' posts, 17.9 mm behind the motor's axis, inside the flange's radius in plan. They stood
    0.4 mm into the spools' lower flanges (the build's assembly check: 1.6 mm^3 each, 2026-11-29), and the guides'
    screw holes kept one line (0.65 mm) from the spools' envelope where the fastener check asks two (0.87 mm).
    Measured on the solids: each mount stands the assembly clearance from its spool's lower half; every guide's screw
    hole keeps the fastener check's wall from each spool's envelope (the blocks are cut to it)."""
    from swiftfin.layout.guide_plan import bare_guide_blocks
    from swiftfin.layout.mount_plan import assembly_gap_mm
    from swiftfin.cad.mount import make_motor_mounts
    from swiftfin.cad.spool import spool_solid
    from swiftfin.layout.design import load_design
    from swiftfin.layout.spool_plan import spool_numbers
    p = load_design(LARGE_DRUM)
    mounts = {s.label: s.solid for s in make_motor_mounts(p)}
    for n in spool_numbers(p)[1:3]:
        gap = mounts[f"motor_mount_{n.joint}"].distance_to(spool_solid(n, "lower"))
        assert gap >= p.print.clearance_assembly_mm, (n.joint, gap)
    rule = p.rules.wall_min_line_widths * p.print.line_width_mm
    env = spool_numbers(p)[0].flange_radius_mm + assembly_gap_mm(p)
    for b in bare_guide_blocks(p):
        for x, y in b.screw_points_mm:
            for kx, ky, kr in b.keep_out_mm:
                assert kr == pytest.approx(env)
                wall = math.hypot(x - kx, y - ky) - kr - b.screw_hole_diameter_mm / 2
                assert wall >= rule - 1e-9, (b.label, x, y, wall)


def test_crossing_rise_on_a_hand_worked_case():
    """Run a from (0, 0, 0) to (10, 0, 0), run b across it in plan at x = 5 (from y = -5 to 5), 1 mm lower: they
    cross at half of a (f1 = 0.5), 1 mm apart. Raised by d at its start, a's line is (10, 0, -d) and the common
    normal of the two lines makes the distance (1 + d/2) / sqrt(1 + d^2/100); 4.5 mm apart needs
    0.19 d^2 + 4 d - 77 = 0 (squared), d = (-4 + sqrt(16 + 58.52)) / 0.38 = 12.1909 mm. Checked again with numpy's
    cross product; and no rise where b passes beside a or a clears it already; columns of designs as one."""
    need = 4.5
    rise = float(L.crossing_rise_mm((0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (5.0, -5.0, -1.0), (5.0, 5.0, -1.0), need, 50.0))
    assert rise == pytest.approx((-4 + math.sqrt(16 + 4 * 0.19 * 77)) / 0.38, abs=1e-6)
    e, f = np.array([10.0, 0.0, -rise]), np.array([0.0, 10.0, 0.0])
    n = np.cross(e, f)
    assert abs(np.dot(np.array([5.0, -5.0, -1.0]) - np.array([0.0, 0.0, rise]), n)) / np.linalg.norm(n) \
        == pytest.approx(need, abs=1e-6)
    assert L.crossing_rise_mm((0, 0, 0), (10, 0, 0), (5, 1, -1), (5, 5, -1), need, 50.0) == 0.0     # beside a
    assert L.crossing_rise_mm((0, 0, 0), (10, 0, 0), (5, -5, -6), (5, 5, -6), need, 50.0) == 0.0    # clear
    assert L.crossing_rise_mm((0, 0, 0), (10, 0, 0), (5, -5, -1), (5, 5, -1), need, 5.0) == 5.0     # capped
    cols = L.crossing_rise_mm((np.zeros(3), np.zeros(3), np.zeros(3)), (10.0, 0.0, 0.0),
                              (5.0, -5.0, np.array([-1.0, -6.0, -3.0])), (5.0, 5.0, np.array([-1.0, -6.0, -3.0])),
                              need, 50.0)
    one = [float(L.crossing_rise_mm((0, 0, 0), (10, 0, 0), (5, -5, z), (5, 5, z), need, 50.0)) for z in (-1, -6, -3)]
    assert cols == pytest.approx(one, abs=1e-12)


BAY_CROSSING = __import__("pathlib").Path(__file__).parent / "data" / "seeded_bay_crossing.toml"


def _clear_route_caches():
    from tests.conftest import clear_layout_caches
    clear_layout_caches()


def test_joint_1s_cable_passes_over_the_lanes_it_crosses(monkeypatch):
    """Joint 1's cable leaves its drum inside the lanes of the motors ahead and ends outside them, at its sector:
    it crosses each in plan. With two or three joints its level lies below the spools' plane and it came down with
    the lanes (tests/data/seeded_bay_crossing.toml, 2 joints). It now rises over them at the bay corner. Measured on
    the bay guide's tubes as the build makes them (their meshes, manifold's min_gap): every two tubes clear by
    ``print.clearance_assembly_mm``. Without the rise the guide's channel check refuses the design, joint 1 against
    joint 2."""
    from itertools import combinations

    from swiftfin.cad.cables import cable_parts, tube_runs
    from swiftfin.layout.design import load_design
    from swiftfin.layout.guide_plan import bare_guide_blocks
    p = load_design(BAY_CROSSING)
    assert p.joints.count == 2
    assert min(L.joint1_rise_mm(p, s) for s in (1, -1)) > 0.0
    routes = {(r.joint, r.side): r for r in L.cable_routes(p)}
    for side in (1, -1):        # the rise: one more bend in the bay guide, on the same line in plan
        assert [b.kind for b in routes[0, side].bends] == ["bay", "drop"]
    tubes = [t for t in tube_runs(p) if t.holder == "guide_bay"]
    assert {(t.joint, t.side) for t in tubes} == {(1, 1), (1, -1), (2, 1), (2, -1)}
    parts = cable_parts(p, pieces=(), tubes=tubes)
    need = p.print.clearance_assembly_mm
    gaps = {(a.label, b.label): a.manifold.min_gap(b.manifold, 3 * need) for a, b in combinations(parts, 2)}
    assert min(gaps.values()) >= need, gaps
    _clear_route_caches()
    monkeypatch.setattr(L, "joint1_rise_mm", lambda p, side: 0.0)
    try:
        with pytest.raises(UserError, match=r"guide_bay: the tube channels of joint 1's (left|right) cable and "
                                            r"joint 2's"):
            bare_guide_blocks(p)
    finally:
        monkeypatch.undo()
        _clear_route_caches()
