"""Capstan spools as numbers: one split spool per motor, on its shaft, in the body frame at rest (mm). The spool is
also the cable's tensioner (the argument for that choice is in :mod:`swiftfin.layout.tension`). No CAD kernel: the
loader makes these numbers (``layout/design.py``), so a design whose spools cannot be made is refused there, naming
the key, instead of half-way through a build (three of six seeded designs were, 2026-11-29).

Numbers (:func:`spool_numbers`, built on :func:`swiftfin.layout.geometry.spool_dims`) and fasteners as records
(:func:`spool_fasteners`, listed in ``swiftfin.cad.fastening.FASTENER_PLANS``; their holes are cut by the registry
from the same records); the solids are :mod:`swiftfin.cad.spool`'s.

The spool, from the motor face up: hub (bore with the shaft's D-flat; a radial set screw onto the flat, threaded
in a brass heat-set insert in a boss of the hub that ends in a flat face, the screw flush with it when tight),
lower flange, grooved drum, upper flange. (Issue 12: a nut in a trap that dropped in through a slot from the hub's
underside left no wall under the nut; a trap open along the screw would let the nut, which the set screw pushes
outward, walk out. The insert takes the screw's thrust on its knurl all round.) The set screw points a quarter turn
from the cable anchors, to the side: the motors and spools stand in a row along x, so its key reaches it only from
the side, before the head's upper half goes on. Both spool screws are driven, and the cables tensioned, before the
head's upper halves close it (their records list those halves in ``installed_after``:
:func:`swiftfin.layout.hull_plan.head_lid_labels`). The drum is **split at the cable plane** into two parts that turn on the shaft:

* ``spool_<j>`` (lower): hub, lower flange, the drum below the cable plane; carries the **right** cable.
* ``spool_<j>_upper``: the drum above the cable plane and the upper flange, a round bore turning on the shaft;
  carries the **left** cable.

The halves are locked by one screw (``spool.index_screw_diameter_mm``) through a vernier of index holes: the
upper half has ``spool.index_holes_upper`` clearance holes, the lower ``spool.index_holes_lower`` self-tap
pilots on the same circle, so some pair lines up every 360 / (upper x lower) degrees (5.7 deg by default: 7 and
9; the upper ring's nearest holes lie half its pitch either side of the anchors and must clear the upper crimp's
seat by two perimeters, which 10 holes did not). Turning
the upper half clockwise (from above) against the lower winds both cables in and raises the pretension by a
known amount per step (:func:`swiftfin.layout.tension.tensioner_numbers`). When the screw would reach further
into the lower half than it is deep, the screw is the longest catalogue length whose pilot stays in the lower half,
and the upper half's top face is sunk in a ring round the index circle (the heads sit in it) until the screw holds
1.5 d of thread.

Interpretation of the parameters:

* The **cable centre line** winds at radius ``spool.drum_diameter_mm / 2``: the radius the layout's cable routes
  leave the drum at and the moment arm the physics uses. The groove root lies one cable radius inside it, the drum
  surface ``spool.groove_depth_mm`` above the root. The groove section is a circle of diameter
  ``cable.diameter_mm + print.clearance_sliding_mm`` resting on the root. The **ridge** between two turns (pitch
  minus the groove's width at the drum surface) must be at least ``print.line_width_mm`` (UserError otherwise).
* The groove is a **right-handed helix** (z rises counter-clockwise seen from above), so the pull-pull cable,
  leaving the drum on both sides toward the tail, wraps between its two leave points: the left (+y) cable leaves
  from the upper end of the wrapped region, the right one from the lower end. The groove runs ``groove_turns``
  turns centred on the cable plane: wraps, the joint's travel at both ends, the margin and the tensioner's storage.
* **Anchors and crimp seats.** Each cable end is wound from its leave point toward the cable plane and dives, half
  a turn before it, into a radial hole at the groove root (half a pitch from the split, on its own half, its axis
  moved off the split until two layers of print are left between the hole and the split face), then
  leaves its half through an axial hole: the left one up through the upper flange, the right one down through the
  lower flange beside the hub. A crimp sleeve (``swiftfin.catalogues.cable_parts``) on the end bears on the
  flange round the hole: the upper one in a counterbore in the top face, the lower one in a channel down the
  hub's side. The capstan's half turn between anchor and leave point unloads the crimp to e^(-mu pi) = 1/3 of
  the cable's tension.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from swiftfin.catalogues.cable_parts import crimp_sleeve
from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import PILOT_PAST_TIP_MM, Fastener
from swiftfin.layout.geometry import cable_routes, motor_placements, spool_dims, spool_travel_turns

WALL_LINES = 2
"""Least printed wall round a hole, a trap or a seat, in line widths (two perimeters; issue 12)."""

ANCHOR_FROM_SPLIT_TURNS = 0.5
"""Groove between a cable's anchor hole and the split plane [turns]: half a turn puts the anchor's radial hole
half a pitch from the split, on its own half, clear of it by a groove radius. (Further round, the capstan between
the anchor and the leave point, 90 deg at rest, would no longer cover joint 4's travel.)"""
ANCHOR_FLOOR_LAYERS = 2
"""Layers of the print left between an anchor's radial hole and the split face: where half a pitch leaves less (a
1.6 mm hole half of a 1.8 mm pitch from the split is 0.1 mm from it: a skin no printer lays), the hole's axis
moves away from the split by the difference, and the cable bends into it by as much (0.32 mm by default, inside
the hole's sliding clearance)."""
ANCHOR_FLOOR_MARGIN_MM = 0.02
"""Kept over the layers, so the tessellated floor does not read a hair under them."""

@dataclass(frozen=True)
class SpoolNumbers:
    """Everything the spool's two solids are built from, in the spool's own frame: z up the shaft from the motor's
    mounting face, angles counter-clockwise from the body's +x axis seen from above [mm, rad]."""
    joint: int                  # 1-based joint the motor drives
    axis_xy_mm: tuple[float, float]
    z_face_mm: float
    hub_radius_mm: float
    hub_z_mm: tuple[float, float]
    flange_radius_mm: float
    lower_flange_z_mm: tuple[float, float]
    drum_z_mm: tuple[float, float]
    upper_flange_z_mm: tuple[float, float]
    split_z_mm: float           # the halves meet here (the cable plane)
    pitch_radius_mm: float      # cable centre line
    root_radius_mm: float       # groove bottom
    surface_radius_mm: float    # drum surface between the groove turns
    groove_radius_mm: float     # radius of the groove's circular section
    groove_centre_radius_mm: float
    groove_pitch_mm: float
    groove_turns: float
    ridge_width_mm: float       # axial width of the drum surface between two groove turns
    cable_plane_mm: float       # groove (and wrap) centre height
    groove_start_angle_rad: float  # angle of the lower end of the groove helix
    leave_angles_rad: tuple[float, float]   # (left, right) cable leave points
    wrap_between_rad: float     # angle of groove between the two leave points
    anchor_hole_diameter_mm: float
    anchor_radius_mm: float     # radius of the axial part of the anchor holes
    anchor_angles_rad: tuple[float, float]  # (left, right) radial part of the anchor holes (helix angles)
    anchor_z_mm: tuple[float, float]        # (left, right) heights of the radial holes' axes (spool frame)
    crimp_seat_diameter_mm: float
    crimp_length_mm: float
    bore_radius_mm: float
    flat_distance_mm: float     # from the axis to the bore's flat (printed, with the sliding clearance)
    shaft_flat_mm: float        # from the axis to the shaft's own flat (where the set screw's tip bears)
    set_screw_angle_rad: float  # direction of the flat and of the set screw (from the axis out)
    set_screw_z_mm: float
    set_screw_length_mm: float
    set_screw_boss_x_mm: tuple[float, float]  # (insert pocket's floor, boss face) from the axis along the screw
    set_screw_boss_half_width_mm: float       # the boss (and the hub) half-width: insert hole / 2 + its wall
    index_radius_mm: float
    index_angles_upper_rad: tuple[float, ...]
    index_angles_lower_rad: tuple[float, ...]
    index_screw: str
    index_screw_length_mm: float
    index_recess_mm: float      # depth of the ring the screw heads sit in (0: on the top face)

    def helix_z_mm(self, angle_rad: float) -> float:
        """Height of the groove centre at ``angle`` on the turn through the cable plane's neighbourhood."""
        mid = self.groove_start_angle_rad + math.pi * self.groove_turns
        return self.cable_plane_mm + self.groove_pitch_mm * (angle_rad - mid) / (2 * math.pi)

    def to_body(self, r: float, angle: float, z: float) -> tuple[float, float, float]:
        """Body-frame point of the spool-frame point (radius, angle, height)."""
        return (self.axis_xy_mm[0] + r * math.cos(angle), self.axis_xy_mm[1] + r * math.sin(angle),
                self.z_face_mm + z)


def _wrap_angle(leave_left: float, leave_right: float, wraps: float) -> float:
    """Clockwise angle from the left leave point to the right one: of the candidates (base + k turns) the one
    nearest ``wraps`` turns, the smaller on a tie (it leaves more groove for the travel)."""
    base = (leave_left - leave_right) % (2 * math.pi)
    k = max(math.ceil(wraps - base / (2 * math.pi) - 0.5 - 1e-9), 0)
    return base + 2 * math.pi * k


def _set_screw_angle(anchor_angle_rad: float) -> float:
    """Direction of the set screw (and of the bore's flat): a quarter turn from the anchors (clear of the lower
    crimp's channel beside the hub), on the side of the two that faces the hull's wall more squarely (+y on a tie).
    The motors and spools stand in a row along x, so a key reaches the hub only from the side, through where the
    head's upper half goes on afterwards."""
    options = (anchor_angle_rad + math.pi / 2, anchor_angle_rad - math.pi / 2)
    return max(options, key=lambda a: (round(abs(math.sin(a)), 9), math.sin(a)))


def ridge_width_mm(p: Params) -> float:
    """Axial width of the drum surface left between two groove turns: pitch - the groove circle's chord at the
    surface, 2 sqrt(r_g^2 - (r_g - depth)^2) (2 r_g if the groove is deeper than its radius)."""
    g_r = (p.cable.diameter_mm + p.print.clearance_sliding_mm) / 2
    h = g_r - p.spool.groove_depth_mm
    width = 2 * math.sqrt(max(g_r * g_r - h * h, 0.0)) if h > 0 else 2 * g_r
    return p.spool.groove_pitch_mm - width


def spool_numbers(p: Params) -> tuple[SpoolNumbers, ...]:
    """The numbers of every spool (index j-1 for joint j). Raises UserError if the design leaves a ridge under a
    line width, or no room for the hub, the anchors, the index holes or the screws: "spool: <key> = <value>: why
    (parts ...)", naming the parts it refuses (:func:`spool_plan` gives the loader the same refusal)."""
    try:
        return _spool_numbers(p)
    except UserError as e:
        parts = ", ".join(f"spool_{mp.joint + 1}" for mp in motor_placements(p))
        raise UserError(f"spool: {e} (parts {parts})") from None


def spool_plan(p: Params) -> tuple[SpoolNumbers, ...]:
    """:func:`spool_numbers` as the loader's plans are called (``layout/design.py``): its refusal begins with the
    key to change (``spool.<key> = <value>: why``), so the loader files it under that key."""
    return _spool_numbers(p)


def _spool_numbers(p: Params) -> tuple[SpoolNumbers, ...]:
    d = spool_dims(p)
    s, m, pr = p.spool, p.motor, p.print
    w = WALL_LINES * pr.line_width_mm
    ridge = ridge_width_mm(p)
    if ridge < pr.line_width_mm - 1e-9:
        g = p.spool.groove_pitch_mm - ridge
        raise UserError(f"spool.groove_pitch_mm = {s.groove_pitch_mm:g}: the groove ridges are {ridge:.2f} mm wide "
                        f"(the pitch less the {g:.2f} mm groove), under one print.line_width_mm = "
                        f"{pr.line_width_mm:g}: raise spool.groove_pitch_mm to at least "
                        f"{math.ceil((g + pr.line_width_mm) * 100) / 100:g}")
    routes = cable_routes(p)
    pitch_r = s.drum_diameter_mm / 2
    root_r = pitch_r - p.cable.diameter_mm / 2
    surf_r = root_r + s.groove_depth_mm
    g_r = (p.cable.diameter_mm + pr.clearance_sliding_mm) / 2
    hole_d = p.cable.diameter_mm + 2 * pr.clearance_sliding_mm
    anchor_r = root_r - hole_d / 2 - w / 2
    bore_r = (m.shaft_diameter_mm + pr.clearance_sliding_mm) / 2
    crimp = crimp_sleeve(p.cable.diameter_mm)
    seat_d = crimp.seat_diameter_mm(pr.clearance_sliding_mm)
    if anchor_r - hole_d / 2 < bore_r + w:
        raise UserError(
            f"spool.drum_diameter_mm = {s.drum_diameter_mm:g}: no room for the cable anchor holes "
            f"({hole_d:.2f} mm) between the groove root (radius {root_r:.2f} mm) and the {2 * bore_r:.2f} mm shaft "
            f"bore: needs a drum of at least {2 * (bore_r + 1.5 * w + hole_d + p.cable.diameter_mm / 2):.2f} mm")
    # ---- set screw in a heat-set insert in a boss on the hub, on the shaft's flat
    ss = fastener(s.set_screw_diameter_mm)
    flat = m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm + pr.clearance_sliding_mm / 2
    shaft_flat = m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm
    x_in = max(flat + w, (bore_r + w) * flat / bore_r)          # pocket floor: two perimeters from the flat and arc
    ss_len = ss.length_for(x_in + ss.insert_pocket_depth_mm - shaft_flat, set_screw=True)
    if ss_len is None:
        raise UserError(f"spool.set_screw_diameter_mm = {s.set_screw_diameter_mm:g}: no {ss.name} set screw in "
                        f"catalogues/fasteners.toml reaches from the face of its insert's boss to the shaft's flat "
                        f"({x_in + ss.insert_pocket_depth_mm - shaft_flat:.1f} mm)")
    x_face = shaft_flat + ss_len                                # flush with the boss's face when tight
    wall_in = math.ceil(max(w, ss.insert_wall_min_mm) / pr.line_width_mm - 1e-9) * pr.line_width_mm
    boss_half = ss.insert_hole_mm / 2 + wall_in                  # whole perimeters round the insert
    hub_z = (d.hub_bottom_mm, d.hub_bottom_mm + d.hub_length_mm)
    if ss.insert_hole_mm / 2 + max(w, ss.insert_wall_min_mm) > d.hub_length_mm / 2:
        raise UserError(f"spool.hub_length_mm = {s.hub_length_mm:g}: too short for the {ss.name} set "
                        f"screw's heat-set insert ({ss.insert_hole_mm:g} mm hole and "
                        f"{max(w, ss.insert_wall_min_mm):.2f} mm of wall below it)")
    # ---- index screw through the vernier
    ix = fastener(s.index_screw_diameter_mm)
    z2 = hub_z[1] + d.flange_mm
    z3 = z2 + d.groove_length_mm
    z4 = z3 + d.flange_mm
    split = d.cable_plane_mm
    index_r = (bore_r + root_r) / 2
    grip_full = z4 - split
    lower_depth = split - hub_z[1]                              # lower drum half + lower flange
    past_max = lower_depth - PILOT_PAST_TIP_MM - w              # the pilot runs past the tip
    ix_len = ix.length_at_most(grip_full + past_max)           # its pilot stays inside the lower half
    if ix_len is None or past_max < ix.engagement_min_mm:
        raise UserError(f"spool.index_screw_diameter_mm = {s.index_screw_diameter_mm:g}: the spool's lower half is "
                        f"{lower_depth:.1f} mm deep, too shallow for the {ix.name} index screw's "
                        f"{ix.engagement_min_mm:.1f} mm of thread (raise spool.tension_storage_turns or "
                        f"spool.flange_thickness_mm, or use a smaller spool.index_screw_diameter_mm)")
    recess = max(grip_full + ix.engagement_min_mm - ix_len, 0.0)   # sink the heads until the thread holds 1.5 d
    if recess > grip_full - d.flange_mm:
        raise UserError(f"spool.index_screw_diameter_mm = {s.index_screw_diameter_mm:g}: the {ix.name} x {ix_len:g} "
                        f"index screw would sink {recess:.1f} mm into the spool's upper half: use a smaller one")
    hole = ix.counterbore_diameter_mm if recess > 0 else ix.clearance_hole_mm
    if index_r - hole / 2 < bore_r + w or index_r + ix.clearance_hole_mm / 2 > root_r - w:
        raise UserError(f"spool.drum_diameter_mm = {s.drum_diameter_mm:g}: no room for the {ix.name} index holes "
                        f"between the bore and the groove root (a larger drum or a smaller "
                        f"spool.index_screw_diameter_mm)")
    # the hub backs the lower flange out past the index ring's pilots (they end in the flange, 1 mm past the tip)
    hub_r = max(boss_half, index_r + ix.pilot_hole_mm / 2 + w)
    nu, nl = s.index_holes_upper, s.index_holes_lower
    if 2 * index_r * math.sin(math.pi / nu) < ix.clearance_hole_mm + w:
        raise UserError(f"spool.index_holes_upper = {nu}: that many holes of {ix.clearance_hole_mm:g} mm do not "
                        f"fit on the {2 * index_r:.1f} mm index circle with two perimeters between them")
    if 2 * index_r * math.sin(math.pi / nl) < ix.pilot_hole_mm + w:
        raise UserError(f"spool.index_holes_lower = {nl}: that many holes do not fit on the {2 * index_r:.1f} mm "
                        f"index circle with two perimeters between them")
    out = []
    for mp in motor_placements(p):
        left = next(r for r in routes if r.joint == mp.joint and r.side == +1).points_mm[0]
        right = next(r for r in routes if r.joint == mp.joint and r.side == -1).points_mm[0]
        phi_l = math.atan2(left[1], left[0] - mp.x_mm)
        phi_r = math.atan2(right[1], right[0] - mp.x_mm)
        wrap = _wrap_angle(phi_l, phi_r, s.wraps)
        phi_mid = phi_l - wrap / 2
        spare = (d.groove_turns - wrap / (2 * math.pi)) / 2
        travel = spool_travel_turns(p, mp.joint) + s.tension_storage_turns / 2
        if spare < travel - 1e-9:
            raise UserError(
                f"spool.groove_margin_turns = {s.groove_margin_turns:g}: on spool_{mp.joint + 1} the cable leaves "
                f"the drum {wrap / (2 * math.pi):.2f} turns apart on its two "
                f"sides, leaving {spare:.2f} turns of groove at each end for {travel:.2f} turns of travel and "
                f"tensioner storage: raise spool.groove_margin_turns or change spool.wraps = {s.wraps:g}")
        a_off = 2 * math.pi * ANCHOR_FROM_SPLIT_TURNS
        if wrap / 2 < a_off + hole_d / root_r:
            raise UserError(f"spool.wraps = {s.wraps:g}: spool_{mp.joint + 1}'s cable wraps "
                            f"{wrap / (2 * math.pi):.2f} turns between its leave points, too few to anchor each end "
                            f"half a turn from the split: spool.wraps must be at least 1.2")
        phi_a = phi_mid + a_off                 # both anchors lie at this angle, a pitch apart
        # the radial holes' axes from the split: the groove's height there, or further out to leave the floor
        floor = ANCHOR_FLOOR_LAYERS * pr.layer_height_mm + ANCHOR_FLOOR_MARGIN_MM
        z_a = max(s.groove_pitch_mm * ANCHOR_FROM_SPLIT_TURNS, floor + hole_d / 2)
        # index holes: each ring starts half an upper pitch from the anchors' axial holes; hole 0 of both lines up
        start = phi_a + math.pi / nu
        up = tuple(start + 2 * math.pi * k / nu for k in range(nu))
        lo = tuple(start + 2 * math.pi * k / nl for k in range(nl))
        # the upper ring clears the upper crimp's seat (it is wider than the anchor hole and reaches below the
        # heads), the lower ring the right anchor's hole, each by two perimeters
        for ring, hd, other in ((up, ix.clearance_hole_mm, seat_d), (lo, ix.pilot_hole_mm, hole_d)):
            gap = min(math.sqrt(index_r**2 + anchor_r**2 - 2 * index_r * anchor_r * math.cos(a - phi_a))
                      for a in ring)
            if gap < hd / 2 + other / 2 + w - 1e-9:
                raise UserError(f"spool.index_holes_upper = {nu}: on spool_{mp.joint + 1} an index hole comes within "
                                f"{gap:.2f} mm of a cable anchor's "
                                f"{'crimp seat' if other == seat_d else 'hole'} ({gap - hd / 2 - other / 2:.2f} mm "
                                f"of wall, needs {w:.2f}): change spool.index_holes_upper / spool.index_holes_lower")
        out.append(SpoolNumbers(
            joint=mp.joint + 1, axis_xy_mm=(mp.x_mm, 0.0), z_face_mm=mp.z_face_mm,
            hub_radius_mm=hub_r, hub_z_mm=hub_z, flange_radius_mm=d.flange_radius_mm,
            lower_flange_z_mm=(hub_z[1], z2), drum_z_mm=(z2, z3), upper_flange_z_mm=(z3, z4), split_z_mm=split,
            pitch_radius_mm=pitch_r, root_radius_mm=root_r, surface_radius_mm=surf_r, groove_radius_mm=g_r,
            groove_centre_radius_mm=root_r + g_r, groove_pitch_mm=s.groove_pitch_mm, groove_turns=d.groove_turns,
            ridge_width_mm=ridge, cable_plane_mm=d.cable_plane_mm,
            groove_start_angle_rad=phi_mid - math.pi * d.groove_turns,
            leave_angles_rad=(phi_l, phi_r), wrap_between_rad=wrap, anchor_hole_diameter_mm=hole_d,
            anchor_radius_mm=anchor_r, anchor_angles_rad=(phi_mid + a_off, phi_mid - a_off),
            anchor_z_mm=(split + z_a, split - z_a),
            crimp_seat_diameter_mm=seat_d, crimp_length_mm=crimp.length_mm,
            bore_radius_mm=bore_r, flat_distance_mm=flat, shaft_flat_mm=shaft_flat,
            set_screw_angle_rad=_set_screw_angle(phi_a), set_screw_z_mm=(hub_z[0] + hub_z[1]) / 2,
            set_screw_length_mm=ss_len, set_screw_boss_x_mm=(x_in, x_face), set_screw_boss_half_width_mm=boss_half,
            index_radius_mm=index_r, index_angles_upper_rad=up, index_angles_lower_rad=lo, index_screw=ix.name,
            index_screw_length_mm=ix_len, index_recess_mm=recess))
    return tuple(out)


# ----------------------------------------------------------------------------------------------- fasteners
def set_screw_record(n: SpoolNumbers, size: str, after: tuple[str, ...] = ()) -> Fastener:
    """Spool ``n``'s set screw: in the hub's insert, onto the shaft's flat, its end flush with the boss's face."""
    a = n.set_screw_angle_rad
    x_head = n.shaft_flat_mm + n.set_screw_length_mm      # the boss's face: the screw ends flush with it
    return Fastener(
        label=f"spool_{n.joint}_set_screw", size=size, kind="set_screw", seat="insert",
        head_mm=n.to_body(x_head, a, n.set_screw_z_mm), axis=(-math.cos(a), -math.sin(a), 0.0),
        length_mm=n.set_screw_length_mm, grip_mm=0.0, head_part=None, thread_part=f"spool_{n.joint}",
        joins=f"spool {n.joint} to its motor's shaft (on the flat)", link=0,
        installed_after=after, meta={"joins_parts": (f"motor_{n.joint}",)})


def index_screw_record(n: SpoolNumbers, angle_upper: float | None = None, after: tuple[str, ...] = ()) -> Fastener:
    """Spool ``n``'s index screw, down through the upper half's index hole at ``angle_upper`` (the first one by
    default: the pair that lines up at rest) into the lower half's pilot."""
    a = n.index_angles_upper_rad[0] if angle_upper is None else angle_upper
    z_head = n.upper_flange_z_mm[1] - n.index_recess_mm
    return Fastener(
        label=f"spool_{n.joint}_index_screw", size=n.index_screw, kind="cap_screw", seat="self_tap",
        head_mm=n.to_body(n.index_radius_mm, a, z_head), axis=(0.0, 0.0, -1.0),
        length_mm=n.index_screw_length_mm, grip_mm=z_head - n.split_z_mm,
        head_part=f"spool_{n.joint}_upper", thread_part=f"spool_{n.joint}",
        joins=f"spool {n.joint}'s halves, through one aligned pair of vernier index holes (the cable tensioner)",
        link=0, recess_mm=n.index_recess_mm, installed_after=after)


def spool_fasteners(p: Params) -> tuple[Fastener, ...]:
    """Every spool's set screw (in a nut in the hub, on the shaft's flat) and index screw (upper half to lower,
    through the pair of index holes that line up at rest)."""
    from swiftfin.layout.hull_plan import head_lid_labels
    size = fastener(p.spool.set_screw_diameter_mm).name
    lid = head_lid_labels(p)       # the head is closed after the spools are fixed and tensioned
    out = []
    for n in spool_numbers(p):
        out += [set_screw_record(n, size, lid), index_screw_record(n, after=lid)]
    return tuple(out)
