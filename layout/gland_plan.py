"""Where the cables cross the hull's bulkheads, and the cable glands through the dry compartment's rear wall, as
numbers (no CAD kernel): the design loader refuses a gland its cable's stroke wets through, the hull cuts its
passages (:mod:`swiftfin.cad.hull`) and the dry wall's check (:mod:`swiftfin.cad.dry_check`) declares its glands
from the same records.

A passage is the route's segment that crosses a bulkhead's mid-plane, from its PTFE tube's mouth (where the route
meets the front face, moved back along the route until the rim of the tube's square-cut end is inside the face) to
the back face. Its tube ends on a printed shoulder (:func:`swiftfin.layout.geometry.tube_seat_shoulder_mm`) short
of the back face, or short of where its bore would break into the room the parent's rear bulkhead leaves for the
link behind (:func:`in_clevis_room`). Through the dry wall the tube is a cable gland (catalogues/seals.toml),
potted along its bore: its packed length runs from the mouth to the seat.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.hull_plan import HullPiece, dry_bulkhead, dry_wall_span_mm, dry_wall_thickness_mm
from swiftfin.layout.joints import all_joint_hardware

ROOM_BISECTIONS = 30
"""Halvings of a passage that find where its bore meets the clevis room (the passage is at most a few tens of mm:
far below a micrometre)."""


def in_clevis_room(p: Params, h, pts: np.ndarray, hole_r: float) -> bool:
    """Whether a hole of radius ``hole_r`` round the segment ``pts`` (two points) reaches into the room the parent's
    rear bulkhead leaves for joint ``h``'s link (the sector and knuckle cylinders of
    :func:`swiftfin.cad.clevis.clevis_cut`), sampled at 11 points."""
    ca, cs = p.print.clearance_assembly_mm, p.print.clearance_sliding_mm
    cuts = ((h.sector_radius_mm + ca, h.z_sector_lo_mm - cs, h.z_sector_hi_mm + cs),
            (h.knuckle_radius_mm + ca, h.z_knuckle_lo_mm - cs, h.z_sector_lo_mm))
    q = pts[0] + np.linspace(0, 1, 11)[:, None] * (pts[1] - pts[0])
    rho = np.hypot(q[:, 0] - h.x_mm, q[:, 1])
    for R, z0, z1 in cuts:
        if np.any((rho < R + hole_r) & (q[:, 2] > z0 - hole_r) & (q[:, 2] < z1 + hole_r)):
            return True
    return False


def bulkhead_spans_mm(p: Params, pc: HullPiece) -> list[tuple[float, float]]:
    """(s_front, s_back) of each bulkhead of the piece; the dry compartment's rear wall is as thick as its cable
    glands need (:func:`swiftfin.layout.hull_plan.dry_bulkhead`)."""
    t = p.hull.bulkhead_thickness_mm
    out = []
    if pc.front_joint is not None:
        out.append((pc.s_start_mm, pc.s_start_mm + t))
    dry = dry_bulkhead(p)
    if dry is not None and dry.piece == pc.name and dry.rear_joint is not None:
        out.append((dry.s_front_mm, pc.s_end_mm))
    elif pc.rear_joint is not None:
        out.append((pc.s_end_mm - t, pc.s_end_mm))
    return out


def _passages(p: Params, sf: float, sb: float, rear) -> list[tuple]:
    """The passages through the bulkhead from station ``sf`` to ``sb`` (``rear``: the hardware of the joint behind
    it when the bulkhead holds that joint's clevis, else None)."""
    r_bore = L.tube_bore_diameter_mm(p, "bulkhead") / 2
    tube_r = p.guides.ptfe_tube_od_mm / 2
    shoulder = L.tube_seat_shoulder_mm(p)
    xf, xb = -sf, -sb
    xm = (xf + xb) / 2
    out = []
    for route in L.cable_routes(p):
        pts = np.asarray(route.points_mm, float)
        for a, b in zip(pts[:-1], pts[1:]):
            if (a[0] - xm) * (b[0] - xm) >= 0:
                continue
            d = b - a
            front, back = a + (xf - a[0]) / d[0] * d, a + (xb - a[0]) / d[0] * d
            u = (back - front) / np.linalg.norm(back - front)
            # the tube's mouth sits back in its bore until the rim of its square-cut end is inside the face
            front = front + tube_r * math.sqrt(max(0.0, 1.0 - u[0] ** 2)) / abs(u[0]) * u
            end = back
            if rear is not None and in_clevis_room(p, rear, np.array([front, back]), r_bore):
                # the bore would break into the clevis room: the tube stops a shoulder short of where it would
                lo, hi = 0.0, 1.0
                for _ in range(ROOM_BISECTIONS):
                    mid = 0.5 * (lo + hi)
                    if in_clevis_room(p, rear, np.array([front, front + mid * (back - front)]), r_bore):
                        hi = mid
                    else:
                        lo = mid
                end = front + lo * (back - front)
            seat = end - shoulder * u
            if float((seat - front) @ u) < L.MIN_TUBE_MM:
                seat = None
            out.append((route, front, back, seat))
    return out


def bulkhead_passages(p: Params, pc: HullPiece) -> list[tuple]:
    """Where the cable routes cross the bulkheads of this piece: ``(route, front, back, seat)`` (body frame, mm; see
    the module's docstring). ``seat`` is None where the passage holds no tube: the bulkhead is too thin for a tube of
    ``MIN_TUBE_MM`` and its shoulder."""
    hw = {h.joint: h for h in all_joint_hardware(p)}
    out = []
    for sf, sb in bulkhead_spans_mm(p, pc):
        rear = pc.rear_joint if sb == pc.s_end_mm else None
        out += _passages(p, sf, sb, None if rear is None else hw[rear])
    return out


def bore_ahead_mm(p: Params, axis_x: float) -> float:
    """How far ahead of a tube's mouth, along its route (``axis_x`` the route direction's x component), the bore of
    a bulkhead passage is cut: 2 mm along the body, plus enough that the tilted bore opens fully on the front face
    where the mouth sits back in it."""
    return (2.0 + L.tube_bore_diameter_mm(p, "bulkhead")) / abs(axis_x)


@dataclass(frozen=True)
class Gland:
    """A cable gland through the dry wall: the PTFE tube potted in its bore from its mouth on the dry face to its
    seat (body frame, mm)."""
    label: str                       # gland_<joint>_<left|right>
    joint: int                       # 1-based joint its cable drives
    side: int
    front_mm: tuple                  # the tube's mouth
    back_mm: tuple                   # where the bore's axis meets the wall's back face
    packed_mm: float                 # mouth to seat along the bore (0: no tube fits)
    stroke_mm: float                 # its cable's stroke: moment arm x its joint's stop angle

    @property
    def axis(self) -> np.ndarray:
        d = np.subtract(self.back_mm, self.front_mm)
        return d / np.linalg.norm(d)


def cable_glands(p: Params, gland_length_mm: float | None = None) -> tuple[Gland, ...]:
    """The cable glands through the dry compartment's rear wall, one per cable that crosses it; none where nothing
    is sealed or the whole hull is (the fin socket's plug closes it). From the hull's segments alone (the wall's
    stations do not depend on how the pieces are cut for the bed). ``gland_length_mm``: the glands the wall would
    have with that ``hull.cable_gland_length_mm`` (only the wall's front face moves), from the same params, so the
    routes' and joints' memos serve those who try several lengths."""
    span = dry_wall_span_mm(p)
    if span is None or span[2] is None:
        return ()
    sf, sb, rear = span
    if gland_length_mm is not None:
        sf = sb - dry_wall_thickness_mm(p, gland_length_mm)
    stops = L.joint_stop_angles_rad(p)
    h = next(h for h in all_joint_hardware(p) if h.joint == rear)
    out = []
    for route, front, back, seat in _passages(p, sf, sb, h):
        u = (back - front) / np.linalg.norm(back - front)
        packed = float((seat - front) @ u) if seat is not None else 0.0
        side = "left" if route.side > 0 else "right"
        out.append(Gland(f"gland_{route.joint + 1}_{side}", route.joint + 1, route.side,
                         tuple(map(float, front)), tuple(map(float, back)), packed,
                         p.joints.tendon_moment_arm_mm * stops[route.joint]))
    return tuple(out)


def wetted(glands) -> list[Gland]:
    """The glands whose packing their cable's stroke wets through: no longer than the stroke."""
    return [g for g in glands if g.packed_mm <= g.stroke_mm]


def wall_room_mm(p: Params) -> float:
    """How much further forward the dry compartment's rear wall may reach [mm]: its front face must keep the assembly
    clearance from the bay guide's aft end (:func:`swiftfin.layout.guide_plan.bare_guide_blocks`; the wall is a
    whole cross-section of the hull). Negative: it reaches too far already; infinite with no bay guide or no wall
    with a joint behind it."""
    from swiftfin.layout.guide_plan import bare_guide_blocks
    span = dry_wall_span_mm(p)
    bay = next((b for b in bare_guide_blocks(p) if b.label == "guide_bay"), None)
    if span is None or span[2] is None or bay is None:
        return math.inf
    return span[0] - p.print.clearance_assembly_mm - (-bay.x_mm[0])


def gland_plan(p: Params) -> tuple[Gland, ...]:
    """The cable glands (:func:`cable_glands`), made as the loader makes every plan. Raises :class:`UserError`
    naming ``hull.cable_gland_length_mm``

    * where a gland is wetted through by its cable's stroke (no longer than it: the wet stretch of cable would reach
      the dry side; the build's dry-wall check refuses it), with the least length, in half millimetres, that keeps
      every gland longer than its stroke. Joint 1's own cables run into its sector's room in the wall's back face,
      which shortens their glands below the key's length (the wall grows forward with the key);
    * where the wall's front face comes within the assembly clearance of the bay guide's aft end (the wall is a
      whole cross-section of the hull), with the most length that leaves it.
    """
    from dataclasses import fields

    from swiftfin.core.schema import Hull
    key = "hull.cable_gland_length_mm"
    have = p.hull.cable_gland_length_mm
    hi = next(f.metadata for f in fields(Hull) if f.name == "cable_gland_length_mm")["hi"]
    room = wall_room_mm(p)
    most = min(hi, math.floor((have + room) * 2.0 + 1e-9) / 2.0) if math.isfinite(room) else hi
    if room < 0.0:
        span = dry_wall_span_mm(p)
        raise UserError(f"{key} = {have:g}: the dry compartment's rear wall ({span[1] - span[0]:.1f} mm: the glands "
                        f"and their seat's shoulder) reaches {-room:.2f} mm too far forward: its front face at station "
                        f"{span[0]:.1f} mm must keep {p.print.clearance_assembly_mm:g} mm "
                        f"(print.clearance_assembly_mm) from the bay guide's aft end: at most {most:g} mm")
    glands = cable_glands(p)
    bad = wetted(glands)
    if not bad:
        return glands
    worst = max(bad, key=lambda g: g.stroke_mm - g.packed_mm)
    length, fix = have, None
    for _ in range(6):      # the packed length grows by about 1 / |u_x| per mm of wall: a step or two
        short = max(((g.stroke_mm - g.packed_mm) * abs(g.axis[0]) for g in bad), default=0.0)
        length = math.ceil((length + short + 0.05) * 2.0) / 2.0
        if length > most:
            break
        bad = wetted(cable_glands(p, length))
        if not bad:
            fix = f"at least {length:g} mm"
            break
    if fix is None:
        fix = (f"no length up to {most:g} mm makes it longer (the bay guide's aft end, or the key's bound, stops the "
               f"wall): a smaller stop angle (joints.stop_margin_deg, swimming.tail_amplitude_m) or moment arm "
               f"(joints.tendon_moment_arm_mm) shortens the stroke")
    raise UserError(f"{key} = {have:g}: {worst.label}'s potted tube through the dry wall is {worst.packed_mm:.1f} mm "
                    f"long, no longer than its cable's stroke {worst.stroke_mm:.1f} mm (joint {worst.joint}): the wet "
                    f"stretch of cable would reach the dry side; {fix}")
