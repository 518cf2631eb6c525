"""Layout numbers against closed forms and their own invariants."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.layout import geometry as L
from swiftfin.core.schema import Params


def test_naca_half_width_formula():
    p = Params()
    # NACA 0015 maximum thickness 15 % of chord at 30 % of chord
    assert 2 * float(np.max(L.naca_half_width_mm(p, np.linspace(0, 520, 5201)))) == pytest.approx(78.0, rel=2e-3)
    assert L.max_width_station_mm(p) == pytest.approx(0.30 * 520, abs=1.0)
    # a hand-worked station: x/c = 0.5 -> y_t = 5 t (0.2969 sqrt(.5) - .126 .5 - .3516 .25 + .2843 .125 - .1015 .0625)
    yt = 5 * 0.15 * (0.2969 * math.sqrt(0.5) - 0.063 - 0.0879 + 0.0355375 - 0.00634375)
    assert float(L.naca_half_width_mm(p, 260.0)) == pytest.approx(yt * 520, rel=1e-12)


def test_default_layout_is_feasible():
    assert L.layout_problems(Params()) == []


def test_routes_end_tangent_to_sector_at_moment_arm():
    p = Params()
    js = L.joint_stations_mm(p)
    m = p.joints.tendon_moment_arm_mm
    for r in L.cable_routes(p):
        a = np.array(r.points_mm[-2][:2])
        b = np.array(r.points_mm[-1][:2])
        c = np.array([-js[r.joint], 0.0])
        u = (b - a) / np.linalg.norm(b - a)
        w = c - a
        dist = abs(u[0] * w[1] - u[1] * w[0])   # perpendicular distance from the joint axis to the cable line
        assert dist == pytest.approx(m, rel=1e-9)
        assert np.linalg.norm(b - c) == pytest.approx(m, rel=1e-9)
        assert np.sign(b[1]) == r.side


def test_crossings_on_hinge_line_and_distinct():
    p = Params()
    js = L.joint_stations_mm(p)
    routes = L.cable_routes(p)
    for k, s in enumerate(js):
        crossing = [q for r in routes if r.joint > k for q in r.points_mm if abs(q[0] + s) < 1e-9]
        assert all(abs(q[1]) < 1e-12 for q in crossing)
        zs = sorted(q[2] for q in crossing)
        assert all(b - a >= p.guides.ptfe_tube_od_mm for a, b in zip(zs, zs[1:]))
        assert len(crossing) == 2 * (p.joints.count - 1 - k)


def test_cables_clear_spools_behind():
    """A cable in its lane passes beside every spool behind its own motor."""
    p = Params()
    d = L.spool_dims(p)
    motors = L.motor_placements(p)
    for mp in motors[1:]:
        for behind in motors[: mp.joint]:
            assert mp.lane_y_mm - p.guides.ptfe_tube_od_mm / 2 > d.flange_radius_mm
            assert behind.s_mm > mp.s_mm


def test_bend_angles_positive_and_links_valid():
    p = Params()
    for r in L.cable_routes(p):
        for b in r.bends:
            assert 0 <= b.angle_rad < math.pi / 2
            assert 0 <= b.link <= p.joints.count
