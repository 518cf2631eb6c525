"""The capstan cables and the PTFE tubes as solids of the assembly, numbers first (centre lines), meshes second.

Issue 12 item 5: every cable and tube is a swept solid along its route that moves with the joints, so that the
assembly check (:mod:`swiftfin.cad.assembly`) proves over the joints' range that no cable passes through a part,
and the rules here prove that every bend meets its minimum radius and every tube is seated against a stop and
held there.

**Cables** (:func:`cable_pieces`). Each side of each pull-pull cable follows
:func:`swiftfin.layout.geometry.cable_routes` (spool tangent -> exit guide -> bay guide -> the hinge lines of the
joints ahead, on the axis -> tangent to its own joint's tendon sector), as a circle of ``cable.diameter_mm`` swept
along the centre line:

* the **exit** and **bay** bends are rounded at the guide channel's radius ``guides.min_bend_radius_mm`` (the same
  arc as :func:`swiftfin.layout.guide_plan.bend_channel`, so the cable runs on the channel's centre line);
* the cable is cut into **pieces, one per kinematic link**: ``cable_<J>_<left|right>_<k>`` is the straight run
  rigid with link k (k = 0: spool to the hinge line of joint 1, or to the sector for J = 1; 1 <= k < J: hinge line
  of joint k to that of joint k+1, or to the sector). Pieces meet on the joint axes, where a rotation of the joint
  does not move them, so the cable is continuous in every pose; a piece ends in a half sphere, so two pieces meeting
  at an angle make the cable's sharp turn round the hinge line (it bends by its rest angle plus the joint angle);
* ``cable_<J>_<side>_<J>_groove`` (link J) is the cable wrapped in the tendon sector's groove at the seated radius
  (``JointHardware.moment_arm_mm``), from the tangent point less the stop angle to the anchor: whatever the joint's
  angle, the wrapped cable lies inside this arc (the straight run stays tangent to the sector, which turns about
  its own axis), so a rigid piece on link J covers every wrap state; ``cable_<J>_<side>_<J>_anchor`` is the radial
  run from the groove into the anchor hole.

The wraps on the spools' drums are not modelled (they lie in the spool's own groove; cad/spool.py checks it).

**PTFE tubes** (:func:`swiftfin.layout.tube_plan.tube_runs`, numbers the loader also reads: it refuses a tube out
of the hull). Where the design puts a tube:

* in every **guide channel**, over the stretch of the channel's centre line that lies inside its printed block,
  from the mouth where the channel opens to the tube's seat (:meth:`swiftfin.layout.guide_plan.GuideBlock.tube_seat`):
  ``tube_<guide>_<J>_<side>``, link 0;
* in every **bulkhead hole** of the hull (:func:`swiftfin.layout.gland_plan.bulkhead_passages`: a bore of PTFE tube OD + 2
  sliding clearance along the route), from the bulkhead's front face to its seat: ``tube_<hull piece>_<J>_<side>``,
  on the piece's link.

The links' pass-through holes are tube-sized too, but nothing in the design says a tube is in them; here the
cable runs bare through them (and must clear them).

**Seats and retention.** Every tube's bore ends flat on a printed shoulder
(:func:`swiftfin.layout.geometry.tube_seat_shoulder_mm`, two line widths) a shoulder short of the part's face, at
the tube's **last** end (downstream, toward the joints); the cable leaves through the exit hole
(:func:`swiftfin.layout.geometry.cable_exit_hole_mm`) in it. The **first** end is the mouth the tube is pushed in
by until it seats. A tube end is *seated* when printed material of its own link fills at least
:data:`STOP_FILL_FRACTION` of the ring (tube ID to OD) within ``print.clearance_sliding_mm`` beyond the end; the
mouth must not be (:func:`tube_stop_problems`, measured on the built meshes). The cable's friction drags the tube
both ways (pull-pull): the shoulder holds one way, the tube's bond along its bore (etched PTFE and epoxy,
``catalogues/adhesives.toml``) the other; both are checked against the friction at the cable's breaking strength
(:func:`tube_retentions`). A one-piece printed part cannot have a shoulder at both ends of a bore that a tube has
to go into, hence the bond.

**Bend radii** (:func:`cable_bends`, :func:`bend_radius_problems`): a tube's bends (its centre line, measured on the
tube pieces) >= ``guides.min_bend_radius_mm``; a cable's bends >= ``rules.drum_to_cable_min x cable.diameter_mm / 2``
(the paper's drum rule, D >= 20 d, read as a least bend radius of 10 d for the braided cable). A cable in a tube
rides on the inside of the bend, so its radius is the tube's less ``(tube ID - cable d) / 2``. On a hinge line the
cable turns by its rest angle plus up to the joint's stop angle round the edge of the link's pass-through hole; a
printed edge has no radius (0 mm), unless the joint hardware declares one (``JointHardware.lead_radius_mm``).

Meshes (:func:`cable_parts`) are numpy sweeps (:func:`swiftfin.layout.sweep.sweep_mesh`, no CAD kernel): polygons
circumscribed about the circle (the mesh contains the true cylinder, so a gap measured on it is never larger than the real one), closed and manifold.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.cad.assembly import Placed, link_transform
from swiftfin.layout.guide_plan import bend_channel
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.joints import all_joint_hardware
from swiftfin.layout.sweep import dedupe_points as _dedupe, sweep_mesh
from swiftfin.layout.tube_plan import (  # noqa: F401 - the tubes' numbers live in layout; named here as before
    ARC_STEP_DEG, SAMPLE_STEP_MM, SIDE_NAME, TUBE_SIDES, TubeRun, _arc_samples, tube_runs)


CABLE_SIDES = 12
"""Polygon sides of a cable's section: circumscribed, its flats lie 3.5 % of the radius (0.02 mm) outside the
true circle. Engineering default (thin, long meshes keep the assembly check fast)."""
MIN_TUBE_MM = L.MIN_TUBE_MM
STOP_FILL_FRACTION = 0.5
"""A tube end is seated when at least this fraction of the ring beyond its end is printed material of its own
link: a shoulder across at least half the tube's wall takes the tube's push. Engineering default."""


# ----------------------------------------------------------------------------------------------- numbers
@dataclass(frozen=True)
class CablePiece:
    """A stretch of one cable rigid with kinematic link ``link``: centre line (body frame at rest, mm)."""
    label: str
    joint: int                   # 1-based joint the cable drives
    side: int                    # +1 left (+y), -1 right
    link: int
    kind: str                    # "run", "groove", "anchor"
    points_mm: tuple             # ((x, y, z), ...) smooth centre line
    radius_mm: float


@dataclass(frozen=True)
class CableBend:
    """A bend of a cable or tube: the largest turn over the joint's range and the radius it is made with."""
    label: str                   # the cable or tube
    kind: str                    # "exit", "drop", "bay" (guide channel), "hinge", "sector", "drum", "tube"
    angle_rad: float
    radius_mm: float
    limit_mm: float
    point_mm: tuple

    @property
    def ok(self) -> bool:
        return self.radius_mm >= self.limit_mm * (1 - 1e-9)


