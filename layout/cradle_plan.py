"""Cradles for the components as numbers: where each bought box of ``params.components`` (battery, electronics)
sits, the printed cradle under it and what holds them, in the body frame at rest (mm). No CAD kernel.

Each component sits in a **cradle**: a block bonded with epoxy into the hull's lower half along its whole underside,
which follows the shell's inner surface (the inner ellipse shrunk by :func:`bond_gap_mm`, so the bond is a touch and
not an overlap), with a **pocket** on top that takes the component's lower part:

* along x and y the pocket is the component's footprint plus ``print.clearance_sliding_mm`` a side, walled by
  :data:`WALL_LINES` extrusion lines on three sides (both flanks and the aft end, which the fish's forward
  acceleration pushes the component against; the fore end is open above the floor, so the cradle printed on its aft
  end has no ceiling: an end wall over the pocket would bridge its whole width, 23.5 mm on the battery's), up to
  :data:`WALL_HEIGHT_FRACTION` of the component's height above its underside (at most :data:`WALL_HEIGHT_MAX_MM`):
  the walls locate it, its top stays free for its wires;
* along z the component sits on a pad of self-adhesive hook-and-loop tape (``catalogues/mounting.toml``), so the
  pocket's floor lies the pad's engaged thickness under the component's underside. The pad holds it down and lets it
  be pulled out (a battery must come out to be charged or swapped).

Under the floor a **lightening channel** runs through the cradle from end to end, as wide as the pocket, leaving
:data:`WALL_LINES` lines of wall over the shell and under the floor (:attr:`Cradle.channel_inset_mm`): a solid block
there would be a lens of sparse infill whose core, 53-89 mm^2 a layer on the battery's cradle, straddles the area
under which PrusaSlicer prints solid (``solid_infill_below_area``, 70 mm^2), and the plastic it weighs displaces trim
lead. Printed on an end, the channel stands upright and needs no support.

The floor must keep two perimeters (``rules.wall_min_line_widths`` lines) over the shell everywhere under the pocket,
and the cradle must lie in one hollow (no bulkhead under it; across a station splice of one link it rests on both
pieces and is bonded to both). A component too low for that, or outside every
hollow, is refused when the design loads, naming ``components[i]`` and the value that would do.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from swiftfin.catalogues.mounting import pad
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.hull_plan import cavity_range_mm, hull_pieces, hull_section_semi_axes_mm, part_label

WALL_LINES = 4
"""Extrusion lines in a cradle's walls [-]: twice the two-perimeter minimum, for a wall that locates a component of
tens of grams under a few g of handling. Engineering default."""
WALL_HEIGHT_FRACTION = 0.5
"""The walls rise this fraction of the component's height above its underside [-]. Engineering default."""
WALL_HEIGHT_MAX_MM = 10.0
"""... and no more than this [mm]: enough to locate it, the rest of it stays reachable. Engineering default."""
PLACEHOLDERS = ("fasteners",)
"""Component names that are mass placeholders (no box to hold): they get no cradle."""
FLOOR_SAMPLES = 41
"""Stations and widths at which the floor's least thickness over the shell is sampled."""


@dataclass(frozen=True)
class Cradle:
    label: str                      # cradle_<component>
    component: str
    index: int                      # in params.components
    link: int
    piece: str                      # the hull piece under the component's centre
    bonded_to: tuple                # the printed parts it is bonded into (the lower halves under it: two across a
    #                                 station splice)
    x_mm: tuple                     # (x lo, x hi) of the cradle (end walls included)
    pocket_x_mm: tuple              # (x lo, x hi) of the pocket
    pocket_half_width_mm: float
    half_width_mm: float            # walls included
    z_floor_mm: float               # the pocket's floor (the pad's underside)  } standing: as they are; hanging
    z_top_mm: float                 # the walls' top                            } (``hangs``): mirrored, z -> -z
    hangs: bool                     # under the upper half's ceiling (the component's centre above the seam plane)
    bond_gap_mm: float              # the underside stands this far inside the shell's inner surface
    pad_mm: float
    floor_min_mm: float             # least floor over the shell under the pocket (measured on the numbers)
    component_size_mm: tuple
    component_mass_kg: float
    channel_inset_mm: float = 0.0   # the lightening channel's walls over the shell and under the floor (0: none)

    @property
    def footprint_mm2(self) -> float:
        """The underside's projection on the xy plane: the bonded area's lower bound (the shell curves up)."""
        return (self.x_mm[1] - self.x_mm[0]) * 2 * self.half_width_mm


