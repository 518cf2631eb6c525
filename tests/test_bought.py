"""Bought parts: closed-form volumes, catalogue masses, placement."""
from __future__ import annotations

import math

import pytest
from build123d import Vector

from swiftfin.layout import geometry as L
from swiftfin.cad.bought import MOTOR_CORNER_CHAMFER_FRACTION, make_bought_parts, pilot_hole_diameter_mm
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params


@pytest.fixture(scope="session")
def bought():
    return make_bought_parts(Params())


def test_labels_masses_and_flags(bought):
    p = Params()
    n = p.joints.count
    labels = [b.label for b in bought]
    k = p.environment.flotation_foam_segments
    assert labels == ([f"motor_{j}" for j in range(1, n + 1)] + [c.name for c in p.components]
                      + [f"flotation_{i}" for i in range(1, k + 1)])
    for b in bought:
        assert not b.printed and b.family == "bought"
        assert b.meta["source"]
        assert b.solid.is_valid and len(b.solid.solids()) == 1
    fixed, foam = bought[:len(bought) - k], bought[len(bought) - k:]
    assert all(b.link == 0 for b in fixed)
    assert [b.link for b in foam] == [p.hull.flooded_from_joint + i for i in range(k)]
    assert [b.mass_kg for b in fixed[:n]] == [p.motor.mass_kg] * n
    assert [b.mass_kg for b in fixed[n:]] == [c.mass_kg for c in p.components]
    assert sum(b.mass_kg for b in fixed) == pytest.approx(4 * 0.28 + 0.046 + 0.030)   # screws: exports/line_masses
    # foam: its density times its own solid's volume
    for b in foam:
        assert b.mass_kg == pytest.approx(p.environment.foam_density_kg_m3 * b.solid.volume * 1e-9, rel=1e-12)


def test_motor_volume_closed_form(bought):
    m = Params().motor
    F, c = m.frame_size_mm, MOTOR_CORNER_CHAMFER_FRACTION * m.frame_size_mm
    frame = (F * F - 2 * c * c) * m.body_length_mm          # four corner triangles of legs c
    boss = math.pi * (m.pilot_diameter_mm / 2) ** 2 * m.pilot_height_mm
    r, h = m.shaft_diameter_mm / 2, m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm
    d_area = math.pi * r * r - (r * r * math.acos(h / r) - h * math.sqrt(r * r - h * h))
    shaft = d_area * (m.shaft_length_mm - m.pilot_height_mm)   # the boss holds the shaft's first mm
    for b in bought[:Params().joints.count]:
        assert b.solid.volume == pytest.approx(frame + boss + shaft, rel=1e-9)


def test_motor_placement(bought):
    p = Params()
    m = p.motor
    for b, mp in zip(bought, L.motor_placements(p)):
        bb = b.solid.bounding_box()
        assert (bb.min.X + bb.max.X) / 2 == pytest.approx(mp.x_mm, abs=1e-9)
        assert bb.min.Z == pytest.approx(mp.z_face_mm - m.body_length_mm, abs=1e-9)
        assert bb.max.Z == pytest.approx(mp.z_face_mm + m.shaft_length_mm, abs=1e-9)
        # on the shaft axis just above the boss: solid; beside the flat: air
        z = mp.z_face_mm + m.pilot_height_mm + 1
        assert b.solid.is_inside(Vector(mp.x_mm, 0, z))
        assert not b.solid.is_inside(Vector(mp.x_mm + m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm / 2, 0, z))
        assert b.solid.is_inside(Vector(mp.x_mm - m.shaft_diameter_mm / 2 + m.shaft_flat_depth_mm / 2, 0, z))


def test_component_boxes(bought):
    p = Params()
    for comp in p.components:
        b = next(x for x in bought if x.label == comp.name)
        sx, sy, sz = comp.size_mm
        assert b.solid.volume == pytest.approx(sx * sy * sz, rel=1e-12)
        c = b.solid.center()
        assert tuple(c) == pytest.approx((-comp.station_fraction * p.body.length_mm, 0.0, comp.z_mm), abs=1e-9)
        assert b.meta["source"] == comp.source


def test_pilot_hole_fraction_brackets_iso_tap_drills():
    # ISO 261 coarse tap drills: M2 1.6, M3 2.5; a printed pilot is a little larger (holes print under size)
    assert 1.6 <= pilot_hole_diameter_mm(2.0) <= 1.8
    assert 2.5 <= pilot_hole_diameter_mm(3.0) <= 2.7


def test_three_joint_design():
    p = replace_key(replace_key(Params(), "joints.count", 3), "joints.stations_fraction", (0.55, 0.65, 0.75))
    parts = make_bought_parts(p)
    assert [b.label for b in parts[:3]] == ["motor_1", "motor_2", "motor_3"]
    assert all(b.solid.is_valid for b in parts)
