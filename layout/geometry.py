"""The layout of the robot as numbers: where every part goes, computed from the parameters alone.

Every part family builds its solid from these numbers, so that parts agree with one another
(house style rule 1: numbers first, solid second). Nothing here imports the CAD kernel.

Frames and conventions (used by every module of the project)
------------------------------------------------------------
* **Body frame** (REP 103): origin at the nose tip, **+x forward** (swimming direction), +y to the fish's
  left, +z up (dorsal). The body axis is the x axis; the body lies at x <= 0.
* **Station** ``s`` is the distance from the nose along the axis, ``s = -x`` (mm in CAD, m in physics).
* The hull's NACA 00xx chord is the body (fork) length L; cross-sections are ellipses with half-width
  ``naca_half_width_mm(s)`` and half-height ``height_to_width`` times that.
* Joint j (1..N, nose to tail) is a revolute joint about a vertical (z) axis through (x=-s_j, y=0).
  Positive joint angle turns the child link's tail toward +y.
* Kinematic link 0 is the head (base); link j is everything behind joint j up to joint j+1.
* Motors stand in a row in the head, shafts up (+z), the stack (motor + spool) centred on the body axis;
  the rear-most motor drives joint 1. The cables of the motors ahead of it run aft in lanes beside the
  spools behind, one lane further out per motor ("exit" guides turn them into the lanes).
* Behind the motor row one "bay" guide turns every cable toward the hinge line of joint 1. At the rear motor's
  aft face the lanes first "drop" (each a third of a level pitch lower than the lane inside it, so that the fan of
  runs to the hinge line keeps its tubes apart) while joint 1's own cable turns toward its sector.
* Cables cross the joints ahead of their own *on the hinge line* (y = 0), each at its own height
  (pairs stacked upward from the axis, the last joint lowest), so a joint's
  rotation does not change their length: no coupling between joints. They leave the hinge line of the
  joint just ahead tangent to their own joint's tendon sector (radius = the tendon moment arm).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, fields

import numpy as np

from swiftfin.catalogues.fasteners import ScrewSize, screw_sizes
from swiftfin.physics.kinematics import max_relative_joint_angles_rad, wave_from_params
from swiftfin.core.params import Problem
from swiftfin.core.schema import Body, Params


# ----------------------------------------------------------------------------------------------- hull profile
def _naca_scalar(xi: float, t: float) -> float:
    xi = min(max(xi, 0.0), 1.0)
    return 5.0 * t * (0.2969 * math.sqrt(xi) - 0.1260 * xi - 0.3516 * xi**2 + 0.2843 * xi**3 - 0.1015 * xi**4)


def naca_half_thickness(xi, t: float):
    """NACA 00xx half thickness / chord at xi = s/L in [0, 1] (open trailing edge, standard coefficients). A
    Python number gives a float by :mod:`math` (the layout's plans call it some 10^5 times per design, where numpy's
    per-call cost was most of the time); arrays go through numpy."""
    if isinstance(xi, (float, int)):
        return _naca_scalar(float(xi), t)
    xi = np.clip(np.asarray(xi, dtype=float), 0.0, 1.0)
    return 5.0 * t * (0.2969 * np.sqrt(xi) - 0.1260 * xi - 0.3516 * xi**2 + 0.2843 * xi**3 - 0.1015 * xi**4)


def naca_half_width_mm(p: Params, s_mm):
    """Outer half-width of the hull at station s [mm] (NACA 00xx thickness distribution)."""
    L = p.body.length_mm
    if isinstance(s_mm, (float, int)):
        return _naca_scalar(float(s_mm) / L, p.body.naca_thickness_fraction) * L
    return naca_half_thickness(np.asarray(s_mm, dtype=float) / L, p.body.naca_thickness_fraction) * L


def half_height_mm(p: Params, s_mm):
    """Outer half-height of the hull at station s [mm]."""
    return p.body.height_to_width * naca_half_width_mm(p, s_mm)


def interior_half_width_at_height_mm(p: Params, s_mm: float, z_mm: float) -> float:
    """Inner half-width of the hull at station s and height z [mm] (ellipse shrunk by the wall); 0 if none."""
    a = float(naca_half_width_mm(p, s_mm)) - p.hull.wall_thickness_mm
    b = float(half_height_mm(p, s_mm)) - p.hull.wall_thickness_mm
    if a <= 0 or b <= 0 or abs(z_mm) >= b:
        return 0.0
    return a * math.sqrt(1.0 - (z_mm / b) ** 2)


def max_width_station_mm(p: Params) -> float:
    """Station of maximum hull width [mm] (30 % of L for every NACA 00xx)."""
    xi = np.linspace(0.0, 1.0, 20001)
    return float(xi[np.argmax(naca_half_thickness(xi, p.body.naca_thickness_fraction))] * p.body.length_mm)


# ----------------------------------------------------------------------------------------------- joints
def joint_stations_mm(p: Params) -> tuple[float, ...]:
    return tuple(f * p.body.length_mm for f in p.joints.stations_fraction)


def hull_end_mm(p: Params) -> float:
    return p.body.hull_end_fraction * p.body.length_mm


@functools.lru_cache(maxsize=256)
def joint_max_angles_rad(p: Params) -> tuple[float, ...]:
    """Largest relative joint angle the wave demands at the design point (eq. 43-47, relative form). Memoised on
    the params (read by nearly every layout function; a family cache's recording view is equal only to itself)."""
    wave = wave_from_params(p.swimming, p.body.length_mm / 1000.0)
    s = np.asarray(joint_stations_mm(p)) / 1000.0
    return tuple(float(v) for v in max_relative_joint_angles_rad(wave, s, p.body.length_mm / 1000.0))


def joint_stop_angles_rad(p: Params) -> tuple[float, ...]:
    """Hard-stop angle of each joint: the wave's maximum plus the margin."""
    m = math.radians(p.joints.stop_margin_deg)
    return tuple(a + m for a in joint_max_angles_rad(p))


LUG_GAP_MARGIN_MM = 0.01
"""Added to the assembly clearance between a joint's lugs and the child's front face: the assembly check reads the gap
on float32 meshes (the lugs' polygons lie inside their circles, the face is flat), and at exactly the clearance it
read 0.500 < 0.5 mm (2026-12-07)."""


def plug_screw_size(pin_diameter_mm: float) -> ScrewSize | None:
    """The smallest thread whose insert's hole clears the pin, so that the reamer passes the empty pocket when the
    two lug bores are line-reamed in one pass (the insert goes in after)."""
    return next((s for s in screw_sizes() if s.insert_hole_mm > pin_diameter_mm + 0.1), None)


def knuckle_radius_mm(p: Params) -> float:
    """Radius of a hinge's knuckle round its pin, and of the parent's lugs (:mod:`swiftfin.layout.joints`): the pin,
    the sliding clearance and a wall of four line widths (2 mm at least)."""
    return p.joints.pin_diameter_mm / 2 + p.print.clearance_sliding_mm + max(2.0, 4 * p.print.line_width_mm)


def hinge_column_radius_mm(p: Params) -> float:
    """Radius of what the parent holds round a hinge's axis as whole cylinders: its two lugs and the bosses beyond
    them that hold the pins' plug inserts (:mod:`swiftfin.layout.joints`). The child's front face stays this far
    (and the assembly clearance) from the axis at every angle. A boss keeps the fastener check's wall round its
    insert and twice the check's probe inset (:data:`~swiftfin.layout.fastening.WALL_PROBE_INSET_MM`, as the link
    flanges' rows do): at the bare least the check read 2.47 mm of the 2.52 an M4 insert's maker asks (5 mm pins,
    2026-12-07). With no insert wide enough for the pin (the joints' plan refuses that) the largest."""
    from swiftfin.layout.fastening import WALL_PROBE_INSET_MM
    plug = plug_screw_size(p.joints.pin_diameter_mm) or screw_sizes()[-1]
    return max(knuckle_radius_mm(p), plug.insert_boss_od_mm(p.print.line_width_mm) / 2 + 2 * WALL_PROBE_INSET_MM)


def joint_gaps_mm(p: Params) -> tuple[float, ...]:
    """Axial gap between the hull segments at each joint, wide enough for the stop angle, and never so narrow that
    the child's front face meets the parent's lugs.

    The child's shell corner at half-width w swings forward by about w sin(theta) when the joint turns. The parent's
    lugs and plug bosses are cylinders round the axis (:func:`hinge_column_radius_mm`) whatever the angle: each half
    of the gap holds one and the assembly clearance (and :data:`LUG_GAP_MARGIN_MM`). A gentle gait (1 Hz, 2 cm: stops of 7-12 deg) left 3.1-4.1 mm
    half gaps round 3.8 mm lugs, and its build failed at the end (2026-12-07: hull_body_1's lugs 0.5 mm into
    hull_body_2's front bulkhead, 25 mm^3).
    """
    floor = 2.0 * (hinge_column_radius_mm(p) + p.print.clearance_assembly_mm + LUG_GAP_MARGIN_MM)
    out = []
    for s, th in zip(joint_stations_mm(p), joint_stop_angles_rad(p)):
        w = float(naca_half_width_mm(p, s))
        out.append(max(w * math.sin(th) + 2.0 * p.print.clearance_assembly_mm + p.hull.wall_thickness_mm, floor))
    return tuple(out)


@dataclass(frozen=True)
class Segment:
    """A hull segment: stations [s_start, s_end] in mm, rigid with kinematic link ``link``."""
    name: str
    s_start_mm: float
    s_end_mm: float
    link: int


def hull_segments(p: Params) -> tuple[Segment, ...]:
    """Head (electronics and motor bay), body segments between joints, and the peduncle."""
    js, gaps = joint_stations_mm(p), joint_gaps_mm(p)
    n = len(js)
    segs = [Segment("hull_head", 0.0, js[0] - gaps[0] / 2, 0)]
    for j in range(n):
        start = js[j] + gaps[j] / 2
        end = js[j + 1] - gaps[j + 1] / 2 if j + 1 < n else hull_end_mm(p)
        name = "hull_peduncle" if j + 1 == n else f"hull_body_{j + 1}"
        segs.append(Segment(name, start, end, j + 1))
    return tuple(segs)


# ----------------------------------------------------------------------------------------------- spools
@dataclass(frozen=True)
class SpoolDims:
    """Axial stack of a spool above its motor face (mm, measured up from the motor's mounting face)."""
    plate_mm: float          # motor-mount plate the motor face screws to
    hub_bottom_mm: float     # bottom of the spool hub
    hub_length_mm: float
    flange_mm: float         # flange thickness
    groove_length_mm: float  # axial length of the helical groove
    groove_turns: float
    drum_radius_mm: float    # groove root radius + depth = drum surface radius
    flange_radius_mm: float
    cable_plane_mm: float    # groove centre height above the motor face
    top_mm: float            # spool top above the motor face
    end_offset_mm: float     # the two cable ends leave at cable_plane +/- end_offset


def spool_travel_turns(p: Params, joint_index: int) -> float:
    """Spool turns from centre to the joint's stop angle: theta_stop * moment arm / spool radius / 2 pi."""
    th = joint_stop_angles_rad(p)[joint_index]
    return th * p.joints.tendon_moment_arm_mm / (p.spool.drum_diameter_mm / 2) / (2 * math.pi)


@functools.lru_cache(maxsize=256)
def spool_dims(p: Params) -> SpoolDims:
    """One spool design for every motor, sized for the joint with the largest travel. Memoised on the params (the
    layout reads it thousands of times per design; a family cache's recording view is equal only to itself)."""
    s = p.spool
    travel = max(spool_travel_turns(p, j) for j in range(p.joints.count))
    turns = s.wraps + 2 * travel + s.groove_margin_turns + s.tension_storage_turns   # storage: split spool
    groove = turns * s.groove_pitch_mm + p.cable.diameter_mm
    plate = plate_thickness_mm(p)
    hub_bottom = plate + max(p.motor.pilot_height_mm - plate, 0.0) + 0.5
    cable_plane = hub_bottom + s.hub_length_mm + s.flange_thickness_mm + groove / 2
    top = hub_bottom + s.hub_length_mm + 2 * s.flange_thickness_mm + groove
    r = s.drum_diameter_mm / 2
    return SpoolDims(plate, hub_bottom, s.hub_length_mm, s.flange_thickness_mm, groove, turns, r,
                     r + s.flange_height_mm, cable_plane, top, s.wraps * s.groove_pitch_mm / 2)


def plate_thickness_mm(p: Params) -> float:
    """Motor-mount plate thickness: 8 perimeters' worth, at least 3 mm."""
    return max(3.0, 8 * p.print.line_width_mm)


# ----------------------------------------------------------------------------------------------- motors
@dataclass(frozen=True)
class MotorPlacement:
    joint: int               # index (0-based) of the joint this motor drives
    s_mm: float              # station of the shaft axis
    z_face_mm: float         # height of the motor's mounting face (body below, spool above)
    z_cable_mm: float        # cable plane of its spool (groove centre)
    lane_y_mm: float         # |y| of the lane its cables run in past the spools behind (0: no lane)

    @property
    def x_mm(self) -> float:
        return -self.s_mm


MOTOR_PITCH_GAP_MM = 3.0     # clearance between neighbouring motor frames


#: Least printed web, in line widths, between two holes or a hole and a bore end (two perimeters)
MIN_WEB_LINES = 2


def tendon_level_pitch_mm(p: Params) -> float:
    """Vertical pitch of the cable levels where cables cross the hinge lines: one pass-through hole (PTFE tube OD
    plus the sliding clearance each side) and a web of :data:`MIN_WEB_LINES` line widths."""
    return (p.guides.ptfe_tube_od_mm + 2 * p.print.clearance_sliding_mm
            + MIN_WEB_LINES * p.print.line_width_mm)


def _stacked_level_mm(p: Params, joint: int, side: int) -> float:
    n = p.joints.count
    pitch = tendon_level_pitch_mm(p)
    return (n - 1 - joint) * 2 * pitch + side * pitch / 2


def tendon_level_mm(p: Params, joint: int, side: int) -> float:
    """Height of joint ``joint``'s (0-based) ``side`` cable in the tail: on the hinge lines it crosses and on
    its tendon sector. Pairs are stacked upward from the axis, the last joint lowest (the tail is smallest
    there) and joint 1 highest (nearest the spool planes); left cable above right by one level pitch. Joint 1's
    pair sits :func:`joint1_lift_mm` higher still where the cables passing under its sector need it.
    """
    return _stacked_level_mm(p, joint, side) + (joint1_lift_mm(p) if joint == 0 else 0.0)


def sector_radius_mm(p: Params) -> float:
    """Outer radius of a tendon sector: the groove's centre (its root at the moment arm less the cable's radius,
    the groove's radius the cable's and half the sliding clearance) and 0.3 of the groove's radius, so the groove's
    opening (1.9 of its radius) is wider than the cable (:mod:`swiftfin.layout.joints`)."""
    rg = p.cable.diameter_mm / 2 + p.print.clearance_sliding_mm / 2
    return p.joints.tendon_moment_arm_mm - p.cable.diameter_mm / 2 + 1.3 * rg


def sector_room_floor_mm(p: Params, joint: int) -> float:
    """Floor of the room a link's tendon sector swings in, cut into its parent's rear bulkhead, with the joint's pair
    at its stacked level (joint 1's lift not counted: :func:`joint1_lift_mm` asks it): the sector's floor (a tube's
    radius under the joint's lower cable where cables of the joints behind cross under it, else half a level pitch)
    less the sliding clearance (:func:`swiftfin.cad.clevis.clevis_cut`)."""
    under = p.guides.ptfe_tube_od_mm / 2 if joint < p.joints.count - 1 else tendon_level_pitch_mm(p) / 2
    return _stacked_level_mm(p, joint, -1) - under - p.print.clearance_sliding_mm


@functools.lru_cache(maxsize=256)
def joint1_lift_mm(p: Params) -> float:
    """How far joint 1's cable pair sits above its place in the stack [mm]: the least lift that keeps the bore of
    every cable passing under its tendon sector (the joints behind, from the bay corner down to joint 1's hinge
    line) under the room the sector swings in, wherever the bore comes within that room's radius of joint 1's axis.

    Why: joint 1's sector room is cut into the head's rear wall, the dry compartment's, whose bores are the cables'
    glands. The passing cables come down from the spools' plane to their levels; with two or three joints their
    levels lie low and they crossed the wall still inside the sector's band, so the room cut their glands short:
    72 of 168 seeded designs (seeds 16, 2027) had such a gland wetted through by its cable's stroke (2026-11-29),
    found only at the build's end; none after. The room's radius is the sector's, the assembly clearance and the bore's radius; the
    bore clears its floor by the bore's radius. The default design needs none."""
    n = p.joints.count
    if n < 2:
        return 0.0
    x_h = -joint_stations_mm(p)[0]
    x_bay = -bay_end_station_mm(p)
    motors = motor_placements(p)
    d = spool_dims(p)
    r_bore = tube_bore_diameter_mm(p, "bulkhead") / 2
    reach = sector_radius_mm(p) + p.print.clearance_assembly_mm + r_bore
    top = -math.inf
    for mp in motors[1:]:
        for side in (1, -1):
            z_a = mp.z_cable_mm + side * d.end_offset_mm - lane_drop_mm(p, mp.joint)
            z_b = _stacked_level_mm(p, mp.joint, side)
            run = math.hypot(x_h - x_bay, mp.lane_y_mm)          # the bay corner to the hinge line, in plan
            f = max(0.0, 1.0 - reach / run)                     # where the bore comes within the room's reach
            top = max(top, z_a + f * (z_b - z_a), z_b)
    lift = top + r_bore - sector_room_floor_mm(p, 0)
    return math.ceil(lift * 100.0) / 100.0 if lift > 0.0 else 0.0


@functools.lru_cache(maxsize=256)
def tube_seat_shoulder_mm(p: Params) -> float:
    """Length along the cable of the printed shoulder each PTFE tube is pushed against (its seat): the tube's bore
    ends flat and the part goes on as the cable's exit hole (:func:`cable_exit_hole_mm`) for
    :data:`MIN_WEB_LINES` line widths, the least printed web, or as many more whole line widths as it takes to hold
    the friction of the most turned guide's cable at its breaking strength: the printed ring sheared through,
    ``shear allowable x pi x bore x length >= T_break (1 - e^(-mu theta))`` (the check of ``cad/cables.py``, tube
    retention, which measures each tube's own turn on the built tubes). A seeded design's bay guide turned its outer
    lanes by 73 deg, 111 N against the 100 N two lines hold (2026-11-29); the default's 58 deg needs the two. The other
    end of the tube is the open mouth it goes in by; what keeps it from walking back out is its bond."""
    from swiftfin.catalogues.printed_strength import printed_strength
    lw = p.print.line_width_mm
    theta = max_guide_turn_rad(p)
    drag = p.cable.breaking_strength_n * (1.0 - math.exp(-p.guides.mu_ptfe * theta))
    per_mm = printed_strength(p.print.material).shear_allowable_mpa * math.pi * tube_bore_diameter_mm(p, "guide")
    return max(MIN_WEB_LINES, math.ceil(drag / per_mm / lw - 1e-9)) * lw


def max_guide_turn_rad(p: Params) -> float:
    """The most any cable turns inside one PTFE guide [rad]: its exit bend, or its drop and bay bends together (one
    tube in the bay guide holds both)."""
    worst = 0.0
    for r in cable_routes(p):
        exit_ = sum(b.angle_rad for b in r.bends if b.kind == "exit")
        bay = sum(b.angle_rad for b in r.bends if b.kind in BAY_GUIDE_BENDS)
        worst = max(worst, exit_, bay)
    return worst


MIN_TUBE_MM = 1.0
"""A stretch of bore shorter than this holds no PTFE tube (a sliver of guide channel at a clipped corner, a bulkhead
too thin for a tube and its shoulder): the cable runs bare through it."""


def tube_bore_diameter_mm(p: Params, kind: str) -> float:
    """Diameter of the bore a PTFE tube sits in: a guide channel ("guide": the tube's OD and the sliding clearance)
    or a bulkhead passage ("bulkhead": the sliding clearance each side, :func:`swiftfin.layout.joints.passage_radius_mm`)."""
    if kind == "guide":
        return p.guides.ptfe_tube_od_mm + p.print.clearance_sliding_mm
    return p.guides.ptfe_tube_od_mm + 2 * p.print.clearance_sliding_mm


def cable_exit_hole_mm(p: Params) -> float:
    """Diameter of the hole through a tube's seat: the tube's bore and the sliding clearance (the cable leaves the
    tube along its axis, so it clears the hole by what it clears the tube's bore)."""
    return p.guides.ptfe_tube_id_mm + p.print.clearance_sliding_mm


def lane_pitch_mm(p: Params) -> float:
    """Lateral pitch of the lanes beside the spools: the tube's OD and :data:`MIN_WEB_LINES` line widths. The guides'
    channels are the OD and the sliding clearance, so the web between two lanes' channels is 0.6 mm on the default
    design: over one line width, under two perimeters (the wall probe lists them). It carries no load (each tube is
    bonded in its own bore). Widened to a full two-perimeter web (2026-11-27), the lanes pushed the bay guide
    0.6 mm further out and the head's upper half could no longer be lifted past it with the sliding clearance."""
    return p.guides.ptfe_tube_od_mm + MIN_WEB_LINES * p.print.line_width_mm


def motor_placements(p: Params) -> tuple[MotorPlacement, ...]:
    """Motors in a row ahead of joint 1, shafts up, the stack (body + spool) centred on the body axis.

    The rear-most motor drives joint 1; the cables of each motor ahead of it run aft in lanes beside the
    spools behind (|y| beyond their flanges), one lane further out per motor.
    """
    n = p.joints.count
    F = p.motor.frame_size_mm
    pitch = F + MOTOR_PITCH_GAP_MM
    s_rear = joint_stations_mm(p)[0] - p.hull.drive_bay_length_mm - F / 2
    d = spool_dims(p)
    z_face = (p.motor.body_length_mm - d.top_mm) / 2
    out = []
    for j in range(n):  # j = 0 is the rear-most motor
        lane = 0.0 if j == 0 else (d.flange_radius_mm + p.print.clearance_assembly_mm + p.guides.ptfe_tube_od_mm / 2
                                   + (j - 1) * lane_pitch_mm(p))
        out.append(MotorPlacement(j, s_rear - j * pitch, z_face, z_face + d.cable_plane_mm, lane))
    return tuple(out)


LANE_DROP_PITCHES = 1 / 3     # each lane's step down at the bay corner, in level pitches (lane_drop_mm)
BAY_AFTER_DROP_RADII = 5 / 8  # the bay corner behind the drop station, in guide bend radii (bay_end_station_mm)
GUIDE_BENDS = ("exit", "drop", "bay")   # route bends held by a PTFE guide (the rest cross hinge lines)
BAY_GUIDE_BENDS = ("drop", "bay")       # those the bay guide holds


def bay_end_station_mm(p: Params) -> float:
    """Station of the bay guide's turn toward joint 1: 5/8 of the guide's bend radius behind the rear motor's aft
    face (:func:`drop_station_mm`), so that a lane's drop and turn both fit, as arcs of that radius, on the straight
    between them: 3.3 mm to spare on the default design, 2.4 mm with a 30 mm drum (at half a radius that drum's
    outer lane lacked 0.4 mm and the guide was refused)."""
    return drop_station_mm(p) + BAY_AFTER_DROP_RADII * p.guides.min_bend_radius_mm


def drop_station_mm(p: Params) -> float:
    """Station where the lanes begin to drop and joint 1's cable turns toward its sector: the rear motor's aft face.
    Behind it the bay guide holds the bends, past the rear spool's flange and aft of the mount's wall pads; further
    forward the guide would have to reach the pads of the rear mount's wall screws (the assembly check found it
    0.37 mm from them at a quarter bend radius forward)."""
    return motor_placements(p)[0].s_mm + p.motor.frame_size_mm / 2


def lane_drop_mm(p: Params, joint: int) -> float:
    """How far lane ``joint`` (0-based, >= 1) lies below its spool's cable plane at the bay corner: a third of a
    level pitch per lane, counted outward.

    Why: from the bay corner the lanes fan in to the hinge line of joint 1 (y = 0), the outer lanes to the lower
    levels. Level with one another, two neighbouring runs start a lane pitch apart across and end two level pitches
    apart in height, and in between come closer than a tube's diameter (4.2 mm of 4.9 on the default design, the
    arcs included); and joint 1's own cable, which leaves the innermost lane outward and upward to its sector,
    crosses the lanes in plan while they are still at its height. Stepped down a third of a level pitch per lane,
    the runs start apart in height as well and draw apart (closest approach 4.81 mm between centre lines on the
    default design, joint 1's right cable and joint 2's; the assembly check measures it on the tubes). Half a pitch
    would bring the outer lane's channel onto the rear mount's screw heads (the bay guide refuses it)."""
    return joint * LANE_DROP_PITCHES * tendon_level_pitch_mm(p)


# ----------------------------------------------------------------------------------------------- cable routes
@dataclass(frozen=True)
class Bend:
    """A change of direction of a cable route, held by a PTFE guide (or a PTFE-lined hole) on link ``link``."""
    point_mm: tuple[float, float, float]
    angle_rad: float
    link: int
    kind: str                # "exit" (behind a spool), "drop" (a lane's step down, or joint 1's rise, in the bay
                             # guide), "bay" (the bay guide's turn toward joint 1), "hinge" (at a joint crossing)


@dataclass(frozen=True)
class CableRoute:
    """One side of a pull-pull cable, as a polyline at rest from spool to tendon sector (body frame, mm)."""
    joint: int
    side: int                                  # +1: left (+y) cable, -1: right
    points_mm: tuple[tuple[float, float, float], ...]
    bends: tuple[Bend, ...]

    @property
    def length_mm(self) -> float:
        pts = np.asarray(self.points_mm)
        return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))

    @property
    def total_bend_rad(self) -> float:
        return sum(b.angle_rad for b in self.bends)


