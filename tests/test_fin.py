"""Caudal fin: planform area and span against the closed forms, section thickness, mount, golden values."""
from __future__ import annotations

import dataclasses
import math

import build123d as bd
import numpy as np
import pytest

from swiftfin.layout import geometry as L
from swiftfin.cad.fin import blade_solid, make_caudal_fin, planform, tang_dims_mm
from swiftfin.core.schema import Params
from tests.golden_check import check_golden

P = Params()


@pytest.fixture(scope="session")
def fin(default_parts):
    """The fin as the registry gives it, with the root screws' pilots cut: the session's default build's."""
    (part,) = [ps for ps in default_parts if ps.family == "fin"]
    return part


@pytest.fixture(scope="session")
def peduncle():
    from swiftfin.cad.fastening import apply_fasteners
    from swiftfin.cad.hull import hull_pieces, piece_parts
    pc = next(pc for pc in hull_pieces(P) if pc.tail)
    return {ps.meta["half"]: ps.solid for ps in apply_fasteners(P, piece_parts(P, pc))}


@pytest.fixture(scope="session")
def blade():
    return blade_solid(P)


def _section_area_y0(solid) -> float:
    """Area of the solid's section by the mid-plane y = 0 (the planform: the sections are symmetric)."""
    faces = bd.section(solid, bd.Plane.XZ).faces()
    return sum(f.area for f in faces)


def test_one_valid_solid_on_the_last_link(fin):
    assert fin.label == "caudal_fin" and fin.link == P.joints.count and fin.family == "fin"
    assert len(fin.solid.solids()) == 1 and fin.solid.is_valid


def test_planform_closed_form_numbers():
    pf = planform(P)
    b, ar = 160.0, 6.0
    assert pf.area_mm2 == pytest.approx(b * b / ar)
    # S = b (c_tip + (c0 - c_tip) pi / 4) with c_tip = 3 * 1.2 mm, worked by hand: c0 = 3.6 + (26.667 - 3.6) 4/pi
    assert pf.root_chord_mm == pytest.approx(3.6 + (160 / 6 - 3.6) * 4 / math.pi, rel=1e-12)
    eta = np.linspace(-1, 1, 200001)
    area = np.trapezoid(pf.chord_mm(eta), eta * b / 2)
    assert area == pytest.approx(b * b / ar, rel=1e-6)
    # the fork (root trailing edge) at the fork length
    assert pf.s_root_le_mm + pf.root_chord_mm == pytest.approx(P.body.length_mm)


def test_span_and_planform_area_measured_on_the_solid(blade):
    bb = blade.bounding_box()
    assert bb.size.Z == pytest.approx(P.caudal_fin.span_mm, abs=1e-3)
    area = _section_area_y0(blade)
    assert area == pytest.approx(P.caudal_fin.span_mm**2 / P.caudal_fin.aspect_ratio, rel=5e-3)


@pytest.mark.parametrize("eta, tol", [(0.0, 0.005), (math.sin(math.pi / 4), 0.005), (0.5, 0.15), (0.9, 0.15)])
def test_leading_edge_sweep_and_chord_on_the_solid(blade, eta, tol):
    """Exact at the loft's sections (eta = 0, sin(pi/4) = sections 0 and 4 of 8); between sections within
    the B-spline interpolation error (the leading edge has a kink at the root that the loft rounds off).
    The 0.004 mm slab itself moves a swept leading edge by 0.002 tan(35 deg) = 0.0014 mm."""
    pf = planform(P)
    z = eta * pf.span_mm / 2
    cut = blade.intersect(bd.Solid.make_box(600, 50, 0.004, bd.Plane(origin=(-600, -25, z - 0.002))))
    bb = bd.Compound([s for sh in cut for s in sh.solids()]).bounding_box(optimal=True)
    s_le = P.body.length_mm - pf.root_chord_mm + z * math.tan(math.radians(P.caudal_fin.sweep_deg))
    assert -bb.max.X == pytest.approx(s_le, abs=tol)
    assert bb.size.X == pytest.approx(float(pf.chord_mm(eta)), abs=tol)


