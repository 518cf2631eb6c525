"""``swiftfin synth`` then ``swiftfin fit`` end to end: the report's fields, plots and held-out options."""
from __future__ import annotations

import json

import pytest

from swiftfin.cli import main
from tests.conftest import DEFAULT_DESIGN, require_shared

D = ["--design", str(DEFAULT_DESIGN)]


def synth(path, *effects, seed=0, duration=20):
    args = ["synth", "joint", "--out", str(path), "--seed", str(seed), "--duration", str(duration), *D]
    for e in effects:
        args += ["--effect", e]
    assert main(args) == 0


@pytest.fixture(scope="module")
def delay_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fit")
    synth(tmp / "run.csv", "sensor_delay=0.015", seed=1)
    code = main(["fit", "joint", str(tmp / "run.csv"), "--out", str(tmp / "out"), *D])
    assert code == 0
    return tmp, json.loads((tmp / "out" / "fit_report.json").read_text())


def test_report_fields(delay_run):
    _, rep = delay_run
    assert rep["family"] == "joint"
    assert rep["n_samples"] == 20000
    assert set(rep["baseline"]) >= {"terms", "rmse_train", "rmse_holdout"}
    assert [e["name"] for e in rep["added_effects"]] == ["sensor_delay"]
    e = rep["added_effects"][0]
    assert e["params"]["delay_s"]["value"] == pytest.approx(0.015, rel=0.08)
    assert e["params"]["delay_s"]["std"] > 0 and e["params"]["delay_s"]["unit"] == "s"
    assert e["rmse_holdout_after"] < 0.3 * e["rmse_holdout_before"]
    assert e["rmse_holdout_before"] == pytest.approx(rep["baseline"]["rmse_holdout"])
    assert {"relative_drop", "p_value"} <= set(e["evidence"])
    assert set(rep["final"]) >= {"rmse_train", "rmse_holdout", "residual_white"}
    assert rep["final"]["rmse_holdout"] == pytest.approx(e["rmse_holdout_after"])
    assert rep["unexplained_structure"] is False
    assert rep["units"]["target"] == "rad"
    assert "contiguous time blocks" in rep["holdout"]


