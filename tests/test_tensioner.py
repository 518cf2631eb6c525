"""The split spool as the cable tensioner: travel against need for every joint, and the count against a closed form."""
from __future__ import annotations

import math

import pytest

from swiftfin.core.errors import UserError
from swiftfin.core.params import replace_key
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.tension import tensioner_numbers


def test_travel_covers_the_need_of_every_joint():
    p = Params()
    ts = tensioner_numbers(p)
    assert [t.joint for t in ts] == list(range(1, p.joints.count + 1))
    for t in ts:
        assert t.available_mm >= t.need_mm
        assert t.need_mm == pytest.approx(t.stretch_mm + t.creep_mm + t.tolerance_mm)


def test_need_and_count_closed_form():
    """Hand-worked for joint 4 of the default: loop = both routes; E A = 2 GPa x pi (0.5 mm)^2 = 1570.8 N."""
    p = Params()
    routes = [r for r in L.cable_routes(p) if r.joint == 3]
    loop = sum(r.length_mm for r in routes)
    ea = 2e9 * math.pi * 0.0005**2
    t = tensioner_numbers(p)[3]
    assert t.loop_length_mm == pytest.approx(loop)
    assert t.stretch_mm == pytest.approx(45.0 * loop / ea, rel=1e-12)            # T L / (E A), in mm
    assert t.creep_mm == pytest.approx(0.03 * loop)
    assert t.tolerance_mm == pytest.approx(2 * 3.0)
    assert t.available_mm == pytest.approx(0.75 * 2 * math.pi * 10.0)
    # count: a vernier of 7 and 9 holes steps 360 / 63 = 5.714 deg; each step takes in r x that of loop
    step = 360.0 / (7 * 9)
    assert t.step_deg == pytest.approx(step)
    assert t.step_mm == pytest.approx(10.0 * math.radians(step))
    k = ea / loop                                                                 # N/mm
    assert t.stiffness_n_mm == pytest.approx(k)
    assert t.newton_per_step == pytest.approx(k * 10.0 * math.radians(step))
    assert t.steps_per_newton == pytest.approx(1 / t.newton_per_step)
    assert t.steps_to_pretension == pytest.approx(45.0 / t.newton_per_step)
    assert t.degrees_per_newton == pytest.approx(math.degrees(loop / (ea * 10.0)))


def test_too_little_storage_is_refused_with_the_turns_needed():
    p = replace_key(Params(), "spool.tension_storage_turns", 0.5)
    # joint 4's loop needs 45.08 mm (its 666 mm of free cable since joint 1 sits at 0.555 L): 45.08 / (pi x 20 mm)
    # = 0.7174 turns, rounded up to 0.72
    with pytest.raises(UserError, match=r"joint 4: .* raise spool.tension_storage_turns = 0.5 to at least 0.72"):
        tensioner_numbers(p)
