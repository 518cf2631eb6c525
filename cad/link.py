"""Joint links: the part that turns each tail joint, numbers first (:func:`joint_hardware`), solids second.

One ``joint_link_<j>`` per joint j (1..N). It is bolted to the front bulkhead of the child hull segment
and turns in the clevis at the rear of the parent segment (both made by :mod:`cad.hull` from the same
numbers, so the two always agree).

Geometry and interpretations (all in the body frame of :mod:`cad.layout`, mm; angles in the horizontal
plane are measured about the joint axis from +x (forward) toward +y):

* **Vertical stack** along the hinge axis (z up), bottom to top::

      parent lower lug | lower knuckle + stop tongue | cable window | tendon sector | parent upper lug

  The cable levels (:func:`cad.layout.tendon_level_mm`) are spaced by one level pitch P starting at -P/2,
  the last joint lowest. Joint j's window holds the levels of the joints behind it (they cross its hinge
  line on the axis); its own pair of levels is just above, on the sector. The window spans
  [lowest level - hole radius - web, own lower level - P/2], the sector the next 2P. P is one pass-through hole
  plus a web of two line widths (:func:`cad.layout.tendon_level_pitch_mm`); the window's floor and the blind pin
  bores' ends keep the same web from the nearest hole, so no skin thinner than two perimeters is left.
* **Hinge**: the cables cross the hinge line *on* the axis, so the pin cannot run through. There are two
  short pins (steel dowels of ``joints.pin_diameter_mm``): one through the parent's lower lug into the
  lower knuckle, one through the parent's upper lug into the sector, which is the link's upper knuckle.
  Bores are ``pin_diameter_mm + 2 clearance_sliding_mm`` in both parts (the pin is glued or pressed into
  one of them on assembly). Axial clearance between lugs and link: ``print.clearance_sliding_mm``.
* **Tendon sector**: a disc of radius ``R_s`` round the axis, cut away in front of the first angle the
  grooves need. Each cable's groove is a partial torus whose section (radius r_g = cable/2 + sliding
  clearance/2) has its root at ``m - cable/2``, so a seated cable's centre line runs at the moment arm
  ``m = joints.tendon_moment_arm_mm`` (the paper's d_mount). The groove starts at the tangent point of the
  route (:func:`cad.layout.cable_routes`, last point) minus the stop angle minus 5 deg and wraps backward to
  the anchor at tangent + stop + 15 deg (clipped so it stays ahead of the child's bulkhead), where a radial
  hole leads the cable end to a vertical anchor hole (knot or crimp).
* **Pass-through holes**: for the cables of the joints behind, at their levels on the hinge line: straight
  holes (PTFE tube OD + 2 sliding clearance) along -x behind the axis (fixed in the child's frame), and a
  horizontal wedge ahead of the axis that opens by the stop angle + 2 deg to each side, because the
  incoming cable is fixed in the parent's frame.
* **Hard stops**: a tongue of half-angle ``beta`` pointing forward on the lower knuckle; the parent carries
  two blocks on its lower lug whose radial faces lie at +/- (beta + theta_stop). The tongue's faces meet
  them when the joint reaches +/- ``cad.layout.joint_stop_angles_rad(p)[j-1]``.
* **Flange**: a plate on the front face of the child's front bulkhead, with four bolt holes (hull screws,
  ``hull.screw_diameter_mm``); the link is trimmed at that face, so nothing of it enters the child.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


from cad.kernel import bd

from cad import layout as L
from cad.part import PartSpec
from swiftfin.errors import BuildError, UserError
from swiftfin.params import Problem
from swiftfin.schema import Params

TONGUE_HALF_DEG = 15.0        # half-angle of the stop tongue
BLOCK_SPAN_DEG = 30.0         # angular width of each parent stop block (reduced where the child would hit it)
GROOVE_LEAD_DEG = 5.0         # groove starts this far ahead of the most-wrapped tangent point
WRAP_MARGIN_DEG = 15.0        # groove continues this far past the least-wrapped tangent point to the anchor
MIN_WRAP_MARGIN_DEG = 3.0     # refuse a design whose anchor cannot sit at least this far past it
FLARE_EXTRA_DEG = 2.0         # pass-through wedge opens this much beyond the stop angle


@dataclass(frozen=True)
class JointHardware:
    """Every number of joint ``joint`` (1-based) shared by its link and its parent's clevis (mm, deg)."""
    joint: int
    x_mm: float                       # joint axis at (x, 0), vertical
    gap_half_mm: float                # parent's rear end at x + gap_half, child's front end at x - gap_half
    stop_deg: float
    pitch_mm: float
    crossing_levels_mm: tuple         # z of the cables of the joints behind (on the hinge line)
    own_levels_mm: tuple              # (z left cable, z right cable) on the sector
    z_knuckle_lo_mm: float
    z_window_lo_mm: float
    z_sector_lo_mm: float
    z_sector_hi_mm: float
    lower_lug_mm: tuple               # (z lo, z hi)
    upper_lug_mm: tuple
    bore_radius_mm: float
    knuckle_radius_mm: float
    lug_radius_mm: float
    hole_diameter_mm: float           # pass-through / bulkhead holes (PTFE tube OD + clearance)
    sector_radius_mm: float
    groove_major_mm: float
    groove_minor_mm: float
    sector_front_deg: float           # sector material only at |angle| >= this
    tangent_deg: tuple                # (left, right) tangent-point angles of the routes
    groove_start_deg: float           # left groove from groove_start to anchor (right: mirrored)
    anchor_deg: float
    anchor_radius_mm: float
    anchor_hole_diameter_mm: float
    cable_hole_diameter_mm: float
    tongue_half_deg: float
    tongue_radius_mm: float
    block_span_deg: float
    block_outer_radius_mm: float
    arm_half_width_mm: float
    flange_thickness_mm: float
    flange_half_width_mm: float
    flange_z_mm: tuple                # (z lo, z hi)
    bolt_points_yz_mm: tuple          # ((y, z), ...) bolt axes along x
    bolt_hole_diameter_mm: float
    cable_diameter_mm: float

    @property
    def moment_arm_mm(self) -> float:
        """Radius of a seated cable's centre line: groove root + cable radius."""
        return self.groove_major_mm - self.groove_minor_mm + self.cable_diameter_mm / 2


