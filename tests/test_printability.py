"""Support area in print orientation (exports/printability.py), against closed forms on solids built here."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.exports.printability import BRIDGE_SAMPLE_MM, best_orientation, bridges, overhang, rotation_matrix


def _mesh(solid):
    from swiftfin.exports.brep import tessellate
    m = tessellate(solid, 0.01, 2.0)
    return m.vertices, m.faces


def test_a_box_on_the_bed_needs_no_support():
    from swiftfin.cad.kernel import bd
    v, f = _mesh(bd.Solid.make_box(20, 10, 5))
    assert overhang(v, f, 45.0).area_mm2 == 0.0


def test_a_t_shape_needs_its_two_ledges_supported():
    """A 10 x 10 x 10 stem under a 30 x 10 x 2 top: the two 10 x 10 ledges hang in the air."""
    from swiftfin.cad.kernel import bd
    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    v, f = _mesh(stem.fuse(top).clean())
    oh = overhang(v, f, 45.0)
    assert oh.area_mm2 == pytest.approx(200.0, rel=1e-6)
    assert oh.lowest_mm == pytest.approx(10.0)
    # upside down the top lies on the bed and nothing overhangs
    v2 = v @ rotation_matrix(180.0, 0.0, 0.0).T
    assert overhang(v2, f, 45.0).area_mm2 == pytest.approx(0.0, abs=1e-9)
    rot, best, tried = best_orientation(v, f, [(0.0, 0.0, 0.0), (180.0, 0.0, 0.0)], 45.0, (250, 210, 220))
    assert rot == (180.0, 0.0, 0.0) and best.area_mm2 == pytest.approx(0.0, abs=1e-9) and len(tried) == 2


def test_a_sphere_needs_its_cap_below_the_support_angle():
    """A sphere of radius R: the faces steeper than 45 deg below the equator form the cap from the bottom up to
    polar angle 45 deg; projected on the bed it is a disc of radius R sin 45 deg, less the faces that touch the bed
    (within BED_CONTACT_MM: a disc of radius sqrt(2 R h))."""
    from swiftfin.exports.printability import BED_CONTACT_MM
    from swiftfin.cad.kernel import bd
    r = 10.0
    v, f = _mesh(bd.Solid.make_sphere(r))
    oh = overhang(v, f, 45.0)
    contact = math.pi * 2 * r * BED_CONTACT_MM
    assert oh.area_mm2 == pytest.approx(math.pi * (r * math.sin(math.radians(45))) ** 2 - contact, rel=0.015)
    oh30 = overhang(v, f, 60.0)     # a larger support angle lets steeper faces print alone: a smaller cap
    assert oh30.area_mm2 == pytest.approx(math.pi * (r * math.sin(math.radians(30))) ** 2 - contact, rel=0.03)


def test_export_picks_the_candidate_that_needs_least_support(default_params):
    """A part whose family offers two orientations is written in the one that needs no support; one that offers
    none keeps its own."""
    from swiftfin.cad.kernel import bd
    from swiftfin.cad.part import PartSpec
    from swiftfin.exports.files import export_part

    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    t = stem.fuse(top).clean()
    free = export_part(PartSpec("t_free", t, 0, "test", meta={"print_candidates": [(180.0, 0.0, 0.0)]}),
                       default_params)
    assert free.print_rotation == (180.0, 0.0, 0.0) and free.support_area_mm2 == pytest.approx(0.0, abs=1e-6)
    assert [(r, a) for r, a, fits in free.orientations] == [((0.0, 0.0, 0.0), 200.0), ((180.0, 0.0, 0.0), 0.0)]
    fixed = export_part(PartSpec("t_fixed", t, 0, "test"), default_params)
    assert fixed.print_rotation == (0.0, 0.0, 0.0) and fixed.support_area_mm2 == pytest.approx(200.0, rel=1e-3)


# ----------------------------------------------------------------------------------------------- thin walls
def _manifold_mesh(m):
    mesh = m.to_mesh()
    return np.asarray(mesh.vert_properties[:, :3], float), np.asarray(mesh.tri_verts)


def test_the_wall_probe_finds_a_thin_wall_where_it_is_and_measures_it():
    """A 20 x 20 x 10 mm block with a pocket that leaves a 0.5 mm wall on its +x side and 3 mm elsewhere: one thin
    region, on that wall, 0.5 mm thick, of about the wall's area on both faces."""
    import manifold3d as m3d
    from swiftfin.exports.printability import thin_walls
    block = m3d.Manifold.cube([20.0, 20.0, 10.0])
    pocket = m3d.Manifold.cube([16.5, 14.0, 7.0]).translate([3.0, 3.0, 3.0])   # x 3..19.5: 0.5 mm left to x = 20
    v, f = _manifold_mesh(block - pocket)
    found = thin_walls(v, f, 0.9)
    assert len(found) == 1
    w = found[0]
    assert w.thickness_mm == pytest.approx(0.5, abs=0.01)
    assert 19.4 <= w.at_mm[0] <= 20.0 + 1e-6 and 3.0 <= w.at_mm[1] <= 17.0 and 3.0 <= w.at_mm[2] <= 10.0
    # the pocket's wall face (14 x 7 mm) and the outside behind it, both probed: about 2 x 98 mm^2
    assert 150.0 < w.area_mm2 < 220.0
    assert thin_walls(v, f, 0.45) == []
    # a 3 mm limit finds the other walls too, none thinner than the thin one
    assert min(x.thickness_mm for x in thin_walls(v, f, 3.5)) == pytest.approx(0.5, abs=0.01)