def test_report_files(delay_run):
    tmp, rep = delay_run
    out = tmp / "out"
    for f in ("fit_report.md", "measured_vs_model.png", "residual_spectrum.png", "residual_vs_sensor_delay.png"):
        assert (out / f).stat().st_size > 1000, f
    assert (out / "measured_vs_model.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    md = (out / "fit_report.md").read_text()
    assert "sensor_delay" in md and "residual_vs_sensor_delay.png" in md and "delay_s" in md


def test_holdout_file(tmp_path):
    synth(tmp_path / "a.csv", "effective_radius=1.04", seed=2)
    synth(tmp_path / "b.csv", "effective_radius=1.04", seed=3)
    code = main(["fit", "joint", str(tmp_path / "a.csv"), "--holdout", str(tmp_path / "b.csv"),
                 "--out", str(tmp_path / "o"), "--no-plots", *D])
    assert code == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    assert rep["n_train"] == 20000 and rep["n_holdout"] == 20000
    assert rep["added_effects"][0]["name"] == "effective_radius"
    v = rep["added_effects"][0]["params"]["ratio_error"]
    assert abs(v["value"] - 0.04) < 3 * v["std"] + 1e-4
    assert "separate run" in rep["holdout"]


def test_holdout_fraction_and_outside_library(tmp_path, capsys):
    synth(tmp_path / "c.csv", "cogging=0.15", seed=4)
    code = main(["fit", "joint", str(tmp_path / "c.csv"), "--holdout", "0.5", "--out", str(tmp_path / "o"),
                 "--no-plots", *D])
    out = capsys.readouterr().out
    assert code == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    assert rep["n_holdout"] == pytest.approx(10000, rel=0.02)
    assert rep["unexplained_structure"] is True
    assert "unexplained structure" in out
    assert "Unexplained structure" in (tmp_path / "o" / "fit_report.md").read_text()


def test_bad_holdout_fraction(tmp_path, capsys):
    synth(tmp_path / "d.csv", seed=5, duration=5)
    code = main(["fit", "joint", str(tmp_path / "d.csv"), "--holdout", "2", *D])
    assert code == 2 and "strictly between 0 and 1" in capsys.readouterr().err


def test_joint_option_checked(tmp_path, capsys):
    synth(tmp_path / "e.csv", seed=6, duration=5)
    code = main(["fit", "joint", str(tmp_path / "e.csv"), "--joint", "9", *D])
    assert code == 2 and "--joint 9" in capsys.readouterr().err


# ------------------------------------------------------------------------------ body family from the CLI

FISH = ("data", "fishsim")


def test_body_within_file_from_cli(tmp_path, capsys):
    """`swiftfin fit body markers_f1_75.csv` goes through the engine with the body family's own criterion and
    reports what the family finds: held-out RMSE 53.0 mm (paper wave) -> 8.5 mm; the tail beats at 0.75 x the
    drive frequency; the time plot shows the tail tip (marker 8), not the motionless marker 2."""
    path = require_shared(*FISH, "markers_f1_75.csv")
    assert main(["fit", "body", str(path), "--out", str(tmp_path / "o")]) == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    names = [e["name"] for e in rep["added_effects"]]
    assert names[0] == "tail_beat_frequency" and {"lateral_offset", "head_yaw"} <= set(names)
    assert rep["added_effects"][0]["params"]["ratio"]["value"] == pytest.approx(0.75, abs=0.01)
    assert rep["baseline"]["rmse_holdout"] == pytest.approx(0.0530, abs=0.002)
    assert rep["final"]["rmse_holdout"] == pytest.approx(0.0085, abs=0.001)
    assert rep["criterion"]["alpha"] == 0.01 and rep["criterion"]["min_relative_drop"] == 0.03
    assert rep["units"]["target"] == "m"
    assert "markers_f1_75.csv" in capsys.readouterr().err        # the cleaning report, as a warning


def test_body_plot_shows_the_tail_tip():
    from swiftfin.calibration.body import FAMILY, load
    from swiftfin.calibration.engine import Calibrator
    from swiftfin.calibration.report import _holdout_view, _shown_rows
    cal = Calibrator(FAMILY, max_effects=1).fit(load(require_shared(*FISH, "markers_f2_25.csv")))
    ctx, hold = _holdout_view(cal)
    rows = _shown_rows(cal, ctx, hold)
    assert rows.any() and set(ctx.signals["marker"][rows]) == {8.0}


def test_body_across_files_from_cli(tmp_path):
    """DATA a folder, --holdout one of its files: fit on the five other drive frequencies, predict 2.25 Hz.
    Measured: paper wave 42.3 mm -> 16.0 mm on the held-out video; the beat ratio is found first."""
    folder = require_shared(*FISH, "markers_f2_25.csv").parent
    code = main(["fit", "body", str(folder), "--holdout", str(folder / "markers_f2_25.csv"),
                 "--out", str(tmp_path / "o"), "--no-plots"])
    assert code == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    assert "separate run" in rep["holdout"] and "markers_f2_25" in rep["holdout"]
    assert "markers_f2_25" not in rep["data"] and rep["data"].count("markers_f") == 5
    assert rep["added_effects"][0]["name"] == "tail_beat_frequency"
    assert rep["baseline"]["rmse_holdout"] == pytest.approx(0.0423, abs=0.002)
    assert rep["final"]["rmse_holdout"] == pytest.approx(0.0160, abs=0.0015)


# ------------------------------------------------------------------------------ drive units follow the columns

def test_rotary_drive_units_follow_the_columns(tmp_path):
    from tests.test_calib_drive import _force, _trajectory, _write
    t, q, v, a = _trajectory(seconds=20.0)
    path = _write(tmp_path / "r.csv", t, q, _force(t, q, v, a, effects=("viscous", "coulomb")), rotary=True)
    assert main(["fit", "drive", str(path), "--out", str(tmp_path / "o"), "--no-plots"]) == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    assert rep["units"]["target"] == "N m" and rep["units"]["position"] == "rad"
    assert rep["units"]["velocity"] == "rad/s"
    assert "inertia_kg_m2" in rep["baseline"]["coef_final"]
    params = {k: p for e in rep["added_effects"] for k, p in e["params"].items()}
    assert params["Fv_nm_s_rad"]["unit"] == "N m s/rad" and params["Fc_nm"]["unit"] == "N m"
    assert params["Fv_nm_s_rad"]["value"] == pytest.approx(150.0, rel=0.05)
    assert "N s/m" not in json.dumps(rep["added_effects"])


# ------------------------------------------------------------------------------ bad input: one message, exit 2

@pytest.fixture(scope="module")
def short_log(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("bad")
    synth(tmp / "a.csv", seed=7, duration=5)
    synth(tmp / "b.csv", seed=8, duration=5)
    (tmp / "empty").mkdir()
    return tmp


BAD = [
    (["fit", "wing", "{a}"], "unknown family 'wing'"),
    (["fit", "joint", "{tmp}/nope.csv"], "nope.csv"),
    (["fit", "joint", "{a}", "{b}"], "reads one log per run"),
    (["fit", "joint", "{tmp}/empty"], "reads one log per run"),
    (["fit", "body", "{tmp}/empty"], "folder holds no CSV file"),
    (["fit", "joint", "{a}", "--holdout", "2"], "strictly between 0 and 1"),
    (["fit", "joint", "{a}", "--holdout", "{tmp}/missing.csv"], "missing.csv: file not found"),
    (["fit", "joint", "{a}", "--holdout", "{a}"], "also given as DATA"),
    (["fit", "body", "{a}", "--holdout", "0.3", "{b}"], "either one fraction or held-out files"),
    (["fit", "joint", "{a}", "--alpha", "0"], "--alpha 0: a significance level"),
    (["fit", "joint", "{a}", "--alpha", "1.5"], "--alpha 1.5"),
    (["fit", "joint", "{a}", "--min-drop", "1"], "--min-drop 1: a relative drop"),
    (["fit", "joint", "{a}", "--min-drop", "-0.1"], "--min-drop -0.1"),
    (["fit", "joint", "{a}", "--max-effects", "-1"], "--max-effects -1"),
    (["fit", "drive", "{a}", "--joint", "1"], "--joint applies to the joint family only"),
    (["fit", "joint", "{a}", "--joint", "9"], "--joint 9"),
    (["fit", "drive", "{a}"], "position"),                   # a joint log is not a drive log: column named
]


@pytest.mark.parametrize("argv,message", BAD, ids=[" ".join(a[1:]) for a, _ in BAD])
def test_bad_input_one_message_exit_2(short_log, tmp_path, capsys, argv, message):
    args = [x.format(a=short_log / "a.csv", b=short_log / "b.csv", tmp=short_log) for x in argv]
    code = main(args + ["--out", str(tmp_path / "o"), *D])
    cap = capsys.readouterr()
    assert code == 2, cap
    err = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert len(err) == 1 and err[0].startswith("swiftfin fit: error:"), cap.err
    assert message in err[0], err[0]
    assert "Traceback" not in cap.err and not (tmp_path / "o" / "fit_report.json").exists()


def test_a_heavier_links_inertia_is_not_taken_for_a_hinge_spring(tmp_path):
    """The load cell's tension follows the joint angle through the link's inertia (J theta'' / 2 d, which a motion
    that rings back and forth makes look like a negative spring). On a design with 1.6-deep sections (its tail link
    1 % heavier) the effective-radius error was refused as "a spring at the hinge" and nothing was named; with the
    acceleration as a nuisance term of the tension's regression it is named and fitted to the noise floor."""
    text = DEFAULT_DESIGN.read_text().replace("height_to_width = 1.5", "height_to_width = 1.6")
    assert "height_to_width = 1.6" in text
    design = tmp_path / "deep.toml"
    design.write_text(text)
    d = ["--design", str(design)]
    for name, seed in (("a.csv", 2), ("b.csv", 3)):
        assert main(["synth", "joint", "--out", str(tmp_path / name), "--seed", str(seed), "--duration", "20",
                     "--effect", "effective_radius=1.04", *d]) == 0
    assert main(["fit", "joint", str(tmp_path / "a.csv"), "--holdout", str(tmp_path / "b.csv"),
                 "--out", str(tmp_path / "o"), "--no-plots", *d]) == 0
    rep = json.loads((tmp_path / "o" / "fit_report.json").read_text())
    assert [e["name"] for e in rep["added_effects"]] == ["effective_radius"]
    v = rep["added_effects"][0]["params"]["ratio_error"]
    assert abs(v["value"] - 0.04) < 3 * v["std"] + 1e-4
