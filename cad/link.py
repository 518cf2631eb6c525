"""Joint links: the part that turns each tail joint, numbers first (:func:`joint_hardware`), solids second.

One ``joint_link_<j>`` per joint j (1..N). It is bolted to the front bulkhead of the child hull segment
and turns in the clevis at the rear of the parent segment (both made by :mod:`cad.hull` from the same
numbers, so the two always agree).

Geometry and interpretations (all in the body frame of :mod:`swiftfin.layout.geometry`, mm; angles in the horizontal
plane are measured about the joint axis from +x (forward) toward +y):

* **Vertical stack** along the hinge axis (z up), bottom to top::

      parent lower lug | lower knuckle + stop tongue | cable window | tendon sector | parent upper lug

  The cable levels (:func:`swiftfin.layout.geometry.tendon_level_mm`) are spaced by one level pitch P starting at -P/2,
  the last joint lowest. Joint j's window holds the levels of the joints behind it (they cross its hinge
  line on the axis); its own pair of levels is just above, on the sector. The window spans
  [lowest level - hole radius - web, own lower level - r], the sector from there to own upper level + P/2, where
  r = P/2 (the last joint) or half the tube's OD (a joint with cables crossing below: the slot the sector swings
  in, cut in the parent's rear bulkhead with the sliding clearance, then keeps a web of two line widths above
  their tube bores; at P/2 it kept 0.15 mm, the wall probe, 2026-11-27). P is one pass-through hole
  plus a web of two line widths (:func:`swiftfin.layout.geometry.tendon_level_pitch_mm`); the window's floor and the blind pin
  bores' ends keep the same web from the nearest hole, so no skin thinner than two perimeters is left.
* **Hinge** (fastener records of :func:`swiftfin.layout.link_plan.link_fasteners`; holes cut by the registry): the
  cables cross the hinge line *on* the axis, so no pin can run through. Two short ISO 8734 dowels
  (``joints.pin_diameter_mm``): one from the parent's lower lug up into the lower knuckle, one from the upper lug
  down into the sector (the link's upper knuckle). Each pin is pressed into the link's blind bore (printed
  ``ream_stock_mm`` under the pin, not reamed: a 0.15 mm press) and turns in its lug's bore, printed under size
  too and reamed to H7 (radial play ``dowel(d).radial_play_mm()``, a few microns). **Alignment**: the link's two
  bores are in one part, both vertical as it prints, so every layer puts them at the same x-y: coaxial to the
  printer's repeatability. The lugs' two bores are in the parent's upper and lower halves: both are *through*
  bores (the insert pockets beyond them are wider than the pin), so with the halves joined on the seam's dowels and
  no link in, one reamer passes both in one pass; the dowels put the halves back on the same line after the link
  is in. **Retention**: a set screw in a heat-set insert in a boss on each lug's outer face closes the bore just
  beyond the pin's end; the pin cannot leave the link, the link cannot leave the lugs. Bores are vertical in the
  print orientation of every part (link upside down; halves cut face down), so no support inside a bore.
  Axial clearance between lugs and link: ``print.clearance_sliding_mm``.
* **Tendon sector**: a disc of radius ``R_s`` round the axis, cut away in front of the first angle the
  grooves need. Each cable's groove is a partial torus whose section (radius r_g = cable/2 + sliding
  clearance/2) has its root at ``m - cable/2``, so a seated cable's centre line runs at the moment arm
  ``m = joints.tendon_moment_arm_mm`` (the paper's d_mount). The groove starts at the tangent point of the
  route (:func:`swiftfin.layout.geometry.cable_routes`, last point) minus the stop angle minus 5 deg and wraps backward to
  the anchor at tangent + stop + 15 deg (clipped so it stays ahead of the child's bulkhead), where a radial
  hole leads the cable end to a vertical anchor hole (knot or crimp).
* **Pass-through holes** (PTFE tube OD + 2 sliding clearance) follow the cables of the joints behind
  (:func:`swiftfin.layout.joints.cable_crossings`): behind the axis a straight hole along the route's next segment
  (fixed in the link: toward the next hinge line or the next sector's tangent point, up to 24 deg off the body
  axis); ahead of it a fan of holes along the route's previous segment turned by every angle within the stop
  angle + 2 deg (that segment is fixed in the parent), one revolved solid (:func:`fan_cutter`). The arm is widened so the angled holes keep two perimeters
  to its sides; there is no window column ahead of the axis, so a small cap on the window's floor (under its
  ceiling) closes each pin bore with the same web (:func:`bore_caps`).
* **Hard stops**: a tongue of half-angle ``beta`` pointing forward on the lower knuckle; the parent carries
  two blocks on its lower lug whose radial faces lie at +/- (beta + theta_stop). The tongue's faces meet
  them when the joint reaches +/- ``swiftfin.layout.geometry.joint_stop_angles_rad(p)[j-1]``.
* **Flange**: a plate on the front face of the child's front bulkhead, held by four cap screws whose heads sit
  on its front face and whose threads go into heat-set inserts in the bulkhead (driven before the link goes into
  its parent's lugs: the tail is assembled from the peduncle forward). The rows sit where a driver's path runs
  clear of the link's own sector, at least the parent's stop-block radius from the axis, and the plate is cut away
  round the axis where the parent's lugs and blocks sweep; the link is trimmed at the bulkhead's face.
"""
from __future__ import annotations

