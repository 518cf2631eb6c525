"""The trim ballast as parts (layout/ballast_plan.py, cad/ballast.py, swiftfin/ballast.py): lead shot set in epoxy,
poured into the hull where it can go. Its integrals are checked against a closed form and a brute-force sum, its
solid against its plan, its place against the hull and the parts inside, and the built fish against the trim."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.catalogues.ballast import ballast_fill
from swiftfin.layout.ballast_plan import (DAM_LABEL, DAM_RISE_MM, FILL_LABEL, fill_density_kg_m3, plan_ballast,
                                          segment)
from tests.conftest import manifold_of


@pytest.fixture(scope="module")
def by_label(default_parts):
    return {s.label: s for s in default_parts}


@pytest.fixture(scope="module")
def fill(by_label):
    return by_label[FILL_LABEL]


def test_fill_density_is_the_catalogue_mix(default_params):
    """Lead shot packed at 0.60 with epoxy (1150 kg/m^3) in its voids, by hand: 0.6 x 11340 + 0.4 x 1150."""
    f = ballast_fill()
    assert fill_density_kg_m3(default_params) == pytest.approx(0.6 * 11340.0 + 0.4 * 1150.0)
    assert f.lead_fraction(11340.0) == pytest.approx(0.6 * 11340.0 / 7264.0)


@pytest.mark.parametrize("level_frac", [0.0, 0.3, 0.7, 0.95])
def test_segment_against_a_brute_force_sum(level_frac):
    """The elliptic segment's area and moment (closed form) against a fine grid's sum over the same section; at the
    seam plane the half ellipse's pi a b / 2 and 4 b / (3 pi) centroid."""
    a, b = 17.0, 29.0
    level = level_frac * b
    area, moment = segment(np.array([a]), np.array([b]), level)
    n = 1601
    y, z = np.meshgrid(np.linspace(-a, a, n), np.linspace(level, b, n))
    inside = (y / a) ** 2 + (z / b) ** 2 <= 1.0
    dA = (2 * a / (n - 1)) * ((b - level) / (n - 1))
    assert area[0] == pytest.approx(inside.sum() * dA, rel=5e-3)
    assert moment[0] == pytest.approx((z * inside).sum() * dA, rel=5e-3)
    if level_frac == 0.0:
        assert area[0] == pytest.approx(math.pi * a * b / 2)
        assert moment[0] / area[0] == pytest.approx(4 * b / (3 * math.pi))


def test_solid_is_its_plan(default_params, fill):
    """The fill's solid (a loft of the inner ellipses cut at the level) holds the plan's volume and centre."""
    plan = fill.meta["plan"]
    assert fill.solid.volume == pytest.approx(plan.volume_mm3, rel=2e-3)
    c = fill.solid.center()
    assert (c.X, c.Y, c.Z) == pytest.approx(plan.com_mm, abs=0.1)
    assert fill.mass_kg == pytest.approx(plan.volume_mm3 * 1e-9 * plan.density_kg_m3, rel=1e-4)   # the last round
    bb = fill.solid.bounding_box()
    assert plan.sigma * bb.min.Z >= plan.z_level_mm - 1e-6 if plan.sigma > 0 else -bb.max.Z >= plan.z_level_mm - 1e-6


def _manifold(solid, p):
    return manifold_of(solid, p.export.mesh_tolerance_mm, p.export.mesh_angular_tolerance_deg)


def test_fill_and_dams_lie_in_the_hollow_clear_of_the_parts_inside(default_params, by_label, fill):
    """Against the half it is poured into, the fill and its dams touch (the bond gap) but do not overlap, and they
    keep print.clearance_assembly_mm from the electronics under them; each end of the fill is a dam or the nose cap,
    the dams stand DAM_RISE_MM proud of the level."""
    p, plan = default_params, fill.meta["plan"]
    dams = [by_label[lb] for lb in by_label if lb.startswith(DAM_LABEL)]
    assert len(dams) == len(plan.dams) >= 1
    shell = _manifold(by_label[plan.bonded_to].solid, p)
    for part in (fill, *dams):
        assert (_manifold(part.solid, p) ^ shell).volume() < 0.5, part.label
    assert plan.z_level_mm - plan.z_dam_mm == pytest.approx(DAM_RISE_MM)
    box = by_label["electronics"].solid.bounding_box()
    for dam in dams:
        dam_edge = dam.solid.bounding_box().min.Z if plan.sigma > 0 else -dam.solid.bounding_box().max.Z
        assert dam_edge >= box.max.Z + p.print.clearance_assembly_mm - 1e-6, dam.label
    if len(plan.dams) == 1:                       # the nose cap closes the fore end, the dam the aft
        assert plan.dams[0][0] == pytest.approx(plan.s_mm[1])
    else:                                         # a dam at each end (2026-11-28, the fill above the electronics)
        assert plan.dams[0][1] == pytest.approx(plan.s_mm[0]) and plan.dams[1][0] == pytest.approx(plan.s_mm[1])


