"""Hostile parameter files: each is refused with exit 2 and one clear message naming the file, the key, the value
and what was expected (house style rule 5), never a traceback, and never touched; the fine ones pass.

Every case runs ``swiftfin params FILE`` in-process; a few also run ``swiftfin check FILE``.
"""
from __future__ import annotations

import os
import signal
import stat
from pathlib import Path

import pytest

from swiftfin.cli import main
from swiftfin.core.params import ParamError
from swiftfin.layout.design import load_design, load_design_source
from tests.conftest import DEFAULT_DESIGN


def _component(name: str, extra: str = "") -> str:
    return (f"[[components]]\nname = {name}\nmass_kg = 0.01\nsize_mm = [10.0, 10.0, 10.0]\n"
            f"station_fraction = 0.3\nsource = \"test\"\n{extra}")


# Specials instead of file contents: made by _make().
DIRECTORY, FIFO, DEV_NULL, MISSING = "<directory>", "<fifo>", "<dev-null>", "<missing>"
# spool.wraps out of range (schema), a cable thicker than its groove (cross-field), a motor too big for the hull
# (layout): three independent problems at the three levels.
THREE_LEVELS = "[spool]\nwraps = -1\n[cable]\ndiameter_mm = 1.5\n[motor]\nframe_size_mm = 60\n"


def case(content, code, *present, absent=(), id):
    return pytest.param(content, code, present, absent, id=id)


# The room behind the motors: too little for the bay guide's bends or the wall, too much for the nose (in the
# params, check and build cases alike).
DRIVE_BAY = [
    case("[hull]\ndrive_bay_length_mm = 20\n", 2, "guide_bay", "more room behind the motors, hull.drive_bay_length_mm",
         id="drive-bay-too-short-for-the-bay-guide"),
    case("[hull]\ndrive_bay_length_mm = 35\n", 2, "reaches 10.36 mm too far forward",
         "or more room behind the motors (hull.drive_bay_length_mm = 35)", id="drive-bay-too-short-for-the-wall"),
    case("[hull]\ndrive_bay_length_mm = 120\n", 2, "does not fit in the hull",
         "less room behind the motors: hull.drive_bay_length_mm = 120", id="drive-bay-too-long-for-the-nose"),
    case("[hull]\ndrive_bay_length_mm = 201\n", 2, "hull.drive_bay_length_mm = 201: out of range: allowed [20, 200]",
         id="drive-bay-out-of-range"),
    # a user's longer fish: its build stopped after 3 minutes at the assembly check (a gland's tube in the gasket)
    case("[body]\nlength_mm = 700\n[hull]\ndrive_bay_length_mm = 60\n", 2,
         "hull.drive_bay_length_mm = 60.0: gland_4_right's PTFE tube", "reaches 0.22 mm into the seam gasket's band",
         "at most 53 mm behind the motors", id="drive-bay-lowers-a-gland-into-the-seam-gasket"),
]


