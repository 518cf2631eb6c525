"""Hostile data through ``swiftfin fit`` and ``swiftfin synth``: each input is refused with one message (exit 2)
naming what is wrong, never a traceback; nothing is written to ``--out`` and the input files are left untouched.

Bases, made once per module: a 3 s joint log from ``swiftfin synth``, an 8 s slice of the real EMPS estimation
run (as a drive CSV and as a small .mat with the real file's variable names), and one real fishsim marker file
(read from ../shared at test time, written to tmp_path). Each case derives one corruption from them.
"""
from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

from swiftfin.cli import main
from tests.conftest import DEFAULT_DESIGN, require_shared

D = ["--design", str(DEFAULT_DESIGN)]
N_DRIVE = 8000          # 8 s of EMPS at 1 kHz: enough to filter, differentiate, decimate, and two reversals


# ------------------------------------------------------------------------------------------------ bases

@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    import scipy.io as sio
    tmp = tmp_path_factory.mktemp("bases")
    assert main(["synth", "joint", "--out", str(tmp / "log.csv"), "--duration", "3", *D]) == 0
    header = (tmp / "log.csv").read_text().splitlines()[0].split(",")
    joint = np.loadtxt(tmp / "log.csv", delimiter=",", skiprows=1)
    emps = sio.loadmat(require_shared("data", "emps", "DATA_EMPS.mat"))
    mat = {k: emps[k][:N_DRIVE] for k in ("t", "qm", "qg", "vir")}
    mat.update({k: emps[k] for k in ("gtau", "kp", "kv")})
    drive = np.column_stack([mat["t"].ravel(), mat["qm"].ravel(), float(emps["gtau"].item()) * mat["vir"].ravel()])
    markers = require_shared("data", "fishsim", "markers_f1_00.csv").read_text()
    return {"joint_header": header, "joint": joint, "mat": mat, "drive": drive, "markers": markers}


# ------------------------------------------------------------------------------------------------ writers

def csv_text(header, data, fmt="%.9g") -> str:
    lines = [",".join(header)] + [",".join(fmt % v for v in row) for row in np.asarray(data, float)]
    return "\n".join(lines) + "\n"


def joint_file(b, tmp, fn=None, header=None, name="log.csv"):
    """The base joint log, columns changed by fn(dict of columns) (in place), written to tmp/name."""
    cols = {h: b["joint"][:, i].copy() for i, h in enumerate(b["joint_header"])}
    if fn:
        fn(cols)
    p = tmp / name
    p.write_text(csv_text(header or list(cols), np.column_stack(list(cols.values()))))
    return p


def joint_text(b, tmp, edit, name="log.csv"):
    """The base joint log as text lines, edited by edit(lines) -> lines."""
    lines = csv_text(b["joint_header"], b["joint"]).splitlines()
    p = tmp / name
    p.write_text("\n".join(edit(lines)) + "\n")
    return p


def drive_file(b, tmp, fn=None, header=("time_s", "position_m", "force_n"), n=N_DRIVE, name="drive.csv"):
    a = b["drive"][:n].copy()
    if fn:
        fn(a)
    p = tmp / name
    p.write_text(csv_text(header, a))
    return p


def mat_file(b, tmp, fn=None, name="DATA_EMPS.mat"):
    import scipy.io as sio
    d = {k: np.array(v, copy=True) for k, v in b["mat"].items()}
    if fn:
        fn(d)
    p = tmp / name
    sio.savemat(p, d)
    return p


def marker_file(b, tmp, name="markers_f1_00.csv", fn=None):
    text = b["markers"]
    if fn:
        text = fn(text)
    p = tmp / name
    p.write_text(text)
    return p


def _set(d, key, value):
    d[key] = value


def _cell(row, col, value):
    def edit(lines):
        parts = lines[row].split(",")
        parts[col] = value
        lines[row] = ",".join(parts)
        return lines
    return edit