def joint_hardware(p: Params, j: int) -> JointHardware:
    """Numbers of joint j (1-based). See the module docstring for the geometry.

    Raises UserError (listing :func:`joint_link_problems` of this joint) when the link cannot be built.
    """
    h, problems = _joint_hardware(p, j)
    if problems:
        raise UserError("\n".join(f"joint_link_{j}: {pr}" for pr in problems))
    return h


def joint_link_problems(p: Params) -> list[Problem]:
    """Designs the schema and :func:`cad.layout.layout_problems` accept but whose joint links cannot be built
    (tendon wrap, stop blocks or flange bolts without room). Meant to be joined to the layout problems."""
    return [pr for j in range(1, p.joints.count + 1) for pr in _joint_hardware(p, j)[1]]


def _joint_hardware(p: Params, j: int) -> tuple[JointHardware, list[Problem]]:
    problems: list[Problem] = []
    n = p.joints.count
    if not 1 <= j <= n:
        raise ValueError(f"joint {j} not in 1..{n}")
    cs, ca, lw = p.print.clearance_sliding_mm, p.print.clearance_assembly_mm, p.print.line_width_mm
    x = -L.joint_stations_mm(p)[j - 1]
    g2 = L.joint_gaps_mm(p)[j - 1] / 2
    th = math.degrees(L.joint_stop_angles_rad(p)[j - 1])
    P = L.tendon_level_pitch_mm(p)
    crossing = tuple(sorted(L.tendon_level_mm(p, k, s) for k in range(j, n) for s in (1, -1)))
    own = (L.tendon_level_mm(p, j - 1, 1), L.tendon_level_mm(p, j - 1, -1))
    z_sec_lo, z_sec_hi = own[1] - P / 2, own[0] + P / 2
    hole_d = p.guides.ptfe_tube_od_mm + 2 * cs
    web = L.MIN_WEB_LINES * lw
    # the window's floor lies a web below the lowest pass-through hole (the arm's underside is that floor)
    z_win_lo = (crossing[0] - hole_d / 2 - web) if crossing else z_sec_lo
    tk = p.joints.link_thickness_mm
    z_k0 = z_win_lo - tk
    lower_lug = (z_k0 - cs - tk, z_k0 - cs)
    upper_lug = (z_sec_hi + cs, z_sec_hi + cs + tk)
    rb = p.joints.pin_diameter_mm / 2 + cs
    rk = rb + max(2.0, 4 * lw)
    dc = p.cable.diameter_mm
    rg = dc / 2 + cs / 2
    m = p.joints.tendon_moment_arm_mm
    R_t = m - dc / 2 + rg                     # groove centre radius: root at m - dc/2
    R_s = R_t + 0.3 * rg                      # groove opening 1.9 r_g > cable diameter
    # tangent points of the two routes of this joint (last route point)
    tang = {}
    for r in L.cable_routes(p):
        if r.joint == j - 1:
            tx, ty, _ = r.points_mm[-1]
            tang[r.side] = math.degrees(math.atan2(ty, tx - x))
    aT = min(tang[1], -tang[-1])              # least forward tangent angle of the two (symmetric at rest)
    aT_max = max(tang[1], -tang[-1])
    g_start = aT - th - GROOVE_LEAD_DEG
    front = max(0.0, g_start)
    # anchor: past the tangent by stop + margin, but ahead of the child's bulkhead plane x - g2
    anchor_d = max(2.0, 2 * dc + 2 * cs)
    ra = max(rk + anchor_d / 2 + 1.0, 0.45 * m)
    lim = -(g2 - rg - 0.5) / R_s
    a_lim = math.degrees(math.acos(max(-1.0, min(1.0, lim))))
    anchor = min(aT_max + th + WRAP_MARGIN_DEG, a_lim)
    if anchor < aT_max + th + MIN_WRAP_MARGIN_DEG:
        problems.append(Problem(
            "joints.tendon_moment_arm_mm", m,
            f"joint {j}'s tendon groove cannot wrap its stop angle ({th:.1f} deg) past the cable's tangent point "
            f"({aT_max:.1f} deg) before it reaches the child's bulkhead (gap {2 * g2:.1f} mm, moment arm {m:g} mm): "
            f"the anchor fits up to {a_lim:.1f} deg, needs {aT_max + th + MIN_WRAP_MARGIN_DEG:.1f} deg; use a "
            f"smaller moment arm (the wrap then fits in the gap) or move the joints"))
    beta = TONGUE_HALF_DEG
    rt = rk + 2.5
    rbo = rt + 1.0
    # block must not reach the child's bulkhead plane when the child turns by theta the other way
    q = (g2 - ca) / rbo
    psi_max = 180.0 if q >= 1 else math.degrees(math.acos(-q))
    span = min(BLOCK_SPAN_DEG, psi_max - beta - 2 * th)
    if span < 8.0:
        problems.append(Problem("joints.stop_margin_deg", p.joints.stop_margin_deg,
                                f"joint {j}: no room for the hard-stop blocks at a {th:.1f} deg stop angle "
                                f"(gap {2 * g2:.1f} mm); use a smaller stop angle"))
    arm = max(rk, hole_d / 2 + 2.5)
    tf = max(1.5, min(3.0, 0.5 * g2))
    bolt_d = p.hull.screw_diameter_mm + 2 * cs
    e = bolt_d / 2 + 1.5
    fz = (z_win_lo, z_sec_hi)
    # flange half-width: bolts clear of the pass-through holes, inside the child's bulkhead, and the
    # flange's corners must not reach the parent's rear bulkhead plane (x + g2) at the stop angle
    thr = math.radians(th)
    w_rot = (g2 - ca + (g2 - tf) * math.cos(thr)) / max(math.sin(thr), 1e-9)
    s_bh = -x + g2 + p.hull.bulkhead_thickness_mm / 2
    w_in = min(L.interior_half_width_at_height_mm(p, s_bh, z) for z in (fz[0] + e, fz[1] - e)) - e
    w_f = min(max(arm + 2 * e, 12.0), w_rot, w_in)
    if w_f - e < hole_d / 2 + bolt_d / 2 + 0.8:
        problems.append(Problem("hull.screw_diameter_mm", p.hull.screw_diameter_mm,
                                f"joint {j}: no room for the link's flange bolts beside the cable holes "
                                f"(flange half-width {w_f:.1f} mm inside the child's bulkhead)"))
    bolts = tuple((sy * (w_f - e), zz) for sy in (1, -1) for zz in (fz[0] + e, fz[1] - e))
    return JointHardware(
        joint=j, x_mm=x, gap_half_mm=g2, stop_deg=th, pitch_mm=P, crossing_levels_mm=crossing,
        own_levels_mm=own, z_knuckle_lo_mm=z_k0, z_window_lo_mm=z_win_lo, z_sector_lo_mm=z_sec_lo,
        z_sector_hi_mm=z_sec_hi, lower_lug_mm=lower_lug, upper_lug_mm=upper_lug, bore_radius_mm=rb,
        knuckle_radius_mm=rk, lug_radius_mm=rk, hole_diameter_mm=hole_d, sector_radius_mm=R_s,
        groove_major_mm=R_t, groove_minor_mm=rg, sector_front_deg=front, tangent_deg=(tang[1], tang[-1]),
        groove_start_deg=g_start, anchor_deg=anchor, anchor_radius_mm=ra, anchor_hole_diameter_mm=anchor_d,
        cable_hole_diameter_mm=dc + 2 * cs, tongue_half_deg=beta, tongue_radius_mm=rt, block_span_deg=span,
        block_outer_radius_mm=rbo, arm_half_width_mm=arm, flange_thickness_mm=tf, flange_half_width_mm=w_f,
        flange_z_mm=fz, bolt_points_yz_mm=bolts, bolt_hole_diameter_mm=bolt_d, cable_diameter_mm=dc), problems


