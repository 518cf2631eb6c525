"""The dry compartment's heat balance and the battery's run time (physics/thermal.py, design_rules heat.* and
power.*), against closed forms and hand arithmetic."""
from __future__ import annotations

import dataclasses
import math

import pytest

from swiftfin.catalogues.materials import material, material_names
from swiftfin.design_rules import RULES, RuleContext, run_rules
from swiftfin.design_rules.rules import dry_wall_area_m2, dry_wall_m2
from swiftfin.physics import thermal as th


def test_losses_and_resistances_are_the_closed_forms():
    assert th.stepper_copper_loss_w(1.5, 1.5) == pytest.approx(1.5**2 * 1.5)          # sine/cosine: I^2 R in all
    assert th.stepper_copper_loss_w(1.5, 1.5, microstepping=False) == pytest.approx(2 * 1.5**2 * 1.5)
    assert th.driver_bridge_loss_w(1.0, 0.75) == pytest.approx(0.75)
    # plane wall with convection on both sides: (1/h1 + t/k + 1/h2) / A; two walls side by side: in parallel
    r1, r2 = (0.2 + 0.002 / 0.13 + 0.005) / 0.1, (0.2 + 0.015 / 0.13 + 0.005) / 0.006
    assert th.compartment_resistance_k_w([(0.1, 0.002)], 0.13, 5.0, 200.0) == pytest.approx(r1)
    assert th.compartment_resistance_k_w([(0.1, 0.002), (0.006, 0.015)], 0.13, 5.0, 200.0) == pytest.approx(
        r1 * r2 / (r1 + r2))
    assert th.case_rise_k(3.0, 0.01, 5.0) == pytest.approx(60.0)
    assert th.run_time_s(4.5 * 3600, 0.8, 10.0) == pytest.approx(1296.0)
    with pytest.raises(ValueError):
        th.compartment_resistance_k_w([(0.0, 0.002)], 0.13, 5.0, 200.0)


def test_the_materials_table_orders_the_softening_temperatures():
    assert material_names() == ("PLA", "PETG", "ASA")
    hdt = [material(n).heat_deflection_temperature_c for n in material_names()]
    assert hdt == sorted(hdt) and hdt[0] == 55.0


def test_dry_wall_area_of_a_cylinder_like_hull_matches_its_closed_form(default_params):
    # a whole sealed hull: the area grows with the sealed length, and scales with the square of the length
    p = default_params
    sealed = dataclasses.replace(p, hull=dataclasses.replace(p.hull, flooded_from_joint=p.joints.count + 1))
    assert dry_wall_area_m2(sealed) > dry_wall_area_m2(p)
    big = dataclasses.replace(p, body=dataclasses.replace(p.body, length_mm=2 * p.body.length_mm))
    # twice as long: four times the area, but for the rear wall, which is as thick as the glands in both (not
    # twice): the big one's side runs that much further, at most 2 t / s_front of its length more
    side, rear, t = dry_wall_m2(p)
    from swiftfin.layout.hull_plan import dry_bulkhead
    s_front = dry_bulkhead(p).s_front_mm
    assert 4 * dry_wall_area_m2(p) < dry_wall_area_m2(big) < 4 * dry_wall_area_m2(p) * (1 + 2 * 1000 * t / s_front)
    # the head's side wall lies between the inscribed and circumscribed cones' areas: bounded by 2 pi b_max s_end
    # (the side ends at the rear wall's front face, 265.4 mm on the default design: short of joint 1 at 288.6 mm)
    from swiftfin.layout.geometry import half_height_mm, joint_stations_mm
    from swiftfin.layout.hull_plan import dry_bulkhead
    s1 = joint_stations_mm(p)[0]
    assert dry_bulkhead(p).s_front_mm < s1 - 20
    assert dry_wall_area_m2(p) < (2 * math.pi * float(half_height_mm(p, 0.3 * p.body.length_mm)) * s1
                                  + math.pi * 60.0**2) * 1e-6


def _heat_findings(p):
    ids = ("heat.dry_compartment", "heat.motor_mount", "power.run_time")
    return {f.rule_id: f for f in run_rules(RuleContext(p), [r for r in RULES if r.rule_id in ids])}


def test_default_heat_balance_by_hand(default_params):
    p = default_params
    f = _heat_findings(p)
    q = p.joints.count * (1.5**2 * 1.5 + 1.5**2 * 0.75) + 0.4                   # 20.65 W
    # the side wall (2 mm) and the rear wall (as thick as the glands: 14 mm + 2 x 0.45 mm shoulder) in parallel
    side, rear, t = dry_wall_m2(p)
    assert t == pytest.approx((14.0 + 2 * 0.45) * 1e-3) and rear > 0 and side + rear == dry_wall_area_m2(p)
    r = 1 / (side / (1 / 5.0 + 0.002 / 0.13 + 1 / 200.0) + rear / (1 / 5.0 + t / 0.13 + 1 / 200.0))
    assert f["heat.dry_compartment"].value == pytest.approx(20.0 + q * r)
    assert f["heat.dry_compartment"].limit == pytest.approx(55.0 - 10.0)       # PLA's HDT less the margin
    case = (4 * 42.3 * 40.0 + 42.3**2) * 1e-6
    assert f["heat.motor_mount"].value == pytest.approx(20.0 + q * r + 1.5**2 * 1.5 / (5.0 * case))
    # the default head in PLA at 1.5 A cooks (honest): the air above PLA's softening, the mounts far above
    assert f["heat.dry_compartment"].severity.name == "FAIL" and f["heat.motor_mount"].severity.name == "FAIL"


def test_the_heat_rules_follow_current_material_and_water(default_params):
    p = default_params
    base = _heat_findings(p)["heat.dry_compartment"].value
    low = dataclasses.replace(p, motor=dataclasses.replace(p.motor, phase_current_a=0.75))
    q, q_low = (p.joints.count * i**2 * (1.5 + 0.75) + 0.4 for i in (1.5, 0.75))      # the rise follows the loss
    assert (_heat_findings(low)["heat.dry_compartment"].value - 20.0) / (base - 20.0) == pytest.approx(q_low / q)
    asa = dataclasses.replace(p, print=dataclasses.replace(p.print, material="ASA"))
    assert _heat_findings(asa)["heat.dry_compartment"].limit == pytest.approx(93.0 - 10.0)
    warm = dataclasses.replace(p, environment=dataclasses.replace(p.environment, water_temperature_c=30.0))
    assert _heat_findings(warm)["heat.dry_compartment"].value == pytest.approx(base + 10.0)


def test_run_time_is_energy_over_draw(default_params):
    p = default_params
    f = _heat_findings(p)["power.run_time"]
    ctx = RuleContext(p)
    draw = p.joints.count * (1.5**2 * 1.5 + 1.5**2 * 0.75) + 0.4 + ctx.loads.mean_positive_power_w
    assert f.value == pytest.approx(4.5 * 3600 * 0.8 / draw / 60.0)
    assert f.limit == 15.0
