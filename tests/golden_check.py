"""Golden values of the default design's parts (house style rule 8): volume and bounding box per part in
``tests/golden/<label>.json``, rewritten only on purpose with ``pytest --update-golden``."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

GOLDEN = Path(__file__).parent / "golden"


def precise_volume_mm3(solid) -> float:
    """B-rep volume by adaptive integration (eps 1e-6, :func:`exports.massprops.solid_volume_props`).
    ``Shape.volume`` uses a fixed-order rule that is off by up to 0.5 % on lofted B-spline solids."""
    from swiftfin.exports.massprops import solid_volume_props
    return solid_volume_props(solid).volume_mm3


def check_golden(label: str, solid, update: bool) -> None:
    bb = solid.bounding_box()
    now = {"volume_mm3": precise_volume_mm3(solid), "bbox_min_mm": list(bb.min), "bbox_max_mm": list(bb.max)}
    path = GOLDEN / f"{label}.json"
    if update:
        path.write_text(json.dumps(now, indent=1) + "\n")
        return
    assert path.exists(), f"no golden file {path.name}: run pytest --update-golden on purpose"
    ref = json.loads(path.read_text())
    assert now["volume_mm3"] == pytest.approx(ref["volume_mm3"], rel=1e-6)
    assert now["bbox_min_mm"] == pytest.approx(ref["bbox_min_mm"], abs=1e-4)
    assert now["bbox_max_mm"] == pytest.approx(ref["bbox_max_mm"], abs=1e-4)
