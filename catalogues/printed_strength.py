"""Sustained-load strength of printed parts in screwed joints (``printed_strength.toml`` beside this module, sources
named there): ``printed_strength("PLA").bearing_allowable_mpa``."""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class PrintedStrength:
    name: str
    tensile_yield_mpa: float
    sustained_fraction: float

    @property
    def bearing_allowable_mpa(self) -> float:
        """Mean pressure a shank or an insert may hold on a printed hole's wall under a held load [MPa]."""
        return self.tensile_yield_mpa * self.sustained_fraction

    @property
    def bending_allowable_mpa(self) -> float:
        """Bending stress a printed section may take stroke after stroke along its layers [MPa]: the held-load
        figure above. The catalogue has no fatigue data; the held-load fraction stands in for it (a load repeated
        millions of times, as the fin's at the tail-beat frequency, is no kinder to a thermoplastic than one held)."""
        return self.bearing_allowable_mpa

    @property
    def shear_allowable_mpa(self) -> float:
        """Shear stress a printed wall may hold under a held load (pull-out, pull-through) [MPa]: half the above."""
        return 0.5 * self.bearing_allowable_mpa


@cache
def printed_strengths() -> tuple[PrintedStrength, ...]:
    rows = tomllib.loads((HERE / "printed_strength.toml").read_text(encoding="utf-8"))
    return tuple(PrintedStrength(name, **{k: float(v) for k, v in row.items()}) for name, row in rows.items())


def printed_strength(name: str) -> PrintedStrength:
    for m in printed_strengths():
        if m.name == name:
            return m
    raise KeyError(f"no material {name!r} in catalogues/printed_strength.toml "
                   f"(it holds {', '.join(m.name for m in printed_strengths())})")