def bond_gap_mm(p: Params) -> float:
    """The glue line: half the sliding clearance (as the flotation blocks'), so bonding is a touch, not an overlap."""
    return 0.5 * p.print.clearance_sliding_mm


def wall_mm(p: Params) -> float:
    return WALL_LINES * p.print.line_width_mm


def inner_semi_axes_mm(p: Params, s_mm: float, gap_mm: float = 0.0) -> tuple[float, float]:
    """Half-width and half-height of the shell's inner surface at station s, shrunk by ``gap_mm`` [mm]."""
    a, b = hull_section_semi_axes_mm(p, s_mm)
    t = p.hull.wall_thickness_mm + gap_mm
    return a - t, b - t


def _hollow(p: Params, s0: float, s1: float):
    """The pieces whose hollows together hold [s0, s1] without a gap (one link), or None."""
    pieces = [(pc, *cavity_range_mm(p, pc)) for pc in hull_pieces(p)]
    under = [(pc, c0, c1) for pc, c0, c1 in pieces if c0 < s1 and c1 > s0]
    if not under or len({pc.link for pc, _, _ in under}) != 1:
        return None
    reach = s0
    for pc, c0, c1 in sorted(under, key=lambda t: t[1]):
        if c0 > reach + 1e-9:
            return None
        reach = max(reach, c1)
    return [pc for pc, _, _ in under] if reach >= s1 - 1e-9 else None


CRADLE_ADHESIVE = "epoxy_sanded_pla"
"""What bonds a cradle into the hull (catalogues/adhesives.toml)."""


def cradle_of(p: Params, i: int, c) -> Cradle:
    """The cradle component ``c`` gets as entry ``i`` of ``p.components``; UserError naming ``components[i]`` and
    the value that would do when it cannot be made there (a designer may try a place before writing it in)."""
    key = f"components[{i}]"
    sx, sy, sz = c.size_mm
    xc = -c.station_fraction * p.body.length_mm
    hangs = c.z_mm > 0.0
    sign = -1.0 if hangs else 1.0         # the hull is symmetric about z = 0: a hanging cradle is a standing one
    zb = sign * c.z_mm - sz / 2           # mirrored
    gap, wall, clr = bond_gap_mm(p), wall_mm(p), p.print.clearance_sliding_mm
    pk = pad()
    px = (xc - sx / 2 - clr, xc + sx / 2 + clr)
    x = (px[0] - wall, px[1] + wall)
    yi = sy / 2 + clr
    yo = yi + wall
    need = p.rules.wall_min_line_widths * p.print.line_width_mm
    room = end_room_mm(p)                                       # clearance, end wall and glue line
    s0, s1 = -(xc + sx / 2) - room, -(xc - sx / 2) + room
    under = _hollow(p, s0, s1)
    if under is None:
        raise UserError(f"{key}.station_fraction = {c.station_fraction:g}: the cradle of {c.name!r} (s = {s0:.1f}.."
                        f"{s1:.1f} mm: the box, {clr:g} mm of clearance and {need:g} mm end walls) does not lie in "
                        f"one hollow of the hull (a bulkhead or the nose is under it): move it")
    lo = min(cavity_range_mm(p, pc)[0] for pc in under) + gap
    hi = max(cavity_range_mm(p, pc)[1] for pc in under) - gap
    x = (max(x[0], -hi), min(x[1], -lo))      # an end of the hollow (the nose, a bulkhead) may be the end wall
    centre = next((pc for pc in under if pc.s_start_mm <= -xc <= pc.s_end_mm), under[0])
    floor = zb - pk.mated_thickness_mm
    least, where = math.inf, None
    for k in range(FLOOR_SAMPLES):
        s = -px[1] + (px[1] - px[0]) * k / (FLOOR_SAMPLES - 1)
        a, b = inner_semi_axes_mm(p, s, gap)
        if a <= yi:
            least, where = -math.inf, (s, yi)
            break
        z_shell = -b * math.sqrt(1.0 - (yi / a) ** 2)       # the shell is highest at the pocket's edge
        if floor - z_shell < least:
            least, where = floor - z_shell, (s, yi)
    if least < need:
        side = "top" if hangs else "underside"
        raise UserError(f"{key}.z_mm = {c.z_mm:g}: {c.name!r} has its pad's {side} (z = {sign * floor:.2f} mm, "
                        f"{pk.mated_thickness_mm:g} mm of hook-and-loop {'over' if hangs else 'under'} the box) "
                        + (f"{least:.2f} mm over the hull's inner wall at s = {where[0]:.1f} mm, "
                           f"|y| = {where[1]:.1f} mm" if math.isfinite(least)
                           else f"where the hull is narrower than the box at s = {where[0]:.1f} mm")
                        + f"; its cradle needs {need:.2f} mm of floor there (rules.wall_min_line_widths lines): "
                        + ((f"lower z_mm to at most {c.z_mm - need + least:.2f}" if hangs else
                            f"raise z_mm to at least {c.z_mm + need - least:.2f}") if math.isfinite(least)
                           else "move or shrink it"))
    top = zb + min(WALL_HEIGHT_FRACTION * sz, WALL_HEIGHT_MAX_MM)
    bonded = tuple(part_label(p, pc, "upper" if hangs else "lower") for pc in under)
    return Cradle(f"cradle_{c.name}", c.name, i, centre.link, centre.name, bonded,
                  x, px, yi, yo, floor, top, hangs, gap, pk.mated_thickness_mm, least, tuple(c.size_mm), c.mass_kg,
                  wall)


