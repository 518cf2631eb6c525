"""The fastener table, the fastener records, their hole cutters and the checks on solids (cad/fastener_check.py),
each against closed forms on small solids built here."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.catalogues.fasteners import (dowel, dowels, eclip_for_pin, fastener, screw_diameters_mm,
                                            screw_sizes)
from swiftfin.layout.fastening import Fastener, screw_length
from tests.conftest import manifold_of


# ------------------------------------------------------------------------------------------------ the tables
def test_every_screw_row_is_consistent():
    assert [s.name for s in screw_sizes()] == ["M2", "M2.5", "M3", "M4"]
    for s in screw_sizes():
        d = s.nominal_diameter_mm
        assert s.pilot_hole_mm < d < s.clearance_hole_mm < s.head_diameter_mm < s.counterbore_diameter_mm
        assert s.key_reach_diameter_mm < s.counterbore_diameter_mm      # the driver fits the recess
        assert s.insert_hole_mm > s.clearance_hole_mm and s.insert_outer_diameter_mm > s.insert_hole_mm
        assert s.nut_width_across_flats_mm > s.clearance_hole_mm
        assert 0.75 * d <= s.nut_height_mm <= 0.85 * d                    # ISO 4032: m ~ 0.8 d
        assert list(s.lengths_mm) == sorted(s.lengths_mm) and list(s.set_screw_lengths_mm) == sorted(
            s.set_screw_lengths_mm)
        assert s.insert_length_mm >= s.engagement_min_mm - 1e-9           # an insert alone gives 1.5 d
        # insert boss: hole plus the larger wall on both sides
        assert s.insert_boss_od_mm(0.45) == pytest.approx(s.insert_hole_mm + 2 * max(0.9, 0.4 * s.insert_outer_diameter_mm))


def test_lookups_by_name_and_diameter_agree_and_unknown_sizes_are_named():
    for d in screw_diameters_mm():
        assert fastener(d) is fastener(fastener(d).name)
    with pytest.raises(KeyError, match="M2, M2.5, M3, M4"):
        fastener(1.6)
    with pytest.raises(KeyError, match="pins.toml"):
        dowel(3.3)


def test_every_dowel_in_a_reamed_bore_has_under_a_tenth_of_play():
    for d in dowels():
        lo, hi = d.radial_play_mm()
        assert -0.01 < lo < hi <= 0.1
    assert dowel(3.0).radial_play_mm() == pytest.approx((-0.004, 0.004))   # H7 0/+10 um, m6 +2/+8 um
    assert eclip_for_pin(3.0).groove_diameter_mm == 1.9


def test_screw_length_picks_the_shortest_catalogue_length_with_full_engagement():
    m3 = fastener("M3")
    assert screw_length(m3, 5.0, "insert") == 12.0          # 5 + 5.7 -> 12
    assert screw_length(m3, 5.0, "nut") == 8.0              # 5 + 2.4 + 0.5 -> 8
    assert screw_length(m3, 5.0, "self_tap") == 10.0        # 5 + 4.5 -> 10
    assert screw_length(m3, 5.0, "insert", room_mm=11.0) is None
    assert screw_length(m3, 50.0, "insert") is None


def _f(**kw) -> Fastener:
    base = dict(label="t", size="M3", kind="cap_screw", seat="insert", head_mm=(0.0, 0.0, 10.0),
                axis=(0.0, 0.0, -1.0), length_mm=10.0, grip_mm=4.0, head_part="top", thread_part="bottom",
                joins="test")
    base.update(kw)
    return Fastener(**base)


def test_fastener_records_name_what_is_wrong_with_their_numbers():
    assert _f().problems() == []
    assert "not a catalogue length" in _f(length_mm=11.0).problems()[0]
    assert "cannot cut its own thread" in " ".join(_f(kind="set_screw", seat="self_tap", length_mm=10.0).problems())
    assert "engagement 2.00 mm < 1.5 x M3" in _f(seat="self_tap", length_mm=6.0).problems()[0]
    assert "needs 2.90 mm" in _f(seat="nut", length_mm=6.0, grip_mm=4.0).problems()[0]
    assert "not a unit vector" in _f(axis=(0.0, 0.0, -2.0)).problems()[0]
    assert _f().engagement_mm == pytest.approx(5.7) and _f(seat="nut").engagement_mm == pytest.approx(2.4)


# ------------------------------------------------------------------------------------------------ on solids
def _manifold(solid):
    return manifold_of(solid, 0.01, 5.0)


@pytest.fixture(scope="module")
def blocks():
    """Two 20 x 20 blocks, bottom 10 mm thick (z 0..10), top 4 mm (z 10..14): an M3 x 12 screw from the top into
    an insert in the bottom, its axis 3.5 mm from the blocks' -x face; its tip 8 mm into the bottom."""
    from swiftfin.cad.kernel import bd
    from swiftfin.cad.fastening import head_cutters, seat_cutters

    f = _f(head_mm=(-6.5, 0.0, 14.0), grip_mm=4.0, length_mm=12.0)
    top = bd.Solid.make_box(20, 20, 4).translate((-10, -10, 10))
    bottom = bd.Solid.make_box(20, 20, 10).translate((-10, -10, 0))
    top = top.cut(*head_cutters(f))
    bottom = bottom.cut(*seat_cutters(f))
    return f, top, bottom


