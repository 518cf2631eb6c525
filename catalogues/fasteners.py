"""Metric screws, nuts, heat-set inserts, dowel pins and retaining clips, read from ``fasteners.toml`` and
``pins.toml`` beside this module (each column's source is named in the file).

``fastener(2.0)`` or ``fastener("M2")`` gives one :class:`ScrewSize`; ``dowel(3.0)`` a :class:`Dowel`;
``eclip_for_pin(3.0)`` the DIN 6799 clip for a pin. Lookups of a size the tables do not hold raise
:class:`KeyError` naming what they hold (the parameter schema offers only these sizes, so a design never gets
there).
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

HERE = Path(__file__).resolve().parent

INSERT_POCKET_EXTRA_MM = 0.5
"""Heat-set insert pocket depth beyond the insert's length [mm]: room for the plastic it displaces
(CNC Kitchen / Ruthex installation notes)."""
INSERT_WALL_FRACTION = 0.4
"""Wall round a heat-set insert / insert outer diameter [-]: Secam's design guide asks 0.25-0.9 x OD in
commodity plastics; 0.4 chosen."""
NUT_TRAP_CLEARANCE_MM = 0.3
"""Nut trap across flats and depth beyond the nut [mm]: a printed hex pocket the nut drops into by hand."""
STEEL_DENSITY_KG_M3 = 7850.0
"""Screws, nuts and dowel pins [kg/m^3]: carbon and alloy steel (ISO 4762 class 12.9, ISO 8734), EN 10025 7850;
A2 stainless is 7900."""
BRASS_DENSITY_KG_M3 = 8470.0
"""Heat-set inserts [kg/m^3]: CW614N (CuZn39Pb3) free-machining brass datasheets, 8.47 g/cm^3."""
INSERT_SOLID_FRACTION = 0.85
"""Metal of a knurled insert / the annulus between its thread and its outer diameter [-]: the knurl's grooves and
the thread's flanks take an estimated 15 % (engineering estimate, not weighed: weigh yours)."""
THREAD_ENGAGEMENT_MIN_D = 1.5
"""Least thread engagement / nominal diameter for a screw into plastic or a brass insert's length limit
[-] (issue 12; VDI 2230 asks 0.8-1 d in steel nuts, printed threads and self-tapped holes need more)."""


@dataclass(frozen=True)
class ScrewSize:
    """One metric thread size: the screw, its nut, its insert and its holes [mm]."""
    name: str
    nominal_diameter_mm: float
    pitch_mm: float
    clearance_hole_mm: float
    head_diameter_mm: float
    head_height_mm: float
    counterbore_diameter_mm: float
    hex_key_mm: float
    key_reach_diameter_mm: float
    pilot_hole_mm: float
    insert_hole_mm: float
    insert_length_mm: float
    insert_outer_diameter_mm: float
    nut_width_across_flats_mm: float
    nut_height_mm: float
    washer_outer_diameter_mm: float
    washer_thickness_mm: float
    lengths_mm: tuple[float, ...]
    set_screw_lengths_mm: tuple[float, ...]

    @property
    def counterbore_depth_mm(self) -> float:
        """Head height plus 0.2 mm: the head sits just below the surface."""
        return self.head_height_mm + 0.2

    @property
    def insert_pocket_depth_mm(self) -> float:
        return self.insert_length_mm + INSERT_POCKET_EXTRA_MM

    @property
    def insert_wall_min_mm(self) -> float:
        return INSERT_WALL_FRACTION * self.insert_outer_diameter_mm

    def insert_boss_od_mm(self, line_width_mm: float, perimeters: float = 2.0) -> float:
        """Least outer diameter of a boss holding this size's insert: the insert hole plus, on each side, the
        larger of ``perimeters`` extrusion lines and the insert maker's wall."""
        return self.insert_hole_mm + 2 * max(perimeters * line_width_mm, self.insert_wall_min_mm)

    @property
    def nut_trap_width_mm(self) -> float:
        """Across flats of a hexagonal nut trap."""
        return self.nut_width_across_flats_mm + NUT_TRAP_CLEARANCE_MM

    @property
    def nut_trap_depth_mm(self) -> float:
        return self.nut_height_mm + NUT_TRAP_CLEARANCE_MM

    @property
    def engagement_min_mm(self) -> float:
        return THREAD_ENGAGEMENT_MIN_D * self.nominal_diameter_mm

    def screw_mass_kg(self, length_mm: float, set_screw: bool = False) -> float:
        """A steel screw of this size: the threaded shank as a cylinder of the pitch diameter (d - 0.6495 P, ISO
        724), and for a cap screw the head (ISO 4762 dk x k) less its hex socket (key across flats, half the head
        deep) [kg]."""
        dp = self.nominal_diameter_mm - 0.6495 * self.pitch_mm
        v = math.pi / 4 * dp**2 * length_mm
        if not set_screw:
            v += (math.pi / 4 * self.head_diameter_mm**2 * self.head_height_mm
                  - math.sqrt(3) / 2 * self.hex_key_mm**2 * self.head_height_mm / 2)
        return v * 1e-9 * STEEL_DENSITY_KG_M3

    @property
    def insert_mass_kg(self) -> float:
        v = math.pi / 4 * (self.insert_outer_diameter_mm**2 - self.nominal_diameter_mm**2) * self.insert_length_mm
        return INSERT_SOLID_FRACTION * v * 1e-9 * BRASS_DENSITY_KG_M3

    @property
    def nut_mass_kg(self) -> float:
        v = (math.sqrt(3) / 2 * self.nut_width_across_flats_mm**2
             - math.pi / 4 * self.nominal_diameter_mm**2) * self.nut_height_mm
        return v * 1e-9 * STEEL_DENSITY_KG_M3

    def length_for(self, need_mm: float, set_screw: bool = False) -> float | None:
        """Shortest catalogue length >= ``need_mm`` (None if even the longest is too short)."""
        offer = self.set_screw_lengths_mm if set_screw else self.lengths_mm
        return next((float(x) for x in offer if x >= need_mm - 1e-9), None)

    def length_at_most(self, limit_mm: float, set_screw: bool = False) -> float | None:
        """Longest catalogue length <= ``limit_mm`` (None if even the shortest is too long)."""
        offer = self.set_screw_lengths_mm if set_screw else self.lengths_mm
        fits = [float(x) for x in offer if x <= limit_mm + 1e-9]
        return fits[-1] if fits else None


