"""Assembly steps (cad/assembly_steps.py): orders and ways in known by construction on boxes, blocks the planner
must find (a captive ring, a wall thinner than any sampling step), the fasteners' precedence, and the default
design's plan checked against an independent sampled sweep."""
from __future__ import annotations

import json

import build123d as bd
import numpy as np
import pytest

from swiftfin.cad.assembly import Contact, Placed
from swiftfin.cad.assembly_steps import AXES, PathMemo, path_blocker, plan_steps, steps_json
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.exports.files import tessellate
from swiftfin.layout.fastening import Fastener
from tests.conftest import session_cache_dir

P = Params()
NO_CONTACTS: tuple[Contact, ...] = ()


def placed(label: str, solid, link: int = 0, family: str = "test") -> Placed:
    m = tessellate(solid, 0.01, 5.0)
    return Placed(label, link, family, m.vertices, m.faces)


def box(x0, x1, y0, y1, z0, z1):
    return bd.Box(x1 - x0, y1 - y0, z1 - z0).moved(bd.Location(((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2)))


def cup():
    """A 40 x 40 x 30 mm box open at the top, 3 mm walls."""
    return box(-20, 20, -20, 20, 0, 30) - box(-17, 17, -17, 17, 3, 31)


def test_a_peg_goes_into_a_cup_from_above_and_the_lid_last():
    cup_p = placed("hull_head_front_lower", cup())
    peg = placed("battery", box(-5, 5, -5, 5, 3.5, 25))
    lid = placed("hull_head_front_upper", box(-20, 20, -20, 20, 30.5, 33))
    plan = plan_steps(P, [cup_p, peg, lid], threads=False, contacts=NO_CONTACTS)
    assert plan.order() == ["hull_head_front_lower", "battery", "hull_head_front_upper"]
    steps = {s.parts[0]: s for s in plan.steps}
    assert steps["battery"].direction == "-z" and steps["hull_head_front_upper"].direction == "-z"
    # the peg's way in starts above the lid's top: its box clears the cup's (top 30) by the margin
    assert steps["battery"].travel_mm[0] == pytest.approx(30 - 3.5 + 2.0, abs=0.05)


def test_a_captive_ring_cannot_be_put_on_and_the_plan_says_which_parts_block():
    """A ring round the waist of a dumbbell whose ends are wider than its hole: no translation frees either."""
    bell = (box(-40, -30, -10, 10, -10, 10) + box(-30, 30, -3, 3, -3, 3) + box(30, 40, -10, 10, -10, 10))
    ring = box(-5, 5, -8, 8, -8, 8) - box(-6, 6, -4, 4, -4, 4)
    with pytest.raises(BuildError) as err:
        plan_steps(P, [placed("joint_link_1", bell), placed("guide_bay", ring)], threads=False,
                   contacts=NO_CONTACTS)
    text = str(err.value)
    assert "no part still in place can be taken out" in text
    assert "guide_bay along +x" in text and "(joint_link_1)" in text


def test_a_wall_thinner_than_any_sampling_step_still_blocks():
    """A 0.2 mm sheet moving through a 0.2 mm sheet: samples 1 mm apart would step over it; the gap-driven
    advancement cannot."""
    sheet = placed("a", box(-10, 10, -10, 10, 0, 0.2))
    wall = placed("b", box(-20, 20, -20, 20, 5.1, 5.3))
    blocked, travel, _ = path_blocker(P, [sheet], "+z", [wall], NO_CONTACTS)
    assert blocked is not None and blocked.blocker == "b"
    assert 4.8 < blocked.travel_mm <= 4.9 + 1e-6    # stopped within the passing gap of the wall's face at 5.1
    free, _, _ = path_blocker(P, [sheet], "-z", [wall], NO_CONTACTS)
    assert free is None


def test_a_declared_contact_may_slide_but_not_overlap():
    """A peg in a hole of its own size (declared contact) slides out along the hole, not across it."""
    plate = placed("spool_1", box(-20, 20, -20, 20, 0, 5) - bd.Cylinder(4, 20))
    peg = placed("motor_1", bd.Cylinder(4, 10).moved(bd.Location((0, 0, 5))))
    contacts = (Contact(r"motor_1", r"spool_1", "a peg in its hole"),)
    assert path_blocker(P, [peg], "+z", [plate], contacts)[0] is None
    blocked = path_blocker(P, [peg], "+x", [plate], contacts)[0]
    assert blocked is not None and blocked.contact and blocked.blocker == "spool_1"


def test_a_contact_slide_is_blocked_at_the_far_end_of_a_long_rail():
    """A block riding on a rail (declared contact, face to face) slides 60 mm along it to a stop at its far end:
    the sampled slide, on the parts cut to where they can meet, finds the stop where an uncut boolean does, and
    the direction away from the stop is clear."""
    rail = placed("hull_body_1_lower", box(-10, 80, -10, 10, -5, 0) + box(70, 80, -10, 10, 0, 6))
    block = placed("battery", box(-10, 10, -8, 8, 0, 5))
    contacts = (Contact(r"battery", r"hull_.+", "riding on its rail"),)
    blocked = path_blocker(P, [block], "+x", [rail], contacts)[0]
    assert blocked is not None and blocked.contact and blocked.blocker == "hull_body_1_lower"
    # the block's front face (x = 10) meets the stop's face (x = 70) at 60 mm; past it the overlap grows by the
    # block's 16 x 5 mm face per mm, and blocks at the first sample past the tessellation's allowance
    allowed = 2 * P.export.mesh_tolerance_mm * min(block.manifold.surface_area(), rail.manifold.surface_area())
    into = allowed / (16 * 5)
    assert 60.0 + into < blocked.travel_mm <= 60.0 + into + P.print.clearance_sliding_mm + 1e-9
    u = np.asarray(AXES["+x"], float)
    whole = (block.manifold.translate(tuple(float(c) for c in blocked.travel_mm * u)) ^ rail.manifold).volume()
    assert blocked.measure_mm == pytest.approx(whole, rel=1e-4)
    assert path_blocker(P, [block], "-x", [rail], contacts)[0] is None


def test_a_fastener_driven_before_a_part_goes_on_orders_the_steps():
    """A screw into the cup's floor whose key passes where another part goes: that part goes on after it, whatever
    the removal preferences say (by label the battery would come out first, so go in last), and the screw is
    listed in the step of the last part it joins."""
    cup_p = placed("hull_body_1_lower", cup())
    blk = placed("battery", box(-5, 5, -5, 5, 3.5, 8))
    side = placed("electronics", box(8, 15, -5, 5, 3.5, 8))      # beside it: nothing but the screw orders them
    screw = Fastener("battery_screw", "M2", "cap_screw", "insert", (0.0, 0.0, 8.0), (0.0, 0.0, -1.0), 8.0, 5.0,
                     "battery", "hull_body_1_lower", "holds the block", 0, installed_after=("electronics",))
    plan = plan_steps(P, [cup_p, blk, side], fasteners=[screw], threads=False, contacts=NO_CONTACTS)
    order = plan.order()
    assert order.index("electronics") > order.index("battery")
    at = next(s for s in plan.steps if "battery_screw" in s.fasteners)
    assert "battery" in at.parts and plan.fastener_count == 1


def test_a_glued_part_goes_in_with_its_host():
    cup_p = placed("hull_body_1_lower", cup())
    foam = placed("flotation_1", box(-17, 17, -17, 17, 3, 10))
    plan = plan_steps(P, [cup_p, foam], glued={"flotation_1": "hull_body_1_lower"}, threads=False,
                      contacts=(Contact(r"flotation_1", r"hull_.+", "glued"),))
    assert [s.parts for s in plan.steps] == [("hull_body_1_lower", "flotation_1")]


def _plan_record(plan):
    return [(s.parts, s.direction, s.travel_mm, s.fasteners, s.threads) for s in plan.steps], plan.notes


def test_remembered_ways_in_give_the_same_plan_and_a_moved_part_is_proved_again(tmp_path):
    """A memo of each pair's result (PathMemo): planned again with it, nothing is proved anew and the plan is the
    same; with the battery moved (a new mesh), only the pairs with the battery are proved again, and a battery moved
    into the cup's wall is still refused (its block comes from a fresh proof, not from the memo)."""
    cup_p = placed("hull_head_front_lower", cup())
    lid = placed("hull_head_front_upper", box(-20, 20, -20, 20, 30.5, 33))
    side = placed("electronics", box(8, 15, -5, 5, 3.5, 8))
    peg = placed("battery", box(-5, 5, -5, 5, 3.5, 25))
    fresh = plan_steps(P, [cup_p, peg, side, lid], threads=False, contacts=NO_CONTACTS)
    memo = PathMemo(tmp_path / "paths")
    first = plan_steps(P, [cup_p, peg, side, lid], threads=False, contacts=NO_CONTACTS, memo=memo)
    assert first.pairs_remembered == 0 and _plan_record(first) == _plan_record(fresh)
    again = plan_steps(P, [cup_p, peg, side, lid], threads=False, contacts=NO_CONTACTS, memo=memo)
    assert _plan_record(again) == _plan_record(fresh)
    assert again.pairs_remembered == again.pair_checks == first.pair_checks >= 2
    moved = placed("battery", box(-4, 6, -5, 5, 3.5, 25))
    other = plan_steps(P, [cup_p, moved, side, lid], threads=False, contacts=NO_CONTACTS, memo=memo)
    assert 0 < other.pairs_remembered < other.pair_checks
    assert other.order() == fresh.order()
    stuck = placed("battery", box(-22, -12, -5, 5, 3.5, 25))       # through the cup's wall at x = -20..-17
    with pytest.raises(BuildError, match="no part still in place can be taken out"):
        plan_steps(P, [cup_p, stuck, side, lid], threads=False, contacts=NO_CONTACTS, memo=memo)


# --------------------------------------------------------------------------------------------- the default design
@pytest.fixture(scope="module")
def default_plan(default_params, tmp_path_factory):
    """The default design's plan, proved with a fresh memo of the pairs' ways in (the build's PathMemo)."""
    from swiftfin.cache import FamilyCache
    from swiftfin.pipeline import build_parts, placed_parts

    result = build_parts(default_params, FamilyCache(session_cache_dir(tmp_path_factory)))
    placed = placed_parts(result)
    memo = PathMemo(tmp_path_factory.mktemp("assembly-paths"))
    return result, placed, plan_steps(default_params, placed, *_fasteners_and_glue(result, placed), memo=memo), memo


def _fasteners_and_glue(result, placed):
    from swiftfin.pipeline import built_fasteners
    return built_fasteners(result, placed)


def test_the_default_plan_planned_again_from_its_memo_is_the_same(default_plan, default_params):
    """Planned again with the memo of the first planning (what a rebuild after a change elsewhere does): every
    pair's way in comes from the memo and the steps are the same, step for step."""
    result, placed, plan, memo = default_plan
    again = plan_steps(default_params, placed, *_fasteners_and_glue(result, placed), memo=memo)
    assert again.pairs_remembered == again.pair_checks == plan.pair_checks > 100
    assert _plan_record(again) == _plan_record(plan)


def test_every_part_fastener_cable_and_tube_of_the_default_design_goes_in_once(default_plan, default_params):
    from swiftfin.cad.cables import tube_runs
    from swiftfin.cad.fastening import all_fasteners

    result, _, plan, _ = default_plan
    parts = [q for s in plan.steps for q in s.parts]
    assert sorted(parts) == sorted(b.spec.label for b in result.parts)
    fast = [f for s in plan.steps for f in s.fasteners]
    assert sorted(fast) == sorted(f.label for f in all_fasteners(default_params))
    threads = [t for s in plan.steps for t in s.threads]
    tubes = [t for t in threads if t.startswith("tube_")]
    assert sorted(tubes) == sorted(t.label for t in tube_runs(default_params))
    for j in range(1, default_params.joints.count + 1):
        assert f"cable_{j}" in threads
    # the file the build writes says the same
    data = json.loads(steps_json(plan))
    assert [s["number"] for s in data["steps"]] == list(range(1, len(plan.steps) + 1))
    assert data["fasteners"] == len(fast)


def test_the_default_plan_honours_every_fasteners_precedence(default_plan, default_params):
    """Read from the fastener records, not the planner: each fastener's parts are all in by its step, and every
    part listed in its installed_after goes on in a later step."""
    from swiftfin.cad.fastening import all_fasteners

    _, _, plan, _ = default_plan
    at = {q: s.number for s in plan.steps for q in s.parts}
    driven = {f: s.number for s in plan.steps for f in s.fasteners}
    for f in all_fasteners(default_params):
        joined = {f.head_part, f.thread_part, f.meta.get("slip_part")} - {None}
        assert max(at[q] for q in joined) == driven[f.label], f.label
        for q in f.installed_after:
            if q in at:
                assert at[q] > driven[f.label], (f.label, q)


def test_each_way_in_is_clear_when_swept_by_an_independent_sampler(default_plan, default_params):
    """An independent check of the planner's proof on the steps a builder finds tightest (the motor units into the
    head, the spools onto their shafts, the lid, the fin into its slot): the part set back along its way in at
    samples every 0.25 mm from its seat to 30 mm out, against every part already placed whose box it comes near; a
    non-contact pair may not overlap at all (boolean volume), a declared contact only by the tessellation's
    allowance."""
    from swiftfin.cad.assembly import CONTACTS, contact_reason

    _, parts, plan, _ = default_plan
    by = {q.label: q for q in parts}
    tol = default_params.export.mesh_tolerance_mm
    before: list[str] = []
    checked = 0
    for s in plan.steps:
        if s.parts and any(k in s.parts[0] for k in ("motor_mount_", "hull_head_rear_upper", "caudal_fin")):
            u = np.asarray(AXES[s.direction], float)
            for q in s.parts:
                m = by[q]
                lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
                lo, hi = np.minimum(lo, lo - 30 * u), np.maximum(hi, hi - 30 * u)
                for other in before:
                    o = by[other]
                    if (o.vertices.min(axis=0) > hi + 0.5).any() or (o.vertices.max(axis=0) < lo - 0.5).any():
                        continue
                    reason = contact_reason(m, o, CONTACTS, default_params)
                    allowed = (2 * tol * min(m.manifold.surface_area(), o.manifold.surface_area())
                               if reason else 1e-3)
                    for t in np.arange(0.25, 30.0, 0.25):
                        vol = (m.manifold.translate(tuple(float(c) for c in -t * u)) ^ o.manifold).volume()
                        assert vol <= allowed, (q, other, t, vol)
                checked += 1
        before += list(s.parts)
    assert checked >= 10
