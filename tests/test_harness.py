"""The wiring harness (layout/harness_plan.py): the leads from the electronics to each motor and to the battery.

Checked against what was written independently of the routing: the catalogue's numbers by hand, the rounded centre
line against the closed form of a corner arc and against the circumradius of its own samples, the routes' ends
against the motors' and components' boxes, and the swept leads against every built part of the default design by
the assembly check (manifold meshes, not the plan's numbers).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from swiftfin.cad.assembly import Placed, check_assembly
from swiftfin.cad.cables import _circumradii, cable_parts, harness_parts
from swiftfin.catalogues.wiring import lead
from swiftfin.core.errors import BuildError
from swiftfin.layout.geometry import inner_envelope_excess_mm, motor_placements
from swiftfin.layout.harness_plan import harness, rounded_centre_line


# --------------------------------------------------------------------------------------------- numbers by hand
def test_a_leads_diameter_bend_radius_and_mass_by_hand():
    m = lead("motor_lead")
    assert m.bundle_diameter_mm == pytest.approx((1 + math.sqrt(2)) * 1.3)          # four circles round a square
    assert m.min_bend_radius_mm == pytest.approx(2 * 1.3 + ((1 + math.sqrt(2)) * 1.3 - 1.3) / 2)
    # four wires: 0.129 mm^2 of copper and the rest of a 1.3 mm circle of PVC, per metre
    per_wire_g = 0.129 * 8.96 + (math.pi / 4 * 1.3**2 - 0.129) * 1.38
    assert m.linear_density_kg_m * 1000 == pytest.approx(4 * per_wire_g)
    assert 10.0 < m.linear_density_kg_m * 1000 < 13.0       # stepper leads weigh about 11 g/m
    pw = lead("power_lead")
    assert pw.bundle_diameter_mm == pytest.approx(2 * 1.6) and pw.min_bend_radius_mm == pytest.approx(4.0)


def test_a_rounded_corner_is_the_arc_tangent_to_both_legs():
    R = 3.0
    pts, length = rounded_centre_line([(0, 0, 0), (10, 0, 0), (10, 10, 0)], R)
    assert length == pytest.approx(20 - 2 * R + math.pi * R / 2)                     # legs less tangents plus arc
    arc = pts[1:-1]
    assert np.allclose(np.linalg.norm(arc - np.array([10 - R, R, 0]), axis=1), R)   # centred R in from both legs
    assert float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))) == pytest.approx(length, rel=1e-3)
    with pytest.raises(ValueError, match="shorter than its bends"):
        rounded_centre_line([(0, 0, 0), (2, 0, 0), (2, 10, 0)], R)                 # a 2 mm leg for a 3 mm arc


# --------------------------------------------------------------------------------------------- the default design
@pytest.fixture(scope="module")
def leads(default_params):
    return harness(default_params)


def test_every_motor_has_a_lead_from_its_flank_to_the_electronics(default_params, leads):
    p = default_params
    elec = next(c for c in p.components if c.name == "electronics")
    sx, sy, sz = elec.size_mm
    s_elec = elec.station_fraction * p.body.length_mm
    by_joint = {h.joint: h for h in leads}
    assert sorted(by_joint) == [0, *range(1, p.joints.count + 1)]
    half = p.motor.frame_size_mm / 2
    sides = []
    for mp in motor_placements(p):
        h = by_joint[mp.joint + 1]
        a, b = np.asarray(h.centre_line_mm[0]), np.asarray(h.centre_line_mm[-1])
        # it leaves the strain relief on the motor's side face, near its back, at the motor's station
        assert a[0] == pytest.approx(-mp.s_mm) and abs(a[1]) == pytest.approx(half + h.spec.exit_proud_mm)
        assert a[2] == pytest.approx(mp.z_face_mm - p.motor.body_length_mm + h.spec.exit_height_mm)
        # and ends on the electronics' side face, within its length and height
        assert abs(b[1]) == pytest.approx(sy / 2 + p.print.clearance_assembly_mm + 0.1)
        assert s_elec - sx / 2 < -b[0] < s_elec + sx / 2 and elec.z_mm - sz / 2 < b[2] < elec.z_mm + sz / 2
        sides.append(int(np.sign(a[1])))
    assert sum(sides) == 0                  # as many leads on each side


def test_no_lead_bends_tighter_than_its_least_radius(leads):
    """Measured on the sampled centre line (the circle through each three samples), not taken from the plan."""
    for h in leads:
        pts = np.asarray(h.centre_line_mm)
        r = _circumradii(pts)
        assert np.min(r) >= h.spec.min_bend_radius_mm * (1 - 1e-6), h.label
        assert h.bend_radius_mm == pytest.approx(h.spec.min_bend_radius_mm)
        assert float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))) == pytest.approx(h.length_mm, rel=1e-3)


def test_the_leads_lie_inside_the_dry_head(default_params, leads):
    from swiftfin.layout.hull_plan import dry_bulkhead
    p = default_params
    rear = dry_bulkhead(p)
    for h in leads:
        pts = np.asarray(h.centre_line_mm)
        assert np.max(inner_envelope_excess_mm(p, pts)) < -h.diameter_mm / 2, h.label
        assert np.max(-pts[:, 0]) < rear.s_front_mm, h.label


def test_the_swept_leads_clear_every_built_part_and_cable(default_params, default_parts, leads):
    """The assembly check on the meshes: every lead against every part of the default design (tessellated as the
    build does) and every cable piece and tube, at the assembly clearance; the leads among themselves too."""
    from swiftfin.exports.brep import tessellate
    p = default_params
    e = p.export
    placed = []
    for s in default_parts:
        m = tessellate(s.solid, e.mesh_tolerance_mm, e.mesh_angular_tolerance_deg)
        placed.append(Placed(s.label, s.link, s.family, m.vertices, m.faces))
    meshes = harness_parts(p, leads)
    stats = check_assembly(p, placed + cable_parts(p) + meshes, focus={q.label for q in meshes})
    assert stats["inside_checked"] == len(leads) and stats["pairs"] > 100
    # and the check sees a lead that is not where the plan put it: one pushed 2 mm out into the flank's bosses
    h = next(h for h in leads if h.label == "lead_motor_4")
    out = dataclasses.replace(h, centre_line_mm=tuple((x, y + 2.0 * np.sign(y), z) for x, y, z in h.centre_line_mm))
    with pytest.raises(BuildError, match="lead_motor_4"):
        check_assembly(p, placed + harness_parts(p, [out]), focus={"lead_motor_4"})


def test_a_design_without_room_for_its_leads_is_refused_naming_the_lead(default_params):
    """The electronics' box made so low that its side face above the cradle cannot take two stacked leads."""
    p = default_params
    comps = tuple(dataclasses.replace(c, size_mm=(c.size_mm[0], c.size_mm[1], 14.0), z_mm=-14.0)
                  if c.name == "electronics" else c for c in p.components)
    q = dataclasses.replace(p, components=comps)
    with pytest.raises(BuildError, match=r"lead_motor_\d.*over the top of the electronics' side face"):
        harness(q)


def test_the_leads_are_weighed_and_bought(default_params, leads):
    from swiftfin.exports.bom import harness_lines
    from swiftfin.exports.line_masses import harness_masses
    p = default_params
    (pm,) = harness_masses(p, leads)
    assert pm.link == 0 and pm.inertial.mass_kg == pytest.approx(sum(h.mass_kg for h in leads))
    total_m = sum(h.cut_length_mm for h in leads) / 1000
    assert pm.inertial.mass_kg == pytest.approx(sum(h.spec.linear_density_kg_m * h.cut_length_mm / 1000 for h in leads))
    assert 0.5 * 0.0105 * total_m < pm.inertial.mass_kg < 1.5 * 0.0115 * total_m
    lines = harness_lines(p)
    cut = [ln for ln in lines if ln.item != "Connector"]
    assert len(cut) == len(leads)
    for ln, h in zip(cut, leads):
        assert f"cut {h.cut_length_mm:.0f} mm" in ln.spec
        assert h.cut_length_mm == pytest.approx(1.1 * h.length_mm + 10.0)
    assert sum(ln.quantity for ln in lines if ln.item == "Connector") == len(leads)
