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

def room_cylinders(p: Params, h) -> tuple[tuple[float, float, float], ...]:
    """The room the parent's rear bulkhead leaves for joint ``h``'s link (the sector and knuckle cylinders of
    :func:`swiftfin.cad.clevis.clevis_cut`, round the joint's vertical axis): ``(radius, z_lo, z_hi)`` of each, mm."""
    ca, cs = p.print.clearance_assembly_mm, p.print.clearance_sliding_mm
    return ((h.sector_radius_mm + ca, h.z_sector_lo_mm - cs, h.z_sector_hi_mm + cs),
            (h.knuckle_radius_mm + ca, h.z_knuckle_lo_mm - cs, h.z_sector_lo_mm))


def in_clevis_room(p: Params, h, pts: np.ndarray, hole_r: float) -> bool:
    """Whether a hole of radius ``hole_r`` round the segment ``pts`` (two points) reaches into the room the parent's
    rear bulkhead leaves for joint ``h``'s link (:func:`room_cylinders`), sampled at 11 points."""
    q = pts[0] + np.linspace(0, 1, 11)[:, None] * (pts[1] - pts[0])
    rho = np.hypot(q[:, 0] - h.x_mm, q[:, 1])
    for R, z0, z1 in room_cylinders(p, h):
        if np.any((rho < R + hole_r) & (q[:, 2] > z0 - hole_r) & (q[:, 2] < z1 + hole_r)):
            return True
    return False


def room_entry(cuts, x_axis, a, b, hole_r):
    """Where, as a fraction of the way from ``a`` to ``b``, a hole of radius ``hole_r`` round the segment first
    reaches into the room ``cuts`` (:func:`room_cylinders`, round the vertical axis at ``(x_axis, 0)``): a point of
    the segment within a cylinder's radius plus ``hole_r`` of the axis and within ``hole_r`` of its height range;
    NaN where it never does. Closed form: the segment's interval inside each cylinder in plan (a quadratic) met with
    its interval inside the height range (linear). Arrays: ``a``, ``b`` (3, ...), the rest broadcast with ``...``
    (the vectorised rules evaluate it on columns of designs)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    ox, oy = a[0] - x_axis, a[1]
    qa = d[0] ** 2 + d[1] ** 2
    flat = qa < 1e-18
    best = np.full(np.broadcast(ox, d[2], hole_r).shape, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for R, z0, z1 in cuts:
            c = ox * ox + oy * oy - (R + hole_r) ** 2
            qb = 2.0 * (ox * d[0] + oy * d[1])
            disc = qb * qb - 4.0 * qa * c
            sq = np.sqrt(np.maximum(disc, 0.0))
            t1 = np.where(flat, np.where(c < 0.0, -np.inf, 0.0), (-qb - sq) / (2.0 * qa))
            t2 = np.where(flat, np.where(c < 0.0, np.inf, 0.0), (-qb + sq) / (2.0 * qa))
            lo_z, hi_z = z0 - hole_r - a[2], z1 + hole_r - a[2]
            flat_z = np.abs(d[2]) < 1e-12
            between = (lo_z < 0.0) & (hi_z > 0.0)
            ta = np.where(flat_z, np.where(between, -np.inf, 0.0), np.minimum(lo_z / d[2], hi_z / d[2]))
            tb = np.where(flat_z, np.where(between, np.inf, 0.0), np.maximum(lo_z / d[2], hi_z / d[2]))
            lo = np.maximum(np.maximum(t1, ta), 0.0)
            hi = np.minimum(np.minimum(t2, tb), 1.0)
            hit = (lo < hi) & (flat | (disc > 0.0))
            best = np.where(hit, np.minimum(best, lo), best)
    return np.where(np.isfinite(best), best, np.nan)


def passage_bore(a, b, x_front, x_back, tube_r, shoulder, cuts=None, x_axis=None, hole_r=0.0):
    """The bore of the route's segment ``a``-``b`` through the bulkhead between the planes ``x = x_front`` and
    ``x = x_back`` (body frame, mm; the segment crosses its mid-plane): ``(front, back, u, run)``: where the bore's
    axis meets the front and back faces, its unit direction, and the run from the tube's mouth to its seat. The
    mouth sits back in the bore until the rim of the tube's square-cut end (radius ``tube_r``) is inside the front
    face, and ``front`` is the mouth; the tube ends ``shoulder`` short of the back face, or of where its bore
    (radius ``hole_r``) would break into the room ``cuts`` round ``x_axis`` (:func:`room_entry`). Arrays as in
    :func:`room_entry`: the loader's plans and the vectorised rules use this one formula."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    d = b - a
    front = a + (x_front - a[0]) / d[0] * d
    back = a + (x_back - a[0]) / d[0] * d
    span = back - front
    u = span / np.sqrt((span ** 2).sum(axis=0))
    front = front + tube_r * np.sqrt(np.maximum(0.0, 1.0 - u[0] ** 2)) / np.abs(u[0]) * u
    reach = (back - front) * u
    reach = reach.sum(axis=0)
    if cuts is not None:
        t = room_entry(cuts, x_axis, front, back, hole_r)
        reach = np.where(np.isnan(t), reach, t * reach)
    return front, back, u, reach - shoulder


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
    cuts = None if rear is None else room_cylinders(p, rear)
    x_axis = None if rear is None else rear.x_mm
    out = []
    for route in L.cable_routes(p):
        pts = np.asarray(route.points_mm, float)
        for a, b in zip(pts[:-1], pts[1:]):
            if (a[0] - xm) * (b[0] - xm) >= 0:
                continue
            front, back, u, run = passage_bore(a, b, xf, xb, tube_r, shoulder, cuts, x_axis, r_bore)
            seat = front + float(run) * u if run >= L.MIN_TUBE_MM else None
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


