"""Support area in print orientation (exports/printability.py), against closed forms on solids built here."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.exports.printability import best_orientation, overhang, rotation_matrix


def _mesh(solid):
    from swiftfin.exports.brep import tessellate
    m = tessellate(solid, 0.01, 2.0)
    return m.vertices, m.faces


def test_a_box_on_the_bed_needs_no_support():
    from swiftfin.cad.kernel import bd
    v, f = _mesh(bd.Solid.make_box(20, 10, 5))
    assert overhang(v, f, 45.0).area_mm2 == 0.0


def test_a_t_shape_needs_its_two_ledges_supported():
    """A 10 x 10 x 10 stem under a 30 x 10 x 2 top: the two 10 x 10 ledges hang in the air."""
    from swiftfin.cad.kernel import bd
    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    v, f = _mesh(stem.fuse(top).clean())
    oh = overhang(v, f, 45.0)
    assert oh.area_mm2 == pytest.approx(200.0, rel=1e-6)
    assert oh.lowest_mm == pytest.approx(10.0)
    # upside down the top lies on the bed and nothing overhangs
    v2 = v @ rotation_matrix(180.0, 0.0, 0.0).T
    assert overhang(v2, f, 45.0).area_mm2 == pytest.approx(0.0, abs=1e-9)
    rot, best, tried = best_orientation(v, f, [(0.0, 0.0, 0.0), (180.0, 0.0, 0.0)], 45.0, (250, 210, 220))
    assert rot == (180.0, 0.0, 0.0) and best.area_mm2 == pytest.approx(0.0, abs=1e-9) and len(tried) == 2


def test_a_sphere_needs_its_cap_below_the_support_angle():
    """A sphere of radius R: the faces steeper than 45 deg below the equator form the cap from the bottom up to
    polar angle 45 deg; projected on the bed it is a disc of radius R sin 45 deg, less the faces that touch the bed
    (within BED_CONTACT_MM: a disc of radius sqrt(2 R h))."""
    from swiftfin.exports.printability import BED_CONTACT_MM
    from swiftfin.cad.kernel import bd
    r = 10.0
    v, f = _mesh(bd.Solid.make_sphere(r))
    oh = overhang(v, f, 45.0)
    contact = math.pi * 2 * r * BED_CONTACT_MM
    assert oh.area_mm2 == pytest.approx(math.pi * (r * math.sin(math.radians(45))) ** 2 - contact, rel=0.015)
    oh30 = overhang(v, f, 60.0)     # a larger support angle lets steeper faces print alone: a smaller cap
    assert oh30.area_mm2 == pytest.approx(math.pi * (r * math.sin(math.radians(30))) ** 2 - contact, rel=0.03)


def test_export_picks_the_candidate_that_needs_least_support(default_params):
    """A part whose family offers two orientations is written in the one that needs no support; one that offers
    none keeps its own."""
    from swiftfin.cad.kernel import bd
    from swiftfin.cad.part import PartSpec
    from swiftfin.exports.files import export_part

    stem = bd.Solid.make_box(10, 10, 10).translate((-5, -5, 0))
    top = bd.Solid.make_box(30, 10, 2).translate((-15, -5, 10))
    t = stem.fuse(top).clean()
    free = export_part(PartSpec("t_free", t, 0, "test", meta={"print_candidates": [(180.0, 0.0, 0.0)]}),
                       default_params)
    assert free.print_rotation == (180.0, 0.0, 0.0) and free.support_area_mm2 == pytest.approx(0.0, abs=1e-6)
    assert [(r, a) for r, a, fits in free.orientations] == [((0.0, 0.0, 0.0), 200.0), ((180.0, 0.0, 0.0), 0.0)]
    fixed = export_part(PartSpec("t_fixed", t, 0, "test"), default_params)
    assert fixed.print_rotation == (0.0, 0.0, 0.0) and fixed.support_area_mm2 == pytest.approx(200.0, rel=1e-3)
