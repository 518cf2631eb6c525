"""Cables and PTFE tubes as solids (cad/cables.py): numbers against closed forms, meshes, the rules, and the
default design's cables in the assembly check over the joints' range."""
from __future__ import annotations

import dataclasses
import math

import build123d as bd
import numpy as np
import pytest

from swiftfin.cad import cables as C
from swiftfin.cad.assembly import (CONTACTS, Placed, cable_clearance_mm, check_assembly, contact_reason,
                                   link_transform)
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.exports.files import tessellate
from swiftfin.layout import geometry as L
from swiftfin.layout.hull_plan import dry_bulkhead

P = Params()  # the schema defaults are the default design


@pytest.fixture(scope="module")
def pieces():
    return C.cable_pieces(P)


@pytest.fixture(scope="module")
def tubes():
    return C.tube_runs(P)


@pytest.fixture(scope="module")
def cable_meshes(pieces, tubes):
    return C.cable_parts(P, pieces, tubes)


@pytest.fixture(scope="module")
def placed_parts(default_parts, default_params):
    """The default design's printed and bought parts as meshes at the export tolerance (as the pipeline does)."""
    e = default_params.export
    out = []
    for s in default_parts:
        m = tessellate(s.solid, e.mesh_tolerance_mm, e.mesh_angular_tolerance_deg)
        out.append(Placed(s.label, s.link, s.family, m.vertices, m.faces))
    return out