def _tangent_point(px: float, py: float, cx: float, cy: float, r: float, side: int) -> tuple[float, float]:
    """Point where a line from P touches the circle (C, r), on the side ``sign(y - cy) == side``."""
    d = math.hypot(px - cx, py - cy)
    if d <= r:
        raise ValueError(f"point ({px:.1f}, {py:.1f}) lies inside the circle of radius {r:.1f}")
    beta = math.atan2(py - cy, px - cx)
    gamma = math.acos(r / d)
    for ang in (beta + gamma, beta - gamma):
        qx, qy = cx + r * math.cos(ang), cy + r * math.sin(ang)
        if (qy - cy) * side > 0:
            return qx, qy
    raise ValueError("no tangent on that side")


def crossing_rise_mm(a0, a1, b0, b1, need_mm, rise_max_mm, bisections: int = 48):
    """How far to raise the start ``a0`` of run ``a`` (its end ``a1`` kept) so that it passes over run ``b`` (from
    ``b0`` to ``b1``) ``need_mm`` apart, measured between the two lines (along their common normal) where they
    cross in plan; 0 where they do not cross in plan or clear already; ``rise_max_mm`` where no rise up to it
    clears (the guide's own check refuses the design). Found by bisection: the lines' distance grows with the rise
    until the raised run stands up steeply. Points are (x, y, z), each coordinate a float or an array of designs
    (:mod:`swiftfin.design_rules.vectorised` calls it with columns; numbers alone go through
    :func:`_crossing_rise_scalar`, the same arithmetic in :mod:`math`)."""
    if not any(np.ndim(q) for pt in (a0, a1, b0, b1) for q in pt):
        return _crossing_rise_scalar(a0, a1, b0, b1, float(need_mm), float(rise_max_mm), bisections)
    ax, ay, az = a0
    ex, ey, ez = (a1[k] - a0[k] for k in range(3))
    fx, fy, fz = (b1[k] - b0[k] for k in range(3))
    wx, wy = b0[0] - ax, b0[1] - ay
    gz = ex * fy - ey * fx
    with np.errstate(divide="ignore", invalid="ignore"):
        f1 = (wx * fy - wy * fx) / gz           # a0 + f1 e = b0 + f2 f, in plan
        f2 = (wx * ey - wy * ex) / gz
        crosses = (np.abs(gz) > 1e-12) & (f1 >= 0) & (f1 <= 1) & (f2 >= 0) & (f2 <= 1)
        h0 = az + f1 * ez - (b0[2] + f2 * fz)    # a over b at the crossing, unraised

        def apart(rise):                         # the lines' distance, a raised by ``rise``
            e_z = ez - rise
            gx, gy = ey * fz - e_z * fy, e_z * fx - ex * fz
            return (h0 + rise * (1.0 - f1)) * np.abs(gz) / np.sqrt(gx * gx + gy * gy + gz * gz)

        lo = np.zeros(np.shape(h0))
        hi = np.zeros(np.shape(h0)) + rise_max_mm
        for _ in range(bisections):
            mid = 0.5 * (lo + hi)
            ok = apart(mid) >= need_mm
            lo, hi = np.where(ok, lo, mid), np.where(ok, mid, hi)
        rise = np.where(apart(0.0) >= need_mm, 0.0, hi)
        return np.where(crosses & np.isfinite(rise), rise, 0.0)


