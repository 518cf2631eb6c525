"""Mass properties of every part and every kinematic link, from the exact B-rep, in SI units: the link assembly.

What is where (house style rules 3, 10):

* :mod:`swiftfin.exports.brep`: tessellation and the B-rep volume properties (OCC's ``MatrixOfInertia`` is the
  inertia *tensor* about the centre of mass); :mod:`swiftfin.exports.inertia`: the inertial algebra
  (:func:`combine`, parallel axis); :mod:`swiftfin.exports.parallel`: the per-part processes.
* :mod:`swiftfin.exports.print_model`: one part's mass model: printed parts as solid minus the sparse-infill core
  (slicer-like layers, B-rep offset or voxel erosion), bought parts at their catalogue mass.
* :mod:`swiftfin.exports.line_masses`: the cables and the PTFE tubes as line masses.
* :mod:`swiftfin.exports.water`: displaced volume, centre of buoyancy, the water a flooded link carries, trim ballast.
* :mod:`swiftfin.exports.mass_gate`: the validation gate every build passes.
* :mod:`swiftfin.exports.mass_json`: ``mass_properties.json``.

This module groups the parts into links (:func:`mass_properties`) and keeps every name above importable from
here (``massprops.part_mass``, ``massprops.validate``, ...), so callers need not know the split.

Links: parts are grouped by ``PartSpec.link``; each link's frame has its origin on its joint axis at z = 0
(link 0: at the nose) and axes parallel to the body frame at rest (layout/geometry.py); the link inertia is about
the link COM in those axes.

Ranges for domain randomisation: each link's mass, COM and inertia at the 16 corners of the uncertainty box
of ``[domain_randomisation]`` (filament density, infill, wall thickness, catalogue masses); the core's change
with the wall thickness is first order (core volume -/+ its side area x the wall change, inertia scaled with
the volume to the 5/3 power).
"""
from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field, replace

import numpy as np

from swiftfin.core import units
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as layout
from swiftfin.layout.ballast_plan import FILL_LABEL
from swiftfin.exports.brep import (  # noqa: F401  re-exported: the mass model's geometry
    VOLUME_EPS, VolumeProps, _props, _wrapped, mesh_volume_props, solid_area_mm2, solid_volume_props)
from swiftfin.exports.brep import tessellate_trimesh as tessellate
from swiftfin.exports.inertia import Inertial, combine, make_inertial, parallel_axis  # noqa: F401  re-exported
from swiftfin.exports.parallel import map_parts
from swiftfin.physics.hydrostatics import static_pitch_deg  # noqa: F401  re-exported
# the parts of the mass model, re-exported so that ``massprops.<name>`` keeps working for every caller
from swiftfin.exports.print_model import (  # noqa: F401
    BRIDGE_EXTRA_SPACING_MM, CORE_METHODS, EXTERNAL_INFILL_MARGIN_MM, INFILL_OVERLAP_FRACTION,
    SOLID_INFILL_BELOW_AREA_MM2, Core, PartMass, PrintModel, _common, _make_solid, _polygon_moments, _translated,
    _valid, bridge_flow_factor, core_key, find_core, layer_core, memoized, occ_core, part_mass, rotation_matrix,
    to_manifold, voxel_core)
from swiftfin.exports.line_masses import (  # noqa: F401
    cable_masses, fastener_masses, harness_masses, link_of_station, ptfe_tube_masses,
    rod_inertial)
from swiftfin.exports.water import (  # noqa: F401
    _ballast_part, _fin_outside_volume, _outside_piece, behind_dry_wall, envelope_inertial, envelope_section_mm, envelope_volume_mm3,
    trim_ballast, trim_margin_kg, ballast_height)
from swiftfin.exports.mass_gate import GATE_MESH_REL_TOL, _inside_box, check_tensor, validate  # noqa: F401
from swiftfin.exports.mass_json import PAPER_MASS_KG, _inertial_dict, report_to_dict  # noqa: F401


# ----------------------------------------------------------------------------------------------- links & report
@dataclass(frozen=True)
class LinkMass:
    index: int
    name: str
    origin_m: tuple[float, float, float]    # link frame origin in the body frame at rest
    inertial: Inertial                      # COM in the link frame, inertia about the COM in link axes
    parts: tuple[str, ...]
    ranges: dict = field(default_factory=dict, compare=False, hash=False)

    @property
    def com_body_m(self) -> np.ndarray:
        return self.inertial.com + np.asarray(self.origin_m)