def seam_band_mm(p: Params) -> tuple[float, float] | None:
    """(z lo, z hi) of the seam gasket where it lies in the dry wall's section [mm]: from the gap under the seam plane
    (:func:`swiftfin.layout.hull_plan.seam_gasket_gap_mm`) to the plane; None where the sealed pieces are not split
    into halves (no seam to open, no gasket)."""
    from swiftfin.catalogues.seals import seam_gasket
    if not p.hull.split_halves:
        return None
    return -seam_gasket().limiter_length_mm(), 0.0


def seam_clearance_mm(p: Params, g: Gland) -> float:
    """How far gland ``g``'s PTFE tube, from its mouth to its seat, keeps from the seam gasket's band in the dry wall
    (:func:`seam_band_mm`) along z [mm]: negative where it crosses it; infinite with no gasket or no tube. A tube of
    radius r along the unit axis u reaches r sqrt(1 - u_z^2) above and below its axis."""
    band = seam_band_mm(p)
    if band is None or g.packed_mm <= 0.0:
        return math.inf
    u = g.axis
    a = np.asarray(g.front_mm, float)
    b = a + g.packed_mm * u
    half = 0.5 * p.guides.ptfe_tube_od_mm * math.sqrt(max(0.0, 1.0 - float(u[2]) ** 2))
    lo, hi = min(a[2], b[2]) - half, max(a[2], b[2]) + half
    return float(max(lo - band[1], band[0] - hi))


