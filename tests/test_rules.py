"""Design rules: findings, severities, the default design's honest verdict, a bad design, missing inputs."""
from __future__ import annotations

import math

import numpy as np
import pytest

from swiftfin.design_rules import RULES, MassProperties, RuleContext, Severity, run_rules, verdict
from swiftfin.design_rules.findings import Finding, at_least, at_most, within
from swiftfin.design_rules.rules import fit_factor, fits_bed
from swiftfin.physics.kinematics import max_relative_joint_angles_rad, wave_from_params
from swiftfin.layout.design import load_design
from swiftfin.core.params import ParamError, params_from_dict
from swiftfin.core.schema import Params


def _by_id(findings):
    return {f.rule_id: f for f in findings}


@pytest.fixture(scope="module")
def default_findings():
    return _by_id(run_rules(RuleContext(Params())))


def test_severity_order_and_verdict():
    assert Severity.PASS < Severity.INFO < Severity.NOT_EVALUATED < Severity.WARN < Severity.FAIL
    fs = [at_least("a", 2.0, 1.0, "s"), at_most("b", 2.0, 1.0, "s", above=Severity.WARN)]
    assert verdict(fs) is Severity.WARN and verdict([]) is Severity.PASS


def test_margins():
    assert at_least("a", 30.0, 20.0, "s").margin == pytest.approx(0.5)
    assert at_most("a", 0.05, 0.1, "s").margin == pytest.approx(0.5)
    f = within("a", 0.15, 0.10, 0.20, "s")
    assert f.margin == pytest.approx(0.25) and f.severity is Severity.PASS     # min(0.05/0.10, 0.05/0.20)
    assert within("a", 0.05, 0.10, 0.20, "s").severity is Severity.FAIL


def test_findings_refuse_nan_and_silent_not_evaluated():
    with pytest.raises(ValueError, match="non-finite"):
        Finding("x", float("nan"), 1.0, 0.0, Severity.PASS, "s")
    with pytest.raises(ValueError, match="must say why"):
        Finding("x", None, None, None, Severity.NOT_EVALUATED, "s")


def test_registry_is_data():
    ids = [r.rule_id for r in RULES]
    assert len(ids) == len(set(ids))
    assert {"paper.drum_to_cable", "paper.pretension_fraction", "paper.holding_torque", "paper.cable_diameter",
            "paper.cable_elongation", "paper.guide_friction", "paper.guides_per_route", "physics.capstan_no_slip",
            "physics.no_slack_side", "physics.stepper_pullout", "physics.microstep_resolution", "physics.strouhal",
            "print.hull_wall", "print.bed_fit", "float.upright", "float.net_buoyancy", "float.level"} <= set(ids)


def test_default_design_verdicts(default_findings):
    f = default_findings
    p = Params()
    # paper guidelines the default meets, with values worked by hand
    assert f["paper.drum_to_cable"].value == pytest.approx(20.0) and f["paper.drum_to_cable"].severity is Severity.PASS
    assert f["paper.pretension_fraction"].value == pytest.approx(0.15)         # 45 / 300
    assert f["paper.cable_diameter"].severity is Severity.PASS
    assert f["paper.guide_friction"].severity is Severity.PASS
    # St = 3 x 0.2 / 1.97 = 0.304569, inside 0.25-0.35
    assert f["physics.strouhal"].value == pytest.approx(0.304569, abs=1e-6)
    assert f["physics.strouhal"].severity is Severity.PASS
    # hull wall 2 mm / 0.45 mm = 4.444 line widths
    assert f["print.hull_wall"].value == pytest.approx(2 / 0.45)
    # half a joint microstep (0.075 / 2 deg) over the smallest joint amplitude (joint 2)
    wave = wave_from_params(p.swimming, 0.52)
    amp = max_relative_joint_angles_rad(wave, np.asarray(p.joints.stations_fraction) * 0.52, 0.52, 256)
    assert f["physics.microstep_resolution"].value == pytest.approx(math.radians(0.0375) / amp.min(), rel=1e-3)
    # what the load model says of the paper's design point: the drive cannot hold the swimming loads
    for rid in ("paper.holding_torque", "paper.cable_elongation", "physics.capstan_no_slip", "physics.no_slack_side",
                "physics.cable_strength", "physics.stepper_pullout", "physics.cable_compliance"):
        assert f[rid].severity is Severity.FAIL, rid
    assert f["paper.guides_per_route"].severity is Severity.WARN              # 4 bends on the joint-3/4 routes
    assert f["float.upright"].severity is Severity.NOT_EVALUATED and "mass properties" in f["float.upright"].detail
    assert verdict(f.values()) is Severity.FAIL