@dataclass(frozen=True)
class MassReport:
    parts: tuple[PartMass, ...]
    links: tuple[LinkMass, ...]
    total: Inertial                         # body frame (origin at the nose)
    displaced_volume_m3: float
    cob_m: tuple[float, float, float]       # centre of buoyancy, body frame
    buoyancy_n: float
    weight_n: float
    print_model: PrintModel
    uncertainty: dict
    link_displaced_volume_m3: tuple[float, ...]
    link_cob_m: tuple[tuple[float, float, float], ...]   # per link, body frame
    link_flooded: tuple[bool, ...] = ()
    link_entrained_water: tuple = ()        # per link: Inertial of the water inside a flooded link (body frame) or None
    trim: dict = field(default_factory=dict)   # the trim ballast computation (see :func:`trim_ballast`)

    @property
    def cob_com_distance_m(self) -> float:
        return float(np.linalg.norm(np.asarray(self.cob_m) - self.total.com))


def link_name(j: int) -> str:
    return "head" if j == 0 else f"link_{j}"


def link_origin_mm(p: Params, j: int) -> tuple[float, float, float]:
    """Link j's frame origin in the body frame [mm]: on joint j's axis (z = 0), or the nose for the head."""
    return (0.0, 0.0, 0.0) if j == 0 else (-layout.joint_stations_mm(p)[j - 1], 0.0, 0.0)


def _corner_inertials(parts_m: list[PartMass], pm: PrintModel, unc: dict, corner) -> list[Inertial]:
    """Every part's inertial at one corner of the uncertainty box (first-order core model)."""
    sr, sf, sw, sb = corner
    rho_f = 1.0 + sr * unc["density_fraction"]
    phi = min(1.0, max(0.0, pm.infill_fraction + sf * unc["infill_fraction"]))
    dw_mm = sw * unc["wall_fraction"] * pm.wall_mm
    out = []
    for pt in parts_m:
        if not pt.printed:
            out.append(pt.inertial.scaled_mass(1.0 + sb * unc["bought_mass_fraction"]))
            continue
        items = [pt.solid.scaled_mass(rho_f)]
        if pt.overlap is not None:
            items.append(pt.overlap.scaled_mass(rho_f))
        if pt.core is not None:
            Vc = pt.volume_core_m3
            Vc_new = max(0.0, Vc - pt.area_core_m2 * units.length_m(dw_mm))
            k = Vc_new / Vc
            core = pt.core.scaled_mass(rho_f * k)
            core = make_inertial(core.mass_kg, core.com, core.inertia * k ** (2.0 / 3.0))
            items.append(core.scaled_mass(-(1.0 - phi)))
        out.append(combine(items))
    return out