@dataclass(frozen=True)
class CableFinding:
    """A rule the cables or tubes fail (a bend too tight, a tube end without a stop)."""
    rule: str                    # "cable_bend_radius", "tube_bend_radius", "tube_stop", "tube_mouth", "tube_retention"
    label: str
    value: float
    limit: float
    where_mm: tuple
    detail: str

    def __str__(self) -> str:
        return f"{self.label}: {self.detail} near ({', '.join(f'{c:.1f}' for c in self.where_mm)}) mm"


def cable_min_bend_radius_mm(p: Params) -> float:
    """Least bend radius of the cable: half the paper's least drum diameter (``rules.drum_to_cable_min`` x d)."""
    return p.rules.drum_to_cable_min * p.cable.diameter_mm / 2


def _rounded_polyline(pts: list, radius: float, dia: float, joint: int, side: int) -> np.ndarray:
    """The polyline with every inner corner replaced by the guide channel's arc of ``radius``."""
    out = [np.asarray(pts[0], float)]
    for k in range(1, len(pts) - 1):
        ch = bend_channel(pts[k - 1], pts[k], pts[k + 1], radius, dia, joint, side, 1.0)
        if ch.angle_rad <= 1e-9:
            out.append(np.asarray(pts[k], float))
        else:
            out += list(_arc_samples(ch))
    out.append(np.asarray(pts[-1], float))
    return _dedupe(np.asarray(out))