import math


from swiftfin.cad.kernel import bd

from swiftfin.layout import geometry as L
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.schema import Params

from swiftfin.layout.joints import (  # noqa: F401  the numbers, re-exported for the part family
    BLOCK_SPAN_DEG, FLARE_EXTRA_DEG, GROOVE_LEAD_DEG, MIN_WRAP_MARGIN_DEG, TONGUE_HALF_DEG,
    WRAP_MARGIN_DEG, CableCrossing, JointHardware, all_joint_hardware, joint_hardware, joint_link_problems)
from swiftfin.layout.link_plan import link_fasteners  # noqa: F401


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


CRUMB_MM3 = 0.1
"""A solid of a boolean result smaller than this [mm^3] (a 1.1 mm length of one 0.45 x 0.2 mm extruded bead) is a
crumb the cuts left, not a piece: an empty shell of coincident faces, or a sliver of a shoulder where two cuts
nearly meet. A slicer drops it; so does :func:`one_solid`. Engineering default."""


def one_solid(shape, label: str) -> bd.Solid:
    """The single solid of a boolean result, or BuildError naming the part."""
    solids = shape.solids() if hasattr(shape, "solids") else [shape]
    if len(solids) > 1:     # crumbs the cuts left are not pieces
        solids = [s for s in solids if abs(s.volume) > CRUMB_MM3] or solids[:1]
    if len(solids) != 1:
        vols = sorted((s.volume for s in solids), reverse=True)
        raise BuildError(f"{label}: expected one solid, got {len(solids)} (volumes {[round(v, 1) for v in vols]})")
    return solids[0]


# ----------------------------------------------------------------------------------------------- solids
def turned(v, deg: float) -> tuple[float, float, float]:
    """Vector ``v`` turned by ``deg`` about +z."""
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


def fan_half_deg(h: JointHardware) -> float:
    """Half-angle of the fan an incoming cable (fixed in the parent) sweeps in the link's frame: the stop angle and
    FLARE_EXTRA_DEG more."""
    return h.stop_deg + FLARE_EXTRA_DEG


FAN_INSET_MM = 0.02
"""How much narrower than its rod, a side, the fan's revolved strip is (:func:`fan_cutter`) [mm]: enough that the
rods cross the strip's faces instead of touching them along a line, little enough to leave the cable (a fraction of
the hole) all its room. The exact tangencies (the end rods and the ball on the strip's faces, the straight hole's
end disc, 1 mm ahead of the pivot, on its floor) left a 700 mm design's joint_link_2 and joint_link_3 with meshes
that were not closed: sliver faces along the holes' floors, found at the end of its build (2026-12-07)."""
FAN_BALL_OVER_MM = 0.01
"""How much larger than the rod the ball at the fan's pivot is [mm]: the rods' end discs at the pivot (the fan's and
the straight hole behind the axis, :func:`cable_hole_cutters`) lie inside it instead of on it. Its caps stand this
far past the hole's radius over less than a square millimetre, under the wall probe's resolution."""


