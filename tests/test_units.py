"""swiftfin.core.units: mm <-> SI, checked by scaling (volume ~ k^3, inertia ~ k^5) and by hand-worked values."""
from __future__ import annotations

import numpy as np
import pytest

from swiftfin.core import units


def test_hand_worked_values():
    assert units.length_m(520.0) == pytest.approx(0.52, rel=1e-15)
    assert units.volume_m3(1.0e6) == pytest.approx(1.0e-3, rel=1e-15)          # a litre
    assert units.area_m2(1.0e6) == pytest.approx(1.0, rel=1e-15)
    assert units.inertia_kg_m2(1.0e6) == pytest.approx(1.0, rel=1e-15)          # kg mm^2 -> kg m^2
    assert units.second_moment_m5(1.0e15) == pytest.approx(1.0, rel=1e-15)
    assert np.allclose(units.length_m(np.array([1000.0, -250.0, 0.5])), [1.0, -0.25, 5e-4], rtol=1e-15)


def test_round_trips():
    x = np.array([0.1, 12.5, -300.0])
    assert np.allclose(units.length_mm(units.length_m(x)), x, rtol=1e-15)
    assert units.volume_mm3(units.volume_m3(123.4)) == pytest.approx(123.4, rel=1e-15)
    assert isinstance(units.length_m(3.0), float)


@pytest.mark.parametrize("k", [0.5, 2.0, 7.3])
def test_scaling_of_a_solid(k):
    """A box scaled by k in mm: its SI volume scales as k^3 and its inertia (fixed density) as k^5."""
    from build123d import Box
    from swiftfin.exports.massprops import solid_volume_props
    rho = 1240.0
    a = solid_volume_props(Box(30.0, 20.0, 10.0))
    b = solid_volume_props(Box(30.0 * k, 20.0 * k, 10.0 * k))
    assert units.volume_m3(b.volume_mm3) == pytest.approx(k**3 * units.volume_m3(a.volume_mm3), rel=1e-9)
    Ia = rho * units.second_moment_m5(np.asarray(a.second_moment_mm5))
    Ib = rho * units.second_moment_m5(np.asarray(b.second_moment_mm5))
    assert np.allclose(Ib, k**5 * Ia, rtol=1e-9, atol=1e-12 * np.abs(Ib).max())  # off-diagonals are ~0
    # and the SI value itself: I_xx = m (b^2 + c^2) / 12 for the 30 x 20 x 10 mm box
    m = rho * 30e-3 * 20e-3 * 10e-3
    assert Ia[0, 0] == pytest.approx(m * (0.02**2 + 0.01**2) / 12, rel=1e-9)
