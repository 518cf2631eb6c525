"""Shared fixtures. Tests write only to tmp_path (house style rule 13)."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
DEFAULT_DESIGN = ROOT / "swiftfin.toml"


def session_cache_dir(tmp_path_factory) -> Path:
    """The rebuild cache every test of the run shares (``swiftfin-cache``). Under pytest-xdist each worker has
    its own base folder, all in one folder of the run: the cache sits there, so a family, a stage result or a
    proved assembly pair one worker stored is read by the others instead of being built again (the cache writes
    each entry whole and renames it into place, so workers never read half an entry)."""
    base = tmp_path_factory.getbasetemp()
    return (base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base) / "swiftfin-cache"


def require_tool(name: str, why: str) -> str:
    """Path of an external tool, or skip with a clear reason (fail in CI, where it must be installed)."""
    path = shutil.which(name)
    if path is None:
        msg = f"{name} not installed: {why} (apt-get install {name})"
        if os.environ.get("SWIFTFIN_REQUIRE_TOOLS"):
            pytest.fail(msg)
        pytest.skip(msg)
    return path


def require_module(name: str, why: str):
    """The imported Python module ``name``, or skip with a clear reason (fail with SWIFTFIN_REQUIRE_TOOLS, as in
    CI, where `.[test]` installs it). Works at module level too."""
    import importlib

    try:
        return importlib.import_module(name)
    except ImportError as exc:
        msg = f"{name} not importable ({exc}): {why} (pip install -e '.[test]')"
        if os.environ.get("SWIFTFIN_REQUIRE_TOOLS"):
            pytest.fail(msg)
        pytest.skip(msg, allow_module_level=True)


def require_shared(*parts: str) -> Path:
    """A path under ../shared, or skip where the folder is absent (a user's plain clone)."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        msg = f"{path} not found: the shared reference data sit beside the checkout in CI"
        if os.environ.get("SWIFTFIN_REQUIRE_TOOLS"):
            pytest.fail(msg)
        pytest.skip(msg)
    return path


@pytest.fixture(scope="session")
def default_params():
    from swiftfin.layout.design import load_design
    return load_design(DEFAULT_DESIGN)


@pytest.fixture(scope="session")
def default_parts(default_params):
    """Every part of the default design: each family of cad/registry.py, in build order (built once per
    session: about 30 s)."""
    from swiftfin.cad.registry import FAMILIES, family_function
    parts = []
    for name in FAMILIES:
        parts += family_function(name)(default_params)
    return parts


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", default=False,
                     help="rewrite tests/golden/*.json from the current build (on purpose only)")


@pytest.fixture(scope="session")
def default_robot(default_params, default_parts, tmp_path_factory):
    """The default design's robot folder (URDF, MJCF, SDF, meshes) and write_robot's summary, written once per session
    (about 60 s; four test modules read it). Tests read it and must not change it."""
    from swiftfin.exports.robot import write_robot
    out = tmp_path_factory.mktemp("default_robot")
    res = write_robot(default_params, default_parts, out)
    return out, res


@pytest.fixture(scope="session")
def default_slices(default_params, default_parts, tmp_path_factory):
    """PrusaSlicer on every printed part of the default design, once per session (about 60 s): label -> (the part's
    export, the slicer's result for its 3MF alone, which carries the design's [print] settings). Read by the
    slicer's and the print model's tests."""
    require_tool("prusa-slicer", "the printed parts are sliced with PrusaSlicer (issues 2 and 15)")
    from swiftfin.exports.files import export_part
    from swiftfin.exports.slicer import slice_stl
    folder = tmp_path_factory.mktemp("default_slices")
    out = {}
    for part in default_parts:
        if not part.printed:
            continue
        ex = export_part(part, default_params)
        threemf = folder / f"{part.label}.3mf"
        threemf.write_bytes(ex.files[".3mf"])
        out[part.label] = (ex, slice_stl(threemf, default_params, settings=False))
    return out


@pytest.fixture(scope="session")
def update_golden(request):
    return request.config.getoption("--update-golden")
