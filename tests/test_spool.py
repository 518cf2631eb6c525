"""Capstan spools against closed forms (house style rule 7) and golden values."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
import trimesh
from build123d import Vector
from OCP.BRepAdaptor import BRepAdaptor_Surface

from swiftfin.layout import geometry as L
from swiftfin.cad.spool import make_spools, spool_numbers, spool_solid
from swiftfin.core.errors import UserError
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params

from tests.golden_check import check_golden


def mesh_of(solid, tol: float) -> trimesh.Trimesh:
    verts, tris = solid.tessellate(tol, 0.2)
    return trimesh.Trimesh(np.array([tuple(v) for v in verts]), np.array(tris), process=True)


@functools.lru_cache(maxsize=None)
def default_spools() -> tuple:
    """The default design's spools, built once per test session (shared with test_mount)."""
    return tuple(make_spools(Params()))


@pytest.fixture(scope="session")
def spools():
    return list(default_spools())


def segment(r: float, h: float) -> tuple[float, float]:
    """Area of the part of a circle (radius r) beyond a chord at signed distance h from the centre, and the
    distance of that part's centroid from the centre."""
    a = r * r * math.acos(h / r) - h * math.sqrt(r * r - h * h)
    return a, 2 * (r * r - h * h) ** 1.5 / (3 * a)


def groove_volume_closed_form(n) -> float:
    """Pappus on the helix: meridional section (groove circle inside the drum cylinder) x path of its centroid.

    The section is the circular segment of the groove circle (radius r_g, centre at R_gc) on the axis side of
    the drum surface r = R_s; swept helically it removes N * 2 pi rbar * A / cos(alpha) (the meridional
    section of a tube swept perpendicular to a helix of lead angle alpha is stretched axially by 1/cos alpha).
    Neglected: the variation of alpha across the section, O((p / 2 pi R)^2 * r_g / R) ~ 1e-5 here.
    """
    a, dc = segment(n.groove_radius_mm, n.groove_centre_radius_mm - n.surface_radius_mm)
    rbar = n.groove_centre_radius_mm - dc
    tan_a = n.groove_pitch_mm / (2 * math.pi * n.groove_centre_radius_mm)
    return n.groove_turns * 2 * math.pi * rbar * a * math.sqrt(1 + tan_a**2)


def test_one_spool_per_motor_on_its_shaft(spools):
    p = Params()
    d = L.spool_dims(p)
    motors = L.motor_placements(p)
    assert [s.label for s in spools] == [f"spool_{j}" for j in range(1, len(motors) + 1)]
    for s, mp in zip(spools, motors):
        assert s.link == 0 and s.family == "spool" and s.printed
        bb = s.solid.bounding_box()
        assert (bb.min.X + bb.max.X) / 2 == pytest.approx(mp.x_mm, abs=1e-6)
        assert (bb.min.Y + bb.max.Y) / 2 == pytest.approx(0.0, abs=1e-6)
        assert bb.max.X - bb.min.X == pytest.approx(2 * d.flange_radius_mm, abs=1e-6)
        assert bb.min.Z == pytest.approx(mp.z_face_mm + d.hub_bottom_mm, abs=1e-6)
        assert bb.max.Z == pytest.approx(mp.z_face_mm + d.top_mm, abs=1e-6)


def test_valid_single_solid_watertight(spools):
    tol = Params().export.mesh_tolerance_mm
    for s in spools:
        assert s.solid.is_valid
        assert len(s.solid.solids()) == 1
        mesh = mesh_of(s.solid, tol)
        assert mesh.is_watertight
        # a chordal deviation <= tol over the area A changes the volume by at most ~ A * tol
        assert mesh.volume == pytest.approx(s.solid.volume, abs=s.solid.area * tol)


@pytest.mark.parametrize("label", [f"spool_{j}" for j in range(1, 5)])
def test_golden(spools, label, update_golden):
    check_golden(label, next(s for s in spools if s.label == label).solid, update_golden)


