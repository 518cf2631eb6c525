"""The PTFE guides' screws as numbers (:func:`guide_fasteners`, registered in ``cad/fastening.py``): down from each
guide's top into inserts in its mount's posts (:mod:`swiftfin.layout.guide_plan`'s module docstring). Apart from
the guides' plan because each screw is driven before the head's lid goes on (it names the hull piece's upper half),
and the hull's plan in turn keeps its seam bosses from under the guides: one module reads both plans.
"""
from __future__ import annotations

from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import Fastener
from swiftfin.layout.geometry import motor_placements
from swiftfin.layout.guide_plan import bare_guide_blocks, guide_screw_fit
from swiftfin.layout.hull_plan import hull_pieces, part_label


def guide_fasteners(p: Params) -> tuple[Fastener, ...]:
    """Every guide's screws: down from its top into inserts in its mount's posts (see the module docstring)."""
    pieces = hull_pieces(p)
    z_face = {f"motor_mount_{mp.joint + 1}": mp.z_face_mm for mp in motor_placements(p)}
    out = []
    for b in bare_guide_blocks(p):
        s = fastener(b.screw_diameter_mm)
        length, grip, recess = guide_screw_fit(p, b, b.seat_mm - z_face[b.mount])
        for i, (x, y) in enumerate(b.screw_points_mm):
            pc = next(q for q in pieces if q.s_start_mm <= -x <= q.s_end_mm)
            out.append(Fastener(f"{b.label}_screw_{i + 1}", s.name, "cap_screw", "insert", (x, y, b.seat_mm + grip),
                                (0.0, 0.0, -1.0), length, grip, b.label, b.mount,
                                f"holds {b.label} on the posts of {b.mount}", 0, recess_mm=recess,
                                installed_after=(part_label(p, pc, "upper"),)))
    return tuple(out)