CASES = [
    # --- fine files: defaults fill the gaps
    case("", 0, "valid", id="empty-file"),
    case("# only a comment\n\n   \n", 0, "valid", id="only-comments"),
    case("[body]\r\nlength_mm = 520.0\r\n", 0, "valid", id="crlf-line-endings"),
    case(b"\xef\xbb\xbf[body]\nlength_mm = 520.0\n", 0, "valid", id="utf8-bom"),
    case("# " + "x" * 200_000 + "\n[body]\nlength_mm = 520\n", 0, "valid", id="very-long-comment-line"),
    # under the motors (at z = 0 these 10 mm boxes stood inside motor 2, which the loader refuses since 2026-11-30)
    case(_component('"battery"', "z_mm = -38.0\n") + _component('"radio_2"', "z_mm = -38.0\n"), 0, "valid",
         id="two-good-components"),
    # --- unknown keys, with suggestions
    case("[spool]\ndiamter_mm = 20\n", 2, "spool.diamter_mm = 20", "did you mean 'drum_diameter_mm'",
         id="unknown-key-suggestion"),
    case("[bodyy]\nlength_mm = 520\n", 2, "bodyy", "unknown section (did you mean 'body'?)", id="unknown-section"),
    case("foo = 1\n", 2, "foo = 1: unknown top-level key", "[body]", "[[components]]", absent=("unknown section",),
         id="top-level-key"),
    case("length_mm = 520\n[body]\nnose_cap_fraction = 0.03\n", 2, "length_mm = 520: unknown top-level key",
         "did you mean 'length_mm' in [body]?", id="top-level-key-of-a-section"),
    case("bdy = 3\n", 2, "bdy = 3: unknown top-level key (did you mean 'body'?)", id="top-level-key-near-section"),
    case("[body]\n\"länge_mm\" = 520\n", 2, "body.länge_mm = 520: unknown key", id="unicode-key"),
    case("[\"🐟\"]\nx = 1\n", 2, "🐟", "unknown section", id="emoji-section"),
    case("[body]\n" + "".join(f"k{i} = {i}\n" for i in range(500)), 2, "500 problem(s)", "body.k99 = 99",
         "... and 400 more", absent=("body.k100 ",), id="many-unknown-keys"),
    case(_component('"a"', "colour = \"red\"\n"), 2, "components[0].colour = 'red': unknown key",
         id="component-unknown-key"),
    # --- wrong types
    case("[body]\nlength_mm = \"520\"\n", 2, "body.length_mm = '520': expected a number in [200, 2000]",
         id="string-for-number"),
    case("[body]\nlength_mm = true\n", 2, "body.length_mm = true: expected a number", id="bool-for-number"),
    case("body = [1, 2]\n", 2, "body = [1, 2]: expected a table of keys", id="list-for-table"),
    case("[[body]]\nlength_mm = 520\n", 2, "body = [{'length_mm': 520}]: expected a table of keys",
         id="array-of-tables-for-table"),
    case("[body]\nlength_mm = {mm = 520}\n", 2, "body.length_mm = {'mm': 520}: expected a number",
         id="table-for-number"),
    case("[body]\nlength_mm = 1979-05-27\n", 2, "body.length_mm = datetime.date(1979, 5, 27): expected a number",
         id="date-for-number"),
    case("[hull]\nsplit_halves = 1\n", 2, "hull.split_halves = 1: expected true or false", id="number-for-bool"),
    case("[joints]\ncount = 2.5\n", 2, "joints.count = 2.5: expected an integer in [1, 8]", id="float-for-int"),
    case("[joints]\nstations_fraction = 0.5\n", 2, "joints.stations_fraction = 0.5: expected a list of numbers",
         id="number-for-list"),
    case("[joints]\nstations_fraction = [0.5, \"x\", 0.7, 0.8]\n", 2, "joints.stations_fraction[1] = 'x'",
         id="string-in-list"),
    case("[joints]\nstations_fraction = []\n", 2, "joints.stations_fraction = []: expected a list", id="empty-list"),
    case("[joints]\nstations_fraction = [" + ", ".join(["0.5"] * 20) + "]\n", 2, "expected 1..8 values, got 20",
         id="list-too-long"),
    case("[cable]\nmaterial = \"hemp\"\n", 2, "cable.material = 'hemp': expected one of", id="string-not-a-choice"),
    case("[motor]\nmicrosteps = 12\n", 2, "motor.microsteps = 12: expected one of 1, 2, 4", id="int-not-a-choice"),
    case("components = 5\n", 2, "components = 5: expected an array of tables [[components]]",
         id="components-not-a-list"),
    case("[components]\nname = \"x\"\n", 2, "expected an array of tables [[components]]", id="components-as-table"),
    # --- non-finite, negative, zero, huge, out of range
    case("[body]\nlength_mm = nan\n", 2, "body.length_mm = nan: expected a finite number", id="nan"),
    case("[body]\nlength_mm = inf\n", 2, "body.length_mm = inf: expected a finite number", id="inf"),
    case("[body]\nlength_mm = -inf\n", 2, "body.length_mm = -inf: expected a finite number", id="minus-inf"),
    case("[joints]\nstations_fraction = [0.545, nan, 0.695, 0.765]\n", 2, "joints.stations_fraction[1] = nan",
         id="nan-in-list"),
    case("[spool]\ndrum_diameter_mm = -20\n", 2, "spool.drum_diameter_mm = -20: out of range: allowed [4, 100]",
         id="negative"),
    case("[body]\nlength_mm = 0\n", 2, "body.length_mm = 0: out of range: allowed [200, 2000]", id="zero"),
    case("[body]\nlength_mm = 1e308\n", 2, "body.length_mm = 1e+308: out of range", id="huge-float"),
    case("[body]\nlength_mm = 1" + "0" * 400 + "\n", 2, "body.length_mm = 1000", "out of range: allowed [200, 2000]",
         id="huge-int-400-digits"),
    case("[body]\nlength_mm = 1" + "0" * 5000 + "\n", 2, "a number too long to read", id="int-past-digit-limit"),
    case("[joints]\ncount = 99\n", 2, "joints.count = 99: out of range: allowed [1, 8]", id="int-out-of-range"),
    case("[joints]\ncount = 99\nstations_fraction = [0.55, 0.65, 0.75]\n", 2, "joints.count = 99",
         absent=("expected 4 stations",), id="failed-count-hides-its-consequence"),
    # --- deep nesting: refused where parsed, never a RecursionError
    case("a = " + "[" * 5000 + "]" * 5000 + "\n", 2, "nested too deeply", id="deep-arrays-5000"),
    case("a = " + "{b = " * 5000 + "1" + "}" * 5000 + "\n", 2, "nested too deeply", id="deep-inline-tables-5000"),
    case("[" + ".".join(["a"] * 5000) + "]\nx = 1\n", 2, "nested more than 16", id="deep-table-header-5000"),
    case("[body]\n" + ".".join(["a"] * 3000) + " = 1\n", 2, "body.a.a", "nested more than 16",
         id="deep-dotted-key-3000"),
    case("[body]\nlength_mm = " + "[" * 40 + "]" * 40 + "\n", 2, "body.length_mm", "nested more than 16",
         id="deep-array-40-in-a-key"),
    case("[body]\nlength_mm = " + "[" * 900 + "]" * 900 + "\n", 2, "nested too deeply", id="deep-array-900"),
    # --- component names
    case(_component('"../../x"'), 2, "components[0].name = '../../x': not a valid name", "letters, digits and "
         "underscores", id="component-name-path"),
    case(_component("'$(touch x)'"), 2, "components[0].name = '$(touch x)': not a valid name",
         id="component-name-shell"),
    case(_component('""'), 2, "components[0].name = '': not a valid name", id="component-name-empty"),
    case(_component('"1st"'), 2, "components[0].name = '1st': not a valid name", id="component-name-digit-first"),
    case(_component('"bätterie"'), 2, "components[0].name = 'bätterie': not a valid name",
         id="component-name-unicode"),
    case(_component('"x' + "y" * 60 + '"'), 2, "components[0].name", "at most 40 characters",
         id="component-name-too-long"),
    case(_component("5"), 2, "components[0].name = 5: expected a string", id="component-name-not-string"),
    case(_component('"battery"') + _component('"radio"') + _component('"battery"'), 2,
         "components[2].name = 'battery': duplicate name: components[0].name is 'battery'",
         id="component-name-duplicate"),
    case(_component('"battery"') + _component('"Battery"'), 2, "components[1].name = 'Battery': duplicate",
         id="component-name-duplicate-case"),
    case("[[components]]\nname = \"x\"\n", 2, "components[0].mass_kg = (missing): required",
         id="component-missing-fields"),
    # --- cross-field and layout problems, and all levels at once
    case("[cable]\ndiameter_mm = 1.5\n", 2, "spool.groove_pitch_mm", "thicker than its groove", id="cross-field"),
    case("[motor]\nframe_size_mm = 60\n", 2, "motor.frame_size_mm = 60.0", "does not fit in the hull",
         id="layout-motor-too-big"),
    case(THREE_LEVELS, 2, "spool.wraps = -1", "spool.groove_pitch_mm", "motor.frame_size_mm",
         id="three-levels-at-once"),
    *DRIVE_BAY,
    case("[body]\nhull_end_fraction = 0.8\n", 2, "body.hull_end_fraction = 0.8", "allowed [0.8, 0.98]",
         "joints.stations_fraction[-1] = 0.765", id="hull-end-fraction"),
    case("[rules]\nstrouhal_min = 0.4\nstrouhal_max = 0.3\n", 2, "rules.strouhal_min = 0.4", id="contradictory-rules"),
    # --- not TOML, not UTF-8, not a regular file
    case("[spool\n", 2, "the file is not valid TOML", id="syntax-error"),
    case("[body]\nlength_mm = 520\nlength_mm = 530\n", 2, "not valid TOML", id="duplicate-toml-key"),
    case(b"[body]\nlength_mm = 5\xff20\n", 2, "is not UTF-8 text: byte 0xff at line 2", id="invalid-utf8"),
    case(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)), 2, "is a binary file", id="binary-file"),
    case("[body]\nlength_mm = 520\n".encode("utf-16"), 2, "is UTF-16 text: save it as UTF-8", id="utf16-file"),
    case(b"\xef\xbb\xbf[body]\nlength_mm = -1\n", 2, "body.length_mm = -1: out of range", id="bom-and-bad-value"),
    case("[body]\nlength_mm = \"" + "x" * 300_000 + "\"\n", 2, "body.length_mm = 'xxxx", "expected a number",
         id="very-long-string-value"),
    case(DIRECTORY, 2, "is a directory", absent=("not found",), id="directory"),
    case(FIFO, 2, "is not a regular file (it is a named pipe (FIFO))", absent=("not found",), id="fifo"),
    case(DEV_NULL, 2, "is not a regular file (it is a character device)", absent=("not found",), id="dev-null"),
    case(MISSING, 2, "parameter file not found", id="missing-file"),
]