@dataclass(frozen=True)
class Dowel:
    """ISO 8734 hardened dowel pin (m6)."""
    diameter_mm: float
    tolerance_mm: tuple[float, float]     # (lower, upper) deviation of the pin from nominal
    lengths_mm: tuple[float, ...]
    reamed_bore_tolerance_mm: tuple[float, float]   # ISO 286 H7 for this diameter
    ream_stock_mm: float

    def radial_play_mm(self) -> tuple[float, float]:
        """(least, greatest) radial play of this pin in a bore reamed to H7 of its nominal size [mm]; a negative
        least play is a light interference (a transition fit)."""
        lo = (self.reamed_bore_tolerance_mm[0] - self.tolerance_mm[1]) / 2
        hi = (self.reamed_bore_tolerance_mm[1] - self.tolerance_mm[0]) / 2
        return lo, hi

    def mass_kg(self, length_mm: float) -> float:
        return math.pi / 4 * self.diameter_mm**2 * length_mm * 1e-9 * STEEL_DENSITY_KG_M3

    def length_for(self, need_mm: float) -> float | None:
        return next((float(x) for x in self.lengths_mm if x >= need_mm - 1e-9), None)

    def length_at_most(self, limit_mm: float) -> float | None:
        fits = [float(x) for x in self.lengths_mm if x <= limit_mm + 1e-9]
        return fits[-1] if fits else None


@dataclass(frozen=True)
class EClip:
    """DIN 6799 retaining washer (E-clip)."""
    groove_diameter_mm: float
    groove_width_mm: float
    outer_diameter_mm: float
    shaft_range_mm: tuple[float, float]


@cache
def _table(name: str) -> dict:
    return tomllib.loads((HERE / name).read_text(encoding="utf-8"))


@cache
def screw_sizes() -> tuple[ScrewSize, ...]:
    """Every thread size of the table, smallest first."""
    out = []
    for name, row in _table("fasteners.toml").items():
        row = dict(row)
        row["lengths_mm"] = tuple(float(x) for x in row["lengths_mm"])
        row["set_screw_lengths_mm"] = tuple(float(x) for x in row["set_screw_lengths_mm"])
        out.append(ScrewSize(name=name, **row))
    return tuple(sorted(out, key=lambda s: s.nominal_diameter_mm))


def screw_diameters_mm() -> tuple[float, ...]:
    """The nominal diameters the table holds (the parameter schema's choices for every screw)."""
    return tuple(s.nominal_diameter_mm for s in screw_sizes())


def fastener(size: str | float) -> ScrewSize:
    """The row for ``"M3"`` or ``3.0``."""
    for s in screw_sizes():
        if s.name == size or (not isinstance(size, str) and abs(s.nominal_diameter_mm - float(size)) < 1e-9):
            return s
    raise KeyError(f"no screw {size!r} in catalogues/fasteners.toml (it holds "
                   f"{', '.join(s.name for s in screw_sizes())})")


@cache
def dowels() -> tuple[Dowel, ...]:
    t = _table("pins.toml")
    rb = t["reamed_bore"]
    out = []
    for row in t["dowel"].values():
        d = float(row["diameter_mm"])
        tol = rb["tolerance_small_mm"] if d <= 3 else rb["tolerance_large_mm"] if d <= 6 else rb["tolerance_xlarge_mm"]
        out.append(Dowel(d, tuple(row["tolerance_mm"]), tuple(float(x) for x in row["lengths_mm"]),
                         tuple(tol), float(rb["ream_stock_mm"])))
    return tuple(sorted(out, key=lambda x: x.diameter_mm))


def dowel_diameters_mm() -> tuple[float, ...]:
    return tuple(d.diameter_mm for d in dowels())


def dowel(diameter_mm: float) -> Dowel:
    for d in dowels():
        if abs(d.diameter_mm - float(diameter_mm)) < 1e-9:
            return d
    raise KeyError(f"no dowel pin of {diameter_mm:g} mm in catalogues/pins.toml (it holds "
                   f"{', '.join(f'{d:g}' for d in dowel_diameters_mm())} mm)")


@cache
def eclips() -> tuple[EClip, ...]:
    return tuple(sorted((EClip(float(r["groove_diameter_mm"]), float(r["groove_width_mm"]),
                               float(r["outer_diameter_mm"]), tuple(r["shaft_range_mm"]))
                         for r in _table("pins.toml")["eclip"].values()), key=lambda c: c.groove_diameter_mm))


def eclip_for_pin(pin_diameter_mm: float) -> EClip:
    """The DIN 6799 clip whose shaft range holds the pin (the smaller clip at a shared bound)."""
    for c in eclips():
        if c.shaft_range_mm[0] < pin_diameter_mm <= c.shaft_range_mm[1] + 1e-9:
            return c
    raise KeyError(f"no DIN 6799 clip for a {pin_diameter_mm:g} mm pin in catalogues/pins.toml")
