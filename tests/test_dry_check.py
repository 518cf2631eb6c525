"""Openings in the dry compartment's wall, found on the solids (cad/dry_check.py): a hole drilled at a known place is
found there with its size, a blind pocket is told from a through-hole, and the default head's known openings are
listed."""
from __future__ import annotations

import pytest

from swiftfin.cad.dry_check import (check_dry_wall, dry_wall_problems, sealed_part_labels, wall_openings,
                                     wall_zone)


@pytest.fixture(scope="module")
def sealed(default_params, default_parts):
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
    # the zone is thinner than the wall by twice the inset: its volume is below the side wall's (area x thickness)
    # plus the rear wall's solid plug (the section at its front face, the larger, times its length), and well above
    # half of that
    import math
    from swiftfin.design_rules.rules import dry_wall_area_m2
    from swiftfin.layout.hull_plan import dry_bulkhead
    from swiftfin.layout.geometry import half_height_mm, naca_half_width_mm
    p = default_params
    dry = dry_bulkhead(p)
    a, b = float(naca_half_width_mm(p, dry.s_front_mm)), float(half_height_mm(p, dry.s_front_mm))
    plug = math.pi * a * b * (dry.s_back_mm - dry.s_front_mm)
    bound = dry_wall_area_m2(p) * 1e6 * p.hull.wall_thickness_mm * 1.1 + plug
    assert 0.5 * bound < zone.volume() < bound


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


def test_every_opening_of_the_default_dry_wall_is_a_declared_sealed_crossing(default_params, sealed):
    """The default head's dry wall on the built solids: its openings are the eight cable glands through the rear
    wall and the screws through the shell (mount wall fixings, splice screws), each bedded; nothing else. The
    window the clevis cut used to leave in the rear bulkhead is gone."""
    p = default_params
    rep = check_dry_wall(p, _mans(sealed, p))
    assert not rep.unsealed and not dry_wall_problems(p, rep)
    assert len(rep.glands) == 2 * p.joints.count
    by = {b for _, b in rep.sealed}
    assert {g.label for g in rep.glands} <= {lb.strip() for b in by for lb in b.split(",")}
    screws = [c.label for c in rep.screws]
    assert any("splice" in lb for lb in screws) and any("wall" in lb for lb in screws)
    assert len(rep.openings) == len(rep.sealed)
    for g in rep.glands:          # every gland's potted tube is longer than its cable's stroke
        assert g.packed_mm > g.stroke_mm, g


def test_a_section_through_the_rear_wall_is_closed_but_for_the_glands(default_params, sealed):
    """The issue's own test: a section through the dry compartment's rear wall is material everywhere inside the
    hull's outline but the glands' bores (their oblique sections, within 25 %)."""
    import math

    import numpy as np
    from swiftfin.layout.geometry import tube_bore_diameter_mm
    from swiftfin.layout.hull_plan import dry_bulkhead, hull_section_semi_axes_mm

    p = default_params
    dry = dry_bulkhead(p)
    s = dry.s_front_mm + 1.5
    x_to_z = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0], [-1.0, 0.0, 0.0, 0.0]])  # z' = -x = station
    area = sum(m.transform(x_to_z).slice(s).area() for m in _mans(sealed, p).values())
    a, b = hull_section_semi_axes_mm(p, s)
    r = tube_bore_diameter_mm(p, "bulkhead") / 2
    bores = 2 * p.joints.count * math.pi * r * r
    missing = math.pi * a * b - area
    assert bores * 0.9 < missing < bores * 1.25, (missing, bores)


