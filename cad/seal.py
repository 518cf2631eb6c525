"""The seam gasket: what seals the head's lid (the upper halves) to its belly pan (the lower halves) (issue 13: "an
openable closure ... whose bolt pattern gives the seal its squeeze").

**The arrangement, and why** (the README's *The dry compartment* gives the measurements behind it). The drive stands
3-6 mm from the head's inner wall at the seam plane, so a face O-ring (its groove and lands reach about 8 mm in from
the skin) cannot pass it: tried, it blocks the assembly. What fits the wall itself is a flat gasket: the lower halves
of the sealed pieces stop :func:`swiftfin.layout.hull_plan.seam_gasket_gap_mm` below the seam plane, and a sheet of
closed-cell silicone sponge, die-cut to the seam face the two halves leave between them (the rim, the rear wall's
section, the seam columns' discs, the nose), fills the gap. The seam screws pass through it, each in a brass
compression limiter (catalogues/seals.toml ``[compression_limiter]``) as long as the gap: the screws pull the faces
onto the limiters, so the sheet's compression is the sheet's thickness less the limiter's length whatever the
screws' torque, in the middle of the sheet's band. The splice between the head's front and rear pieces is bonded
(``bonded_seam``): the lid and the pan are each one bonded piece, opened at the gasket only.

**The part** (:func:`seam_gasket_part`): the slab of the sealed pieces' own solids between the gap's faces (made by
the hull family, which has those solids), less a hole round each seam screw's limiter and each seam dowel
(:func:`gasket_holes`). It is a bought part (``printed=False``, family ``seal``): its outline goes to the builder
as a drawing (:func:`swiftfin.exports.gasket.gasket_outline_svg`), its mass is the sponge's plus the limiters'. Its
solid is the gasket compressed in place, so it touches both halves (a declared contact, cad/assembly.py).

**The numbers** (:func:`swiftfin.exports.gasket.gasket_numbers`, the findings ``seal.seam_gasket_*`` of every
build): the compression at the gap's extremes (the limiter's length +/- its cutting tolerance, each printed face +/- ``limits.print_tolerance_mm``
flat), against the sheet's band; the contact stress at the least compression against the water's pressure at the
design depth times the safety factor; the sealing ring's narrowest strip (the widest disc that travels all round the
ring between the outline and the cavity) against the sheet's least strip; and the least web of sponge a hole leaves
to an edge.
"""
from __future__ import annotations

import math

from swiftfin.cad.kernel import bd
from swiftfin.cad.link import one_solid, rod
from swiftfin.cad.part import PartSpec
from swiftfin.catalogues.seals import compression_limiter, seam_gasket
from swiftfin.core.schema import Params
from swiftfin.layout.hull_plan import HullPiece, seam_features, seam_gasket_gap_mm

GASKET_LABEL = "seam_gasket"
"""The head's (link 0's) gasket; a sealed link behind it (``hull.flooded_from_joint`` > 1) has its own,
``seam_gasket_<link>`` (:func:`gasket_label`)."""


def gasket_label(link: int) -> str:
    return GASKET_LABEL if link == 0 else f"{GASKET_LABEL}_{link}"
HOLE_DIAMETRAL_CLEARANCE_MM = 0.4
"""A die-cut hole round a limiter is this much wider than it, so the limiter stands free and no sponge is trapped
under it: a steel-rule die places a hole in soft sponge to about +/- 0.2 mm (engineering default). A dowel's hole is
the dowel's own diameter: the sponge closes round the pin, so the dowels locate the gasket on the lower halves while
the drive and the lid go in."""


def gasket_holes(p: Params, pieces) -> list[tuple[str, float, float, float]]:
    """(label, x, y, radius) of every hole the gasket has: one round each seam screw's limiter, with
    :data:`HOLE_DIAMETRAL_CLEARANCE_MM`, and one the size of each seam dowel of the sealed pieces (mm, body frame)."""
    lim = compression_limiter()
    out = []
    for pc in pieces:
        for f in seam_features(p, pc):
            d = (lim.outer_diameter_mm + HOLE_DIAMETRAL_CLEARANCE_MM if f.kind == "screw"
                 else p.hull.seam_dowel_diameter_mm)
            out.append((f"{pc.name}_{f.kind}_{'p' if f.side > 0 else 'm'}y_{f.index + 1}", -f.s_mm, f.y_mm, d / 2))
    return out