def all_joint_hardware(p: Params) -> tuple[JointHardware, ...]:
    return tuple(joint_hardware(p, j) for j in range(1, p.joints.count + 1))


# ----------------------------------------------------------------------------------------------- solid helpers
def pie(x: float, radius: float, a0_deg: float, a1_deg: float, z0: float, z1: float,
        y: float = 0.0) -> bd.Solid:
    """Sector of a vertical cylinder round (x, y): angles a0..a1 (deg from +x toward +y), heights z0..z1."""
    a0 = math.radians(a0_deg)
    pl = bd.Plane(origin=(x, y, z0), x_dir=(math.cos(a0), math.sin(a0), 0), z_dir=(0, 0, 1))
    return bd.Solid.make_cylinder(radius, z1 - z0, pl, angle=a1_deg - a0_deg)


def vcyl(x: float, y: float, radius: float, z0: float, z1: float) -> bd.Solid:
    return bd.Solid.make_cylinder(radius, z1 - z0, bd.Plane(origin=(x, y, z0), z_dir=(0, 0, 1)))


def box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float) -> bd.Solid:
    return bd.Solid.make_box(x1 - x0, y1 - y0, z1 - z0, bd.Plane(origin=(x0, y0, z0), z_dir=(0, 0, 1)))


def rod(start, direction, radius: float, length: float) -> bd.Solid:
    """Cylinder of ``radius`` from ``start`` along unit ``direction`` for ``length``."""
    return bd.Solid.make_cylinder(radius, length, bd.Plane(origin=tuple(start), z_dir=tuple(direction)))


