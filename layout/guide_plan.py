"""PTFE tube guides at the cable routes' "exit" and "bay" bends, as numbers (body frame at rest, mm): channel
paths, block extents, screw points, tube seats and the guides' screws. No CAD kernel: the loader places them
(a design whose bend, posts or screws do not fit is refused when it loads), and :mod:`swiftfin.cad.guide` makes
the solids from the same numbers.

* ``guide_exit_<j>`` (motor j >= 2): between spool j and the spool behind it; holds both of motor j's cables
  through their exit bends into their lanes, and lets the lanes of the motors ahead pass straight through.
  Screwed from above onto two posts of ``motor_mount_<j>`` (:mod:`swiftfin.layout.mount_plate_plan` places the posts at
  :attr:`GuideBlock.screw_points_mm`, :func:`post_radius_mm` across).
* ``guide_bay``: behind the motor row; every cable's bay bend. Screwed onto posts at the aft edge of
  ``motor_mount_1``'s plate; notched over the plate, it hangs down behind the motor as far as the descending
  channels need, and prints upside down (its top is the one flat face).

Screws (:func:`swiftfin.layout.guide_screws.guide_fasteners`, registered in ``cad/fastening.py``):
``guides.screw_diameter_mm`` cap screws driven down from the guide's top into brass heat-set inserts in the tops of
the mount's posts (the post holds the insert maker's wall round it). The head sits on the guide's top when the
shortest screw that fills the insert is one the post can take; otherwise (the tall bay guide) it sinks in a shallow
counterbore just deep enough for the longest catalogue length to fill the insert exactly (a deeper one would open
into the channels below). The key comes from above, before the upper hull half goes on.

**Tube seats.** Each cable's channel is the PTFE tube's bore (OD + sliding clearance) from the face where the
cable comes in (the mouth: the tube is pushed in there) to its seat near the face where the cable leaves, a printed
shoulder (:func:`swiftfin.layout.geometry.tube_seat_shoulder_mm`) short of it, whole round the bore even where the
face is slanted (:attr:`GuideBlock.tube_seats_mm`); the cable's exit hole goes on through the shoulder. The tube is
bonded in (``cad/cables.py``, retention).

Each bent channel follows the route: straight in along the incoming segment, an arc of radius
``guides.min_bend_radius_mm`` through the route's bend angle in the plane of the two segments (tangent to
both), straight out. Its diameter is the tube's OD plus the sliding clearance. Blocks are clipped to the
hull's inner wall (less the assembly gap, :func:`swiftfin.layout.mount_plan.assembly_gap_mm`) at the narrower of
their two ends, and cut clear of the spools beside them. A bend that does not fit raises UserError naming the guide,
the bend angle and the radius.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np

from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.schema import Params
from swiftfin.layout.geometry import (BAY_GUIDE_BENDS, MIN_WEB_LINES, MOTOR_PITCH_GAP_MM, cable_exit_hole_mm,
                                      cable_routes, half_height_mm, motor_placements, naca_half_width_mm, spool_dims,
                                      tube_bore_diameter_mm, tube_seat_shoulder_mm)
from swiftfin.layout.mount_plan import BOSS_MARGIN_MM, assembly_gap_mm, motor_screw_fit


def post_radius_mm(p: Params) -> float:
    """Radius of a guide post on a mount: the insert boss rule (insert hole plus the larger of two lines and the
    insert maker's wall, ``catalogues/fasteners.toml``) and the margin."""
    return fastener(p.guides.screw_diameter_mm).insert_boss_od_mm(p.print.line_width_mm) / 2 + BOSS_MARGIN_MM


@dataclass(frozen=True)
class Channel:
    """A tube channel: polyline in -> (arc) -> out, body frame [mm]. ``angle_rad`` 0 for a straight pass."""
    joint: int                   # 1-based joint of the cable
    side: int
    p_in: tuple                  # a point on the incoming line, outside the block
    t1: tuple                    # arc start (tangent point on the incoming segment)
    t2: tuple                    # arc end
    p_out: tuple                 # a point on the outgoing line, outside the block
    bend_point: tuple            # the route's corner
    angle_rad: float
    radius_mm: float
    centre: tuple                # arc centre
    diameter_mm: float

    @property
    def mid(self) -> tuple:
        """Mid point of the arc (the tangent point for a straight channel)."""
        if self.angle_rad <= 1e-9:
            return self.t1
        c, b = np.asarray(self.centre), np.asarray(self.bend_point)
        w = (b - c) / np.linalg.norm(b - c)
        return tuple(c + self.radius_mm * w)


@dataclass(frozen=True)
class GuideBlock:
    """A guide as numbers: a box (clipped to the hull, less keep-outs and notch) with its channels, body frame [mm]."""
    label: str
    mount: str                   # the motor mount carrying it
    x_mm: tuple[float, float]
    y_mm: tuple[float, float]
    z_mm: tuple[float, float]
    clip_ellipse_mm: tuple[tuple[float, float], tuple[float, float]]   # the hull clip's half-width and
    # half-height (centred on the axis) at x_mm[0] and at x_mm[1]; in between, linear (a ruled loft)
    channels: tuple[Channel, ...]
    screw_points_mm: tuple[tuple[float, float], ...]   # (x, y) of the vertical screws (down into the posts)
    screw_diameter_mm: float
    screw_hole_diameter_mm: float
    keep_out_mm: tuple[tuple[float, float, float], ...] = ()   # (x, y, radius): vertical cylinders cut away (spools)
    seat_z_mm: float | None = None          # underside at the screws (the posts' tops); None: the block's floor
    notch_mm: tuple[float, float] | None = None   # (x, z): the block is cut away for x >= x, z < z (over a plate)
    print_rotation: tuple[float, float, float] = (0.0, 0.0, 0.0)   # floor on the bed; (180, 0, 0): top on the bed
    tube_seats_mm: tuple = ()   # ((joint, side, (x, y, z)), ...): where each cable's tube ends on its shoulder
    exit_hole_diameter_mm: float = 0.0      # the cable's hole on through each shoulder

    @property
    def seat_mm(self) -> float:
        return self.z_mm[0] if self.seat_z_mm is None else self.seat_z_mm

    def tube_seat(self, joint: int, side: int) -> tuple | None:
        """The point on the (joint, side) channel line where its tube ends against the printed shoulder."""
        return next((q for j, s, q in self.tube_seats_mm if (j, s) == (joint, side)), None)


def is_chain_end(b: GuideBlock, ch: Channel) -> bool:
    """Whether ``ch`` is the last channel of its cable's line through the block (no channel of the same cable
    goes on from its outgoing straight)."""
    return not any(o is not ch and (o.joint, o.side) == (ch.joint, ch.side) and np.allclose(ch.p_out, o.t1)
                   for o in b.channels)


def inside_block(b: GuideBlock, pts: np.ndarray, keep_out_pad_mm: float = 0.0) -> np.ndarray:
    """Which points lie in the guide block's printed body before its channels are cut (box, hull clip,
    spool keep-outs, notch), as :func:`guide_solid` makes it. ``keep_out_pad_mm`` widens the
    spool keep-outs (a tube's centre line stops its radius short of a spool's envelope, so its rim does too)."""
    pts = np.atleast_2d(np.asarray(pts, dtype=float))
    (x0, x1), (y0, y1), (z0, z1) = b.x_mm, b.y_mm, b.z_mm
    x, y, z = pts[:, 0], pts[:, 1], pts[:, 2]
    ok = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1) & (z >= z0) & (z <= z1)
    a, h = clip_at(b, x)
    ok &= (y / a) ** 2 + (z / h) ** 2 <= 1.0
    for kx, ky, kr in b.keep_out_mm:
        ok &= np.hypot(x - kx, y - ky) >= kr + keep_out_pad_mm
    if b.notch_mm is not None:
        nx, nz = b.notch_mm
        ok &= ~((x >= nx) & (z < nz))
    return ok


