"""Capstan spools as solids: one split spool per motor, on its shaft, in the body frame at rest (mm), built from
:func:`swiftfin.layout.spool_plan.spool_numbers` (what each dimension means, the split, the vernier of index holes,
the anchors and crimp seats: that module's docstring). The fasteners' holes (set screw, index screw) are cut by the
registry from :func:`swiftfin.layout.spool_plan.spool_fasteners`' records.
"""
from __future__ import annotations

import math
from dataclasses import replace

from swiftfin.cad.kernel import Axis, Edge, Face, Location, Plane, Solid, Wire

from swiftfin.catalogues.fasteners import fastener
from swiftfin.layout.spool_plan import SpoolNumbers, index_screw_record, spool_numbers
from swiftfin.cad.part import PartSpec
from swiftfin.core.schema import Params

CRIMP_SEAT_DEPTH_MM = 0.6
"""Depth of the counterbore that centres the upper crimp sleeve on the top face [mm]. Engineering default."""

PRINT_ROTATION = (180.0, 0.0, 0.0)
"""Both halves print upside down: the lower half on its split face, the upper half on its flange's top face."""


# ----------------------------------------------------------------------------------------------- solids
def _cyl(r: float, z0: float, z1: float) -> Solid:
    return Solid.make_cylinder(r, z1 - z0, Plane.XY.offset(z0))


def _radial_cyl(r: float, angle: float, r0: float, r1: float, z: float) -> Solid:
    """Cylinder of radius r along the ray at ``angle`` from radius r0 to r1, at height z."""
    d = (math.cos(angle), math.sin(angle), 0.0)
    origin = (r0 * d[0], r0 * d[1], z)
    return Solid.make_cylinder(r, r1 - r0, Plane(origin=origin, z_dir=d))


def _axial_cyl(r: float, at_r: float, angle: float, z0: float, z1: float) -> Solid:
    return Solid.make_cylinder(r, z1 - z0, Plane(origin=(at_r * math.cos(angle), at_r * math.sin(angle), z0)))


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


def _anchor_cutters(n: SpoolNumbers, side: int) -> list[Solid]:
    """The anchor of the left (side +1, up through the upper flange) or right (-1, down through the lower
    flange) cable: radial hole at the groove root, axial hole out of its half, crimp seat."""
    r = n.anchor_hole_diameter_mm / 2
    angle = n.anchor_angles_rad[0 if side > 0 else 1]
    z = n.anchor_z_mm[0 if side > 0 else 1]
    out = [_radial_cyl(r, angle, n.anchor_radius_mm, n.groove_centre_radius_mm + n.groove_radius_mm, z)]
    seat_r = n.crimp_seat_diameter_mm / 2
    if side > 0:
        top = n.upper_flange_z_mm[1]
        out.append(_axial_cyl(r, n.anchor_radius_mm, angle, z - 0.37 * r, top + 1))   # past the radial hole's axis
        seat_bottom = top - max(CRIMP_SEAT_DEPTH_MM, n.index_recess_mm + CRIMP_SEAT_DEPTH_MM)
        out.append(_axial_cyl(seat_r, n.anchor_radius_mm, angle, seat_bottom, top + 1))
    else:
        bottom = n.lower_flange_z_mm[0]
        out.append(_axial_cyl(r, n.anchor_radius_mm, angle, bottom - 1, z + 0.37 * r))
        # the crimp hangs below the lower flange in a channel down the hub's side
        out.append(_axial_cyl(seat_r, n.anchor_radius_mm, angle, n.hub_z_mm[0] - 1, bottom))
    return out


def _bore_cutter(n: SpoolNumbers, z0: float, z1: float, flat: bool) -> Solid:
    rod = _cyl(n.bore_radius_mm, z0 - 1, z1 + 1)
    if not flat:
        return rod
    half = Solid.make_box(2 * n.bore_radius_mm + 2, 4 * n.bore_radius_mm + 4, z1 - z0 + 4,
                          Plane.XY.offset(z0 - 2)).translate((n.flat_distance_mm, -2 * n.bore_radius_mm - 2, 0))
    return rod.cut(half).rotate(Axis.Z, math.degrees(n.set_screw_angle_rad))


def _set_screw_boss(n: SpoolNumbers) -> Solid:
    """The hub's boss for the set screw's insert: as wide as the hub, over the hub's height, from the axis out to
    its flat face (the registry cuts the insert's pocket from the fastener record)."""
    h = n.set_screw_boss_half_width_mm
    x1 = n.set_screw_boss_x_mm[1]
    z0, z1 = n.hub_z_mm
    box = Solid.make_box(x1, 2 * h, z1 - z0, Plane.XY.offset(z0)).translate((0.0, -h, 0))
    return box.rotate(Axis.Z, math.degrees(n.set_screw_angle_rad))


