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
from swiftfin.core.errors import BuildError
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
    """A family that fails after another was built (the fin, then one that raises): no folder is left. (Only the
    fin before it: the whole design built afresh first, as this test did, cost about 150 s and proved nothing
    more.)"""
    (env / "design.toml").write_text(dump_toml())
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"],
                                               "exploding": "tests.test_build:_exploding_family"})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)
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


def _fin_only(monkeypatch):
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"]})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)


def _failing_check(result, cache=None, progress=None):
    raise BuildError("assembly: caudal_fin meets hull_peduncle_upper by 0.4 mm at joint 4 = 20 deg")


@pytest.mark.parametrize("writing", ["passes", "fails too"])
def test_a_failing_check_beside_the_writing_refuses_the_build(env, monkeypatch, capsys, writing):
    """The checks run on a forked process while the parts, the STEP and the robot are written: their failure
    still refuses the build (exit 1, no folder), and comes first when the writing fails as well."""
    (env / "design.toml").write_text(dump_toml())
    _fin_only(monkeypatch)
    monkeypatch.setattr(pipeline, "check_built", _failing_check)

    def robot(*args, **kwargs):
        if writing == "fails too":
            raise BuildError("mass properties: link 4 fails the gate")
        return []        # a writer that never joins the checks: the build joins them before the swap

    monkeypatch.setattr(pipeline, "write_robot_and_report", robot)
    assert main(["build", "design.toml", "--out", "out"]) == 1
    err = capsys.readouterr().err
    assert "caudal_fin meets hull_peduncle_upper" in err and "link 4 fails the gate" not in err
    assert not (env / "out").exists() and leftovers(env) == []


@pytest.mark.slow
def test_default_design_builds_end_to_end(env, capsys):
    """`swiftfin build swiftfin.toml --out build`: every family, every printed part, passes the checks."""
    rc = main(["build", str(DEFAULT_DESIGN), "--out", "build"])
    out, err = capsys.readouterr()
    assert rc == 0, err[-3000:]
    assert "cables, tubes and leads clear:" in out                # the cables', tubes' and leads' proof ran
    assert "PTFE tubes seated: every tube on its printed shoulder" in out    # and every tube's seat was measured
    assert "every touching pair of the contact table joined" in out         # and how every mating pair is held
    manifest = json.loads((env / "build" / "manifest.json").read_text())
    families = {p["family"] for p in manifest["parts"]}
    # the seam gasket, cut from the hull family's solids; the trim ballast, made after the rest (swiftfin/ballast.py)
    assert families == set(registry.FAMILIES) | {"seal", "ballast"}
    for part in manifest["parts"]:
        expected = [f"parts/{part['label']}{k}" for k in (".step", ".stl", ".3mf")] if part["printed"] else []
        if part["family"] == "seal":                           # bought, die-cut: its outline drawing
            expected = [f"parts/{part['label']}.svg"]
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
    # the printability rules from the folder (`swiftfin check --build`): every printed part has its record in the
    # manifest, and the rules count the regions the build's summary counted from its exports (two paths)
    assert main(["check", str(DEFAULT_DESIGN), "--build", "build", "--json", "check.json"]) == 1
    by = {f["rule_id"]: f for f in json.loads((env / "check.json").read_text())["findings"]}
    printed = [q for q in manifest["parts"] if q["printed"]]
    assert all("print" in q and q["print_rotation"] == q["print"]["rotation_deg"] for q in printed)
    walls = sum(len(q["print"]["thin_walls"]) for q in printed)
    assert by["print.thin_walls"]["value"] == walls
    assert (f"walls (ray-cast probe): {walls} region(s)" if walls else "walls: none under two perimeters") in out
    assert by["print.support"]["severity"] == "INFO" and by["print.support"]["value"] == pytest.approx(
        sum(q["print"]["support_area_mm2"] for q in printed), abs=0.01)
    assert by["print.bridges"]["severity"] in ("PASS", "WARN") and by["float.level"]["severity"] != "NOT_EVALUATED"
    # no fastener hole needs support inside in the orientations chosen (every one of them checked)
    assert by["print.bores"]["severity"] == "PASS" and sum(q["print"]["bores_checked"] for q in printed) > 200
    # a build without the cache (every solid made afresh in this process) lists the same files and hashes,
    # STEP included (fixed header dates, occurrence ids renumbered per file)
    assert main(["build", str(DEFAULT_DESIGN), "--out", "fresh", "--no-cache"]) == 0
    assert (env / "fresh" / "manifest.json").read_text() == (env / "build" / "manifest.json").read_text()