def _make(tmp_path: Path, content) -> Path:
    if content == DIRECTORY:
        path = tmp_path / "design.toml"
        path.mkdir()
    elif content == FIFO:
        path = tmp_path / "design.toml"
        os.mkfifo(path)
    elif content == DEV_NULL:
        path = Path(os.devnull)
    elif content == MISSING:
        path = tmp_path / "design.toml"
    else:
        path = tmp_path / "design.toml"
        path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
    return path


def _snapshot(path: Path):
    """What the file is and holds (a directory: its listing; a FIFO or device: its type), to prove it untouched."""
    if not os.path.lexists(path):
        return None
    st = os.stat(path)
    if stat.S_ISREG(st.st_mode):
        return ("file", path.read_bytes(), st.st_mtime_ns)
    if stat.S_ISDIR(st.st_mode):
        return ("dir", sorted(os.listdir(path)))
    return ("special", stat.S_IFMT(st.st_mode))


@pytest.fixture
def no_hang():
    """Fail (rather than hang the run) if reading a FIFO or a device blocks."""
    def on_alarm(signum, frame):
        raise TimeoutError("reading the parameter file hung")
    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


def _run(argv, path, capsys, code, present, absent):
    before = _snapshot(path)
    rc = main(argv)
    out = capsys.readouterr()
    assert rc == code, out.err
    assert "Traceback" not in out.out + out.err
    text = out.err if code == 2 else out.out + out.err
    if code == 2:
        assert str(path) in out.err, "the message must name the file"
        assert out.err.count(f"{path}:") == 1, "one message, naming the file once"
    for piece in present:
        assert piece in text
    for piece in absent:
        assert piece not in text
    assert _snapshot(path) == before, "the parameter file must be left untouched"
    return out


