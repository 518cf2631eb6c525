"""Parameter file: schema, defaults, and bad input (one clear message per problem, exit code 2)."""
from __future__ import annotations

import subprocess
import sys

import pytest

from swiftfin.cli import main
from swiftfin.layout.design import load_design
from swiftfin.core.params import ParamError, dump_toml, params_from_dict, to_dict
from swiftfin.core.schema import Params
from tests.conftest import DEFAULT_DESIGN


def test_default_file_is_the_schema_default():
    assert DEFAULT_DESIGN.read_text() == dump_toml(), "regenerate with `swiftfin params --dump > swiftfin.toml`"
    assert load_design(DEFAULT_DESIGN) == Params()


def test_paper_values_in_default():
    p = Params()
    assert p.body.length_mm == 520 and p.body.naca_thickness_fraction == 0.15
    assert p.joints.count == 4 and p.joints.tendon_moment_arm_mm == 15
    assert p.motor.holding_torque_nm == 0.42 and p.motor.microsteps == 16
    assert p.spool.drum_diameter_mm == 20 and p.spool.wraps == 2
    assert p.cable.diameter_mm == 1.0
    assert p.swimming.tail_beat_frequency_hz == 3 and p.swimming.tail_amplitude_m == 0.10
    assert p.swimming.wavelength_body_lengths == 1.25


def test_roundtrip_dict():
    p = Params()
    assert params_from_dict(to_dict(p)) == p


def _write(tmp_path, text):
    f = tmp_path / "design.toml"
    f.write_text(text)
    return f


BAD_FILES = [
    ("[spool]\ndiamter_mm = 20\n", ["spool.diamter_mm", "did you mean 'drum_diameter_mm'"]),
    ("[spool]\ndrum_diameter_mm = -20\n", ["spool.drum_diameter_mm = -20", "allowed [4, 100]"]),
    ("[cable]\ndiameter_mm = 1.5\n", ["spool.groove_pitch_mm", "thicker than its groove"]),
    ("[print]\nclearance_sliding_mm = 1.2\n", ["spool.groove_pitch_mm", "2.2 mm wide", "pitch >= 2.4 mm"]),
    ("[spool]\ndrum_diameter_mm = 6\n", ["spool.drum_diameter_mm = 6.0", "too small for the motor shaft"]),
    ("[guides]\nptfe_tube_id_mm = 0.8\n", ["guides.ptfe_tube_id_mm", "cable hole smaller than the cable"]),
    ("[joints]\ncount = 3\n", ["joints.stations_fraction", "expected 3 stations"]),
    ("[joints]\nstations_fraction = [0.6, 0.55, 0.7, 0.75]\n", ["strictly increasing"]),
    ("[joints]\ncount = 'four'\n", ["joints.count = 'four'", "expected an integer"]),
    ("[motor]\nmicrosteps = 12\n", ["motor.microsteps = 12", "expected one of"]),
    ("[hull]\nsplit_halves = 1\n", ["hull.split_halves = 1", "expected true or false"]),
    ("[hull]\nflooded_from_joint = 7\n", ["hull.flooded_from_joint = 7", "or 5 for a hull sealed throughout"]),
    ("[hull]\nflooded_from_joint = 2\n", ["hull.flooded_from_joint = 2", "only the head can be sealed"]),
    ("[environment]\ntrim_ballast = 'yes'\n", ["environment.trim_ballast = 'yes'", "expected true or false"]),
    ("[bodyy]\nlength_mm = 520\n", ["bodyy", "did you mean 'body'"]),
    ("[cable]\npretension_n = 400\n", ["cable.pretension_n = 400", "below cable.breaking_strength_n"]),
    ("[body]\nlength_mm = 'long'\n", ["body.length_mm = 'long'", "expected a number"]),
    ("[body]\nlength_mm = nan\n", ["body.length_mm = nan", "finite"]),
    ("[joints]\ntendon_moment_arm_mm = 30\n", ["tendon sector of joint", "does not fit in the hull"]),
    ("[joints]\nstations_fraction = [0.30, 0.62, 0.695, 0.765]\n", ["motor for joint", "does not fit"]),
    ("[spool\n", ["not valid TOML"]),
    ("[[components]]\nname = 'x'\n", ["components[0].mass_kg", "required"]),
    ("[rules]\nstrouhal_min = 0.4\n", ["rules.strouhal_min = 0.4", "below rules.strouhal_max"]),
    ("[joints]\ncount = 2\nstations_fraction = [0.58, 0.72]\n", ["joints.tendon_moment_arm_mm",
                                                                  "tendon groove cannot wrap its stop angle"]),
    # a seeded sweep drew a 4.5 mm arm: the anchor hole lay outside the groove and the link's cut came out empty
    ("[joints]\ntendon_moment_arm_mm = 4.5\n", ["joints.tendon_moment_arm_mm = 4.5", "anchor does not fit inside",
                                                 "a moment arm of at least"]),
]


@pytest.mark.parametrize("text,expected", BAD_FILES, ids=[b[0].split("\n")[0] + b[0].split("\n")[1][:12] for b in BAD_FILES])
def test_bad_file_message(tmp_path, capsys, text, expected):
    f = _write(tmp_path, text)
    with pytest.raises(ParamError) as err:
        load_design(f)
    msg = str(err.value)
    assert str(f) in msg
    for piece in expected:
        assert piece in msg
    assert main(["params", str(f)]) == 2
    out = capsys.readouterr()
    assert "Traceback" not in out.err and str(f) in out.err


def test_all_problems_reported_together(tmp_path):
    f = _write(tmp_path, "[spool]\ndiamter_mm = 1\nwraps = -1\n[cable]\ndiameter_mm = 'x'\n")
    with pytest.raises(ParamError) as err:
        load_design(f)
    assert len(err.value.problems) == 3


def test_missing_file(tmp_path):
    with pytest.raises(ParamError, match="parameter file not found"):
        load_design(tmp_path / "nope.toml")


def test_cli_no_traceback_subprocess(tmp_path):
    f = _write(tmp_path, "[spool]\ndrum_diameter_mm = -1\n")
    r = subprocess.run([sys.executable, "-m", "swiftfin.cli", "params", str(f)], capture_output=True, text=True)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "spool.drum_diameter_mm = -1" in r.stderr