def test_a_hole_drilled_in_the_dry_wall_refuses_the_build_with_its_part_and_place(default_params, sealed):
    """A test-only 3 mm hole along the body through the rear wall, away from every gland: the build's dry-wall
    check refuses it, naming the part and the hole's position."""
    from dataclasses import replace
    from types import SimpleNamespace

    from swiftfin import pipeline
    from swiftfin.cad.assembly import Placed
    from swiftfin.cad.kernel import bd
    from swiftfin.core.errors import BuildError
    from swiftfin.exports.brep import tessellate
    from swiftfin.layout.hull_plan import dry_bulkhead

    p = default_params
    dry = dry_bulkhead(p)
    label = next(lb for lb in sealed if lb.startswith(dry.piece) and lb.endswith("_lower"))
    y, z = -15.0, -25.0                            # low in the wall: the glands are all above the seam
    hole = bd.Solid.make_cylinder(1.5, dry.s_back_mm - dry.s_front_mm + 4.0,
                                  bd.Plane(origin=(-dry.s_front_mm + 2.0, y, z), z_dir=(-1, 0, 0)))
    specs = dict(sealed)
    specs[label] = replace(sealed[label], solid=sealed[label].solid.cut(hole))
    placed = []
    for lb, spec in specs.items():
        m = tessellate(spec.solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)
        placed.append(Placed(lb, 0, "hull", m.vertices, m.faces))
    with pytest.raises(BuildError) as err:
        pipeline.check_dry_wall_built(SimpleNamespace(params=p), placed)
    msg = str(err.value)
    assert "the dry compartment is not closed" in msg and label in msg and "not a declared sealed crossing" in msg
    line = next(ln for ln in msg.splitlines() if label in ln)
    x_c, y_c, z_c = (float(v) for v in line.split(" at (")[1].split(")")[0].split(","))
    assert y_c == pytest.approx(y, abs=0.5) and z_c == pytest.approx(z, abs=0.5)
    assert -dry.s_back_mm <= x_c <= -dry.s_front_mm


def test_a_wall_too_thin_for_the_clevis_room_reopens_the_window_and_is_refused(default_params):
    """The defect this check was written for: with glands of 2 mm the rear wall is the 3 mm bulkhead again, joint
    1's clevis room cuts through it, and the build refuses the window with its part and place."""
    from swiftfin.cad.registry import family_function
    from swiftfin.core.params import replace_key

    p = replace_key(default_params, "hull.cable_gland_length_mm", 2.0)
    parts = {s.label: s for s in family_function("hull")(p) if s.label in sealed_part_labels(p)}
    rep = check_dry_wall(p, _mans(parts, p))
    problems = dry_wall_problems(p, rep)
    window = [o for o in rep.unsealed if o.volume_mm3 > 300]
    assert window and window[0].part.startswith("hull_head_rear"), rep.unsealed
    assert any("not a declared sealed crossing" in pr for pr in problems)
    assert any("no longer than the cable's stroke" in pr for pr in problems)


