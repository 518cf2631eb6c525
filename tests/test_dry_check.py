"""Openings in the dry compartment's wall, found on the solids (cad/dry_check.py): a hole drilled at a known place is
found there with its size, a blind pocket is told from a through-hole, and the default head's known openings are
listed."""
from __future__ import annotations

import pytest

from swiftfin.cad.dry_check import Opening, sealed_part_labels, wall_openings, wall_zone


@pytest.fixture(scope="module")
def sealed(default_params, default_parts):
    from swiftfin.cad.assembly import Placed
    from swiftfin.exports.brep import tessellate
    labels = sealed_part_labels(default_params)
    specs = {s.label: s for s in default_parts if s.label in labels}
    assert set(specs) == set(labels)
    return specs


def _mans(specs, p):
    from swiftfin.cad.assembly import Placed
    from swiftfin.exports.brep import tessellate
    out = {}
    for label, s in specs.items():
        m = tessellate(s.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        out[label] = Placed(label, 0, "hull", m.vertices, m.faces).manifold
    return out


def test_the_wall_zone_is_the_shell_between_the_envelopes(default_params):
    zone, outer, inner = wall_zone(default_params)
    assert zone.volume() > 0 and outer.volume() > 0 and inner.volume() > 0
    # the zone is thinner than the wall by twice the inset: its volume is below the wall's (area x thickness)
    from swiftfin.design_rules.rules import dry_wall_area_m2
    assert zone.volume() < dry_wall_area_m2(default_params) * 1e6 * default_params.hull.wall_thickness_mm * 1.1


def test_a_drilled_hole_and_a_blind_pocket_are_found_where_they_are(default_params, sealed):
    from dataclasses import replace
    from swiftfin.cad.kernel import bd
    from swiftfin.layout.hull_plan import hull_section_semi_axes_mm

    p = default_params
    before = _mans(sealed, p)
    base = wall_openings(p, before)
    # a 5 mm hole straight down through the top of the front upper half at s = 100 mm, and a 6 mm blind pocket
    # 1 mm deep (half the wall) from the outside at s = 170 mm, where the hull is near its widest and its top flat
    def upper_at(s):
        return next(lb for lb, sp in sealed.items() if lb.endswith("_upper")
                    and sp.solid.bounding_box().min.X < -s < sp.solid.bounding_box().max.X)
    label, label2 = upper_at(100.0), upper_at(170.0)
    a, b = hull_section_semi_axes_mm(p, 100.0)
    hole = bd.Solid.make_cylinder(2.5, 20.0, bd.Plane(origin=(-100.0, 0.0, b - 8.0)))
    a2, b2 = hull_section_semi_axes_mm(p, 170.0)
    pocket = bd.Solid.make_cylinder(3.0, 10.0, bd.Plane(origin=(-170.0, 0.0, b2 - 1.0)))
    cut = dict(sealed)
    cut[label] = replace(sealed[label], solid=sealed[label].solid.cut(hole))
    cut[label2] = replace(cut[label2], solid=cut[label2].solid.cut(pocket))
    after = wall_openings(p, _mans(cut, p))
    new = [o for o in after if all(abs(o.centre_mm[0] - q.centre_mm[0]) > 1.0 or abs(o.centre_mm[2] - q.centre_mm[2]) > 1
                                   for q in base)]
    assert len(new) == 2, (new, base)
    through = next(o for o in new if o.through)
    blind = next(o for o in new if not o.through)
    assert through.part == label and through.centre_mm[0] == pytest.approx(-100.0, abs=0.3)
    assert through.size_mm[0] == pytest.approx(5.0, abs=0.3)         # the hole's diameter along x
    assert blind.part == label2 and blind.centre_mm[0] == pytest.approx(-170.0, abs=0.3)
    assert "pocket in the dry wall" in str(blind) and "opening through the dry wall" in str(through)


def test_the_default_heads_openings_are_listed(default_params, sealed):
    """What floods the default head today (issue 13): its cuts through the dry wall, each with its part and place.
    The largest is the window the clevis cut leaves in the rear bulkhead."""
    ops = [o for o in wall_openings(default_params, _mans(sealed, default_params)) if o.through]
    assert ops, "the default head has no opening in its dry wall"
    biggest = max(ops, key=lambda o: o.volume_mm3)
    assert isinstance(biggest, Opening) and biggest.part.startswith("hull_head")
