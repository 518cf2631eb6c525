"""Capstan spools: one per motor, on its shaft, in the body frame at rest (mm).

Numbers first (:func:`spool_numbers`, built on :func:`swiftfin.layout.geometry.spool_dims`), solid second (:func:`spool_solid`).

The spool, from the motor face up: hub (bore with the shaft's D-flat, radial set screw onto the flat), lower
flange, grooved drum, upper flange. Interpretation of the parameters (see the module's notes in the report):

* The **cable centre line** winds at radius ``spool.drum_diameter_mm / 2``: that is the radius the layout's cable
  routes leave the drum at and the moment arm the physics uses. The groove root lies one cable radius inside
  it, the drum surface ``spool.groove_depth_mm`` above the root (``SpoolDims.drum_radius_mm`` for the default,
  where the depth is half the cable). The groove section is a circle of diameter
  ``cable.diameter_mm + print.clearance_sliding_mm`` resting on the root.
* The groove is a **right-handed helix** (z rises counter-clockwise seen from above), so the pull-pull cable,
  leaving the drum on both sides toward the tail, wraps between its two leave points (friction capstan,
  paper §2.3.1): the left (+y) cable leaves from the upper end of the wrapped region, the right one from
  the lower end. The groove runs ``groove_turns`` turns centred on the cable plane: ``wraps`` between the
  leave points plus the joint's travel and margin at both ends, as :func:`swiftfin.layout.geometry.spool_dims` sizes it.
* **Anchors.** Each cable end (left and right piece of the pull-pull pair) is wound from its leave point
  toward the middle of the wrapped region, where it dives into a radial hole at the groove root and leaves
  the spool through an axial hole up through the upper flange, to be knotted (or crimped) on its top face,
  where both knots can be reached with the spool on its motor. The ends of the groove stay free for the
  travel: an anchor there would sit where the other cable's turns run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from swiftfin.cad.kernel import Axis, Edge, Face, Location, Plane, Solid, Wire

from swiftfin.cad.bought import pilot_hole_diameter_mm
from swiftfin.layout.geometry import cable_routes, motor_placements, spool_dims, spool_travel_turns
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params

HUB_WALL_SET_SCREWS = 1.5
"""Hub wall (bore to outside) / set screw diameter [-]: 4.5 mm of thread for an M3 set screw.
Engineering default."""

PRINT_ROTATION = (180.0, 0.0, 0.0)
"""Print upside down: the upper flange's flat face on the bed, the hub on top (its overhang is the lower
flange's rim, ``spool.flange_height_mm`` wide; the hub-down way would add the flange's whole underside)."""


@dataclass(frozen=True)
class SpoolNumbers:
    """Everything the spool solid is built from, in the spool's own frame: z up the shaft from the motor's
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
    pitch_radius_mm: float      # cable centre line
    root_radius_mm: float       # groove bottom
    surface_radius_mm: float    # drum surface between the groove turns
    groove_radius_mm: float     # radius of the groove's circular section
    groove_centre_radius_mm: float
    groove_pitch_mm: float
    groove_turns: float
    cable_plane_mm: float       # groove (and wrap) centre height
    groove_start_angle_rad: float  # angle of the lower end of the groove helix
    leave_angles_rad: tuple[float, float]   # (left, right) cable leave points
    wrap_between_rad: float     # angle of groove between the two leave points
    anchor_hole_diameter_mm: float
    anchor_radius_mm: float     # radius of the axial part of the anchor holes
    anchor_angles_rad: tuple[float, float]  # (left, right) radial part of the anchor holes
    bore_radius_mm: float
    flat_distance_mm: float     # from the axis to the bore's flat; the flat faces +x
    set_screw_hole_diameter_mm: float
    set_screw_z_mm: float

    def helix_z_mm(self, angle_rad: float) -> float:
        """Height of the groove centre at ``angle`` on the turn through the cable plane's neighbourhood."""
        mid = self.groove_start_angle_rad + math.pi * self.groove_turns
        return self.cable_plane_mm + self.groove_pitch_mm * (angle_rad - mid) / (2 * math.pi)


def _wrap_angle(leave_left: float, leave_right: float, wraps: float) -> float:
    """Clockwise angle from the left leave point to the right one: of the candidates (base + k turns) the one
    nearest ``wraps`` turns, the smaller on a tie (it leaves more groove for the travel)."""
    base = (leave_left - leave_right) % (2 * math.pi)
    k = max(math.ceil(wraps - base / (2 * math.pi) - 0.5 - 1e-9), 0)
    return base + 2 * math.pi * k


