"""How a component is held in its cradle, read from ``mounting.toml`` beside this module (sources named there):
``pad()``, the hook-and-loop pad it sits on. (The cradle's bond into the hull is an adhesive of ``adhesives.toml``.)"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class Pad:
    """A pad of hook-and-loop tape between a component and its cradle's floor."""
    description: str
    mated_thickness_mm: float
    areal_mass_g_cm2: float
    peel_strength_n_cm: float
    source: str


@cache
def _table() -> dict:
    with open(HERE / "mounting.toml", "rb") as fh:
        return tomllib.load(fh)


def pad() -> Pad:
    row = _table()["hook_and_loop"]
    return Pad(row["description"], float(row["mated_thickness_mm"]), float(row["areal_mass_g_cm2"]),
               float(row["peel_strength_n_cm"]), row["source"])