def test_the_built_fish_is_neutral_and_says_what_the_fill_misses(default_robot, default_params, fill):
    """The mass model with the fill: weight = buoyancy, the fill is the trim's mass, and what it misses of the level
    trim's station is reported and costs the static pitch within environment.max_static_pitch_deg."""
    import json
    out, _ = default_robot
    data = json.loads((out / "mass_properties.json").read_text())
    t, tot = data["trim"], data["total"]
    assert t["placed"] == "fill"
    assert t["fill_mass_kg"] == pytest.approx(t["mass_kg"], abs=2e-4)       # the dam's last round: < 0.2 g
    assert abs(tot["net_buoyancy_n"]) < 2e-4 * 9.81
    assert t["fill_miss_x_m"] == pytest.approx(t["x_m"] - fill.meta["plan"].com_mm[0] / 1000, abs=1e-4)
    assert abs(tot["static_pitch_deg"]) <= default_params.environment.max_static_pitch_deg


def test_a_free_target_is_met_with_two_dams(default_params):
    """Where the hollow is free round the target (mid-head, no parts in the way) the fill is centred on it to the
    grid and has a dam at each end."""
    p = default_params
    plan, why = plan_ballast(p, 0.03, -100.0, 10.0, 0, ())
    assert why == ""
    assert plan.com_mm[0] == pytest.approx(-100.0, abs=0.1)
    assert len(plan.dams) == 2 and plan.dams[0][1] == pytest.approx(plan.s_mm[0])
    assert plan.volume_mm3 == pytest.approx(0.03 / fill_density_kg_m3(p) * 1e9, rel=1e-6)


def test_no_room_is_said(default_params):
    """A part filling the whole hollow, or more lead than the hollow holds: no plan, and the reason names it."""
    p = default_params
    plan, why = plan_ballast(p, 0.03, -100.0, 10.0, 0, [("blocker", (-300.0, -80.0, -80.0), (0.0, 80.0, 80.0))])
    assert plan is None and "blocker" in why
    plan, why = plan_ballast(p, 50.0, -100.0, 10.0, 0, ())
    assert plan is None and "holds" in why


def test_a_fill_against_the_nose_cap_keeps_clear_of_a_part_over_its_middle(default_params):
    """Against the nose cap the fill has no front dam; a part standing in its stretch (not over its aft dam) is kept
    clear all the same. Until 2026-11-29 the plan looked for parts over the span of the dams only, which without a
    front dam was the aft dam alone: a seeded design's 2.8 kg fill was poured through its battery and the battery's
    cradle (1.2 and 1.3 cm^3; the build's assembly check found them and refused the design)."""
    p = default_params
    clr = p.print.clearance_assembly_mm
    free, why = plan_ballast(p, 0.03, -20.0, 10.0, 0, ())
    assert why == "" and len(free.dams) == 1, "the fill lies against the nose cap, its one dam aft"
    mid = 0.5 * sum(free.s_mm)
    box = ("blocker", (-(mid + 2.0), -80.0, -80.0), (-(mid - 2.0), 80.0, 80.0))
    plan, why = plan_ballast(p, 0.03, -20.0, 10.0, 0, [box])
    assert why == "" and plan is not None
    for s0, s1 in (plan.s_mm, *plan.dams):
        assert s1 <= mid - 2.0 - clr + 1e-9 or s0 >= mid + 2.0 + clr - 1e-9, (s0, s1)


def test_a_fill_at_a_spliced_end_gets_a_dam_clear_of_the_splice(default_params):
    """A piece's open (spliced) front end holds no fill: the fill would run out of the piece when poured, and the
    splice's tabs and screws take SPLICE_LENGTH_MM behind the cut. A fill wanted there starts behind a dam that
    stands clear of them (it used to start 1 mm ahead of the piece, with no dam)."""
    from swiftfin.layout.hull_plan import SPLICE_LENGTH_MM, hull_pieces
    p = default_params
    pc = next(q for q in hull_pieces(p) if q.front_cut and q.link == 0)
    plan, why = plan_ballast(p, 0.03, -(pc.s_start_mm + 2.0), 10.0, 0, ())
    assert why == "" and plan.piece == pc.name
    assert plan.dams[0][1] == pytest.approx(plan.s_mm[0])
    assert plan.dams[0][0] >= pc.s_start_mm + SPLICE_LENGTH_MM