def test_drum_flanges_hub_volume_closed_form():
    n = spool_numbers(Params())[0]
    blank = spool_solid(n, groove=False, anchors=False, bore=False, set_screw=False)
    h = lambda z: z[1] - z[0]  # noqa: E731
    expected = math.pi * (n.hub_radius_mm**2 * h(n.hub_z_mm) + n.surface_radius_mm**2 * h(n.drum_z_mm)
                          + n.flange_radius_mm**2 * (h(n.lower_flange_z_mm) + h(n.upper_flange_z_mm)))
    assert blank.volume == pytest.approx(expected, rel=1e-9)
    # hand-worked default: hub r 2.65 + 1.5 x 3 = 7.15 x 8, drum r 10 x 5.5075, flanges r 13 x 1.6 each
    assert expected == pytest.approx(math.pi * (7.15**2 * 8 + 100 * 5.507488210540301 + 169 * 3.2), rel=1e-12)


def test_bore_volume_is_the_d_profile():
    n = spool_numbers(Params())[0]
    blank = spool_solid(n, groove=False, anchors=False, bore=False, set_screw=False)
    bored = spool_solid(n, groove=False, anchors=False, bore=True, set_screw=False)
    r, f = n.bore_radius_mm, n.flat_distance_mm
    a_d = math.pi * r * r - segment(r, f)[0]
    length = n.upper_flange_z_mm[1] - n.hub_z_mm[0]
    assert blank.volume - bored.volume == pytest.approx(a_d * length, rel=1e-7)


@pytest.mark.parametrize("changes", [{}, {"spool.drum_diameter_mm": 30.0, "spool.wraps": 3.0}])
def test_groove_volume_pappus(changes):
    p = Params()
    for k, v in changes.items():
        p = replace_key(p, k, v)
    n = spool_numbers(p)[0]
    blank = spool_solid(n, groove=False, anchors=False, bore=False, set_screw=False)
    grooved = spool_solid(n, groove=True, anchors=False, bore=False, set_screw=False)
    assert blank.volume - grooved.volume == pytest.approx(groove_volume_closed_form(n), rel=1e-3)


def _faces(solid, kind: str):
    return [f for f in solid.faces() if f.geom_type.name == kind]


def test_bore_and_flat_measured_on_solid(spools):
    p = Params()
    m, clr = p.motor, p.print.clearance_sliding_mm
    for s, mp in zip(spools, L.motor_placements(p)):
        bore = []
        for f in _faces(s.solid, "CYLINDER"):
            c = BRepAdaptor_Surface(f.wrapped).Cylinder()
            loc = c.Axis().Location()
            if abs(c.Axis().Direction().Z()) > 1 - 1e-9 and math.hypot(loc.X() - mp.x_mm, loc.Y()) < 1e-6 \
                    and c.Radius() < m.shaft_diameter_mm:
                bore.append(c.Radius())
        assert bore and all(r == pytest.approx((m.shaft_diameter_mm + clr) / 2, abs=1e-9) for r in bore)
        flats = [f for f in _faces(s.solid, "PLANE") if abs(abs(f.normal_at().X) - 1) < 1e-9
                 and abs(f.center().X - mp.x_mm) < m.shaft_diameter_mm]
        assert len(flats) == 1
        assert flats[0].center().X - mp.x_mm == pytest.approx(
            m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm + clr / 2, abs=1e-9)
        # the flat runs the whole bore
        bb = flats[0].bounding_box()
        assert bb.max.Z - bb.min.Z == pytest.approx(L.spool_dims(p).top_mm - L.spool_dims(p).hub_bottom_mm, abs=1e-6)


