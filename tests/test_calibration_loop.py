"""Closing the loop (issue 14, item 4): ``swiftfin fit joint`` writes ``calibration.toml``; ``swiftfin check
--calibration`` re-evaluates the rules with it. The fit is run on simulated logs of known truth
(``swiftfin synth``); the calibrated loads are checked against their closed form; a bad calibration file is one
message naming the file and the key, exit 2. The build's side (the simulator files) is in tests/test_build.py."""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from swiftfin.calibration.closing import calibration_from_report, joint_values
from swiftfin.calibration.joint import BENCH_BEARING_DAMPING_NM_S_RAD
from swiftfin.cli import main
from swiftfin.core.calibration import (Calibration, JointCalibration, Measured, calibration_from_dict,
                                       calibration_toml, load_calibration)
from swiftfin.core.params import ParamError
from swiftfin.design_rules import RuleContext
from tests.conftest import DEFAULT_DESIGN


@pytest.fixture(scope="module")
def p():
    from swiftfin.layout.design import load_design
    return load_design(DEFAULT_DESIGN)


def _fit(tmp_path, effects: list[str], name: str) -> dict:
    """Simulate a bench log of joint 4 with ``effects``, fit it, return the calibration file's content."""
    log = tmp_path / f"{name}.csv"
    args = ["synth", "joint", "--out", str(log), "--design", str(DEFAULT_DESIGN), "--seed", "3"]
    for e in effects:
        args += ["--effect", e]
    assert main(args) == 0
    out = tmp_path / f"fit_{name}"
    assert main(["fit", "joint", str(log), "--design", str(DEFAULT_DESIGN), "--out", str(out), "--no-plots"]) == 0
    return tomllib.loads((out / "calibration.toml").read_text()), out / "calibration.toml"


def test_the_fit_writes_the_hinge_damping_it_was_given(tmp_path, p, capsys):
    """Known truth: the simulated bench's hinge has its bearing damping plus 0.02 N m s/rad."""
    raw, path = _fit(tmp_path, ["viscous_friction=0.02"], "visc")
    m = raw["joint_4"]["hinge_damping_nm_s_rad"]
    assert m["value"] == pytest.approx(0.02 + BENCH_BEARING_DAMPING_NM_S_RAD, rel=0.03)
    assert m["effect"] == "viscous_friction" and m["std"] > 0
    assert raw["source"]["log"].endswith("visc.csv") and len(raw["source"]["log_sha256"]) == 64
    assert "design" not in raw                               # a damping revises no design key
    assert "calibration:" in capsys.readouterr().out
    # check --calibration: the rules' load model carries c w at joint 4, nothing at the others
    cal = load_calibration(path, p)
    base, calibrated = RuleContext(p).loads, RuleContext(p, calibration=cal).loads
    c = m["value"]
    assert np.allclose(calibrated.torque_nm[:, 3] - base.torque_nm[:, 3], c * base.joint_rate_rad_s[:, 3])
    assert np.array_equal(calibrated.torque_nm[:, :3], base.torque_nm[:, :3])
    assert main(["check", str(DEFAULT_DESIGN), "--calibration", str(path)]) in (0, 1)
    out = capsys.readouterr().out
    assert f"calibrated by {path}: joint 4 hinge_damping_nm_s_rad: {c:.4g}" in out


def test_a_softer_cable_revises_the_design_modulus_and_the_rules_read_it(tmp_path, p, capsys):
    """Known truth: the bench's cables are 0.1 of the design's stiffness, so the effective modulus is 0.1 x
    2 GPa. The engine's estimate is 8 % low on this log (its quoted standard error is far smaller: issue 14's
    overconfidence, not this file's), so the truth is held at 15 %."""
    raw, path = _fit(tmp_path, ["cable_compliance=0.1"], "soft")
    e = raw["design"]["cable.youngs_modulus_gpa"]["value"]
    assert e == pytest.approx(0.1 * p.cable.youngs_modulus_gpa, rel=0.15)
    cal = load_calibration(path, p)
    revised = cal.revised_params(p)
    assert revised.cable.youngs_modulus_gpa == e
    assert main(["check", str(DEFAULT_DESIGN), "--calibration", str(path), "--json", str(tmp_path / "c.json")]) == 1
    import json
    findings = {f["rule_id"]: f for f in json.loads((tmp_path / "c.json").read_text())["findings"]}
    assert f"E = {e:g} GPa" in findings["paper.cable_elongation"]["detail"]
    from swiftfin.design_rules import run_rules
    base = {f.rule_id: f.value for f in run_rules(RuleContext(p))}
    # ten times softer cables stretch about ten times more
    assert findings["paper.cable_elongation"]["value"] == pytest.approx(
        base["paper.cable_elongation"] * p.cable.youngs_modulus_gpa / e, rel=1e-6)