def spool_numbers(p: Params) -> tuple[SpoolNumbers, ...]:
    """The numbers of every spool (index j-1 for joint j). Raises UserError if the spool has no room for its hub."""
    d = spool_dims(p)
    s, m, pr = p.spool, p.motor, p.print
    routes = cable_routes(p)
    out = []
    for mp in motor_placements(p):
        left = next(r for r in routes if r.joint == mp.joint and r.side == +1).points_mm[0]
        right = next(r for r in routes if r.joint == mp.joint and r.side == -1).points_mm[0]
        phi_l = math.atan2(left[1], left[0] - mp.x_mm)
        phi_r = math.atan2(right[1], right[0] - mp.x_mm)
        wrap = _wrap_angle(phi_l, phi_r, s.wraps)
        phi_mid = phi_l - wrap / 2
        spare = (d.groove_turns - wrap / (2 * math.pi)) / 2
        travel = spool_travel_turns(p, mp.joint)
        if spare < travel - 1e-9:
            raise UserError(
                f"spool_{mp.joint + 1}: the cable leaves the drum {wrap / (2 * math.pi):.2f} turns apart on its two "
                f"sides, leaving {spare:.2f} turns of groove at each end for {travel:.2f} turns of travel: raise "
                f"spool.groove_margin_turns or change spool.wraps = {s.wraps:g}")
        pitch_r = s.drum_diameter_mm / 2
        root_r = pitch_r - p.cable.diameter_mm / 2
        surf_r = root_r + s.groove_depth_mm
        g_r = (p.cable.diameter_mm + pr.clearance_sliding_mm) / 2
        hole_d = p.cable.diameter_mm + 2 * pr.clearance_sliding_mm
        anchor_r = root_r - hole_d / 2 - pr.line_width_mm
        bore_r = (m.shaft_diameter_mm + pr.clearance_sliding_mm) / 2
        hub_r = bore_r + HUB_WALL_SET_SCREWS * s.set_screw_diameter_mm
        if anchor_r - hole_d / 2 < bore_r + pr.line_width_mm:
            raise UserError(
                f"spool_{mp.joint + 1}: spool.drum_diameter_mm = {s.drum_diameter_mm:g} leaves no room for the "
                f"cable anchor holes ({hole_d:.2f} mm) between the groove root (radius {root_r:.2f} mm) and the "
                f"{2 * bore_r:.2f} mm shaft bore: needs a drum of at least "
                f"{2 * (bore_r + 2 * pr.line_width_mm + hole_d + p.cable.diameter_mm / 2):.2f} mm")
        z0 = d.hub_bottom_mm
        z1 = z0 + d.hub_length_mm
        z2 = z1 + d.flange_mm
        z3 = z2 + d.groove_length_mm
        eps = hole_d / root_r
        out.append(SpoolNumbers(
            joint=mp.joint + 1, axis_xy_mm=(mp.x_mm, 0.0), z_face_mm=mp.z_face_mm,
            hub_radius_mm=hub_r, hub_z_mm=(z0, z1), flange_radius_mm=d.flange_radius_mm,
            lower_flange_z_mm=(z1, z2), drum_z_mm=(z2, z3), upper_flange_z_mm=(z3, z3 + d.flange_mm),
            pitch_radius_mm=pitch_r, root_radius_mm=root_r, surface_radius_mm=surf_r, groove_radius_mm=g_r,
            groove_centre_radius_mm=root_r + g_r, groove_pitch_mm=s.groove_pitch_mm, groove_turns=d.groove_turns,
            cable_plane_mm=d.cable_plane_mm, groove_start_angle_rad=phi_mid - math.pi * d.groove_turns,
            leave_angles_rad=(phi_l, phi_r), wrap_between_rad=wrap, anchor_hole_diameter_mm=hole_d,
            anchor_radius_mm=anchor_r, anchor_angles_rad=(phi_mid + eps, phi_mid - eps),
            bore_radius_mm=bore_r,
            flat_distance_mm=m.shaft_diameter_mm / 2 - m.shaft_flat_depth_mm + pr.clearance_sliding_mm / 2,
            set_screw_hole_diameter_mm=pilot_hole_diameter_mm(s.set_screw_diameter_mm),
            set_screw_z_mm=(z0 + z1) / 2))
    return tuple(out)


# ----------------------------------------------------------------------------------------------- solids
def _cyl(r: float, z0: float, z1: float) -> Solid:
    return Solid.make_cylinder(r, z1 - z0, Plane.XY.offset(z0))