def end_room_mm(p: Params) -> float:
    """How far beyond a component's box, at each end along the body, its cradle needs the hollow: the sliding
    clearance, an end wall of two perimeters and the glue line (what :func:`cradle_of` asks of the hollow)."""
    return p.print.clearance_sliding_mm + p.rules.wall_min_line_widths * p.print.line_width_mm + bond_gap_mm(p)


@functools.lru_cache(maxsize=32)
def cradles(p: Params) -> tuple[Cradle, ...]:
    """One cradle per component of ``params.components`` (not the mass placeholders), in their order."""
    return tuple(cradle_of(p, i, c) for i, c in enumerate(p.components) if c.name not in PLACEHOLDERS)


def components_clear_of_motors(p: Params) -> None:
    """Raises :class:`UserError` naming ``components[i].station_fraction`` where a component comes within the
    assembly clearance of a motor (:func:`_motor_in_the_way`); one of the loader's plans (``layout.design``)."""
    for i, comp in enumerate(p.components):
        if comp.name in PLACEHOLDERS:
            continue
        pr = _motor_in_the_way(p, i, comp)
        if pr is not None:
            raise UserError(f"{pr.key} = {pr.value!r}: {pr.expected}")


def _motor_in_the_way(p: Params, i: int, comp):
    """The problem of component ``comp`` (``components[i]``) coming within ``print.clearance_assembly_mm`` of a motor,
    or None. The component is taken with its cradle (its box grown by the sliding clearance and the cradle's wall,
    down to the shell, or up to it where the cradle hangs), the motor as its frame from the body's back up to the
    mount plate on its face. Found by the build's assembly check at its end until 2026-11-30: a seeded design's board
    inside motor 4 (16 947 mm^3), and the default with 5 mm more room behind the motors (951 mm^3)."""
    from swiftfin.core.params import Problem
    c = p.print.clearance_assembly_mm
    sx, sy, sz = comp.size_mm
    sc = comp.station_fraction * p.body.length_mm
    grow = p.print.clearance_sliding_mm + wall_mm(p)
    s_lo, s_hi = sc - sx / 2 - grow, sc + sx / 2 + grow
    z_lo, z_hi = comp.z_mm - sz / 2, comp.z_mm + sz / 2
    z_lo, z_hi = (z_lo, math.inf) if comp.z_mm > 0.0 else (-math.inf, z_hi)     # the cradle reaches the shell
    F = p.motor.frame_size_mm
    for mp in L.motor_placements(p):       # both boxes straddle y = 0: they meet in plan where they meet along s
        m_lo, m_hi = mp.z_face_mm - p.motor.body_length_mm, mp.z_face_mm + L.plate_thickness_mm(p)
        gap_s = max(s_lo - (mp.s_mm + F / 2), (mp.s_mm - F / 2) - s_hi)
        gap_z = max(z_lo - m_hi, m_lo - z_hi)
        if max(gap_s, gap_z) < c:
            return Problem(f"components[{i}].station_fraction", comp.station_fraction,
                           f"{comp.name!r} and its cradle (s = {s_lo:.1f}..{s_hi:.1f} mm, z up to {z_hi:.1f} mm) "
                           f"come within print.clearance_assembly_mm ({c:g} mm) of motor {mp.joint + 1} (its frame "
                           f"and mount plate at s = {mp.s_mm - F / 2:.1f}..{mp.s_mm + F / 2:.1f} mm, z = {m_lo:.1f}.."
                           f"{m_hi:.1f} mm): move it (station_fraction, z_mm), or the motors "
                           f"(hull.drive_bay_length_mm = {p.hull.drive_bay_length_mm:g})")
    return None