def test_section_thickness_and_printable_trailing_edge(blade):
    """Max thickness at half span = NACA thickness of that chord (plus the trailing-edge ramp at 30 %
    chord), computed here from the 00xx formula on a dense grid; the trailing edge is min_thickness_mm."""
    pf = planform(P)
    f = P.caudal_fin
    eta = 0.5
    c = float(pf.chord_mm(eta))
    T = max(f.thickness_fraction * c, f.min_thickness_mm)
    xi = np.linspace(0, 1, 20001)
    t = T / c
    yt = 5 * t * (0.2969 * np.sqrt(xi) - 0.1260 * xi - 0.3516 * xi**2 + 0.2843 * xi**3 - 0.1015 * xi**4)
    y = c * yt + xi * (f.min_thickness_mm / 2 - c * yt[-1])
    z = eta * pf.span_mm / 2
    cut = blade.intersect(bd.Solid.make_box(600, 50, 0.04, bd.Plane(origin=(-600, -25, z - 0.02))))
    bb = bd.Compound([s for sh in cut for s in sh.solids()]).bounding_box(optimal=True)
    assert bb.size.Y == pytest.approx(2 * y.max(), abs=0.05)
    # trailing edge: a thin slab 0.1 mm ahead of the trailing edge
    x_te = -(float(pf.s_le_mm(eta)) + c)
    cut = blade.intersect(bd.Solid.make_box(0.1, 50, 0.04, bd.Plane(origin=(x_te, -25, z - 0.02))))
    bb = bd.Compound([s for sh in cut for s in sh.solids()]).bounding_box(optimal=True)
    assert bb.size.Y == pytest.approx(f.min_thickness_mm, abs=0.05)


def test_tang_mounts_the_fin_to_the_peduncle(fin):
    td = tang_dims_mm(P)
    bb = fin.solid.bounding_box()
    assert -bb.max.X == pytest.approx(L.hull_end_mm(P) - P.caudal_fin.mount_length_mm, abs=1e-6)
    # inside the peduncle end the fin is exactly the tang: section area = tang thickness x height
    s = L.hull_end_mm(P) - 2.0
    sec = bd.section(fin.solid, bd.Plane(origin=(-s, 0, 0), x_dir=(0, 1, 0), z_dir=(1, 0, 0)))
    assert sum(f.area for f in sec.faces()) == pytest.approx(td.thickness_mm * td.height_mm, rel=1e-9)
    # a pilot through the tang at each root screw, at two stations along the body
    assert len(td.screw_stations_mm) == 2 and td.screw_stations_mm[1] - td.screw_stations_mm[0] >= 5.0
    for st in td.screw_stations_mm:
        for z in td.screw_z_mm:
            assert not fin.solid.is_inside(bd.Vector(-st, 0.0, z))


def _inside(solid, x, y, z) -> bool:
    return solid.is_inside(bd.Vector(x, y, z))


def _edge(solid, x, z, y_in: float, y_out: float, want_inside_at_in: bool) -> float:
    """|y| where the solid's material starts or ends between y_in and y_out (bisection to 1 um)."""
    for _ in range(40):
        mid = 0.5 * (y_in + y_out)
        if _inside(solid, x, mid, z) == want_inside_at_in:
            y_in = mid
        else:
            y_out = mid
    return abs(0.5 * (y_in + y_out))


def test_root_tang_slop_is_the_declared_fit_measured_on_the_solids(fin, peduncle):
    """Between the screws, across y and z: socket (measured on the hull halves) minus tang (measured on the fin)
    is caudal_fin.root_fit_clearance_mm on each side (was 0.3 mm of slop per side)."""
    td = tang_dims_mm(P)
    fit = P.caudal_fin.root_fit_clearance_mm
    assert td.fit_clearance_mm == fit and fit <= 0.15
    x = -(td.screw_stations_mm[0] + td.screw_stations_mm[1]) / 2
    z = td.height_mm / 4
    for sg in (1, -1):
        tang = _edge(fin.solid, x, z, 0.0, sg * td.thickness_mm, True)
        socket = _edge(peduncle["upper"], x, z, sg * 6.0, 0.0, True)
        assert socket - tang == pytest.approx(fit, abs=2e-3)
        assert socket - tang <= fit + 2e-3
    # and in z (top of the tang against the socket's roof, in the upper half)
    def z_edge(solid, z_in, z_out, want):
        for _ in range(40):
            mid = 0.5 * (z_in + z_out)
            z_in, z_out = (mid, z_out) if _inside(solid, x, 0.0, mid) == want else (z_in, mid)
        return 0.5 * (z_in + z_out)
    ztang = z_edge(fin.solid, 0.0, td.height_mm, True)
    zsock = z_edge(peduncle["upper"], td.height_mm, 0.5, True)
    assert zsock - ztang == pytest.approx(fit, abs=2e-3)


