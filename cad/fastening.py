"""Holes for the fasteners of :mod:`swiftfin.layout.fastening`, cut from the same records the checks and the bill
of materials read, and the list of every fastener of the robot.

``head_cutters(f)``: what the head part loses (the clearance hole through the grip and, when the head is recessed,
its counterbore and the room above it). ``seat_cutters(f)``: what the thread part loses (the insert's pocket, the
nut's hex trap and the screw's way through it, or the self-tap pilot; a dowel's bore, printed
``ream_stock_mm`` under the pin and reamed to H7 on assembly, catalogues/pins.toml). Both are lists of
build123d solids in the body frame at rest, to be cut from the part that owns them.

Each part family's plan that places fasteners is listed in :data:`FASTENER_PLANS`; :func:`all_fasteners` gathers
them (labels unique, every record's own numbers checked).
"""
from __future__ import annotations

import functools
import importlib
import math

import numpy as np

from swiftfin.cad.kernel import bd
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import Fastener, check_unique

FASTENER_PLANS: dict[str, str] = {}
"""Part family -> ``"module:function"``, each ``function(params) -> tuple[Fastener, ...]``."""
FASTENER_PLANS.update(hull="swiftfin.layout.hull_plan:hull_fasteners", fin="swiftfin.layout.fin_plan:fin_fasteners")
FASTENER_PLANS.update(spool="swiftfin.layout.spool_plan:spool_fasteners")
FASTENER_PLANS.update(link="swiftfin.layout.link_plan:link_fasteners")
FASTENER_PLANS.update(mount="swiftfin.layout.mount_plate_plan:mount_fasteners",
                      guide="swiftfin.layout.guide_screws:guide_fasteners")

OVERCUT_MM = 0.5
"""Cutters run this far past the faces they open, so no zero-thickness skin is left."""


@functools.lru_cache(maxsize=8)
def all_fasteners(p: Params) -> tuple[Fastener, ...]:
    """Every fastener of the design, family by family; BuildError if a record is inconsistent."""
    out: list[Fastener] = []
    for ref in FASTENER_PLANS.values():
        module, func = ref.split(":")
        out += getattr(importlib.import_module(module), func)(p)
    problems = check_unique(out) + [pr for f in out for pr in f.problems()]
    if problems:
        raise BuildError("fasteners:\n" + "\n".join(f"  - {pr}" for pr in problems))
    return tuple(out)


def _rod(start, direction, radius: float, length: float) -> bd.Solid:
    return bd.Solid.make_cylinder(radius, length, bd.Plane(origin=tuple(map(float, start)),
                                                           z_dir=tuple(map(float, direction))))


def _x_dir(axis) -> tuple[float, float, float]:
    """A unit vector normal to ``axis`` (the hex trap's flats are set from it): the projection of +z, else +x."""
    a = np.asarray(axis, dtype=float)
    for ref in ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)):
        v = np.asarray(ref) - np.dot(ref, a) * a
        if np.linalg.norm(v) > 1e-3:
            return tuple(v / np.linalg.norm(v))
    raise AssertionError


def _hex_prism(centre, axis, across_flats_mm: float, length_mm: float) -> bd.Solid:
    r = across_flats_mm / math.sqrt(3.0)          # circumradius
    pl = bd.Plane(origin=tuple(map(float, centre)), x_dir=_x_dir(axis), z_dir=tuple(map(float, axis)))
    pts = [pl.from_local_coords((r * math.cos(math.radians(30 + 60 * k)), r * math.sin(math.radians(30 + 60 * k))))
           for k in range(6)]
    face = bd.Face(bd.Wire.make_polygon([tuple(q) for q in pts], close=True))
    return bd.Solid.extrude(face, bd.Vector(*[length_mm * c for c in axis]))


def head_cutters(f: Fastener, head_room_mm: float = 10.0) -> list[bd.Solid]:
    """The head part's clearance hole over the grip; with a recess, the counterbore and ``head_room_mm`` of
    room above it for the head and the key."""
    if f.kind == "dowel" or f.head_part is None:
        return []
    s = f.screw
    a = np.asarray(f.axis, dtype=float)
    out = [_rod(f.point_mm(-OVERCUT_MM), a, s.clearance_hole_mm / 2, f.grip_mm + 2 * OVERCUT_MM)]
    if f.recess_mm > 0:
        r, length = s.counterbore_diameter_mm / 2, f.recess_mm + head_room_mm
        out.append(_rod(f.point_mm(-length), a, r, length))
        if f.recess_open_toward is not None:
            out.append(_slot(f.point_mm(-length), a, np.asarray(f.recess_open_toward, dtype=float), r, length))
    return out