@pytest.mark.parametrize("content,code,present,absent", CASES)
def test_hostile_parameter_file(tmp_path, capsys, no_hang, content, code, present, absent):
    path = _make(tmp_path, content)
    _run(["params", str(path)], path, capsys, code, present, absent)


CHECK_CASES = [
    case("", 1, "verdict: FAIL", id="empty-file"),       # the default design fails paper.drum_to_cable: exit 1
    case(b"\xef\xbb\xbf", 1, "verdict: FAIL", id="bom-only"),
    case("a = " + "[" * 5000 + "]" * 5000 + "\n", 2, "nested too deeply", id="deep-arrays-5000"),
    case(THREE_LEVELS, 2, "spool.wraps = -1", "spool.groove_pitch_mm", "motor.frame_size_mm",
         id="three-levels-at-once"),
    *DRIVE_BAY,
    case(_component('"../../x"'), 2, "components[0].name = '../../x'", id="component-name-path"),
    case(_component('"radio"', "z_mm = -70.0\n"), 2, "components[0].z_mm = -70.0",
         "past the hull's inner surface", id="component-through-the-hull"),
    case(_component('"radio"').replace("station_fraction = 0.3", "station_fraction = 0.7"), 2,
         "components[0].station_fraction = 0.7", "leaves the head's hollow", id="component-in-the-flooded-tail"),
    case(DIRECTORY, 2, "is a directory", id="directory"),
    case(FIFO, 2, "is not a regular file", id="fifo"),
]


@pytest.mark.parametrize("content,code,present,absent", CHECK_CASES)
def test_hostile_parameter_file_check(tmp_path, capsys, no_hang, content, code, present, absent):
    path = _make(tmp_path, content)
    _run(["check", str(path)], path, capsys, code, present, absent)


BUILD_CASES = [
    case("a = " + "[" * 5000 + "]" * 5000 + "\n", 2, "nested too deeply", id="deep-arrays-5000"),
    case("[body]\nlength_mm = " + "[" * 40 + "]" * 40 + "\n", 2, "nested more than 16", id="deep-array-40"),
    case(THREE_LEVELS, 2, "spool.wraps = -1", "spool.groove_pitch_mm", "motor.frame_size_mm",
         id="three-levels-at-once"),
    *DRIVE_BAY,
    case(DIRECTORY, 2, "is a directory", id="directory"),
    case(FIFO, 2, "is not a regular file", id="fifo"),
]


