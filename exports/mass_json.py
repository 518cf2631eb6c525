"""The mass report as JSON: ``mass_properties.json``, every part, link and the whole fish, in SI units.

:func:`report_to_dict` turns a :class:`swiftfin.exports.massprops.MassReport` into plain JSON types (floats are
written by ``json`` with ``repr``, all digits), with the frames, the print settings, the uncertainty box of the
ranges and the buoyancy and trim summary. The trim dict goes through the project's one JSON helper,
:func:`swiftfin.core.jsonable.jsonable`.
"""
from __future__ import annotations

import numpy as np

from swiftfin.core.jsonable import jsonable
from swiftfin.core.schema import Params
from swiftfin.exports.inertia import Inertial
from swiftfin.physics.hydrostatics import static_pitch_deg

PAPER_MASS_KG = 1.2          # SwiftFin paper, Table 2


# ----------------------------------------------------------------------------------------------- JSON
def _inertial_dict(it: Inertial, frame: str) -> dict:
    I = it.inertia
    return {"mass_kg": it.mass_kg, "com_m": list(it.com_m), "frame": frame,
            "inertia_kg_m2": {"ixx": I[0, 0], "iyy": I[1, 1], "izz": I[2, 2],
                              "ixy": I[0, 1], "ixz": I[0, 2], "iyz": I[1, 2]},
            "principal_moments_kg_m2": np.linalg.eigvalsh(I).tolist()}


def report_to_dict(params: Params, report) -> dict:
    """Everything, as plain JSON types; floats are written by ``json`` with ``repr`` (all digits).

    ``report``: a :class:`swiftfin.exports.massprops.MassReport` (not imported here: massprops imports this).
    """
    pr = params.print
    d = {
        "units": "SI (kg, m, kg m^2, N); inertia about the centre of mass",
        "frames": "body frame: origin at the nose, +x forward, +z up (layout/geometry.py); link frames: origin on the "
                  "link's joint axis at z = 0 (head: the nose), axes parallel to the body frame at rest",
        "print_settings": {"perimeters": pr.perimeters, "line_width_mm": pr.line_width_mm,
                           "layer_height_mm": pr.layer_height_mm, "top_layers": pr.top_layers,
                           "bottom_layers": pr.bottom_layers, "infill_fraction": pr.infill_fraction,
                           "infill_pattern": pr.infill_pattern,
                           "filament_density_kg_m3": pr.filament_density_kg_m3,
                           "wall_mm": report.print_model.wall_mm, "top_mm": report.print_model.top_mm,
                           "bottom_mm": report.print_model.bottom_mm},
        "uncertainty_for_ranges": report.uncertainty,
        "parts": [], "links": [],
    }
    for pt in report.parts:
        e = {"label": pt.label, "link": pt.link, "family": pt.family, "printed": pt.printed, "method": pt.method,
             "flags": list(pt.flags), "volume_solid_m3": pt.volume_solid_m3, "volume_core_m3": pt.volume_core_m3,
             "volume_material_m3": pt.volume_material_m3}
        e.update(_inertial_dict(pt.inertial, "body"))
        d["parts"].append(e)
    for k, (lk, V, cob) in enumerate(zip(report.links, report.link_displaced_volume_m3, report.link_cob_m)):
        e = {"index": lk.index, "name": lk.name, "origin_m": list(lk.origin_m), "parts": list(lk.parts),
             "flooded": bool(report.link_flooded[k]) if report.link_flooded else False,
             "displaced_volume_m3": V, "cob_m_body": list(cob), "com_m_body": lk.com_body_m.tolist()}
        e.update(_inertial_dict(lk.inertial, f"link {lk.name}"))
        e["ranges"] = lk.ranges
        w = report.link_entrained_water[k] if report.link_entrained_water else None
        if w is not None:
            e["entrained_water"] = {**_inertial_dict(w.shifted(lk.origin_m), f"link {lk.name}"),
                                    "note": "water inside the flooded segments, moving with the link: inertia in "
                                            "water (the MJCF adds it), neutrally buoyant"}
        d["links"].append(e)
    g = params.environment.gravity_m_s2
    d["total"] = {**_inertial_dict(report.total, "body"),
                  "paper_mass_kg": PAPER_MASS_KG,
                  "displaced_volume_m3": report.displaced_volume_m3,
                  "displaced_volume_note": (
                      "sealed links (ahead of hull.flooded_from_joint = "
                      f"{params.hull.flooded_from_joint}): their closed outer envelope up to the dry "
                      "compartment's rear wall (behind it, in the joint gap: only the solids), "
                      "plus the caudal fin behind the hull end; flooded links: the solid volume of their parts only "
                      "(printed parts are closed shells); the water inside a flooded link or its joint gap moves with it "
                      "(links[].entrained_water)"),
                  "cob_m": list(report.cob_m), "buoyancy_n": report.buoyancy_n, "weight_n": report.weight_n,
                  "net_buoyancy_n": report.buoyancy_n - report.weight_n,
                  "neutral_mass_kg": report.buoyancy_n / g,
                  "cob_com_distance_m": report.cob_com_distance_m,
                  "cob_above_com_m": report.cob_m[2] - report.total.com_m[2],
                  "com_ahead_of_cob_m": report.total.com_m[0] - report.cob_m[0],
                  "static_pitch_deg": static_pitch_deg(report.total.com_m, report.cob_m)}
    d["trim"] = jsonable(report.trim)
    return d