def test_cutters_remove_the_closed_form_volumes(blocks):
    f, top, bottom = blocks
    s = f.screw
    clear = math.pi * (s.clearance_hole_mm / 2) ** 2 * 4.0
    assert 20 * 20 * 4 - top.volume == pytest.approx(clear, rel=1e-6)
    pocket = math.pi * (s.insert_hole_mm / 2) ** 2 * s.insert_pocket_depth_mm
    tip = math.pi * (s.clearance_hole_mm / 2) ** 2 * (8.0 + 0.5 - s.insert_pocket_depth_mm)   # to the tip + 0.5
    assert 20 * 20 * 10 - bottom.volume == pytest.approx(pocket + tip, rel=1e-6)


def test_walls_are_measured_on_the_solid_against_closed_forms(blocks, default_params):
    from swiftfin.cad.fastener_check import check_fasteners

    f, top, bottom = blocks
    mans = {"top": _manifold(top), "bottom": _manifold(bottom)}
    rep = check_fasteners(default_params, [f], mans, raise_on_failure=False)
    by = {w.feature: w for w in rep.walls}
    s = f.screw
    # the hole's centre is 3.5 mm from the -x face: wall = 3.5 - r (to the tessellation of the hole)
    assert by["clearance hole"].wall_mm == pytest.approx(3.5 - s.clearance_hole_mm / 2 - 0.05, abs=0.02)
    assert by["insert pocket"].wall_mm == pytest.approx(3.5 - s.insert_hole_mm / 2 - 0.05, abs=0.02)
    assert by["insert pocket"].limit_mm == pytest.approx(max(0.9, s.insert_wall_min_mm))
    # 1.45 mm < the M3 insert's 1.84 mm wall: named with the part and the place
    assert any("bottom: wall round the insert pocket of t is 1.45 mm" in x for x in rep.problems), rep.problems
    assert all("clearance hole" not in x for x in rep.problems)


def test_a_pocket_without_material_and_a_blocked_driver_are_named(blocks, default_params):
    from swiftfin.cad.kernel import bd
    from swiftfin.cad.fastener_check import check_fasteners

    f, top, bottom = blocks
    lid = bd.Solid.make_box(10, 10, 2).translate((-11.5, -5, 34))      # over the head, 17 mm up
    mans = {"top": _manifold(top), "bottom": _manifold(bottom), "lid": _manifold(lid)}
    rep = check_fasteners(default_params, [f], mans, raise_on_failure=False)
    assert any("driver's path" in x and "runs into lid" in x for x in rep.problems), rep.problems
    rep = check_fasteners(default_params, [_f(head_mm=(-6.5, 0.0, 14.0), length_mm=12.0, installed_after=("lid",))],
                          mans,
                          raise_on_failure=False)
    assert not any("driver" in x for x in rep.problems)
    # a part glued into the lid goes on with it: out of the way too, but only when declared so
    foam = bd.Solid.make_box(10, 10, 2).translate((-11.5, -5, 30))
    mans["foam"] = _manifold(foam)
    late = _f(head_mm=(-6.5, 0.0, 14.0), length_mm=12.0, installed_after=("lid",))
    rep = check_fasteners(default_params, [late], mans, raise_on_failure=False)
    assert any("runs into foam" in x for x in rep.problems), rep.problems
    rep = check_fasteners(default_params, [late], mans, raise_on_failure=False, goes_in_with={"foam": "lid"})
    assert not any("driver" in x for x in rep.problems)
    del mans["foam"]
    # the screw moved off the blocks: its insert has no material round it
    off = _f(head_mm=(-30.0, 0.0, 14.0), length_mm=12.0)
    rep = check_fasteners(default_params, [off], mans, raise_on_failure=False)
    assert any("no material of bottom round its insert pocket" in x for x in rep.problems), rep.problems