def test_no_slack_rule_is_pretension_vs_half_the_torque_over_the_arm(default_findings):
    f = default_findings["physics.no_slack_side"]
    from swiftfin.layout.loads import joint_loads
    peak = joint_loads(Params()).peak_torque_nm.max()
    assert f.value == 45.0 and f.limit == pytest.approx(peak / (2 * 0.015))


def _write(tmp_path, text):
    path = tmp_path / "design.toml"
    path.write_text(text)
    return path


# a drum just under the paper's 20 d: the spool can still be made (a 12 mm one, as this used to be, has no room for
# its anchors and index holes: the loader refuses it, naming the key and the least drum, below)
BAD = "[spool]\ndrum_diameter_mm = 19.8\n[cable]\ndiameter_mm = 1.0\npretension_n = 15.0\n"
# the wider stops keep the joints' gaps, and so the dry wall, far enough ahead of joint 1 that the cables cross the
# wall clear of the seam gasket (layout/gland_plan.py); with the default 5 deg the loader refuses the light gait
LIGHT = "[swimming]\ntail_beat_frequency_hz = 2.0\ntail_amplitude_m = 0.03\nspeed_m_s = 0.4\n[joints]\nstop_margin_deg = 18.0\n"


def test_bad_design_fails_drum_pretension_and_slip(tmp_path):
    fs = _by_id(run_rules(RuleContext(load_design(_write(tmp_path, BAD)))))
    assert fs["paper.drum_to_cable"].severity is Severity.FAIL and fs["paper.drum_to_cable"].value == 19.8
    assert fs["paper.pretension_fraction"].severity is Severity.FAIL
    assert fs["paper.pretension_fraction"].value == pytest.approx(0.05)
    assert fs["physics.capstan_no_slip"].severity is Severity.FAIL


def test_a_drum_with_no_room_for_its_spool_is_refused_by_the_loader(tmp_path):
    with pytest.raises(ParamError, match=r"spool.drum_diameter_mm = 12.0: no room for the cable anchor holes .* at "
                                         r"least 12.20 mm"):
        load_design(_write(tmp_path, BAD.replace("19.8", "12.0")))


def test_slip_rule_separates_the_bad_spool_at_a_light_load(tmp_path):
    # 2 Hz, 3 cm: the default spool and 45 N pretension hold; 15 N pretension lets a side go slack and slip
    good = _by_id(run_rules(RuleContext(load_design(_write(tmp_path, LIGHT + "[cable]\nyoungs_modulus_gpa = 100.0\n")))))
    bad = _by_id(run_rules(RuleContext(load_design(_write(tmp_path, LIGHT + BAD)))))
    assert good["physics.capstan_no_slip"].severity is Severity.PASS
    assert good["physics.no_slack_side"].severity is Severity.PASS
    assert bad["physics.capstan_no_slip"].severity is Severity.FAIL
    assert bad["physics.no_slack_side"].severity is Severity.FAIL


