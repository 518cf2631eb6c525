"""``swiftfin check``: the table, the JSON, and the exit codes 0 / 1 / 2."""
from __future__ import annotations

import json

from swiftfin.cli import main
from tests.conftest import DEFAULT_DESIGN


def _write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_default_design_fails_with_a_table_and_json(tmp_path, capsys):
    out_json = tmp_path / "check.json"
    assert main(["check", str(DEFAULT_DESIGN), "--json", str(out_json)]) == 1
    out = capsys.readouterr().out
    assert out.splitlines()[1].split() == ["rule", "value", "limit", "margin", "verdict"]
    assert "paper.drum_to_cable" in out and "verdict: FAIL" in out
    data = json.loads(out_json.read_text())
    assert data["verdict"] == "FAIL"
    by_id = {f["rule_id"]: f for f in data["findings"]}
    assert by_id["physics.strouhal"]["severity"] == "PASS"
    assert by_id["float.upright"]["severity"] == "NOT_EVALUATED" and by_id["float.upright"]["value"] is None
    assert len(data["loads"]["per_joint"]) == 4


def test_passing_design_exits_0(tmp_path, capsys):
    # light swimming, a stiff cable (Dyneema-like modulus) at 38 N of pretension (its friction through the bends is
    # most of the motor's torque at this gait), the motors at 1.0 A (their torques scaled with the current) in an
    # ASA head, and built parts that fit the bed: nothing fails. Stops 18 deg past the wave's angles: with the
    # default 5 deg the joints' gaps close up at this gait, the dry wall moves aft toward joint 1, and a gland's tube
    # runs into the seam gasket (the loader refuses it, layout/gland_plan.py; built, the tail's segments also met)
    params = _write(tmp_path, "light.toml", "[swimming]\ntail_beat_frequency_hz = 1.0\ntail_amplitude_m = 0.02\n"
                                           "speed_m_s = 0.15\n[joints]\nstop_margin_deg = 18.0\n"
                                           "[cable]\nyoungs_modulus_gpa = 100.0\n"
                                           "pretension_n = 38.0\n"
                                           "[motor]\nphase_current_a = 1.0\nholding_torque_nm = 0.28\n"
                                           "pullout_curve_torque_nm = [0.27, 0.25, 0.22, 0.16, 0.09, 0.03]\n"
                                           "[print]\nmaterial = \"ASA\"\n")
    boxes = _write(tmp_path, "boxes.json", json.dumps({"hull_head_upper": [200, 80, 60], "spool": [26, 26, 20]}))
    mp = _write(tmp_path, "mp.json", json.dumps({"total_mass_kg": 1.2, "com_m": [-0.2, 0, -0.01],
                                                 "cob_m": [-0.2, 0, 0.0], "displaced_volume_m3": 1.21e-3}))
    assert main(["check", params, "--parts-bbox", boxes, "--mass-properties", mp]) == 0
    out = capsys.readouterr().out
    assert "verdict: WARN" in out and "FAIL" not in out.split("verdict:")[0].split("why:")[0]


def test_bad_design_fails_the_named_rules(tmp_path, capsys):
    # a drum just under 20 cable diameters (a 12 mm one has no room for the spool: the loader refuses it)
    params = _write(tmp_path, "bad.toml", "[spool]\ndrum_diameter_mm = 19.8\n[cable]\ndiameter_mm = 1.0\n"
                                         "pretension_n = 15.0\n")
    out_json = tmp_path / "bad.json"
    assert main(["check", params, "--json", str(out_json)]) == 1
    sev = {f["rule_id"]: f["severity"] for f in json.loads(out_json.read_text())["findings"]}
    assert sev["paper.drum_to_cable"] == sev["paper.pretension_fraction"] == sev["physics.capstan_no_slip"] == "FAIL"


def test_bad_parameter_file_exits_2(tmp_path, capsys):
    params = _write(tmp_path, "bad.toml", "[spool]\ndrum_diameter_mm = -3\n")
    assert main(["check", params]) == 2
    err = capsys.readouterr().err
    assert "spool.drum_diameter_mm = -3" in err and "Traceback" not in err


def test_contradictory_rule_limits_exit_2(tmp_path, capsys):
    params = _write(tmp_path, "r.toml", "[rules]\nstrouhal_min = 0.4\nstrouhal_max = 0.3\n")
    assert main(["check", params]) == 2
    assert "rules.strouhal_min" in capsys.readouterr().err