def test_set_screw_and_anchor_holes_are_open(spools):
    p = Params()
    for s, n in zip(spools, spool_numbers(p)):
        x0, z0 = n.axis_xy_mm[0], n.z_face_mm
        mid_wall = (n.bore_radius_mm + n.hub_radius_mm) / 2
        # on the set screw's axis (toward the flat, +x): a hole; a quarter turn away: solid hub
        assert not s.solid.is_inside(Vector(x0 + mid_wall, 0, z0 + n.set_screw_z_mm))
        assert s.solid.is_inside(Vector(x0, mid_wall, z0 + n.set_screw_z_mm))
        for angle in n.anchor_angles_rad:   # both lead up, out through the upper flange
            z_out = n.upper_flange_z_mm
            q = (x0 + n.anchor_radius_mm * math.cos(angle), n.anchor_radius_mm * math.sin(angle))
            zf = z0 + sum(z_out) / 2
            assert not s.solid.is_inside(Vector(q[0], q[1], zf))          # the hole through the flange
            rot = angle + math.pi / 2
            assert s.solid.is_inside(Vector(x0 + n.anchor_radius_mm * math.cos(rot),
                                            n.anchor_radius_mm * math.sin(rot), zf))
            # the radial leg opens into the groove at the helix height
            zr = z0 + n.helix_z_mm(angle)
            rr = (n.anchor_radius_mm + n.root_radius_mm) / 2
            assert not s.solid.is_inside(Vector(x0 + rr * math.cos(angle), rr * math.sin(angle), zr))


def test_groove_meets_the_cable_routes():
    """The routes leave the drum at the cable's pitch radius, on the groove within half a pitch."""
    p = Params()
    routes = L.cable_routes(p)
    for n in spool_numbers(p):
        phi_l = n.leave_angles_rad[0]
        for side, phi in ((+1, phi_l), (-1, phi_l - n.wrap_between_rad)):   # unwrapped along the groove
            q = next(r for r in routes if r.joint == n.joint - 1 and r.side == side).points_mm[0]
            assert math.atan2(q[1], q[0] - n.axis_xy_mm[0]) == pytest.approx(math.remainder(phi, 2 * math.pi))
            assert math.hypot(q[0] - n.axis_xy_mm[0], q[1]) == pytest.approx(n.pitch_radius_mm, rel=1e-9)
            # the layout puts the leave points spool.wraps pitches apart; the drum's geometry puts them
            # wrap_between turns apart: the groove meets each route within a quarter pitch
            assert abs(n.helix_z_mm(phi) - (q[2] - n.z_face_mm)) <= n.groove_pitch_mm / 4 + 1e-9
        # the wrap between the leave points is the candidate nearest spool.wraps
        assert abs(n.wrap_between_rad / (2 * math.pi) - p.spool.wraps) <= 0.5 + 1e-9


def test_print_orientation_puts_a_flange_face_on_the_bed(spools):
    s = spools[0]
    rx, ry, rz = s.print_rotation
    from build123d import Axis
    rotated = s.solid.rotate(Axis.X, rx).rotate(Axis.Y, ry).rotate(Axis.Z, rz)
    zmin = rotated.bounding_box().min.Z
    bed = [f for f in rotated.faces() if f.geom_type.name == "PLANE" and abs(f.center().Z - zmin) < 1e-6]
    r_f = L.spool_dims(Params()).flange_radius_mm
    assert sum(f.area for f in bed) > 0.9 * math.pi * r_f**2


@pytest.mark.parametrize("changes", [
    {"spool.drum_diameter_mm": 30.0, "spool.wraps": 3.0},
    {"joints.count": 3, "joints.stations_fraction": (0.55, 0.65, 0.75)},
])
def test_other_designs_build_valid_spools(changes):
    p = Params()
    for k, v in changes.items():
        p = replace_key(p, k, v)
    assert L.layout_problems(p) == []
    numbers = spool_numbers(p)
    assert len(numbers) == p.joints.count
    for n in (numbers[0], numbers[-1]):   # the spools differ only in the angles of their leave points
        solid = spool_solid(n)
        assert solid.is_valid and len(solid.solids()) == 1
        assert solid.bounding_box().max.X - solid.bounding_box().min.X == pytest.approx(2 * n.flange_radius_mm)


def test_drum_too_small_for_the_anchors_is_refused():
    """A 10 mm drum passes the schema's wall check but has no room for the anchor holes around the bore."""
    p = replace_key(Params(), "spool.drum_diameter_mm", 10.0)
    with pytest.raises(UserError, match=r"spool_1: spool.drum_diameter_mm = 10 leaves no room for the cable anchor"):
        spool_numbers(p)