def test_friction_and_damping_in_the_loads_match_their_closed_form(p):
    cal = Calibration({}, (JointCalibration(2, {"hinge_friction_nm": Measured(0.05, 0.001, "coulomb_friction"),
                                                "hinge_damping_nm_s_rad": Measured(0.01, 0.0, "viscous_friction")}),))
    base, calibrated = RuleContext(p).loads, RuleContext(p, calibration=cal).loads
    w = base.joint_rate_rad_s[:, 1]
    assert np.allclose(calibrated.torque_nm[:, 1], base.torque_nm[:, 1] + 0.01 * w + 0.05 * np.sign(w))
    assert np.allclose(calibrated.components_nm["hinge"][:, [0, 2, 3]], 0.0)
    # and the drive follows: a larger joint torque needs a larger motor torque at that joint
    assert RuleContext(p, calibration=cal).drive.peak_motor_torque_nm[1] > RuleContext(p).drive.peak_motor_torque_nm[1]


def test_the_report_to_calibration_mapping(tmp_path):
    """Each effect's fitted parameters to the robot's quantities, with first-order error propagation."""
    def eff(name, params, physical=None, conf="high", twins=()):
        return {"name": name, "params": {k: {"value": v, "std": s} for k, (v, s) in params.items()},
                "physical": {k: {"value": v, "std": s} for k, (v, s) in (physical or {}).items()},
                "confidence": conf, "indistinguishable_from": list(twins)}
    rep = {"added_effects": [
        eff("viscous_friction", {"gain": (1.0, 0.01), "damping_nm_s_rad": (0.03, 0.001)}),
        eff("coulomb_friction", {"gain": (0.9, 0.02), "friction_torque_nm": (0.02, 0.001)}, twins=("backlash",)),
        eff("cable_compliance", {"gain": (1.0, 0.0), "stiffness_factor": (0.5, 0.01)},
            {"joint_stiffness_nm_rad": (1.2, 0.02), "effective_modulus_gpa": (1.0, 0.02)}),
        eff("effective_radius", {"ratio_error": (0.05, 0.001)}),
        eff("sensor_delay", {"gain": (1.0, 0.0), "delay_s": (0.008, 0.0001)}, conf="medium")]}
    joint, design = joint_values(rep)
    assert joint["hinge_damping_nm_s_rad"].value == pytest.approx(0.03 + BENCH_BEARING_DAMPING_NM_S_RAD)
    assert joint["hinge_friction_nm"].value == pytest.approx(0.018)
    assert joint["hinge_friction_nm"].std == pytest.approx(math.hypot(0.9 * 0.001, 0.02 * 0.02))
    assert joint["hinge_friction_nm"].confidence == "low"          # indistinguishable from backlash: said so
    assert joint["joint_stiffness_nm_rad"].value == 1.2 and design["cable.youngs_modulus_gpa"].value == 1.0
    assert joint["spool_radius_ratio"].value == pytest.approx(1.05)
    assert joint["sensor_delay_s"].confidence == "medium"
    # the file round-trips
    log = tmp_path / "a \"quoted\" log.csv"
    log.write_text("time_s\n")
    cal = calibration_from_report(rep, 3, log, DEFAULT_DESIGN)
    from swiftfin.layout.design import load_design
    back = calibration_from_dict(tomllib.loads(calibration_toml(cal)), load_design(DEFAULT_DESIGN))
    assert back.joint(3).values == cal.joint(3).values and back.design == cal.design
    assert back.source["log"] == str(log)


