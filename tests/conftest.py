"""Shared fixtures. Tests write only to tmp_path (house style rule 13)."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"
DEFAULT_DESIGN = ROOT / "swiftfin.toml"


def clear_layout_caches() -> None:
    """Forget every memoised number of the layout (each ``functools.lru_cache`` in ``swiftfin.layout``), for a test
    that patches a layout function to show what the design would be without it: a memo made before the patch
    would answer for the patched design (``layout.joints._joint_hardware`` is memoised since 2026-12-07)."""
    import sys
    for name, mod in list(sys.modules.items()):
        if not name.startswith("swiftfin.layout") or mod is None:
            continue
        for value in vars(mod).values():
            if callable(getattr(value, "cache_clear", None)) and getattr(value, "__module__", "") == name:
                value.cache_clear()


def session_shared_dir(tmp_path_factory) -> Path:
    """A folder every test of the run shares. Under pytest-xdist each worker has its own base folder, all in one
    folder of the run: that one (the run's own base folder without xdist)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def session_cache_dir(tmp_path_factory) -> Path:
    """The rebuild cache every test of the run shares (``swiftfin-cache`` in :func:`session_shared_dir`): a family,
    a stage result or a proved assembly pair one worker stored is read by the others instead of being built again
    (the cache writes each entry whole and renames it into place, so workers never read half an entry)."""
    return session_shared_dir(tmp_path_factory) / "swiftfin-cache"


def _sliced_once(folder: Path, label: str, threemf: bytes, compute):
    """``compute()`` for one part's 3MF, done by one worker of the run: the result is filed under the 3MF's
    SHA-256 in ``folder``; a worker that finds another slicing the part (its lock taken) returns None at once, and
    one called again for it (``compute`` None) waits for that worker's result. So two workers slicing the same
    parts split them instead of each slicing all."""
    import fcntl
    import hashlib
    import pickle

    key = hashlib.sha256(threemf).hexdigest()[:20]
    done = folder / f"{label}.{key}.pkl"
    with open(folder / f"{label}.{key}.lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | (fcntl.LOCK_NB if compute is not None else 0))
        except BlockingIOError:
            return None
        if done.is_file():
            return pickle.loads(done.read_bytes())
        value = (compute or (lambda: None))()
        if value is None:
            return None
        tmp = folder / f".{label}.{key}.{os.getpid()}"
        tmp.write_bytes(pickle.dumps(value))
        os.replace(tmp, done)
        return value


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


def manifold_of(solid, tolerance_mm: float, angular_tolerance_deg: float):
    """A CAD solid as a manifold3d Manifold (its tessellation at the given tolerances), for exact booleans on meshes
    (overlap and touch between parts)."""
    from swiftfin.cad.assembly import Placed
    from swiftfin.exports.brep import tessellate
    m = tessellate(solid, tolerance_mm, angular_tolerance_deg)
    return Placed("x", 0, "x", m.vertices, m.faces).manifold


@pytest.fixture(scope="session")
def default_params():
    from swiftfin.layout.design import load_design
    return load_design(DEFAULT_DESIGN)


@pytest.fixture(scope="session")
def default_build(default_params, tmp_path_factory):
    """The default design's parts as the build makes them (swiftfin.pipeline.build_parts: each family of
    cad/registry.py in build order, checked, read back from its BREP, exported, with the print orientation its
    export chose), then the trim ballast's dam and fill (pipeline.place_ballast), through the run's shared rebuild
    cache: the first worker to get here builds them (about 2 min), the others wait for it and read them. A
    BuildResult: tests read it and must not change it."""
    import fcntl

    from swiftfin.cache import FamilyCache
    from swiftfin.pipeline import build_parts, place_ballast

    cache = FamilyCache(session_cache_dir(tmp_path_factory))
    # one worker at a time: the first builds (the build's own processes on every core), the others wait and read
    # every family from the cache; without it two workers arriving together each built the whole design
    with open(session_shared_dir(tmp_path_factory) / "default-build.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        result = build_parts(default_params, cache)
        place_ballast(result, cache)
    return result


@pytest.fixture(scope="session")
def default_parts(default_build):
    """Every part of the default design (:func:`default_build`'s PartSpecs, in build order)."""
    return [b.spec for b in default_build.parts]


LONGEST_FILES_S = {"test_massprops.py": 610, "test_synthesis.py": 500, "test_build.py": 450, "test_hull.py": 420,
                   "test_sweep.py": 400, "test_vectorised_rules.py": 250, "test_mount.py": 190,
                   "test_independent_bench.py": 170, "test_dry_check.py": 160}
"""Seconds the longest test files took in a fresh-clone CI run (2026-11-29, two workers, from pytest's slowest
durations; the shared fixtures' setup counted where it fell): the order :func:`pytest_collection_modifyitems` starts
them in. Only an order: a file missing here, or grown, still runs."""


def pytest_collection_modifyitems(config, items):
    """The longest test files first (longest processing time first: :data:`LONGEST_FILES_S`, then the other files
    holding a ``@pytest.mark.slow`` test), each file's own order kept. ``make test`` hands whole files to the workers
    in this order (pytest-xdist ``--dist loadfile``), so the long files start early and the short ones fill the end;
    in name order three of the longest (test_synthesis, test_sweep, test_vectorised_rules: 18 min together) came
    last and one worker ran alone at the end (74 min of CPU in 48 min of the run on two cores, 2026-11-29)."""
    slow = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: (-LONGEST_FILES_S.get(item.path.name, 0), item.path not in slow))


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
def default_slices(default_params, default_build, tmp_path_factory):
    """PrusaSlicer on every printed part of the default design, once per run (about 150 s on one worker): label ->
    (the part's export, as the build writes it, and the slicer's result for its 3MF alone, which carries the
    design's [print] settings). Read by the slicer's and the print model's tests. Under pytest-xdist the workers
    split the parts between them (:func:`_sliced_once`): a part is sliced by whichever worker takes it first, the
    others read its result."""
    require_tool("prusa-slicer", "the printed parts are sliced with PrusaSlicer (issues 2 and 15)")
    from swiftfin.exports.slicer import slice_stl
    folder = tmp_path_factory.mktemp("default_slices")
    shared = session_shared_dir(tmp_path_factory) / "default-slices"
    shared.mkdir(exist_ok=True)
    exports, sliced = {}, {}
    for b in default_build.parts:
        if not b.spec.printed:
            continue
        label = b.spec.label
        ex = exports[label] = b.export
        threemf = folder / f"{label}.3mf"
        threemf.write_bytes(ex.files[".3mf"])
        sliced[label] = _sliced_once(shared, label, ex.files[".3mf"],
                                     lambda f=threemf: slice_stl(f, default_params, settings=False))
    for label, res in sliced.items():       # the parts another worker was slicing: wait for its results
        if res is None:
            sliced[label] = _sliced_once(shared, label, exports[label].files[".3mf"], None)
            if sliced[label] is None:       # that worker failed or stopped: slice it here
                sliced[label] = slice_stl(folder / f"{label}.3mf", default_params, settings=False)
    return {label: (exports[label], sliced[label]) for label in exports}


@pytest.fixture(scope="session")
def update_golden(request):
    return request.config.getoption("--update-golden")
