"""Trim ballast fills, read from ``ballast.toml`` beside this module (sources named there):
``ballast_fill("lead_shot_epoxy").density_kg_m3(11340.0)``."""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class BallastFill:
    name: str
    description: str
    packing_fraction: float          # of the fill's volume that is lead [-]
    shot_diameter_mm: float
    binder_density_kg_m3: float
    source: str

    def density_kg_m3(self, lead_density_kg_m3: float) -> float:
        """The cured fill's density: lead in the packed fraction, binder in the voids [kg/m^3]."""
        phi = self.packing_fraction
        return phi * lead_density_kg_m3 + (1.0 - phi) * self.binder_density_kg_m3

    def lead_fraction(self, lead_density_kg_m3: float) -> float:
        """Of the fill's mass, the fraction that is lead (what the builder weighs out) [-]."""
        return self.packing_fraction * lead_density_kg_m3 / self.density_kg_m3(lead_density_kg_m3)


@cache
def ballast_fills() -> tuple[BallastFill, ...]:
    rows = tomllib.loads((HERE / "ballast.toml").read_text(encoding="utf-8"))
    return tuple(BallastFill(name, r["description"], float(r["packing_fraction"]), float(r["shot_diameter_mm"]),
                             float(r["binder_density_kg_m3"]), r["source"]) for name, r in rows.items())


def ballast_fill(name: str = "lead_shot_epoxy") -> BallastFill:
    return by_name(ballast_fills(), name, "ballast fill", "ballast.toml")