SEAT_STEP_MM = 0.05
"""Step along a channel's outgoing straight when placing its tube's seat."""
SEAT_RING_POINTS = 16
"""Points round the bore's rim at which the shoulder is proved to be printed material."""
SEAT_CHUNK = 16
"""Candidate seats measured at once, farthest first (numpy over a chunk; the search stops at the first whole rim)."""
SEAT_RIM_FRACTION = 0.75
"""Least share of the bore's rim a shoulder must close where no seat closes all of it (the tube check asks half
the ring, ``cad/cables.py`` STOP_FILL_FRACTION)."""


def _tube_seat(b: GuideBlock, ch: Channel, shoulder_mm: float) -> tuple | None:
    """The seat of the tube in ``ch`` (the last channel of its cable's line): the farthest point of the outgoing
    straight, within its last stretch inside the block, from which the bore's rim stays in printed material for
    ``shoulder_mm`` further along (whole round the bore if such a point exists, else at least
    :data:`SEAT_RIM_FRACTION` of it: a channel near the hull's clip runs open at its side). None when the straight
    has no such point (no tube there, or a channel open along its length: the build's tube check then names it)."""
    start = np.asarray(ch.t2 if ch.angle_rad > 1e-9 else ch.t1, float)
    d = unit_vector(np.subtract(ch.p_out, start))
    n = int(math.ceil(np.linalg.norm(np.subtract(ch.p_out, start)) / SEAT_STEP_MM)) + 1
    s = np.arange(n) * SEAT_STEP_MM
    inside = inside_block(b, start + s[:, None] * d)
    if not inside.any():
        return None
    last = int(np.flatnonzero(inside)[-1])
    e1 = unit_vector(np.cross(d, (0.0, 0.0, 1.0)) if abs(d[2]) < 0.9 else np.cross(d, (1.0, 0.0, 0.0)))
    e2 = np.cross(d, e1)
    ang = np.linspace(0, 2 * math.pi, SEAT_RING_POINTS, endpoint=False)
    rim = ch.diameter_mm / 2 * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2)
    depth = np.linspace(0.0, shoulder_mm, 4)
    first = last                          # the run of points inside the block ending at ``last``, never index 0:
    while first > 1 and inside[first - 1]:    # the bore keeps a length of straight
        first -= 1
    if last < 1:
        return None
    cand = np.arange(last, first - 1, -1)                                   # farthest first
    q = start + s[cand, None] * d                                           # (k, 3)
    filled = []
    for k0 in range(0, len(cand), SEAT_CHUNK):       # a whole rim is usually found among the farthest few
        ring = (q[k0:k0 + SEAT_CHUNK, None, None, :] + depth[None, :, None, None] * d
                + rim[None, None, :, :])                                    # (k, depths, points, 3)
        filled.append(inside_block(b, ring.reshape(-1, 3)).reshape(ring.shape[:3]).mean(axis=2).min(axis=1))
        whole = np.flatnonzero(filled[-1] >= 1.0)
        if len(whole):
            return tuple(float(c) for c in q[k0 + whole[0]])
    ok = np.flatnonzero(np.concatenate(filled) >= SEAT_RIM_FRACTION)
    return tuple(float(c) for c in q[ok[0]]) if len(ok) else None


