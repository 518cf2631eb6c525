"""Leads inside the dry head (motor and battery), read from ``wiring.toml`` beside this module (sources named there):
``lead("motor_lead").bundle_diameter_mm``."""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from swiftfin.catalogues.table import by_name

HERE = Path(__file__).resolve().parent

BUNDLE_FACTOR = {1: 1.0, 2: 2.0, 3: 1.0 + 2.0 / math.sqrt(3.0), 4: 1.0 + math.sqrt(2.0)}
"""Diameter of the least circle round n equal round wires / the wire's diameter [-] (wiring.toml names the source)."""


@dataclass(frozen=True)
class Lead:
    name: str
    description: str
    wires: int
    wire_od_mm: float
    conductor_area_mm2: float
    exit_height_mm: float         # where it leaves its component, above the component's back face [mm]
    exit_proud_mm: float          # the strain relief (or the battery snap) it leaves through, proud of the face [mm]
    connector: str
    conductor_density_kg_m3: float
    insulation_density_kg_m3: float
    min_bend_wire_ods: float
    termination_mm: float
    service_fraction: float

    @property
    def bundle_diameter_mm(self) -> float:
        """The circle that holds the lead's wires [mm]."""
        return BUNDLE_FACTOR[self.wires] * self.wire_od_mm

    @property
    def min_bend_radius_mm(self) -> float:
        """Least bend radius of the lead's centre line: its innermost wire at ``min_bend_wire_ods`` x its OD [mm]."""
        return self.min_bend_wire_ods * self.wire_od_mm + (self.bundle_diameter_mm - self.wire_od_mm) / 2

    @property
    def linear_density_kg_m(self) -> float:
        """Copper and insulation of all its wires, per metre [kg/m]."""
        wire_area = math.pi / 4 * self.wire_od_mm**2
        per_wire = (self.conductor_area_mm2 * self.conductor_density_kg_m3
                    + (wire_area - self.conductor_area_mm2) * self.insulation_density_kg_m3) * 1e-6
        return self.wires * per_wire


@cache
def leads() -> tuple[Lead, ...]:
    rows = tomllib.loads((HERE / "wiring.toml").read_text(encoding="utf-8"))
    common = rows.pop("common")
    shared = {k: float(common[k]) for k in ("conductor_density_kg_m3", "insulation_density_kg_m3",
                                             "min_bend_wire_ods", "termination_mm", "service_fraction")}
    return tuple(Lead(name, r["description"], int(r["wires"]), float(r["wire_od_mm"]), float(r["conductor_area_mm2"]),
                      float(r["exit_height_mm"]), float(r["exit_proud_mm"]), r["connector"], **shared)
                 for name, r in rows.items())


def lead(name: str) -> Lead:
    return by_name(leads(), name, "lead", "wiring.toml")
