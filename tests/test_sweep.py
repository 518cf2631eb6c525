"""A seeded random sweep over the documented parameter ranges (house style rule 9).

Each sample changes a random subset of the schema's numeric keys to a value drawn uniformly from that key's
documented range. Every design the loader accepts must build every part family into valid single solids; every
design it refuses must be refused with problems that each name a key and what was expected. A part family may
still refuse an accepted design (a UserError), but only with a message that names the parameter to change.
"""
from __future__ import annotations

from dataclasses import fields

import numpy as np
import pytest

from swiftfin.cad.registry import FAMILIES, family_function
from swiftfin.layout.design import check_design
from swiftfin.core.errors import UserError
from swiftfin.core.params import ParamError, params_from_dict, to_dict
from swiftfin.core.schema import SECTIONS, Params

SEED = 20261121
N_BUILT = 3          # designs built in full (each builds all 36-ish parts)
SHARE_CHANGED = 0.12  # share of the numeric keys changed per sample


def _numeric_fields():
    out = []
    for section, cls in SECTIONS.items():
        for f in fields(cls):
            lo, hi = f.metadata.get("lo"), f.metadata.get("hi")
            if lo is None or hi is None or isinstance(f.default, (bool, str, tuple)) or f.metadata.get("choices"):
                continue
            out.append((section, f.name, isinstance(f.default, int), lo, hi))
    return out


def _sample(rng: np.random.Generator) -> dict:
    raw = to_dict(Params())
    for section, name, is_int, lo, hi in _numeric_fields():
        if rng.random() < SHARE_CHANGED:
            v = rng.uniform(lo, hi)
            raw[section][name] = int(round(v)) if is_int else float(v)
    return raw


@pytest.mark.slow
def test_seeded_sweep_over_documented_ranges():
    rng = np.random.default_rng(SEED)
    built, refused_by_loader, refused_by_family, attempts = [], 0, 0, 0
    while len(built) < N_BUILT:
        attempts += 1
        assert attempts < 2000, "the sweep could not find enough accepted designs"
        raw = _sample(rng)
        try:
            p = check_design(params_from_dict(raw, "sweep"), "sweep")
        except ParamError as err:
            assert err.problems, "a refusal must list its problems"
            for pr in err.problems:
                assert pr.key and pr.expected, f"unclear refusal: {pr}"
                assert "nan" not in str(pr).lower(), f"NaN in a refusal: {pr}"
            refused_by_loader += 1
            continue
        try:
            parts = [part for name in FAMILIES for part in family_function(name)(p)]
        except UserError as err:
            msg = str(err)
            assert "_mm" in msg or "." in msg, f"family refusal without a parameter to change: {msg}"
            refused_by_family += 1
            continue
        labels = [part.label for part in parts]
        assert len(labels) == len(set(labels)), "part labels must be unique"
        for part in parts:
            solid = part.solid
            assert solid.is_valid, f"{part.label} is not a valid solid in an accepted design"
            assert len(solid.solids()) == 1, f"{part.label} is {len(solid.solids())} solids"
            assert solid.volume > 0, part.label
        built.append(len(parts))
    # the sweep must really explore: some designs refused, some built
    assert refused_by_loader > 0
    print(f"sweep (seed {SEED}): {attempts} designs drawn, {refused_by_loader} refused by the loader, "
          f"{refused_by_family} refused by a part family, {len(built)} built ({built} parts)")
