"""swiftfin/prefetch.py: the layer cores worked out beside the modelling are the ones the mass model then uses."""
from __future__ import annotations

import pytest

from swiftfin.cache import StageCache
from swiftfin.exports import massprops
from swiftfin.exports.robot import as_trimesh
from swiftfin.pipeline import STAGE_MODULES, run_family
from swiftfin.prefetch import Prefetch


@pytest.fixture(scope="module")
def guides(default_params):
    parts, _ = run_family("guide", default_params, None)       # the real family, exported, with content keys
    return parts


def _masses(p, built, memo):
    meshes = {b.spec.label: as_trimesh(b.export.mesh) for b in built}     # as exports/robot.py hands them
    return {m.label: m for m in massprops.mass_properties(p, [b.spec for b in built], meshes, memo=memo).parts
            if m.label in meshes}


def test_the_mass_model_takes_the_prefetched_cores_and_they_are_its_own(default_params, guides, tmp_path,
                                                                         monkeypatch):
    p = default_params
    pf = Prefetch(tmp_path, STAGE_MODULES["part_core"], jobs=2)
    if pf.pool is None:
        pytest.skip("no fork on this platform: nothing is prefetched")
    pf.parts(guides, p)
    assert pf.close() == sum(b.spec.printed for b in guides) == 4
    direct = _masses(p, guides, None)                          # computed here, no store

    def not_again(*a, **k):
        raise AssertionError("the mass model sliced a part whose core was prefetched")
    monkeypatch.setattr(massprops, "layer_core", not_again)
    memo = StageCache(tmp_path, STAGE_MODULES).memo({b.spec.label: b.content_sha256 for b in guides})
    stored = _masses(p, guides, memo)
    for label, m in direct.items():                            # the same numbers, to the last bit
        assert stored[label].volume_core_m3 == m.volume_core_m3 > 0
        assert stored[label].inertial.mass_kg == m.inertial.mass_kg
        assert stored[label].flags == m.flags


def test_a_failed_build_does_not_wait_for_the_queued_cores(default_params, guides, tmp_path):
    pf = Prefetch(tmp_path, STAGE_MODULES["part_core"], jobs=2)
    if pf.pool is None:
        pytest.skip("no fork on this platform: nothing is prefetched")
    pf.parts(guides * 20, default_params)                      # 80 jobs queued
    assert pf.close(cancel=True) == 0
    assert pf.pool is None


def test_one_job_means_no_worker(tmp_path):
    pf = Prefetch(tmp_path, STAGE_MODULES["part_core"], jobs=1)
    assert pf.pool is None and pf.close() == 0


def test_the_report_takes_the_prefetched_plots_and_they_are_its_own(default_params, tmp_path, monkeypatch):
    from swiftfin.cache import FamilyCache
    from swiftfin.prefetch import report_plots
    from swiftfin.report import html

    p = default_params
    pf = Prefetch(tmp_path, STAGE_MODULES["part_core"], jobs=2)
    if pf.pool is None:
        pytest.skip("no fork on this platform: nothing is prefetched")
    pf.plots(p)
    assert pf.close() == 1
    direct = html.standard_plots.__wrapped__(p)               # drawn here

    def not_again(*a, **k):
        raise AssertionError("the report drew plots the build's worker had drawn")
    monkeypatch.setattr(html.standard_plots, "__wrapped__", not_again)
    stored = report_plots(FamilyCache(tmp_path), p)
    assert [q.png for q in stored] == [q.png for q in direct]   # the same three pictures, byte for byte
