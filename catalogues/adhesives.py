"""Adhesives for bonded bought parts, read from ``adhesives.toml`` beside this module (sources named there):
``adhesive("epoxy_etched_ptfe").allowable_shear_mpa``."""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Adhesive:
    name: str
    description: str
    lap_shear_mpa: float
    design_fraction: float
    source: str

    @property
    def allowable_shear_mpa(self) -> float:
        """Mean shear stress a bench-made bond may be loaded with [MPa]."""
        return self.lap_shear_mpa * self.design_fraction


@cache
def adhesives() -> tuple[Adhesive, ...]:
    rows = tomllib.loads((HERE / "adhesives.toml").read_text(encoding="utf-8"))
    return tuple(Adhesive(name, row["description"], float(row["lap_shear_mpa"]), float(row["design_fraction"]),
                          row["source"]) for name, row in rows.items())


def adhesive(name: str) -> Adhesive:
    return by_name(adhesives(), name, "adhesive", "adhesives.toml")