def test_a_wedge_tip_is_not_a_wall_and_a_plate_is_as_thick_as_it_is():
    import manifold3d as m3d
    from swiftfin.exports.printability import thin_walls
    # a 20 deg wedge, 30 mm long and 20 mm wide: its faces are 20 deg apart, its tip thinner than any limit
    tan = math.tan(math.radians(10.0))
    wedge = m3d.Manifold.extrude(m3d.CrossSection([[(0.0, 0.0), (30.0, -30.0 * tan), (30.0, 30.0 * tan)]]), 20.0)
    v, f = _manifold_mesh(wedge)
    assert thin_walls(v, f, 0.9) == []
    plate = m3d.Manifold.cube([30.0, 30.0, 2.0])
    v, f = _manifold_mesh(plate)
    assert thin_walls(v, f, 1.9) == []
    # its two faces, 2 mm apart (more than a region's reach), are two regions of 900 mm^2 each
    found = thin_walls(v, f, 2.1)
    assert len(found) == 2
    for w in found:
        assert w.thickness_mm == pytest.approx(2.0, abs=1e-6)
        assert w.area_mm2 == pytest.approx(30 * 30, rel=0.05)


def test_a_wall_along_the_print_vertical_is_held_to_layers_not_lines():
    """A 30 x 30 x 0.6 mm plate. Printed flat (the print's vertical along its thickness) it is three 0.2 mm layers
    and passes a two-layer limit; stood on its edge (the vertical across its thickness) it is a 0.6 mm wall of
    lines and fails two perimeters. The block with the 0.5 mm side wall keeps failing whichever way is up, when its
    thin wall runs across the vertical."""
    import manifold3d as m3d
    from swiftfin.exports.printability import thin_walls
    v, f = _manifold_mesh(m3d.Manifold.cube([30.0, 30.0, 0.6]))
    flat = thin_walls(v, f, 0.9, up=np.array([0.0, 0.0, 1.0]), layered_limit_mm=0.4)
    assert flat == []
    on_edge = thin_walls(v, f, 0.9, up=np.array([1.0, 0.0, 0.0]), layered_limit_mm=0.4)
    assert len(on_edge) == 1           # both faces, 0.6 mm apart: within a region's reach, one region
    assert on_edge[0].thickness_mm == pytest.approx(0.6, abs=1e-6) and on_edge[0].limit_mm == 0.9
    assert on_edge[0].area_mm2 == pytest.approx(2 * 30 * 30, rel=0.05)
    # a film of one layer fails the layered limit too
    v, f = _manifold_mesh(m3d.Manifold.cube([30.0, 30.0, 0.2]))
    film = thin_walls(v, f, 0.9, up=np.array([0.0, 0.0, 1.0]), layered_limit_mm=0.4)
    assert film and all(w.limit_mm == 0.4 for w in film)
    block = m3d.Manifold.cube([20.0, 20.0, 10.0]) - m3d.Manifold.cube([16.5, 14.0, 7.0]).translate([3.0, 3.0, 3.0])
    v, f = _manifold_mesh(block)
    for up in ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)):
        found = thin_walls(v, f, 0.9, up=np.array(up), layered_limit_mm=0.4)
        assert len(found) == 1 and found[0].thickness_mm == pytest.approx(0.5, abs=0.01)


