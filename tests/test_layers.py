"""The shape of the house: one installed name, layers that import one way, no cycles, kernel-free commands.

* import-linter (the contracts in pyproject.toml) on the package as installed (tests/package_tree.py);
* no import cycle between modules, counting imports inside functions (grimp reads every import statement);
* ``check``, ``audit``, ``params``, ``fit`` and ``solve`` never import the CAD kernel (build123d, OCP), and ``--help``
  imports no command's heavy dependencies;
* the wheel's only top-level package is ``swiftfin``, it ships the default design, and the installed
  ``swiftfin check`` runs it from an empty folder (exit 1: the rules' verdict on the paper's design).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

from tests.conftest import DEFAULT_DESIGN, ROOT
from tests.package_tree import assemble, package_dirs

KERNEL = ("build123d", "OCP")


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> Path:
    return assemble(tmp_path_factory.mktemp("pkgtree"))


def _env(pythonpath: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(pythonpath)
    return env


def test_every_repository_folder_is_mapped_into_swiftfin():
    dirs = package_dirs()
    assert all(name == "swiftfin" or name.startswith("swiftfin.") for name in dirs)
    for folder in ("cad", "design_rules", "exports", "physics", "layout", "core", "calibration", "report",
                   "catalogues"):
        assert dirs[f"swiftfin.{folder}"] == ROOT / folder
    # every folder of Python sources at the top of the repository is installed (none is forgotten)
    mapped = {p.resolve() for p in dirs.values()}
    for d in ROOT.iterdir():
        if d.is_dir() and (d / "__init__.py").is_file() and d.name not in ("tests", "bench"):
            assert d.resolve() in mapped, f"{d.name}/ is not installed under swiftfin"


def test_import_contracts_hold(tree, tmp_path):
    exe = Path(sys.executable).with_name("lint-imports")
    if not exe.exists():
        pytest.fail("lint-imports (import-linter) is not installed: pip install -e '.[test]'")
    # run from an empty folder so that the repository's own swiftfin/ folder is not on the path
    r = subprocess.run([str(exe), "--config", str(ROOT / "pyproject.toml"), "--no-cache"], cwd=tmp_path,
                       env=_env(tree), capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout[-4000:] + r.stderr[-2000:]
    assert "0 broken" in r.stdout


CYCLES = textwrap.dedent("""
    import json, sys
    import grimp
    g = grimp.build_graph("swiftfin", cache_dir=None)
    adj = {m: sorted(g.find_modules_directly_imported_by(m)) for m in sorted(g.modules)}
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)
    def visit(v):
        index[v] = low[v] = counter[0]; counter[0] += 1; stack.append(v); on.add(v)
        for w in adj[v]:
            if w not in index:
                visit(w); low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop(); on.discard(w); comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))
    for m in adj:
        if m not in index:
            visit(m)
    print(json.dumps({"modules": len(adj), "cycles": comps}))
""")


def test_no_import_cycles_even_inside_functions(tree, tmp_path):
    r = subprocess.run([sys.executable, "-c", CYCLES], cwd=tmp_path, env=_env(tree), capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    out = json.loads(r.stdout)
    assert out["modules"] > 60     # the whole package was read
    assert out["cycles"] == [], "modules that import each other (directly or round a loop): " + str(out["cycles"])


PROBE = textwrap.dedent("""
    import json, sys
    from swiftfin.cli import main
    try:
        code = main(sys.argv[1:])
    except SystemExit as exc:   # --help
        code = exc.code
    heavy = ("build123d", "OCP", "scipy", "mujoco", "trimesh", "matplotlib", "swiftfin.calibration.engine")
    print(json.dumps({"code": code, "loaded": [m for m in heavy if m in sys.modules]}), file=sys.stderr)