def test_fastener_masses_come_from_the_catalogue_and_sit_on_their_links(default_params):
    from swiftfin.exports.line_masses import fastener_masses

    m3 = fastener("M3")
    # ISO 4762 M3 x 10 weighs about 1.0 g, an ISO 4032 M3 nut 0.37 g, an ISO 8734 3 x 12 pin 0.67 g (7.85 g/cm^3)
    assert m3.screw_mass_kg(10.0) == pytest.approx(0.99e-3, rel=0.1)
    assert m3.nut_mass_kg == pytest.approx(0.37e-3, rel=0.05)
    assert dowel(3.0).mass_kg(12.0) == pytest.approx(math.pi / 4 * 3.0**2 * 12.0 * 7.85e-6, rel=1e-9)   # kg/mm^3
    fs = [_f(label="a", link=0), _f(label="b", link=0, head_mm=(-100.0, 0.0, 10.0)), _f(label="c", link=2)]
    pms = {pm.label: pm for pm in fastener_masses(default_params, fs)}
    assert set(pms) == {"fasteners_link_0", "fasteners_link_2"}
    one = m3.screw_mass_kg(10.0) + m3.insert_mass_kg
    assert pms["fasteners_link_0"].inertial.mass_kg == pytest.approx(2 * one)
    # the COM halfway between the two screws' middles (x = 0 and -100 mm), 5 mm below their heads
    assert pms["fasteners_link_0"].inertial.com == pytest.approx([-0.05, 0.0, 0.005])


def test_every_fastener_of_the_default_design_names_its_parts(default_params, default_parts):
    """Labels are made by code: every record's parts exist (the build checks only fasteners whose parts it built)."""
    from swiftfin.cad.fastening import all_fasteners
    labels = {s.label for s in default_parts}
    fs = all_fasteners(default_params)
    assert fs
    for f in fs:
        named = {f.head_part, f.thread_part, f.meta.get("slip_part"), *f.meta.get("joins_parts", ())} - {None}
        assert named <= labels, (f.label, named - labels)


# ------------------------------------------------------------------------------------------------ mating pairs
def test_a_touching_pair_of_the_contact_table_needs_a_fastener_or_a_declared_joint(default_params):
    """``unfastened_contacts`` (run in every build's fastener check): a pair the contact table lets touch, that
    touches, is named unless a fastener record joins it or GLUED declares how it is held; a pair apart, the
    diagonal hull halves that meet on an edge, a spool's upper half on its shaft (a bearing) and a component on its
    cradle's pad are not."""
    from swiftfin.cad.assembly import Placed
    from swiftfin.cad.fastener_check import unfastened_contacts
    from swiftfin.cad.link import box
    from swiftfin.exports.brep import tessellate

    def placed(label, solid):
        m = tessellate(solid, 0.01, 5.0)
        return Placed(label, 0, "test", m.vertices, m.faces)

    p = default_params
    hull = placed("hull_head_front_upper", box(0, 10, 0, 10, 0, 10))
    mount = placed("motor_mount_1", box(10, 20, 0, 10, 0, 10))                  # face to face
    apart = placed("motor_mount_1", box(10.5, 20, 0, 10, 0, 10))                # 0.5 mm > sliding clearance
    found = unfastened_contacts(p, [hull, mount], [])
    assert len(found) == 1 and "hull_head_front_upper and motor_mount_1 touch" in found[0]
    screw = _f(head_part="hull_head_front_upper", thread_part="motor_mount_1")
    assert unfastened_contacts(p, [hull, mount], [screw]) == []
    assert unfastened_contacts(p, [hull, apart], []) == []
    diagonal = placed("hull_head_rear_lower", box(10, 20, 0, 10, -10, 0))       # meets hull on an edge
    assert unfastened_contacts(p, [hull, diagonal], []) == []
    same_piece = placed("hull_head_front_lower", box(0, 10, 0, 10, -10, 0))    # face to face: needs its screws
    assert len(unfastened_contacts(p, [hull, same_piece], [])) == 1
    upper = placed("spool_1_upper", box(0, 10, 0, 10, 10, 20))
    shaft = placed("motor_1", box(0, 10, 0, 10, 0, 10))
    assert unfastened_contacts(p, [upper, shaft], []) == []                    # turns on it: a bearing fit
    lower = placed("spool_1", box(0, 10, 0, 10, 10, 20))
    assert len(unfastened_contacts(p, [lower, shaft], [])) == 1                # fixed on it: by its set screw
    cradle = placed("cradle_radio", box(0, 10, 0, 10, 0, 10))
    radio = placed("radio", box(0, 10, 0, 10, 10, 20))
    other = placed("battery", box(0, 10, 0, 10, 10, 20))
    assert unfastened_contacts(p, [cradle, radio], []) == []                   # on its pad
    assert unfastened_contacts(p, [cradle, other], []) == []                   # not its cradle: no contact at all