def _crossing_rise_scalar(a0, a1, b0, b1, need: float, rise_max: float, bisections: int) -> float:
    """:func:`crossing_rise_mm` for one design: the same operations in the same order on Python floats (IEEE
    doubles, as numpy's), so the same bits, without numpy's cost per call on scalars (the loader calls it some 50
    times a design; it was 6 % of drawing seeded designs, 2026-11-30)."""
    ax, ay, az = (float(q) for q in a0)
    bx, by, bz = (float(q) for q in b0)
    ex, ey, ez = float(a1[0]) - ax, float(a1[1]) - ay, float(a1[2]) - az
    fx, fy, fz = float(b1[0]) - bx, float(b1[1]) - by, float(b1[2]) - bz
    wx, wy = bx - ax, by - ay
    gz = ex * fy - ey * fx
    if not abs(gz) > 1e-12:
        return 0.0
    f1 = (wx * fy - wy * fx) / gz
    f2 = (wx * ey - wy * ex) / gz
    if not (0 <= f1 <= 1 and 0 <= f2 <= 1):
        return 0.0
    h0 = az + f1 * ez - (bz + f2 * fz)
    agz = abs(gz)

    def apart(rise):
        e_z = ez - rise
        gx, gy = ey * fz - e_z * fy, e_z * fx - ex * fz
        return (h0 + rise * (1.0 - f1)) * agz / math.sqrt(gx * gx + gy * gy + gz * gz)

    if apart(0.0) >= need:
        return 0.0
    lo, hi = 0.0, 0.0 + rise_max
    for _ in range(bisections):
        mid = 0.5 * (lo + hi)
        if apart(mid) >= need:
            hi = mid
        else:
            lo = mid
    return hi if math.isfinite(hi) else 0.0