def _sector_arc(x_axis: float, radius: float, z: float, a0_deg: float, a1_deg: float) -> np.ndarray:
    n = max(3, int(math.ceil(abs(a1_deg - a0_deg) / ARC_STEP_DEG)) + 1)
    a = np.radians(np.linspace(a0_deg, a1_deg, n))
    return np.column_stack([x_axis + radius * np.cos(a), radius * np.sin(a), np.full(n, z)])


def cable_pieces(p: Params) -> tuple[CablePiece, ...]:
    """Every cable as pieces rigid with their links (see the module docstring)."""
    r = p.cable.diameter_mm / 2
    R = p.guides.min_bend_radius_mm
    dia = p.guides.ptfe_tube_od_mm + p.print.clearance_sliding_mm
    stops = L.joint_stop_angles_rad(p)
    hw = {h.joint: h for h in all_joint_hardware(p)}
    out = []
    for route in L.cable_routes(p):
        J, side = route.joint + 1, route.side
        name = f"cable_{J}_{SIDE_NAME[side]}"
        pts = [np.asarray(q, float) for q in route.points_mm]
        hinge_idx = [k + 1 for k, b in enumerate(route.bends) if b.kind == "hinge"]
        cuts = [0] + hinge_idx + [len(pts) - 1]
        for link, (i0, i1) in enumerate(zip(cuts[:-1], cuts[1:])):
            seg = pts[i0:i1 + 1]
            line = _rounded_polyline(seg, R, dia, J, side) if link == 0 else np.asarray(seg)
            out.append(CablePiece(f"{name}_{link}", J, side, link, "run", tuple(map(tuple, line)), r))
        h = hw[J]
        m = h.moment_arm_mm
        z = h.own_levels_mm[0 if side > 0 else 1]
        a_t = side * h.tangent_deg[0 if side > 0 else 1]          # |tangent angle| of this side
        stop = math.degrees(stops[J - 1])
        arc = _sector_arc(h.x_mm, m, z, side * (a_t - stop), side * h.anchor_deg)
        out.append(CablePiece(f"{name}_{J}_groove", J, side, J, "groove", tuple(map(tuple, arc)), r))
        u = np.array([math.cos(math.radians(side * h.anchor_deg)), math.sin(math.radians(side * h.anchor_deg)), 0.0])
        a0 = np.array([h.x_mm, 0.0, z]) + m * u
        a1 = np.array([h.x_mm, 0.0, z]) + h.anchor_radius_mm * u
        out.append(CablePiece(f"{name}_{J}_anchor", J, side, J, "anchor", (tuple(a0), tuple(a1)), r))
    return tuple(out)


