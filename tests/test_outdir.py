"""``--out`` writes only what the tool owns (issue 11): a user's files are never touched, the output place is
checked before any work, leftovers of killed builds are removed only when provably the tool's, and the manifest
hashes the parameter-file bytes the build parsed."""
from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys

import pytest

from swiftfin import outdir, pipeline
from swiftfin.cad import registry
from swiftfin.cli import main
from swiftfin.core.params import dump_toml
from swiftfin.exports.manifest import verify_manifest
from tests.conftest import session_cache_dir


@pytest.fixture
def env(tmp_path, monkeypatch, tmp_path_factory):
    """tmp_path as the working folder, the session's cache, and a fin-only "design" (the file mechanics; the
    robot, mass properties and report of the real design are checked in tests/test_build.py)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("SWIFTFIN_CACHE_DIR", str(session_cache_dir(tmp_path_factory)))
    monkeypatch.setattr(registry, "FAMILIES", {"fin": registry.FAMILIES["fin"]})
    monkeypatch.setattr(pipeline, "FAMILIES", registry.FAMILIES)
    monkeypatch.setattr(pipeline, "write_robot_and_report", lambda *a, **k: [])
    (tmp_path / "design.toml").write_text(dump_toml())
    return tmp_path


def _no_work(monkeypatch):
    """Make any build fail loudly: a refusal must come before the parts are made."""
    def boom(*a, **k):
        raise AssertionError("the build started")
    monkeypatch.setattr(pipeline, "build_parts", boom)


def _snapshot(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_folder_with_a_users_file_is_refused_before_any_work_and_untouched(env, monkeypatch, capsys):
    out = env / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    (out / "sub").mkdir()
    (out / "sub" / "data.csv").write_text("1,2\n")
    before = _snapshot(out)
    _no_work(monkeypatch)
    assert main(["build", "design.toml", "--out", "mine"]) == 2
    err = capsys.readouterr().err
    assert "--out mine is not replaced" in err and "no manifest.json" in err and "Traceback" not in err
    assert _snapshot(out) == before
    assert sorted(p.name for p in env.iterdir()) == ["design.toml", "mine"]     # no temporary folder either


def test_a_previous_build_with_a_users_file_added_is_refused(env, capsys):
    assert main(["build", "design.toml", "--out", "out"]) == 0
    (env / "out" / "my_print_settings.ini").write_text("keep me")
    before = _snapshot(env / "out")
    assert main(["build", "design.toml", "--out", "out"]) == 2
    err = capsys.readouterr().err
    assert "my_print_settings.ini: on disk but not in the manifest" in err
    assert _snapshot(env / "out") == before


def test_a_previous_build_is_replaced(env, capsys):
    assert main(["build", "design.toml", "--out", "out"]) == 0
    first = _snapshot(env / "out")
    assert main(["build", "design.toml", "--out", "out"]) == 0
    assert _snapshot(env / "out") == first and verify_manifest(env / "out") == []
    assert sorted(p.name for p in env.iterdir()) == ["design.toml", "out"]


def test_an_empty_folder_is_used(env):
    (env / "out").mkdir()
    assert main(["build", "design.toml", "--out", "out"]) == 0
    assert verify_manifest(env / "out") == []


def test_the_parameter_file_inside_out_is_refused(env, monkeypatch, capsys):
    (env / "proj").mkdir()
    (env / "proj" / "design.toml").write_text(dump_toml())
    _no_work(monkeypatch)
    assert main(["build", "proj/design.toml", "--out", "proj"]) == 2
    assert "holds proj/design.toml, which this build reads" in capsys.readouterr().err
    assert (env / "proj" / "design.toml").read_text() == dump_toml()


@pytest.mark.parametrize("where", [".", "..", "HOME", "/", "FILE", "SYMLINK"])
def test_places_that_are_never_replaced(env, monkeypatch, capsys, where):
    home = env / "home"
    home.mkdir()
    (home / ".bashrc").write_text("x")
    monkeypatch.setenv("HOME", str(home))
    (env / "a_file").write_text("a user's file")
    (env / "target").mkdir()
    (env / "link").symlink_to(env / "target")
    arg = {"HOME": str(home), "FILE": "a_file", "SYMLINK": "link"}.get(where, where)
    before = _snapshot(env)
    _no_work(monkeypatch)
    assert main(["build", "design.toml", "--out", arg]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "Traceback" not in err
    assert _snapshot(env) == before


def test_an_unwritable_place_is_refused_before_any_work(env, monkeypatch, capsys):
    _no_work(monkeypatch)
    assert main(["build", "design.toml", "--out", "/proc/swiftfin_build"]) == 2
    assert "--out /proc/swiftfin_build" in capsys.readouterr().err
    (env / "blocker").write_text("a file where a folder should be")
    assert main(["build", "design.toml", "--out", "blocker/out"]) == 2
    assert "is not a folder" in capsys.readouterr().err


def test_stale_temporary_folders_are_removed_only_when_provably_ours(env):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    ours_dead = env / ".out.tmp-dead1"
    ours_dead.mkdir()
    (ours_dead / outdir.MARKER).write_text(outdir._marker(int(dead)))
    (ours_dead / "half.stl").write_text("half a build")
    old_dead = env / ".out.old-dead2"
    old_dead.mkdir()
    (old_dead / outdir.MARKER).write_text(outdir._marker(int(dead)))
    ours_alive = env / ".out.tmp-alive"
    ours_alive.mkdir()
    (ours_alive / outdir.MARKER).write_text(outdir._marker(os.getpid()))
    not_ours = env / ".out.tmp-users"
    not_ours.mkdir()
    (not_ours / "keep.txt").write_text("no marker: not provably the tool's")
    other_name = env / ".other.tmp-x"
    other_name.mkdir()
    (other_name / outdir.MARKER).write_text(outdir._marker(int(dead)))
    assert main(["build", "design.toml", "--out", "out"]) == 0
    left = sorted(p.name for p in env.iterdir())
    assert left == sorted(["design.toml", "out", ".out.tmp-alive", ".out.tmp-users", ".other.tmp-x"])


def test_the_manifest_hashes_the_bytes_the_build_parsed(env, monkeypatch):
    """The parameter file edited during the build: the manifest records the file the parts came from."""
    original = (env / "design.toml").read_bytes()
    real = pipeline.build_parts

    def edit_then_build(p, *a, **k):
        (env / "design.toml").write_text(dump_toml().replace("span_mm = ", "span_mm = 1", 1))
        return real(p, *a, **k)

    monkeypatch.setattr(pipeline, "build_parts", edit_then_build)
    assert main(["build", "design.toml", "--out", "out"]) == 0
    manifest = json.loads((env / "out" / "manifest.json").read_text())
    assert manifest["params_sha256"] == hashlib.sha256(original).hexdigest()
    assert (env / "design.toml").read_bytes() != original