def fan_cutter(point, u, radius: float, length: float, half_deg: float) -> bd.Solid:
    """The hole a straight rod (``radius``, from ``point`` along unit ``u`` for ``length``) cuts while it turns
    about the vertical axis through ``point`` by +/- ``half_deg``: its section in its own vertical plane (a strip
    2 radius wide, cut at the turning axis) revolved through the whole fan, with the rod itself at both ends of
    the fan and a ball at the pivot. One revolved face instead of a union of many turned rods: the rods all meet
    at the pivot, and OpenCascade's booleans of near-coincident cylinders there shred the part."""
    px, py, pz = point
    hx, hy, v = u
    h = math.hypot(hx, hy)
    if h < 1e-6:       # a vertical rod turns on itself
        return rod(point, u, radius, length)
    er = (hx / h, hy / h)
    # the strip in (rho, z) about the pivot, clipped to rho >= eps (Sutherland-Hodgman on one edge): an edge on the
    # turning axis itself would revolve into degenerate faces; the ball covers the thin core left. The strip is
    # FAN_INSET_MM narrower than the rod a side, so the rods at the fan's ends and the ball cross its revolved faces
    # instead of touching them along a line: that tangency tessellated into a mesh that is not closed
    w = radius - FAN_INSET_MM
    quad = [(s * h - t * v, s * v + t * h) for s, t in ((0.0, -w), (length, -w), (length, w), (0.0, w))]
    eps = 0.05 * radius
    poly = []
    for (r0, z0), (r1, z1) in zip(quad, quad[1:] + quad[:1]):
        if r0 >= eps:
            poly.append((r0, z0))
        if (r0 >= eps) != (r1 >= eps):
            k = (r0 - eps) / (r0 - r1)
            poly.append((eps, z0 + k * (z1 - z0)))
    pts = [(px + r * er[0], py + r * er[1], pz + z) for r, z in poly]
    face = bd.Face(bd.Wire.make_polygon(pts, close=True))
    axis = bd.Axis((px, py, pz), (0, 0, 1))
    sweep = bd.Solid.revolve(face.rotate(axis, -half_deg), 2 * half_deg, axis)
    ends = [rod(point, turned(u, a), radius, length) for a in (-half_deg, half_deg)]
    ball = bd.Solid.make_sphere(radius + FAN_BALL_OVER_MM, angle1=-90, angle2=90, angle3=360,
                                plane=bd.Plane(origin=tuple(point)))
    return sweep.fuse(*ends, ball).clean()


def cable_hole_cutters(h: JointHardware) -> list[bd.Solid]:
    """Pass-through holes for the cables of the joints behind: straight along the outgoing segment (behind the
    axis, to past the flange) and a fan along the incoming one (ahead of the axis, to past the sector's rim)."""
    hr = h.hole_diameter_mm / 2
    out = []
    for cr in h.crossings:
        d = cr.dir_out
        length = (h.gap_half_mm + 1.0) / max(abs(d[0]), 1e-6) + 1.0
        out.append(rod(cr.point_mm, d, hr, length))      # from the pivot: its end disc inside the fan's ball
        u = cr.dir_in
        reach = (h.sector_radius_mm + 1.0) / max(math.hypot(u[0], u[1]), 0.2) + 0.5
        out.append(fan_cutter(cr.point_mm, u, hr, reach, fan_half_deg(h)))
    return out


def flange_solid(h: JointHardware) -> bd.Solid:
    """The plate on the child's bulkhead, cut away round the axis where the parent's lugs and blocks sweep."""
    x_back = h.x_mm - h.gap_half_mm
    w = h.flange_half_width_mm
    plate = box(x_back, x_back + h.flange_thickness_mm, -w, w, *h.flange_z_mm)
    return plate.cut(*[vcyl(h.x_mm, 0, r, z0, z1) for z0, z1, r in h.flange_keep_out_mm if z1 > z0])


CAP_PAST_WEB_MM = 0.2
"""A bore cap reaches this far past the bore's web into the pass-through hole's clearance, where the hole's cutter
trims it (see :func:`bore_caps`) [mm]."""


