"""Servo-gear losses (paper eq. 4-19) against values worked by hand."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.physics import servo_gear as sg


def test_mesh_efficiency_eq5():
    # pi x 0.08 = 0.251327; / cos 20 deg (0.939693) = 0.267454; x (1/12 + 1/48 = 0.104167) = 0.027860
    assert sg.mesh_efficiency(0.08, math.radians(20), 12, 48) == pytest.approx(1 - 0.027860, abs=2e-6)
    # three stages compound: 0.972140^3 = 0.918727
    assert sg.train_efficiency(0.972140, 3) == pytest.approx(0.918727, abs=2e-6)


def test_backlash_chain_eq6_to_9():
    # eq. 8: (2 pi 3)^2 x 0.96 = 355.3058 x 0.96 = 341.0935 rad/s^2
    a = sg.reversal_acceleration(3.0, 0.96)
    assert a == pytest.approx(341.0935, rel=1e-6)
    # eq. 7: sqrt(2 x 341.0935 x 0.0175) = sqrt(11.93827) = 3.455180 rad/s
    w = sg.backlash_impact_speed(a, 0.0175)
    assert w == pytest.approx(3.455180, rel=1e-6)
    # eq. 6: 0.5 x 5e-6 x 11.93827 x (1 - 0.49) = 1.522129e-5 J
    e = sg.backlash_impact_energy(5e-6, w, 0.7)
    assert e == pytest.approx(1.522129e-5, rel=1e-6)
    # two impacts per cycle: 2 x 3 x 1.522129e-5 = 9.132776e-5 W; eq. 9 as printed gives half: 4.566388e-5 W
    assert sg.backlash_power(5e-6, 3.0, 0.96, 0.0175, 0.7) == pytest.approx(9.132776e-5, rel=1e-6)
    assert sg.paper_backlash_power(5e-6, 3.0, 0.96, 0.0175, 0.7) == pytest.approx(4.566388e-5, rel=1e-6)


def test_backlash_scales_as_f_cubed():
    p3 = sg.backlash_power(5e-6, 3.0, 0.96, 0.0175, 0.7)
    assert sg.backlash_power(5e-6, 6.0, 0.96, 0.0175, 0.7) == pytest.approx(8 * p3, rel=1e-12)


def test_friction_power_eq14_hand_and_numeric():
    # w0 = 2 pi 3 x 0.96 = 18.09557 rad/s
    # Coulomb: 0.005 x (2/pi) x 18.09557 = 0.057600 (= 4 f theta0 tau_c = 4 x 3 x 0.96 x 0.005)
    # viscous: 0.5 x 5e-5 x 18.09557^2 (327.4497) = 0.0081862
    p = sg.friction_power(0.005, 5e-5, 3.0, 0.96)
    assert p == pytest.approx(0.057600 + 0.0081862, rel=1e-5)
    # independent: the cycle mean of |tau_f theta_dot| sampled finely
    t = np.linspace(0, 1 / 3, 200001)
    td = 18.09557 * np.cos(2 * np.pi * 3 * t)
    num = np.trapezoid(np.abs((0.005 * np.sign(td) + 5e-5 * td) * td), t) * 3
    assert p == pytest.approx(num, rel=1e-5)
    # the paper's eq. 15 has 8 f theta0 tau_c for the Coulomb part: twice the mean
    assert sg.paper_friction_power(0.005, 0.0, 3.0, 0.96) == pytest.approx(2 * 0.057600, rel=1e-9)


def test_reflected_inertia_eq16():
    # output side: J_load + N^2 J_motor = 1e-6 + 1e4 x 5.4e-6 = 0.054001
    assert sg.inertia_at_output(5.4e-6, 1e-6, 100) == pytest.approx(0.054001, rel=1e-12)
    # load at the motor: 1e-6 / 100^2 = 1e-10 (the paper's eq. 16 gives N^2 J_load = 1e-2)
    assert sg.load_inertia_at_motor(1e-6, 100) == pytest.approx(1e-10, rel=1e-12)


def test_inertia_power_eq17():
    # 4 pi^2 f^3 theta0^2 J = 39.47842 x 27 x 0.25 x 1e-3 = 0.2664793 W
    p = sg.inertia_power(1e-3, 3.0, 0.5)
    assert p == pytest.approx(0.2664793, rel=1e-6)
    # the same as 2 f x kinetic energy at peak speed: 6 x 0.5e-3 x (2 pi 3 x 0.5 = 9.424778)^2
    assert p == pytest.approx(6 * 0.5e-3 * 9.424778**2, rel=1e-6)


def test_servo_efficiency_eq18_19():
    # 0.9 x 2 / (2 + 0.2 + 0.3 + 0.1) = 1.8 / 2.6
    assert sg.servo_efficiency(0.9, 2.0, 0.2, 0.3, 0.1) == pytest.approx(1.8 / 2.6, rel=1e-12)
    # f = 2: 0.9 x 2 / (2 + 0.01 x 8 + 0.1 x 2 + 0.02 x 4 + 0.01 x 8) = 1.8 / 2.44 = 0.737705
    assert float(sg.servo_efficiency_curve(2.0, 0.9, 1.0, 0.01, 0.1, 0.02, 0.01)) == pytest.approx(0.737705, rel=1e-6)
