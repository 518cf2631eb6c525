"""The caudal fin's plan as numbers: the planform (span, chords, sweep, root station) and the root tang.
No CAD kernel: the hull, the mass model and the robot model read it; the solid is made by
:mod:`swiftfin.cad.fin` (whose docstring gives the geometry).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L

@dataclass(frozen=True)
class Planform:
    span_mm: float
    area_mm2: float
    root_chord_mm: float
    tip_chord_mm: float
    sweep_rad: float
    s_root_le_mm: float       # station of the root leading edge

    def chord_mm(self, eta):
        eta = np.clip(np.abs(np.asarray(eta, dtype=float)), 0.0, 1.0)
        return self.tip_chord_mm + (self.root_chord_mm - self.tip_chord_mm) * np.sqrt(1.0 - eta**2)

    def s_le_mm(self, eta):
        return self.s_root_le_mm + np.abs(np.asarray(eta, dtype=float)) * self.span_mm / 2 * math.tan(self.sweep_rad)


def planform(p: Params) -> Planform:
    f = p.caudal_fin
    b = f.span_mm
    S = b * b / f.aspect_ratio
    c_tip = 3 * f.min_thickness_mm
    c0 = c_tip + (S / b - c_tip) * 4 / math.pi
    if c0 <= c_tip:
        raise BuildError(f"caudal_fin: root chord {c0:.1f} mm not above the tip chord {c_tip:.1f} mm "
                         f"(span {b:g} mm, aspect ratio {f.aspect_ratio:g})")
    s_root = max(p.body.length_mm - c0, L.hull_end_mm(p) + p.print.clearance_assembly_mm)
    return Planform(b, S, c0, c_tip, math.radians(f.sweep_deg), s_root)


@dataclass(frozen=True)
class TangDims:
    thickness_mm: float       # along y
    height_mm: float          # along z
    s_front_mm: float         # front end of the tang (inside the peduncle)
    screw_station_mm: float
    screw_z_mm: tuple


def tang_dims_mm(p: Params) -> TangDims:
    """The root tang and its screws, sized from the peduncle's end section only.

    Thickness ``max(2 min_thickness_mm, w_end / 2)`` and height ``h_end`` (w_end, h_end: the hull's outer half-width
    and half-height at the hull end), so the slot leaves at least half the end section as wall. It reads no
    planform parameter: the hull (which cuts the slot) need not be rebuilt when the fin's span or shape
    changes. Only its rear end (30 % of the root chord into the blade) depends on the planform.
    """
    f = p.caudal_fin
    s_end = L.hull_end_mm(p)
    w_end = float(L.naca_half_width_mm(p, s_end))
    h_end = float(L.half_height_mm(p, s_end))
    thick = max(2 * f.min_thickness_mm, 0.5 * w_end)
    height = h_end
    return TangDims(thick, height, s_end - f.mount_length_mm, s_end - f.mount_length_mm / 2,
                    (height / 4, -height / 4))


def tang_back_station_mm(p: Params) -> float:
    """Rear end of the tang: 30 % of the root chord into the blade."""
    pf = planform(p)
    return pf.s_root_le_mm + 0.3 * pf.root_chord_mm