def bore_caps(p: Params, h: JointHardware) -> list[bd.Solid]:
    """Caps that keep the pins' bores blind. With no window column ahead of the axis, the lower bore (its cutter
    overruns the pin's end by ``BORE_OVERRUN_MM``) would open on the window's floor, and the upper one end less than a
    web above its ceiling. A disc over the bore stands on the floor (hangs from the ceiling) until the bore's end is
    a web of :data:`swiftfin.layout.geometry.MIN_WEB_LINES` line widths inside the material, and
    ``CAP_PAST_WEB_MM`` more: the nearest pass-through hole's edge may lie exactly a web beyond the bore's end, so
    the cap reaches into the hole's clearance and the hole's own cutters trim it (a cap face tangent or coplanar to
    a hole leaves an edge the mesh cannot close). Its radius stays ``CAP_PAST_WEB_MM`` inside the hole's, so no
    sliver stands beside a hole."""
    from swiftfin.layout.joints import BORE_OVERRUN_MM
    web = L.MIN_WEB_LINES * p.print.line_width_mm
    r = min(h.bore_radius_mm + web, h.hole_diameter_mm / 2 - CAP_PAST_WEB_MM)
    lower, upper = h.pins
    out = []
    if h.z_sector_lo_mm <= h.z_window_lo_mm:
        return out                                              # no window (the last joint): the bores end inside
    end = lower.inner_z_mm + BORE_OVERRUN_MM                    # the lower bore's end
    if end + web > h.z_window_lo_mm + 1e-9:
        out.append(vcyl(h.x_mm, 0.0, r, h.z_window_lo_mm - 0.5, end + web + CAP_PAST_WEB_MM))   # from in the knuckle
    end = upper.inner_z_mm - BORE_OVERRUN_MM
    if end - web < h.z_sector_lo_mm - 1e-9:
        out.append(vcyl(h.x_mm, 0.0, r, end - web - CAP_PAST_WEB_MM, h.z_sector_lo_mm + 0.5))  # to in the sector
    return out


def link_solid(p: Params, h: JointHardware) -> bd.Solid:
    """The link without its fastener holes (the pin bores and the flange inserts come from the records)."""
    x = h.x_mm
    g2 = h.gap_half_mm
    rk = h.knuckle_radius_mm
    z0, zw, zs, zt = h.z_knuckle_lo_mm, h.z_window_lo_mm, h.z_sector_lo_mm, h.z_sector_hi_mm
    x_back = x - g2
    big = 4 * h.sector_radius_mm
    # --- body
    parts = [vcyl(x, 0, rk, z0, zw),                                                   # lower knuckle
             pie(x, h.tongue_radius_mm, -h.tongue_half_deg, h.tongue_half_deg, z0, zw),  # stop tongue
             box(x_back, x, -h.arm_half_width_mm, h.arm_half_width_mm, zw, zt)]         # arm
    sector = vcyl(x, 0, h.sector_radius_mm, zs, zt)
    if h.sector_front_deg > 0:
        sector = sector.cut(pie(x, big, -h.sector_front_deg, h.sector_front_deg, zs - 1, zt + 1))
    parts += [sector, vcyl(x, 0, rk, zs, zt), flange_solid(h)]
    body = parts[0].fuse(*parts[1:]).clean()
    # --- cuts
    cuts = cable_hole_cutters(h)
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
    # one tool at a time: the fans' revolved faces in one multi-tool boolean came out empty (OCC 7.8), alone each
    # cuts as it should
    for c in cuts:
        body = body.cut(c)
    # the bores' caps, trimmed by the pass-through holes on their own and fused last (fused before the cuts, a
    # 3-joint design's link came out inside out)
    holes = cable_hole_cutters(h)
    for cap in bore_caps(p, h):
        for c in holes:
            cap = cap.cut(c)
        body = body.fuse(cap).clean()
    # trim at the child's bulkhead face
    body = isect(body, box(x_back, x + big, -big, big, min(z0, h.flange_z_mm[0]) - 1, max(zt, h.flange_z_mm[1]) + 1))
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
