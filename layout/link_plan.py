"""The joint links' fasteners as records (body frame at rest, mm): the hinge pins, the plugs that keep them in and
the flange screws that fix each link to its child's front bulkhead. Built on the hinge numbers of
:mod:`swiftfin.layout.joints` and the hull pieces of :mod:`swiftfin.layout.hull_plan` (which itself reads the
joints, so the records live here, above both). No CAD kernel; the registry cuts the holes from these records.
"""
from __future__ import annotations

from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import Fastener, screw_length
from swiftfin.layout.hull_plan import hull_pieces, part_label
from swiftfin.layout.joints import all_joint_hardware


def _earlier_parts(p: Params, j: int, pieces=None) -> tuple[str, ...]:
    """Labels of every part of the links ahead of joint j (0 .. j-1): the tail is assembled from the peduncle
    forward, so they go on after joint j's flange screws are driven (the driver reaches them from the front). A
    part glued into one of these (a flotation block) goes on with it (``cad.fastener_check``'s ``goes_in_with``)."""
    out = []
    for pc in (hull_pieces(p) if pieces is None else pieces):
        if pc.link < j:
            out += sorted({part_label(p, pc, "upper"), part_label(p, pc, "lower")})
    out += [f"joint_link_{k}" for k in range(1, j)]
    n = p.joints.count
    out += [f"{fam}_{k}" for k in range(1, n + 1) for fam in ("motor", "motor_mount", "spool")]
    out += [f"spool_{k}_upper" for k in range(1, n + 1)] + [f"guide_exit_{k}" for k in range(2, n + 1)] + ["guide_bay"]
    return tuple(out)


def link_fasteners(p: Params) -> tuple[Fastener, ...]:
    """Every fastener of the joint links (body frame at rest, mm):

    * ``joint_<j>_pin_lower`` / ``_upper``: the hinge pins (ISO 8734, ``joints.pin_diameter_mm``), ``seat="press"`` in
      the link (``thread_part``), turning in the parent's lug (``meta["slip_part"]``), whose bore the registry cuts
      from the same record: one cylinder through both parts, so the two bores of a pin are coaxial by
      construction. ``head_mm`` is the pin's outer end, the axis points into the link.
    * ``joint_<j>_plug_lower`` / ``_upper``: the set screw plugs that keep the pins in (flush with the boss's face,
      in an insert coaxial with the pin, its tip ``PIN_END_GAP_MM`` + the pocket's extra short of the pin's end).
    * ``joint_<j>_flange_<k>``: four cap screws (``hull.screw_diameter_mm``), heads on the link flange's front face,
      threads in heat-set inserts in the child's front bulkhead (upper/lower half by the row's side of z = 0).
    """
    out = []
    pieces = hull_pieces(p)
    for h in all_joint_hardware(p):
        j = h.joint
        parent = next(pc for pc in pieces if pc.rear_joint == j)
        child = next(pc for pc in pieces if pc.front_joint == j)
        link = f"joint_link_{j}"
        plug = fastener(h.plug_screw)
        plug_len = plug.length_for(plug.insert_length_mm, set_screw=True)
        lo_play, hi_play = h.pin_radial_play_mm
        for pin in h.pins:
            lug = part_label(p, parent, "lower" if pin.where == "lower" else "upper")
            axis = (0.0, 0.0, float(pin.sign))
            out.append(Fastener(
                f"joint_{j}_pin_{pin.where}", f"{h.pin_diameter_mm:g}", "dowel", "press", (h.x_mm, 0.0, pin.outer_z_mm),
                axis, pin.length_mm, 0.0, None, link, f"hinge of joint {j} ({pin.where}): pressed in {link}, turns in "
                f"the lug of {lug}", j,
                meta={"slip_part": lug, "joins_parts": (lug,), "radial_play_mm": (lo_play, hi_play),
                      "bore": "printed pin - ream stock; the lug's bore line-reamed H7 with the other lug's in one pass",
                      "in_lug_mm": pin.in_lug_mm, "in_link_mm": pin.in_link_mm}))
            out.append(Fastener(
                f"joint_{j}_plug_{pin.where}", plug.name, "set_screw", "insert", (h.x_mm, 0.0, pin.boss_face_z_mm),
                axis, plug_len, 0.0, None, lug, f"keeps the {pin.where} hinge pin of joint {j} in", parent.link,
                meta={"retains": f"joint_{j}_pin_{pin.where}"}))
        s = fastener(h.flange_screw)
        length = screw_length(s, h.flange_thickness_mm, "insert")
        x_face = h.x_mm - h.gap_half_mm + h.flange_thickness_mm
        after = _earlier_parts(p, j, pieces)
        for k, (y, z) in enumerate(h.bolt_points_yz_mm):
            bulkhead = part_label(p, child, "upper" if z > 0 else "lower")
            out.append(Fastener(
                f"joint_{j}_flange_{k + 1}", s.name, "cap_screw", "insert", (x_face, y, z), (-1.0, 0.0, 0.0),
                length, h.flange_thickness_mm, link, bulkhead, f"{link} to the front bulkhead of {child.name}", j,
                installed_after=after))
    return tuple(out)