def test_cables_passing_under_joint_1s_sector_keep_their_glands_clear_of_its_room(monkeypatch):
    """With two joints (tests/data/seeded_bay_crossing.toml) joint 2's cables come down from the spools' plane to
    their low level and crossed the head's rear wall still inside the band of joint 1's tendon sector: the clevis
    room cut their glands to nothing (0.0 mm packed of a 7.7 mm stroke), found only at the build's end. Joint 1's
    pair now sits higher (``layout.geometry.joint1_lift_mm``). Measured along each passing gland's bore, 400 points
    from its mouth to the wall's back face, against joint 1's hardware (``layout.joints``): wherever the bore comes
    within the room's radius of the axis it stays under the room's floor; each gland runs the wall's full depth to
    its seat. Without the lift the bores break into the room and the glands are wetted through."""
    from pathlib import Path

    import numpy as np

    from swiftfin.cad.dry_check import cable_glands
    from swiftfin.layout import geometry as L
    from swiftfin.layout.design import load_design
    from swiftfin.layout.hull_plan import dry_bulkhead
    from swiftfin.layout.joints import joint_hardware

    p = load_design(Path(__file__).parent / "data" / "seeded_bay_crossing.toml")
    assert p.joints.count == 2 and L.joint1_lift_mm(p) > 2 * L.tendon_level_pitch_mm(p)

    def passing(p):
        h = joint_hardware(p, 1)
        reach = h.sector_radius_mm + p.print.clearance_assembly_mm
        floor = h.z_sector_lo_mm - p.print.clearance_sliding_mm
        out = []
        for g in cable_glands(p):
            if g.joint == 1:
                continue
            a, b = np.asarray(g.start_mm), np.asarray(g.end_mm)
            q = a + np.linspace(0.0, 1.0, 400)[:, None] * (b - a)
            q = q[q[:, 0] >= -dry_bulkhead(p).s_back_mm]           # in the wall
            near = np.hypot(q[:, 0] - h.x_mm, q[:, 1]) < reach + g.radius_mm
            out.append((g, near.sum(), np.min(floor - (q[near, 2] + g.radius_mm), initial=np.inf)))
        return out

    got = passing(p)
    assert len(got) == 2
    wall = dry_bulkhead(p).s_back_mm - dry_bulkhead(p).s_front_mm
    for g, n_near, margin in got:
        assert n_near > 0 and margin >= -1e-6, (g.label, margin)     # within the room's reach, under its floor
        assert g.packed_mm > wall - L.tube_seat_shoulder_mm(p) - 1.0 and g.packed_mm > g.stroke_mm
    from tests.conftest import clear_layout_caches
    monkeypatch.setattr(L, "joint1_lift_mm", lambda p: 0.0)
    clear_layout_caches()
    try:
        for g, n_near, margin in passing(p):
            assert margin < -1.0 and g.packed_mm <= g.stroke_mm, (g.label, margin, g.packed_mm)
    finally:
        monkeypatch.undo()
        clear_layout_caches()


def _default_with(key: str, value) -> dict:
    import tomllib
    from pathlib import Path
    raw = tomllib.loads((Path(__file__).parent.parent / "swiftfin.toml").read_text(encoding="utf-8"))
    section, name = key.split(".")
    raw[section][name] = value
    return raw


