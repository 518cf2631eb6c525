"""The caudal fin's plan as numbers: the planform (span, chords, sweep, root station), the root tang and the
screws that hold it (:func:`fin_fasteners`, registered in ``cad/fastening.py``). No CAD kernel: the hull, the mass
model and the robot model read it; the solid is made by :mod:`swiftfin.cad.fin` (whose docstring gives the
geometry and argues the root joint).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.fastening import Fastener

ROOT_SCREW_FRACTIONS = (0.25, 0.75)
"""Stations of the two root screws, as fractions of the tang's length in the socket from its front end: as far
apart along the body as the holes' walls allow, so the pair takes the fin's bending moment as a couple."""

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
    screw_stations_mm: tuple  # the two root screw stations (nose to tail)
    screw_z_mm: tuple         # heights of the screws: (upper half, lower half)
    fit_clearance_mm: float   # socket - tang, on each side (y and z)


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
    s_front = s_end - f.mount_length_mm
    cb = fastener(p.hull.screw_diameter_mm).counterbore_diameter_mm
    # each screw in one half, its counterbore keeping two perimeters (and 0.1 mm) from the seam plane z = 0
    z = max(height / 4, cb / 2 + 2 * p.print.line_width_mm + 0.1)
    return TangDims(thick, height, s_front, tuple(s_front + k * f.mount_length_mm for k in ROOT_SCREW_FRACTIONS),
                    (z, -z), f.root_fit_clearance_mm)


def tang_back_station_mm(p: Params) -> float:
    """Rear end of the tang: 30 % of the root chord into the blade."""
    pf = planform(p)
    return pf.s_root_le_mm + 0.3 * pf.root_chord_mm


def fin_fasteners(p: Params) -> tuple[Fastener, ...]:
    """The root screws: at each of the two stations one in each hull half, from the +y side (head in a counterbore
    of the peduncle's wall) into a thread formed in the tang, which they draw onto the socket's +y face. The
    length is the longest catalogue screw whose head sinks below the skin and whose tip stays 0.5 mm inside the
    tang with 1.5 d of thread in it; the same length at both stations. The pilot runs through the tang (a blind
    one would leave a floor thinner than a line under the tip)."""
    from swiftfin.layout.hull_plan import hull_pieces, hull_section_semi_axes_mm, part_label
    td = tang_dims_mm(p)
    s = fastener(p.hull.screw_diameter_mm)
    tail = next(pc for pc in hull_pieces(p) if pc.tail)
    r_cb = s.counterbore_diameter_mm / 2
    rooms = []
    for st in td.screw_stations_mm:
        a, b = hull_section_semi_axes_mm(p, st + r_cb)            # the narrower end of the counterbore
        z = abs(td.screw_z_mm[0]) + r_cb
        y_skin = a * math.sqrt(max(0.0, 1 - (z / b) ** 2))         # innermost skin point over the counterbore
        rooms.append(y_skin - s.counterbore_depth_mm - 0.1 - td.thickness_mm / 2)   # head face -> tang face
    engage_max = td.thickness_mm - 0.5
    length = s.length_at_most(min(rooms) + engage_max)
    grip = None if length is None else length - max(s.engagement_min_mm, length - min(rooms))
    if length is None or grip < td.fit_clearance_mm + 2 * p.print.line_width_mm or length - grip > engage_max:
        raise BuildError(f"caudal_fin: no {s.name} screw fits the root (room {min(rooms):.2f} mm to the tang, tang "
                         f"{td.thickness_mm:.2f} mm thick)")
    out = []
    for i, st in enumerate(td.screw_stations_mm):
        a, b = hull_section_semi_axes_mm(p, st)
        for z, half in zip(td.screw_z_mm, ("upper", "lower")):
            y_head = td.thickness_mm / 2 + grip
            y_axis_skin = a * math.sqrt(max(0.0, 1 - (abs(z) / b) ** 2))
            out.append(Fastener(f"caudal_fin_root_{i + 1}_{half}", s.name, "cap_screw", "self_tap",
                                (-st, y_head, z), (0.0, -1.0, 0.0), length, grip, part_label(p, tail, half),
                                "caudal_fin", "holds the caudal fin's root tang in the peduncle", p.joints.count,
                                recess_mm=y_axis_skin - y_head,
                                pilot_past_tip_mm=y_head - length + td.thickness_mm / 2))
    return tuple(out)
