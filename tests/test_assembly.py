"""Assembly checks: kinematics against closed forms, clashes built on purpose, and the default design."""
from __future__ import annotations

import math

import build123d as bd
import numpy as np
import pytest

from swiftfin.cad.assembly import (Contact, Placed, chain_transform, check_assembly, inner_envelope_excess_mm,
                          joint_transform, link_transform)
from swiftfin.layout.geometry import half_height_mm, joint_stations_mm, joint_stop_angles_rad, naca_half_width_mm
from swiftfin.exports.files import tessellate
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from tests.conftest import session_cache_dir

P = Params()  # the schema defaults are the default design


def placed(label: str, solid, link: int, family: str = "test") -> Placed:
    m = tessellate(solid, 0.01, 5.0)
    return Placed(label, link, family, m.vertices, m.faces)


def box(x0, x1, y0, y1, z0, z1):
    return bd.Box(x1 - x0, y1 - y0, z1 - z0).moved(bd.Location(((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)))


# --------------------------------------------------------------------------------------------- kinematics
def test_positive_joint_angle_turns_the_tail_toward_plus_y():
    s1 = joint_stations_mm(P)[0]
    th = math.radians(20)
    m = joint_transform(P, 1, th)
    q = m @ np.array([-s1 - 100.0, 0.0, 7.0, 1.0])
    assert q[:3] == pytest.approx([-s1 - 100 * math.cos(th), 100 * math.sin(th), 7.0], abs=1e-9)
    # a point on the axis does not move
    assert (m @ np.array([-s1, 0, 3, 1]))[:3] == pytest.approx([-s1, 0, 3], abs=1e-12)


def test_chain_carries_the_child_axis_with_the_parent():
    s1, s2 = joint_stations_mm(P)[:2]
    a, b = math.radians(10), math.radians(-15)
    m = link_transform(P, 2, [a, b, 0.3, 0.4])  # joints 3 and 4 do not move link 2
    # joint 2's axis point is moved by joint 1 only
    axis2 = m @ np.array([-s2, 0, 0, 1.0])
    d = s2 - s1
    assert axis2[:3] == pytest.approx([-s1 - d * math.cos(a), d * math.sin(a), 0], abs=1e-9)
    # a point 30 mm behind joint 2 turns by the sum of both angles relative to the body axis
    q = m @ np.array([-s2 - 30.0, 0, 0, 1.0])
    assert q[:3] == pytest.approx(axis2[:3] + 30 * np.array([-math.cos(a + b), math.sin(a + b), 0]), abs=1e-9)
    assert np.allclose(chain_transform(P, 1, 2, {1: a, 2: b}), m)


# --------------------------------------------------------------------------------------------- clearance
def _corner_reach(theta: float, r: float, half: float) -> float:
    """Largest y of a cube (half-size ``half``) centred r behind joint 1 when the joint turns by theta:
    y = r sin(theta) + half (sin(theta) + cos(theta)) (corner dx = -half, dy = +half)."""
    return r * math.sin(theta) + half * (math.sin(theta) + math.cos(theta))


@pytest.mark.parametrize("gap_mm, ok", [(0.6, True), (0.45, False), (-0.5, False)])
def test_clearance_over_the_range_of_motion(gap_mm, ok):
    """A cube on link 1 swings toward a wall on link 0; its closest approach is at the stop and equals
    ``gap_mm`` by construction. The wall is 9+ mm away at rest, so only the range of motion can find it."""
    s1 = joint_stations_mm(P)[0]
    stop = joint_stop_angles_rad(P)[0]
    r, h = 50.0, 1.0
    cube = placed("cube", box(-s1 - r - h, -s1 - r + h, -h, h, -h, h), link=1)
    y0 = _corner_reach(stop, r, h) + gap_mm
    assert y0 - h > 9.0  # far at rest
    wall = placed("wall", box(-s1 - 80, -s1 - 20, y0, y0 + 5, -10, 10), link=0)
    if ok:
        stats = check_assembly(P, [wall, cube], contacts=(), inside_hull=False)
        assert stats["pairs"] == 1
    else:
        with pytest.raises(BuildError) as err:
            check_assembly(P, [wall, cube], contacts=(), inside_hull=False)
        msg = str(err.value)
        assert "wall and cube" in msg and "joint 1 = +" in msg
        assert "< print.clearance_assembly_mm" in msg or "interfere" in msg


def test_clash_at_rest_names_both_parts():
    a = placed("block_a", box(-100, -80, -5, 5, -5, 5), link=0)
    b = placed("block_b", box(-82, -60, -5, 5, -5, 5), link=0)   # 2 mm overlap in x: 2 x 10 x 10 mm^3
    with pytest.raises(BuildError) as err:
        check_assembly(P, [a, b], contacts=(), inside_hull=False)
    msg = str(err.value)
    assert "block_a and block_b interfere at rest" in msg
    assert "overlap 200.0 mm^3" in msg


def test_clearance_just_met_at_rest_passes_and_just_missed_fails():
    a = placed("block_a", box(-100, -80, -5, 5, -5, 5), link=0)
    far = placed("block_b", box(-79.45, -60, -5, 5, -5, 5), link=0)   # gap 0.55 >= 0.5
    near = placed("block_b", box(-79.55, -60, -5, 5, -5, 5), link=0)  # gap 0.45 < 0.5
    check_assembly(P, [a, far], contacts=(), inside_hull=False)
    with pytest.raises(BuildError, match=r"gap 0\.450 mm < print.clearance_assembly_mm 0\.5"):
        check_assembly(P, [a, near], contacts=(), inside_hull=False)


def test_declared_contact_may_touch_but_not_interpenetrate():
    a = placed("tab_1", box(-100, -80, -5, 5, -5, 5), link=0)
    touching = placed("plate_1", box(-80, -60, -5, 5, -5, 5), link=0)
    sunk = placed("plate_1", box(-81, -60, -5, 5, -5, 5), link=0)
    table = (Contact(r"tab_(?P<j>\d+)", r"plate_(?P<j>\d+)", "screwed face to face"),)
    with pytest.raises(BuildError):
        check_assembly(P, [a, touching], contacts=(), inside_hull=False)       # undeclared: too close
    check_assembly(P, [a, touching], contacts=table, inside_hull=False)          # declared: touching is fine
    with pytest.raises(BuildError, match="tab_1 and plate_1 interfere at rest"):
        check_assembly(P, [a, sunk], contacts=table, inside_hull=False)          # 100 mm^3 of overlap is not
    other = placed("plate_2", box(-80, -60, -5, 5, -5, 5), link=0)
    with pytest.raises(BuildError):
        check_assembly(P, [a, other], contacts=table, inside_hull=False)  # tab_1 with plate_2: not declared
    moving = placed("plate_1", box(-80, -60, -5, 5, -5, 5), link=1)
    same_link = (Contact(r"tab_(?P<j>\d+)", r"plate_(?P<j>\d+)", "same link only", link_delta=0),)
    assert not same_link[0].matches("tab_1", "plate_1", 0, 1)
    assert same_link[0].matches("plate_1", "tab_1", 0, 0)
    with pytest.raises(BuildError):
        check_assembly(P, [a, moving], contacts=same_link, inside_hull=False)


def test_contact_across_a_joint_is_sampled_over_the_range():
    """A cube on link 1 touching a wall on link 0 at rest, pushing into it as the joint turns: a declared
    contact must still not interpenetrate anywhere in the range."""
    s1 = joint_stations_mm(P)[0]
    cube = placed("cube_1", box(-s1 - 52, -s1 - 48, -2, 2, -2, 2), link=1)
    wall = placed("wall_1", box(-s1 - 70, -s1 - 30, 2, 6, -10, 10), link=0)
    table = (Contact(r"cube_1", r"wall_1", "test"),)
    with pytest.raises(BuildError, match=r"wall_1 and cube_1 interfere at joint 1 = \+"):
        check_assembly(P, [wall, cube], contacts=table, inside_hull=False)


# --------------------------------------------------------------------------------------------- inside the hull
def test_inner_envelope_matches_the_naca_ellipse():
    s = 150.0
    a = float(naca_half_width_mm(P, s)) - P.hull.wall_thickness_mm
    b = float(half_height_mm(P, s)) - P.hull.wall_thickness_mm
    pts = np.array([[-s, a, 0], [-s, 0, b], [-s, a / math.sqrt(2), b / math.sqrt(2)], [-s, 0, 0]])
    ex = inner_envelope_excess_mm(P, pts)
    assert ex[:3] == pytest.approx(0.0, abs=1e-9)
    assert ex[3] < -a / 2


def test_part_poking_through_the_hull_is_found():
    s = 150.0
    a = float(naca_half_width_mm(P, s)) - P.hull.wall_thickness_mm
    inside = placed("battery_like", box(-s - 5, -s + 5, -a + 3, a - 3, -3, 3), link=0, family="bought")
    outside = placed("battery_like", box(-s - 5, -s + 5, -a + 3, a + 1, -3, 3), link=0, family="bought")
    check_assembly(P, [inside], contacts=())
    with pytest.raises(BuildError, match="battery_like lies outside the hull's inner surface by 1.0"):
        check_assembly(P, [outside], contacts=())
    # the fin is outside by design and is not checked
    check_assembly(P, [placed("fin_like", box(-s - 5, -s + 5, -a + 3, a + 1, -3, 3), 0, "fin")], contacts=())


# --------------------------------------------------------------------------------------------- the default design
@pytest.mark.slow
def test_default_design_passes_the_assembly_checks(default_params, tmp_path_factory):
    """Every part of the default design: clearances over the joints' range, declared contacts, inside the hull.
    Through the session's rebuild cache, as a build does: a pair another test of the run (the end-to-end build)
    proved on the same meshes is read, not proved again."""
    from swiftfin.cache import FamilyCache
    from swiftfin.pipeline import build_parts, check_built

    cache = FamilyCache(session_cache_dir(tmp_path_factory))
    result = build_parts(default_params, cache)
    check_built(result, cache)  # raises BuildError naming the parts and the joint angles
    stats = result.assembly_stats
    n = len(result.parts)
    assert stats["pairs"] + stats["contact_pairs"] == n * (n - 1) // 2
    assert stats["contact_pairs"] > 0 and stats["inside_checked"] > 0


def test_clevis_contact_applies_only_near_the_joint():
    """The link-in-clevis contact covers the hull piece at the joint, not every piece of the link ahead."""
    from swiftfin.cad.assembly import CONTACTS, contact_reason

    s1 = joint_stations_mm(P)[0]
    link = placed("joint_link_1", box(-s1 - 5, -s1 + 5, -5, 5, -5, 5), link=1)
    rear = placed("hull_head_rear_upper", box(-s1 + 8, -s1 + 60, -20, 20, 0, 20), link=0)
    front = placed("hull_head_front_upper", box(-s1 + 150, -s1 + 260, -20, 20, 0, 20), link=0)
    assert "clevis" in contact_reason(rear, link, CONTACTS, P)
    assert contact_reason(front, link, CONTACTS, P) is None


def test_the_fin_slot_contact_holds_for_a_hull_not_split_in_halves():
    """With hull.split_halves = false the peduncle is one part, 'hull_peduncle': the fin's tang still slides into
    its slot (declared contact), as in the split hull's 'hull_peduncle_lower' (a build without halves failed on it)."""
    from swiftfin.cad.assembly import CONTACTS, contact_reason

    fin = placed("caudal_fin", box(-500, -480, -2, 2, -10, 10), link=4)
    for label in ("hull_peduncle", "hull_peduncle_lower"):
        ped = placed(label, box(-480, -440, -10, 10, -10, 10), link=4)
        assert "slot" in contact_reason(fin, ped, CONTACTS, P), label