def _still_markers(text):
    """The first frame repeated for every frame, with 0.3 px of tracking noise: a fish that does not swim."""
    rows = [r for r in text.splitlines() if r.strip()]
    first = np.array([float(v) for v in rows[0].split(",")])
    rng = np.random.default_rng(0)
    a = first[None, :] + 0.3 * rng.standard_normal((len(rows), first.size))
    return "\n".join(",".join(f"{v:.3f}" for v in r) for r in a) + "\n"


def _coinciding_heads(text):
    out = []
    for r in text.splitlines():
        v = r.split(",")
        v[2], v[3] = v[0], v[1]
        out.append(",".join(v))
    return "\n".join(out) + "\n"


def _nan_time(c):
    c["time_s"][100:103] = np.nan


def _dup_time(c):
    c["time_s"][500] = c["time_s"][499]


def _back_time(c):
    c["time_s"][800] = c["time_s"][700]


def _joint_gap(c):
    c["joint_angle_rad"][1000:1050] = np.nan


def _joint_start_nan(c):
    c["joint_angle_rad"][0] = np.nan


def _joint_copy(c):
    c["joint_angle_rad"][:] = c["motor_angle_rad"]


def _joint_near_copy(c):
    c["joint_angle_rad"][:] = c["motor_angle_rad"] + 1e-4 * np.random.default_rng(1).standard_normal(len(c["time_s"]))


def _scale(key, k):
    def fn(c):
        c[key] *= k
    return fn


def _const(key, v=0.1):
    def fn(c):
        c[key][:] = v
    return fn


def _mat_set(key, value):
    return lambda d: _set(d, key, value)


def _mat_backwards(d):
    d["t"] = d["t"].copy()
    d["t"][2000] = d["t"][1000]


def _mat_dup(d):
    d["t"] = d["t"].copy()
    d["t"][10] = d["t"][9]


def _mat_nan(key, i=100):
    def fn(d):
        d[key] = d[key].copy()
        d[key][i] = np.nan
    return fn


def _rows(n):
    return lambda lines: lines[: n + 1]


# ------------------------------------------------------------------------------------------------ the table
# (build(bases, tmp) -> argv without --out, command, expected exit code, substring of the message)

def fit(family, *files_and_options):
    return ["fit", family, *map(str, files_and_options)]


