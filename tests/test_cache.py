"""Rebuild cache: reads are recorded, keys follow the parameters a family reads, cached output is identical."""
from __future__ import annotations

import dataclasses
import sys

import pytest

from swiftfin import cache as cache_mod
from swiftfin.cache import FamilyCache, RecordingParams, module_closure, record_reads, source_hash
from swiftfin.core.params import replace_key
from swiftfin.pipeline import build_parts, run_family
from swiftfin.core.schema import Params, Spool
from tests.conftest import session_cache_dir


# --------------------------------------------------------------------------------------------- the proxy
def test_proxy_records_exactly_the_keys_read():
    view, reads = record_reads(Params())
    assert view.spool.drum_diameter_mm == 20.0
    assert view.joints.stations_fraction == Params().joints.stations_fraction
    n = len(view.components)
    assert reads == {"spool.drum_diameter_mm": 20.0,
                     "joints.stations_fraction": list(Params().joints.stations_fraction),
                     "components": [dataclasses.asdict(c) | {"size_mm": list(c.size_mm)}
                                    for c in Params().components]}
    assert n == len(Params().components)


def test_proxy_looks_like_params_and_is_read_only():
    view, reads = record_reads(Params())
    assert isinstance(view, Params) and isinstance(view.spool, Spool)
    with pytest.raises(dataclasses.FrozenInstanceError):
        view.spool = None
    # dataclasses.replace on a section reads (and records) every field it copies, not the one it replaces
    s2 = dataclasses.replace(view.spool, wraps=3.0)
    assert s2.wraps == 3.0 and isinstance(s2, Spool) and type(s2) is Spool
    assert {k for k in reads if k.startswith("spool.")} == {f"spool.{f.name}" for f in dataclasses.fields(Spool)
                                                            if f.name != "wraps"}
    assert dataclasses.asdict(view.cable)["diameter_mm"] == 1.0 and "cable.diameter_mm" in reads
    # hashable by identity, equal only to itself: a memo keyed on params cannot skip the recording
    other, _ = record_reads(Params())
    assert view == view and view != other and hash(view) != hash(other)


# --------------------------------------------------------------------------------------------- source hash
def test_module_closure_follows_project_imports():
    mods = module_closure("swiftfin.layout.geometry")
    assert {"swiftfin.layout.geometry", "swiftfin.physics.kinematics", "swiftfin.core.params", "swiftfin.core.schema"} <= set(mods)
    assert not any(m.startswith(("numpy", "build123d")) for m in mods)


