"""Bad measured logs are refused with the file, the column and the row named (exit 2); short NaN gaps are filled
with a warning; no fit is reported on data that cannot support one."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from swiftfin.calibration.io import Column, read_log, split_holdout_arg
from swiftfin.cli import main
from swiftfin.core.errors import UserError
from tests.conftest import DEFAULT_DESIGN

HEADER = "time_s,motor_angle_rad,joint_angle_rad"


@pytest.fixture(scope="module")
def good_rows(default_params):
    from swiftfin.calibration.joint import joint_design
    from swiftfin.calibration.synth import simulate_joint
    log = simulate_joint(joint_design(default_params), {}, duration_s=6.0, seed=2)
    return np.column_stack([log.t, log.motor_angle_rad, log.joint_angle_rad])


def write(path, rows, header=HEADER, extra=None):
    lines = [header]
    for r in rows:
        lines.append(",".join("" if (isinstance(v, float) and math.isnan(v)) else repr(float(v)) if not isinstance(v, str)
                              else v for v in r))
    path.write_text("\n".join(lines) + "\n")
    return path


def fit(path, tmp_path, capsys, *extra):
    code = main(["fit", "joint", str(path), "--design", str(DEFAULT_DESIGN), "--out", str(tmp_path / "out"),
                 "--no-plots", *extra])
    return code, capsys.readouterr()


def test_good_log_reads(tmp_path, good_rows):
    p = write(tmp_path / "ok.csv", good_rows)
    log = read_log(p, (Column("time_s", "s", "time"), Column("joint_angle_rad", "rad", "angle", math.pi / 2)))
    assert log.n == len(good_rows)
    assert np.allclose(log["joint_angle_rad"], good_rows[:, 2])
    assert log.notes == []


def test_extra_columns_ignored(tmp_path, good_rows):
    rows = np.column_stack([good_rows, np.arange(len(good_rows))])
    p = write(tmp_path / "extra.csv", rows, header=HEADER + ",temperature_c")
    log = read_log(p, (Column("time_s", "s", "time"), Column("motor_angle_rad", "rad")))
    assert set(log.columns) == {"time_s", "motor_angle_rad"}


def test_misnamed_column_suggests_closest(tmp_path, good_rows, capsys):
    p = write(tmp_path / "bad.csv", good_rows, header="time_s,motor_angle_rad,joint_angle_deg")
    code, io = fit(p, tmp_path, capsys)
    assert code == 2
    assert "bad.csv" in io.err and "missing column 'joint_angle_rad'" in io.err
    assert "did you mean 'joint_angle_deg'" in io.err
    assert "Traceback" not in io.err
    assert not (tmp_path / "out" / "fit_report.json").exists()


def test_missing_column(tmp_path, good_rows, capsys):
    p = write(tmp_path / "two.csv", good_rows[:, :2], header="time_s,motor_angle_rad")
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "missing column 'joint_angle_rad'" in io.err


def test_duplicated_time_names_row(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[100, 0] = rows[99, 0]
    p = write(tmp_path / "dup.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2
    # data index 99 -> spreadsheet row 101 (header is row 1)
    assert "duplicated time stamp" in io.err and "rows 101 and 102" in io.err and "'time_s'" in io.err


def test_time_backwards_names_row(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[200, 0] = rows[198, 0] - 0.5
    p = write(tmp_path / "back.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "time goes backwards at row 202" in io.err


def test_short_nan_gap_filled_with_warning(tmp_path, good_rows):
    rows = good_rows.copy()
    rows[300:304, 2] = np.nan
    p = write(tmp_path / "gap.csv", rows)
    log = read_log(p, (Column("time_s", "s", "time"), Column("joint_angle_rad", "rad", "angle", math.pi / 2)))
    assert len(log.notes) == 1
    assert "rows 302-305" in log.notes[0] and "linear interpolation" in log.notes[0] and "gap.csv" in log.notes[0]
    # interpolated values lie on the line between the neighbours
    t = good_rows[:, 0]
    expect = np.interp(t[300:304], t[[299, 304]], good_rows[[299, 304], 2])
    assert np.allclose(log["joint_angle_rad"][300:304], expect, atol=1e-12)


def test_short_gap_warning_reaches_cli(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[1000:1003, 2] = np.nan
    p = write(tmp_path / "gap.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 0
    assert "warning" in io.err and "rows 1002-1004" in io.err
    rep = json.loads((tmp_path / "out" / "fit_report.json").read_text())
    assert any("rows 1002-1004" in n for n in rep["notes"])


def test_long_nan_gap_refused(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[500:560, 1] = np.nan
    p = write(tmp_path / "long.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2
    assert "'motor_angle_rad'" in io.err and "rows 502-561" in io.err and "too long" in io.err


def test_degrees_in_rad_column(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[:, 2] = np.degrees(rows[:, 2])
    p = write(tmp_path / "deg.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "'joint_angle_rad'" in io.err and "looks like degrees" in io.err and "row " in io.err


def test_small_degrees_caught_by_ratio(tmp_path, good_rows, capsys):
    """Degrees that stay within +-pi/2 (a small swing) are caught by comparing with the rigid capstan."""
    rows = good_rows.copy()
    rows[:, 1] *= 0.06            # small swing: max |joint| in degrees stays below pi/2
    rows[:, 2] = np.degrees(rows[:, 2] * 0.06)
    assert np.max(np.abs(rows[:, 2])) < math.pi / 2
    p = write(tmp_path / "deg2.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "looks like degrees" in io.err


def test_non_numeric_cell(tmp_path, good_rows, capsys):
    rows = good_rows.astype(object)
    rows[40, 1] = "12,5"  # a decimal comma splits the row; make it a clearly bad cell instead
    rows[40, 1] = "abc"
    p = write(tmp_path / "txt.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "'motor_angle_rad' row 42: 'abc' is not a number" in io.err


def test_too_short(tmp_path, good_rows, capsys):
    p = write(tmp_path / "short.csv", good_rows[:30])
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "short.csv" in io.err and "too short" in io.err


def test_too_short_in_time(tmp_path, good_rows, capsys):
    p = write(tmp_path / "short2.csv", good_rows[:1500])
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "'time_s' spans 1.5 s" in io.err


def test_poorly_excited(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[:, 1] = 0.003 * np.sin(rows[:, 0])       # 1.5 microsteps of motion
    rows[:, 2] = rows[:, 1] * 2 / 3
    p = write(tmp_path / "still.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "'motor_angle_rad'" in io.err and "poorly excited" in io.err
    assert not (tmp_path / "out").exists()


def test_joint_not_following(tmp_path, good_rows, capsys):
    rows = good_rows.copy()
    rows[:, 2] = 0.001 * np.sin(rows[:, 0])
    p = write(tmp_path / "loose.csv", rows)
    code, io = fit(p, tmp_path, capsys)
    assert code == 2 and "'joint_angle_rad'" in io.err and "does not follow" in io.err


def test_missing_file_and_empty(tmp_path, capsys):
    code, io = fit(tmp_path / "nope.csv", tmp_path, capsys)
    assert code == 2 and "nope.csv: file not found" in io.err
    (tmp_path / "empty.csv").write_text("")
    code, io = fit(tmp_path / "empty.csv", tmp_path, capsys)
    assert code == 2 and "empty file" in io.err


def test_holdout_argument():
    assert split_holdout_arg(None) == (None, 0.3)
    assert split_holdout_arg("0.25") == (None, 0.25)
    assert split_holdout_arg("run2.csv") == ("run2.csv", None)
    with pytest.raises(UserError, match="strictly between 0 and 1"):
        split_holdout_arg("1.5")


def test_unknown_family(tmp_path, capsys):
    code = main(["fit", "tail", "x.csv", "--design", str(DEFAULT_DESIGN)])
    assert code == 2 and "unknown family 'tail'" in capsys.readouterr().err


def test_optional_load_cell_column_is_checked_when_present(good_rows, tmp_path, capsys):
    """cable_tension_n is optional: absent, the fit runs without it; present with a bad cell, the message names
    the column and the row (exit 2)."""
    rows = [list(r) + [45.0] for r in good_rows]
    rows[7][3] = "heavy"
    path = write(tmp_path / "lc.csv", rows, header=HEADER + ",cable_tension_n")
    code, out = fit(path, tmp_path, capsys)
    assert code == 2
    assert "column 'cable_tension_n' row 9: 'heavy' is not a number" in out.err
    assert "Traceback" not in out.err
    log = read_log(write(tmp_path / "plain.csv", good_rows), [Column("time_s", "s", "time"),
                                                              Column("cable_tension_n", "N", optional=True)])
    assert "cable_tension_n" not in log.columns