def test_mass_properties_drive_the_floating_rules():
    ok = MassProperties.from_dict({"total_mass_kg": 1.2, "com_m": [-0.2, 0, -0.01], "cob_m": [-0.2, 0, 0.0],
                                   "displaced_volume_m3": 1.22e-3})
    fs = _by_id(run_rules(RuleContext(Params(), mass_properties=ok),
                          [r for r in RULES if r.rule_id.startswith("float.")]))
    # z_cob - z_com = 10 mm; (1000 x 1.22e-3 - 1.2) / 1.2 = 0.016667 within 0.05
    assert fs["float.upright"].value == pytest.approx(10.0) and fs["float.upright"].severity is Severity.PASS
    assert fs["float.net_buoyancy"].value == pytest.approx(0.016667, abs=1e-6)
    assert fs["float.net_buoyancy"].severity is Severity.PASS
    assert fs["float.level"].value == pytest.approx(0.0, abs=1e-9) and fs["float.level"].severity is Severity.PASS
    # the sealed default design before trimming: COM 30 mm ahead of the COB, 7.5 mm below it -> 76 deg nose down
    nose_heavy = MassProperties(1.7, (-0.170, 0, -0.0075), (-0.200, 0, 0.0), 1.7e-3)
    fl = _by_id(run_rules(RuleContext(Params(), mass_properties=nose_heavy),
                          [r for r in RULES if r.rule_id == "float.level"]))["float.level"]
    assert fl.value == pytest.approx(math.degrees(math.atan2(30.0, 7.5)), rel=1e-9)
    assert fl.severity is Severity.FAIL and "nose-down" in fl.detail
    capsized = MassProperties(1.2, (-0.2, 0, 0.01), (-0.2, 0, 0.0), 1.5e-3)
    fs = _by_id(run_rules(RuleContext(Params(), mass_properties=capsized),
                          [r for r in RULES if r.rule_id.startswith("float.")]))
    assert fs["float.upright"].severity is Severity.FAIL and fs["float.net_buoyancy"].severity is Severity.FAIL


def test_mass_properties_bad_input_lists_every_problem():
    with pytest.raises(ParamError) as exc:
        MassProperties.from_dict({"total_mass_kg": -1, "com_m": [0, 0], "cob_m": [0, 0, float("nan")], "x": 1})
    msg = str(exc.value)
    for key in ("total_mass_kg", "com_m", "cob_m", "displaced_volume_m3", "unknown key"):
        assert key in msg


def test_bed_fit_geometry():
    bed = (250.0, 210.0, 220.0)
    assert fits_bed((240, 200, 100), bed)
    assert not fits_bed((240, 200, 230), bed)
    # 280 x 20 fits only turned: at 40 deg, 280 cos + 20 sin = 227.3 <= 250 and 280 sin + 20 cos = 195.3 <= 210
    assert fits_bed((280, 20, 10), bed) and not fits_bed((280, 20, 10), bed, n_angles=1)
    # 300 x 30 does not fit at any angle
    assert not fits_bed((300, 30, 10), bed)
    # a box of half the bed can double
    assert fit_factor((125, 105, 110), bed) == pytest.approx(2.0, rel=1e-6)


def test_bed_fit_uses_built_boxes_when_given():
    ctx = RuleContext(Params(), part_bboxes_mm={"a": (100.0, 100.0, 50.0), "b": (125.0, 105.0, 110.0)})
    f = _by_id(run_rules(ctx, [r for r in RULES if r.rule_id == "print.bed_fit"]))["print.bed_fit"]
    assert f.value == pytest.approx(2.0, rel=1e-6) and "built parts" in f.detail


def test_rule_param_contradictions():
    with pytest.raises(ParamError) as err:
        params_from_dict({"rules": {"strouhal_min": 0.4, "strouhal_max": 0.3}})
    assert [pr.key for pr in err.value.problems] == ["rules.strouhal_min"]


