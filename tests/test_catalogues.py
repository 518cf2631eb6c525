"""The motor and cable catalogues: every number has a source, the entries fit the schema's ranges, the default
design's motor and cable are entries of them, and a malformed table is refused with every problem named."""
from __future__ import annotations

from dataclasses import fields

import pytest

from swiftfin.catalogues import cables as cables_mod
from swiftfin.catalogues import motors as motors_mod
from swiftfin.catalogues.cables import cable_params, cable_spec, cables
from swiftfin.catalogues.motors import motor, motor_params, motors
from swiftfin.core.params import ParamError, params_from_dict, to_dict
from swiftfin.core.schema import Cable, Motor, Params


def _meta(cls, name: str) -> dict:
    return next(f.metadata for f in fields(cls) if f.name == name)


def test_every_number_has_a_source():
    from swiftfin.catalogues.motors import PARAM_KEYS
    for m in motors():
        for k in PARAM_KEYS:
            assert getattr(m, k) is None or m.sources.get(k), (m.name, k)
        assert m.maker
    for c in cables():
        for k in list(c.params()) + [f for f in ("fibre_tensile_modulus_gpa", "fibre_tenacity_n_tex",
                                                  "fibre_tensile_strength_gpa") if getattr(c, f) is not None]:
            assert c.sources.get(k), (c.name, k)


def test_the_catalogues_hold_what_issue_16_asks():
    assert {"17HS4401", "17HS19-2004S1", "23HS22-2804S", "17HS15-1684S-PG5"} <= set(motors_mod.motor_names())
    assert motor("17HS15-1684S-PG5").gear_ratio == pytest.approx(5.18)          # the geared NEMA 17
    assert motor("23HS22-2804S").frame_size_mm == 57.0                          # a NEMA 23
    assert {"braided nylon 1 mm", "Dyneema SK75", "Vectran HT", "7x7 stainless 1/16 in"} <= set(
        cables_mod.cable_names())


def test_values_fit_the_schema_ranges():
    for m in motors():
        for k, v in m.params().items():
            meta = _meta(Motor, k)
            assert meta["lo"] <= v <= meta["hi"], (m.name, k, v)
    materials = _meta(Cable, "material")["choices"]
    for c in cables():
        assert c.material in materials, c.name
        for k, v in c.params().items():
            if k == "material":
                continue
            meta = _meta(Cable, k)
            assert meta["lo"] <= v <= meta["hi"], (c.name, k, v)


def test_the_default_design_is_the_17hs4401_on_braided_nylon():
    """Every number of the entry but the current: the paper holds its 17HS4401 at 1.5 A, not the rated 1.7 A (and
    still counts the rated 0.42 N m: see the README)."""
    p = Params()
    for k, v in motor_params("17HS4401").items():
        if k != "phase_current_a":
            assert getattr(p.motor, k) == pytest.approx(v), k
    assert motor_params("17HS4401")["phase_current_a"] == 1.7 and p.motor.phase_current_a == 1.5
    for k, v in cable_params("braided nylon 1 mm").items():
        assert getattr(p.cable, k) == v, k


def test_a_design_names_a_catalogue_motor_and_cable():
    """``motor.model`` / ``cable.model`` fill the keys the file leaves out with the entry's numbers; the keys the
    entry does not hold keep the schema's defaults; a key given beside the model that agrees is accepted."""
    p = params_from_dict({"motor": {"model": "17HS19-2004S1"}, "cable": {"model": "braided nylon 1 mm"}})
    assert p.motor.model == "17HS19-2004S1"
    for k, v in motor_params("17HS19-2004S1").items():
        assert getattr(p.motor, k) == v, k
    assert p.motor.holding_torque_nm == 0.59 and p.motor.body_length_mm == 48.0
    assert p.motor.shaft_diameter_mm == Motor().shaft_diameter_mm          # not in the entry: the default
    p2 = params_from_dict({"motor": {"model": "17HS19-2004S1", "holding_torque_nm": 0.59}})
    assert p2.motor == p.motor
    # the dumped design reads back the same (every key explicit, each agreeing with the entry)
    assert params_from_dict(to_dict(p)) == p