def seam_face_area_mm2(solid) -> float:
    """The gasket's area: its planar faces in the seam plane (z = 0, facing up), summed. Exact on the B-rep, where
    OpenCascade's default volume integration is 3 % off on this thin slab of lofted skin."""
    return float(sum(f.area for f in solid.faces()
                     if abs(f.normal_at().Z - 1.0) < 1e-9 and abs(f.center().Z) < 1e-6))


def seam_gasket_part(p: Params, slabs: list[tuple[HullPiece, bd.Shape]]) -> PartSpec:
    """The seam gasket of one sealed link's pieces (see the module docstring): ``slabs`` are (piece, the slab of its
    solid between the gap's faces)."""
    pieces = [pc for pc, _ in slabs]
    gap = max(seam_gasket_gap_mm(p, pc) for pc in pieces)
    body = slabs[0][1]
    if len(slabs) > 1:
        body = body.fuse(*[s for _, s in slabs[1:]]).clean()
    holes = gasket_holes(p, pieces)
    body = body.cut(*[rod((x, y, -gap - 1.0), (0, 0, 1), r, gap + 2.0) for _, x, y, r in holes])
    label = gasket_label(min(pc.link for pc in pieces))
    solid = one_solid(body, label)
    sheet, lim = seam_gasket(), compression_limiter()
    n_screws = sum(1 for f in (f for pc in pieces for f in seam_features(p, pc)) if f.kind == "screw")
    area_mm2 = seam_face_area_mm2(solid)
    sponge_kg = sheet.density_kg_m3 * area_mm2 * sheet.sheet_thickness_mm * 1e-9
    limiters_kg = n_screws * lim.mass_kg(gap)
    return PartSpec(label, solid, min(pc.link for pc in pieces), "seal", printed=False,
                    mass_kg=sponge_kg + limiters_kg, meta={
                        "source": "catalogues/seals.toml [seam_gasket] density x the sheet's volume, and "
                                  "[compression_limiter] x the seam screws",
                        "gap_mm": gap, "area_mm2": area_mm2, "sponge_kg": sponge_kg, "limiters_kg": limiters_kg,
                        "pieces": tuple(pc.name for pc in pieces), "screws": n_screws, "holes": tuple(holes),
                        "bom_item": "Seam gasket, die-cut",
                        "bom_spec": (f"{sheet.sheet} cut to parts/{label}.svg ({area_mm2 / 100:.1f} cm^2, "
                                     f"{sponge_kg * 1000:.2f} g), {len(holes)} holes"),
                        "bom": [{"item": "Compression limiter",
                                 "spec": f"{lim.tube}, cut {gap:.2f} +/- {lim.length_tolerance_mm:g} mm",
                                 "quantity": n_screws, "where": "round each seam screw of "
                                 + ", ".join(pc.name for pc in pieces) + ", in the gasket's holes",
                                 "source": "catalogues/seals.toml [compression_limiter]"}] + _splice_bonds(p, pieces)})


SPLICE_GLUE_LINE_MM = 0.2
"""Epoxy's line on a splice's faces [mm] (gap-filling epoxy on sanded faces: 0.1-0.3 mm)."""


def _splice_bonds(p: Params, pieces) -> list[dict]:
    """The bill's line for the epoxy that bonds the sealed pieces' splices (``bonded_seam``): the shell's ring at
    each cut times :data:`SPLICE_GLUE_LINE_MM`, the tabs' and pads' faces besides, rounded up to 0.1 mL."""
    from swiftfin.catalogues.adhesives import adhesive
    from swiftfin.layout.hull_plan import hull_section_semi_axes_mm, splice_joint
    names = {pc.name for pc in pieces}
    cuts = [splice_joint(p, pc).s_cut_mm for pc in pieces if pc.rear_cut]
    if not cuts:
        return []
    w = p.hull.wall_thickness_mm
    ring = sum(math.pi * (a * b - (a - w) * (b - w)) for a, b in (hull_section_semi_axes_mm(p, s) for s in cuts))
    ml = math.ceil(4 * ring * SPLICE_GLUE_LINE_MM / 100) / 10
    glue = adhesive("epoxy_sanded_pla")
    return [{"item": "Adhesive", "spec": glue.description, "quantity": ml, "unit": "mL",
             "where": (f"the splice{'s' if len(cuts) > 1 else ''} of {', '.join(sorted(names))} (both halves): bonded "
                      "so that the lid and the belly pan are one piece each and the gasket is the only seam opened"),
             "source": "catalogues/seals.toml [bonded_seam]; the faces' area x a 0.2 mm line, x 4 for the tabs"}]