def test_no_nan_over_a_seeded_sweep():
    rng = np.random.default_rng(4)
    for _ in range(6):
        d = {"swimming": {"tail_beat_frequency_hz": float(rng.uniform(0.5, 4.0)),
                          "tail_amplitude_m": float(rng.uniform(0.01, 0.08)),
                          "speed_m_s": float(rng.choice([0.0, rng.uniform(0.1, 2.0)]))},
             "cable": {"pretension_n": float(rng.uniform(0.0, 100.0))},
             "guides": {"mu_ptfe": float(rng.uniform(0.01, 0.5))}}
        fs = run_rules(RuleContext(params_from_dict(d)))   # Finding refuses non-finite numbers itself
        assert len(fs) == len(RULES)
        assert all(f.severity is not Severity.NOT_EVALUATED or f.detail for f in fs)


def test_values_and_margins_read_as_a_person_would():
    """A level fish's pitch of 2e-13 deg reads 0; a value 849 times its limit reads "849x the limit", not
    "-84780 %" (issue 15); within 100 % the margin stays a percentage."""
    from swiftfin.design_rules.findings import at_most

    tiny = at_most("float.level", 2.1e-13, 5.0, "test", unit="deg")
    assert tiny.value_text() == "0" and tiny.margin_text() == "+100 %"
    far = at_most("physics.cable_compliance", 16.98, 0.02, "test")
    assert far.margin_text() == "849x the limit"
    near = at_most("x", 1.5, 1.0, "test")
    assert near.margin_text() == "-50 %"


# --------------------------------------------------------------------------------------------- fin root
def test_fin_root_is_the_peak_moment_over_the_tangs_section(default_findings):
    """physics.fin_root: the load model's fin forces about the socket's mouth over h t^2 / 6 of the tang there,
    against PLA's 57 MPa x 0.3 (catalogues/printed_strength.toml). Default: 1.56 N m on 4.09 x 13.10 mm, 42.7 MPa
    (worked with a script on the load model, 2026-11-28): the flat-printed tang is past its allowable at 3 Hz."""
    import dataclasses
    from swiftfin.layout.fin_plan import tang_dims_mm
    from swiftfin.layout.loads import joint_loads
    p = Params()
    f = default_findings["physics.fin_root"]
    td = tang_dims_mm(p)
    z = td.height_mm * td.thickness_mm**2 / 6
    assert z == pytest.approx(36.5628, rel=1e-4)
    m = joint_loads(p).peak_fin_root_moment_nm
    assert m == pytest.approx(1.5624, rel=1e-3)
    assert f.value == pytest.approx(m * 1e3 / z) and f.value == pytest.approx(42.73, rel=1e-3)
    assert f.limit == pytest.approx(57.0 * 0.3) and f.comparison == "<="
    assert f.severity is Severity.FAIL
    # at a tenth of the frequency (the same stride) the forces fall about a hundredfold and the tang holds
    slow = dataclasses.replace(p, swimming=dataclasses.replace(p.swimming, tail_beat_frequency_hz=0.3,
                                                               speed_m_s=p.swimming.speed_m_s / 10))
    assert joint_loads(slow).peak_fin_root_moment_nm < m / 50


def test_fin_root_moment_is_the_fins_moment_about_a_joint_at_the_mouth():
    """Put the last joint at the hull end: the fin's moment about the mouth (a point interpolated on the last link)
    is then exactly the fin's share of that joint's torque (computed about the joint's own node)."""
    import dataclasses
    from swiftfin.layout.loads import joint_loads
    p = Params()
    st = (*p.joints.stations_fraction[:-1], p.body.hull_end_fraction)
    jl = joint_loads(dataclasses.replace(p, joints=dataclasses.replace(p.joints, stations_fraction=st)))
    fin = jl.components_nm["fin_lift"][:, -1] + jl.components_nm["fin_added_mass"][:, -1]
    assert np.abs(fin).max() > 0.5
    np.testing.assert_allclose(jl.fin_root_moment_nm, fin, rtol=0, atol=1e-12)
