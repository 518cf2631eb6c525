"""Flotation foam blocks (layout/flotation_plan.py, cad/bought.py): where they go, how big they are, and what the
loader refuses. The volumes are checked two ways: the plan's numerical integral of its sections against the
OpenCascade volume of the lofted, notched solid."""
from __future__ import annotations

import dataclasses
import pytest

from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.design import design_problems
from swiftfin.layout.flotation_plan import foam_blocks, foam_lift_n
from swiftfin.layout.hull_plan import hull_section_semi_axes_mm

P = Params()


def _with_env(**kw) -> Params:
    return dataclasses.replace(P, environment=dataclasses.replace(P.environment, **kw))


def test_default_design_has_a_block_in_each_of_the_first_three_flooded_segments():
    """Three since the wiring was weighed (2026-11-28): with two the trim lead would sit ahead of the nose."""
    blocks = foam_blocks(P)
    assert P.environment.flotation_foam_segments == 3
    assert [b.link for b in blocks] == [P.hull.flooded_from_joint + k for k in range(3)]
    assert [b.glued_to for b in blocks] == ["hull_body_1_lower", "hull_body_2_lower", "hull_body_3_lower"]


def test_block_sits_under_every_cable_inside_the_hull_and_between_its_joints():
    r = max(P.guides.ptfe_tube_od_mm, P.cable.diameter_mm) / 2
    lowest = min(L.tendon_level_mm(P, j, s) for j in range(P.joints.count) for s in (-1, 1))
    js = L.joint_stations_mm(P)
    for b in foam_blocks(P):
        assert b.z_top_mm <= lowest - r - P.print.clearance_assembly_mm + 1e-9
        assert b.z_top_mm < 0.0                       # all of it in the lower half: the seam is z = 0
        assert js[b.link - 1] < b.s0_mm < b.s1_mm < js[b.link]
        for s in (b.s0_mm, b.s1_mm):
            a, h = hull_section_semi_axes_mm(P, s)
            ai, bi = a - P.hull.wall_thickness_mm, h - P.hull.wall_thickness_mm
            for y, z in b.section_yz_mm(P, s):
                assert (y / ai) ** 2 + (z / bi) ** 2 <= 1.0 + 1e-9, (b.label, s, y, z)


def test_plan_volume_equals_the_occ_volume_of_the_solid():
    pytest.importorskip("build123d")
    from swiftfin.cad.bought import make_foam_blocks
    specs = {s.label: s for s in make_foam_blocks(P)}
    for b in foam_blocks(P):
        s = specs[b.label]
        v_occ = s.solid.volume
        assert s.solid.is_valid
        assert v_occ == pytest.approx(b.volume_mm3(P), rel=1e-3)
        assert s.mass_kg == pytest.approx(P.environment.foam_density_kg_m3 * v_occ * 1e-9, rel=1e-12)
        # the notches are really cut: the solid is smaller than the un-notched loft's section x length
        assert v_occ < (b.s1_mm - b.s0_mm) * (b.z_top_mm - b.z_floor_mm) * 2 * b.y_max_mm


def test_lift_is_the_displaced_water_less_the_foam():
    b = foam_blocks(P)[0]
    e = P.environment
    assert foam_lift_n(P, b) == pytest.approx(
        (e.water_density_kg_m3 - e.foam_density_kg_m3) * e.gravity_m_s2 * b.volume_mm3(P) * 1e-9)
    assert foam_lift_n(P, b) > 0.1          # about 17 g: not a sliver


def test_no_blocks_when_asked_for_none():
    assert foam_blocks(_with_env(flotation_foam_segments=0)) == ()


def test_loader_refuses_more_blocks_than_flooded_segments():
    raw = {"hull": {"flooded_from_joint": 4}, "environment": {"flotation_foam_segments": 2}}
    _, problems = design_problems(raw)
    keys = [pr.key for pr in problems]
    assert "environment.flotation_foam_segments" in keys
    text = str(next(pr for pr in problems if pr.key == "environment.flotation_foam_segments"))
    assert "1 flooded segment" in text


