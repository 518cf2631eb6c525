"""Cables (the tendons), read from ``cables.toml`` beside this module (every number's source is in the file).

``cable_spec("braided nylon 1 mm")`` gives the :class:`CableSpec`; ``cable_params(name)`` the keys of a design's
``[cable]`` section the entry fills, and :meth:`CableSpec.missing` those a design naming it must still give. A
cable's breaking strength and effective modulus depend on its construction: entries that hold only the fibre
maker's figures (``fibre_*``, as (low, high) ranges) fill nothing the rules read.

The lowest layer: it reads its own data file and imports nothing else of swiftfin.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, field, fields
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name, is_positive_number

HERE = Path(__file__).resolve().parent

#: The entry's fields a design's ``[cable]`` section takes under the same name.
PARAM_KEYS = ("material", "diameter_mm", "breaking_strength_n", "youngs_modulus_gpa", "creep_allowance_fraction",
              "linear_density_g_m", "bending_stiffness_n_m2")
#: What the design rules need of a cable (the rest have defaults that do not depend on the product).
RULE_KEYS = ("diameter_mm", "breaking_strength_n", "youngs_modulus_gpa")


@dataclass(frozen=True)
class CableSpec:
    """One cable or fibre (SI unless the name says otherwise; None: not published or not traced to a source)."""
    name: str
    material: str
    diameter_mm: float | None = None
    breaking_strength_n: float | None = None
    youngs_modulus_gpa: float | None = None          # effective, on the full section
    creep_allowance_fraction: float | None = None
    linear_density_g_m: float | None = None
    bending_stiffness_n_m2: float | None = None
    fibre_tensile_modulus_gpa: tuple | None = None   # (low, high), the fibre's, not the cable's
    fibre_tenacity_n_tex: tuple | None = None
    fibre_tensile_strength_gpa: tuple | None = None
    fibre_elongation_at_break_fraction: tuple | None = None
    sources: dict = field(default_factory=dict)

    def params(self) -> dict:
        """The ``[cable]`` keys this entry gives, with their values."""
        return {k: getattr(self, k) for k in PARAM_KEYS if getattr(self, k) is not None}

    def missing(self) -> tuple[str, ...]:
        """The ``[cable]`` keys the rules read that this entry does not give (a design naming it must)."""
        return tuple(k for k in RULE_KEYS if getattr(self, k) is None)


_RANGES = tuple(f.name for f in fields(CableSpec) if f.name.startswith("fibre_"))
_NUMBERS = tuple(f.name for f in fields(CableSpec)
                 if f.name not in ("name", "material", "sources") and f.name not in _RANGES)


@cache
def cables() -> tuple[CableSpec, ...]:
    """Every entry of ``cables.toml``. Raises ValueError listing every malformed one (a number without a source,
    an unknown field, a value that is not positive, a range whose ends are out of order)."""
    raw = tomllib.loads((HERE / "cables.toml").read_text(encoding="utf-8"))
    out, problems = [], []
    for name, row in raw.items():
        row = dict(row)
        sources = row.pop("sources", {})
        kw = {}
        for k, v in row.items():
            if k == "material":
                kw[k] = str(v)
            elif k in _NUMBERS:
                if not is_positive_number(v):
                    problems.append(f"[{name}] {k} = {v!r}: expected a positive number")
                kw[k] = float(v) if isinstance(v, (int, float)) else v
            elif k in _RANGES:
                if not (isinstance(v, list) and len(v) == 2 and all(isinstance(x, (int, float)) and x > 0 for x in v)
                        and v[0] <= v[1]):
                    problems.append(f"[{name}] {k} = {v!r}: expected [low, high], positive numbers")
                kw[k] = tuple(float(x) for x in v) if isinstance(v, list) else v
            else:
                problems.append(f"[{name}] unknown field {k!r}")
                continue
            if k not in sources:
                problems.append(f"[{name}] {k} has no source in [{name}.sources]")
        if "material" not in kw:
            problems.append(f"[{name}] needs a material")
        if not problems:
            out.append(CableSpec(name, sources=dict(sources), **kw))
    if problems:
        raise ValueError("catalogues/cables.toml: " + "; ".join(problems))
    return tuple(out)


def cable_names() -> tuple[str, ...]:
    return tuple(c.name for c in cables())


def cable_spec(name: str) -> CableSpec:
    return by_name(cables(), name, "cable", "cables.toml")


def cable_params(name: str) -> dict:
    """The ``[cable]`` keys the catalogue entry ``name`` fills (see :data:`PARAM_KEYS`)."""
    return cable_spec(name).params()
