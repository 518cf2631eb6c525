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
  [lowest level - hole radius - web, own lower level - P/2], the sector the next 2P. P is one pass-through hole
  plus a web of two line widths (:func:`swiftfin.layout.geometry.tendon_level_pitch_mm`); the window's floor and the blind pin
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
  route (:func:`swiftfin.layout.geometry.cable_routes`, last point) minus the stop angle minus 5 deg and wraps backward to
  the anchor at tangent + stop + 15 deg (clipped so it stays ahead of the child's bulkhead), where a radial
  hole leads the cable end to a vertical anchor hole (knot or crimp).
* **Pass-through holes**: for the cables of the joints behind, at their levels on the hinge line: straight
  holes (PTFE tube OD + 2 sliding clearance) along -x behind the axis (fixed in the child's frame), and a
  horizontal wedge ahead of the axis that opens by the stop angle + 2 deg to each side, because the
  incoming cable is fixed in the parent's frame.
* **Hard stops**: a tongue of half-angle ``beta`` pointing forward on the lower knuckle; the parent carries
  two blocks on its lower lug whose radial faces lie at +/- (beta + theta_stop). The tongue's faces meet
  them when the joint reaches +/- ``swiftfin.layout.geometry.joint_stop_angles_rad(p)[j-1]``.
* **Flange**: a plate on the front face of the child's front bulkhead, with four bolt holes (hull screws,
  ``hull.screw_diameter_mm``); the link is trimmed at that face, so nothing of it enters the child.
"""
from __future__ import annotations

import math


from swiftfin.cad.kernel import bd

from swiftfin.layout import geometry as L
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.schema import Params

from swiftfin.layout.joints import (  # noqa: F401  the numbers, re-exported for the part family
    BLOCK_SPAN_DEG, FLARE_EXTRA_DEG, GROOVE_LEAD_DEG, MIN_WRAP_MARGIN_DEG, TONGUE_HALF_DEG, WRAP_MARGIN_DEG,
    JointHardware, all_joint_hardware, joint_hardware, joint_link_problems)


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