BAD = {
    "unknown table": ("[joints_4]\n", ["joints_4", "unknown table", "did you mean 'joint_1'"]),
    "joint beyond the design": ("[joint_9]\n", ["joint_9", "expected joint_1 .. joint_4"]),
    "joint written twice": ("[joint_4]\n[joint_04]\n", ["joint_04", "expected joint_1 .. joint_4"]),
    "unknown quantity": ("[joint_4]\nhinge_dampin_nm_s_rad = { value = 0.1, std = 0.0, effect = \"v\" }\n",
                         ["joint_4.hinge_dampin_nm_s_rad", "did you mean 'hinge_damping_nm_s_rad'"]),
    "negative std": ("[joint_4]\nhinge_friction_nm = { value = 0.1, std = -1.0, effect = \"c\" }\n",
                     ["joint_4.hinge_friction_nm.std = -1.0", "a standard error is >= 0"]),
    "not a number": ("[joint_4]\nhinge_friction_nm = { value = \"much\", std = 0.0, effect = \"c\" }\n",
                     ["joint_4.hinge_friction_nm.value = 'much'", "expected a finite number"]),
    "negative damping": ("[joint_1]\nhinge_damping_nm_s_rad = { value = -0.1, std = 0.0, effect = \"v\" }\n",
                         ["joint_1.hinge_damping_nm_s_rad.value = -0.1", "expected >= 0"]),
    "bare number": ("[joint_1]\nhinge_damping_nm_s_rad = 0.1\n",
                    ["joint_1.hinge_damping_nm_s_rad = 0.1", "expected a table"]),
    "design key not revisable": ("[design]\n\"body.length_mm\" = { value = 1.0, std = 0.0, effect = \"x\" }\n",
                                 ["design.\"body.length_mm\"", "not a key a calibration revises"]),
    "revised key out of range": ("[design]\n\"cable.youngs_modulus_gpa\" = { value = 1e6, std = 0.0, effect = "
                                 "\"cable_compliance\" }\n", ["cable.youngs_modulus_gpa", "1000000.0"]),
    "not toml": ("[joint_4\n", ["not valid TOML"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_calibration_file_is_refused_naming_file_and_key(tmp_path, case, capsys):
    text, expected = BAD[case]
    f = tmp_path / "cal.toml"
    f.write_text(text)
    rc = main(["check", str(DEFAULT_DESIGN), "--calibration", str(f)])
    err = capsys.readouterr().err
    assert rc == 2, err
    assert str(f) in err and "calibration file" in err and "Traceback" not in err
    for piece in expected:
        assert piece in err, err


def test_a_missing_calibration_file_is_refused_before_a_build(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["build", str(DEFAULT_DESIGN), "--out", "out", "--calibration", "nope.toml"]) == 2
    assert "calibration file not found" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("text, expected", [
    ("link_inertia_kg_m2 = -1.0\n", ["link_inertia_kg_m2 = -1.0", "expected a number in [1e-09, 1]"]),
    ("link_inertia = 1e-5\n", ["link_inertia = 1e-05", "did you mean 'link_inertia_kg_m2'"]),
    ("bearing_damping_nm_s_rad = \"low\"\n", ["bearing_damping_nm_s_rad = 'low'"]),
    ("link_inertia_kg_m2 = \n", ["not valid TOML"]),
    ("medium = \"oil\"\n", ["medium = 'oil'", 'expected "air" or "water"']),
    ("medium = 1\n", ["medium = 1", 'expected "air" or "water"']),
    ("mediun = \"water\"\n", ["did you mean 'medium'"]),
])
def test_a_bad_bench_file_is_refused_by_synth_and_fit(tmp_path, text, expected, capsys):
    bench = tmp_path / "bench.toml"
    bench.write_text(text)
    for args in (["synth", "joint", "--out", str(tmp_path / "log.csv")],
                 ["fit", "joint", str(tmp_path / "log.csv"), "--out", str(tmp_path / "fit")]):
        assert main(args + ["--bench", str(bench)]) == 2
        err = capsys.readouterr().err
        assert str(bench) in err and "bench file" in err and "Traceback" not in err
        for piece in expected:
            assert piece in err, err
    assert not (tmp_path / "log.csv").exists() and not (tmp_path / "fit").exists()


@pytest.mark.parametrize("inertia", [1.2e-4, 6e-6, 1.5e-3])
def test_a_bench_file_changes_the_simulated_and_the_modelled_link(tmp_path, p, inertia):
    """A bench holding another link than the design's tail (2.10e-4 kg m^2 about hinge 4, in air) rings at another
    frequency: simulated with it and fitted without the bench file, the fit finds the link's inertia (lighter or
    heavier than the design's) and the difference as an added inertia; fitted with the bench file, nothing."""
    from swiftfin.calibration.joint import joint_design
    prior = joint_design(p).link_inertia_kg_m2
    assert prior == pytest.approx(2.10e-4, rel=0.01)        # the design's link 4 and fin, thin-shell estimate
    bench = tmp_path / "bench.toml"
    bench.write_text(f"link_inertia_kg_m2 = {inertia!r}\n")
    assert main(["synth", "joint", "--out", str(tmp_path / "log.csv"), "--bench", str(bench), "--seed", "2"]) == 0
    assert main(["fit", "joint", str(tmp_path / "log.csv"), "--out", str(tmp_path / "plain"), "--no-plots"]) == 0
    assert main(["fit", "joint", str(tmp_path / "log.csv"), "--out", str(tmp_path / "bench"), "--no-plots",
                 "--bench", str(bench)]) == 0
    plain = tomllib.loads((tmp_path / "plain" / "calibration.toml").read_text())["joint_4"]
    benched = tomllib.loads((tmp_path / "bench" / "calibration.toml").read_text())["joint_4"]
    assert plain["added_inertia_kg_m2"]["value"] == pytest.approx(inertia - prior, rel=0.05)
    assert "added_inertia_kg_m2" not in benched


def test_bench_and_mjcf_are_for_the_joint_family_and_a_bad_mjcf_is_named(tmp_path, capsys):
    assert main(["fit", "drive", "x.mat", "--bench", "b.toml"]) == 2
    assert "--bench applies to the joint family only" in capsys.readouterr().err
    assert main(["synth", "joint", "--out", str(tmp_path / "log.csv"), "--seed", "1"]) == 0
    (tmp_path / "not.xml").write_text("<mujoco><worldbody><body></mujoco>")
    assert main(["fit", "joint", str(tmp_path / "log.csv"), "--out", str(tmp_path / "f"), "--no-plots",
                 "--mjcf", str(tmp_path / "not.xml")]) == 2
    err = capsys.readouterr().err
    assert f"--mjcf {tmp_path / 'not.xml'}: MuJoCo cannot load it" in err and "Traceback" not in err
    assert not (tmp_path / "f").exists()              # refused before the fit: nothing written
    assert main(["fit", "joint", str(tmp_path / "log.csv"), "--out", str(tmp_path / "g"), "--mjcf",
                 str(tmp_path)]) == 2
    assert "file not found" in capsys.readouterr().err


def test_a_measured_friction_is_as_stiff_as_mujoco_allows_at_the_exported_time_step():
    """MuJoCo wants a constraint's time constant at least twice the time step; the calibrated friction's is
    exactly that at the MJCF's step (stiffer would be ignored, softer lets the link creep through its stuck band)."""
    from swiftfin.exports.mjcf import TIMESTEP_S
    from swiftfin.layout.servo import FRICTION_TIMECONST_S
    assert FRICTION_TIMECONST_S == pytest.approx(2 * TIMESTEP_S)


def test_a_calibrated_drive_takes_a_measured_zero_as_zero(p):
    """A hinge measured with no friction keeps 0, and one whose damping was measured keeps it: a value in the file
    is never replaced by the placeholder."""
    from swiftfin.layout.servo import UNCALIBRATED_DAMPING_NM_S_RAD, drive_stiffness_nm_rad, joint_servo
    jc = JointCalibration(4, {"hinge_damping_nm_s_rad": Measured(0.0, 0.0, "viscous_friction"),
                              "hinge_friction_nm": Measured(0.0, 0.0, "coulomb_friction")})
    s = joint_servo(p, 4, jc)
    assert s.damping_nm_s_rad == 0.0 and s.friction_nm == 0.0
    assert s.kp_nm_rad == pytest.approx(drive_stiffness_nm_rad(p, 4)) and s.kv_nm_s_rad == 0.0
    empty = joint_servo(p, 4, JointCalibration(4, {}))
    assert empty.damping_nm_s_rad == UNCALIBRATED_DAMPING_NM_S_RAD