def isect(a: bd.Shape, b: bd.Shape) -> bd.Shape:
    """Boolean common of two shapes as one shape (a Compound when it has several solids)."""
    res = a.intersect(b)
    if res is None:
        return bd.Compound([])
    if isinstance(res, bd.Shape):
        return res
    solids = [s for r in res for s in r.solids()]
    return solids[0] if len(solids) == 1 else bd.Compound(solids)


def one_solid(shape, label: str) -> bd.Solid:
    """The single solid of a boolean result, or BuildError naming the part."""
    solids = shape.solids() if hasattr(shape, "solids") else [shape]
    if len(solids) != 1:
        vols = sorted((s.volume for s in solids), reverse=True)
        raise BuildError(f"{label}: expected one solid, got {len(solids)} (volumes {[round(v, 1) for v in vols]})")
    return solids[0]


# ----------------------------------------------------------------------------------------------- solids
def link_solid(p: Params, h: JointHardware) -> bd.Solid:
    x = h.x_mm
    g2 = h.gap_half_mm
    rk, rb = h.knuckle_radius_mm, h.bore_radius_mm
    z0, zw, zs, zt = h.z_knuckle_lo_mm, h.z_window_lo_mm, h.z_sector_lo_mm, h.z_sector_hi_mm
    x_back = x - g2
    big = 4 * h.sector_radius_mm
    # --- body
    parts = [vcyl(x, 0, rk, z0, zw),                                                   # lower knuckle
             pie(x, h.tongue_radius_mm, -h.tongue_half_deg, h.tongue_half_deg, z0, zw),  # stop tongue
             box(x_back, x, -h.arm_half_width_mm, h.arm_half_width_mm, zw, zt)]         # arm
    if zs > zw:
        parts.append(vcyl(x, 0, rk, zw, zs))                                           # window column
    sector = vcyl(x, 0, h.sector_radius_mm, zs, zt)
    if h.sector_front_deg > 0:
        sector = sector.cut(pie(x, big, -h.sector_front_deg, h.sector_front_deg, zs - 1, zt + 1))
    parts += [sector, vcyl(x, 0, rk, zs, zt),
              box(x_back, x_back + h.flange_thickness_mm, -h.flange_half_width_mm, h.flange_half_width_mm,
                  *h.flange_z_mm)]
    body = parts[0].fuse(*parts[1:]).clean()
    # --- cuts
    hr = h.hole_diameter_mm / 2
    # blind pin bores end a web short of the nearest pass-through hole (else a 0.4 mm skin separates them)
    web = L.MIN_WEB_LINES * p.print.line_width_mm
    z_bore_lo = min(zw, h.crossing_levels_mm[0] - hr - web) if h.crossing_levels_mm else zw
    z_bore_hi = max(zs, h.crossing_levels_mm[-1] + hr + web) if h.crossing_levels_mm else zs
    cuts = [vcyl(x, 0, rb, z0 - 1, z_bore_lo),                                         # lower pin bore (blind)
            vcyl(x, 0, rb, z_bore_hi, zt + 1)]                                         # upper pin bore (blind)
    flare = math.radians(h.stop_deg + FLARE_EXTRA_DEG)
    lf = rk + 1.5
    for z in h.crossing_levels_mm:
        cuts.append(rod((x + 0.01, 0, z), (-1, 0, 0), hr, g2 + 1.0))                   # straight, behind
        w = hr + lf * math.tan(flare)
        wedge = bd.Solid.extrude(bd.Face(bd.Wire.make_polygon(
            [(x, -hr, z - hr), (x + lf, -w, z - hr), (x + lf, w, z - hr), (x, hr, z - hr)], close=True)),
            bd.Vector(0, 0, 2 * hr))
        cuts += [wedge, rod((x, 0, z), (1, 0, 0), hr, lf)]
    # grooves and anchors: left (+y) cable at own_levels[0], right at own_levels[1], mirrored
    span = h.anchor_deg - h.groove_start_deg
    for side, z in ((1, h.own_levels_mm[0]), (-1, h.own_levels_mm[1])):
        a0 = h.groove_start_deg if side > 0 else -h.anchor_deg
        a0r = math.radians(a0)
        pl = bd.Plane(origin=(x, 0, z), x_dir=(math.cos(a0r), math.sin(a0r), 0), z_dir=(0, 0, 1))
        cuts.append(bd.Solid.make_torus(h.groove_major_mm, h.groove_minor_mm, pl, 0, 360, span))
        aa = math.radians(side * h.anchor_deg)
        u = (math.cos(aa), math.sin(aa), 0.0)
        ra = h.anchor_radius_mm
        start = (x + (h.groove_major_mm + 0.2) * u[0], (h.groove_major_mm + 0.2) * u[1], z)
        cuts.append(rod(start, (-u[0], -u[1], 0), h.cable_hole_diameter_mm / 2, h.groove_major_mm + 0.2 - ra))
        cuts.append(vcyl(x + ra * u[0], ra * u[1], h.anchor_hole_diameter_mm / 2, zs - 0.01, zt + 0.01))
    for (y, z) in h.bolt_points_yz_mm:
        cuts.append(rod((x_back - 1, y, z), (1, 0, 0), h.bolt_hole_diameter_mm / 2, h.flange_thickness_mm + 2))
    body = body.cut(*cuts)
    # trim at the child's bulkhead face
    body = isect(body, box(x_back, x + big, -big, big, z0 - 1, zt + 1))
    return one_solid(body, f"joint_link_{h.joint}")


def make_joint_links(p: Params) -> list[PartSpec]:
    """One ``joint_link_<j>`` per joint, in the body frame at rest (mm).

    Raises UserError listing every :func:`joint_link_problems` of the design at once.

    Printed upside down (rx = 180 deg): the sector's flat top goes on the bed, so the sector plate does not
    overhang the narrower window column below it.
    """
    problems = joint_link_problems(p)
    if problems:
        raise UserError("joint links cannot be built:\n" + "\n".join(f"  - {pr}" for pr in problems))
    out = []
    for h in all_joint_hardware(p):
        out.append(PartSpec(label=f"joint_link_{h.joint}", solid=link_solid(p, h), link=h.joint, family="link",
                            print_rotation=(180.0, 0.0, 0.0),
                            meta={"joint": h.joint, "moment_arm_mm": h.moment_arm_mm,
                                  "stop_deg": h.stop_deg}))
    return out