def _densify(pts: np.ndarray, step: float) -> np.ndarray:
    out = [pts[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        n = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        out += list(a + np.linspace(0, 1, n + 1)[1:, None] * (b - a))
    return np.asarray(out)


# ----------------------------------------------------------------------------------------------- bends
def _circumradii(pts: np.ndarray) -> np.ndarray:
    """Radius of the circle through each three consecutive points (inf on a straight stretch)."""
    a, b, c = pts[:-2], pts[1:-1], pts[2:]
    ab, bc, ca = (np.linalg.norm(b - a, axis=1), np.linalg.norm(c - b, axis=1), np.linalg.norm(a - c, axis=1))
    cross = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = ab * bc * ca / (2 * cross)
    return np.where(cross > 1e-9 * np.maximum(ab * bc, 1e-12), r, np.inf)


def cable_bends(p: Params, pieces=None, tubes=None) -> tuple[CableBend, ...]:
    """Every bend of every cable and tube with its radius and limit (see the module docstring)."""
    pieces = cable_pieces(p) if pieces is None else pieces
    tubes = tube_runs(p) if tubes is None else tubes
    lim_c = cable_min_bend_radius_mm(p)
    lim_t = p.guides.min_bend_radius_mm
    ride = (p.guides.ptfe_tube_id_mm - p.cable.diameter_mm) / 2
    hw = {h.joint: h for h in all_joint_hardware(p)}
    turns = {(c.label, c.point_mm): c.worst_rad for c in L.hinge_crossings(p)}     # over the joint's range
    out = []
    for route in L.cable_routes(p):
        J, side = route.joint + 1, route.side
        name = f"cable_{J}_{SIDE_NAME[side]}"
        pts = route.points_mm
        for k, bend in enumerate(route.bends, start=1):
            if bend.kind in L.GUIDE_BENDS:
                out.append(CableBend(name, bend.kind, bend.angle_rad, p.guides.min_bend_radius_mm - ride, lim_c,
                                     bend.point_mm))
            else:
                lead = float(getattr(hw[bend.link], "lead_radius_mm", 0.0) or 0.0)
                out.append(CableBend(name, "hinge", turns[name, tuple(pts[k])], lead, lim_c, bend.point_mm))
        h = hw[J]
        z = h.own_levels_mm[0 if side > 0 else 1]
        out.append(CableBend(name, "sector", math.radians(h.anchor_deg - side * h.tangent_deg[0 if side > 0 else 1]),
                             h.moment_arm_mm, lim_c, (h.x_mm, 0.0, z)))
        mp = L.motor_placements(p)[J - 1]
        out.append(CableBend(name, "drum", 2 * math.pi * p.spool.wraps, p.spool.drum_diameter_mm / 2, lim_c,
                             (mp.x_mm, 0.0, mp.z_cable_mm)))
    for t in tubes:
        rr = _circumradii(np.asarray(t.points_mm, float))
        if len(rr) and np.isfinite(rr).any():
            i = int(np.argmin(rr))
            pts = np.asarray(t.points_mm, float)
            d0 = np.diff(pts, axis=0)
            d0 = d0 / np.linalg.norm(d0, axis=1)[:, None]
            ang = math.acos(max(-1.0, min(1.0, float(d0[0] @ d0[-1]))))
            out.append(CableBend(t.label, "tube", ang, float(rr[i]), lim_t, tuple(pts[i + 1])))
    return tuple(out)


def bend_radius_problems(p: Params, bends=None) -> list[CableFinding]:
    out = []
    for b in (cable_bends(p) if bends is None else bends):
        if b.ok:
            continue
        rule = "tube_bend_radius" if b.kind == "tube" else "cable_bend_radius"
        src = ("guides.min_bend_radius_mm" if b.kind == "tube"
               else "rules.drum_to_cable_min x cable.diameter_mm / 2")
        what = {"hinge": "round the edge of the pass-through hole on the hinge line (no lead radius)"}.get(
            b.kind, f"at its {b.kind} bend")
        out.append(CableFinding(rule, b.label, b.radius_mm, b.limit_mm, tuple(b.point_mm),
                                f"bends by up to {math.degrees(b.angle_rad):.1f} deg {what} with radius "
                                f"{b.radius_mm:.2f} mm < {b.limit_mm:g} mm ({src})"))
    return out


# ----------------------------------------------------------------------------------------------- meshes
def cable_parts(p: Params, pieces=None, tubes=None) -> list[Placed]:
    """Every cable piece and tube as a :class:`swiftfin.cad.assembly.Placed` mesh (families "cable", "tube"), for
    :func:`swiftfin.cad.assembly.check_assembly` together with the printed and bought parts."""
    pieces = cable_pieces(p) if pieces is None else pieces
    tubes = tube_runs(p) if tubes is None else tubes
    out = []
    for c in pieces:
        v, f = sweep_mesh(c.points_mm, c.radius_mm, CABLE_SIDES, round_ends=True)
        out.append(Placed(c.label, c.link, "cable", v, f))
    for t in tubes:
        v, f = sweep_mesh(t.points_mm, t.od_mm / 2, TUBE_SIDES, inner_radius=t.id_mm / 2)
        out.append(Placed(t.label, t.link, "tube", v, f))
    return out


def harness_parts(p: Params, leads=None) -> list[Placed]:
    """Every lead of the wiring harness (:func:`swiftfin.layout.harness_plan.harness`) as a mesh of family
    "harness" on the head (link 0), swept along its rounded centre line, flat at both ends."""
    from swiftfin.layout.harness_plan import harness
    leads = harness(p) if leads is None else leads
    out = []
    for h in leads:
        v, f = sweep_mesh(h.centre_line_mm, h.diameter_mm / 2, CABLE_SIDES)
        out.append(Placed(h.label, 0, "harness", v, f))
    return out


# ----------------------------------------------------------------------------------------------- stops
def _end_ring(t: TubeRun, end: int, depth_mm: float):
    """The ring (tube ID to OD) from the tube's end ``end`` (0: first point, -1: last) ``depth_mm`` outward."""
    import manifold3d as m3d
    pts = np.asarray(t.points_mm, float)
    if end == 0:
        q, d = pts[0], pts[0] - pts[1]
    else:
        q, d = pts[-1], pts[-1] - pts[-2]
    d = d / np.linalg.norm(d)
    v, f = sweep_mesh([q, q + depth_mm * d], t.od_mm / 2 * math.cos(math.pi / TUBE_SIDES), TUBE_SIDES,
                      inner_radius=t.id_mm / 2)
    return m3d.Manifold(m3d.Mesh(vert_properties=v.astype(np.float32), tri_verts=f.astype(np.uint32))), q


def _ring_fill(t: TubeRun, end: int, depth_mm: float, solid: list[Placed]) -> tuple[float, tuple]:
    """Fraction of the ring beyond the tube's end ``end`` (within ``depth_mm``) that is printed material of the
    tube's own link, and the end's point."""
    ring, q = _end_ring(t, end, depth_mm)
    lo, hi = np.asarray(ring.bounding_box()[:3]), np.asarray(ring.bounding_box()[3:])
    filled = 0.0
    for part in solid:
        if part.link != t.link:
            continue
        plo, phi = part.bounds
        if np.any(plo > hi) or np.any(phi < lo):
            continue
        filled += (part.manifold ^ ring).volume()
    return filled / ring.volume(), tuple(float(c) for c in q)


def tube_stop_problems(p: Params, tubes, parts: list[Placed]) -> list[CableFinding]:
    """Tubes not seated: the **last** end (its seat) must have a stop, printed material of the tube's link filling
    :data:`STOP_FILL_FRACTION` of the ring beyond the end within ``print.clearance_sliding_mm``; the **first** end is
    the mouth the tube goes in by and must be open (less than that fraction). Measured on the parts' meshes."""
    depth = p.print.clearance_sliding_mm
    solid = [q for q in parts if q.family not in ("cable", "tube")]
    out = []
    for t in tubes:
        frac, q = _ring_fill(t, -1, depth, solid)
        if frac < STOP_FILL_FRACTION:
            out.append(CableFinding("tube_stop", t.label, frac, STOP_FILL_FRACTION, q,
                                    f"its seat (last) end has no stop ({100 * frac:.0f} % of the ring within "
                                    f"{depth:g} mm beyond it is printed material of link {t.link}, needs "
                                    f"{100 * STOP_FILL_FRACTION:.0f} %)"))
        frac, q = _ring_fill(t, 0, depth, solid)
        if frac >= STOP_FILL_FRACTION:
            out.append(CableFinding("tube_mouth", t.label, frac, STOP_FILL_FRACTION, q,
                                    f"its mouth (first) end is closed ({100 * frac:.0f} % of the ring within "
                                    f"{depth:g} mm beyond it is printed material of link {t.link}): the tube "
                                    f"cannot go in"))
    return out


TUBE_ADHESIVE = "epoxy_etched_ptfe"
"""The bond that keeps each PTFE tube from walking out of its mouth (``catalogues/adhesives.toml``)."""


def tube_turn_rad(t: TubeRun) -> float:
    """Total angle the tube's centre line turns through [rad] (the sum of its polyline's corner angles)."""
    d = np.diff(np.asarray(t.points_mm, float), axis=0)
    d = d[np.linalg.norm(d, axis=1) > 1e-9]
    d = d / np.linalg.norm(d, axis=1)[:, None]
    return float(np.sum(np.arccos(np.clip(np.einsum("ij,ij->i", d[:-1], d[1:]), -1.0, 1.0))))


@dataclass(frozen=True)
class TubeRetention:
    """What holds a tube in place and what pulls on it [N]: the cable's friction on the bore drags it along."""
    label: str
    turn_rad: float
    drag_n: float                # at the cable's breaking strength: T (1 - e^(-mu theta))
    bond_n: float                # allowable shear x pi OD x length
    shoulder_n: float            # printed shear allowable x pi bore d x shoulder length

    @property
    def ok(self) -> bool:
        return self.drag_n <= min(self.bond_n, self.shoulder_n)


def tube_retentions(p: Params, tubes) -> list[TubeRetention]:
    """Each tube's drag and holds. The cable turning through theta in the tube, with tension T on its tight side,
    leaves it with T e^(-mu theta) (eq. 24 of the paper, ``guides.mu_ptfe``); the difference is the friction on
    the bore, which drags the tube along the cable, one way or the other as the joint swings. T is the cable's
    breaking strength (the tube holds for as long as the cable does). The shoulder takes it one way
    (the printed ring sheared through, ``catalogues/printed_strength.toml``), the bond the other (the tube's
    outside over its whole length, ``catalogues/adhesives.toml``)."""
    from swiftfin.catalogues.adhesives import adhesive
    from swiftfin.catalogues.printed_strength import printed_strength
    bond = adhesive(TUBE_ADHESIVE).allowable_shear_mpa
    shear = printed_strength(p.print.material).shear_allowable_mpa
    shoulder = L.tube_seat_shoulder_mm(p)
    out = []
    for t in tubes:
        th = tube_turn_rad(t)
        drag = p.cable.breaking_strength_n * (1.0 - math.exp(-p.guides.mu_ptfe * th))
        bore = L.tube_bore_diameter_mm(p, t.kind)
        out.append(TubeRetention(t.label, th, drag, bond * math.pi * t.od_mm * t.length_mm,
                                 shear * math.pi * bore * shoulder))
    return out


def tube_retention_problems(p: Params, tubes) -> list[CableFinding]:
    out = []
    by = {t.label: t for t in tubes}
    for r in tube_retentions(p, tubes):
        if r.ok:
            continue
        weak, hold = min((("bond", r.bond_n), ("shoulder", r.shoulder_n)), key=lambda kv: kv[1])
        out.append(CableFinding("tube_retention", r.label, hold, r.drag_n, tuple(by[r.label].points_mm[-1]),
                                f"the cable's friction ({math.degrees(r.turn_rad):.0f} deg of turn, "
                                f"{r.drag_n:.1f} N at the cable's breaking strength) exceeds what its {weak} holds "
                                f"({hold:.1f} N)"))
    return out


def check_tube_seats(p: Params, parts: list[Placed], tubes=None) -> dict:
    """Every tube seated on its shoulder, its mouth open, and held both ways (:func:`tube_stop_problems`,
    :func:`tube_retention_problems`). Raises BuildError listing every failure; returns counts and the least
    margin of the holds over the drag."""
    tubes = tube_runs(p) if tubes is None else tubes
    problems = tube_stop_problems(p, tubes, parts) + tube_retention_problems(p, tubes)
    if problems:
        raise BuildError(f"{len(problems)} PTFE tube rule(s) failed:\n"
                         + "\n".join(f"  - {pr}" for pr in problems))
    rs = tube_retentions(p, tubes)
    worst = min(rs, key=lambda r: min(r.bond_n, r.shoulder_n) / max(r.drag_n, 1e-12))
    return {"tubes": len(tubes), "seats": len(tubes), "worst_tube": worst.label, "worst_drag_n": worst.drag_n,
            "worst_hold_n": min(worst.bond_n, worst.shoulder_n)}


def check_cables(p: Params, parts: list[Placed], tubes=None) -> dict:
    """The cable rules that are not clearances: bend radii and tube seats (the clearances are the assembly check's,
    run with :func:`cable_parts` among the parts). Raises BuildError listing every failure; returns counts."""
    tubes = tube_runs(p) if tubes is None else tubes
    bends = cable_bends(p, tubes=tubes)
    problems = (bend_radius_problems(p, bends) + tube_stop_problems(p, tubes, parts)
                + tube_retention_problems(p, tubes))
    if problems:
        raise BuildError(f"{len(problems)} cable and tube rule(s) failed:\n"
                         + "\n".join(f"  - {pr}" for pr in problems))
    return {"bends": len(bends), "tube_ends": 2 * len(tubes)}


def cable_intrusions(p: Params, piece: CablePiece, part: Placed, angles_rad: dict | None = None,
                     resolution_mm: float = 0.01) -> tuple[float, tuple | None]:
    """How deep the cable piece's surface runs into ``part`` [mm] (0: it does not) and where, with both placed at
    the joint angles (``angles_rad``: {joint: angle}, the others 0). Found by bisection on the radius of the swept
    cable: the depth is the radius less the thickest cable that still clears the part (the cable's radius or more
    when its centre line itself is in the part). For reports; the check is the assembly's."""
    import manifold3d as m3d
    angles = dict(angles_rad or {})
    full = [angles.get(j, 0.0) for j in range(1, p.joints.count + 1)]
    m = np.linalg.inv(link_transform(p, part.link, full)) @ link_transform(p, piece.link, full)
    pts = np.asarray(piece.points_mm, float) @ m[:3, :3].T + m[:3, 3]
    target = part.manifold

    def overlap(rho):
        v, f = sweep_mesh(pts, rho, CABLE_SIDES, round_ends=True)
        man = m3d.Manifold(m3d.Mesh(vert_properties=v.astype(np.float32), tri_verts=f.astype(np.uint32)))
        inter = target ^ man
        return inter.volume(), inter

    vol, inter = overlap(piece.radius_mm)
    if vol <= 0:
        return 0.0, None
    bb = inter.bounding_box()
    where = tuple(float((a + b) / 2) for a, b in zip(bb[:3], bb[3:]))
    lo, hi = 0.0, piece.radius_mm
    back = link_transform(p, part.link, full)
    if overlap(resolution_mm)[0] > 0:   # the centre line is in the part: radius + the deepest point's depth
        c = _densify(pts, 0.1)
        c = c[np.all((c >= np.asarray(bb[:3]) - 1e-6) & (c <= np.asarray(bb[3:]) + 1e-6), axis=1)]
        best, at = 0.0, where
        for q in c:
            ball = m3d.Manifold.sphere(resolution_mm, 16).translate(tuple(q))
            if (ball - target).volume() > 0.5 * ball.volume():
                continue
            a, b = 0.0, 2 * piece.radius_mm + 10.0
            while b - a > resolution_mm:
                mid = (a + b) / 2
                ball = m3d.Manifold.sphere(mid, 24).translate(tuple(q))
                if (ball - target).volume() > 1e-6 * ball.volume():
                    b = mid
                else:
                    a = mid
            if a > best:
                best, at = a, tuple(float(v) for v in back[:3, :3] @ q + back[:3, 3])
        return float(piece.radius_mm + best), at
    while hi - lo > resolution_mm:
        mid = (lo + hi) / 2
        if overlap(mid)[0] > 0:
            hi = mid
        else:
            lo = mid
    w = back[:3, :3] @ np.asarray(where) + back[:3, 3]
    return float(piece.radius_mm - lo), tuple(float(c) for c in w)