def _radial_cyl(r: float, angle: float, r0: float, r1: float, z: float) -> Solid:
    """Cylinder of radius r along the ray at ``angle`` from radius r0 to r1, at height z."""
    d = (math.cos(angle), math.sin(angle), 0.0)
    origin = (r0 * d[0], r0 * d[1], z)
    return Solid.make_cylinder(r, r1 - r0, Plane(origin=origin, z_dir=d))


def groove_cutter(n: SpoolNumbers) -> Solid:
    """The groove: a circle swept along the helix, clipped to the drum cylinder (what the groove removes)."""
    height = n.groove_pitch_mm * n.groove_turns
    z_start = n.cable_plane_mm - height / 2
    helix = Edge.make_helix(n.groove_pitch_mm, height, n.groove_centre_radius_mm, center=(0, 0, z_start))
    helix = helix.rotate(Axis.Z, math.degrees(n.groove_start_angle_rad))
    start = helix.position_at(0)
    section = Face(Wire.make_circle(n.groove_radius_mm, Plane(origin=start, z_dir=helix.tangent_at(0))))
    tube = Solid.sweep(section, helix, is_frenet=True)
    margin = 2 * n.groove_radius_mm + 1
    clip = _cyl(n.surface_radius_mm, z_start - margin, z_start + height + margin)
    return _one(tube.intersect(clip), "groove")


def _one(shape, what: str) -> Solid:
    solids = shape.solids()
    if len(solids) != 1:
        raise RuntimeError(f"{what}: expected one solid, got {len(solids)}")
    return solids[0]


def _anchor_cutters(n: SpoolNumbers) -> list[Solid]:
    r = n.anchor_hole_diameter_mm / 2
    out = []
    for angle in n.anchor_angles_rad:
        z = n.helix_z_mm(angle)
        radial = _radial_cyl(r, angle, n.anchor_radius_mm, n.groove_centre_radius_mm + n.groove_radius_mm, z)
        ax, ay = n.anchor_radius_mm * math.cos(angle), n.anchor_radius_mm * math.sin(angle)
        z_start = z - 0.37 * r   # past the radial hole's axis: no tangent faces
        axial = Solid.make_cylinder(r, n.upper_flange_z_mm[1] + 1 - z_start, Plane(origin=(ax, ay, z_start)))
        out += [radial, axial]
    return out


def _bore_cutter(n: SpoolNumbers) -> Solid:
    z0, z1 = n.hub_z_mm[0] - 1, n.upper_flange_z_mm[1] + 1
    rod = _cyl(n.bore_radius_mm, z0, z1)
    half = Solid.make_box(2 * n.bore_radius_mm + 2, 4 * n.bore_radius_mm + 4, z1 - z0 + 2,
                          Plane.XY.offset(z0 - 1)).translate((n.flat_distance_mm, -2 * n.bore_radius_mm - 2, 0))
    return rod.cut(half)


def spool_solid(n: SpoolNumbers, *, groove: bool = True, anchors: bool = True, bore: bool = True,
                set_screw: bool = True) -> Solid:
    """The spool in the body frame at rest. The keywords leave features out (for the analytic tests)."""
    body = _cyl(n.hub_radius_mm, *n.hub_z_mm)
    for part in (_cyl(n.flange_radius_mm, *n.lower_flange_z_mm), _cyl(n.surface_radius_mm, *n.drum_z_mm),
                 _cyl(n.flange_radius_mm, *n.upper_flange_z_mm)):
        body = body.fuse(part)
    body = body.clean()
    cutters: list[Solid] = []
    if groove:
        cutters.append(groove_cutter(n))
    if anchors:
        cutters += _anchor_cutters(n)
    if bore:
        cutters.append(_bore_cutter(n))
    if set_screw:
        cutters.append(_radial_cyl(n.set_screw_hole_diameter_mm / 2, 0.0, 0.0, n.hub_radius_mm + 1, n.set_screw_z_mm))
    if cutters:
        body = body.cut(*cutters)
    return _one(body, f"spool_{n.joint}").moved(Location((n.axis_xy_mm[0], n.axis_xy_mm[1], n.z_face_mm)))


def make_spools(p: Params) -> list[PartSpec]:
    """One ``spool_<j>`` per motor (joint j), on its motor's shaft, link 0."""
    out = []
    for n in spool_numbers(p):
        out.append(PartSpec(label=f"spool_{n.joint}", solid=spool_solid(n), link=0, family="spool",
                            print_rotation=PRINT_ROTATION,
                            meta={"joint": n.joint,
                                  "wrap_between_leave_points_turns": n.wrap_between_rad / (2 * math.pi)}))
    return out