def test_bad_side_files_exit_2(tmp_path, capsys):
    mp = _write(tmp_path, "mp.json", json.dumps({"total_mass_kg": "heavy"}))
    assert main(["check", str(DEFAULT_DESIGN), "--mass-properties", mp]) == 2
    err = capsys.readouterr().err
    assert "total_mass_kg" in err and "displaced_volume_m3" in err
    boxes = _write(tmp_path, "b.json", "{not json")
    assert main(["check", str(DEFAULT_DESIGN), "--parts-bbox", boxes]) == 2
    assert "not readable JSON" in capsys.readouterr().err
    assert main(["check", str(DEFAULT_DESIGN), "--parts-bbox", str(tmp_path / "missing.json")]) == 2


def test_a_builds_own_mass_properties_file_is_accepted(tmp_path, capsys):
    """`swiftfin check --mass-properties build/mass_properties.json` reads the build's `total` table; a bad one is
    named as a mass-properties file, not a parameter file, with long values shortened."""
    total = {"mass_kg": 1.73, "com_m": [-0.174, 0, -0.0075], "cob_m": [-0.174, 0, 0.0001],
             "displaced_volume_m3": 1.73e-3, "inertia_kg_m2": {"ixx": 1e-3}}
    mp = _write(tmp_path, "mass_properties.json", json.dumps({"units": "SI", "parts": [], "links": [], "total": total}))
    out_json = tmp_path / "c.json"
    main(["check", str(DEFAULT_DESIGN), "--mass-properties", mp, "--json", str(out_json)])
    sev = {f["rule_id"]: f["severity"] for f in json.loads(out_json.read_text())["findings"]}
    assert sev["float.upright"] == sev["float.net_buoyancy"] == sev["float.level"] == "PASS"
    bad = _write(tmp_path, "bad_mp.json", json.dumps({"total": {"mass_kg": -1, "com_m": [0, 0]}, "x": list(range(99))}))
    assert main(["check", str(DEFAULT_DESIGN), "--mass-properties", bad]) == 2
    err = capsys.readouterr().err
    assert "problem(s) in the mass-properties file" in err and "total_mass_kg = -1" in err
    assert "Traceback" not in err


def test_loads_flag_prints_sensitivities(capsys):
    assert main(["check", str(DEFAULT_DESIGN), "--loads"]) == 1
    out = capsys.readouterr().out
    assert "sensitivity d log(output) / d log(coefficient)" in out and "hydro.fin_added_mass_coefficient" in out


def test_json_into_a_new_folder_and_unwritable_path(tmp_path, capsys):
    out = tmp_path / "build" / "deep" / "check.json"
    assert main(["check", str(DEFAULT_DESIGN), "--json", str(out)]) == 1 and out.is_file()
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["check", str(DEFAULT_DESIGN), "--json", str(blocker / "check.json")]) == 2
    assert "cannot write" in capsys.readouterr().err


def _build_folder(tmp_path, parts, mass=True):
    d = tmp_path / "b"
    d.mkdir()
    (d / "manifest.json").write_text(json.dumps({"parts": parts}))
    if mass:
        total = {"mass_kg": 1.73, "com_m": [-0.174, 0, -0.0075], "cob_m": [-0.174, 0, 0.0001],
                 "displaced_volume_m3": 1.73e-3}
        (d / "mass_properties.json").write_text(json.dumps({"total": total}))
    return str(d)


def _printed(label, support, walls=(), bridges=(), bores=()):
    return {"label": label, "printed": True, "print_size_mm": [40, 30, 20],
            "print": {"rotation_deg": [0, 0, 0], "support_area_mm2": support, "bores_checked": 6,
                      "supported_bores": [{"fastener": f"{label}_screw_{i}", "what": "counterbore", "diameter_mm": d,
                                           "tilt_deg": 90.0} for i, d in enumerate(bores)],
                      "thin_walls": [{"thickness_mm": t, "limit_mm": lim, "area_mm2": 3.0, "at_mm": [-10, 2, 5],
                                      "kind": "wall"} for t, lim in walls],
                      "bridges": [{"span_mm": s, "limit_mm": 10.0, "area_mm2": 40.0, "at_mm": [-5, 0, 3]}
                                  for s in bridges]}}


