"""Bought parts as simple solids with catalogue masses: the stepper motors and the components of
``params.components`` (battery, electronics, ...). Body frame at rest, mm; ``printed=False``.

Cable and PTFE tube are not solids here (they have no fixed shape at rest worth a STEP file); their mass
belongs to whoever sums the cable lengths (``swiftfin.layout.geometry.cable_routes``).
"""
from __future__ import annotations

from swiftfin.cad.kernel import Plane, Polygon, Solid, extrude

from swiftfin.layout.flotation_plan import FoamBlock, foam_block_size_mm, foam_blocks
from swiftfin.layout.geometry import motor_placements
from swiftfin.cad.part import PartSpec
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

MOTOR_CORNER_CHAMFER_FRACTION = 0.1
"""Leg of the 45 deg chamfer on the frame's four long edges / frame size [-]. NEMA 17 drawings (17HS4401:
42.3 mm frame, ~4-5 mm chamfers) give about 0.1."""

PILOT_HOLE_FRACTION = 0.85
"""Pilot hole for a self-tapping (thread-forming) screw in printed PLA / nominal diameter [-].
ISO 261 tap drills are 0.80-0.84 x d (M2 1.6, M3 2.5); printed holes come out ~0.1 mm under size, so 0.85."""


def pilot_hole_diameter_mm(screw_diameter_mm: float) -> float:
    """Hole a screw of nominal ``screw_diameter_mm`` cuts its own thread in (printed plastic)."""
    return PILOT_HOLE_FRACTION * screw_diameter_mm


def motor_solid(p: Params, x_mm: float, z_face_mm: float) -> Solid:
    """NEMA frame (chamfered square prism below the face), pilot boss and D-flat shaft above it, axis (x, 0)."""
    m = p.motor
    h, c = m.frame_size_mm / 2, MOTOR_CORNER_CHAMFER_FRACTION * m.frame_size_mm
    octagon = Polygon((h - c, -h), (h, -h + c), (h, h - c), (h - c, h), (-h + c, h), (-h, h - c), (-h, -h + c),
                      (-h + c, -h), align=None)
    frame = extrude(octagon, m.body_length_mm).solids()[0].translate((0, 0, -m.body_length_mm))
    r = m.shaft_diameter_mm / 2
    shaft = Solid.make_cylinder(r, m.shaft_length_mm)
    if m.shaft_flat_depth_mm > 0:
        shaft = shaft.cut(Solid.make_box(r, 2 * r + 2, m.shaft_length_mm + 2).translate(
            (r - m.shaft_flat_depth_mm, -r - 1, -1)))
    body = frame.fuse(shaft)
    if m.pilot_height_mm > 0:
        body = body.fuse(Solid.make_cylinder(m.pilot_diameter_mm / 2, m.pilot_height_mm))
    body = body.clean().solids()[0]
    return body.translate((x_mm, 0.0, z_face_mm))


def foam_solid(p: Params, blk: FoamBlock):
    """The block: a ruled loft between its two end sections, less the vertical notches about the joint axes."""
    from swiftfin.cad.kernel import bd
    wires = []
    for s in (blk.s0_mm, blk.s1_mm):
        yz = blk.section_yz_mm(p, s)
        wires.append(bd.Wire.make_polygon([bd.Vector(-s, float(y), float(z)) for y, z in yz], close=True))
    body = bd.Solid.make_loft(wires, ruled=True)
    height = blk.z_top_mm - blk.z_floor_mm + 4.0
    for s_axis, r in blk.notches:
        cyl = bd.Solid.make_cylinder(r, height).translate((-s_axis, 0.0, blk.z_floor_mm - 2.0))
        body = body.cut(cyl)
    solids = body.solids()
    if len(solids) != 1:
        raise BuildError(f"{blk.label}: the notches about the joint axes split the foam block in {blk.piece} into "
                         f"{len(solids)} pieces")
    return solids[0]


def make_foam_blocks(p: Params) -> list[PartSpec]:
    """The flotation blocks of :func:`swiftfin.layout.flotation_plan.foam_blocks`, bought foam cut to shape."""
    out = []
    rho = p.environment.foam_density_kg_m3
    for blk in foam_blocks(p):
        solid = foam_solid(p, blk)
        mass = rho * solid.volume * 1e-9
        ln, w, h = foam_block_size_mm(p, blk)
        out.append(PartSpec(label=blk.label, solid=solid, link=blk.link, family="bought", printed=False,
                            mass_kg=mass, meta={
                                "source": "environment.foam_density_kg_m3 x the block's volume "
                                          "(layout/flotation_plan.py)",
                                "glued_to": blk.glued_to,
                                "bom_item": "Flotation foam block, closed-cell (e.g. PVC foam H100)",
                                "bom_spec": (f"cut from {ln:.0f} x {w:.0f} x {h:.0f} mm (L x W x H), "
                                             f"{solid.volume / 1000:.1f} cm^3, {mass * 1000:.1f} g; glued into "
                                             f"{blk.glued_to} under the cables")}))
    return out


def make_bought_parts(p: Params) -> list[PartSpec]:
    """``motor_<j>`` at each motor placement, one box per component (all on link 0), then the flotation blocks
    (on their flooded links); none printed."""
    out = []
    for mp in motor_placements(p):
        out.append(PartSpec(label=f"motor_{mp.joint + 1}", solid=motor_solid(p, mp.x_mm, mp.z_face_mm), link=0,
                            family="bought", printed=False, mass_kg=p.motor.mass_kg,
                            meta={"joint": mp.joint + 1, "source": "motor.mass_kg (17HS4401 datasheet)"}))
    for comp in p.components:
        sx, sy, sz = comp.size_mm
        x = -comp.station_fraction * p.body.length_mm
        box = Solid.make_box(sx, sy, sz, Plane.XY).translate((x - sx / 2, -sy / 2, comp.z_mm - sz / 2))
        out.append(PartSpec(label=comp.name, solid=box, link=0, family="bought", printed=False,
                            mass_kg=comp.mass_kg, meta={"source": comp.source or "params.components"}))
    return out + make_foam_blocks(p)
