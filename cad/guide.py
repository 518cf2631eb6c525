"""PTFE tube guides at the cable routes' "exit" and "bay" bends: the solids, made from the numbers of
:mod:`swiftfin.layout.guide_plan` (channel paths, block extents, screw points, tube seats; its docstring gives the
arrangement and why). Each block is the box of its extents clipped to the hull's inner wall by a ruled loft, less
its channels (swept circles, each ending flat at its tube's seat with the cable's exit hole on through the
shoulder), the spools' envelopes and the plate's notch; the screw holes are cut by the registry from the guides'
fastener records.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from swiftfin.cad.kernel import Edge, Face, Plane, Solid, Transition, Wire

from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout.guide_plan import (Channel, GuideBlock, channel_bores_mm, guide_blocks, is_chain_end,
                                        unit_vector)


def channel_path(ch: Channel) -> Wire:
    """The channel's centre line as a wire: line, arc (if any), line."""
    edges = [Edge.make_line(ch.p_in, ch.t1)]
    if ch.angle_rad > 1e-6:
        edges.append(Edge.make_three_point_arc(ch.t1, ch.mid, ch.t2))
    edges.append(Edge.make_line(ch.t2 if ch.angle_rad > 1e-6 else ch.t1, ch.p_out))
    return Wire(edges)


# ----------------------------------------------------------------------------------------------- solids
def channel_solid(ch: Channel) -> Solid:
    """The tube channel: the circle of the channel's diameter swept along its centre line."""
    start = tuple(np.asarray(ch.p_in))
    normal = tuple(unit_vector(np.subtract(ch.t1, ch.p_in)))
    section = Face(Wire.make_circle(ch.diameter_mm / 2, Plane(origin=start, z_dir=normal)))
    return Solid.sweep(section, channel_path(ch), transition=Transition.ROUND)


def guide_solid(b: GuideBlock) -> Solid:
    (x0, x1), (y0, y1), (z0, z1) = b.x_mm, b.y_mm, b.z_mm
    box = Solid.make_box(x1 - x0, y1 - y0, z1 - z0).translate((x0, y0, z0))
    (a0, h0), (a1, h1) = b.clip_ellipse_mm
    # the loft runs 1 mm past each end along its own slope, so the box's end faces cut it
    k0, k1 = -1.0 / (x1 - x0), 1.0 + 1.0 / (x1 - x0)
    ends = [Wire.make_ellipse(a0 + k * (a1 - a0), h0 + k * (h1 - h0), Plane.YZ.offset(x))
            for k, x in ((k0, x0 - 1), (k1, x1 + 1))]
    loft = Solid.make_loft(ends, ruled=True)
    body = box.intersect(loft).solids()[0]
    cutters = []
    for ch in b.channels:
        seat = b.tube_seat(ch.joint, ch.side) if is_chain_end(b, ch) else None
        if seat is None:
            cutters.append(channel_solid(ch))
            continue
        # the bore ends flat at the tube's seat; the cable's exit hole goes on through the shoulder
        d = unit_vector(np.subtract(ch.p_out, seat))
        cutters.append(channel_solid(replace(ch, p_out=seat)))
        start = np.asarray(seat) - 0.1 * d
        cutters.append(Solid.make_cylinder(b.exit_hole_diameter_mm / 2,
                                           float(np.linalg.norm(np.subtract(ch.p_out, start))),
                                           Plane(origin=tuple(start), z_dir=tuple(d))))
    for x, y, r in b.keep_out_mm:
        cutters.append(Solid.make_cylinder(r, z1 - z0 + 2, Plane(origin=(x, y, z0 - 1))))
    if b.notch_mm is not None:
        nx, nz = b.notch_mm
        cutters.append(Solid.make_box(x1 - nx + 1, y1 - y0 + 2, nz - z0 + 1).translate((nx, y0 - 1, z0 - 1)))
    body = body.cut(*cutters)       # the screw holes come from guide_fasteners (cut by the registry)
    solids = body.solids()
    if len(solids) != 1:
        raise UserError(f"{b.label}: the guide falls apart into {len(solids)} pieces around the channels and "
                        f"spools; this design leaves no room for it (check spool.flange_height_mm, "
                        f"guides.ptfe_tube_od_mm and the joint stations)")
    return solids[0]


def make_guides(p: Params) -> list[PartSpec]:
    """``guide_exit_<j>`` for motors j >= 2 and ``guide_bay``, link 0, each printed on its flat face."""
    out = []
    for b in guide_blocks(p):
        out.append(PartSpec(label=b.label, solid=guide_solid(b), link=0, family="guide",
                            print_rotation=b.print_rotation,
                            meta={"mount": b.mount, "load_free_bores_mm": channel_bores_mm(b),
                                  "bends_deg": [round(math.degrees(ch.angle_rad), 3) for ch in b.channels
                                                if ch.angle_rad > 0]}))
    return out


