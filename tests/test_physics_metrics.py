"""Efficiency curves (eq. 30-35), position fidelity (eq. 36-40), Strouhal (eq. 41-42), performance (§5-6)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.physics import efficiency as ef
from swiftfin.physics import fidelity as fi
from swiftfin.physics import performance as pf
from swiftfin.physics import strouhal as st


def test_efficiency_curves_eq31_35():
    assert float(ef.capstan_efficiency_curve(3.0)) == pytest.approx(0.941)        # 0.95 - 0.009
    assert float(ef.servo_efficiency_fit(3.0)) == pytest.approx(0.827)            # 0.92 - 0.075 - 0.018
    assert float(ef.paper_ratio_at(3.0)) == pytest.approx(0.941 / 0.827)          # 1.13785
    assert float(ef.paper_ratio_at(5.0)) == pytest.approx(0.935 / 0.745)          # 1.25503
    assert float(ef.efficiency_ratio(0.8, 0.4)) == pytest.approx(2.0)


def test_backlash_rms_is_half_the_backlash_eq37_38():
    phi = math.radians(1.0)
    t = np.linspace(0, 1, 100000, endpoint=False)
    cmd = math.radians(55) * np.sin(2 * np.pi * t)
    act = fi.backlash_output(cmd, np.cos(2 * np.pi * t), phi)
    rms = math.sqrt(float(np.mean((cmd - act) ** 2)))
    assert rms == pytest.approx(phi / 2, rel=1e-9)                 # not phi / sqrt 2 as eq. 38 prints
    assert float(fi.backlash_rms_error(phi)) == pytest.approx(rms, rel=1e-9)
    # eq. 36: 1 - 0.5 / 55 = 0.990909
    assert fi.fidelity_from_signals(cmd, act, math.radians(55)) == pytest.approx(0.990909, abs=1e-6)
    assert float(fi.position_fidelity(0.5, 55.0)) == pytest.approx(0.990909, abs=1e-6)


def test_quantisation_rms():
    x = np.linspace(0, 10, 1000001)
    q = 0.1
    err = x - q * np.round(x / q)
    assert float(fi.quantisation_rms(q)) == pytest.approx(math.sqrt(float(np.mean(err**2))), rel=1e-3)


def test_capstan_error_eq39_40():
    # as printed: sqrt(0.1125^2 + (0.001 / 0.01)^2) = sqrt(0.01265625 + 0.01) = 0.150520
    assert float(fi.capstan_rms_error(0.1125, 0.001, 0.01)) == pytest.approx(0.150520, abs=1e-6)
    # at the joint: q = 1.8 deg / 16 x 10 / 15 = 0.075 deg = 1.308997e-3 rad, RMS q / sqrt 12 = 3.778748e-4 rad;
    # stretch 0.1 mm over d_mount 15 mm = 6.666667e-3 rad; hypot = 6.677367e-3 rad
    e = fi.joint_error_capstan_rad(math.radians(1.8), 16, 0.010, 0.015, 1e-4)
    assert e == pytest.approx(6.677367e-3, rel=1e-6)


def test_strouhal_eq41_42():
    # 3 x 0.2 / 1.97 = 0.304569
    assert float(st.strouhal(3.0, 0.2, 1.97)) == pytest.approx(0.304569, abs=1e-6)
    # -0.4 x 0.02^2 = -1.6e-4
    assert float(st.strouhal_penalty(0.4, 0.02)) == pytest.approx(-1.6e-4)


def test_performance_metrics():
    assert pf.quasi_propulsive_efficiency(3.72, 1.0, 2.16) == pytest.approx(1.722222, abs=1e-6)  # 3.72 / 2.16
    assert pf.cost_of_transport(2.16, 1.2, 1.97) == pytest.approx(0.913706, abs=1e-6)          # 2.16 / 2.364
    assert pf.transport_economy(1.97, 2.16) == pytest.approx(0.912037, abs=1e-6)
    assert pf.range_m(50 * 3600, 0.93) == pytest.approx(167400.0)                               # 180 kJ x 0.93
    assert pf.body_lengths_per_s(1.97, 0.52) == pytest.approx(3.788462, abs=1e-6)
    assert pf.relative_reduction(4.5, 2.16) == pytest.approx(0.52)
    assert pf.relative_improvement(63, 54) == pytest.approx(1 / 6)
    assert pf.wave_speed_m_s(3.0, 0.65) == pytest.approx(1.95)
    assert pf.slip_ratio(1.97, 1.95) == pytest.approx(1.010256, abs=1e-6)
    # COT and transport economy are reciprocal through the mass: TE = 1 / (COT m)
    assert pf.transport_economy(1.97, 2.16) == pytest.approx(1 / (pf.cost_of_transport(2.16, 1.2, 1.97) * 1.2))