def mass_properties(params: Params, parts, meshes: dict | None = None,
                    uncertainty: dict | None = None, core_method: str = "layers", memo=None,
                    jobs: int | None = 1) -> MassReport:
    """Mass properties of every part and link of a design (``parts``: list of PartSpec).

    ``meshes``: optional {label: trimesh in mm} (used for the voxel fallback; tessellated here if absent).
    ``uncertainty``: relative uncertainties for the domain-randomisation ranges (defaults from
    :func:`default_uncertainty`). ``memo``: the application's store of per-part results (:func:`memoized`);
    ``jobs``: processes for the per-part work (:func:`map_parts`; None: one per core).
    """
    pm = PrintModel.from_params(params)
    meshes = dict(meshes or {})
    unc = uncertainty or default_uncertainty(params)
    def layers(part, mesh):
        """The part's layer core from the memo (stage "part_core", which the application may have filled while
        the later parts were modelled: swiftfin/prefetch.py), or computed into it; None when the layers model
        is not asked for or cannot take the mesh (part_mass then runs the fallbacks and says so)."""
        if not part.printed or core_method != "layers" or mesh is None:
            return None
        try:
            return memoized(memo, "part_core", (part.label,),
                            core_key(pm, params.print.layer_height_mm, part.print_rotation),
                            lambda: layer_core(mesh, rotation_matrix(part.print_rotation), pm,
                                               params.print.layer_height_mm))
        except ValueError:
            return None

    def one(part) -> PartMass:
        mesh = meshes.get(part.label)
        if mesh is None and part.printed:
            mesh = tessellate(part.solid, params.export.mesh_tolerance_mm, params.export.mesh_angular_tolerance_deg)
        try:
            props = memoized(memo, "solid_props", (part.label,), None, lambda: solid_volume_props(part.solid))
            return memoized(memo, "part_mass", (part.label,),
                            [dataclasses.asdict(pm), params.print.layer_height_mm, core_method],
                            lambda: part_mass(part, pm, mesh, params.print.layer_height_mm, core_method, props,
                                              layers(part, mesh)))
        except ValueError as exc:
            raise BuildError(f"part {part.label}: mass model failed: {exc}") from exc

    out: list[PartMass] = map_parts(one, list(parts), jobs)
    out += cable_masses(params)
    out += ptfe_tube_masses(params)
    out += fastener_masses(params)
    out += harness_masses(params)
    links_idx = sorted({pt.link for pt in out})
    if links_idx != list(range(len(links_idx))) or len(links_idx) != params.joints.count + 1:
        raise BuildError(f"links: parts belong to links {links_idx}; expected 0..{params.joints.count} "
                         f"(one per joint plus the head)")
    # displaced volume per link: a sealed link displaces its closed envelope (plus the fin behind the hull end);
    # a flooded one (hull.flooded_from_joint) only the solids of its parts, and carries the water inside it
    js = layout.joint_stations_mm(params)
    bounds = [0.0, *js, layout.hull_end_mm(params)]
    rho_w = params.environment.water_density_kg_m3
    flooded = tuple(j >= params.hull.flooded_from_joint for j in range(len(bounds) - 1))
    V_fin, c_fin, fin_link, fin_pieces = _fin_outside_volume(params, parts, memo, meshes)
    # the last sealed link ends at its dry wall's back face: behind it (the joint gap) only solids displace water
    gap_link, s_wall, gap_pieces = behind_dry_wall(params, parts, memo, meshes)

    def displacement(items: list[PartMass]):
        link_V, link_cob, water = [], [], []
        for j in range(len(bounds) - 1):
            if not flooded[j]:
                s_dry = s_wall if j == gap_link else bounds[j + 1]
                V, s_c = envelope_volume_mm3(params, bounds[j], s_dry)
                cob = np.array([-s_c, 0.0, 0.0])
                w = None
                if j == gap_link:    # the solids in the joint gap (lugs, stops) displace their own volume; the
                    #                  water round them moves with the link
                    for pr in gap_pieces:
                        cob = (V * cob + pr.volume_mm3 * np.asarray(pr.centroid_mm)) / (V + pr.volume_mm3)
                        V += pr.volume_mm3
                    w = combine([envelope_inertial(params, s_wall, bounds[j + 1], rho_w),
                                 *[pr.inertial(-rho_w) for pr in gap_pieces]])
                    check_tensor(f"water inside link {j} behind its dry wall", w.inertia, w.mass_kg)
                if V_fin > 0 and j == fin_link:
                    cob = (V * cob + V_fin * c_fin) / (V + V_fin)
                    V += V_fin
                link_V.append(V)
                link_cob.append(cob)
                water.append(w)
                continue
            mine = [pt for pt in items if pt.link == j and pt.volume_solid_m3 > 0]
            V_m3 = sum(pt.volume_solid_m3 for pt in mine)
            cob_m = sum(pt.volume_solid_m3 * pt.solid.com for pt in mine) / V_m3 if V_m3 > 0 else np.zeros(3)
            link_V.append(V_m3 * 1e9)
            link_cob.append(1000.0 * cob_m)
            # the water inside: the envelope at water density less the parts' solids at water density (the fin's
            # part behind the hull end was never inside the envelope)
            env = envelope_inertial(params, bounds[j], bounds[j + 1], rho_w)
            minus = [pt.solid.scaled_mass(-rho_w * pt.volume_solid_m3 / pt.solid.mass_kg) for pt in mine]
            if V_fin > 0 and j == fin_link:      # add back the fin's solid behind the hull end, at water density
                minus += [pr.inertial(rho_w) for pr in fin_pieces]
            w = combine([env, *minus])
            check_tensor(f"water inside link {j}", w.inertia, w.mass_kg)
            water.append(w)
        return link_V, link_cob, water

    # a trim ballast built as a part (swiftfin.pipeline.place_ballast) is what the trim below sizes: the trim is
    # computed without it, and the part, where the hull could take it, stands for the trim's ideal sphere
    fill = [pt for pt in out if pt.label == FILL_LABEL]
    out = [pt for pt in out if pt.label != FILL_LABEL]
    link_V, link_cob, water = displacement(out)
    trim: dict = {"enabled": bool(params.environment.trim_ballast)}
    if params.environment.trim_ballast:
        V_m3 = units.volume_m3(sum(link_V))
        cob0 = units.length_m(sum(v * c for v, c in zip(link_V, link_cob)) / sum(link_V))
        dry = combine([pt.inertial for pt in out])
        trim.update(trim_ballast(params, dry.mass_kg, dry.com, V_m3, cob0, flooded))
        head = [pt.inertial for pt in out if pt.link == 0]
        if head:                         # what a builder may add to the head, at its centre, and still trim it
            trim["head_margin_kg"] = trim_margin_kg(params, dry.mass_kg, dry.com, V_m3, cob0, flooded,
                                                    float(combine(head).com[0]))
        if fill and (trim.get("possible") or trim.get("sphere_only")):
            trim = {**trim, "possible": True, "reason": ""}
            f = fill[0]
            c = f.inertial.com
            trim.update({"placed": "fill", "fill_mass_kg": f.inertial.mass_kg, "fill_com_m": [float(v) for v in c],
                         "fill_miss_x_m": float(trim["x_m"] - c[0]), "z_m": float(c[2])})
            out.append(f)
            link_V, link_cob, water = displacement(out)
        elif trim.get("possible"):
            j = int(trim["link"])
            carried = [pt.inertial for pt in out if pt.link == j] + ([water[j]] if water[j] is not None else [])
            # clear of the solid parts inside (the hull's room is in z_room_m; cables, tubes, leads and fasteners are
            # summed per link here, their boxes the link's, and none runs through the nose's middle)
            keep = [(pt.label, pt.bbox_m) for pt in out if pt.link == j
                    and pt.family not in ("hull", "fin", "cable", "ptfe", "fastener", "ballast",
                                                                 "harness")]
            trim = ballast_height(trim, combine(carried), keep, params.print.clearance_assembly_mm * 1e-3)
            if trim.get("possible"):
                out.append(_ballast_part(params, trim))
                link_V, link_cob, water = displacement(out)
    links_idx = sorted({pt.link for pt in out})
    V_tot = sum(link_V)
    cob_mm = sum(v * c for v, c in zip(link_V, link_cob)) / V_tot
    links = []
    for j in links_idx:
        members = [pt for pt in out if pt.link == j]
        origin = units.length_m(np.asarray(link_origin_mm(params, j)))
        inert = combine([pt.inertial for pt in members]).shifted(origin)
        links.append(LinkMass(j, link_name(j), tuple(float(v) for v in origin), inert,
                              tuple(pt.label for pt in members)))
    # domain-randomisation ranges: the extreme corners of the uncertainty box (density, infill, wall, bought)
    corners = list(itertools.product((-1, 1), repeat=4))
    samples = {j: [] for j in links_idx}
    for corner in corners:
        inerts = _corner_inertials(out, pm, unc, corner)
        for j in links_idx:
            li = combine([it for it, pt in zip(inerts, out) if pt.link == j]).shifted(links[j].origin_m)
            samples[j].append(li)
    links = [replace(lk, ranges=_ranges(samples[lk.index])) for lk in links]
    total = combine([pt.inertial for pt in out])
    g = params.environment.gravity_m_s2
    V_m3 = units.volume_m3(V_tot)
    return MassReport(tuple(out), tuple(links), total, V_m3, tuple(float(v) for v in units.length_m(cob_mm)),
                      rho_w * g * V_m3, total.mass_kg * g, pm, dict(unc),
                      tuple(units.volume_m3(v) for v in link_V),
                      tuple(tuple(float(x) for x in units.length_m(c)) for c in link_cob),
                      flooded, tuple(water), trim)


def default_uncertainty(params: Params) -> dict:
    """Relative uncertainties of the print inputs, from ``[domain_randomisation]`` if present."""
    dr = getattr(params, "domain_randomisation", None)
    if dr is None:
        return {"density_fraction": 0.03, "infill_fraction": 0.05, "wall_fraction": 0.10,
                "bought_mass_fraction": 0.05}
    return {"density_fraction": dr.filament_density_fraction, "infill_fraction": dr.infill_absolute,
            "wall_fraction": dr.wall_thickness_fraction, "bought_mass_fraction": dr.bought_mass_fraction}


def _ranges(samples: list[Inertial]) -> dict:
    m = [s.mass_kg for s in samples]
    I = np.array([s.inertia for s in samples])
    c = np.array([s.com for s in samples])
    names = {"ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1), "ixz": (0, 2), "iyz": (1, 2)}
    out = {"mass_kg": [min(m), max(m)],
           "com_m": [c.min(axis=0).tolist(), c.max(axis=0).tolist()]}
    for k, (i, j) in names.items():
        out[f"{k}_kg_m2"] = [float(I[:, i, j].min()), float(I[:, i, j].max())]
    return out