def test_the_wall_probe_measures_the_hull_skin_as_the_wall_parameter(default_params, default_parts):
    """On a built hull half, where the skin's normal is along one of its section's axes (the crest, y ~ 0) and the
    hull barely tapers (the head's widest length), the cavity (the section's semi-axes less the wall) lies exactly
    ``hull.wall_thickness_mm`` inside the skin: the probe reads it there. (Elsewhere a section shrunk on both
    semi-axes is thinner along the normal than the wall, and more so where the hull tapers: the probe reads 1.9 mm
    and less towards the nose.)"""
    from swiftfin.exports.brep import tessellate
    from swiftfin.exports.printability import wall_thickness_samples
    p = default_params
    spec = next(s for s in default_parts if s.label == "hull_head_rear_upper")
    m = tessellate(spec.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
    points, thickness, is_wall, per_point, _ = wall_thickness_samples(m.vertices, m.faces)
    crest = is_wall & (np.abs(points[:, 1]) < 2.0) & (-points[:, 0] > 170.0) & (-points[:, 0] < 230.0) \
        & (points[:, 2] > 40.0)
    assert crest.sum() > 100
    assert np.median(thickness[crest]) == pytest.approx(p.hull.wall_thickness_mm, abs=0.01)


# ---------------------------------------------------------------------------------------------------- bridges
def _tunnel(width_mm: float, height_mm: float = 8.0, stalactite: bool = False):
    """A 40 x 30 x 15 mm block on the bed with a tunnel ``width_mm`` wide and ``height_mm`` high through it along x:
    its ceiling bridges the tunnel's width. ``stalactite``: a 4 x 4 x 2 mm block hangs from the ceiling's middle."""
    from swiftfin.cad.kernel import bd
    block = bd.Solid.make_box(40, 30, 15).translate((-20, -15, 0))
    s = block.cut(bd.Solid.make_box(50, width_mm, height_mm).translate((-25, -width_mm / 2, 0)))
    if stalactite:
        s = s.fuse(bd.Solid.make_box(4, 4, 2).translate((-2, -2, height_mm - 2)))
    return s.clean()


def test_a_tunnel_bridges_its_width_a_ledge_twice_its_reach_and_a_hanging_block_nothing():
    """Closed forms: a tunnel's ceiling spans the tunnel's width (both long edges stand on its walls; its open ends
    hold nothing); a T's 10 mm ledges are anchored on the stem alone, so each spans 20 mm (its tip is as far from
    the stem as the middle of a 20 mm bridge from its ends); a block hanging from a ceiling has no edge with
    material below it; a box on the bed, and the T upside down, bridge nothing."""
    from swiftfin.cad.kernel import bd
    for width in (12.0, 20.0):
        v, f = _mesh(_tunnel(width))
        (b,) = bridges(v, f, 10.0)
        assert b.span_mm == pytest.approx(width, abs=2 * BRIDGE_SAMPLE_MM)
        assert b.area_mm2 == pytest.approx(40.0 * width, rel=1e-9)
        assert b.at_mm[2] == pytest.approx(8.0) and abs(b.at_mm[1]) <= BRIDGE_SAMPLE_MM   # on the tunnel's centre line
    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    v, f = _mesh(stem.fuse(top).clean())
    spans = sorted(b.span_mm for b in bridges(v, f, 10.0))
    assert spans == pytest.approx([20.0, 20.0], abs=2 * BRIDGE_SAMPLE_MM)
    assert bridges(v, f, 10.0, up=(0.0, 0.0, -1.0)) == []              # printed on its top: nothing hangs
    v, f = _mesh(bd.Solid.make_box(20, 10, 5))
    assert bridges(v, f, 10.0) == []
    v, f = _mesh(_tunnel(20.0, stalactite=True))
    found = sorted(bridges(v, f, 10.0), key=lambda b: b.area_mm2)
    assert math.isinf(found[0].span_mm) and found[0].area_mm2 == pytest.approx(16.0, rel=1e-9)
    assert found[0].at_mm[2] == pytest.approx(6.0)
    assert found[1].span_mm == pytest.approx(20.0, abs=2 * BRIDGE_SAMPLE_MM)   # the ceiling round it


def test_bridges_measured_in_the_print_frame_are_reported_in_the_parts_frame():
    """The same T turned 90 deg about x and printed with the turned vertical: the same spans, and the farthest
    points turned with it."""
    from swiftfin.cad.kernel import bd
    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    v, f = _mesh(stem.fuse(top).clean())
    R = rotation_matrix(90.0, 0.0, 0.0)
    flat = sorted(bridges(v, f, 10.0), key=lambda b: b.at_mm[0])
    turned = sorted(bridges(v @ R.T, f, 10.0, up=R @ [0.0, 0.0, 1.0]), key=lambda b: (R.T @ b.at_mm)[0])
    for a, b in zip(flat, turned):
        assert b.span_mm == pytest.approx(a.span_mm, abs=1e-9)
        assert R.T @ np.asarray(b.at_mm) == pytest.approx(np.asarray(a.at_mm), abs=1e-6)


def test_prusaslicer_bridges_the_tunnels_the_way_we_measure_them(tmp_path, default_params):
    """Independent check: PrusaSlicer slices the two tunnels with the design's settings. Its bridge layer over each
    tunnel's ceiling runs across the tunnel (along y), and its longest bridge thread is our span plus the same
    anchoring at the two ends for both widths (so the 8 mm between the tunnels is 8 mm in both)."""
    import re
    from swiftfin.exports.files import print_transform, stl_bytes, tessellate
    from swiftfin.exports.slicer import slice_stl
    from tests.conftest import require_tool
    require_tool("prusa-slicer", "the bridge measure is checked against the slicer's own bridges")
    p = default_params
    extra = []
    for width in (12.0, 20.0):
        m = tessellate(_tunnel(width), 0.05, 10.0)
        (b,) = bridges(m.vertices, m.faces, p.print.max_bridge_mm)
        m = m.transformed(print_transform(m, (0, 0, 0), p.print.bed_x_mm, p.print.bed_y_mm))
        stl, gcode = tmp_path / f"tunnel_{width:g}.stl", tmp_path / f"tunnel_{width:g}.gcode"
        stl.write_bytes(stl_bytes(m, "tunnel"))
        slice_stl(stl, p, gcode_out=gcode)
        x = y = z = 0.0
        kind, threads = None, []
        for line in gcode.read_text().splitlines():
            if line.startswith(";TYPE:"):
                kind = line[6:].strip()
            elif line.startswith(("G1 ", "G0 ")):
                d = {k: float(val) for k, val in re.findall(r"([XYZE])([-\d.]+)", line)}
                nx, ny, z = d.get("X", x), d.get("Y", y), d.get("Z", z)
                if kind == "Bridge infill" and d.get("E", 0.0) > 0 and 8.0 < z <= 8.0 + 2 * p.print.layer_height_mm:
                    threads.append((abs(nx - x), abs(ny - y)))
                x, y = nx, ny
        threads = np.array(threads)
        assert len(threads), width
        longest = threads[np.argmax(np.hypot(threads[:, 0], threads[:, 1]))]
        assert longest[0] < 0.05 * longest[1]                # across the tunnel
        extra.append(longest[1] - b.span_mm)
    assert 0.0 < extra[0] < 10.0
    assert extra[1] == pytest.approx(extra[0], abs=0.5)


@pytest.mark.slow
def test_the_default_parts_bridges_are_on_their_surface_and_inside_their_support(default_params, default_parts):
    """On built parts, as exported (exports.files.export_part: print orientation chosen, bridges over
    ``print.max_bridge_mm`` kept): each reported bridge's farthest point lies on the part's surface, and the
    bridges are part of the area the overhang count already supports (a ceiling within 10 deg of horizontal leans
    past any support angle): their plan area is within the part's support area. Cross-checks of two independent
    computations on the same mesh. The upper hull halves print upright, so their crown is a ceiling."""
    import math
    import trimesh
    from swiftfin.exports.files import export_part
    p = default_params
    found = {}
    for label in ("hull_body_1_upper", "joint_link_4"):
        spec = next(s for s in default_parts if s.label == label)
        exp = export_part(spec, p)
        assert exp.bridges, label
        tri = np.asarray(exp.mesh.vertices)[np.asarray(exp.mesh.faces)]
        for b in exp.bridges:
            assert b.span_mm > p.print.max_bridge_mm and b.limit_mm == p.print.max_bridge_mm
            on = trimesh.triangles.closest_point(tri, np.tile(b.at_mm, (len(tri), 1)))
            assert np.linalg.norm(on - np.asarray(b.at_mm), axis=1).min() < 0.05, (label, b)
        plan = sum(b.area_mm2 for b in exp.bridges) * math.cos(math.radians(10.0))
        assert plan <= exp.support_area_mm2 + 1e-6, (label, plan, exp.support_area_mm2)
        found[label] = max(b.span_mm for b in exp.bridges)
    assert found["hull_body_1_upper"] > 30.0          # the crown of an upright shell: about its inner width


def test_a_web_between_two_declared_bores_is_held_to_one_line_a_skin_to_two():
    """A 20 x 12 x 10 mm block with two 3 mm bores along x, 3.6 mm apart (a 0.6 mm web between them), and a third
    0.6 mm under the top face. Undeclared, both thin places fail two perimeters (0.9 mm). With the bores declared
    load-free, the web between the first two is held to one line width (0.45: passes; 0.7: a "web" region), while
    the skin over the third stays a wall at 0.9, though that bore is declared too (its other face is no bore)."""
    import manifold3d as m3d
    from swiftfin.exports.printability import between_bores, thin_walls

    def bore(y, z):
        return m3d.Manifold.cylinder(24.0, 1.5, 1.5, 64).rotate([0.0, 90.0, 0.0]).translate([-2.0, y, z])

    block = m3d.Manifold.cube([20.0, 12.0, 10.0])
    holes = [(3.0, 3.0), (6.6, 3.0), (6.6, 7.9)]            # the third's top at 9.4: 0.6 mm of skin to z = 10
    part = block
    for y, z in holes:
        part = part - bore(y, z)
    v, f = _manifold_mesh(part)
    plain = thin_walls(v, f, 0.9)
    in_web = [w for w in plain if 4.4 < w.at_mm[1] < 5.2 and w.at_mm[2] < 4.0]
    on_top = [w for w in plain if w.at_mm[2] > 9.0]
    # the web's thin strip is narrow (where the bores' gap is under 0.9 mm) and its sampling breaks it in pieces
    assert in_web and on_top and len(in_web) + len(on_top) == len(plain)
    assert all(w.kind == "wall" and w.thickness_mm == pytest.approx(0.6, abs=0.02) for w in plain)
    declared = [[[-2.0, y, z], [22.0, y, z], 1.5] for y, z in holes]
    skin = thin_walls(v, f, 0.9, bores=declared, web_limit_mm=0.45)
    assert skin and all(w.kind == "wall" and w.at_mm[2] > 9.0 and w.limit_mm == 0.9 for w in skin)
    webs = thin_walls(v, f, 0.9, bores=declared, web_limit_mm=0.7)
    web = [w for w in webs if w.kind == "web"]
    assert web and all(w.limit_mm == 0.7 and 4.4 < w.at_mm[1] < 5.2 for w in web)
    assert "web between bores" in str(web[0])
    # the classifier itself: a point on bore 1 whose ray ends on bore 2 is a web; ending on the same bore is not
    on1, on2 = np.array([[10.0, 4.5, 3.0]]), np.array([[10.0, 5.1, 3.0]])
    assert between_bores(on1, on2, declared).tolist() == [True]
    assert between_bores(on1, np.array([[10.0, 1.5, 3.0]]), declared).tolist() == [False]


def test_the_fastener_bores_listed_are_the_holes_cut(default_params):
    """``layout.fastening.bores_in_part`` (what the support rule reads) against the cutters of ``cad/fastening.py``
    (what the parts get): for a screw of each seat and a dowel, pointed along z, the cutters' widths across the axis
    are the listed diameters."""
    from swiftfin.cad.fastening import head_cutters, seat_cutters
    from swiftfin.layout.fastening import Fastener, bores_in_part

    def widths(solids):
        return sorted({round(s.bounding_box().size.X, 4) for s in solids})

    for seat in ("insert", "self_tap", "nut"):
        f = Fastener("t", "M3", "cap_screw", seat, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 12.0, 4.0, "a", "b", "test",
                     recess_mm=1.0)
        assert widths(head_cutters(f)) == sorted(round(d, 4) for _, d in bores_in_part(f, "a")), seat
        if seat != "nut":      # the hex trap's box is its width across corners one way, across flats the other
            assert widths(seat_cutters(f)) == sorted(round(d, 4) for _, d in bores_in_part(f, "b")), seat
    pin = Fastener("p", "3", "dowel", "press", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 8.0, 0.0, None, "b", "test",
                   meta={"slip_part": "c"})
    assert widths(seat_cutters(pin)) == [round(d, 4) for _, d in bores_in_part(pin, "b")] == \
        [round(d, 4) for _, d in bores_in_part(pin, "c")]


def test_a_hull_half_on_end_would_need_support_in_its_seam_bores(default_params):
    """The rule's reason for printing the hull's halves cut face down, on the real design: so, the head's upper
    half needs no support in any fastener hole. Its seam's 10 bores stand vertical; the splice's screws (along the
    skin's normal, 55 deg) and the motor mounts' wall screws (through the side wall, 81-82 deg) lean, and are
    bridged (4.3 mm at most, under the 10 mm limit). Turned on end (ry = 90) the seam's bores lie across the layers
    too, and with a bridge limit under their width every hole is listed with its tilt."""
    import dataclasses

    from swiftfin.pipeline import fastener_bores

    n, found = fastener_bores(default_params, "hull_head_front_upper", (0.0, 0.0, 0.0))
    assert n == 28 and found == ()
    p = dataclasses.replace(default_params, print=dataclasses.replace(default_params.print, max_bridge_mm=1.0))
    _, flat = fastener_bores(p, "hull_head_front_upper", (0.0, 0.0, 0.0))
    assert flat and not any("_seam_" in b.fastener for b in flat)
    assert all(("_splice_" in b.fastener and 50 < b.tilt_deg < 60) or ("_wall_" in b.fastener and b.tilt_deg > 80)
               for b in flat)
    _, on_end = fastener_bores(p, "hull_head_front_upper", (0.0, 90.0, 0.0))
    seam = [b for b in on_end if "_seam_" in b.fastener]
    assert len(on_end) == n and len(seam) == 10
    assert all(b.tilt_deg == pytest.approx(90.0, abs=1e-6) for b in seam)
    assert {b.what for b in seam} == {"insert hole", "pin bore"}
