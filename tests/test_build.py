"""``swiftfin build``: exit codes, nothing written on bad input or failure, atomic replacement, full build."""
from __future__ import annotations

import json
import tomllib

import pytest
import tomli_w

from swiftfin.cad import registry
from swiftfin.exports.manifest import verify_manifest
from swiftfin import pipeline
from swiftfin.cli import main
from swiftfin.core.params import dump_toml
from tests.conftest import DEFAULT_DESIGN, session_cache_dir


@pytest.fixture
def env(tmp_path, monkeypatch, tmp_path_factory):
    """Work in tmp_path with the session's shared cache."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SWIFTFIN_CACHE_DIR", str(session_cache_dir(tmp_path_factory)))
    return tmp_path


def leftovers(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _with(section: str, key: str, value, rename: str | None = None) -> str:
    raw = tomllib.loads(dump_toml())
    if rename:
        raw[section][rename] = raw[section].pop(key)
    else:
        raw[section][key] = value
    return tomli_w.dumps(raw)


def _bad_files():
    return {
        "typo": (_with("spool", "drum_diameter_mm", None, rename="drum_diamter_mm"),
                 ["spool.drum_diamter_mm", "did you mean 'drum_diameter_mm'"]),
        "negative length": (_with("body", "length_mm", -520.0), ["body.length_mm = -520.0", "out of range"]),
        "cable thicker than its groove": (_with("cable", "diameter_mm", 1.9),
                                          ["spool.groove_pitch_mm", "thicker than its groove"]),
        "not toml": ("[body\nlength_mm = 1", ["not valid TOML"]),
    }


@pytest.mark.parametrize("case", list(_bad_files()))
def test_bad_parameter_file_exits_2_and_writes_nothing(env, case, capsys):
    text, expected = _bad_files()[case]
    (env / "bad.toml").write_text(text)
    rc = main(["build", "bad.toml", "--out", "out"])
    err = capsys.readouterr().err
    assert rc == 2, err
    for piece in expected:
        assert piece in err
    assert "Traceback" not in err
    assert not (env / "out").exists() and leftovers(env) == []


def test_missing_parameter_file_exits_2(env, capsys):
    assert main(["build", "nope.toml", "--out", "out"]) == 2
    assert "parameter file not found" in capsys.readouterr().err
    assert not (env / "out").exists()


def _exploding_family(params):
    raise RuntimeError("boom at the fillet")


def test_failing_family_leaves_no_folder_and_keeps_an_old_build(env, monkeypatch, capsys):
    (env / "design.toml").write_text(dump_toml())
    monkeypatch.setitem(registry.FAMILIES, "exploding", "tests.test_build:_exploding_family")
    rc = main(["build", "design.toml", "--out", "out", "--no-cache"])
    err = capsys.readouterr().err
    assert rc == 1
    assert "part family 'exploding' failed: RuntimeError: boom at the fillet" in err
    assert not (env / "out").exists() and leftovers(env) == []
    # a folder in the way that is not a previous build is refused before any work, and left as it was
    (env / "out").mkdir()
    (env / "out" / "old.txt").write_text("previous build")
    assert main(["build", "design.toml", "--out", "out", "--no-cache"]) == 2
    assert "--out out is not replaced" in capsys.readouterr().err
    assert [p.name for p in (env / "out").iterdir()] == ["old.txt"]
    assert leftovers(env) == []


def test_interrupted_write_leaves_no_folder(env, monkeypatch, capsys):
    """Ctrl-C while the files are being written: no output folder, no temporary folder."""
    (env / "design.toml").write_text(dump_toml())
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"]})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)
    # interrupted after the parts and the assembly STEP are written, while the robot is being written (a fin-only
    # "design" has no robot to export: this test is about the file mechanics; the robot, mass properties and report
    # of the real design are checked in test_default_design_builds_end_to_end). Not the STEP itself: the session's
    # cache may hold it, and then it is not made again.
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(pipeline, "write_robot_and_report", interrupted)
    assert main(["build", "design.toml", "--out", "out"]) == 130
    assert not (env / "out").exists() and leftovers(env) == []


def test_one_family_build_writes_files_and_manifest(env, monkeypatch, capsys):
    """The whole write path on one family (the fin): files, manifest, table, replacement of an old build."""
    (env / "design.toml").write_text(dump_toml())
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"]})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)
    # a fin-only "design" has no robot to export: this test is about the file mechanics; the robot, mass
    # properties and report of the real design are checked in test_default_design_builds_end_to_end
    monkeypatch.setattr(pipeline, "write_robot_and_report", lambda *a, **k: [])
    assert main(["build", "design.toml", "--out", "out"]) == 0
    out, err = capsys.readouterr()
    files = sorted(p.relative_to(env / "out").as_posix() for p in (env / "out").rglob("*") if p.is_file())
    assert files == ["assembly.step", "manifest.json", "parts/caudal_fin.3mf", "parts/caudal_fin.step",
                     "parts/caudal_fin.stl"]
    assert verify_manifest(env / "out") == []
    manifest = json.loads((env / "out" / "manifest.json").read_text())
    import hashlib
    assert manifest["params_sha256"] == hashlib.sha256((env / "design.toml").read_bytes()).hexdigest()
    assert manifest["parts"][0]["label"] == "caudal_fin"
    assert "caudal_fin" in err and "link 4" in err                 # progress line
    assert "volume cm^3" in out and "caudal_fin" in out             # summary table
    assert leftovers(env) == []
    # the same parameter file again: the same manifest (STEP dates are fixed)
    first = (env / "out" / "manifest.json").read_text()
    assert main(["build", "design.toml", "--out", "out"]) == 0
    assert (env / "out" / "manifest.json").read_text() == first


@pytest.mark.slow
def test_default_design_builds_end_to_end(env, capsys):
    """`swiftfin build swiftfin.toml --out build`: every family, every printed part, passes the checks."""
    rc = main(["build", str(DEFAULT_DESIGN), "--out", "build"])
    out, err = capsys.readouterr()
    assert rc == 0, err[-3000:]
    assert "cables and tubes clear:" in out                       # the cables' and tubes' proof ran in the build
    assert "PTFE tubes seated: every tube on its printed shoulder" in out    # and every tube's seat was measured
    manifest = json.loads((env / "build" / "manifest.json").read_text())
    families = {p["family"] for p in manifest["parts"]}
    assert families == set(registry.FAMILIES)
    for part in manifest["parts"]:
        expected = [f"parts/{part['label']}{k}" for k in (".step", ".stl", ".3mf")] if part["printed"] else []
        assert part["files"] == expected
    assert verify_manifest(env / "build") == []
    assert leftovers(env) == []
    listed = {f["path"] for f in manifest["files"]}
    for rel in ("robot/swiftfin.urdf", "robot/swiftfin.xml", "robot/swiftfin.sdf", "mass_properties.json",
                "report.html", "assembly.step", "bom.csv", "assembly_steps.json"):
        assert rel in listed and (env / "build" / rel).is_file()
    # the bill of materials counts every fastener of the design and shows in the report
    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.exports.bom import read_bom_csv
    from swiftfin.layout.design import load_design
    rows = read_bom_csv((env / "build" / "bom.csv").read_text())
    screws = sum(int(r["quantity"]) for r in rows if r["item"] in ("Socket head cap screw", "Set screw, flat point"))
    fasteners = all_fasteners(load_design(DEFAULT_DESIGN))
    assert screws == sum(1 for f in fasteners if f.kind != "dowel")
    assert sum(int(r["quantity"]) for r in rows if r["item"] == "Stepper motor") == 4
    page = (env / "build" / "report.html").read_text()
    assert 'id="bom"' in page and "Heat-set insert" in page
    # the assembly steps: every part and fastener once, one exploded view per step that puts parts in
    steps = json.loads((env / "build" / "assembly_steps.json").read_text())["steps"]
    assert sorted(q for s in steps for q in s["parts"]) == sorted(p["label"] for p in manifest["parts"])
    assert sum(len(s["fasteners"]) for s in steps) == len(fasteners)
    section = page[page.index('<section id="steps">'):]
    section = section[:section.index("</section>")]
    assert section.count("data:image/png;base64,") == sum(1 for s in steps if s["parts"])
    assert section.count("<h3>Step ") == len(steps)
    # a build without the cache (every solid made afresh in this process) lists the same files and hashes,
    # STEP included (fixed header dates, occurrence ids renumbered per file)
    assert main(["build", str(DEFAULT_DESIGN), "--out", "fresh", "--no-cache"]) == 0
    assert (env / "fresh" / "manifest.json").read_text() == (env / "build" / "manifest.json").read_text()