""")


def _probe(args: list[str], cwd: Path) -> dict:
    r = subprocess.run([sys.executable, "-c", PROBE, *args], cwd=cwd, capture_output=True, text=True, timeout=600)
    return json.loads(r.stderr.strip().splitlines()[-1])


@pytest.mark.parametrize("args", [["check"], ["audit"], ["params"], ["params", "--dump"],
                                  ["check", str(DEFAULT_DESIGN), "--loads"],
                                  ["solve", "--vary", "cable.pretension_n=10:100", "--samples", "16"]])
def test_kernel_free_commands_do_not_import_the_kernel(args, tmp_path):
    out = _probe(args, tmp_path)
    assert out["code"] in (0, 1)
    assert not set(out["loaded"]) & set(KERNEL), f"swiftfin {' '.join(args)} imported {out['loaded']}"


def test_help_imports_no_heavy_dependency(tmp_path):
    out = _probe(["--help"], tmp_path)
    assert out["code"] == 0 and out["loaded"] == []
    out = _probe(["check", "--help"], tmp_path)
    assert out["code"] == 0 and out["loaded"] == []
    out = _probe(["solve", "--help"], tmp_path)
    assert out["code"] == 0 and out["loaded"] == []


def test_fit_does_not_import_the_kernel(tmp_path):
    from swiftfin.cli import main

    log = tmp_path / "log.csv"
    assert main(["synth", "joint", "--out", str(log), "--duration", "4", "--effect", "offset",
                 "--design", str(DEFAULT_DESIGN)]) == 0
    out = _probe(["fit", "joint", str(log), "--out", str(tmp_path / "fit"), "--no-plots",
                  "--design", str(DEFAULT_DESIGN)], tmp_path)
    assert out["code"] == 0
    assert not set(out["loaded"]) & set(KERNEL), out["loaded"]


@pytest.mark.parametrize("command", ["build", "check", "audit", "fit", "synth", "report", "params", "solve", "sweep"])
def test_every_command_has_a_description_and_an_example(command, capsys):
    from swiftfin.cli import main

    with pytest.raises(SystemExit) as exc:
        main([command, "--help"])
    assert exc.value.code == 0
    text = capsys.readouterr().out
    assert "examples:" in text and f"swiftfin {command}" in text.split("examples:")[1]
    description = text.split("\n\n")[1]
    assert len(description.split()) >= 20, description


def test_python_dash_m_runs_the_command(tmp_path):
    r = subprocess.run([sys.executable, "-m", "swiftfin", "params"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0 and "valid" in r.stdout, r.stderr


def test_a_design_in_the_working_folder_is_the_default(tmp_path):
    """./swiftfin.toml wins over the shipped design; without one, the shipped design is used."""
    (tmp_path / "swiftfin.toml").write_text("[body]\nlength_mm = 560\n")
    r = subprocess.run([sys.executable, "-m", "swiftfin", "params"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0 and r.stdout.startswith("swiftfin.toml: valid"), r.stdout + r.stderr


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    """The wheel, built from a copy of the sources (a build in the checkout would leave build/lib there)."""
    import shutil

    src = tmp_path_factory.mktemp("src") / "swiftfin"
    shutil.copytree(ROOT, src, symlinks=True, ignore=shutil.ignore_patterns(
        ".git", ".venv", ".cache", "build", "*.egg-info", "__pycache__", ".pytest_cache"))
    out = tmp_path_factory.mktemp("wheel")
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(src)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    (whl,) = out.glob("swiftfin-*.whl")
    return whl


def test_the_wheel_installs_one_top_level_package_with_the_default_design(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    top = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert top == {"swiftfin"}
    assert "swiftfin/swiftfin.toml" in names
    assert zipfile.ZipFile(wheel).read("swiftfin/swiftfin.toml") == DEFAULT_DESIGN.read_bytes()
    for sub in ("cad", "design_rules", "exports", "physics", "layout", "core", "calibration", "report", "commands",
                "catalogues"):
        assert f"swiftfin/{sub}/__init__.py" in names
    for table in ("fasteners.toml", "pins.toml", "materials.toml", "seals.toml"):   # the tables travel along
        assert f"swiftfin/catalogues/{table}" in names


def test_installed_check_runs_the_shipped_design_from_an_empty_folder(wheel, tmp_path):
    site = tmp_path / "site"
    with zipfile.ZipFile(wheel) as z:
        z.extractall(site)
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "report.py").write_text("raise RuntimeError('a user file named report.py was imported')\n")
    (empty / "physics.py").write_text("raise RuntimeError('a user file named physics.py was imported')\n")
    r = subprocess.run([sys.executable, "-c", PROBE, "check"], cwd=empty, env=_env(site), capture_output=True,
                       text=True, timeout=600)
    out = json.loads(r.stderr.strip().splitlines()[-1])
    assert out["code"] == 1, r.stdout + r.stderr      # the paper's design fails its rules
    assert str(site) in r.stdout                      # the shipped design, from the installed package
    assert not set(out["loaded"]) & set(KERNEL)
