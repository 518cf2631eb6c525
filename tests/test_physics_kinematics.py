"""Wave kinematics (eq. 43-47) and the motor step transformation (eq. 48)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.physics import kinematics as k
from swiftfin.core.schema import Params


def _wave():
    return k.wave_from_params(Params().swimming, 0.52)


def test_envelope_and_wavenumber_eq45_46():
    w = _wave()
    assert w.c2_per_m == pytest.approx(0.10 / 0.52**2)             # 0.369822
    assert float(w.envelope_m(0.52)) == pytest.approx(0.10)
    assert w.wavenumber_rad_m == pytest.approx(2 * math.pi / 0.65)   # 9.666439


def test_slope_is_the_x_derivative_eq47():
    w = _wave()
    x, t, h = 0.41, 0.037, 1e-6
    fd = (w.lateral_m(x + h, t) - w.lateral_m(x - h, t)) / (2 * h)
    assert float(w.slope(x, t)) == pytest.approx(float(fd), rel=1e-7)


def test_rigid_rotation_gives_zero_joint_angles():
    # y = c x sin(-w t) with k = 0: at every instant a straight line, so relative joint angles are 0 while the
    # absolute tangent of eq. 47 is atan(c sin(-w t)), not 0
    w = k.Wave(0.52, 0.0, 0.3, 0.0, 0.0, 2.0)
    t = np.linspace(0, 0.5, 40, endpoint=False)   # includes t = 0.125 s, where |sin| = 1
    st = [0.2, 0.3, 0.4]
    assert np.abs(k.relative_joint_angles_rad(w, st, 0.52, t)).max() < 1e-12
    assert np.abs(k.absolute_tangent_angles_rad(w, st, t)).max() == pytest.approx(math.atan(0.3), rel=1e-3)


def test_motor_steps_eq48():
    # 10 deg at the joint x 15/10 = 15 deg at the motor; x 16 / 1.8 deg = 133.33 -> 133 microsteps
    s = k.motor_steps(math.radians(10.0), 0.015, 0.010, 16, math.radians(1.8))
    assert int(s) == 133 and np.issubdtype(np.asarray(s).dtype, np.integer)
    assert float(k.motor_angle_rad(0.1, 0.015, 0.010)) == pytest.approx(0.15)
    # one microstep at the joint: 0.1125 deg x 10 / 15 = 0.075 deg
    assert k.joint_resolution_rad(math.radians(1.8), 16, 0.015, 0.010) == pytest.approx(math.radians(0.075))
    # 2 rad/s at the joint -> 3 rad/s at the motor / 0.0314159 rad = 95.493 full steps/s
    assert float(k.full_step_rate(2.0, 0.015, 0.010, math.radians(1.8))) == pytest.approx(95.4930, abs=1e-4)


def test_periodic_derivative():
    T = 0.25
    t = np.linspace(0, T, 64, endpoint=False)
    y = np.stack([np.sin(2 * np.pi * t / T), np.cos(4 * np.pi * t / T)], axis=1)
    d = k.periodic_derivative(y, T)
    assert d[:, 0] == pytest.approx(2 * np.pi / T * np.cos(2 * np.pi * t / T), abs=1e-9)
    assert d[:, 1] == pytest.approx(-4 * np.pi / T * np.sin(4 * np.pi * t / T), abs=1e-9)