def test_source_hash_changes_with_an_imported_module(tmp_path, monkeypatch):
    pkg = tmp_path / "sfpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from sfpkg.b import f\n")
    (pkg / "b.py").write_text("def f():\n    return 1\n")
    (pkg / "c.py").write_text("X = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(cache_mod, "PROJECT_PACKAGES", cache_mod.PROJECT_PACKAGES + ("sfpkg",))
    h1 = source_hash("sfpkg.a")
    (pkg / "c.py").write_text("X = 2\n")          # not imported by a: same hash
    assert source_hash("sfpkg.a") == h1
    (pkg / "b.py").write_text("def f():\n    return 2\n")
    assert source_hash("sfpkg.a") != h1
    sys.modules.pop("sfpkg", None)


# --------------------------------------------------------------------------------------------- real families
@pytest.fixture(scope="module")
def shared_cache(tmp_path_factory):
    return FamilyCache(session_cache_dir(tmp_path_factory))


def _by_label(result):
    return {b.spec.label: b for b in result.parts}


def test_fin_span_change_rebuilds_the_fin_and_not_the_hull(default_params, shared_cache):
    build_parts(default_params, shared_cache, families=("hull", "fin"))   # warm (or already warm)
    again = build_parts(default_params, shared_cache, families=("hull", "fin"))
    assert all(b.cached for b in again.parts)
    changed = replace_key(default_params, "caudal_fin.span_mm", default_params.caudal_fin.span_mm + 10.0)
    after = build_parts(changed, shared_cache, families=("hull", "fin"))
    rebuilt = {b.spec.label for b in after.parts if not b.cached}
    assert rebuilt == {b.spec.label for b in after.parts if b.spec.family == "fin"}
    assert any(b.spec.family == "hull" and b.cached for b in after.parts)
    fin_old = next(b for b in again.parts if b.spec.family == "fin")
    fin_new = next(b for b in after.parts if b.spec.family == "fin")
    assert fin_new.export.volume_mm3 > fin_old.export.volume_mm3  # the change reached the fin


def test_unrelated_key_reuses_everything_with_identical_bytes(default_params, shared_cache):
    first = build_parts(default_params, shared_cache)
    unrelated = replace_key(default_params, "environment.water_viscosity_pa_s", 1.1e-3)
    second = build_parts(unrelated, shared_cache)
    assert all(b.cached for b in second.parts), [b.spec.label for b in second.parts if not b.cached]
    a, b = _by_label(first), _by_label(second)
    assert a.keys() == b.keys()
    for label in a:
        assert a[label].export.files == b[label].export.files, label


def test_cached_family_equals_a_fresh_build(default_params, shared_cache):
    """The cached fin (BREP round trip + stored bytes) equals the fin built now without the cache."""
    cached, _ = run_family("fin", default_params, shared_cache)
    cached, _ = run_family("fin", default_params, shared_cache)
    fresh, _ = run_family("fin", default_params, None)
    assert all(b.cached for b in cached) and not any(b.cached for b in fresh)
    for c, f in zip(cached, fresh):
        assert c.spec.label == f.spec.label and c.spec.link == f.spec.link
        assert c.spec.solid.volume == pytest.approx(f.spec.solid.volume, rel=1e-12)
        for kind in (".stl", ".3mf"):
            assert c.export.files[kind] == f.export.files[kind]


def test_a_damaged_entry_is_rebuilt(default_params, tmp_path):
    cache = FamilyCache(tmp_path / "c")
    run_family("fin", default_params, cache)
    entries = list((tmp_path / "c" / "fin").glob("*/*/entry.pkl"))
    assert len(entries) == 1
    entries[0].write_bytes(b"not a pickle")
    parts, _ = run_family("fin", default_params, cache)
    assert not any(b.cached for b in parts)


def test_recorded_keys_are_the_family_inputs(default_params, tmp_path):
    """The fin reads its own section and the print/export settings, and what the fastener plans read (the registry
    cuts every fastener's holes in every family's parts, so the layout the plans place them by is an input: a
    motor that moves a seam screw may move a hole). The gait enters only as the joints' stop angles (they set the
    joint gaps and so the hull pieces the plans place screws in): exactly the swimming keys those angles read.
    Never the water, the hydrodynamics, the rules or the power budget."""
    import json
    from swiftfin.layout.geometry import joint_stop_angles_rad
    cache = FamilyCache(tmp_path / "c")
    run_family("fin", default_params, cache)
    (keysets,) = [json.loads(f.read_text()) for f in (tmp_path / "c" / "fin").glob("*/keysets.json")]
    keys = set(keysets[0])
    assert "caudal_fin.span_mm" in keys and "export.mesh_tolerance_mm" in keys
    assert not any(k.startswith(("environment.", "hydro.", "rules.", "power.")) for k in keys)
    stop_reads: dict = {}
    joint_stop_angles_rad(RecordingParams(default_params, stop_reads))
    gait = {k for k in stop_reads if k.startswith("swimming.")}
    assert gait and {k for k in keys if k.startswith("swimming.")} == gait
    assert isinstance(RecordingParams(default_params, {}), Params)


def test_entries_of_an_older_source_are_deleted(default_params, tmp_path):
    cache = FamilyCache(tmp_path / "c")
    stale = tmp_path / "c" / "fin" / "0123456789abcdef0123456789abcdef"
    (stale / "x").mkdir(parents=True)
    run_family("fin", default_params, cache)
    assert not stale.exists()
    assert len(list((tmp_path / "c" / "fin").iterdir())) == 1