@pytest.mark.parametrize("content,code,present,absent", BUILD_CASES)
def test_hostile_parameter_file_build(tmp_path, capsys, no_hang, content, code, present, absent):
    """`swiftfin build` refuses the file before any work: exit 2, nothing written."""
    path = _make(tmp_path, content)
    out_dir = tmp_path / "out"
    _run(["build", str(path), "--out", str(out_dir), "--no-cache"], path, capsys, code, present, absent)
    assert not out_dir.exists()


def test_table_is_large_enough():
    assert len(CASES) >= 50 and len({c.id for c in CASES}) == len(CASES)


# ----------------------------------------------------------------------------------------------- one by one
def test_every_level_reported_at_once(tmp_path):
    """A range error (schema), a cable thicker than its groove (cross-field) and a motor too big for the hull
    (layout) are reported together, in that order, in one ParamError."""
    f = tmp_path / "three.toml"
    f.write_text(THREE_LEVELS)
    with pytest.raises(ParamError) as err:
        load_design(f)
    keys = [pr.key for pr in err.value.problems]
    assert keys[0] == "spool.wraps" and keys[1] == "spool.groove_pitch_mm"
    assert "motor.frame_size_mm" in keys
    msg = str(err.value)
    for key in ("spool.wraps", "spool.groove_pitch_mm", "motor.frame_size_mm"):
        assert key in msg


def test_later_problem_that_hangs_on_a_substituted_default_is_left_out(tmp_path):
    """With body.length_mm refused, the default length stands in; a tendon sector that only fails to fit at
    that length (it fits in a longer fish) is not reported, the length-independent groove problem is."""
    f = tmp_path / "d.toml"
    f.write_text("[body]\nlength_mm = -5\n[cable]\ndiameter_mm = 1.5\n[joints]\ntendon_moment_arm_mm = 30\n")
    with pytest.raises(ParamError) as err:
        load_design(f)
    assert [pr.key for pr in err.value.problems] == ["body.length_mm", "spool.groove_pitch_mm"]


def test_bom_file_loads_equal_to_the_same_without(tmp_path):
    text = "[body]\nlength_mm = 600.0\n[spool]\nwraps = 3\n"
    plain, bom = tmp_path / "plain.toml", tmp_path / "bom.toml"
    plain.write_text(text)
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode())
    p = load_design(bom)
    assert p == load_design(plain) and p.body.length_mm == 600.0


def test_load_design_source_reads_the_file_once(tmp_path, monkeypatch):
    """The params come from exactly the bytes returned (the caller hashes those), read with one open()."""
    f = tmp_path / "d.toml"
    data = b"[body]\nlength_mm = 560.0\n"      # the default, longer (at 600 mm its dry wall meets the bay guide)
    f.write_bytes(data)
    opened = []
    real_open = os.open

    def counting_open(path, *args, **kw):
        opened.append(str(path))
        return real_open(path, *args, **kw)

    monkeypatch.setattr(os, "open", counting_open)
    params, raw = load_design_source(f)
    monkeypatch.undo()
    assert raw == data and opened == [str(f)]
    assert params.body.length_mm == 560.0 and params == load_design(f)
    default, default_raw = load_design_source(DEFAULT_DESIGN)
    assert default_raw == DEFAULT_DESIGN.read_bytes() and default == load_design(DEFAULT_DESIGN)


def test_dev_zero_does_not_hang(capsys, no_hang):
    assert main(["params", "/dev/zero"]) == 2
    assert "is not a regular file (it is a character device)" in capsys.readouterr().err


def test_bad_mass_properties_file_is_named_as_such(tmp_path, capsys, no_hang):
    """A bad --mass-properties file is a problem in that file, not in the parameter file."""
    for make, expected in ((lambda p: p.mkdir(), "is a directory, not a mass properties file"),
                           (lambda p: os.mkfifo(p), "is not a regular file"),
                           (lambda p: p.write_text("{not json"), "is not readable JSON"),
                           (lambda p: p.write_text("[" * 100_000), "nested too deeply"),
                           (lambda p: None, "mass properties file (JSON) not found")):
        path = tmp_path / f"mp{len(list(tmp_path.iterdir()))}.json"
        make(path)
        assert main(["check", str(DEFAULT_DESIGN), "--mass-properties", str(path)]) == 2
        err = capsys.readouterr().err
        assert f"{path}: 1 problem(s) in the mass-properties file" in err and expected in err, err
        assert "parameter file" not in err and "Traceback" not in err
    assert main(["check", str(DEFAULT_DESIGN), "--mass-properties", "/dev/zero"]) == 2
    assert "mass-properties file" in capsys.readouterr().err
