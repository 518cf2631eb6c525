"""Printable materials (``materials.toml`` beside this module, sources named there): ``material("PLA")``."""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Material:
    name: str
    density_kg_m3: float
    heat_deflection_temperature_c: float
    thermal_conductivity_w_m_k: float


@cache
def materials() -> tuple[Material, ...]:
    rows = tomllib.loads((HERE / "materials.toml").read_text(encoding="utf-8"))
    return tuple(Material(name, **{k: float(v) for k, v in row.items()}) for name, row in rows.items())


def material_names() -> tuple[str, ...]:
    return tuple(m.name for m in materials())


def material(name: str) -> Material:
    return by_name(materials(), name, "material", "materials.toml")
