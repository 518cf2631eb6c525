"""Joint hardware as numbers: every dimension a joint link and its parent's clevis share (mm, deg), and the
designs whose links cannot be built. No CAD kernel: the design loader and the rules use it on every command.

The geometry these numbers describe is documented in :mod:`swiftfin.cad.link`, which makes the solids.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from swiftfin.core.errors import UserError
from swiftfin.core.params import Problem
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L

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
    """Designs the schema and :func:`swiftfin.layout.geometry.layout_problems` accept but whose joint links cannot be built
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
