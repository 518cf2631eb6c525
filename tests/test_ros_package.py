"""``swiftfin build --ros2-package``: a ROS 2 description package (exports/ros_package.py) beside the robot folder's
files, checked by its consumers' parsers (urdfdom's check_urdf, PyBullet) on the mini stand-in design (fast); the
CLI option is checked to reach exports.robot.write_robot."""
from __future__ import annotations

import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from swiftfin import __version__, pipeline
from swiftfin.cad import registry
from swiftfin.cli import main
from swiftfin.core.params import dump_toml
from swiftfin.exports import robot as robot_export
from swiftfin.exports.manifest import make_manifest, manifest_text, sha256_bytes, verify_manifest
from swiftfin.exports.robot import write_robot
from swiftfin.exports.ros_package import DEFAULT_PACKAGE, package_version, ros_package_files
from tests.conftest import require_module, require_tool, session_cache_dir
from tests.robot_helpers import mini_parts

PKG = DEFAULT_PACKAGE
PREFIX = f"package://{PKG}/"


@pytest.fixture(scope="module")
def mini(tmp_path_factory, default_params):
    """The mini stand-in design written with the ROS 2 package (exporter mechanics only: see robot_helpers)."""
    out = tmp_path_factory.mktemp("ros_mini")
    res = write_robot(default_params, mini_parts(default_params), out, ros2_package=True)
    return out, res


def _pkg(mini) -> Path:
    out, _ = mini
    return out / "robot" / PKG


def _mesh_uris(tree: ET.ElementTree) -> list[str]:
    return [m.get("filename") for m in tree.getroot().iter("mesh")]


def test_mini_package_layout_is_launch_free(mini):
    pkg = _pkg(mini)
    files = sorted(p.relative_to(pkg).as_posix() for p in pkg.rglob("*") if p.is_file())
    assert {"package.xml", "CMakeLists.txt", "README.md", "urdf/swiftfin.urdf"} <= set(files)
    assert all(f in {"package.xml", "CMakeLists.txt", "README.md", "urdf/swiftfin.urdf"} or
               (f.startswith("meshes/") and f.endswith(".obj")) for f in files), files
    assert not (pkg / "launch").exists()
    # the package's meshes are copies of the robot folder's
    for m in (pkg / "meshes").iterdir():
        assert m.read_bytes() == (pkg.parent / "meshes" / m.name).read_bytes()
    cmake = (pkg / "CMakeLists.txt").read_text()
    assert f"project({PKG})" in cmake and "find_package(ament_cmake REQUIRED)" in cmake
    assert "install(DIRECTORY urdf meshes DESTINATION share/${PROJECT_NAME})" in cmake and "ament_package()" in cmake
    readme = (pkg / "README.md").read_text()
    assert "colcon build" in readme and "robot_state_publisher" in readme


def test_mini_package_xml_format_3(mini):
    root = ET.parse(_pkg(mini) / "package.xml").getroot()
    assert root.tag == "package" and root.get("format") == "3"
    assert root.findtext("name") == PKG
    assert root.findtext("version") == package_version(__version__)
    assert root.findtext("description").strip()
    assert root.find("maintainer").get("email") and "FILL IN" in root.findtext("maintainer")
    assert root.findtext("license") == "MIT"
    assert [e.text for e in root.findall("buildtool_depend")] == ["ament_cmake"]
    assert root.findtext("export/build_type") == "ament_cmake"


def test_mini_every_package_uri_names_a_mesh_of_the_package(mini):
    pkg = _pkg(mini)
    uris = _mesh_uris(ET.parse(pkg / "urdf" / "swiftfin.urdf"))
    assert uris and all(u.startswith(PREFIX + "meshes/") for u in uris), uris
    for u in uris:
        assert (pkg / u[len(PREFIX):]).is_file(), u
    # and every mesh in the package is used
    assert {u[len(PREFIX):] for u in uris} == {f"meshes/{m.name}" for m in (pkg / "meshes").iterdir()}


def test_mini_package_urdf_equals_the_plain_urdf_but_for_mesh_uris(mini):
    pkg = _pkg(mini)
    plain = ET.parse(pkg.parent / "swiftfin.urdf")
    packaged = ET.parse(pkg / "urdf" / "swiftfin.urdf")
    n = 0
    for m in packaged.getroot().iter("mesh"):
        uri = m.get("filename")
        assert uri.startswith(PREFIX)
        m.set("filename", uri[len(PREFIX):])
        n += 1
    assert n == len(_mesh_uris(plain)) > 0
    assert ET.tostring(packaged.getroot()) == ET.tostring(plain.getroot())


def test_mini_check_urdf_accepts_package_uris_as_they_are(mini):
    """urdfdom parses the URDF without resolving meshes, so the package:// URIs are accepted unresolved."""
    exe = require_tool("check_urdf", "urdfdom's parser validates the URDF (apt-get install liburdfdom-tools)")
    run = subprocess.run([exe, str(_pkg(mini) / "urdf" / "swiftfin.urdf")], capture_output=True, text=True)
    text = run.stdout + run.stderr
    assert run.returncode == 0, text
    assert "Successfully Parsed XML" in text and "root Link: head" in text
    assert "error" not in text.lower() and "warn" not in text.lower(), text