def _seam_problem(p: Params, glands) -> str | None:
    """The refusal of a gland whose tube comes within the assembly clearance of the seam gasket (see
    :func:`gland_plan`), with the most room behind the motors, in half millimetres, that keeps every gland clear
    (each cable's route falls toward its level on joint 1's hinge line, lower at the wall the longer its run)."""
    from dataclasses import fields

    from swiftfin.core.params import replace_key
    from swiftfin.core.schema import Hull
    c = p.print.clearance_assembly_mm
    worst = min(glands, key=lambda g: seam_clearance_mm(p, g), default=None)
    if worst is None or seam_clearance_mm(p, worst) >= c:
        return None
    key, have = "hull.drive_bay_length_mm", p.hull.drive_bay_length_mm
    meta = {f.name: f.metadata for f in fields(Hull)}
    lo_key, gland_lo = meta["drive_bay_length_mm"]["lo"], meta["cable_gland_length_mm"]["lo"]

    def clear(bay: float) -> bool:
        try:
            q = replace_key(p, key, bay)
            return all(seam_clearance_mm(q, g) >= c for g in cable_glands(q))
        except Exception:  # noqa: BLE001 - a layout the loader's other checks refuse there: not a way out
            return False

    lo, hi = math.ceil(lo_key * 2.0) / 2.0, math.floor(have * 2.0) / 2.0 - 0.5
    found = None
    if lo <= hi and clear(lo):
        while hi - lo > 0.25:          # the largest half millimetre that clears
            mid = math.floor((lo + hi) / 2.0 * 2.0) / 2.0
            if mid <= lo:
                mid = lo + 0.5
            lo, hi = (mid, hi) if clear(mid) else (lo, mid - 0.5)
        found = lo
    # less room behind the motors leaves the wall less room ahead of the bay guide (the other refusal here); the
    # wall's room only grows with the motors further forward, so the bound found is the one to try
    room = -math.inf
    if found is not None:
        try:
            room = wall_room_mm(replace_key(p, key, found))
        except Exception:  # noqa: BLE001 - as above
            pass
    if room >= 0.0:
        fix = f"at most {found:g} mm behind the motors (the motors nearer joint 1 keep the cables higher at the wall)"
    elif room + p.hull.cable_gland_length_mm >= gland_lo:
        most = math.floor((room + p.hull.cable_gland_length_mm) * 2.0) / 2.0
        fix = (f"at most {found:g} mm behind the motors (the motors nearer joint 1 keep the cables higher at the "
               f"wall), where the wall has room for glands of at most {most:g} mm (hull.cable_gland_length_mm)")
    else:
        fix = ("no room behind the motors clears it and leaves the wall its room ahead of the bay guide: the cables "
               "fall toward their levels on joint 1's hinge line, which lie about the seam plane; a wall further from "
               "that hinge line keeps them higher (larger stop angles widen the joint's gap: joints.stop_margin_deg)")
    band = seam_band_mm(p)
    d = seam_clearance_mm(p, worst)
    how = f"reaches {-d:.2f} mm into" if d < 0 else f"keeps only {d:.2f} mm from"
    return (f"{key} = {have:g}: {worst.label}'s PTFE tube through the dry compartment's rear wall {how} the seam "
            f"gasket's band (z = {band[0]:g}..{band[1]:g} mm; print.clearance_assembly_mm = {c:g} mm): potted across "
            f"the seam the head opens at, it would bond the lid to the belly pan; {fix}")


def gland_plan(p: Params) -> tuple[Gland, ...]:
    """The cable glands (:func:`cable_glands`), made as the loader makes every plan. Raises :class:`UserError`
    naming ``hull.cable_gland_length_mm``

    * where a gland is wetted through by its cable's stroke (no longer than it: the wet stretch of cable would reach
      the dry side; the build's dry-wall check refuses it), with the least length, in half millimetres, that keeps
      every gland longer than its stroke. Joint 1's own cables run into its sector's room in the wall's back face,
      which shortens their glands below the key's length (the wall grows forward with the key);
    * where the wall's front face comes within the assembly clearance of the bay guide's aft end (the wall is a
      whole cross-section of the hull), with the most length that leaves it.

    and ``hull.drive_bay_length_mm`` where a gland's tube comes within the assembly clearance of the seam gasket,
    which lies in the wall's section where the head opens (:func:`seam_clearance_mm`): potted there, the tube would
    bond the lid to the belly pan. The build's assembly check found it at its end (a 700 mm design with 60 mm
    behind the motors, 2026-12-07: gland_4_right 0.22 mm into the band); of 200 seeded designs 38 had such a tube.
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
                        f"(print.clearance_assembly_mm) from the bay guide's aft end: at most {most:g} mm, or more "
                        f"room behind the motors (hull.drive_bay_length_mm = {p.hull.drive_bay_length_mm:g})")
    glands = cable_glands(p)
    seam = _seam_problem(p, glands)
    if seam is not None:
        raise UserError(seam)
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
               f"wall): more room behind the motors (hull.drive_bay_length_mm = {p.hull.drive_bay_length_mm:g}) "
               f"lets the wall grow; a smaller stop angle (joints.stop_margin_deg, swimming.tail_amplitude_m) or "
               f"moment arm (joints.tendon_moment_arm_mm) shortens the stroke")
    raise UserError(f"{key} = {have:g}: {worst.label}'s potted tube through the dry wall is {worst.packed_mm:.1f} mm "
                    f"long, no longer than its cable's stroke {worst.stroke_mm:.1f} mm (joint {worst.joint}): the wet "
                    f"stretch of cable would reach the dry side; {fix}")