CASES = [
    # ---- joint CSV
    pytest.param(lambda b, t: fit("joint", t / "nope.csv"), 2, "file not found", id="joint-missing-file"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, lambda l: [""])), 2, "empty file", id="joint-empty"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, lambda l: l[:1])), 2, "0 data rows", id="joint-header-only"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, _rows(30))), 2, "too short", id="joint-30-rows"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, header=["time_s", "motor_angle_rad", "joint_angle",
                                                                     "cable_tension_n"])),
                 2, "did you mean 'joint_angle'", id="joint-misnamed-column"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, lambda l: [",".join(r.split(",")[:2]) for r in l])),
                 2, "missing column 'joint_angle_rad'", id="joint-missing-column"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, lambda l: [r.replace(",", ";") for r in l])),
                 2, "missing column 'time_s'", id="joint-semicolons"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, _cell(40, 2, "0,5"))), 2, "row 41",
                 id="joint-extra-cell-comma-decimal"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, _cell(40, 2, "abc"))), 2,
                 "row 41: 'abc' is not a number", id="joint-text-cell"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, _cell(40, 1, "inf"))), 2, "infinite value",
                 id="joint-inf-cell"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _nan_time)), 2, "missing time stamps at rows 102-104",
                 id="joint-nan-time"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _dup_time)), 2, "duplicated time stamp",
                 id="joint-duplicate-time"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _back_time)), 2, "time goes backwards at row 802",
                 id="joint-time-backwards"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _joint_gap)), 2, "too long to fill", id="joint-long-gap"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _joint_start_nan)), 2, "at the start/end",
                 id="joint-gap-at-start"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _scale("joint_angle_rad", 180 / math.pi))), 2,
                 "looks like degrees", id="joint-degrees"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _scale("motor_angle_rad", 180 / math.pi))), 2,
                 "looks like degrees", id="motor-degrees"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _scale("time_s", 1000.0))), 2,
                 "time in milliseconds", id="joint-time-ms"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _joint_copy)), 2,
                 "exact copy of column 'motor_angle_rad'", id="joint-copy-of-motor"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _joint_near_copy)), 2,
                 "equals column 'motor_angle_rad'", id="joint-near-copy-of-motor"),
    pytest.param(lambda b, t: fit("joint", joint_text(b, t, _rows(1500))), 2, "at least 2 s",
                 id="joint-1.5-s"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _const("motor_angle_rad"))), 2, "microsteps",
                 id="motor-still"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _const("joint_angle_rad"))), 2,
                 "does not follow its motor", id="joint-still"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _scale("joint_angle_rad", 0.1))), 2, "ratio 0.1",
                 id="joint-10x-small"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t, _scale("cable_tension_n", 1e4))), 2,
                 "beyond the plausible", id="tension-implausible"),
    pytest.param(lambda b, t: fit("joint", _binary(t / "log.csv")), 2, "not a text CSV", id="joint-binary"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--holdout", t / "log.csv"), 2, "also given as DATA",
                 id="holdout-is-data"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), joint_file(b, t, name="b.csv")), 2,
                 "reads one log per run", id="joint-two-files"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--joint", "99"), 2, "the design has joints",
                 id="joint-option-out-of-range"),
    # ---- drive CSV
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _scale_col(1, 1000.0))), 2,
                 "position is in millimetres", id="drive-position-mm"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _scale_col(0, 1000.0))), 2, "time in milliseconds",
                 id="drive-time-ms"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, header=("time_s", "position_m", "force"))), 2,
                 "missing column 'force_n'", id="drive-misnamed-force"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _swap_rows(0, 300, 200))), 2, "time goes backwards",
                 id="drive-time-backwards"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _nan_rows(1, 1000, 1100))), 2, "too long to fill",
                 id="drive-position-gap"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _fill_col(1, 0.1))), 2, "barely moves",
                 id="drive-still"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, n=300)), 2, "too few", id="drive-300-samples"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t, _fill_col(2, np.nan))), 2, "too long to fill",
                 id="drive-force-all-nan"),
    pytest.param(lambda b, t: fit("drive", drive_file(b, t), "--joint", "1"), 2, "--joint applies",
                 id="drive-joint-option"),
    # ---- drive .mat (the real file's variable names)
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_set("t", "0.001 0.002"))), 2,
                 "variable 't' holds text", id="mat-time-string"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_set("gtau", np.zeros((0, 0))))), 2,
                 "variable 'gtau' is empty", id="mat-gain-empty"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_set("gtau", "35.15"))), 2,
                 "variable 'gtau' is text", id="mat-gain-string"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_set("gtau", np.array([[-35.15]])))), 2,
                 "positive force gain", id="mat-gain-negative"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_backwards)), 2, "time goes backwards at sample 2001",
                 id="mat-time-backwards"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_dup)), 2, "duplicated time stamp",
                 id="mat-time-duplicate"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_nan("t"))), 2, "missing time stamps at sample 101",
                 id="mat-time-nan"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, _mat_nan("qm"))), 2, "variable 'qm' sample 101",
                 id="mat-position-nan"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, lambda d: _set(d, "qm", d["qm"][:-5]))), 2,
                 "'t' has 8000", id="mat-length-mismatch"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, lambda d: _set(d, "t", np.tile(d["t"], (1, 2))))), 2,
                 "expected a numeric vector", id="mat-time-matrix"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, lambda d: d.pop("vir"))), 2, "missing variable",
                 id="mat-missing-vir"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, lambda d: _set(d, "qm", 1000 * d["qm"]))), 2,
                 "column 'qm'", id="mat-position-mm"),
    pytest.param(lambda b, t: fit("drive", mat_file(b, t, lambda d: _set(d, "t", 1000 * d["t"]))), 2,
                 "time in milliseconds", id="mat-time-ms"),
    pytest.param(lambda b, t: fit("drive", _text(t / "DATA_EMPS.mat", "t,qm\n1,2\n")), 2,
                 "not a readable MATLAB file", id="mat-not-a-mat"),
    # ---- body markers
    pytest.param(lambda b, t: fit("body", marker_file(b, t, "markers_f0_00.csv")), 2, "0 Hz", id="markers-0-hz"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, "markers_f99_00.csv")), 2,
                 "the file name says a drive frequency of 99 Hz", id="markers-99-hz-name"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, "markers_f0_25.csv")), 2, "misnamed file",
                 id="markers-0.25-hz-name"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, "markers.csv")), 2,
                 "cannot read the drive frequency", id="markers-no-frequency"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=_still_markers)), 2, "did not swim",
                 id="markers-motionless"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=lambda s: "\n".join(
        ",".join(r.split(",")[:17]) for r in s.splitlines()))), 2, "17 columns", id="markers-17-columns"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=lambda s: s.replace(s.split(",")[5], "x", 1))), 2,
                 "not a number", id="markers-text-cell"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=lambda s: "\n".join(s.splitlines()[:60]))), 2,
                 "frames; at least 120", id="markers-1-s"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=lambda s: s.replace(s.split(",")[5], "nan", 1))), 2,
                 "missing coordinate", id="markers-nan"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t, fn=_coinciding_heads)), 2, "coincide",
                 id="markers-heads-coincide"),
    pytest.param(lambda b, t: fit("body", _binary(t / "markers_f1_00.csv")), 2, "not a text CSV",
                 id="markers-binary"),
    pytest.param(lambda b, t: fit("body", _mkdir(t / "empty")), 2, "holds no CSV", id="markers-empty-folder"),
    # ---- options
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--alpha", "2"), 2, "--alpha", id="alpha-2"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--min-drop", "1.5"), 2, "--min-drop",
                 id="min-drop-1.5"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--max-effects", "-1"), 2, "--max-effects",
                 id="max-effects-negative"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--holdout", "1.5"), 2, "strictly between 0 and 1",
                 id="holdout-1.5"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--holdout", "0.3", "0.2"), 2, "either one fraction",
                 id="holdout-two-fractions"),
    pytest.param(lambda b, t: fit("wing", joint_file(b, t)), 2, "wing", id="unknown-family"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--out", _text(t / "taken", "mine\n")), 2,
                 "exists and is a file", id="fit-out-is-a-file"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--out", "/proc/swiftfin_no/out"), 2,
                 "cannot create the folder", id="fit-out-under-proc"),
    pytest.param(lambda b, t: fit("joint", joint_file(b, t), "--out", _text(t / "f", "mine\n") / "out"), 2,
                 "is a file, so no folder", id="fit-out-under-a-file"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(_mkdir(t / "outdir")), "--duration", "3"], 2,
                 "is a folder", id="synth-out-is-a-folder"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", "/proc/swiftfin_no.csv", "--duration", "3"], 2,
                 "cannot write into /proc", id="synth-out-under-proc"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(t / "o.csv"), "--duration", "0.1"], 2, "--duration",
                 id="synth-duration-short"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(t / "o.csv"), "--rate", "5"], 2, "--rate",
                 id="synth-rate-low"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(t / "o.csv"), "--noise", "-1"], 2, "--noise",
                 id="synth-noise-negative"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(t / "o.csv"), "--effect", "warp_drive"], 2,
                 "--effect", id="synth-unknown-effect"),
    pytest.param(lambda b, t: ["synth", "joint", "--out", str(t / "o.csv"), "--joint", "99"], 2,
                 "the design has joints", id="synth-joint-out-of-range"),
    # ---- accepted: Excel's "CSV UTF-8" (a byte-order mark before the header)
    pytest.param(lambda b, t: fit("joint", _bom(joint_file(b, t)), "--no-plots"), 0, "no effect added",
                 id="joint-utf8-bom-accepted"),
    pytest.param(lambda b, t: fit("drive", _bom(drive_file(b, t)), "--no-plots"), 0, "+ coulomb_friction",
                 id="drive-utf8-bom-accepted"),
    # ---- accepted: the untouched bases (the corruptions above are what is refused, not the data)
    pytest.param(lambda b, t: fit("drive", mat_file(b, t), "--no-plots"), 0, "+ coulomb_friction", id="mat-slice"),
    pytest.param(lambda b, t: fit("body", marker_file(b, t), "--no-plots", "--max-effects", "1"), 0,
                 "+ tail_beat_frequency", id="markers-real-0.75-beat-ratio"),
]


