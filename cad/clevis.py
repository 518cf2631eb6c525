"""The clevis: the parent segment's half of each hinge, fused to (and cut from) the rear bulkhead of the hull
piece ahead of the joint by :mod:`swiftfin.cad.hull`, from the numbers of :mod:`swiftfin.layout.joints` that the
link (:mod:`swiftfin.cad.link`) is made from too, so the two halves of a hinge always agree.

The lugs' pin bores and the plugs' insert pockets are not cut here: they come from the hinge's fastener records
(:func:`swiftfin.layout.link_plan.link_fasteners`), the pin's bore from the same record as the link's, through the
registry. This module adds the material: the lugs, the plug bosses on their outer faces, the stop blocks.
"""
from __future__ import annotations

from swiftfin.cad.kernel import bd
from swiftfin.cad.link import JointHardware, box, pie, vcyl
from swiftfin.core.schema import Params


def clevis_cut(h: JointHardware, p: Params) -> list[bd.Solid]:
    """Room in the parent's rear end for the parts of the link that swing (sector, window column, tongue)."""
    ca, cs = p.print.clearance_assembly_mm, p.print.clearance_sliding_mm
    x = h.x_mm
    sweep = h.tongue_half_deg + h.stop_deg + 1.0
    out = [pie(x, h.tongue_radius_mm + ca, -sweep, sweep, h.z_knuckle_lo_mm - cs, h.z_window_lo_mm + 0.01),
           vcyl(x, 0, h.knuckle_radius_mm + ca, h.z_knuckle_lo_mm - cs, h.z_sector_lo_mm + 0.01),
           vcyl(x, 0, h.sector_radius_mm + ca, h.z_sector_lo_mm - cs, h.z_sector_hi_mm + cs)]
    return out


def clevis_add(h: JointHardware, p: Params) -> list[bd.Solid]:
    """Lugs (each with the boss of its pin's plug on its outer face) and stop blocks on the parent's rear
    bulkhead."""
    x = h.x_mm
    cs = p.print.clearance_sliding_mm
    x_front = x + h.gap_half_mm + p.hull.bulkhead_thickness_mm - 0.01
    rl = h.lug_radius_mm
    out = []
    for z0, z1 in (h.lower_lug_mm, h.upper_lug_mm):
        out += [box(x, x_front, -rl, rl, z0, z1), vcyl(x, 0, rl, z0, z1)]
    for pin in h.pins:
        b0, b1 = pin.boss_mm
        out.append(vcyl(x, 0, pin.boss_radius_mm, b0 - (0.01 if pin.sign < 0 else 0), b1 + (0.01 if pin.sign > 0 else 0)))
    lo = h.lower_lug_mm
    a_out = h.tongue_half_deg + h.stop_deg + h.block_span_deg
    out.append(pie(x, h.block_outer_radius_mm, -a_out, a_out, *lo))
    for sgn in (1, -1):
        a0 = h.tongue_half_deg + h.stop_deg
        a_lo, a_hi = (a0, a0 + h.block_span_deg) if sgn > 0 else (-a0 - h.block_span_deg, -a0)
        block = pie(x, h.block_outer_radius_mm, a_lo, a_hi, lo[1] - 0.01, h.z_window_lo_mm - cs)
        block = block.cut(vcyl(x, 0, h.knuckle_radius_mm + cs, lo[1] - 1, h.z_window_lo_mm))
        out.append(block)
    return out