def test_a_hull_sealed_behind_the_head_is_refused_naming_the_key():
    """Only the head can be sealed: a sealed segment behind it would need glands in both its walls and a closed
    clevis room for the joint behind it, which the build does not make (a seeded design sealed to joint 4 got as far
    as the build's dry-compartment check, 2026-11-29). Sealed throughout, with no foam, it is refused for that alone."""
    raw = {"hull": {"flooded_from_joint": P.joints.count + 1}, "environment": {"flotation_foam_segments": 0}}
    _, problems = design_problems(raw)
    assert [pr.key for pr in problems] == ["hull.flooded_from_joint"]
    assert "only the head can be sealed" in problems[0].expected


def test_loader_refuses_a_block_with_no_room_naming_the_key_once():
    # a 12 mm vent keeps the peduncle's block off the keel by 12 mm: it has no height left under the cables
    raw = {"hull": {"vent_hole_diameter_mm": 12.0}, "environment": {"flotation_foam_segments": 4}}
    _, problems = design_problems(raw)
    assert len(problems) == 1, [str(x) for x in problems]
    pr = problems[0]
    assert pr.key == "environment.flotation_foam_segments" and pr.value == 4
    assert "no room for a foam block in hull_peduncle" in pr.expected and "height" in pr.expected


def test_a_plan_that_cannot_be_made_is_reported_under_its_key(monkeypatch):
    """A plan's BuildError (no catalogue length, no room) becomes one problem under the key its table names; text
    that merely looks like 'key = value: ...' but names no key does not hijack it."""
    import types

    from swiftfin.core.errors import BuildError
    from swiftfin.layout import design

    fake = types.ModuleType("swiftfin_fake_plan")

    def no_screw(p):
        raise BuildError("no M2 screw of 22.6 mm for the motor mounts' wall fixings")

    def odd_text(p):
        raise BuildError("grip = 22.6 mm: longer than any M2 screw")

    fake.no_screw, fake.odd_text = no_screw, odd_text
    monkeypatch.setitem(__import__("sys").modules, "swiftfin_fake_plan", fake)
    monkeypatch.setattr(design, "_PLANS", (("swiftfin_fake_plan:no_screw", "hull.screw_diameter_mm", "the wall fixings"),
                                           ("swiftfin_fake_plan:odd_text", "hull.screw_diameter_mm", "the splices")))
    problems = design.plan_problems(P)
    assert [pr.key for pr in problems] == ["hull.screw_diameter_mm", "hull.screw_diameter_mm"]
    assert problems[0].value == P.hull.screw_diameter_mm
    assert "the wall fixings cannot be made for this design: no M2 screw of 22.6 mm" in problems[0].expected
    assert "the splices cannot be made for this design: grip = 22.6 mm" in problems[1].expected


def test_a_block_whose_middle_the_joints_swing_takes_away_all_along_is_refused_at_load():
    """tests/data/seeded_foam_apart.toml (a seeded five-joint design): hull_body_1's block, 7.8 mm long between
    notches of 17.2 mm radius about axes 31 mm apart, would be two pieces; the build used to stop at its solid.
    The default's first block keeps 1.9 mm of centre line between its notches, and is one solid."""
    import tomllib
    from pathlib import Path

    from swiftfin.layout.flotation_plan import _centre_cut_all_along
    raw = tomllib.loads((Path(__file__).parent / "data" / "seeded_foam_apart.toml").read_text())
    _, problems = design_problems(raw)
    assert [pr.key for pr in problems] == ["environment.flotation_foam_segments"], [str(x) for x in problems]
    assert "hull_body_1" in problems[0].expected and "come apart" in problems[0].expected
    raw["environment"]["flotation_foam_segments"] = 0
    assert design_problems(raw)[1] == []
    # the cover: touching notches leave nothing; a hair between them keeps the block whole
    assert _centre_cut_all_along(0.0, 10.0, [(-5.0, 10.0), (15.0, 10.0)])
    assert not _centre_cut_all_along(0.0, 10.0, [(-5.0, 10.0), (15.1, 10.0)])
    assert not _centre_cut_all_along(0.0, 10.0, [])
    first = foam_blocks(P)[0]
    gap = min(s + r for s, r in first.notches), max(s - r for s, r in first.notches)
    assert gap[1] - gap[0] == pytest.approx(1.91, abs=0.01)