def test_the_loader_refuses_a_gland_its_stroke_wets_through_and_names_the_length_that_is_not(tmp_path):
    """Joint 1's own cables run into its sector's room in the dry wall's back face, so their glands are shorter than
    ``hull.cable_gland_length_mm`` (10.3 of 14 mm on the default). Declared 9 mm, they would be 5.3 mm against a
    6.6 mm stroke: the build refused it at its end (the dry wall's check); the loader refuses it now, under the key,
    with the least length in half millimetres that keeps every gland longer than its stroke. That length is checked
    by loading it (accepted) and half a millimetre less (refused), and on the glands themselves."""
    import re
    import subprocess
    import sys
    from pathlib import Path

    from swiftfin.core.params import params_from_dict
    from swiftfin.layout.design import design_problems
    from swiftfin.layout.gland_plan import cable_glands

    key = "hull.cable_gland_length_mm"
    _, problems = design_problems(_default_with(key, 9.0))
    assert [pr.key for pr in problems] == [key], [str(pr) for pr in problems]
    text = problems[0].expected
    assert "gland_1_" in text and "no longer than its cable's stroke 6.6 mm (joint 1)" in text, text
    least = float(re.search(r"at least ([0-9.]+) mm", text).group(1))
    assert 9.0 < least < 14.0
    assert design_problems(_default_with(key, least))[1] == []
    assert [pr.key for pr in design_problems(_default_with(key, least - 0.5))[1]] == [key]
    ok = params_from_dict(_default_with(key, least))
    assert min(g.packed_mm - g.stroke_mm for g in cable_glands(ok)) > 0.0
    short = params_from_dict(_default_with(key, least - 0.5))
    assert min(g.packed_mm - g.stroke_mm for g in cable_glands(short)) <= 0.0
    path = tmp_path / "short_glands.toml"
    text = (Path(__file__).parent.parent / "swiftfin.toml").read_text(encoding="utf-8")
    assert text.count("cable_gland_length_mm = 14.0\n") == 1
    path.write_text(text.replace("cable_gland_length_mm = 14.0\n", "cable_gland_length_mm = 9.0\n"), encoding="utf-8")
    run = subprocess.run([sys.executable, "-m", "swiftfin", "check", str(path)], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 2 and "Traceback" not in run.stderr and key in run.stderr, run.stderr


def test_the_loader_refuses_a_dry_wall_that_reaches_the_bay_guide():
    """The dry wall is a whole cross-section of the hull, as thick as the glands and their shoulder: one declared
    millimetre longer than the default's 14 mm brings its front face onto the bay guide's aft end (0.28 mm to spare
    after the assembly clearance). Refused under the key with the most length that leaves the clearance, which
    loads."""
    import re

    from swiftfin.core.params import params_from_dict
    from swiftfin.layout.guide_plan import guide_blocks
    from swiftfin.layout.hull_plan import dry_wall_span_mm

    key = "hull.cable_gland_length_mm"
    _, problems = design_problems_of(_default_with(key, 15.0))
    assert [pr.key for pr in problems] == [key], [str(pr) for pr in problems]
    assert "bay guide's aft end" in problems[0].expected
    most = float(re.search(r"at most ([0-9.]+) mm", problems[0].expected).group(1))
    assert most == 14.0
    assert design_problems_of(_default_with(key, most))[1] == []
    for length, clear in ((15.0, False), (most, True)):
        p = params_from_dict(_default_with(key, length))
        bay = next(b for b in guide_blocks(p) if b.label == "guide_bay")
        gap = dry_wall_span_mm(p)[0] - (-bay.x_mm[0])            # stations: the wall's front face is aft
        assert (gap >= p.print.clearance_assembly_mm) is clear, gap


def design_problems_of(raw):
    from swiftfin.layout.design import design_problems
    return design_problems(raw)


def test_the_dry_walls_room_to_the_bay_guide_is_what_the_meshes_measure(default_params, default_parts):
    """The loader's numbers (``layout.gland_plan.wall_room_mm``: the wall's front face against the bay guide's aft
    end, less the assembly clearance) against the built parts' meshes: manifold's min_gap between the bay guide and
    the head's rear pieces cut at the wall's front face (ahead of it the shell comes 0.56 mm from the guide's clipped
    corner, which the assembly check measures). The default keeps 0.78 mm where 0.5 is asked. A 600 mm body
    measured 0.471 mm both ways (2026-11-29: the loader refuses it; the build's assembly check had refused it at its
    end)."""
    from swiftfin.layout.gland_plan import wall_room_mm
    from swiftfin.layout.hull_plan import dry_wall_span_mm
    p = default_params
    specs = {s.label: s for s in default_parts if s.label == "guide_bay" or s.label.startswith("hull_head_rear")}
    mans = _mans(specs, p)
    x_front = -dry_wall_span_mm(p)[0]
    wall = [m.trim_by_plane((-1.0, 0.0, 0.0), -(x_front + 0.01)) for label, m in mans.items() if label != "guide_bay"]
    gap = min(mans["guide_bay"].min_gap(m, 3.0) for m in wall if not m.is_empty())
    want = wall_room_mm(p) + p.print.clearance_assembly_mm
    assert 0.5 < want < 1.0
    assert gap == pytest.approx(want, abs=2 * p.export.mesh_tolerance_mm), (gap, want)


def _gland_ratings_by_bisection(p):
    """Each cable gland's rated depth [m], computed apart from ``layout.gland_plan``'s closed form: the route's segment
    across the dry wall's mid-plane, its mouth set back until the tube's rim is inside the front face, its bore walked
    back in 40 halvings of the sampled room test (``in_clevis_room``) to where it would break into joint k's room,
    less the seat's shoulder; then ``2 tau_y (packed - stroke) / h`` over the safety factor x rho g."""
    import math

    import numpy as np

    from swiftfin.catalogues.seals import cable_gland
    from swiftfin.layout import geometry as L
    from swiftfin.layout.gland_plan import in_clevis_room
    from swiftfin.layout.hull_plan import dry_wall_span_mm
    from swiftfin.layout.joints import joint_hardware

    sf, sb, rear = dry_wall_span_mm(p)
    h = joint_hardware(p, rear)
    xf, xb = -sf, -sb
    r_bore, tube_r = L.tube_bore_diameter_mm(p, "bulkhead") / 2, p.guides.ptfe_tube_od_mm / 2
    g, env = cable_gland(), p.environment
    stops = L.joint_stop_angles_rad(p)
    out = {}
    for route in L.cable_routes(p):
        pts = np.asarray(route.points_mm, float)
        for a, b in zip(pts[:-1], pts[1:]):
            if (a[0] - (xf + xb) / 2) * (b[0] - (xf + xb) / 2) >= 0:
                continue
            u = (b - a) / np.linalg.norm(b - a)
            front = a + (xf - a[0]) / u[0] * u
            back = a + (xb - a[0]) / u[0] * u
            front = front + tube_r * math.sqrt(1 - u[0] ** 2) / abs(u[0]) * u
            lo, hi = 0.0, float((back - front) @ u)
            if not in_clevis_room(p, h, np.array([front, back]), r_bore):
                lo = hi
            else:
                for _ in range(40):
                    mid = (lo + hi) / 2
                    inside = in_clevis_room(p, h, np.array([front, front + mid * u]), r_bore)
                    lo, hi = (lo, mid) if inside else (mid, hi)
            packed = lo - L.tube_seat_shoulder_mm(p)
            packed = packed if packed >= L.MIN_TUBE_MM else 0.0
            stroke = p.joints.tendon_moment_arm_mm * stops[route.joint]
            hold = 2 * g.grease_yield_stress_pa * max(packed - stroke, 0.0) / g.radial_gap_mm
            side = "left" if route.side > 0 else "right"
            out[f"gland_{route.joint + 1}_{side}"] = hold / (g.pressure_safety_factor * env.water_density_kg_m3
                                                            * env.gravity_m_s2)
    return out


ROOM_BEHIND_THE_MOTORS = {"hull.drive_bay_length_mm": 45.5, "hull.cable_gland_length_mm": 16.0}
"""seeded_gland_short's motors 0.5 mm further forward, which leaves its wall room for 16 mm glands. Until 2026-12-07
this was 5 mm and 20 mm glands, a design the loader took and the build would have refused: its cables then cross
the wall lower, and gland_2_right's tube runs into the seam gasket (0.10 mm into its band); the loader refuses that
now, and 45.5 mm is the most room behind the motors it leaves this design."""


def _with(p, changes: dict):
    """``p`` with ``changes`` through the loader's checks (schema, cross-field and layout: ParamError)."""
    from swiftfin.core.params import ParamError, to_dict
    from swiftfin.layout.design import design_problems
    d = to_dict(p)
    for key, value in changes.items():
        section, name = key.split(".")
        d[section][name] = value
    q, problems = design_problems(d)
    if problems:
        raise ParamError("test", problems)
    return q


@pytest.mark.parametrize("name, changes, verdict", [
    (None, {}, "PASS"), ("seeded_bay_crossing.toml", {}, "PASS"), ("seeded_gland_short.toml", {}, "FAIL"),
    ("seeded_gland_short.toml", ROOM_BEHIND_THE_MOTORS, "PASS")])
def test_check_rates_every_gland_by_its_own_packed_length(name, changes, verdict):
    """``seal.cable_gland`` in ``swiftfin check`` is the least depth over the glands through the dry wall, each its own
    packed length less its own joint's stroke (computed here apart, by bisection on the sampled room test). On
    tests/data/seeded_gland_short.toml joint 1's glands are cut to 6.7 mm by its sector's room for a 4.8 mm stroke:
    0.39 m against the 0.5 m design depth, FAIL; the declared 15 mm less the longest stroke, which the rule rated
    until 2026-11-30, would read 1.6 m and pass. The vectorised twin gives the same value."""
    from pathlib import Path

    from swiftfin.core.schema import Params
    from swiftfin.design_rules import RuleContext, run_rules
    from swiftfin.design_rules.rules import gland_rating_m
    from swiftfin.design_rules.vectorised import evaluate
    from swiftfin.layout.design import load_design
    from swiftfin.layout.geometry import joint_stop_angles_rad

    p = Params() if name is None else load_design(Path(__file__).parent / "data" / name)
    if changes:
        p = _with(p, changes)
    f = next(f for f in run_rules(RuleContext(p)) if f.rule_id == "seal.cable_gland")
    apart = _gland_ratings_by_bisection(p)
    assert len(apart) == 2 * p.joints.count
    worst = min(apart, key=apart.get)
    assert f.value == pytest.approx(apart[worst], abs=1e-6) and f.detail.startswith(worst + ":"), (f.detail, apart)
    assert f.severity.name == verdict
    res = evaluate([p])
    assert res.value[0, res.index("seal.cable_gland")] == pytest.approx(f.value, rel=1e-9)
    declared = gland_rating_m(p, p.hull.cable_gland_length_mm,
                              p.joints.tendon_moment_arm_mm * max(joint_stop_angles_rad(p)))
    assert f.value < declared
    if name == "seeded_gland_short.toml" and not changes:
        assert worst.startswith("gland_1_") and f.value == pytest.approx(0.39, abs=0.01) and declared > 1.5


def test_more_room_behind_the_motors_lets_the_dry_wall_grow():
    """seeded_gland_short's glands cannot grow past 15.5 mm: the wall's front face reaches the bay guide, and the
    loader's refusal names the room behind the motors (``hull.drive_bay_length_mm``) as the way out. 0.5 mm more of it
    moves every motor 0.5 mm forward (and the guides and lanes with them): the wall then takes 16 mm glands (the rule
    passes, above). 5 mm more would take 20 mm glands, but the cables then cross the wall so low that a gland's tube
    runs into the seam gasket, and the loader says how much room this design can have."""
    from pathlib import Path

    from swiftfin.core.params import ParamError
    from swiftfin.layout.design import load_design
    from swiftfin.layout.geometry import cable_routes, joint_stations_mm, motor_placements
    from swiftfin.layout.gland_plan import wall_room_mm

    p = load_design(Path(__file__).parent / "data" / "seeded_gland_short.toml")
    with pytest.raises(ParamError, match=r"hull\.cable_gland_length_mm = 16\.0: .* bay guide.s aft end: at most "
                                         r"15\.5 mm, or more room behind the motors \(hull.drive_bay_length_mm = 45\)"):
        _with(p, {"hull.cable_gland_length_mm": 16.0})
    with pytest.raises(ParamError, match=r"hull\.drive_bay_length_mm = 50\.0: gland_2_right's PTFE tube .* reaches "
                                         r"0\.10 mm into the seam gasket's band .* at most 45\.5 mm behind the motors .*, where "
                                         r"the wall has room for glands of at most 16 mm"):
        _with(p, {"hull.drive_bay_length_mm": 50.0, "hull.cable_gland_length_mm": 20.0})
    q = _with(p, ROOM_BEHIND_THE_MOTORS)
    assert joint_stations_mm(q) == joint_stations_mm(p)
    for a, b in zip(motor_placements(p), motor_placements(q)):
        assert b.s_mm == pytest.approx(a.s_mm - 0.5, abs=1e-9) and b.z_cable_mm == a.z_cable_mm
    # every cable leaves its drum 0.5 mm further forward; the hinge lines stay where the joints are
    for ra, rb in zip(cable_routes(p), cable_routes(q)):
        assert rb.points_mm[0][0] == pytest.approx(ra.points_mm[0][0] + 0.5, abs=1e-9)
        assert [b.point_mm[0] for b in rb.bends if b.kind == "hinge"] == [
            b.point_mm[0] for b in ra.bends if b.kind == "hinge"]
    assert wall_room_mm(q) > 0.0