def test_a_key_that_contradicts_its_model_is_refused_with_both_numbers():
    with pytest.raises(ParamError) as err:
        params_from_dict({"motor": {"model": "17HS19-2004S1", "holding_torque_nm": 0.42, "body_length_mm": 40.0}})
    msg = str(err.value)
    assert "motor.holding_torque_nm = 0.42" in msg and "gives 0.59" in msg and "'custom'" in msg
    assert "motor.body_length_mm = 40" in msg and "gives 48.0" in msg


def test_a_fibre_only_cable_asks_for_the_cable_numbers():
    with pytest.raises(ParamError) as err:
        params_from_dict({"cable": {"model": "Dyneema SK75"}})
    msg = str(err.value)
    for k in ("cable.diameter_mm", "cable.breaking_strength_n", "cable.youngs_modulus_gpa"):
        assert f"{k} = (missing)" in msg
    p = params_from_dict({"cable": {"model": "Dyneema SK75", "diameter_mm": 1.0, "breaking_strength_n": 1000.0,
                                    "youngs_modulus_gpa": 40.0}})
    assert p.cable.material == "dyneema"


def test_an_unknown_model_is_refused_with_the_names_on_offer(tmp_path):
    with pytest.raises(ParamError) as err:
        params_from_dict({"motor": {"model": "17HS4402"}})
    msg = str(err.value)
    assert "motor.model" in msg and "17HS4401" in msg and "custom" in msg


def test_the_command_line_refuses_a_contradiction_with_exit_2(tmp_path):
    import subprocess
    import sys
    f = tmp_path / "d.toml"
    f.write_text('[motor]\nmodel = "17HS19-2004S1"\nholding_torque_nm = 0.42\n', encoding="utf-8")
    before = f.read_bytes()
    r = subprocess.run([sys.executable, "-m", "swiftfin", "params", str(f)], capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "motor.holding_torque_nm = 0.42" in r.stderr and "gives 0.59" in r.stderr
    assert f.read_bytes() == before


def test_fibre_entries_say_what_a_design_must_still_give():
    assert cable_spec("braided nylon 1 mm").missing() == ()
    assert set(cable_spec("Dyneema SK75").missing()) == {"diameter_mm", "breaking_strength_n", "youngs_modulus_gpa"}
    lo, hi = cable_spec("Dyneema SK75").fibre_tensile_modulus_gpa
    assert 100 < lo <= hi < 140


def test_unknown_names_list_the_catalogue():
    with pytest.raises(KeyError, match="17HS4401"):
        motor("17HS9999")
    with pytest.raises(KeyError, match="braided nylon 1 mm"):
        cable_spec("hemp")


def test_a_malformed_table_is_refused_with_every_problem(tmp_path, monkeypatch):
    (tmp_path / "motors.toml").write_text(
        '["X1"]\nmaker = "x"\nholding_torque_nm = 0.4\nframe_size_mm = -1.0\nwidth_mm = 3.0\n'
        '["X1".sources]\nframe_size_mm = "a sheet"\n', encoding="utf-8")
    (tmp_path / "cables.toml").write_text(
        '["C1"]\nmaterial = "steel"\nbreaking_strength_n = 100.0\nfibre_tenacity_n_tex = [3.0, 2.0]\n'
        '["C1".sources]\n', encoding="utf-8")
    monkeypatch.setattr(motors_mod, "HERE", tmp_path)
    monkeypatch.setattr(cables_mod, "HERE", tmp_path)
    motors_mod.motors.cache_clear()
    cables_mod.cables.cache_clear()
    try:
        with pytest.raises(ValueError) as err:
            motors_mod.motors()
        msg = str(err.value)
        assert "holding_torque_nm has no source" in msg and "frame_size_mm = -1.0" in msg and "width_mm" in msg
        with pytest.raises(ValueError) as err:
            cables_mod.cables()
        msg = str(err.value)
        assert "breaking_strength_n has no source" in msg and "fibre_tenacity_n_tex" in msg
    finally:
        motors_mod.motors.cache_clear()
        cables_mod.cables.cache_clear()
