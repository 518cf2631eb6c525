"""The O-ring gland table (catalogues/seals.toml): every gland squeezes and fills its cord inside the limits, even
with a printed groove's tolerance; stretch is the closed form."""
from __future__ import annotations

import math

import pytest

from swiftfin.catalogues.seals import face_gland, face_glands, seal_limits, stretch


def test_every_gland_keeps_its_cord_inside_the_limits_at_the_print_tolerance():
    lim = seal_limits()
    assert len(face_glands()) == 8
    for g in face_glands():
        lo, hi = g.squeeze_range(lim.print_tolerance_mm)
        assert lim.squeeze_min_fraction <= lo < g.squeeze() < hi <= lim.squeeze_max_fraction, g
        assert g.fill() <= lim.fill_max_fraction, g
        assert g.fill(g.depth_mm - lim.print_tolerance_mm) <= 0.95, g     # room left even in a shallow groove
        assert g.width_mm > g.cord_mm                                      # the ring lies flat in it


def test_squeeze_fill_and_stretch_closed_forms():
    g = face_gland(2.62)
    assert g.squeeze() == pytest.approx((2.62 - 1.96) / 2.62)
    assert g.fill() == pytest.approx(math.pi / 4 * 2.62**2 / (1.96 * 3.52))
    assert stretch(100.0, 103.0) == pytest.approx(0.03) and stretch(100.0, 98.0) == pytest.approx(-0.02)
    with pytest.raises(KeyError, match="1.78"):
        face_gland(1.8)
