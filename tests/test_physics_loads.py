"""The swimming load model (layout/loads.py): closed-form limits, hand-worked values, exact scalings."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.layout.geometry import joint_stations_mm
from swiftfin.layout import loads as ld
from swiftfin.core.params import params_from_dict, replace_key
from swiftfin.core.schema import Params


def test_ellipse_helpers_on_a_circle():
    assert ld.ellipse_perimeter(0.03, 0.03) == pytest.approx(2 * math.pi * 0.03, rel=1e-12)
    # integral of y^2 ds around a circle of radius a: pi a^3
    assert ld._ellipse_y2_line_integral(0.03, 0.03) == pytest.approx(math.pi * 0.03**3, rel=1e-9)


def test_fin_geometry_hand():
    f = ld.fin_geometry(Params())
    # S = 0.16^2 / 6 = 4.266667e-3 m^2, c = S / b = 0.0266667 m
    assert f.area_m2 == pytest.approx(4.266667e-3, rel=1e-6) and f.chord_m == pytest.approx(0.0266667, rel=1e-5)
    # mass = 1240 x 0.685 x 0.12 x c^2 (7.111111e-4) x 0.16 = 0.0115971 kg
    assert f.mass_kg == pytest.approx(0.0115971, rel=1e-5)
    # quarter chord: hull end 0.4758 + c/4 (0.0066667) + tan 35 deg x b/4 (0.7002075 x 0.04 = 0.0280083) = 0.5104750
    assert f.quarter_chord_station_m == pytest.approx(0.5104750, abs=1e-6)


def test_shell_mass_of_link1_against_a_hand_estimate():
    lm = ld.shell_link_masses(Params())
    # link 1 = hull_body_1 from 296.90 to 316.99 mm (20.09 mm). At its middle (xi = 0.5903) the NACA 0015 half
    # width is 0.75 (0.2969 x 0.7683 - 0.126 x 0.5903 - 0.3516 x 0.3484 + 0.2843 x 0.2057 - 0.1015 x 0.1214) x 520
    # = 30.18 mm, half height (x 1.6) 48.29 mm. Mid-wall ellipse 29.18 x 47.29 mm: perimeter (Ramanujan) 243.6 mm,
    # shell 1240 x 0.002 x 0.2436 x 0.02009 = 0.01214 kg; two 3 mm bulkheads pi 28.18 x 46.29 mm^2 x 3 mm x 1240
    # = 2 x 0.01524 kg. Total about 0.0426 kg.
    assert lm[0].mass_kg == pytest.approx(0.0426, rel=0.03)
    assert 0.29690 < lm[0].com_station_m < 0.31699
    for m in lm:
        assert m.mass_kg > 0 and m.izz_com_kg_m2 > 0
    # mass and inertia are proportional to the filament density
    p2 = replace_key(Params(), "print.filament_density_kg_m3", 2480.0)
    for a, b in zip(lm, ld.shell_link_masses(p2)):
        assert b.mass_kg == pytest.approx(2 * a.mass_kg, rel=1e-12)
        assert b.izz_com_kg_m2 == pytest.approx(2 * a.izz_com_kg_m2, rel=1e-12)


def test_point_mass_on_the_tail_link_closed_form():
    # a 0.1 kg point mass at the fork (x = L = 0.52 m), nothing else: it moves with y(L, t) = 0.10 sin(k L - w t),
    # acceleration amplitude w^2 A = (6 pi)^2 x 0.10 = 35.53058 m/s^2, arm to joint 4 = 0.52 - 0.3978 = 0.1222 m:
    # torque amplitude 0.1 x 35.53058 x 0.1222 = 0.434184 N m at joint 4; at joint 1 the arm is 0.52 - 0.2834
    p = Params()
    xj = np.asarray(joint_stations_mm(p)) / 1000
    masses = tuple([ld.LinkMass(0.0, x + 0.01, 0.0) for x in xj[:3]] + [ld.LinkMass(0.1, 0.52, 0.0)])
    jl = ld.joint_loads(p, link_masses=masses)
    inertia = jl.components_nm["link_inertia"]
    assert np.abs(inertia[:, 3]).max() == pytest.approx(0.434184, rel=2e-3)
    assert np.abs(inertia[:, 0]).max() == pytest.approx(0.1 * 35.53058 * (0.52 - xj[0]), rel=2e-3)


def test_fin_added_mass_at_rest_in_the_water_closed_form():
    # U = 0 and a small amplitude: w ~ y_dot, so the fin's reaction is m_a y_ddot with
    # m_a = rho pi (b/2)^2 c = 1000 x pi x 0.08^2 x 0.0266667 = 0.536165 kg, at the fin centroid on the tail link
    p = params_from_dict({"swimming": {"tail_amplitude_m": 0.005, "speed_m_s": 0.0}})
    fin = ld.fin_geometry(p)
    assert 1000 * math.pi * 0.08**2 * fin.chord_m == pytest.approx(0.536165, rel=1e-6)
    jl = ld.joint_loads(p)
    xj = np.asarray(joint_stations_mm(p)) / 1000
    w, L = 2 * math.pi * 3.0, 0.52
    k = 2 * math.pi / (1.25 * L)
    amp = lambda x: 0.005 * (x / L) ** 2                           # noqa: E731
    # the tail link's chord interpolates the node phasors A(x4) e^(i k x4) and A(L) e^(i k L)
    s = (fin.centroid_station_m - xj[3]) / (L - xj[3])
    y_c = abs((1 - s) * amp(xj[3]) * np.exp(1j * k * xj[3]) + s * amp(L) * np.exp(1j * k * L))
    expected = 0.536165 * w**2 * y_c * (fin.centroid_station_m - xj[3])
    assert np.abs(jl.components_nm["fin_added_mass"][:, 3]).max() == pytest.approx(expected, rel=2e-3)


@pytest.mark.parametrize("key,component", [("hydro.body_added_mass_coefficient", "body_added_mass"),
                                           ("hydro.body_drag_coefficient", "body_drag"),
                                           ("hydro.fin_added_mass_coefficient", "fin_added_mass")])
def test_components_are_linear_in_their_coefficient(key, component):
    p = Params()
    a = ld.joint_loads(p).components_nm[component]
    from swiftfin.core.params import get_key
    b = ld.joint_loads(replace_key(p, key, 0.5 * get_key(p, key))).components_nm[component]
    assert b == pytest.approx(0.5 * a, rel=1e-10, abs=1e-14)


def test_hydrodynamic_components_scale_with_water_density():
    p = Params()
    a = ld.joint_loads(p).components_nm
    b = ld.joint_loads(replace_key(p, "environment.water_density_kg_m3", 1100.0)).components_nm
    for name in ("body_added_mass", "body_drag", "fin_added_mass", "fin_lift"):
        assert b[name] == pytest.approx(1.1 * a[name], rel=1e-10, abs=1e-14)
    assert b["link_inertia"] == pytest.approx(a["link_inertia"], rel=1e-12)


def test_drive_loads_hand_worked_joint1():
    # constant +0.3 N m on every joint, joints turning positive (left cable winding onto the spool)
    p = Params()
    n = 8
    z = np.zeros((n, 4))
    jl = ld.JointLoads(np.linspace(0, 1 / 3, n, endpoint=False), z, z + 1.0, z, z + 0.3)
    dl = ld.drive_loads(p, jl)
    # joint 1 routes (swiftfin.layout.geometry): left 65.4491 mm, 0.211481 rad of bends; right 65.1500 mm, 0.177051 rad
    # (since the cable turns toward its sector at the rear motor's aft face, issue 12).
    # stiffness ~ 1/length: left share 65.1500 / 130.5991 = 0.498855, right 0.501145.
    # T_left = 45 + (0.3 / 0.015) x 0.498855 = 54.97710 N; T_right = 45 - 20 x 0.501145 = 34.97710 N
    assert dl.tension_left_joint_n[0, 0] == pytest.approx(54.97710, abs=1e-4)
    assert dl.tension_right_joint_n[0, 0] == pytest.approx(34.97710, abs=1e-4)
    # at the spool: left x e^(0.05 x 0.211481) = x 1.010630 -> 55.56151; right x e^(-0.05 x 0.177051) = x 0.991187
    # -> 34.66883; motor torque (55.56151 - 34.66883) x 0.010 = 0.208927 N m
    assert dl.motor_torque_nm[0, 0] == pytest.approx(0.208927, abs=1e-5)
    # the plain-efficiency formula tau r / (m eta) = 0.2 / 0.989482 = 0.202126 misses the pretension's own friction
    eta = math.exp(-0.05 * 0.211481)
    assert float(ld.simple_motor_torque_nm(0.3, 0.010, 0.015, eta)) == pytest.approx(0.202126, abs=1e-5)
    # step rate: 1 rad/s x 1.5 / 0.0314159 rad = 47.7465 full steps/s
    assert dl.step_rate_full_steps_s[0, 0] == pytest.approx(47.7465, abs=1e-3)
    # capstan capacity T_slack e^(0.35 x 4 pi) / T_tight = 34.66883 x 81.30680 / 55.56151
    assert dl.capstan_capacity[0, 0] == pytest.approx(34.66883 * 81.30680 / 55.56151, rel=1e-5)


def test_default_design_goes_slack_and_tension_is_torque_over_arm():
    p = Params()
    jl = ld.joint_loads(p)
    dl = ld.drive_loads(p, jl)
    # at the paper's design point the peak torque exceeds 2 m T0 = 1.35 N m, so one side goes slack and the
    # other carries tau / m
    assert np.all(jl.peak_torque_nm > 2 * 0.015 * 45.0)
    assert dl.min_tension_n == pytest.approx(np.zeros(4), abs=1e-12)
    assert dl.peak_tension_n == pytest.approx(jl.peak_torque_nm / 0.015, rel=1e-9)


def test_sensitivity_table_is_finite_and_consistent():
    tab = ld.sensitivity_table(Params())
    assert set(tab) == set(ld.UNCERTAIN_COEFFICIENTS)
    for row in tab.values():
        assert all(math.isfinite(v) for v in row.values())
        # slack regime: T = tau / m, so the two elasticities are equal
        assert row["peak_cable_tension_n"] == pytest.approx(row["peak_joint_torque_nm"], abs=1e-9)
    # the cable's modulus does not change the torque (prescribed kinematics)
    assert tab["cable.youngs_modulus_gpa"]["peak_joint_torque_nm"] == pytest.approx(0.0, abs=1e-12)
    # the fin dominates: its added-mass and lift coefficients matter far more than the body's
    assert tab["hydro.fin_added_mass_coefficient"]["peak_joint_torque_nm"] > \
        10 * tab["hydro.body_added_mass_coefficient"]["peak_joint_torque_nm"]


def test_link_masses_override_is_used_and_checked():
    p = Params()
    heavy = tuple(ld.LinkMass(1.0, m.com_station_m, m.izz_com_kg_m2) for m in ld.shell_link_masses(p))
    a = ld.joint_loads(p).components_nm["link_inertia"]
    b = ld.joint_loads(p, link_masses=heavy).components_nm["link_inertia"]
    assert np.abs(b).max() > 5 * np.abs(a).max()
    with pytest.raises(ValueError, match="3 links"):
        ld.joint_loads(p, link_masses=heavy[:3])


def test_hinge_inertia_by_hand_and_in_water():
    """The joint fit's prior for the link on a hinge: in air the links behind it by the parallel-axis theorem from
    shell_link_masses; in water, added on top, the fin's strip added mass rho pi (b/2)^2 c at its centroid's lever
    (closed form, by hand here) plus the body strips' and the water inside the shells; the water terms only in
    water."""
    from swiftfin.core.schema import Params
    from swiftfin.layout.geometry import joint_stations_mm
    from swiftfin.layout.loads import fin_geometry, hinge_inertia, shell_link_masses
    p = Params()
    j = p.joints.count - 1
    x = joint_stations_mm(p)[j] / 1000.0
    lm = shell_link_masses(p)[j]
    air = hinge_inertia(p, j)
    assert air.total_kg_m2 == pytest.approx(lm.izz_com_kg_m2 + lm.mass_kg * (lm.com_station_m - x) ** 2, rel=1e-12)
    water = hinge_inertia(p, j, "water")
    fin = fin_geometry(p)
    by_hand = 1000.0 * math.pi * (fin.span_m / 2) ** 2 * fin.chord_m * (fin.centroid_station_m - x) ** 2
    assert p.environment.water_density_kg_m3 == pytest.approx(1000.0, rel=0.03)
    assert 0.97 * by_hand < water.added_mass_kg_m2 < 1.3 * by_hand        # the fin by hand, plus the body strips
    assert water.total_kg_m2 == pytest.approx(air.links_kg_m2 + water.added_mass_kg_m2 + water.entrained_kg_m2)
    assert water.total_kg_m2 > 30 * air.total_kg_m2
    with pytest.raises(ValueError, match="medium 'oil'"):
        hinge_inertia(p, j, "oil")
