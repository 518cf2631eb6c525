"""Capstan transmission (paper eq. 20-29) and the pull-pull tension split, against hand-worked values."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.physics import capstan as cp


def test_tension_ratio_eq21():
    # 0.35 x 4 pi = 4.398230; e^4 = 54.598150, e^0.398230 = 1.489187 -> 81.3068
    assert float(cp.tension_ratio(0.35, 4 * math.pi)) == pytest.approx(54.598150 * 1.489187, rel=2e-6)
    assert float(cp.tension_ratio(0.35, 4 * math.pi)) == pytest.approx(81.307, abs=1e-3)


def test_bending_correction_eq23():
    # EI / (T0 r^2) = 1e-5 / (10 x 1e-4) = 0.01 -> T1 = 10 x 81.307 x 1.01 = 821.20
    assert cp.bending_corrected_tension(10.0, 0.35, 4 * math.pi, 1e-5, 0.01) == pytest.approx(821.20, abs=0.01)
    # EI = 0: plain capstan
    assert cp.bending_corrected_tension(10.0, 0.35, 4 * math.pi, 0.0, 0.01) == pytest.approx(813.07, abs=0.01)


def test_guide_and_route_efficiency_eq24_25():
    # e^(-0.05 pi/2) = e^(-0.0785398) = 0.924465
    assert float(cp.guide_efficiency(0.05, math.pi / 2)) == pytest.approx(0.924465, abs=1e-6)
    # two such bends: 0.924465^2 = 0.854636
    assert cp.route_efficiency(0.05, [math.pi / 2, math.pi / 2]) == pytest.approx(0.854636, abs=1e-6)


def test_contact_efficiency_eq26_27():
    # 1 - (2 x 0.15 / pi) asin(0.5) = 1 - (0.3 / pi)(pi / 6) = 1 - 0.05 exactly
    assert cp.contact_efficiency(0.15, 0.5) == pytest.approx(0.95, abs=1e-12)
    assert cp.contact_efficiency(0.15, 0.0) == 1.0
    with pytest.raises(ValueError, match="outside"):
        cp.contact_efficiency(0.15, 1.5)


def test_total_eq28_29():
    # 0.95 x 0.95^2 x 0.98 = 0.857375 x 0.98 = 0.8402275
    assert cp.capstan_efficiency(0.95, 0.95, 2, 0.98) == pytest.approx(0.8402275, abs=1e-9)


def test_pull_pull_split():
    m, t0 = 0.015, 45.0
    # equal stiffness: T0 +/- tau / (2 m) = 45 +/- 0.6 / 0.03 = 65, 25
    a, b = cp.pull_pull_tensions(0.6, m, t0)
    assert (float(a), float(b)) == pytest.approx((65.0, 25.0))
    a, b = cp.pull_pull_tensions(-0.6, m, t0)
    assert (float(a), float(b)) == pytest.approx((25.0, 65.0))
    # unequal stiffness k_a = 2 k_b: 45 + 0.6 x 2 / (3 x 0.015) = 71.667, 45 - 0.6 / (3 x 0.015) = 31.667
    a, b = cp.pull_pull_tensions(0.6, m, t0, 2.0, 1.0)
    assert (float(a), float(b)) == pytest.approx((71.6667, 31.6667), abs=1e-4)
    assert (float(a) - float(b)) * m == pytest.approx(0.6)   # the pair still carries the torque
    # past slack (tau / 2m = 60 > 45): one side carries tau / m = 120 N, the other 0
    a, b = cp.pull_pull_tensions(np.array([1.8, -1.8]), m, t0)
    assert a.tolist() == pytest.approx([120.0, 0.0]) and b.tolist() == pytest.approx([0.0, 120.0])


def test_cable_stiffness():
    # E A / L = 2e9 x (pi x 1e-6 / 4 = 7.853982e-7) / 0.1 = 15707.96 N/m
    assert cp.cable_stiffness_n_m(2e9, 1e-3, 0.1) == pytest.approx(15707.96, rel=1e-6)