def box(x0, x1, y0, y1, z0, z1):
    return bd.Box(x1 - x0, y1 - y0, z1 - z0).moved(bd.Location(((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)))


def placed(label, solid, link, family="test"):
    m = tessellate(solid, 0.01, 5.0)
    return Placed(label, link, family, m.vertices, m.faces)


# --------------------------------------------------------------------------------------------- numbers
def test_one_piece_per_link_plus_the_groove_and_the_anchor(pieces):
    """Joint J's cable crosses the hinge lines of joints 1..J-1: J straight pieces (links 0..J-1), then its groove and
    anchor on link J: 2 x sum(J + 2) pieces in all."""
    n = P.joints.count
    assert len(pieces) == 2 * sum(J + 2 for J in range(1, n + 1))
    for J in range(1, n + 1):
        for side in ("left", "right"):
            mine = {c.label: c for c in pieces if c.label.startswith(f"cable_{J}_{side}_")}
            assert set(mine) == ({f"cable_{J}_{side}_{k}" for k in range(J)}
                                 | {f"cable_{J}_{side}_{J}_groove", f"cable_{J}_{side}_{J}_anchor"})
            assert all(mine[f"cable_{J}_{side}_{k}"].link == k for k in range(J))
            assert mine[f"cable_{J}_{side}_{J}_groove"].link == J


def test_pieces_meet_on_the_hinge_lines_in_every_pose(pieces):
    """A piece ends where the next begins, on the joint's axis (x = -s_k, y = 0): the cable stays whole whatever the
    joints do (the point on the axis does not move)."""
    st = L.joint_stations_mm(P)
    rng = np.random.default_rng(3)
    stops = L.joint_stop_angles_rad(P)
    by = {c.label: c for c in pieces}
    for J in range(2, P.joints.count + 1):
        for side in ("left", "right"):
            for k in range(1, J):
                a, b = by[f"cable_{J}_{side}_{k - 1}"], by[f"cable_{J}_{side}_{k}"]
                end, start = np.asarray(a.points_mm[-1]), np.asarray(b.points_mm[0])
                assert end == pytest.approx(start, abs=1e-9)
                assert end[:2] == pytest.approx([-st[k - 1], 0.0], abs=1e-9)
                for _ in range(5):
                    th = [float(rng.uniform(-s, s)) for s in stops]
                    ma, mb = link_transform(P, a.link, th), link_transform(P, b.link, th)
                    assert (ma @ np.append(end, 1))[:3] == pytest.approx((mb @ np.append(start, 1))[:3], abs=1e-9)


def test_groove_piece_is_the_seated_radius_round_the_joint_axis(pieces):
    from swiftfin.layout.joints import all_joint_hardware
    for h in all_joint_hardware(P):
        for side in ("left", "right"):
            g = np.asarray(next(c for c in pieces if c.label == f"cable_{h.joint}_{side}_{h.joint}_groove").points_mm)
            assert np.hypot(g[:, 0] - h.x_mm, g[:, 1]) == pytest.approx(P.joints.tendon_moment_arm_mm, abs=1e-9)
            # the straight run ends tangent to it, at the route's last point, inside the arc's span
            last = np.asarray(next(r for r in L.cable_routes(P) if r.joint + 1 == h.joint
                                   and r.side == (1 if side == "left" else -1)).points_mm[-1])
            assert np.min(np.linalg.norm(g - last, axis=1)) < 2 * math.radians(C.ARC_STEP_DEG) * 15.0


def test_tubes_lie_in_their_guides_and_bulkheads(tubes):
    """A tube per cable per guide it passes (a lane's drop and turn in the bay guide are one tube through two joined
    channels) and per bulkhead hole that lies wholly in the bulkhead's material."""
    from swiftfin.layout.guide_plan import channel_centre_lines, guide_blocks
    guide = [t for t in tubes if t.kind == "guide"]
    blocks = guide_blocks(P)
    assert len(guide) == sum(len(channel_centre_lines(b)) for b in blocks)
    joined = sum(len(b.channels) - len(channel_centre_lines(b)) for b in blocks)
    assert joined == 2 * (P.joints.count - 1)      # every lane's drop + turn
    bulk = [t for t in tubes if t.kind == "bulkhead"]
    assert bulk
    for t in bulk:                    # a bulkhead's tube; the dry wall's are its cable glands, as long as the wall
        wall = _wall_mm(t.holder)
        assert L.MIN_TUBE_MM <= t.length_mm <= 1.5 * wall / _axis_x(t), (t.label, t.length_mm, wall)
    assert all(t.od_mm == P.guides.ptfe_tube_od_mm and t.id_mm == P.guides.ptfe_tube_id_mm for t in tubes)


# --------------------------------------------------------------------------------------------- meshes
def test_meshes_are_closed_and_match_the_swept_volume(pieces, tubes, cable_meshes):
    """Volume of a straight cable piece (capsule) and of a tube piece against the circumscribed polygon's closed form."""
    by = {q.label: q for q in cable_meshes}
    n = C.CABLE_SIDES
    k = n / math.pi * math.tan(math.pi / n)          # circumscribed polygon area / circle area
    for c in pieces:
        if c.kind == "anchor" or (c.kind == "run" and len(c.points_mm) == 2):
            length = float(np.linalg.norm(np.subtract(c.points_mm[1], c.points_mm[0])))
            expect = k * math.pi * c.radius_mm**2 * length + 4 / 3 * math.pi * c.radius_mm**3
            assert by[c.label].manifold.volume() == pytest.approx(expect, rel=0.03)
    for t in tubes:
        if len(t.points_mm) == 2:
            nt = C.TUBE_SIDES
            ro = t.od_mm / 2 / math.cos(math.pi / nt)
            ri = t.id_mm / 2
            area = nt / 2 * math.sin(2 * math.pi / nt) * (ro**2 - ri**2)
            # float32 meshes 300 mm from the origin: their ends lie within ~1e-4 mm of the true ones
            assert by[t.label].manifold.volume() == pytest.approx(area * t.length_mm, rel=1e-5, abs=area * 1e-4)
    assert all(q.manifold.volume() > 0 for q in cable_meshes)


# --------------------------------------------------------------------------------------------- bends
def test_tube_bends_are_the_guide_radius(tubes):
    bends = [b for b in C.cable_bends(P, tubes=tubes) if b.kind == "tube"]
    assert bends
    for b in bends:
        assert b.radius_mm == pytest.approx(P.guides.min_bend_radius_mm, rel=1e-6)
        assert b.ok


def test_cable_bends_off_the_hinge_lines_meet_the_cable_minimum():
    """Guide bends (tube radius less the cable's ride on the bore's inside), sector and drum >= 10 d."""
    lim = P.rules.drum_to_cable_min * P.cable.diameter_mm / 2
    for b in C.cable_bends(P):
        if b.kind in ("exit", "drop", "bay"):
            assert b.radius_mm == pytest.approx(P.guides.min_bend_radius_mm
                                                - (P.guides.ptfe_tube_id_mm - P.cable.diameter_mm) / 2)
        if b.kind not in ("hinge", "tube"):
            assert b.ok and b.limit_mm == lim


def test_hinge_bend_is_the_rest_angle_plus_at_most_the_stop():
    stops = L.joint_stop_angles_rad(P)
    rest = {(f"cable_{r.joint + 1}_{'left' if r.side > 0 else 'right'}", b.point_mm): b.angle_rad
            for r in L.cable_routes(P) for b in r.bends if b.kind == "hinge"}
    hinge = [b for b in C.cable_bends(P) if b.kind == "hinge"]
    assert len(hinge) == len(rest) == 2 * sum(range(P.joints.count))
    for b in hinge:
        k = L.joint_stations_mm(P).index(-b.point_mm[0]) + 1
        a0 = rest[(b.label, b.point_mm)]
        assert a0 - 1e-9 <= b.angle_rad <= a0 + stops[k - 1] + 1e-9


def test_hinge_turns_over_the_range_by_the_chain_of_joint_transforms():
    """``layout.geometry.hinge_crossings`` (the rule's and the bends' numbers) against the assembly's own joint
    motion: the outgoing segment moved by ``cad.assembly.chain_transform`` at each of the 41 angles from stop to stop
    (what cad/cables.py computed itself until 2026-12-07)."""
    from swiftfin.cad.assembly import chain_transform
    stops = L.joint_stop_angles_rad(P)
    crossings = {(c.label, c.point_mm): c for c in L.hinge_crossings(P)}
    n = 0
    for r in L.cable_routes(P):
        pts = r.points_mm
        for k, b in enumerate(r.bends, start=1):
            if b.kind != "hinge":
                continue
            u = np.subtract(pts[k], pts[k - 1])
            u = u / np.linalg.norm(u)
            worst = 0.0
            for th in np.linspace(-stops[b.link - 1], stops[b.link - 1], 41):
                v = chain_transform(P, b.link, b.link, {b.link: float(th)})[:3, :3] @ np.subtract(pts[k + 1], pts[k])
                worst = max(worst, math.acos(min(1.0, float(u @ v) / float(np.linalg.norm(v)))))
            c = crossings[f"cable_{r.joint + 1}_{'left' if r.side > 0 else 'right'}", tuple(pts[k])]
            assert c.joint == b.link and c.rest_rad == b.angle_rad
            assert c.worst_rad == pytest.approx(worst, abs=1e-12)
            n += 1
    assert n == len(crossings) == 12


def test_check_says_the_hinge_crossings_bend_round_a_sharp_edge():
    """``swiftfin check`` reports what the expected failure below measures (the build had hidden it): the default's
    12 crossings turn the cable 15.9-77.1 deg round an edge of 0 mm radius where it needs 10 mm; WARN (no key can
    give the edge a lead, and a FAIL would fail every design of two joints or more). One joint: nothing crosses."""
    from swiftfin.design_rules import RuleContext, Severity, run_rules
    f = next(f for f in run_rules(RuleContext(P)) if f.rule_id == "physics.hinge_bend")
    assert f.severity == Severity.WARN and f.value == 0.0 and f.limit == pytest.approx(10.0)
    assert f.detail.startswith("12 of 12 hinge-line crossings turn the cable by 15.9-77.1 deg"), f.detail
    assert "cable_2_right at joint 1, 77.1 deg" in f.detail
    one = dataclasses.replace(P, joints=dataclasses.replace(P.joints, count=1, stations_fraction=(0.6,)))
    assert L.hinge_crossings(one) == ()
    from swiftfin.design_rules.rules import hinge_bend
    assert hinge_bend(RuleContext(one)).severity == Severity.NOT_EVALUATED


@pytest.mark.xfail(strict=True, raises=AssertionError, reason=(
    "Today (re-measured 2026-11-30) every hinge-line crossing turns the cable round the sharp edge of the link's "
    "pass-through hole (radius 0, no lead): 12 bends of 15.9-77.1 deg over the range (joint 2's cables 77.1 deg at "
    "joint 1) need >= 10 mm (10 d). A lead radius (JointHardware.lead_radius_mm) alone would couple the joints and "
    "slacken the pairs (a cable turning round it leaves the axis): the rest turns must leave the hinge lines first, "
    "which needs about 20 mm more room behind the motors (README, Cables and tubes)."))
def test_every_cable_bend_meets_the_cable_minimum_radius():
    problems = C.bend_radius_problems(P)
    assert not problems, "\n".join(map(str, problems))


# --------------------------------------------------------------------------------------------- stops
def test_a_tube_is_seated_on_a_shoulder_at_its_last_end_and_goes_in_by_its_first():
    t = C.TubeRun("tube_test_1_left", 1, 1, 0, "guide", "holder", ((0, 0, 0), (-10, 0, 0)), 4.0, 2.0)
    shoulder = placed("holder", box(-12, -10.0, -5, 5, -5, 5), 0)        # a wall right at the seat (last) end
    far = placed("holder", box(-12, -10.5, -5, 5, -5, 5), 0)             # 0.5 mm beyond: > sliding clearance
    other_link = placed("holder", box(-12, -10.0, -5, 5, -5, 5), 1)
    mouth = placed("holder", box(0.0, 2, -5, 5, -5, 5), 0)               # a wall across the mouth (first) end
    rules = lambda parts: {f.rule for f in C.tube_stop_problems(P, [t], parts)}
    assert rules([shoulder]) == set()
    assert rules([far]) == {"tube_stop"}
    assert rules([other_link]) == {"tube_stop"}          # a stop on another link does not hold the tube
    assert rules([shoulder, mouth]) == {"tube_mouth"}    # seated, but it could never have gone in


def test_every_tube_is_seated_on_its_shoulder_with_its_mouth_open(placed_parts, tubes):
    """Measured on the built meshes of the default design: every guide channel's bore and every bulkhead's bore
    ends on a printed shoulder at the tube's last end, and is open at its first. Before the shoulders
    (2026-11-25) all 74 tube ends were open: the bores ran straight through."""
    problems = C.tube_stop_problems(P, tubes, placed_parts)
    assert not problems, "\n".join(map(str, problems))
    assert {t.kind for t in tubes} == {"guide", "bulkhead"}


def test_a_tube_ends_a_shoulder_short_of_its_bore_and_the_exit_hole_clears_the_cable(tubes):
    shoulder = L.tube_seat_shoulder_mm(P)
    assert shoulder == pytest.approx(L.MIN_WEB_LINES * P.print.line_width_mm)
    assert L.cable_exit_hole_mm(P) - P.cable.diameter_mm >= 2 * cable_clearance_mm(P)
    from swiftfin.layout.gland_plan import in_clevis_room as in_clevis_cut
    from swiftfin.layout.joints import all_joint_hardware
    hw = {h.joint: h for h in all_joint_hardware(P)}
    dry = dry_bulkhead(P)
    r_tube, r_bore = P.guides.ptfe_tube_od_mm / 2, L.tube_bore_diameter_mm(P, "bulkhead") / 2
    short = 0
    for t in tubes:
        if t.kind != "bulkhead":
            continue
        # the bulkhead's thickness along the route, less the mouth's setback (the rim of the square-cut end inside
        # the front face) and the shoulder
        ux = _axis_x(t)
        full = _wall_mm(t.holder) / ux - r_tube * math.sqrt(1 - ux**2) / ux - shoulder
        if t.length_mm == pytest.approx(full, abs=1e-9):
            continue
        # only a dry-wall gland stops short, and only where its bore, carried on, breaks into the clevis room
        short += 1
        assert t.holder == dry.piece and t.length_mm < full, (t.label, t.length_mm, full)
        a, b = (np.asarray(q, float) for q in t.points_mm)
        u = (b - a) / np.linalg.norm(b - a)
        end = b + shoulder * u
        assert not in_clevis_cut(P, hw[dry.rear_joint], np.array([a, end - 0.01 * u]), r_bore), t.label
        assert in_clevis_cut(P, hw[dry.rear_joint], np.array([a, end + 0.05 * u]), r_bore), t.label
    assert 0 < short < 8               # the upper glands of joints 1 and 2 (those beside the clevis room)


def _axis_x(t) -> float:
    a, b = (np.asarray(q, float) for q in t.points_mm)
    return abs(float((b - a)[0] / np.linalg.norm(b - a)))


def _wall_mm(holder: str) -> float:
    """A hull piece's bulkhead thickness along the body: the dry compartment's rear wall is as thick as its glands."""
    dry = dry_bulkhead(P)
    return dry.s_back_mm - dry.s_front_mm if holder == dry.piece else P.hull.bulkhead_thickness_mm


def test_tube_drag_and_holds_match_their_closed_forms():
    """A tube turning 90 deg on a quarter circle: the cable's friction is T (1 - e^(-mu pi / 2)) at the cable's
    breaking strength T; the bond holds tau pi OD L, the shoulder tau_print pi (OD + clearance) s."""
    from swiftfin.catalogues.adhesives import adhesive
    from swiftfin.catalogues.printed_strength import printed_strength
    a = np.radians(np.linspace(0, 90, 91))
    arc = np.column_stack([20 * np.sin(a), 20 * (1 - np.cos(a)), np.zeros_like(a)])
    pts = tuple(map(tuple, np.vstack([[(-5.0, 0.0, 0.0)], arc, [(20.0, 25.0, 0.0)]])))   # straight in and out
    t = C.TubeRun("tube_q_1_left", 1, 1, 0, "guide", "q", pts, 4.0, 2.0)
    assert C.tube_turn_rad(t) == pytest.approx(math.pi / 2, rel=1e-9)
    (r,) = C.tube_retentions(P, [t])
    assert r.drag_n == pytest.approx(P.cable.breaking_strength_n * (1 - math.exp(-P.guides.mu_ptfe * math.pi / 2)))
    assert r.bond_n == pytest.approx(adhesive(C.TUBE_ADHESIVE).allowable_shear_mpa * math.pi * 4.0 * t.length_mm)
    assert r.shoulder_n == pytest.approx(printed_strength(P.print.material).shear_allowable_mpa * math.pi
                                         * (4.0 + P.print.clearance_sliding_mm) * L.tube_seat_shoulder_mm(P))
    assert t.length_mm == pytest.approx(10 + 20 * math.pi / 2, rel=1e-4)


def test_a_tube_the_cable_would_drag_out_is_named():
    """A short tube round a full turn with a strong, grippy cable: its bond (pi x 4 mm x 3 mm of epoxy) cannot hold
    the friction; the finding names the tube and the bond."""
    a = np.radians(np.linspace(0, 360, 361))
    pts = tuple(map(tuple, np.column_stack([0.5 * np.sin(a), 0.5 * (1 - np.cos(a)), 0.01 * a])))
    t = C.TubeRun("tube_coil_1_left", 1, 1, 0, "guide", "q", pts, 4.0, 2.0)
    strong = dataclasses.replace(P, cable=dataclasses.replace(P.cable, breaking_strength_n=5000.0))
    (f,) = C.tube_retention_problems(strong, [t])
    assert f.rule == "tube_retention" and f.label == "tube_coil_1_left" and "bond" in f.detail
    assert C.tube_retention_problems(P, C.tube_runs(P)) == []


def test_the_default_tubes_hold_with_margin(tubes):
    """The default design's worst tube (joint 4's bay tube, 58 deg of turn): 14.8 N of friction at the cable's
    300 N breaking strength against 104 N on its shoulder and 380 N of bond (re-measured 2026-11-25)."""
    rs = C.tube_retentions(P, tubes)
    worst = max(rs, key=lambda r: r.drag_n / min(r.bond_n, r.shoulder_n))
    assert worst.label.startswith("tube_guide_bay_4")
    assert worst.drag_n / min(worst.bond_n, worst.shoulder_n) < 0.2


# --------------------------------------------------------------------------------------------- clearance
def test_cable_clearance_is_half_the_sliding_clearance():
    assert cable_clearance_mm(P) == pytest.approx(0.5 * P.print.clearance_sliding_mm)


def test_declared_contacts_of_a_cable(cable_meshes):
    by = {q.label: q for q in cable_meshes}
    link2 = Placed("joint_link_2", 2, "link", np.zeros((3, 3)), np.zeros((1, 3), int))
    link1 = Placed("joint_link_1", 1, "link", np.zeros((3, 3)), np.zeros((1, 3), int))
    spool2 = Placed("spool_2_upper", 0, "spool", np.zeros((3, 3)), np.zeros((1, 3), int))
    assert "groove" in contact_reason(by["cable_2_left_2_groove"], link2, CONTACTS, P)
    assert "tangent" in contact_reason(by["cable_2_left_1"], link2, CONTACTS, P)
    assert contact_reason(by["cable_2_left_1"], link1, CONTACTS, P) is None     # passes through: must clear it
    assert contact_reason(by["cable_3_left_1"], link2, CONTACTS, P) is None
    assert "spool" in contact_reason(by["cable_2_left_0"], spool2, CONTACTS, P)
    assert contact_reason(by["cable_3_left_0"], spool2, CONTACTS, P) is None
    assert "hinge line" in contact_reason(by["cable_3_left_0"], by["cable_3_left_1"], CONTACTS, P)
    assert contact_reason(by["cable_3_left_0"], by["cable_3_right_1"], CONTACTS, P) is None
    assert "tube" in contact_reason(by["cable_2_left_0"], by["tube_guide_bay_2_left"], CONTACTS, P)
    assert contact_reason(by["cable_1_left_0"], by["tube_guide_bay_2_left"], CONTACTS, P) is None
    guide = Placed("guide_bay", 0, "guide", np.zeros((3, 3)), np.zeros((1, 3), int))
    assert "channel" in contact_reason(by["tube_guide_bay_2_left"], guide, CONTACTS, P)


def test_a_cable_swung_into_a_part_is_named_with_the_joint_angle(cable_meshes):
    """Joint 2's left cable runs on link 1 from joint 1's axis out to its sector; a block on link 0 beside its far end
    is clear at rest (and by the cable clearance up to some angle), met as joint 1 turns toward +y."""
    cab = next(q for q in cable_meshes if q.label == "cable_2_left_1")
    end = cab.vertices[np.argmin(cab.vertices[:, 0])]
    x1 = -L.joint_stations_mm(P)[0]
    r = math.hypot(end[0] - x1, end[1])
    stop = L.joint_stop_angles_rad(P)[0]
    y_reach = r * math.sin(math.atan2(end[1], x1 - end[0]) + stop)   # far end's y at the stop (+ its radius)
    wall = placed("wall", box(end[0] - 6, end[0] + 8, y_reach - 1.0, y_reach + 4, end[2] - 3, end[2] + 3), 0)
    with pytest.raises(BuildError) as err:
        check_assembly(P, [wall, cab], contacts=(), inside_hull=False)
    msg = str(err.value)
    assert "wall and cable_2_left_1" in msg and "joint 1 = +" in msg
    # and a cable moved into a part at rest: both named, the overlap measured
    block = placed("block", box(end[0] + 5, end[0] + 15, end[1] - 3, end[1] + 3, end[2] - 3, end[2] + 3), 1)
    with pytest.raises(BuildError, match=r"block and cable_2_left_1 interfere at rest: overlap"):
        check_assembly(P, [block, cab], contacts=(), inside_hull=False)
    clear = placed("block", box(end[0] + 5, end[0] + 15, end[1] + 3, end[1] + 6, end[2] - 3, end[2] + 3), 1)
    check_assembly(P, [clear, cab], contacts=(), inside_hull=False)


@pytest.mark.slow
def test_cables_and_tubes_clear_every_part_over_the_range(placed_parts, cable_meshes):
    """The default design's cables and tubes against every part and one another, over the joints' range (the build
    runs the same proof: swiftfin.pipeline.check_cables_built). Before the lanes dropped in the bay guide
    (2026-11-25) this found 11 clashes there: the channels of joints 1 and 2 crossed (13.3 mm^3 of tube in tube) and
    the neighbouring lanes' tubes were 0.17-0.24 mm apart."""
    stats = check_assembly(P, placed_parts + cable_meshes, focus={q.label for q in cable_meshes})
    assert stats["pairs"] > len(cable_meshes)


def test_a_guide_that_turns_its_cables_further_gets_a_longer_shoulder():
    """The tube's printed shoulder holds the friction of its cable at the breaking strength. Two lines hold the
    default's tubes (its guides turn a cable 58 deg at most); a seeded design's bay guide turns its outer lanes by
    up to 73 deg, 111 N against the 100 N two lines hold (the build refused it, 2026-11-29). Its shoulder is now as
    many whole lines as that needs, every built tube's retention (its own turn, measured on its centre line) passes,
    and every tube of its guides still finds its seat."""
    from pathlib import Path
    from swiftfin.layout.guide_plan import guide_blocks, is_chain_end
    from swiftfin.layout.design import load_design
    assert L.tube_seat_shoulder_mm(P) == pytest.approx(2 * P.print.line_width_mm)
    p = load_design(Path(__file__).parent / "data" / "seeded_large_drum.toml")
    assert L.tube_seat_shoulder_mm(p) == pytest.approx(3 * p.print.line_width_mm)
    tubes = C.tube_runs(p)
    assert max(C.tube_turn_rad(t) for t in tubes) > math.radians(70)
    assert C.tube_retention_problems(p, tubes) == []
    for b in guide_blocks(p):
        ends = [(ch.joint, ch.side) for ch in b.channels if is_chain_end(b, ch)]
        assert all(b.tube_seat(j, s) is not None for j, s in ends), b.label
