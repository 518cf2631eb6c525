"""The components' cradles: one printed block per bought box of ``params.components`` (battery, electronics), bonded
into the hull's lower half, with a pocket the box sits in on a hook-and-loop pad (body frame at rest, mm).

Numbers first (:func:`swiftfin.layout.cradle_plan.cradles`, which argues the arrangement), solid second
(:func:`cradle_solid`): the box of the cradle's outline, from under the shell up to the walls' top, intersected
with the shell's inner surface shrunk by the bond gap (a loft of the hull's inner ellipses, as the hull's own
hollow), less the pocket from the floor up (open at its fore end), less the lightening channel under the floor
(:attr:`~swiftfin.layout.cradle_plan.Cradle.channel_inset_mm`) and less the room of any station splice's tabs and
pads it comes near (:func:`swiftfin.cad.hull.splice_keep_outs`, grown by ``print.clearance_assembly_mm``). The
component sits ``pad_mm`` above the pocket's floor, the walls ``print.clearance_sliding_mm`` from its sides.
Printed in whichever of the six axis orientations needs least support (the export chooses:
``meta["print_candidates"]``; on its aft end).
"""
from __future__ import annotations

import math

from swiftfin.cad.kernel import bd
from swiftfin.cad.hull import splice_keep_outs
from swiftfin.cad.link import box, isect, one_solid
from swiftfin.cad.part import PartSpec
from swiftfin.catalogues.adhesives import adhesive
from swiftfin.catalogues.mounting import pad
from swiftfin.core.schema import Params
from swiftfin.layout.cradle_plan import CRADLE_ADHESIVE, Cradle, cradles, inner_semi_axes_mm

LOFT_STATIONS = 9
"""Sections of the inner-surface loft over the cradle's length (the hull's hollow is lofted through
``hull.loft_stations`` over a whole piece: these are closer, so the two surfaces agree to far under the bond gap)."""
AXIS_ROTATIONS = ((0.0, 0.0, 0.0), (180.0, 0.0, 0.0), (90.0, 0.0, 0.0), (-90.0, 0.0, 0.0), (0.0, 90.0, 0.0),
                  (0.0, -90.0, 0.0))


def inner_loft(p: Params, s0: float, s1: float, gap_mm: float, stations: int) -> bd.Solid:
    """The shell's hollow between stations s0 and s1 (mm, s0 < s1), its inner surface shrunk by ``gap_mm``: a loft
    of the inner ellipses at ``stations`` evenly spaced stations (the cradles' and the trim ballast's solids)."""
    wires = []
    for k in range(stations):
        s = s0 + (s1 - s0) * k / (stations - 1)
        a, b = inner_semi_axes_mm(p, s, gap_mm)
        pl = bd.Plane(origin=(-s, 0, 0), x_dir=(0, 1, 0), z_dir=(1, 0, 0))
        wires.append(bd.Wire([bd.Edge.make_ellipse(a, b, pl)]))
    return bd.Solid.make_loft(wires)


def _inner_loft(p: Params, c: Cradle, inset_mm: float = 0.0) -> bd.Solid:
    return inner_loft(p, -c.x_mm[1] - 1.0, -c.x_mm[0] + 1.0, c.bond_gap_mm + inset_mm, LOFT_STATIONS)


def cradle_solid(p: Params, c: Cradle) -> bd.Solid:
    """The cradle of :class:`~swiftfin.layout.cradle_plan.Cradle` ``c`` as one solid: made standing on the lower
    half's floor, mirrored about the seam plane when it hangs from the upper half (the hull is symmetric about it)."""
    low = -max(inner_semi_axes_mm(p, -x)[1] for x in c.x_mm) - 5.0
    outline = box(c.x_mm[0], c.x_mm[1], -c.half_width_mm, c.half_width_mm, low, c.z_top_mm)
    body = isect(outline, _inner_loft(p, c))
    pocket = box(c.pocket_x_mm[0], c.x_mm[1] + 1.0, -c.pocket_half_width_mm, c.pocket_half_width_mm,   # open fore
                 c.z_floor_mm, c.z_top_mm + 1.0)
    lo, hi = body.bounding_box().min, body.bounding_box().max
    keep = [k for k in splice_keep_outs(p, p.print.clearance_assembly_mm)
            if not any(a > b for a, b in zip(k.bounding_box().min, hi)) and
            not any(a < b for a, b in zip(k.bounding_box().max, lo))]
    cuts = [pocket, *keep]
    if c.channel_inset_mm > 0:
        channel = box(c.x_mm[0] - 1.0, c.x_mm[1] + 1.0, -c.pocket_half_width_mm, c.pocket_half_width_mm, low,
                      c.z_floor_mm - c.channel_inset_mm)
        cuts.append(isect(channel, _inner_loft(p, c, c.channel_inset_mm)))
    solid = one_solid(body.cut(*cuts), c.label)
    return solid.mirror(bd.Plane.XY) if c.hangs else solid


def make_cradles(p: Params) -> list[PartSpec]:
    """``cradle_<component>`` per component (link of the hull under it), bonded into that piece's lower half."""
    out = []
    pk, bond = pad(), adhesive(CRADLE_ADHESIVE)
    for c in cradles(p):
        sx, sy, _ = c.component_size_mm
        out.append(PartSpec(label=c.label, solid=cradle_solid(p, c), link=c.link, family="cradle", meta={
            "component": c.component, "bonded_to": c.bonded_to,
            "print_candidates": AXIS_ROTATIONS,
            "bom": [
                {"item": "Hook-and-loop pad", "spec": f"{pk.description}, {sx:.0f} x {sy:.0f} mm, "
                                                      f"{pk.mated_thickness_mm:g} mm engaged",
                 "quantity": 1, "where": f"{c.component} on {c.label}", "source": pk.source},
                {"item": "Epoxy", "spec": f"{bond.description}: bonds {c.label} into {' and '.join(c.bonded_to)}"
                                          + (" (it spans their splice: those halves then come apart only with it)"
                                             if len(c.bonded_to) > 1 else "")
                                          + f", {c.footprint_mm2 / 100:.1f} cm^2 x a {c.bond_gap_mm:g} mm glue line",
                 "quantity": math.ceil(c.footprint_mm2 * c.bond_gap_mm / 1000 * 10) / 10, "unit": "mL",
                 "where": c.label, "source": bond.source},
            ]}))
    return out