def _binary(p: Path) -> Path:
    p.write_bytes(b"\xff\xfe\x00\x01" + bytes(range(256)) * 4)
    return p


def _text(p: Path, s: str) -> Path:
    p.write_text(s)
    return p


def _mkdir(p: Path) -> Path:
    p.mkdir()
    return p


def _bom(p: Path) -> Path:
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    return p


def _scale_col(j, k):
    def fn(a):
        a[:, j] *= k
    return fn


def _fill_col(j, v):
    def fn(a):
        a[:, j] = v
    return fn


def _swap_rows(j, i, k):
    def fn(a):
        a[i, j] = a[k, j]
    return fn


def _nan_rows(j, i0, i1):
    def fn(a):
        a[i0:i1, j] = np.nan
    return fn


def _snapshot(folder: Path) -> dict:
    """Every file under folder (recursively) -> sha256 of its bytes."""
    return {str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_table_is_large_enough():
    assert len(CASES) >= 50


@pytest.mark.parametrize("build, code, message", CASES)
def test_hostile_input(bases, tmp_path, capsys, build, code, message):
    case = tmp_path / "case"
    case.mkdir()
    argv = build(bases, case)
    if "--out" not in argv:
        argv += ["--out", str(tmp_path / "out")]
    if argv[0] == "fit" and "--design" not in argv:
        argv += D
    if argv[0] == "synth" and "--design" not in argv:
        argv += D
    before = _snapshot(case)
    got = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert got == code, out + err
    assert message in (err if code else out), out + err
    assert _snapshot(case) == before                   # inputs (and an existing --out) untouched
    if code == 2:
        assert not (tmp_path / "out").exists()          # nothing written to --out
        assert len(err.strip().splitlines()) == 1       # one message


def test_utf8_bom_gives_the_same_data(bases, tmp_path):
    """Excel's "CSV UTF-8" puts a byte-order mark before the header: the same log with and without it reads the
    same (joint and drive CSV, marker CSV)."""
    from swiftfin.calibration.drive_data import read_drive_csv
    from swiftfin.calibration.fishsim import read_marker_csv
    from swiftfin.calibration.io import read_log
    from swiftfin.calibration.joint import COLUMNS
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    plain, bom = joint_file(bases, tmp_path / "a"), _bom(joint_file(bases, tmp_path / "b"))
    a, b = read_log(plain, COLUMNS), read_log(bom, COLUMNS)
    assert list(a.columns) == list(b.columns) == [c.name for c in COLUMNS]
    for k in a.columns:
        np.testing.assert_array_equal(a[k], b[k])
    da, db = read_drive_csv(drive_file(bases, tmp_path / "a")), read_drive_csv(_bom(drive_file(bases, tmp_path / "b")))
    np.testing.assert_array_equal(da.position, db.position)
    np.testing.assert_array_equal(da.force, db.force)
    ma = read_marker_csv(marker_file(bases, tmp_path / "a"))
    mb = read_marker_csv(_bom(marker_file(bases, tmp_path / "b")))
    np.testing.assert_array_equal(ma, mb)