def test_root_screws_two_stations_coaxial_holes_and_thread_in_the_tang(fin, peduncle):
    """Four records (two stations x two halves); along each axis the peduncle has a clearance hole and counterbore
    from the skin to the socket, the tang a pilot; the tip stays inside the tang; full engagement."""
    from swiftfin.layout.fin_plan import fin_fasteners
    td = tang_dims_mm(P)
    recs = fin_fasteners(P)
    assert len(recs) == 4 and len({round(f.head_mm[0], 6) for f in recs}) == 2
    for f in recs:
        assert f.problems() == [] and f.engagement_mm >= 1.5 * 2.0
        s = f.screw
        half = peduncle[f.head_part.rsplit("_", 1)[1]]
        for d in np.linspace(-1.0, f.grip_mm - 0.05, 8):              # head recess and clearance hole
            assert not _inside(half, *f.point_mm(d))
        for d in np.linspace(f.grip_mm + 0.2, f.length_mm, 6):          # pilot in the tang: open on the axis
            assert not _inside(fin.solid, *f.point_mm(d))
        c = f.point_mm(f.grip_mm + 1.5)                                 # ... with tang material round it
        for dx, dz in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            assert _inside(fin.solid, c[0] + dx * (s.pilot_hole_mm / 2 + 0.3), c[1], c[2] + dz * (s.pilot_hole_mm / 2 + 0.3))
        assert f.tip_mm[1] >= -td.thickness_mm / 2 + 0.5 - 1e-9        # no hole needed in the far wall
        # the head bears on the peduncle's wall and sits below its skin
        h = f.point_mm(0.3)
        assert _inside(half, h[0] + s.head_diameter_mm / 2 - 0.05, h[1], h[2])
        assert f.recess_mm >= s.counterbore_depth_mm


def test_golden(fin, update_golden):
    check_golden("caudal_fin", fin.solid, update_golden)


@pytest.mark.parametrize("changes", [
    {"span_mm": 100.0, "aspect_ratio": 3.0, "sweep_deg": 0.0},
    {"span_mm": 250.0, "aspect_ratio": 9.0, "sweep_deg": 50.0, "thickness_fraction": 0.2},
])
def test_other_fins_build_and_match_their_closed_forms(changes):
    p = dataclasses.replace(P, caudal_fin=dataclasses.replace(P.caudal_fin, **changes))
    part = make_caudal_fin(p)[0]
    assert part.solid.is_valid and len(part.solid.solids()) == 1
    b = blade_solid(p)
    assert b.bounding_box().size.Z == pytest.approx(p.caudal_fin.span_mm, abs=1e-2)
    assert _section_area_y0(b) == pytest.approx(p.caudal_fin.span_mm**2 / p.caudal_fin.aspect_ratio, rel=5e-3)


@pytest.mark.parametrize("tolerance_mm", [0.05, 0.02])
def test_a_seeded_fins_mesh_is_watertight_at_its_tips(tolerance_mm):
    """The fin of one of our sampler's designs (tests/data/seeded_large_drum.toml: span 168 mm, AR 5.2, a 1.7 mm
    least thickness) at the export's tolerance and finer. Lofted smooth through its tip sections, its surface rose
    above the tip planes and folded back, and the mesh had 39 edges of four triangles at 0.05 mm (232 at 0.02):
    the build refused the design at the export. Counted here on the mesh as the exports make it."""
    from pathlib import Path

    import trimesh

    from swiftfin.cad.kernel import precise_volume_mm3
    from swiftfin.exports.brep import tessellate
    from swiftfin.layout.design import load_design
    p = load_design(Path(__file__).parent / "data" / "seeded_large_drum.toml")
    solid = make_caudal_fin(p)[0].solid
    m = tessellate(solid, tolerance_mm, p.export.mesh_angular_tolerance_deg)
    tm = trimesh.Trimesh(m.vertices, m.faces, process=False)
    _, uses = np.unique(tm.edges_sorted, axis=0, return_counts=True)
    assert (uses == 2).all(), f"{int((uses != 2).sum())} edges not shared by exactly two triangles"
    assert tm.is_watertight and tm.volume == pytest.approx(precise_volume_mm3(solid), rel=0.01)
