"""Crimp sleeves for cable ends, read from ``cable_parts.toml`` beside this module (each column's source is named
in the file).

``crimp_sleeve(1.0)`` gives the :class:`CrimpSleeve` for a 1.0 mm cable: the smallest sleeve whose row takes a
cable at least that thick (a thinner cable in a larger sleeve crimps; a thicker one does not fit). A cable
thicker than every row raises :class:`KeyError` naming the sizes the table holds.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class CrimpSleeve:
    """A single-barrel crimp sleeve [mm]."""
    cable_diameter_mm: float
    bore_mm: float
    outer_diameter_mm: float
    length_mm: float
    crimped_outer_diameter_mm: float
    holding_fraction: float

    def seat_diameter_mm(self, clearance_mm: float) -> float:
        """Diameter of a counterbore the crimped sleeve drops into: its crimped width and the clearance each side."""
        return self.crimped_outer_diameter_mm + 2 * clearance_mm


@cache
def _table() -> tuple[CrimpSleeve, ...]:
    with open(HERE / "cable_parts.toml", "rb") as fh:
        raw = tomllib.load(fh)
    rows = [CrimpSleeve(**{k: float(v) for k, v in row.items()}) for row in raw.values()]
    return tuple(sorted(rows, key=lambda r: r.cable_diameter_mm))


def crimp_sleeve(cable_diameter_mm: float) -> CrimpSleeve:
    for row in _table():
        if row.cable_diameter_mm >= cable_diameter_mm - 1e-9:
            return row
    raise KeyError(f"no crimp sleeve for a {cable_diameter_mm:g} mm cable in catalogues/cable_parts.toml "
                   f"(rows: {', '.join(f'{r.cable_diameter_mm:g}' for r in _table())} mm)")