@pytest.mark.slow
def test_the_loop_closes_from_a_bench_log_to_a_calibrated_build(env, capsys):
    """Issue 14 item 4, end to end: a bench log of known truth (`swiftfin synth`, a bench file's heavier link,
    0.02 N m s/rad of hinge damping) -> `swiftfin fit joint --bench --mjcf` (the MJCF of a plain build) writes
    calibration.toml and replays the log through the MJCF's joint in MuJoCo, as exported and as calibrated ->
    `swiftfin build --calibration` writes an MJCF whose joint MuJoCo reads as the replay's calibrated drive. The
    calibrated replay's error is lower than the exported one's and near the sensor's noise. Runs after the
    end-to-end build in this file, so every part comes from the session's cache."""
    from tests.conftest import require_module
    mujoco = require_module("mujoco", "replays the log and loads the calibrated MJCF")

    assert main(["build", str(DEFAULT_DESIGN), "--out", "plain"]) == 0
    (env / "bench.toml").write_text("link_inertia_kg_m2 = 2e-5\nbearing_damping_nm_s_rad = 3e-4\n")
    assert main(["synth", "joint", "--out", "log.csv", "--bench", "bench.toml", "--effect", "viscous_friction=0.02",
                 "--seed", "5"]) == 0
    assert main(["fit", "joint", "log.csv", "--bench", "bench.toml", "--mjcf", "plain/robot/swiftfin.xml",
                 "--out", "fit"]) == 0
    out = capsys.readouterr().out
    rep = json.loads((env / "fit" / "fit_report.json").read_text())
    before, after = rep["replay"]["before"]["rmse_rad"], rep["replay"]["after"]["rmse_rad"]
    assert after < 0.2 * before and after < 2.0 * rep["final"]["rmse_holdout"], (before, after)
    assert "replay in MuJoCo through joint_4" in out and (env / "fit" / "replay.png").is_file()
    cal = tomllib.loads((env / "fit" / "calibration.toml").read_text())
    assert cal["joint_4"]["hinge_damping_nm_s_rad"]["value"] == pytest.approx(0.02 + 3e-4, rel=0.03)
    assert main(["build", str(DEFAULT_DESIGN), "--out", "calibrated", "--calibration", "fit/calibration.toml"]) == 0
    m = mujoco.MjModel.from_xml_path(str(env / "calibrated" / "robot" / "swiftfin.xml"))
    jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "joint_4")
    act = next(a for a in range(m.nu) if m.actuator_trnid[a][0] == jid)
    drive = rep["replay"]["after"]["drive"]
    assert m.dof_damping[m.jnt_dofadr[jid]] == pytest.approx(drive["damping_nm_s_rad"], rel=1e-9)
    assert m.actuator_gainprm[act][0] == pytest.approx(drive["kp_nm_rad"], rel=1e-9)
    assert -m.actuator_biasprm[act][2] == pytest.approx(drive["kv_nm_s_rad"], abs=1e-12)
    # the report's rules are re-evaluated with the measured damping (the load model's hinge torque)
    assert "calibration.toml" in (env / "calibrated" / "report.html").read_text()


@pytest.mark.slow
def test_a_calibrated_build_carries_the_measured_joint_into_the_simulators(env, capsys):
    """`swiftfin build --calibration FILE` (issue 14: close the loop): the measured hinge damping, dry friction and
    drive stiffness of joint 4 reach the MJCF (damping, frictionloss, the position servo's kp, no kv and no
    armature) and the URDF (dynamics), as MuJoCo and PyBullet read them; the other joints keep the
    design's values; the build keeps a copy of the file in its manifest. Runs after the end-to-end build in this
    file, so every part comes from the session's cache."""
    from tests.conftest import require_module
    from swiftfin.layout.servo import UNCALIBRATED_DAMPING_NM_S_RAD, joint_stiffness_nm_rad
    from swiftfin.layout.design import load_design

    mujoco = require_module("mujoco", "loads the calibrated MJCF")
    c, tc, k = 0.0213, 0.0117, 1.7
    (env / "cal.toml").write_text(
        "[joint_4]\n"
        f"hinge_damping_nm_s_rad = {{ value = {c}, std = 0.0004, effect = \"viscous_friction\" }}\n"
        f"hinge_friction_nm = {{ value = {tc}, std = 0.0003, effect = \"coulomb_friction\" }}\n"
        f"joint_stiffness_nm_rad = {{ value = {k}, std = 0.02, effect = \"cable_compliance\" }}\n")
    rc = main(["build", str(DEFAULT_DESIGN), "--out", "cal_build", "--calibration", "cal.toml"])
    assert rc == 0, capsys.readouterr().err[-3000:]
    out = env / "cal_build"
    assert verify_manifest(out) == []
    assert (out / "calibration.toml").read_bytes() == (env / "cal.toml").read_bytes()
    assert "calibration.toml" in {f["path"] for f in json.loads((out / "manifest.json").read_text())["files"]}
    m = mujoco.MjModel.from_xml_path(str(out / "robot" / "swiftfin.xml"))
    dof = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, m.dof_jntid[i]): i for i in range(m.nv)}
    assert m.dof_damping[dof["joint_4"]] == pytest.approx(c) and m.dof_frictionloss[dof["joint_4"]] == pytest.approx(tc)
    for j in (1, 2, 3):
        assert m.dof_damping[dof[f"joint_{j}"]] == pytest.approx(UNCALIBRATED_DAMPING_NM_S_RAD)
        assert m.dof_frictionloss[dof[f"joint_{j}"]] == 0.0
    motor = joint_stiffness_nm_rad(load_design(DEFAULT_DESIGN))
    kp = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a): m.actuator_gainprm[a][0] for a in range(m.nu)}
    assert kp["motor_4"] == pytest.approx(k) and kp["motor_1"] == pytest.approx(motor)
    kv = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a): -m.actuator_biasprm[a][2] for a in range(m.nu)}
    assert kv["motor_4"] == 0.0 and kv["motor_1"] > 0          # a measured joint's damping is all its damping
    pybullet = require_module("pybullet", "loads the calibrated URDF")
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(out / "robot" / "swiftfin.urdf"))
        info = {pybullet.getJointInfo(body, i)[1].decode(): pybullet.getJointInfo(body, i)
                for i in range(pybullet.getNumJoints(body))}
        assert info["joint_4"][6] == pytest.approx(c) and info["joint_4"][7] == pytest.approx(tc)  # damping, friction
        assert info["joint_1"][7] == 0.0
    finally:
        pybullet.disconnect(cid)
