"""``swiftfin synth`` then ``swiftfin fit`` end to end: the report's fields, plots and held-out options."""
from __future__ import annotations

import json

import pytest

from swiftfin.cli import main
from tests.conftest import DEFAULT_DESIGN

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