def test_mini_pybullet_resolves_package_uris(mini, capfd):
    """PyBullet strips ``package://`` and finds ``<pkg>/meshes/...`` on its search path: the package's parent
    folder, where a ROS install's share/ would be."""
    pybullet = require_module("pybullet", "PyBullet is needed to load the URDF")
    out, res = mini
    pkg = _pkg(mini)
    cid = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.setAdditionalSearchPath(str(pkg.parent), physicsClientId=cid)
        body = pybullet.loadURDF(str(pkg / "urdf" / "swiftfin.urdf"), flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                 physicsClientId=cid)
        links = {lk.name: lk for lk in res["robot"].links}
        names = {-1: pybullet.getBodyInfo(body, physicsClientId=cid)[0].decode()}
        for j in range(pybullet.getNumJoints(body, physicsClientId=cid)):
            names[j] = pybullet.getJointInfo(body, j, physicsClientId=cid)[12].decode()
        assert set(names.values()) == set(links)
        for idx, name in names.items():
            assert pybullet.getDynamicsInfo(body, idx, physicsClientId=cid)[0] == pytest.approx(
                links[name].inertial.mass_kg, rel=1e-6)
            shapes = pybullet.getCollisionShapeData(body, idx, physicsClientId=cid)
            assert len(shapes) == len(links[name].collisions)
            for s in shapes:
                assert s[2] == pybullet.GEOM_MESH
                path = Path(s[4].decode())
                assert path.is_file() and path.parent == pkg / "meshes", path
    finally:
        pybullet.disconnect(cid)
    err = capfd.readouterr()
    assert "cannot find" not in (err.out + err.err).lower()


def test_mini_every_written_file_is_listed_and_the_manifest_verifies(mini):
    """write_robot's ``files`` (what the pipeline's manifest lists) covers the package: a manifest made from it
    verifies clean."""
    out, res = mini
    on_disk = {p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()}
    assert set(res["files"]) == on_disk
    assert any(f.startswith(f"robot/{PKG}/") for f in res["files"])
    entries = [{"path": rel, "sha256": sha256_bytes((out / rel).read_bytes()), "bytes": (out / rel).stat().st_size}
               for rel in sorted(res["files"])]
    manifest = make_manifest(entries, [], Path("design.toml"), params_sha256="0" * 64)
    (out / "manifest.json").write_text(manifest_text(manifest))
    try:
        assert verify_manifest(out) == []
    finally:
        (out / "manifest.json").unlink()


def test_mini_no_package_without_the_option(tmp_path, default_params):
    res = write_robot(default_params, mini_parts(default_params), tmp_path)
    assert not (tmp_path / "robot" / PKG).exists()
    assert not any(PKG in f for f in res["files"])


def test_ros_package_refuses_bad_names_and_missing_meshes(mini):
    _, res = mini
    robot = res["robot"]
    meshes = {f"meshes/{m.name}": m.read_bytes() for m in (_pkg(mini) / "meshes").iterdir()}
    files = ros_package_files(robot, meshes, "fish_description")
    assert ET.fromstring(files["package.xml"]).findtext("name") == "fish_description"
    assert all(u.startswith("package://fish_description/meshes/")
               for u in _mesh_uris(ET.ElementTree(ET.fromstring(files["urdf/swiftfin.urdf"]))))
    for bad in ("Swiftfin", "swift-fin", "1fin", "swift__fin", "fin_"):
        with pytest.raises(ValueError, match="REP 144"):
            ros_package_files(robot, meshes, bad)
    first = sorted(meshes)[0]
    with pytest.raises(ValueError, match=first):
        ros_package_files(robot, {k: v for k, v in meshes.items() if k != first})


@pytest.mark.parametrize("given, want", [("0.1.0", "0.1.0"), ("1.2", "1.2.0"), ("0.0.0+src", "0.0.0"),
                                         ("2.0.1.dev3", "2.0.1"), ("3", "3.0.0"), ("x", "0.0.0")])
def test_ros_package_version_is_three_integers(given, want):
    assert package_version(given) == want


@pytest.fixture
def env(tmp_path, monkeypatch, tmp_path_factory):
    """As tests/test_outdir.py: tmp_path as the working folder, the session's cache, a fin-only design; here the
    robot writer is replaced by a recorder (the real one is checked above on the mini design) and the report by
    a stub."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SWIFTFIN_CACHE_DIR", str(session_cache_dir(tmp_path_factory)))
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"]})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)
    calls = []

    def record(params, parts, out_dir, **kwargs):
        calls.append(kwargs)
        files = ["robot/swiftfin.urdf"] + ([f"robot/{PKG}/package.xml"] if kwargs.get("ros2_package") else [])
        for rel in files:
            (Path(out_dir) / rel).parent.mkdir(parents=True, exist_ok=True)
            (Path(out_dir) / rel).write_text("stand-in")
        return {"files": files}

    monkeypatch.setattr(robot_export, "write_robot", record)
    monkeypatch.setattr(pipeline, "report_for_build",
                        lambda result, out_dir, *a, **k: (Path(out_dir) / "report.html").write_text("stub"))
    (tmp_path / "design.toml").write_text(dump_toml())
    return tmp_path, calls


@pytest.mark.parametrize("flag", [True, False])
def test_ros_cli_option_reaches_write_robot(env, flag):
    folder, calls = env
    assert main(["build", "design.toml", "--out", "out"] + (["--ros2-package"] if flag else [])) == 0
    assert len(calls) == 1 and calls[0]["ros2_package"] is flag
    assert (folder / "out" / "robot" / PKG / "package.xml").is_file() is flag
    assert verify_manifest(folder / "out") == []