def screw_hole_diameter_mm(p: Params) -> float:
    """Clearance hole for the guide screws (ISO 273 medium, ``catalogues/fasteners.toml``)."""
    return fastener(p.guides.screw_diameter_mm).clearance_hole_mm


def unit_vector(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


POST_STEP_MM = 0.05
"""Step aft of a guide's posts, from just inside the motor frame's edge, while they do not fit (a large drum)."""


def _head_gap_mm(p: Params, dx_mm: float, y_mm: float, post_r_mm: float) -> float:
    """Gap in plan between a post ``dx_mm`` along x and ``y_mm`` across from a motor's axis and the nearest of that
    motor's mounting screw heads (at +/- half the hole spacing; a head's radius taken as the screw's diameter)."""
    hs = p.motor.hole_spacing_mm / 2
    return math.hypot(abs(dx_mm) - hs, abs(y_mm) - hs) - post_r_mm - p.motor.mount_screw_diameter_mm


def _hole_wall_mm(p: Params) -> float:
    """The wall kept round a guide screw's hole: two perimeters (:data:`~swiftfin.layout.geometry.MIN_WEB_LINES`
    line widths, what the fastener check asks with the default ``rules.wall_min_line_widths``: the rule is the
    check's, never an input of the parts) and :data:`~swiftfin.layout.mount_plan.BOSS_MARGIN_MM` (the check measures
    on the meshes from just inside the hole's surface: a wall of exactly two lines read 0.84 mm of 0.87)."""
    return MIN_WEB_LINES * p.print.line_width_mm + BOSS_MARGIN_MM


def _clear_of_spool_mm(reach_mm: float, dx_mm: float) -> float:
    """How far off the body axis (|y|) a screw ``dx_mm`` along x from a spool's axis must stand for its hole's edge
    and wall (``reach_mm`` from the hole's centre to the spool's envelope's radius) to clear the envelope."""
    return math.sqrt(max(0.0, reach_mm**2 - dx_mm**2))


def bend_channel(prev, corner, nxt, radius: float, diameter: float, joint: int, side: int, reach: float) -> Channel:
    """Channel through the corner of the polyline prev -> corner -> next with an arc of ``radius``."""
    a, b, c = (np.asarray(q, dtype=float) for q in (prev, corner, nxt))
    u, v = unit_vector(b - a), unit_vector(c - b)
    angle = math.acos(max(-1.0, min(1.0, float(u @ v))))
    t = radius * math.tan(angle / 2)
    t1, t2 = b - t * u, b + t * v
    if angle > 1e-9:
        w = unit_vector(v - (v @ u) * u)
        centre = t1 + radius * w
    else:
        centre = b
    return Channel(joint, side, tuple(t1 - reach * u), tuple(t1), tuple(t2), tuple(t2 + reach * v), tuple(b),
                   angle, radius, tuple(centre), diameter)


CLIP_SAMPLES = 9
"""Stations between a block's ends at which its ruled hull clip is proved inside the hull's inner section."""


def _clip_ellipse(p: Params, s0_mm: float, s1_mm: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """The hull's inner cross-section, less the clearance, at each end of [s0, s1] (stations), joined by a ruled
    loft: the sections in between have the semi-axes linearly between the ends'. The hull's half-width and
    half-height are concave in the station (a foil's thickness), so the chord lies inside; where a design's are
    not, both ends shrink by the most the chord stands out at :data:`CLIP_SAMPLES` stations between them. (The
    clip used to be the narrower end's section all along, which left the bay guide's outer channels breaking
    out of its sides at the wider end: 0.00-0.20 mm walls, 2026-11-27.)"""
    c = assembly_gap_mm(p)

    def inner(s):
        return np.array([float(naca_half_width_mm(p, s)), float(half_height_mm(p, s))]) - p.hull.wall_thickness_mm - c

    e0, e1 = inner(s0_mm), inner(s1_mm)
    excess = max(0.0, max(float(np.max((1 - t) * e0 + t * e1 - inner((1 - t) * s0_mm + t * s1_mm)))
                          for t in np.linspace(0.0, 1.0, CLIP_SAMPLES)))
    return tuple(map(float, e0 - excess)), tuple(map(float, e1 - excess))


def clip_at(b: GuideBlock, x_mm):
    """The hull clip's (half-width, half-height) at body-frame ``x_mm`` (scalar or array), as the loft has it."""
    (a0, h0), (a1, h1) = b.clip_ellipse_mm
    x0, x1 = b.x_mm
    t = np.clip((np.asarray(x_mm, dtype=float) - x0) / (x1 - x0), 0.0, 1.0)
    return a0 + t * (a1 - a0), h0 + t * (h1 - h0)


def arc_points(ch: Channel, n: int = 33) -> np.ndarray:
    """Points along the channel's arc, t1 to t2."""
    if ch.angle_rad <= 1e-9:
        return np.array([ch.t1])
    c = np.asarray(ch.centre)
    a, b = np.asarray(ch.t1) - c, np.asarray(ch.t2) - c
    w = b - (b @ a) / (a @ a) * a
    w = w / np.linalg.norm(w) * ch.radius_mm
    f = np.linspace(0, ch.angle_rad, n)[:, None]
    return c + np.cos(f) * a + np.sin(f) * w


def channel_centre_lines(b: GuideBlock, arc=arc_points, straight=None) -> list[tuple[int, int, np.ndarray]]:
    """Each cable's centre line through the block, ``(joint, side, points)``: straight in, arc, straight out, with a
    lane's drop and turn (two channels sharing the straight between them) joined into one line. ``arc(ch)`` gives
    the points of a channel's arc, t1 to t2; ``straight(a, b)`` those of a straight stretch (default: its ends)."""
    straight = straight or (lambda a, c: np.array([a, c], dtype=float))
    chains: list[list[Channel]] = []
    for ch in b.channels:
        last = chains[-1][-1] if chains else None
        if last is not None and (last.joint, last.side) == (ch.joint, ch.side) and np.allclose(last.p_out, ch.t1):
            chains[-1].append(ch)
        else:
            chains.append([ch])
    out = []
    for chain in chains:
        parts, start = [], chain[0].p_in
        for ch in chain:
            parts += [straight(np.asarray(start, float), np.asarray(ch.t1, float)),
                      arc(ch) if ch.angle_rad > 1e-9 else np.array([ch.t1], dtype=float)]
            start = ch.t2 if ch.angle_rad > 1e-9 else ch.t1
        parts.append(straight(np.asarray(start, float), np.asarray(chain[-1].p_out, float)))
        out.append((chain[0].joint, chain[0].side, np.vstack(parts)))
    return out


def _straight_in_box(b: GuideBlock, step_mm: float):
    """Points every ``step_mm`` along a straight stretch, only where it lies within the block's x range."""
    x0, x1 = b.x_mm

    def straight(a: np.ndarray, c: np.ndarray) -> np.ndarray:
        dx = c[0] - a[0]
        lo, hi = 0.0, 1.0
        if abs(dx) > 1e-12:
            t0, t1 = sorted(((x0 - a[0]) / dx, (x1 - a[0]) / dx))
            lo, hi = max(lo, t0), min(hi, t1)
        elif not x0 <= a[0] <= x1:
            return np.empty((0, 3))
        if hi < lo:
            return np.empty((0, 3))
        k = max(1, int(math.ceil((hi - lo) * float(np.linalg.norm(c - a)) / step_mm)))
        return a + np.linspace(lo, hi, k + 1)[:, None] * (c - a)
    return straight


CLEARANCE_STEP_MM = 0.5
"""Spacing of the points at which :func:`channel_clearance_mm` measures: between two lines 4.5 mm apart it reads at
most 0.014 mm over their true distance (both ends of the closest pair a quarter step off)."""


def channel_clearance_mm(p: Params, b: GuideBlock) -> list[tuple[float, tuple[int, int], tuple[int, int], np.ndarray]]:
    """Closest approach of every two cables' channels inside the block (those whose extents come within two tube
    ODs), between centre lines, ``(distance, (joint, side), (joint, side), point)``, closest first: each tube (its OD) must clear the other by
    ``print.clearance_assembly_mm``, as the build's assembly check measures them on the tubes (their meshes lie
    inside the round surfaces, so they clear by no less)."""
    od = p.guides.ptfe_tube_od_mm
    lines = []
    for j, s, pts in channel_centre_lines(b, arc=lambda ch: arc_points(ch, 65),
                                          straight=_straight_in_box(b, CLEARANCE_STEP_MM)):
        pts = pts[inside_block(b, pts, od / 2)]
        if len(pts):
            lines.append(((j, s), pts))
    out = []
    boxes = [(pts.min(axis=0), pts.max(axis=0)) for _, pts in lines]
    for a in range(len(lines)):
        for c in range(a + 1, len(lines)):
            (lo_a, hi_a), (lo_c, hi_c) = boxes[a], boxes[c]
            if float(np.linalg.norm(np.maximum(0.0, np.maximum(lo_a - hi_c, lo_c - hi_a)))) > 2 * od:
                continue              # boxes far apart: not among the closest that matter
            d2 = ((lines[a][1][:, None, :] - lines[c][1][None, :, :]) ** 2).sum(axis=-1)   # a few hundred each
            i = int(np.argmin(d2)) // d2.shape[1]
            out.append((math.sqrt(float(d2.min())), lines[a][0], lines[c][0], lines[a][1][i]))
    return sorted(out, key=lambda t: t[0])


def _check_channel_clearance(p: Params, b: GuideBlock) -> None:
    need = p.guides.ptfe_tube_od_mm + p.print.clearance_assembly_mm
    close = channel_clearance_mm(p, b)
    if close and close[0][0] < need - 1e-6:
        d, (j1, s1), (j2, s2), q = close[0]
        name = lambda j, s: f"joint {j}'s {'left' if s > 0 else 'right'} cable"   # noqa: E731
        raise UserError(f"{b.label}: the tube channels of {name(j1, s1)} and {name(j2, s2)} come {d:.2f} mm apart "
                        f"between centre lines at ({q[0]:.1f}, {q[1]:.1f}, {q[2]:.1f}) mm, where a tube's OD and "
                        f"print.clearance_assembly_mm need {need:.2f} mm (guides.ptfe_tube_od_mm = "
                        f"{p.guides.ptfe_tube_od_mm:g} mm; "
                        f"a smaller guides.min_bend_radius_mm = {p.guides.min_bend_radius_mm:g} mm keeps the "
                        f"channels nearer the routes, which clear it where they cross)")


def _check_arc(label: str, ch: Channel, x_lo: float, x_hi: float, seg_in: float, seg_out: float,
               axes=(), keep_out: float = 0.0) -> None:
    t = ch.radius_mm * math.tan(ch.angle_rad / 2)
    arc = arc_points(ch)
    xs = arc[:, 0]
    problems = []
    for ax, ay in axes:
        gap = float(np.min(np.hypot(arc[:, 0] - ax, arc[:, 1] - ay))) - keep_out
        if gap < -1e-6:
            problems.append(f"the arc runs {-gap:.1f} mm into the spool at x = {ax:.1f} mm")
    if t > seg_in or t > seg_out:
        problems.append(f"the arc needs {t:.1f} mm of straight route on each side, the route has "
                        f"{min(seg_in, seg_out):.1f} mm")
    if min(xs) < x_lo - 1e-6 or max(xs) > x_hi + 1e-6:
        problems.append(f"the arc spans x = {min(xs):.1f} .. {max(xs):.1f} mm, the guide's room is "
                        f"x = {x_lo:.1f} .. {x_hi:.1f} mm")
    if problems:
        raise UserError(f"{label}: the {math.degrees(ch.angle_rad):.1f} deg bend of joint {ch.joint}'s "
                        f"{'left' if ch.side > 0 else 'right'} cable cannot be made with the minimum bend radius "
                        f"guides.min_bend_radius_mm = {ch.radius_mm:g} mm: " + "; ".join(problems)
                        + " (use a smaller guides.min_bend_radius_mm, i.e. a more flexible tube"
                        + (", or more room behind the motors, hull.drive_bay_length_mm" if label == "guide_bay" else "")
                        + ")")


def _with_seats(p: Params, b: GuideBlock) -> GuideBlock:
    shoulder = tube_seat_shoulder_mm(p)
    seats = ((ch.joint, ch.side, _tube_seat(b, ch, shoulder)) for ch in b.channels if is_chain_end(b, ch))
    return replace(b, exit_hole_diameter_mm=cable_exit_hole_mm(p),
                   tube_seats_mm=tuple(q for q in seats if q[2] is not None))


@functools.lru_cache(maxsize=64)
def guide_blocks(p: Params) -> tuple[GuideBlock, ...]:
    """The exit guides (motors 2..N) and the bay guide, with their tubes' seats. Raises UserError if a bend does
    not fit.

    Memoised on the params, as :func:`swiftfin.layout.hull_plan.hull_pieces` (the guides and the tubes ask for
    them; a family cache's recording view is equal only to itself, so it never receives blocks computed without
    recording its reads)."""
    return tuple(_with_seats(p, b) for b in bare_guide_blocks(p))


@functools.lru_cache(maxsize=64)
def bare_guide_blocks(p: Params) -> tuple[GuideBlock, ...]:
    """:func:`guide_blocks` without the tubes' seats (``tube_seats_mm`` empty, no exit hole): what the mounts'
    posts and every screw read. The seats are most of the blocks' cost (0.85 s on the default design, against
    about 0.1 s for the rest), and every family cuts its holes from all the design's fasteners."""
    g, pr = p.guides, p.print
    d = spool_dims(p)
    c = assembly_gap_mm(p)
    wall = pr.perimeters * pr.line_width_mm
    R = g.min_bend_radius_mm
    dia = tube_bore_diameter_mm(p, "guide")
    r_ch = dia / 2
    motors = motor_placements(p)
    routes = cable_routes(p)
    post_r = post_radius_mm(p)
    reach = 4 * R + 100.0
    blocks = []
    # ---- exit guides: from the spool behind's axis to this spool's axis, less both spools' envelopes
    env_r = d.flange_radius_mm + c
    for mp in motors[1:]:
        label = f"guide_exit_{mp.joint + 1}"
        behind = motors[mp.joint - 1]
        # up to the spools' axes, less half a gap: the exit guides either side of a spool do not touch
        x_lo, x_hi = behind.x_mm + c / 2, mp.x_mm - c / 2
        if 2 * env_r + 2 * wall > x_hi - x_lo:
            raise UserError(f"{label}: the spools' flanges (radius {d.flange_radius_mm:.1f} mm) leave no room for "
                            f"the guide between motors {mp.joint} and {mp.joint + 1} ({x_hi - x_lo:.1f} mm apart): "
                            f"use a smaller spool.drum_diameter_mm or spool.flange_height_mm")
        axes = ((mp.x_mm, 0.0), (behind.x_mm, 0.0))
        chans = []
        for r in routes:
            if r.joint != mp.joint:
                continue
            pts = r.points_mm
            ch = bend_channel(pts[0], pts[1], pts[2], R, dia, r.joint + 1, r.side, reach)
            _check_arc(label, ch, x_lo, x_hi, float(np.linalg.norm(np.subtract(pts[1], pts[0]))),
                       float(np.linalg.norm(np.subtract(pts[2], pts[1]))),
                       axes, env_r + g.ptfe_tube_od_mm / 2)
            chans.append(ch)
        for r in routes:   # the lanes of the motors ahead pass straight through
            if r.joint > mp.joint:
                y, z = r.points_mm[2][1], r.points_mm[2][2]
                chans.append(Channel(r.joint + 1, r.side, (x_hi + reach, y, z), (x_hi, y, z), (x_hi, y, z),
                                     (x_lo - reach, y, z), (x_hi, y, z), 0.0, 0.0, (x_hi, y, z), dia))
        ys = [abs(ch.t2[1]) for ch in chans]
        zs = [ch.t2[2] for ch in chans]
        y_half = max(ys) + r_ch + wall
        zr = (min(zs) - r_ch - wall, max(zs) + r_ch + wall)
        hole_r = screw_hole_diameter_mm(p) / 2
        # the posts stand just inside the motor frame's aft edge, the fastener check's wall between each screw hole
        # and the spool's envelope (one line, as it was, left 0.65 mm of 0.87 on a seeded design's large drum,
        # 2026-11-29), clear of the motor's screw heads; where a large drum leaves no room between the two, they
        # step aft (their plate's edge toward the mount behind, keeping the assembly gap from it)
        for back in np.arange(0.0, max(MOTOR_PITCH_GAP_MM - wall - c, 0.0) + 1e-9, POST_STEP_MM):
            x_post = float(mp.x_mm - p.motor.frame_size_mm / 2 + post_r - back)
            dx = x_post - mp.x_mm
            y_post = max(p.motor.hole_spacing_mm / 4, _clear_of_spool_mm(env_r + hole_r + _hole_wall_mm(p), dx))
            head_gap = _head_gap_mm(p, dx, y_post, post_r)
            if head_gap >= 0:
                break
        if head_gap < 0:
            raise UserError(f"{label}: its posts (at {dx:.1f}, +/-{y_post:.1f} mm from the motor axis, clear of "
                            f"spool {mp.joint + 1}'s flange of radius {d.flange_radius_mm:.1f} mm) would sit on the "
                            f"motor's screw heads: use a smaller spool.drum_diameter_mm or spool.flange_height_mm")
        # a post stands under the block's floor: where it reaches into the spool's envelope in plan (a large drum
        # on a small frame: 0.77 mm on a seeded design, whose posts then stood 0.4 mm into the lower flange,
        # 2026-11-29), the floor comes down to the flange's underside less the gap, so the post stops short of it
        flange_bottom = mp.z_face_mm + d.hub_bottom_mm + d.hub_length_mm - c
        if math.hypot(dx, y_post) - post_r < env_r and zr[0] > flange_bottom:
            zr = (flange_bottom, zr[1])
        # trim to the arcs plus one tube diameter of straight channel either side, and the screws
        arcs_x = np.concatenate([arc_points(ch)[:, 0] for ch in chans if ch.angle_rad > 0])
        x_lo = max(x_lo, min(float(arcs_x.min()) - g.ptfe_tube_od_mm, x_post - post_r - wall))
        x_hi = min(x_hi, max(float(arcs_x.max()) + g.ptfe_tube_od_mm, x_post + post_r + wall))
        blocks.append(GuideBlock(
            label, f"motor_mount_{mp.joint + 1}", (x_lo, x_hi), (-y_half, y_half), zr, _clip_ellipse(p, -x_lo, -x_hi),
            tuple(chans), ((x_post, y_post), (x_post, -y_post)), g.screw_diameter_mm, screw_hole_diameter_mm(p),
            tuple((x, y, env_r) for x, y in axes)))
    # ---- bay guide: behind the rear spool, on posts at the aft edge of motor_mount_1's plate; it reaches
    # forward over the plate (notched over the plate and the motor's screw heads) and hangs down aft of the
    # motor's frame as far as the descending channels need.
    rear = motors[0]
    label = "guide_bay"
    F = p.motor.frame_size_mm
    hole_r = screw_hole_diameter_mm(p) / 2
    plate_top = rear.z_face_mm + d.plate_mm
    env_r = d.flange_radius_mm + c
    # between the rear motor's own two cables (they leave the drum at y = +/- its radius), two lines of wall from each,
    # and the fastener check's wall from the rear spool's envelope (the block is cut clear of it over the plate),
    # clear of the motor's screw heads: just inside the frame's aft edge, or stepped aft (a large drum) until they fit
    y_cables = d.drum_radius_mm - r_ch - hole_r - 2 * pr.line_width_mm
    for back in np.arange(0.0, post_r + 1e-9, POST_STEP_MM):
        x_post = float(rear.x_mm - F / 2 + post_r - back)
        dx = x_post - rear.x_mm
        y_env = _clear_of_spool_mm(env_r + hole_r + _hole_wall_mm(p), dx)
        y_post = min(max(p.motor.hole_spacing_mm / 4, y_env), y_cables)
        fits = not (y_post < y_env - 1e-9 or (y_post < post_r and y_env > 0.0))
        if fits and _head_gap_mm(p, dx, y_post, post_r) >= 0:
            break
    else:
        raise UserError(f"{label}: no room for its screws between motor 1's two cables (|y| <= {y_cables:.1f} mm), "
                        f"clear of spool 1's flange and of the motor's screw heads: use a smaller "
                        f"spool.flange_height_mm or guides.screw_diameter_mm")
    screws = ((x_post, y_post), (x_post, -y_post)) if y_post >= post_r else ((x_post, 0.0),)
    chans = []
    for r in routes:
        pts = r.points_mm
        seg = [float(np.linalg.norm(np.subtract(pts[k + 1], pts[k]))) for k in range(len(pts) - 1)]
        made = [(bend_channel(pts[k - 1], pts[k], pts[k + 1], R, dia, r.joint + 1, r.side, reach), seg[k - 1], seg[k])
                for k in (i + 1 for i, b in enumerate(r.bends) if b.kind in BAY_GUIDE_BENDS)]
        if len(made) == 2:   # a lane's drop then its turn: the straight between them holds both arcs' tangents
            (a, a_in, a_out), (b, b_in, b_out) = made
            ta, tb = (ch.radius_mm * math.tan(ch.angle_rad / 2) for ch in (a, b))
            made = [(replace(a, p_out=b.t1), a_in, a_out - tb), (replace(b, p_in=a.t2), b_in - ta, b_out)]
        chans += made
    x_lo = min(float(arc_points(ch)[:, 0].min()) for ch, _, _ in chans) - g.ptfe_tube_od_mm
    x_hi = min(rear.x_mm, max([x_post + post_r + wall]
                              + [float(arc_points(ch)[:, 0].max()) + g.ptfe_tube_od_mm for ch, _, _ in chans]))
    for ch, a, b in chans:
        _check_arc(label, ch, x_lo, x_hi, a, b, ((rear.x_mm, 0.0),), env_r + g.ptfe_tube_od_mm / 2)
    chans = [ch for ch, _, _ in chans]
    # extents of the channel centre lines inside [x_lo, x_hi]
    samples = []
    f = np.linspace(0, 1, 401)[:, None]
    for ch in chans:
        for q0, q1 in ((ch.p_in, ch.t1), (ch.t2, ch.p_out)):
            q0 = np.asarray(q0, float)
            samples.append(q0 + f * (np.asarray(q1, float) - q0))
        samples.append(arc_points(ch))
    samples = np.vstack(samples)
    samples = samples[(samples[:, 0] >= x_lo) & (samples[:, 0] <= x_hi)]
    y_half = float(np.max(np.abs(samples[:, 1]))) + r_ch + wall
    zr = (float(np.min(samples[:, 2])) - r_ch - wall, float(np.max(samples[:, 2])) + r_ch + wall)
    # the seat on the posts: above the plate and the motor screws' heads (on their spot faces)
    fit = motor_screw_fit(p)
    seat = plate_top + fit.spot_face_mm + fit.head_height_mm + c
    notch_x = min(rear.x_mm - F / 2, x_post - post_r - wall) - c   # the plate's aft edge (mount_plate_plan)
    over_plate = samples[samples[:, 0] >= notch_x - r_ch]
    if len(over_plate) and float(over_plate[:, 2].min()) - r_ch - wall < seat:
        raise UserError(f"{label}: the channels over motor_mount_1 come down to z = "
                        f"{float(over_plate[:, 2].min()) - r_ch:.1f} mm, too close to the plate and its screw heads "
                        f"(z = {seat:.1f} mm) for the guide's floor: use a smaller guides.min_bend_radius_mm = {R:g} "
                        f"mm or a larger spool.hub_length_mm")
    notch = (notch_x, seat) if zr[0] < seat else None
    if notch is None:
        seat = zr[0]
    blocks.append(GuideBlock(label, "motor_mount_1", (x_lo, x_hi), (-y_half, y_half), zr,
                             _clip_ellipse(p, -x_lo, -x_hi), tuple(chans), screws,
                             g.screw_diameter_mm, screw_hole_diameter_mm(p),
                             ((rear.x_mm, 0.0, env_r),), seat_z_mm=seat, notch_mm=notch,
                             print_rotation=(180.0, 0.0, 0.0)))
    for b in blocks:
        _check_channel_clearance(p, b)
    return tuple(blocks)


def channel_bores_mm(b: GuideBlock) -> list[list]:
    """The block's tube channels as bore segments, ``[[x, y, z], [x, y, z], radius]`` each (an arc as chords of
    :func:`arc_points`, within 0.01 mm of it): the webs between two of them are held to one line width by the wall
    probe (``exports/printability.py``), not to two perimeters.

    Why a web between two tubes' bores carries no load that its thinness matters to: each tube is bonded in its
    own bore; along a straight it pushes on nothing, and round an arc it bears on the inside of its bend with the
    cable's tension over the radius (T / R: 2.25 N per mm at the default 45 N of pretension round its 20 mm bends),
    which presses the web through its thickness against the next tube, which backs it. Compression through the
    thickness over the tube's height (about its OD) is about 1 MPa at pretension, against some 60 MPa that PLA takes
    in compression; nothing bends or pulls the web. Two perimeters are for walls that do; this web needs only to be
    there, one line wide (PrusaSlicer's variable-width perimeters print a 0.6 mm web as one line)."""
    out = []
    for ch in b.channels:
        r = ch.diameter_mm / 2
        if ch.angle_rad <= 1e-9:                   # a lane passing straight through
            out.append([list(map(float, ch.p_in)), list(map(float, ch.p_out)), r])
            continue
        arc = arc_points(ch)
        line = np.vstack([np.asarray(ch.p_in, float), arc, np.asarray(ch.p_out, float)])
        out += [[list(map(float, line[k])), list(map(float, line[k + 1])), r] for k in range(len(line) - 1)]
    return out


def guide_screw_fit(p: Params, b: GuideBlock, post_height_mm: float) -> tuple[float, float, float]:
    """(length, grip, recess) of ``b``'s screws: head on the top when the shortest screw that fills the insert leaves
    the post's floor under its tip, else the longest catalogue length, its thread ending at the insert's end and its
    head sunk as far as that needs."""
    s = fastener(b.screw_diameter_mm)
    floor = p.print.top_layers * p.print.layer_height_mm
    grip_max = b.z_mm[1] - b.seat_mm
    length = s.length_for(grip_max + s.insert_length_mm)
    if length is not None and length - grip_max <= post_height_mm - floor + 1e-9:
        return length, grip_max, 0.0
    length = s.length_at_most(grip_max + s.insert_length_mm)
    if length is None or length - s.insert_length_mm < 2 * p.print.line_width_mm:
        raise BuildError(f"{b.label}: no {s.name} length fits its {grip_max:.1f} mm tall block and its posts "
                         f"({post_height_mm:.1f} mm)")
    grip = length - s.insert_length_mm
    return length, grip, grip_max - grip