RISE_MAX_PITCHES = 2.0
"""The most joint 1's cable rises at the bay corner (:func:`joint1_rise_mm`), in level pitches: of 200 seeded designs
(seeds 16 and 2027), 117 need a rise, the largest 1.45 pitches (2026-11-29); a design no such rise clears is
refused by the bay guide's check."""
BAY_ARC_ALLOWANCE_LINES = 0.25
"""Line widths added to what joint 1's cable and a lane clear at their crossing (:func:`bay_crossing_gap_mm`), for
the bay guide's channels, which round the routes' corners by arcs (with none, one of 58 seeded designs kept 0.01 mm
too little on the channels' centre lines; with a quarter, the closest of 195 keeps 0.011 mm over the need, the
default 0.31 mm, 2026-11-29). The guide's own check (:func:`swiftfin.layout.guide_plan.channel_clearance_mm`)
measures the channels and refuses what is left."""


def bay_crossing_gap_mm(p: Params) -> float:
    """What joint 1's cable and a lane's must clear where they cross in plan, between centre lines: a tube's OD and
    the assembly clearance (the gap the assembly check asks between two tubes), and :data:`BAY_ARC_ALLOWANCE_LINES`
    line widths for the guide's arcs, which round the routes' corners."""
    return p.guides.ptfe_tube_od_mm + p.print.clearance_assembly_mm + BAY_ARC_ALLOWANCE_LINES * p.print.line_width_mm