SLOT_REACH_MM = 25.0
"""How far an open counterbore's slot runs outward from the axis (past any skin it opens through)."""


def _slot(start, axis: np.ndarray, toward: np.ndarray, half_width_mm: float, length_mm: float) -> bd.Solid:
    """A box from the axis outward along ``toward``, as wide as the counterbore, ``length_mm`` along the axis from
    ``start``: the counterbore's outer half carried out through the surface, so its rim meets the skin square."""
    pl = bd.Plane(origin=tuple(map(float, start)), x_dir=tuple(map(float, toward)), z_dir=tuple(map(float, axis)))
    box = bd.Box(SLOT_REACH_MM, 2 * half_width_mm, length_mm,
                 align=(bd.Align.MIN, bd.Align.CENTER, bd.Align.MIN))
    return (pl * box).solid()


def seat_cutters(f: Fastener, open_mm: float = 0.0) -> list[bd.Solid]:
    """The thread part's cuts. ``open_mm``: for a nut, how far the hex trap continues past the nut's far face
    (to the part's surface, so the nut drops in along the axis); for an insert, ignored (the pocket opens at the
    grip, where the screw arrives)."""
    a = np.asarray(f.axis, dtype=float)
    if f.kind == "dowel":
        from swiftfin.catalogues.fasteners import dowel
        pin = dowel(float(f.size))
        d = pin.diameter_mm - pin.ream_stock_mm      # printed under size, reamed to H7 on assembly
        return [_rod(f.point_mm(-OVERCUT_MM), a, d / 2, f.length_mm + 2 * OVERCUT_MM)]
    s = f.screw
    past = f.length_mm - f.grip_mm
    out = []
    if f.seat == "insert":
        out.append(_rod(f.point_mm(f.grip_mm - OVERCUT_MM), a, s.insert_hole_mm / 2,
                        s.insert_pocket_depth_mm + OVERCUT_MM))
        beyond = past - s.insert_pocket_depth_mm
        if beyond > 0:   # the screw's tip runs on past the insert's pocket: room for it, and half a mm more
            out.append(_rod(f.point_mm(f.grip_mm + s.insert_pocket_depth_mm - 0.01), a,
                            s.clearance_hole_mm / 2, beyond + OVERCUT_MM + 0.01))
    elif f.seat == "nut":
        out.append(_rod(f.point_mm(f.grip_mm - OVERCUT_MM), a, s.clearance_hole_mm / 2, past + 2 * OVERCUT_MM))
        out.append(_hex_prism(f.point_mm(f.grip_mm), a, s.nut_trap_width_mm, s.nut_trap_depth_mm + open_mm))
    elif f.seat == "self_tap":
        out.append(_rod(f.point_mm(f.grip_mm - OVERCUT_MM), a, s.pilot_hole_mm / 2,
                        past + f.pilot_past_tip_mm + OVERCUT_MM))
    elif f.seat == "tapped":
        pass             # a bought part's own tapped hole: nothing to cut
    else:
        raise BuildError(f"{f.label}: seat {f.seat!r} has no cutter for a {f.kind}")
    return out


def cutters_for(p: Params, label: str) -> list[bd.Solid]:
    """Every cut the fasteners ask of the part ``label``: head holes where it is a head part, seats where it is
    a thread part, and a pin's bore where the pin slips into it (``meta["slip_part"]``: one bore through both
    parts, from the same record)."""
    out: list[bd.Solid] = []
    for f in all_fasteners(p):
        if f.head_part == label:
            out += head_cutters(f)
        if f.thread_part == label or (f.kind == "dowel" and f.meta.get("slip_part") == label):
            out += seat_cutters(f, open_mm=float(f.meta.get("nut_open_mm", 0.0)))
    return out


def apply_fasteners(p: Params, specs: list) -> list:
    """The family's parts with their fastener holes cut (printed parts only: a bought part comes with its own
    threads). A part that falls apart under its holes is a BuildError naming it."""
    from dataclasses import replace

    from swiftfin.cad.link import one_solid
    out = []
    for s in specs:
        cuts = cutters_for(p, s.label) if s.printed else []
        if cuts:
            s = replace(s, solid=one_solid(s.solid.cut(*cuts), f"{s.label} (with its fastener holes)"))
        out.append(s)
    return out