def _blank(n: SpoolNumbers) -> Solid:
    body = _cyl(n.hub_radius_mm, *n.hub_z_mm)
    for part in (_cyl(n.flange_radius_mm, *n.lower_flange_z_mm), _cyl(n.surface_radius_mm, *n.drum_z_mm),
                 _cyl(n.flange_radius_mm, *n.upper_flange_z_mm)):
        body = body.fuse(part)
    return body.clean()


def _index_cutters(n: SpoolNumbers, half: str) -> list[Solid]:
    """Every index hole but the one the index screw's record sits in (the registry cuts that one): the cutters of
    the same record moved to each hole, in the spool's own frame. The upper half also gets the ring its screw
    heads sink into, when they do."""
    from swiftfin.cad.fastening import head_cutters, seat_cutters
    base = index_screw_record(n)
    back = Location((-n.axis_xy_mm[0], -n.axis_xy_mm[1], -n.z_face_mm))
    out: list[Solid] = []
    angles = n.index_angles_upper_rad if half == "upper" else n.index_angles_lower_rad
    for a in angles[1:]:
        f = replace(base, head_mm=n.to_body(n.index_radius_mm, a, base.head_mm[2] - n.z_face_mm))
        for c in (head_cutters(f) if half == "upper" else seat_cutters(f)):
            out.append(c.moved(back))
    if half == "upper" and n.index_recess_mm > 0:
        cb = fastener(n.index_screw).counterbore_diameter_mm / 2
        top = n.upper_flange_z_mm[1]
        ring = _cyl(n.index_radius_mm + cb, top - n.index_recess_mm, top + 1).cut(
            _cyl(n.index_radius_mm - cb, top - n.index_recess_mm - 1, top + 2))
        out.append(ring)
    return out


def spool_solid(n: SpoolNumbers, half: str = "whole", *, groove: bool = True, anchors: bool = True,
                bore: bool = True, set_screw: bool = True, index: bool = True) -> Solid:
    """The spool in the body frame at rest: ``half`` = "lower" (``spool_<j>``), "upper" (``spool_<j>_upper``) or
    "whole" (both, fused: the envelope other parts keep clear of). The keywords leave features out (for the
    analytic tests); the fastener holes of :func:`spool_fasteners` records are not cut here (the registry cuts
    them), only the nut's drop slot and the index holes the records do not sit in."""
    if half == "whole":
        lo = spool_solid(n, "lower", groove=groove, anchors=anchors, bore=bore, set_screw=set_screw, index=index)
        up = spool_solid(n, "upper", groove=groove, anchors=anchors, bore=bore, set_screw=set_screw, index=index)
        return _one(lo.fuse(up).clean(), f"spool_{n.joint}")
    body = _blank(n)
    big = 2 * n.flange_radius_mm + 2
    if half == "lower":
        keep = Solid.make_box(big, big, n.split_z_mm - n.hub_z_mm[0] + 2, Plane.XY.offset(n.hub_z_mm[0] - 2))
        z_span = (n.hub_z_mm[0], n.split_z_mm)
    else:
        keep = Solid.make_box(big, big, n.upper_flange_z_mm[1] - n.split_z_mm + 2, Plane.XY.offset(n.split_z_mm))
        z_span = (n.split_z_mm, n.upper_flange_z_mm[1])
    if set_screw and half == "lower":
        body = body.fuse(_set_screw_boss(n)).clean()
    body = _one(body.intersect(keep.translate((-big / 2, -big / 2, 0))), f"spool_{n.joint} {half}")
    cutters: list[Solid] = []
    if groove:
        cutters.append(groove_cutter(n))
    if anchors:
        cutters += _anchor_cutters(n, +1 if half == "upper" else -1)
    if bore:
        cutters.append(_bore_cutter(n, *z_span, flat=half == "lower"))
    if index:
        cutters += _index_cutters(n, half)
    if cutters:
        body = body.cut(*cutters)
    label = f"spool_{n.joint}" + ("_upper" if half == "upper" else "")
    return _one(body, label).moved(Location((n.axis_xy_mm[0], n.axis_xy_mm[1], n.z_face_mm)))


def make_spools(p: Params) -> list[PartSpec]:
    """Two parts per motor (joint j), on its motor's shaft, link 0: ``spool_<j>`` (hub, lower half, right cable)
    and ``spool_<j>_upper`` (upper half, left cable), locked together by the index screw."""
    out = []
    for n in spool_numbers(p):
        meta = {"joint": n.joint, "wrap_between_leave_points_turns": n.wrap_between_rad / (2 * math.pi),
                "ridge_width_mm": n.ridge_width_mm}
        out.append(PartSpec(label=f"spool_{n.joint}", solid=spool_solid(n, "lower"), link=0, family="spool",
                            print_rotation=PRINT_ROTATION, meta=dict(meta, half="lower")))
        out.append(PartSpec(label=f"spool_{n.joint}_upper", solid=spool_solid(n, "upper"), link=0, family="spool",
                            print_rotation=PRINT_ROTATION, meta=dict(meta, half="upper")))
    return out