def _joint1_straight_run(p: Params, side: int) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Joint 1's ``side`` cable run straight from the drop station (where it leaves its drum's lane) to its tangent
    point on its tendon sector: (where that line crosses the bay corner's station, the tangent point), body frame."""
    d = spool_dims(p)
    x_bay, x_drop = -bay_end_station_mm(p), -drop_station_mm(p)
    z_s = motor_placements(p)[0].z_cable_mm + side * d.end_offset_mm
    z_t = tendon_level_mm(p, 0, side)
    y0 = side * d.drum_radius_mm
    tx, ty = _tangent_point(x_drop, y0, -joint_stations_mm(p)[0], 0.0, p.joints.tendon_moment_arm_mm, side)
    f = (x_drop - x_bay) / (x_drop - tx)
    return (x_bay, y0 + f * (ty - y0), z_s + f * (z_t - z_s)), (tx, ty, z_t)


def joint1_rise_mm(p: Params, side: int) -> float:
    """How far joint 1's ``side`` cable rises at the bay corner above its straight run from the drop station to its
    tendon sector, so that it passes over the lanes of that side (:func:`crossing_rise_mm`): it leaves its drum
    inside them and ends outside them, so it crosses every one in plan. Most designs with four joints or more need
    none (joint 1's cable climbs to its level, the highest, as the lanes drop to theirs); with two or three joints
    joint 1's level lies below the spools' plane and its cable came down with the lanes (1.2 to 3.1 mm apart where
    4.6 mm was needed, on 123 of 196 seeded designs, 2026-11-29)."""
    js = joint_stations_mm(p)
    x_bay = -bay_end_station_mm(p)
    motors = motor_placements(p)
    z_s = motors[0].z_cable_mm + side * spool_dims(p).end_offset_mm
    a0, tangent = _joint1_straight_run(p, side)
    need = bay_crossing_gap_mm(p)
    rise = 0.0
    for mp in motors[1:]:
        b0 = (x_bay, side * mp.lane_y_mm, z_s - lane_drop_mm(p, mp.joint))
        b1 = (-js[0], 0.0, tendon_level_mm(p, mp.joint, side))
        rise = max(rise, float(crossing_rise_mm(a0, tangent, b0, b1, need,
                                                RISE_MAX_PITCHES * tendon_level_pitch_mm(p))))
    return rise if rise > 0.01 else 0.0


def _turn_angle(a, b, c) -> float:
    u = np.subtract(b, a)
    v = np.subtract(c, b)
    cosang = float(np.dot(u, v) / (np.linalg.norm(u) * np.linalg.norm(v)))
    return math.acos(max(-1.0, min(1.0, cosang)))


@functools.lru_cache(maxsize=256)
def cable_routes(p: Params) -> tuple[CableRoute, ...]:
    """Both cables of every joint, at rest (memoised on the params, as :func:`spool_dims`).

    spool tangent -> (motors ahead of the rear one) exit guide into its lane -> level along the lane to the drop
    station, then down to the bay corner (:func:`lane_drop_mm` below the spool's plane) -> the hinge lines of the
    joints ahead, on the axis (y = 0, z = +/- h_j) -> tangent to the tendon sector of its joint (radius = moment
    arm, z = +/- h_j). Joint 1's cable turns at the drop station straight toward its sector, rising over the
    lanes at the bay corner where it must (:func:`joint1_rise_mm`). Bends are the route's turning points.
    """
    js = joint_stations_mm(p)
    m = p.joints.tendon_moment_arm_mm
    d = spool_dims(p)
    x_bay = -bay_end_station_mm(p)
    x_drop = -drop_station_mm(p)
    routes = []
    for mp in motor_placements(p):
        j = mp.joint
        for side in (+1, -1):
            z_s = mp.z_cable_mm + side * d.end_offset_mm
            z_t = tendon_level_mm(p, j, side)
            pts: list[tuple[float, float, float]] = []
            kinds: list[tuple[str, int]] = []
            if j == 0:
                y_lane = side * d.drum_radius_mm
                pts += [(mp.x_mm, y_lane, z_s), (x_drop, y_lane, z_s)]  # leaves the drum straight aft
                kinds.append(("bay", 0))
                rise = joint1_rise_mm(p, side)
                if rise > 0.0:   # over the lanes: up at the bay corner, on the same line in plan
                    bay, _ = _joint1_straight_run(p, side)
                    pts.append((bay[0], bay[1], bay[2] + rise))
                    kinds.append(("drop", 0))
            else:
                y_lane = side * mp.lane_y_mm
                x_in = mp.x_mm - d.flange_radius_mm - p.guides.min_bend_radius_mm / 2
                sx, sy = _tangent_point(x_in, y_lane, mp.x_mm, 0.0, d.drum_radius_mm, side)
                pts += [(sx, sy, z_s), (x_in, y_lane, z_s), (x_drop, y_lane, z_s),
                        (x_bay, y_lane, z_s - lane_drop_mm(p, j))]
                kinds += [("exit", 0), ("drop", 0), ("bay", 0)]
            for k in range(j):  # hinge-line crossings of the joints ahead
                pts.append((-js[k], 0.0, z_t))
                kinds.append(("hinge", k + 1))
            last = pts[-1]
            tx, ty = _tangent_point(last[0], last[1], -js[j], 0.0, m, side)
            pts.append((tx, ty, z_t))
            bends = []
            for k in range(1, len(pts) - 1):
                ang = _turn_angle(pts[k - 1], pts[k], pts[k + 1])
                kind, link = kinds[k - 1]
                bends.append(Bend(tuple(float(v) for v in pts[k]), ang, link, kind))
            routes.append(CableRoute(j, side, tuple(tuple(float(v) for v in q) for q in pts), tuple(bends)))
    return tuple(routes)


# ----------------------------------------------------------------------------------------------- feasibility
HINGE_TURN_SAMPLES = 41
"""Joint angles, from stop to stop, at which a hinge crossing's turn is taken (:func:`hinge_crossings`)."""


@dataclass(frozen=True)
class HingeCrossing:
    """Where a cable crosses the hinge line of a joint it does not drive: on the axis, out of the pass-through hole
    of the link ahead (fixed) into the one behind (turning with the joint)."""
    label: str                   # cable_<joint>_<left|right>
    joint: int                   # the hinge's joint (1-based)
    point_mm: tuple              # on the hinge axis (body frame, at rest)
    rest_rad: float              # the route's turn there at rest
    worst_rad: float             # the largest turn over the joint's range (its stops)


@functools.lru_cache(maxsize=64)
def hinge_crossings(p: Params) -> tuple[HingeCrossing, ...]:
    """Every cable's hinge-line crossings (:func:`cable_routes`, bends of kind ``hinge``) with the largest turn over
    the joint's range: the incoming segment fixed in the link ahead, the outgoing one turned about the vertical hinge
    axis by every one of :data:`HINGE_TURN_SAMPLES` angles from stop to stop."""
    stops = joint_stop_angles_rad(p)
    out = []
    for r in cable_routes(p):
        pts = r.points_mm
        for k, b in enumerate(r.bends, start=1):
            if b.kind != "hinge":
                continue
            u = np.subtract(pts[k], pts[k - 1])
            u = u / np.linalg.norm(u)
            v0 = np.subtract(pts[k + 1], pts[k])
            v0 = v0 / np.linalg.norm(v0)
            worst = 0.0
            for th in np.linspace(-stops[b.link - 1], stops[b.link - 1], HINGE_TURN_SAMPLES):
                c, s = math.cos(-th), math.sin(-th)
                v = np.array([c * v0[0] - s * v0[1], s * v0[0] + c * v0[1], v0[2]])
                worst = max(worst, math.acos(max(-1.0, min(1.0, float(u @ v)))))
            out.append(HingeCrossing(f"cable_{r.joint + 1}_{'left' if r.side > 0 else 'right'}", b.link,
                                     tuple(pts[k]), b.angle_rad, worst))
    return tuple(out)


def layout_problems(p: Params) -> list[Problem]:
    """Geometric impossibilities of a schema-valid design: parts that cannot fit in the hull."""
    out: list[Problem] = []
    F = p.motor.frame_size_mm
    c = p.print.clearance_assembly_mm
    motors = motor_placements(p)
    d = spool_dims(p)
    # every motor (frame below the face, spool flange above it) inside the hull, at its four corners
    for mp in motors:
        z_lo = mp.z_face_mm - p.motor.body_length_mm
        z_hi = mp.z_face_mm + d.top_mm
        for s in (mp.s_mm - F / 2, mp.s_mm + F / 2):
            for z in (z_lo, z_hi):
                room = interior_half_width_at_height_mm(p, s, z)
                need = F / 2 + c if z == z_lo else max(d.flange_radius_mm, F / 2) + c
                if room < need:
                    key, value = (("joints.stations_fraction", list(p.joints.stations_fraction)) if s > 0
                                  else ("motor.frame_size_mm", F))
                    out.append(Problem(key, value,
                                       f"motor for joint {mp.joint + 1} does not fit in the hull: at station "
                                       f"{s:.0f} mm, height {z:.0f} mm the hull has {room:.1f} mm half-width, "
                                       f"needs {need:.1f} mm (move joint 1 aft, or use a smaller motor.frame_size_mm, "
                                       f"or a larger body.height_to_width, or less room behind the motors: "
                                       f"hull.drive_bay_length_mm = {p.hull.drive_bay_length_mm:g})"))
                    break
            else:
                continue
            break
    # tendon sector (radius m) plus cable and wall inside the hull at each joint, at its cable plane
    m = p.joints.tendon_moment_arm_mm
    for mp in motors:
        s = joint_stations_mm(p)[mp.joint]
        room = min(interior_half_width_at_height_mm(p, s, tendon_level_mm(p, mp.joint, sd) + sd * p.cable.diameter_mm)
                   for sd in (1, -1))
        need = m + p.cable.diameter_mm + c
        if room < need:
            out.append(Problem("joints.tendon_moment_arm_mm", m,
                               f"the tendon sector of joint {mp.joint + 1} does not fit in the hull at station "
                               f"{s:.0f} mm: half-width {room:.1f} mm, needs {need:.1f} mm"))
    # the head segment must hold the motor row
    segs = hull_segments(p)
    if motors[-1].s_mm - F / 2 < p.body.nose_cap_fraction * p.body.length_mm:
        out.append(Problem("joints.stations_fraction", list(p.joints.stations_fraction),
                           f"the motor row reaches into the nose cap: move joint 1 aft, or leave less room behind "
                           f"the motors (hull.drive_bay_length_mm = {p.hull.drive_bay_length_mm:g})"))
    for seg in segs:
        need = 2 * p.hull.bulkhead_thickness_mm + 2 * p.joints.pin_diameter_mm
        if seg.s_end_mm - seg.s_start_mm >= need:
            continue
        if seg.name == "hull_peduncle":   # the hull end, behind the last joint, is what the user moves
            meta = next(f.metadata for f in fields(Body) if f.name == "hull_end_fraction")
            lo, hi = meta["lo"], meta["hi"]
            least = (seg.s_start_mm + need) / p.body.length_mm
            fix = (f"body.hull_end_fraction must be >= {math.ceil(least * 1000) / 1000:g} (allowed [{lo:g}, {hi:g}])"
                   if least <= hi else f"no body.hull_end_fraction in [{lo:g}, {hi:g}] leaves room")
            out.append(Problem("body.hull_end_fraction", p.body.hull_end_fraction,
                               f"the peduncle (hull behind the last joint, joints.stations_fraction[-1] = "
                               f"{p.joints.stations_fraction[-1]:g}) is only {seg.s_end_mm - seg.s_start_mm:.1f} mm "
                               f"long after the joint's gap, needs {need:.1f} mm (two bulkheads and the hinge pin): "
                               f"{fix}, or move the last joint forward"))
        else:
            out.append(Problem("joints.stations_fraction", list(p.joints.stations_fraction),
                               f"{seg.name} is only {seg.s_end_mm - seg.s_start_mm:.1f} mm long after the joint "
                               f"gaps: joints too close together for their range of motion"))
    # stop angle must stay below 90 deg (the hull shells would overlap)
    for j, th in enumerate(joint_stop_angles_rad(p)):
        if th >= math.radians(80):
            out.append(Problem("swimming.tail_amplitude_m", p.swimming.tail_amplitude_m,
                               f"joint {j + 1} would need {math.degrees(th):.0f} deg of travel (>= 80 deg)"))
    return out


def inner_envelope_excess_mm(p: Params, vertices: np.ndarray) -> np.ndarray:
    """How far each point lies outside the hull's inner surface [mm, approximately: normalised ellipse
    radius excess x the local half-width]; <= 0 inside. Points ahead of the nose or behind the hull end
    count as outside by their distance."""
    s = -vertices[:, 0]
    a = np.asarray(naca_half_width_mm(p, s)) - p.hull.wall_thickness_mm
    b = np.asarray(half_height_mm(p, s)) - p.hull.wall_thickness_mm
    ok = (a > 0) & (b > 0)
    r = np.full(len(s), np.inf)
    r[ok] = np.sqrt((vertices[ok, 1] / a[ok]) ** 2 + (vertices[ok, 2] / b[ok]) ** 2)
    excess = np.where(ok, (r - 1.0) * np.minimum(a, b).clip(min=1e-9), np.inf)
    excess = np.maximum(excess, np.maximum(-s, s - hull_end_mm(p)))
    return excess