def test_check_reads_a_build_folders_printability(tmp_path, capsys):
    """`swiftfin check --build DIR`: the print rules from the manifest's records (support summed, INFO; a wall under
    its limit fails, named with its part and place; bridges over the limit warn), the float rules from the folder's
    mass properties, the bed rule from its boxes."""
    d = _build_folder(tmp_path, [_printed("bracket", 120.5, walls=[(0.61, 0.9)], bridges=[23.0, None], bores=[12.0]),
                                 _printed("lid", 30.0), {"label": "motor", "printed": False}])
    out_json = tmp_path / "c.json"
    assert main(["check", str(DEFAULT_DESIGN), "--build", d, "--json", str(out_json)]) == 1
    by = {f["rule_id"]: f for f in json.loads(out_json.read_text())["findings"]}
    assert by["print.support"]["severity"] == "INFO" and by["print.support"]["value"] == 150.5
    assert "2 of 2 printed parts need support; most: bracket 120, lid 30 mm^2" in by["print.support"]["detail"]
    tw = by["print.thin_walls"]            # 0.61 mm: over one line, under two perimeters: it prints, thin
    assert tw["severity"] == "WARN" and tw["value"] == 1 and tw["limit"] == 0
    assert "bracket, 0.61 mm wall (limit 0.90) over 3.0 mm^2 at (-10.0, 2.0, 5.0) mm" in tw["detail"]
    br = by["print.bridges"]
    assert br["severity"] == "WARN" and br["value"] == 2
    assert "longest: bracket, 23.0 mm" in br["detail"] and "1 with no edge on material below" in br["detail"]
    bo = by["print.bores"]
    assert bo["severity"] == "FAIL" and bo["value"] == 1
    assert "of 12 fastener holes; widest: counterbore of bracket_screw_0 in bracket, 12.00 mm at 90 deg" in bo["detail"]
    assert by["float.upright"]["severity"] == "PASS"
    assert "40 x 30 x 20 mm on a" in by["print.bed_fit"]["detail"] and "built parts" in by["print.bed_fit"]["detail"]
    # a wall under one line does not print at all: FAIL, said so
    d3 = tmp_path / "thin"
    d3.mkdir()
    (d3 / "manifest.json").write_text(json.dumps({"parts": [_printed("lid", 0.0, walls=[(0.61, 0.9), (0.3, 0.9)])]}))
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(d3), "--json", str(out_json)]) == 1
    tw = {f["rule_id"]: f for f in json.loads(out_json.read_text())["findings"]}["print.thin_walls"]
    assert tw["severity"] == "FAIL" and tw["value"] == 2 and "1 too thin to print at all" in tw["detail"]
    # without a build the print rules say what they need
    assert main(["check", str(DEFAULT_DESIGN), "--json", str(out_json)]) == 1
    by = {f["rule_id"]: f for f in json.loads(out_json.read_text())["findings"]}
    assert all(by[k]["severity"] == "NOT_EVALUATED" and "--build" in by[k]["detail"]
               for k in ("print.support", "print.thin_walls", "print.bridges", "print.bores"))
    # a clean build passes the walls and bridges
    d2 = tmp_path / "clean"
    d2.mkdir()
    (d2 / "manifest.json").write_text(json.dumps({"parts": [_printed("lid", 0.0)]}))
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(d2), "--json", str(out_json)]) == 1
    by = {f["rule_id"]: f for f in json.loads(out_json.read_text())["findings"]}
    assert by["print.thin_walls"]["severity"] == by["print.bridges"]["severity"] == by["print.bores"]["severity"] == "PASS"
    assert by["float.upright"]["severity"] == "NOT_EVALUATED"      # that folder has no mass properties


def test_a_bad_build_folder_exits_2_naming_what_is_wrong(tmp_path, capsys):
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(tmp_path / "nope")]) == 2
    assert "not a folder; expected a build folder" in capsys.readouterr().err
    (tmp_path / "empty").mkdir()
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(tmp_path / "empty")]) == 2
    assert "no manifest.json in it" in capsys.readouterr().err
    bad = _printed("bracket", -4.0, walls=[(0.6, "thin")])
    bad["print"]["supported_bores"] = [{"fastener": "s", "what": "pilot", "diameter_mm": 0}]
    d = _build_folder(tmp_path, [bad])
    assert main(["check", str(DEFAULT_DESIGN), "--build", d]) == 2
    err = capsys.readouterr().err
    assert "problem(s) in the build's manifest" in err
    assert "parts[bracket].print.support_area_mm2 = -4.0" in err
    assert "parts[bracket].print.thin_walls[0].limit_mm = 'thin'" in err and "Traceback" not in err
    assert "parts[bracket].print.supported_bores[0]" in err
    old = tmp_path / "old"
    old.mkdir()
    (old / "manifest.json").write_text(json.dumps({"parts": [{"label": "lid", "printed": True,
                                                               "print_size_mm": [1, 2, 3]}]}))
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(old)]) == 2
    assert "rebuild with `swiftfin build --out" in capsys.readouterr().err
    (old / "manifest.json").write_text("[1, 2")
    assert main(["check", str(DEFAULT_DESIGN), "--build", str(old)]) == 2
    assert "not readable JSON" in capsys.readouterr().err
