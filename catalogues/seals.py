"""Seals (``seals.toml`` beside this module, sources there). Static O-ring face seals: the gland for a cord, and the
three numbers that judge an installed ring — squeeze, gland fill and stretch — with the limits they must meet. The
grease-packed cable gland (:func:`cable_gland`), and the other declared crossings of the dry wall
(:func:`seal_item`).

A printed groove is only as exact as the printer: :meth:`FaceGland.squeeze_range` gives the squeeze at the gland
depth +/- ``limits.print_tolerance_mm``, which is what the seal rule checks.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class SealLimits:
    squeeze_min_fraction: float
    squeeze_max_fraction: float
    fill_max_fraction: float
    stretch_max_fraction: float
    print_tolerance_mm: float


@dataclass(frozen=True)
class FaceGland:
    """A rectangular face-seal groove for one O-ring cord [mm]."""
    cord_mm: float
    depth_mm: float
    width_mm: float

    def squeeze(self, depth_mm: float | None = None) -> float:
        """(cord - gland depth) / cord [-]."""
        d = self.depth_mm if depth_mm is None else depth_mm
        return (self.cord_mm - d) / self.cord_mm

    def squeeze_range(self, tolerance_mm: float) -> tuple[float, float]:
        """Squeeze at the deepest and the shallowest groove the printer may make."""
        return self.squeeze(self.depth_mm + tolerance_mm), self.squeeze(self.depth_mm - tolerance_mm)

    def fill(self, depth_mm: float | None = None, width_mm: float | None = None) -> float:
        """Cord section / groove section [-]."""
        d = self.depth_mm if depth_mm is None else depth_mm
        w = self.width_mm if width_mm is None else width_mm
        return math.pi / 4 * self.cord_mm**2 / (d * w)


def stretch(ring_inner_length_mm: float, groove_inner_length_mm: float) -> float:
    """Stretch of a ring whose free inner circumference is ``ring_inner_length_mm`` when it lies against the inner
    wall of a groove of inner perimeter ``groove_inner_length_mm`` [-] (negative: it is compressed)."""
    return (groove_inner_length_mm - ring_inner_length_mm) / ring_inner_length_mm


@cache
def _table() -> dict:
    return tomllib.loads((HERE / "seals.toml").read_text(encoding="utf-8"))


def _row(cls, section: str):
    """The ``[section]`` table of seals.toml as ``cls``: numbers as floats, text as it stands."""
    return cls(**{k: (v if isinstance(v, str) else float(v)) for k, v in _table()[section].items()})


@cache
def seal_limits() -> SealLimits:
    return SealLimits(**{k: float(v) for k, v in _table()["limits"].items()})


@cache
def face_glands() -> tuple[FaceGland, ...]:
    return tuple(sorted((FaceGland(**{k: float(v) for k, v in row.items()})
                         for row in _table()["face_gland"].values()), key=lambda g: g.cord_mm))


def cord_diameters_mm() -> tuple[float, ...]:
    return tuple(g.cord_mm for g in face_glands())


def face_gland(cord_mm: float) -> FaceGland:
    for g in face_glands():
        if abs(g.cord_mm - cord_mm) < 1e-9:
            return g
    raise KeyError(f"no face gland for a {cord_mm:g} mm cord in catalogues/seals.toml (it holds "
                   f"{', '.join(f'{c:g}' for c in cord_diameters_mm())} mm)")


@dataclass(frozen=True)
class SeamGasket:
    """The seam gasket's sheet (``[seam_gasket]``): thickness, compression band, stiffness, density."""
    sheet_thickness_mm: float
    compression_min_fraction: float
    compression_max_fraction: float
    stress_at_25pct_kpa: float
    density_kg_m3: float
    min_width_thicknesses: float
    min_web_mm: float
    pressure_safety_factor: float
    sheet: str

    def limiter_length_mm(self) -> float:
        """The limiter that stops the faces at the middle of the compression band [mm]."""
        mid = 0.5 * (self.compression_min_fraction + self.compression_max_fraction)
        return self.sheet_thickness_mm * (1.0 - mid)

    def compression(self, gap_mm: float) -> float:
        """(free thickness - gap) / free thickness [-]."""
        return (self.sheet_thickness_mm - gap_mm) / self.sheet_thickness_mm

    def min_width_mm(self) -> float:
        return self.min_width_thicknesses * self.sheet_thickness_mm

    def compression_range(self, gap_mm: float, tolerance_mm: float) -> tuple[float, float]:
        """The least and most compression over a gap of ``gap_mm`` +/- ``tolerance_mm`` [-]."""
        return self.compression(gap_mm + tolerance_mm), self.compression(max(gap_mm - tolerance_mm, 0.0))

    def stress_kpa(self, compression: float) -> float:
        """Contact stress at ``compression`` [kPa]: linear through the table's point at 25 % (a closed-cell foam
        stiffens beyond its plateau, so this under-states the stress above 25 %: a seating check errs safe)."""
        return self.stress_at_25pct_kpa * compression / 0.25


def seam_gap_tolerance_mm() -> float:
    """What the seam gasket's gap may be off by: the limiter's cutting tolerance and each of the two printed faces
    +/- ``limits.print_tolerance_mm`` off flat (the worst case adds them) [mm]."""
    return compression_limiter().length_tolerance_mm + 2 * seal_limits().print_tolerance_mm


@cache
def seam_gasket() -> SeamGasket:
    return _row(SeamGasket, "seam_gasket")


@dataclass(frozen=True)
class CompressionLimiter:
    """The brass sleeve round each seam screw that sets the gasket's gap (``[compression_limiter]``)."""
    outer_diameter_mm: float
    inner_diameter_mm: float
    length_tolerance_mm: float
    density_kg_m3: float
    tube: str

    def mass_kg(self, length_mm: float) -> float:
        area = math.pi / 4 * (self.outer_diameter_mm**2 - self.inner_diameter_mm**2)
        return self.density_kg_m3 * area * length_mm * 1e-9


@cache
def compression_limiter() -> CompressionLimiter:
    return _row(CompressionLimiter, "compression_limiter")


@dataclass(frozen=True)
class CableGland:
    """The grease-packed cable gland of ``seals.toml`` (``[cable_gland]``)."""
    grease_yield_stress_pa: float
    pressure_safety_factor: float
    stroke_margin_mm: float
    sleeve_diametral_clearance_mm: float
    grease: str

    @property
    def radial_gap_mm(self) -> float:
        return self.sleeve_diametral_clearance_mm / 2


@cache
def cable_gland() -> CableGland:
    return _row(CableGland, "cable_gland")


@cache
def seal_item(kind: str) -> dict:
    """The row of a declared crossing of the dry wall (``bedded_screw``, ``bonded_seam``)."""
    return dict(_table()[kind])
