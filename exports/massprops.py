"""Mass properties of every part and every kinematic link, from the exact B-rep, in SI units.

Method (house style rules 3, 10)
--------------------------------
* **Solid geometry** comes from OpenCascade (``BRepGProp.VolumeProperties``): volume, centroid and the second
  moment of volume about the centroid (OCC's ``MatrixOfInertia`` is the inertia *tensor* about the centre of
  mass, products of inertia with their minus sign). Converted mm -> m in :mod:`swiftfin.core.units`.
* **Bought parts** (``PartSpec.printed`` False) carry a catalogue ``mass_kg``; their box/cylinder geometry is
  taken as a uniform-density body scaled to that mass. The **cables** are line masses
  (``cable.linear_density_g_m``) along ``swiftfin.layout.geometry.cable_routes`` plus their wraps on the drums
  (:func:`cable_masses`, one ``cables_link_<j>`` entry per link). The **PTFE tube** lines every guide channel
  where it passes through its printed block (:func:`ptfe_tube_masses`): a thin-walled rod of
  ``guides.ptfe_tube_od_mm`` / ``ptfe_tube_id_mm`` and ``guides.ptfe_density_kg_m3`` along the channel centre
  lines of ``cad.guide.guide_blocks``, one ``ptfe_tube_link_<j>`` entry per link that holds guides.
* **Printed parts** are not solid. Mass model ``m = rho * (V_solid - (1 - infill) * V_core + V_extra)``: the B-rep
  solid minus ``(1 - infill)`` times the *core*, the region the slicer fills with sparse infill; the core's
  first and second moments are subtracted the same way (inertia about the part's COM by the parallel-axis
  theorem, :func:`combine`). The side walls are ``w = perimeters * line_width``, the skins
  ``t_top = top_layers * layer_height`` and ``t_bottom = bottom_layers * layer_height``, in the part's print
  orientation (``PartSpec.print_rotation``). Three core models, tried in this order:

  1. ``layers`` (default): what the slicer does. The tessellated part, turned to its print orientation, is cut
     at every mid-layer height (manifold3d); each section is shrunk by ``w`` (2-D round offset) and intersected
     with the sections ``top_layers`` above and ``bottom_layers`` below. Volume, centroid and second moments
     are summed slab by slab from polygon moment formulas. Needs a manifold mesh. Four PrusaSlicer habits
     (its defaults, which exports/slicer.py keeps) are modelled because each moved some part by 3-12 %:
     skins grow 3 mm into the sparse infill (:data:`EXTERNAL_INFILL_MARGIN_MM`), core pieces under 70 mm^2 print
     solid (:data:`SOLID_INFILL_BELOW_AREA_MM2`), infill overlaps the perimeters by 25 % of a line
     (:data:`INFILL_OVERLAP_FRACTION`), and overhangs and solid layers over sparse infill are laid as bridges
     with 1.4 x the plastic (:func:`bridge_flow_factor`). The last two are extra plastic, added with their
     own moments.
  2. ``occ-offset``: the B-rep uniform inward offset by ``w`` (``BRepOffsetAPI_MakeOffsetShape``), then top and
     bottom erosion by intersecting with the solid translated down by ``t_top`` and up by ``t_bottom``. This is
     the textbook first model, but its normal offset makes horizontal skins ``max(w, t)`` thick: with the default
     print (w = 1.35 mm > t = 0.8/1.0 mm) it under-predicts the core of a 40 x 30 x 20 mm block by 5 % and
     over-predicts its printed volume by 6 % against PrusaSlicer, hence second. Used where the mesh is not a
     manifold.
  3. ``voxel``: voxel erosion of the mesh in print orientation (a horizontal disc of radius ``w`` and a
     vertical segment ``[-t_bottom, t_top]`` as the structuring element); coarse (surface voxels make the core
     a few % large) but it never fails.

  Every method that fails is named in the part's flags. An empty core (walls thinner than two side walls,
  e.g. the 2 mm hull shells) is legitimate: the part prints solid, as the slicer prints it.

Links: parts are grouped by ``PartSpec.link``; each link's frame has its origin on its joint axis at z = 0
(link 0: at the nose) and axes parallel to the body frame at rest (layout/geometry.py); the link inertia is about
the link COM in those axes.

Buoyancy: the hull is taken as **sealed and skinned** (an assumption: a waterproof skin spans the joint
gaps and the segments are closed), so the displaced volume is the closed outer envelope of the body from the nose to the hull end
(the NACA 00xx elliptical sections of layout/geometry.py, integrated numerically) plus the part of the caudal fin
behind the hull end (exact B-rep). Water inside the hull is not displaced water: it is sealed.

Ranges for domain randomisation: each link's mass, COM and inertia at the 16 corners of the uncertainty box
of ``[domain_randomisation]`` (filament density, infill, wall thickness, catalogue masses); the core's change
with the wall thickness is first order (core volume -/+ its side area x the wall change, inertia scaled with
the volume to the 5/3 power).
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from swiftfin.layout import geometry as layout
from swiftfin.core import units
from swiftfin.physics.hydrostatics import static_pitch_deg
from swiftfin.exports.brep import (  # noqa: F401  re-exported: the mass model's geometry
    VOLUME_EPS, VolumeProps, _props, _wrapped, mesh_volume_props, solid_area_mm2, solid_volume_props)
from swiftfin.exports.brep import tessellate_trimesh as tessellate
from swiftfin.exports.inertia import Inertial, combine, make_inertial, parallel_axis  # noqa: F401  re-exported
from swiftfin.exports.parallel import map_parts
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params

PAPER_MASS_KG = 1.2          # SwiftFin paper, Table 2
GATE_MESH_REL_TOL = 0.01     # OCC vs mesh agreement [-] (issue 3, item 5)


def memoized(memo, stage: str, labels: tuple[str, ...], extra, compute):
    """``compute()``, or its stored result: ``memo(stage, labels, extra, compute)`` is the application's store
    (swiftfin.cache.StageCache), keyed by the content of the named parts, ``extra`` and the stage's code. The
    functions here stay pure: with ``memo`` None they compute."""
    return compute() if memo is None else memo(stage, tuple(labels), extra, compute)


def rotation_matrix(print_rotation_deg) -> np.ndarray:
    """The matrix of build123d's ``Rotation(rx, ry, rz)`` acting on points (body frame -> print frame)."""
    from build123d import Pos, Rotation
    rot = Rotation(*print_rotation_deg)
    cols = []
    for e in np.eye(3):
        p = (rot * Pos(*e)).position
        cols.append([p.X, p.Y, p.Z])
    return np.array(cols).T


# ----------------------------------------------------------------------------------------------- print model
@dataclass(frozen=True)
class PrintModel:
    """Wall thicknesses and infill of a printed part [mm], from ``[print]``."""
    wall_mm: float
    top_mm: float
    bottom_mm: float
    infill_fraction: float
    density_kg_m3: float
    line_width_mm: float
    nozzle_mm: float = 0.4

    @classmethod
    def from_params(cls, p: Params) -> "PrintModel":
        pr = p.print
        return cls(pr.perimeters * pr.line_width_mm, pr.top_layers * pr.layer_height_mm,
                   pr.bottom_layers * pr.layer_height_mm, pr.infill_fraction, pr.filament_density_kg_m3,
                   pr.line_width_mm, pr.nozzle_diameter_mm)


@dataclass(frozen=True)
class Core:
    """The sparse-infill region of a printed part."""
    props: VolumeProps | None      # None: empty core (the part prints solid)
    area_mm2: float                # surface area of the core (for the wall-thickness sensitivity)
    method: str                    # "layers" | "occ-offset" | "voxel"
    note: str = ""
    overlap: VolumeProps | None = None   # extra plastic where infill overlaps the perimeters (layers model)


def _make_solid(shape):
    """A closed shell from BRepOffsetAPI -> a solid."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
    from OCP.TopAbs import TopAbs_SHELL, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    if shape.ShapeType() == TopAbs_SOLID:
        return shape
    mk = BRepBuilderAPI_MakeSolid()
    exp = TopExp_Explorer(shape, TopAbs_SHELL)
    n = 0
    while exp.More():
        mk.Add(TopoDS.Shell(exp.Current()))
        n += 1
        exp.Next()
    if n == 0:
        raise ValueError("offset produced no shell")
    return mk.Solid()


def _valid(shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer
    return bool(BRepCheck_Analyzer(shape).IsValid())


def _common(a, b):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common
    op = BRepAlgoAPI_Common(a, b)
    if not op.IsDone():
        raise ValueError("boolean common failed")
    return op.Shape()


def _translated(shape, v_mm):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Trsf, gp_Vec
    t = gp_Trsf()
    t.SetTranslation(gp_Vec(*map(float, v_mm)))
    return BRepBuilderAPI_Transform(shape, t, True).Shape()


def occ_core(solid, up, pm: PrintModel) -> Core:
    """The core by B-rep offset and vertical erosion (module docstring). Raises ValueError where OCC fails."""
    from OCP.BRepOffset import BRepOffset_Skin
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
    from OCP.GeomAbs import GeomAbs_Intersection
    S = _wrapped(solid)
    if not _valid(S):
        raise ValueError("the part's solid is not valid")
    v_s = solid_volume_props(S).volume_mm3
    a_s = solid_area_mm2(S)
    mk = BRepOffsetAPI_MakeOffsetShape()
    mk.PerformByJoin(S, -pm.wall_mm, 1e-4, BRepOffset_Skin, False, False, GeomAbs_Intersection)
    if not mk.IsDone():
        raise ValueError("BRepOffsetAPI_MakeOffsetShape failed")
    off = _make_solid(mk.Shape())
    if not _valid(off):
        raise ValueError("inward offset is not a valid solid")
    v_off = solid_volume_props(off).volume_mm3
    if not (0.0 < v_off < v_s) or v_s - v_off > 1.5 * a_s * pm.wall_mm:
        raise ValueError(f"inward offset volume {v_off:.1f} mm^3 is implausible for a solid of {v_s:.1f} mm^3")
    up = np.asarray(up, dtype=float)
    core = _common(off, _translated(S, -pm.top_mm * up))
    core = _common(core, _translated(S, pm.bottom_mm * up))
    props = solid_volume_props(core)
    if props.volume_mm3 <= 1e-6 * v_s:
        return Core(None, 0.0, "occ-offset", "empty after top/bottom erosion")
    inside = solid_volume_props(_common(core, S)).volume_mm3
    if abs(inside - props.volume_mm3) > 1e-3 * props.volume_mm3:
        raise ValueError("core pokes out of the solid")
    return Core(props, solid_area_mm2(core), "occ-offset")


def voxel_core(mesh, R, pm: PrintModel, max_cells: float = 6.0e6) -> Core:
    """Fallback core: voxel erosion of the mesh (mm, body frame) in print orientation ``R`` (body -> print)."""
    from scipy import ndimage
    m = mesh.copy()
    T = np.eye(4)
    T[:3, :3] = R
    m.apply_transform(T)
    ext = m.bounds[1] - m.bounds[0]
    pitch = max(0.2, float((np.prod(ext) / max_cells) ** (1 / 3)))
    vox = m.voxelized(pitch).fill()
    grid = vox.matrix.astype(bool)
    rw = pm.wall_mm / pitch
    kt, kb = int(math.ceil(pm.top_mm / pitch)), int(math.ceil(pm.bottom_mm / pitch))
    r = int(math.ceil(rw))
    ii, jj = np.mgrid[-r:r + 1, -r:r + 1]
    disc = (ii**2 + jj**2) <= rw**2
    se_disc = disc[:, :, None]
    se_vert = np.zeros((1, 1, kt + kb + 1), dtype=bool)
    se_vert[0, 0, :] = True
    core = ndimage.binary_erosion(grid, structure=se_disc, border_value=0)
    # vertical: a voxel stays if the kt voxels above it and the kb below are solid (scipy: centre = len//2 + origin)
    core &= ndimage.binary_erosion(grid, structure=se_vert, border_value=0, origin=(0, 0, kb - (kt + kb + 1) // 2))
    n = int(core.sum())
    if n == 0:
        return Core(None, 0.0, "voxel", f"empty core (pitch {pitch:.2f} mm)")
    idx = np.argwhere(core)
    pts = vox.indices_to_points(idx)          # voxel centres, print frame
    pts = pts @ R                             # back to the body frame (R orthonormal: R^T p)
    dv = pitch**3
    V = n * dv
    c = pts.mean(axis=0)
    d = pts - c
    second = (np.eye(3) * np.sum(d * d) - d.T @ d) * dv + np.eye(3) * n * dv * pitch**2 / 6.0
    # surface area of the core, from its boundary voxel faces (for the wall sensitivity only)
    faces = sum(int(np.abs(np.diff(np.pad(core, 1).astype(np.int8), axis=a)).sum()) for a in range(3))
    return Core(_props(V, c, second), faces * pitch**2, "voxel", f"pitch {pitch:.2f} mm")


def _polygon_moments(polys):
    """Signed area, first moments (Sx = int x, Sy = int y), second moments (int x^2, int y^2, int xy) and
    perimeter of a set of closed contours (outer CCW, holes CW, as Clipper/manifold return them)."""
    A = Sx = Sy = Sxx = Syy = Sxy = per = 0.0
    for poly in polys:
        P = np.asarray(poly, dtype=float)
        if len(P) < 3:
            continue
        x0, y0 = P[:, 0], P[:, 1]
        x1, y1 = np.roll(x0, -1), np.roll(y0, -1)
        cr = x0 * y1 - x1 * y0
        A += cr.sum() / 2
        Sx += ((x0 + x1) * cr).sum() / 6
        Sy += ((y0 + y1) * cr).sum() / 6
        Sxx += ((x0**2 + x0 * x1 + x1**2) * cr).sum() / 12
        Syy += ((y0**2 + y0 * y1 + y1**2) * cr).sum() / 12
        Sxy += ((x0 * y1 + 2 * x0 * y0 + 2 * x1 * y1 + x1 * y0) * cr).sum() / 24
        per += np.hypot(x1 - x0, y1 - y0).sum()
    return A, Sx, Sy, Sxx, Syy, Sxy, per


def to_manifold(mesh):
    import manifold3d as m3
    return m3.Manifold(m3.Mesh(vert_properties=np.asarray(mesh.vertices, dtype=np.float32),
                               tri_verts=np.asarray(mesh.faces, dtype=np.uint32)))


SOLID_INFILL_BELOW_AREA_MM2 = 70.0
"""Core regions of a layer smaller than this are printed solid [mm^2]: PrusaSlicer's ``solid_infill_below_area``
default (70 mm^2), which exports/slicer.py leaves at its default."""


INFILL_OVERLAP_FRACTION = 0.25
"""Infill (solid and sparse) overlaps the innermost perimeter by this fraction of the line width: PrusaSlicer's
``infill_overlap`` default (25 %), which exports/slicer.py leaves at its default. The overlap is extra plastic
(measured on hull_body_3_upper: 4.6 % of its volume), so the layers model adds it."""


EXTERNAL_INFILL_MARGIN_MM = 3.0
"""PrusaSlicer grows every top and bottom skin by this margin into the sparse infill to anchor it
(``EXTERNAL_INFILL_MARGIN``, 3 mm, in its source); it matters on sloped skins (the fin, the spool flanges)."""

BRIDGE_EXTRA_SPACING_MM = 0.05
"""PrusaSlicer lays bridges (overhangs, and solid infill over sparse infill) as round threads of the nozzle
diameter ``d`` spaced ``d + 0.05 mm`` (its ``thick_bridges`` default and BRIDGE_EXTRA_SPACING)."""


def bridge_flow_factor(nozzle_mm: float, layer_height_mm: float) -> float:
    """Plastic per area of a bridged layer / that of a normal layer: (pi d^2 / 4) / ((d + 0.05) h).
    1.40 for a 0.4 mm nozzle and 0.2 mm layers."""
    return (math.pi * nozzle_mm**2 / 4) / ((nozzle_mm + BRIDGE_EXTRA_SPACING_MM) * layer_height_mm)


def layer_core(mesh, R, pm: PrintModel, layer_height_mm: float) -> Core:
    """The core as the slicer finds it, layer by layer (mesh in mm, body frame; ``R``: body -> print).

    The part is turned to its print orientation and dropped on the bed; each layer's section (at mid-layer)
    is shrunk by the side wall ``w`` (a 2-D round offset, as the perimeters are laid) and intersected with the
    sections of the ``top_layers`` layers above and the ``bottom_layers`` below (the solid skins); pieces of a
    layer's core smaller than :data:`SOLID_INFILL_BELOW_AREA_MM2` print solid, as in the slicer. The core's
    volume, centroid and second moments are summed slab by slab (polygon moment formulas), then turned back
    to the body frame.
    """
    import manifold3d as m3
    m = mesh.copy()
    T = np.eye(4)
    T[:3, :3] = R
    m.apply_transform(T)
    z0 = float(m.bounds[0][2])
    m.apply_translation([0.0, 0.0, -z0])
    man = to_manifold(m)
    if man.status() != m3.Error.NoError:
        raise ValueError(f"mesh is not a manifold ({man.status()})")
    h = layer_height_mm
    n = int(math.ceil(float(m.bounds[1][2]) / h))
    nt = int(round(pm.top_mm / h))
    nb = int(round(pm.bottom_mm / h))
    sections = [man.slice((i + 0.5) * h) for i in range(n)]
    empty = m3.CrossSection()
    o = INFILL_OVERLAP_FRACTION * pm.line_width_mm
    acc = np.zeros((2, 10))   # [core, overlap] x (V, S1[3], S2[6])
    side_area = 0.0

    def add(row: int, polys, z: float, weight: float) -> float:
        A, Sx, Sy, Sxx, Syy, Sxy, per = _polygon_moments(polys)
        if A <= 0:
            return 0.0
        w = weight * h
        acc[row] += w * np.array([A, Sx, Sy, A * z, Sxx, Syy, A * (z * z + h * h / 12), Sxy, Sx * z, Sy * z])
        return per

    bridge_extra = bridge_flow_factor(pm.nozzle_mm, h) - 1.0
    prev_core = empty
    for i in range(n):
        sec = sections[i]
        if sec.is_empty():
            prev_core = empty
            continue
        z = (i + 0.5) * h
        # overhangs: the part of this layer not resting on the layer below is laid with bridge flow
        if i > 0:
            over = sec - sections[i - 1].offset(pm.line_width_mm / 2, m3.JoinType.Round, 2.0, 64)
            if not over.is_empty():
                add(1, over.to_polygons(), z, bridge_extra)
        inner = sec.offset(-pm.wall_mm, m3.JoinType.Round, 2.0, 64)
        if inner.is_empty():
            prev_core = empty
            continue
        core = inner
        for k in range(1, nt + 1):
            core = core ^ (sections[i + k] if i + k < n else empty)
        for k in range(1, nb + 1):
            core = core ^ (sections[i - k] if i - k >= 0 else empty)
        if EXTERNAL_INFILL_MARGIN_MM > 0 and not core.is_empty():
            skin = inner - core
            if not skin.is_empty():
                core = core - skin.offset(EXTERNAL_INFILL_MARGIN_MM, m3.JoinType.Round, 2.0, 64)
        pieces = [c for c in core.decompose() if c.area() >= SOLID_INFILL_BELOW_AREA_MM2] if not core.is_empty() else []
        a_core = sum(c.area() for c in pieces)
        core_cs = empty
        for c in pieces:
            core_cs = core_cs + c
        if pieces:
            side_area += h * add(0, core_cs.to_polygons(), z, 1.0)
        # infill (solid or sparse) overlaps the innermost perimeter by o: a band inside the inner contour,
        # filled at the inner region's mean density
        a_inner = inner.area()
        rho_inner = ((a_inner - a_core) + pm.infill_fraction * a_core) / a_inner
        band = inner - inner.offset(-o, m3.JoinType.Round, 2.0, 64)
        if not band.is_empty():
            add(1, band.to_polygons(), z, rho_inner)
        # internal bridges: solid infill laid over the sparse infill of the layer below (bridge flow)
        if not prev_core.is_empty():
            ib = (inner - core_cs) ^ prev_core
            if not ib.is_empty():
                add(1, ib.to_polygons(), z, bridge_extra)
        prev_core = core_cs

    def props(row: int):
        V = acc[row, 0]
        if V <= 0:
            return None
        S1 = acc[row, 1:4]
        Sxx, Syy, Szz, Sxy, Sxz, Syz = acc[row, 4:10]
        S2 = np.array([[Sxx, Sxy, Sxz], [Sxy, Syy, Syz], [Sxz, Syz, Szz]])
        c = S1 / V
        C2 = S2 - V * np.outer(c, c)                 # about the centroid
        second = np.trace(C2) * np.eye(3) - C2       # volume inertia tensor about the centroid
        c_body = R.T @ (c + np.array([0.0, 0.0, z0]))
        return _props(V, c_body, R.T @ second @ R)

    core_props, overlap = props(0), props(1)
    if core_props is None:
        return Core(None, 0.0, "layers", "empty core (prints solid)", overlap)
    return Core(core_props, side_area, "layers", f"{n} layers of {h:g} mm", overlap)


# ----------------------------------------------------------------------------------------------- parts
@dataclass(frozen=True)
class PartMass:
    """Mass properties of one part, body frame, SI."""
    label: str
    link: int
    family: str
    printed: bool
    method: str                     # how the mass model was built
    flags: tuple[str, ...]
    volume_solid_m3: float
    volume_core_m3: float           # sparse-infill core (0 for bought parts and solid prints)
    volume_material_m3: float       # predicted volume of plastic: V_solid - (1 - infill) V_core
    area_core_m2: float
    inertial: Inertial              # about the part COM, body axes, COM in the body frame
    solid: Inertial                 # the same solid at full density (printed) or catalogue mass (bought)
    core: Inertial | None           # the core at full density (None if empty)
    overlap: Inertial | None        # extra plastic where the infill overlaps the perimeters (layers model)
    bbox_m: tuple[tuple[float, float, float], tuple[float, float, float]]


CORE_METHODS = ("layers", "occ-offset", "voxel")


def find_core(solid, mesh, R, pm: PrintModel, layer_height_mm: float, first: str = "layers"):
    """The core by the first method that works, in the order of :data:`CORE_METHODS` starting at ``first``.

    Returns (Core, flags): a flag names every method that failed and why.
    """
    from OCP.Standard import Standard_Failure
    flags = []
    order = CORE_METHODS[CORE_METHODS.index(first):]
    for method in order:
        try:
            if method == "layers":
                return layer_core(mesh, R, pm, layer_height_mm), flags
            if method == "occ-offset":
                return occ_core(solid, R.T @ np.array([0.0, 0.0, 1.0]), pm), flags
            return voxel_core(mesh, R, pm), flags
        except (ValueError, Standard_Failure) as exc:   # OCC errors surface as Standard_Failure
            flags.append(f"core:{method} failed ({str(exc) or type(exc).__name__})")
    raise ValueError("; ".join(flags))


def part_mass(part, pm: PrintModel, mesh=None, layer_height_mm: float = 0.2, core_method: str = "layers",
              props: VolumeProps | None = None) -> PartMass:
    """Mass properties of one :class:`cad.part.PartSpec`.

    ``mesh``: its tessellation in mm (trimesh), needed by the ``layers`` and ``voxel`` core models; ``props``:
    its B-rep volume properties when already known (:func:`solid_volume_props`).
    """
    solid = part.solid
    props = props if props is not None else solid_volume_props(solid)
    if props.volume_mm3 <= 0:
        raise BuildError(f"part {part.label}: mass model failed: B-rep volume {props.volume_mm3!r} mm^3")
    bb = solid.bounding_box()
    bbox = (tuple(units.length_m(np.array([bb.min.X, bb.min.Y, bb.min.Z]))),
            tuple(units.length_m(np.array([bb.max.X, bb.max.Y, bb.max.Z]))))
    V = units.volume_m3(props.volume_mm3)
    if not part.printed:
        if part.mass_kg is None or part.mass_kg <= 0:
            raise BuildError(f"part {part.label}: bought part without a positive catalogue mass_kg")
        full = props.inertial(part.mass_kg / V)
        return PartMass(part.label, part.link, part.family, False,
                        "catalogue mass, uniform density over its CAD geometry (OCC)", (), V, 0.0, V, 0.0,
                        full, full, None, None, bbox)
    R = rotation_matrix(part.print_rotation)
    try:
        core, flags = find_core(solid, mesh, R, pm, layer_height_mm, core_method)
    except ValueError as exc:
        raise BuildError(f"part {part.label}: mass model failed: every core model failed: {exc}") from exc
    full = props.inertial(pm.density_kg_m3)
    items = [full]
    overlap = core.overlap.inertial(pm.density_kg_m3) if core.overlap is not None else None
    V_over = units.volume_m3(core.overlap.volume_mm3) if core.overlap is not None else 0.0
    if overlap is not None:
        items.append(overlap)
    how = {"layers": "slicer-like layers (mesh sections shrunk by the side walls, top/bottom skins, "
                     "infill overlap added)",
           "occ-offset": "B-rep uniform inward offset by the side wall, top/bottom erosion (OCC)",
           "voxel": "voxel erosion of the mesh (fallback)"}[core.method]
    if core.props is None:
        flags.append("core:empty (walls only: prints solid)")
        return PartMass(part.label, part.link, part.family, True, f"solid, no sparse core; {how}",
                        tuple(flags), V, 0.0, V + V_over, 0.0, combine(items), full, None, overlap, bbox)
    if not 0 < core.props.volume_mm3 < props.volume_mm3:
        raise BuildError(f"part {part.label}: mass model failed: core volume {core.props.volume_mm3!r} mm^3 "
                         f"not inside (0, {props.volume_mm3!r})")
    core_in = core.props.inertial(pm.density_kg_m3)
    items.append(core_in.scaled_mass(-(1.0 - pm.infill_fraction)))
    net = combine(items)
    Vc = units.volume_m3(core.props.volume_mm3)
    method = f"B-rep solid minus (1 - {pm.infill_fraction:g} infill) x core; core by {how}"
    return PartMass(part.label, part.link, part.family, True, method, tuple(flags), V, Vc,
                    V - (1.0 - pm.infill_fraction) * Vc + V_over, units.area_m2(core.area_mm2), net, full, core_in,
                    overlap, bbox)


def rod_inertial(mass_kg: float, a_m, b_m, radius_m: float) -> Inertial:
    """A uniform solid rod from a to b [m]: I = m (3 r^2 + l^2) / 12 across, m r^2 / 2 along."""
    a, b = np.asarray(a_m, dtype=float), np.asarray(b_m, dtype=float)
    d = b - a
    length = float(np.linalg.norm(d))
    u = d / length
    P = np.outer(u, u)
    I = mass_kg * (3 * radius_m**2 + length**2) / 12 * (np.eye(3) - P) + mass_kg * radius_m**2 / 2 * P
    return make_inertial(mass_kg, (a + b) / 2, I)


def link_of_station(p: Params, s_mm: float) -> int:
    """The kinematic link at station s: 0 ahead of joint 1, j between joint j and joint j+1."""
    return int(sum(1 for sj in layout.joint_stations_mm(p) if s_mm >= sj))


def cable_masses(p: Params) -> list[PartMass]:
    """The capstan cables as line masses along their rest routes (swiftfin.layout.geometry.cable_routes), one entry per
    link a route crosses: segments are cut at the joint stations and each piece is a thin rod of the cable's
    diameter and ``cable.linear_density_g_m``. The wraps on the spools (about ``spool.wraps`` turns of
    ``pi x drum diameter`` per cable) are added to the head as a ring at the spool axis."""
    rho_l = p.cable.linear_density_g_m / 1000.0            # kg/m
    r = units.length_m(p.cable.diameter_mm / 2)
    js = layout.joint_stations_mm(p)
    pieces: dict[int, list[Inertial]] = {}
    for route in layout.cable_routes(p):
        pts = np.asarray(route.points_mm, dtype=float)
        for a, b in zip(pts[:-1], pts[1:]):
            cuts = sorted({0.0, 1.0, *[(-sj - a[0]) / (b[0] - a[0]) for sj in js
                                       if b[0] != a[0] and 0.0 < (-sj - a[0]) / (b[0] - a[0]) < 1.0]})
            for t0, t1 in zip(cuts[:-1], cuts[1:]):
                pa, pb = a + t0 * (b - a), a + t1 * (b - a)
                length_m = units.length_m(float(np.linalg.norm(pb - pa)))
                if length_m <= 0:
                    continue
                link = link_of_station(p, -0.5 * (pa[0] + pb[0]))
                pieces.setdefault(link, []).append(
                    rod_inertial(rho_l * length_m, units.length_m(pa), units.length_m(pb), r))
    for mp in layout.motor_placements(p):
        R = units.length_m(p.spool.drum_diameter_mm / 2)
        m = rho_l * 2 * p.spool.wraps * 2 * math.pi * R       # two cable ends share the drum
        c = units.length_m(np.array([mp.x_mm, 0.0, mp.z_cable_mm]))
        pieces.setdefault(0, []).append(make_inertial(m, c, m * R**2 * np.diag([0.5, 0.5, 1.0])))
    out = []
    for link, items in sorted(pieces.items()):
        it = combine(items)
        pts = np.array([i.com for i in items])
        bbox = (tuple(pts.min(axis=0) - r), tuple(pts.max(axis=0) + r))
        out.append(PartMass(f"cables_link_{link}", link, "cable", False,
                            "line mass: cable.linear_density_g_m along swiftfin.layout.geometry.cable_routes (thin rods) plus the "
                            "drum wraps", (), 0.0, 0.0, 0.0, 0.0, it, it, None, None, bbox))
    return out


def _channel_centre_line(ch, n_arc: int = 33) -> np.ndarray:
    from swiftfin.cad.guide import arc_points
    mid = arc_points(ch, n_arc) if ch.angle_rad > 1e-9 else np.array([ch.t1])
    return np.vstack([np.asarray(ch.p_in, float), mid, np.asarray(ch.p_out, float)])


def _clip_polyline_x(pts: np.ndarray, x_lo: float, x_hi: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """Pieces of a polyline with x inside [x_lo, x_hi]."""
    out = []
    for a, b in zip(pts[:-1], pts[1:]):
        if b[0] == a[0]:
            t0, t1 = (0.0, 1.0) if x_lo <= a[0] <= x_hi else (1.0, 1.0)
        else:
            ta, tb = (x_lo - a[0]) / (b[0] - a[0]), (x_hi - a[0]) / (b[0] - a[0])
            t0, t1 = max(0.0, min(ta, tb)), min(1.0, max(ta, tb))
        if t1 > t0:
            out.append((a + t0 * (b - a), a + t1 * (b - a)))
    return out


def ptfe_tube_masses(p: Params) -> list[PartMass]:
    """The PTFE tube pieces lining the guide channels, as thin rods along each channel's centre line (line, arc,
    line of :class:`cad.guide.Channel`) clipped to its block's length, one entry per link. A tube is a hollow
    cylinder: mass rho pi (OD^2 - ID^2) / 4 per metre; its inertia across is taken as a solid rod's of the outer
    radius scaled to that mass (the radial term is < 1e-3 of the total for a piece longer than 5 OD)."""
    from swiftfin.cad.guide import guide_blocks
    g = p.guides
    r_o, r_i = g.ptfe_tube_od_mm / 2, g.ptfe_tube_id_mm / 2
    rho_l = g.ptfe_density_kg_m3 * math.pi * units.length_m(1.0) ** 2 * (r_o**2 - r_i**2)   # kg/m
    pieces: dict[int, list[Inertial]] = {}
    ends: dict[int, list[np.ndarray]] = {}
    for block in guide_blocks(p):
        x_lo, x_hi = block.x_mm
        for ch in block.channels:
            for a, b in _clip_polyline_x(_channel_centre_line(ch), x_lo, x_hi):
                length_m = units.length_m(float(np.linalg.norm(b - a)))
                if length_m <= 0:
                    continue
                link = link_of_station(p, -0.5 * (a[0] + b[0]))
                ends.setdefault(link, []).extend([units.length_m(a), units.length_m(b)])
                pieces.setdefault(link, []).append(
                    rod_inertial(rho_l * length_m, units.length_m(a), units.length_m(b), units.length_m(r_o)))
    out = []
    for link, items in sorted(pieces.items()):
        it = combine(items)
        pts = np.array(ends[link])
        pad = units.length_m(r_o)
        out.append(PartMass(f"ptfe_tube_link_{link}", link, "ptfe", False,
                            f"line mass: guides.ptfe_density_kg_m3 x pi (OD^2 - ID^2) / 4 = {1000 * rho_l:.3g} g/m "
                            "along the guide channels (cad.guide.guide_blocks), clipped to each block",
                            (), 0.0, 0.0, 0.0, 0.0, it, it, None, None,
                            (tuple(pts.min(axis=0) - pad), tuple(pts.max(axis=0) + pad))))
    return out


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


def envelope_section_mm(p: Params, s_mm):
    """Outer half-width and half-height of the skinned body at station s [mm] (0 outside the hull)."""
    s = np.asarray(s_mm, dtype=float)
    inside = (s >= 0) & (s <= layout.hull_end_mm(p))
    a = np.where(inside, layout.naca_half_width_mm(p, s), 0.0)
    return a, p.body.height_to_width * a


def envelope_volume_mm3(p: Params, s0_mm: float, s1_mm: float, n: int = 4001) -> tuple[float, float]:
    """Volume [mm^3] and station of the centroid [mm] of the skinned body between two stations (Simpson)."""
    from scipy.integrate import simpson
    s = np.linspace(s0_mm, s1_mm, n)
    a, b = envelope_section_mm(p, s)
    area = np.pi * a * b
    V = float(simpson(area, x=s))
    return V, (float(simpson(area * s, x=s)) / V if V > 0 else 0.5 * (s0_mm + s1_mm))


def envelope_inertial(p: Params, s0_mm: float, s1_mm: float, density_kg_m3: float, n: int = 400) -> Inertial:
    """The hull's closed outer envelope between stations s0 and s1 as a uniform body (elliptical slices of
    :func:`envelope_section_mm`, each a thin elliptic disc: I_xx = m (a^2 + b^2) / 4, I_yy = m (b^2 / 4 + ds^2 / 12),
    I_zz = m (a^2 / 4 + ds^2 / 12)), body frame, SI."""
    edges = np.linspace(s0_mm, s1_mm, n + 1)
    mids, ds = 0.5 * (edges[1:] + edges[:-1]), (s1_mm - s0_mm) / n
    a, b = envelope_section_mm(p, mids)
    a_m, b_m, ds_m = units.length_m(a), units.length_m(b), units.length_m(ds)
    m = density_kg_m3 * math.pi * a_m * b_m * ds_m
    items = [make_inertial(mi, (-units.length_m(si), 0.0, 0.0),
                           np.diag([mi * (ai**2 + bi**2) / 4, mi * (bi**2 / 4 + ds_m**2 / 12),
                                    mi * (ai**2 / 4 + ds_m**2 / 12)]))
             for mi, si, ai, bi in zip(m, mids, a_m, b_m) if mi > 0]
    return combine(items)


def trim_ballast(p: Params, mass_kg: float, com_m, volume_m3: float, cob_m, flooded_links) -> dict:
    """The lead ballast that makes the fish neutral (weight = buoyancy) and level (COM under the COB), placed on
    the hull floor (its lowest inside point, for the largest righting lever).

    Neutral: ``M + m = rho_w (V + v)`` with ``v = m / rho_b`` when the ballast sits in a flooded link (it
    displaces water) and ``v = 0`` in a sealed one. Level: ``(M x_com + m x) / (M + m) = (V x_cob + v x) / (V + v)``,
    so ``x = (rho_w V x_cob - M x_com) / (m - rho_w v)``. Returns the numbers and, when no ballast can do it (the
    fish sinks, or the place falls outside the hull), ``possible`` False and the reason."""
    rho_w, rho_b = p.environment.water_density_kg_m3, p.environment.ballast_density_kg_m3
    M, V = float(mass_kg), float(volume_m3)
    x_com, x_cob = float(com_m[0]), float(cob_m[0])
    out = {"ballast_density_kg_m3": rho_b, "excess_buoyancy_kg": rho_w * V - M}
    if rho_w * V - M <= 0:
        return {**out, "possible": False,
                "reason": f"the fish sinks by {M - rho_w * V:.4g} kg: ballast cannot trim it (it needs flotation)"}
    x_m = None
    for in_flooded in (True, False):
        m = (rho_w * V - M) / (1.0 - rho_w / rho_b) if in_flooded else rho_w * V - M
        v = m / rho_b if in_flooded else 0.0
        x_m = (rho_w * V * x_cob - M * x_com) / (m - rho_w * v)
        link = link_of_station(p, -1000.0 * x_m)
        if flooded_links[min(link, len(flooded_links) - 1)] == in_flooded:
            break
    s_mm = -1000.0 * x_m
    r_mm = 1000.0 * (3.0 * m / rho_b / (4.0 * math.pi)) ** (1.0 / 3.0)
    s_lo, s_hi = 0.0, layout.hull_end_mm(p)
    a, b = envelope_section_mm(p, s_mm)
    room = float(min(a, b)) - p.hull.wall_thickness_mm - r_mm
    out.update({"mass_kg": m, "x_m": x_m, "station_fraction": s_mm / p.body.length_mm, "link": link,
                "in_flooded_link": bool(flooded_links[min(link, len(flooded_links) - 1)]),
                "sphere_radius_mm": r_mm})
    if not (s_lo < s_mm < s_hi) or room <= 0:
        return {**out, "possible": False,
                "reason": f"the ballast would have to sit at station {s_mm:.0f} mm ({s_mm / p.body.length_mm:.3f} L), "
                          f"{'outside the hull' if not (s_lo < s_mm < s_hi) else 'where a sphere of it does not fit'}"}
    z_m = -units.length_m(float(b) - p.hull.wall_thickness_mm - r_mm)
    return {**out, "possible": True, "z_m": float(z_m)}


def _ballast_part(p: Params, trim: dict) -> PartMass:
    m, r = trim["mass_kg"], units.length_m(trim["sphere_radius_mm"])
    c = np.array([trim["x_m"], 0.0, trim["z_m"]])
    it = make_inertial(m, c, 0.4 * m * r * r * np.eye(3))
    bbox = (tuple(c - r), tuple(c + r))
    return PartMass("trim_ballast", int(trim["link"]), "ballast", False,
                    "computed: lead sphere (environment.ballast_density_kg_m3) that makes the fish neutral and level "
                    "(exports.massprops.trim_ballast)", (), m / p.environment.ballast_density_kg_m3, 0.0,
                    m / p.environment.ballast_density_kg_m3, 0.0, it, it, None, None, bbox)


def _outside_piece(part, x_end_mm: float, big_mm: float) -> VolumeProps | None:
    """Volume properties of the part of a solid behind the plane x = x_end (None if none of it is)."""
    from build123d import Box, Pos
    cut = Pos(x_end_mm - big_mm / 2, 0, 0) * Box(big_mm, big_mm, big_mm)
    pr = solid_volume_props(_common(_wrapped(part.solid), cut.wrapped))
    return pr if pr.volume_mm3 > 0 else None


def _fin_outside_volume(p: Params, parts, memo=None, meshes: dict | None = None) -> tuple[float, np.ndarray, int, list]:
    """Volume [mm^3], centroid [mm] and link of the parts behind the hull end (the caudal fin), and the volume
    properties of each piece (for the water a flooded link does not carry there)."""
    x_end = -layout.hull_end_mm(p)
    V, first, link, pieces = 0.0, np.zeros(3), -1, []
    for part in parts:
        mesh = (meshes or {}).get(part.label)
        x_min = float(mesh.bounds[0][0]) if mesh is not None else part.solid.bounding_box().min.X
        if x_min - p.export.mesh_tolerance_mm >= x_end:     # the B-rep lies within the mesh tolerance of its mesh
            continue
        big = 4.0 * p.body.length_mm
        pr = memoized(memo, "outside_piece", (part.label,), [x_end, big],
                      lambda part=part: _outside_piece(part, x_end, big))
        if pr is not None:
            V += pr.volume_mm3
            first = first + pr.volume_mm3 * np.asarray(pr.centroid_mm)
            link = max(link, part.link)
            pieces.append(pr)
    return V, (first / V if V > 0 else first), link, pieces


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
    def one(part) -> PartMass:
        mesh = meshes.get(part.label)
        if mesh is None and part.printed:
            mesh = tessellate(part.solid, params.export.mesh_tolerance_mm, params.export.mesh_angular_tolerance_deg)
        try:
            props = memoized(memo, "solid_props", (part.label,), None, lambda: solid_volume_props(part.solid))
            return memoized(memo, "part_mass", (part.label,),
                            [dataclasses.asdict(pm), params.print.layer_height_mm, core_method],
                            lambda: part_mass(part, pm, mesh, params.print.layer_height_mm, core_method, props))
        except ValueError as exc:
            raise BuildError(f"part {part.label}: mass model failed: {exc}") from exc

    out: list[PartMass] = map_parts(one, list(parts), jobs)
    out += cable_masses(params)
    out += ptfe_tube_masses(params)
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

    def displacement(items: list[PartMass]):
        link_V, link_cob, water = [], [], []
        for j in range(len(bounds) - 1):
            if not flooded[j]:
                V, s_c = envelope_volume_mm3(params, bounds[j], bounds[j + 1])
                cob = np.array([-s_c, 0.0, 0.0])
                if V_fin > 0 and j == fin_link:
                    cob = (V * cob + V_fin * c_fin) / (V + V_fin)
                    V += V_fin
                link_V.append(V)
                link_cob.append(cob)
                water.append(None)
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

    link_V, link_cob, water = displacement(out)
    trim: dict = {"enabled": bool(params.environment.trim_ballast)}
    if params.environment.trim_ballast:
        V_m3 = units.volume_m3(sum(link_V))
        cob0 = units.length_m(sum(v * c for v, c in zip(link_V, link_cob)) / sum(link_V))
        dry = combine([pt.inertial for pt in out])
        trim.update(trim_ballast(params, dry.mass_kg, dry.com, V_m3, cob0, flooded))
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


# ----------------------------------------------------------------------------------------------- validation gate
def check_tensor(name: str, I, mass: float) -> None:
    """Symmetric, positive-definite, triangle inequalities on the principal moments; raises BuildError."""
    I = np.asarray(I, dtype=float)
    scale = max(np.abs(I).max(), 1e-300)
    if not np.all(np.isfinite(I)) or not math.isfinite(mass) or mass <= 0:
        raise BuildError(f"{name}: mass {mass!r} kg or inertia not finite/positive")
    if np.abs(I - I.T).max() > 1e-9 * scale:
        raise BuildError(f"{name}: inertia tensor not symmetric")
    ev = np.linalg.eigvalsh(I)
    if ev.min() <= 0:
        raise BuildError(f"{name}: inertia tensor not positive-definite (principal moments {ev.tolist()!r})")
    a, b, c = sorted(ev)
    if a + b < c * (1 - 1e-9):
        raise BuildError(f"{name}: principal moments {ev.tolist()!r} break the triangle inequality")


def _inside_box(pt, lo, hi, tol=1e-9) -> bool:
    return bool(np.all(pt >= np.asarray(lo) - tol) and np.all(pt <= np.asarray(hi) + tol))


def validate(params: Params, report: MassReport, parts=None, meshes: dict | None = None, memo=None) -> list[str]:
    """The gate every build passes (issue 3, item 5). Returns the checks done; raises BuildError on a failure.

    * every part and link tensor: symmetric, positive-definite, triangle inequalities;
    * link masses add up to the total (1e-9 relative);
    * every link COM inside the skinned hull envelope (elliptic section at its station) if its station is
      within the hull, else (the tail link with the fin) inside the union of its parts' bounding boxes, and
      always inside that union;
    * OCC and mesh (trimesh) agree within 1 % on volume, on the COM (1 % of the bounding-box diagonal) and on
      the inertia tensor (1 % of its norm), for every part whose mesh is given (the exported STL meshes);
    * the mesh of each part is watertight.
    """
    done = []
    for pt in report.parts:
        check_tensor(f"part {pt.label}", pt.inertial.inertia, pt.inertial.mass_kg)
    for lk in report.links:
        check_tensor(f"link {lk.name}", lk.inertial.inertia, lk.inertial.mass_kg)
    done.append("tensors: symmetric, positive-definite, triangle inequality")
    msum = sum(lk.inertial.mass_kg for lk in report.links)
    if abs(msum - report.total.mass_kg) > 1e-9 * report.total.mass_kg:
        raise BuildError(f"links: masses sum to {msum!r} kg, total is {report.total.mass_kg!r} kg")
    done.append("link masses sum to the total")
    for lk in report.links:
        members = [pt for pt in report.parts if pt.link == lk.index]
        lo = np.min([pt.bbox_m[0] for pt in members], axis=0)
        hi = np.max([pt.bbox_m[1] for pt in members], axis=0)
        c = lk.com_body_m
        if not _inside_box(c, lo, hi):
            raise BuildError(f"link {lk.name}: COM {c.tolist()!r} m outside its parts' bounding box")
        s_mm = -units.length_mm(c[0])
        if 0 <= s_mm <= layout.hull_end_mm(params):
            a, b = envelope_section_mm(params, s_mm)
            y, z = units.length_mm(c[1]), units.length_mm(c[2])
            if a <= 0 or (y / a) ** 2 + (z / b) ** 2 > 1.0:
                raise BuildError(f"link {lk.name}: COM {c.tolist()!r} m outside the hull envelope")
    done.append("link COMs inside the hull envelope (and their parts' bounding boxes)")
    if meshes:
        for pt in report.parts:
            mesh = meshes.get(pt.label)
            if mesh is None:
                continue
            if not mesh.is_watertight:
                raise BuildError(f"part {pt.label}: exported mesh is not watertight")
            part = next((q for q in parts if q.label == pt.label), None) if parts else None
            if part is None:
                continue
            a = memoized(memo, "solid_props", (part.label,), None, lambda part=part: solid_volume_props(part.solid))
            b = mesh_volume_props(mesh)
            if abs(b.volume_mm3 - a.volume_mm3) > GATE_MESH_REL_TOL * a.volume_mm3:
                raise BuildError(f"part {pt.label}: OCC volume {a.volume_mm3:.6g} mm^3 vs mesh {b.volume_mm3:.6g}"
                                 f" mm^3 differ by more than 1 %")
            diag = float(np.linalg.norm(np.asarray(mesh.bounds[1]) - mesh.bounds[0]))
            if np.linalg.norm(np.subtract(a.centroid_mm, b.centroid_mm)) > GATE_MESH_REL_TOL * diag:
                raise BuildError(f"part {pt.label}: OCC and mesh centroids differ by more than 1 % of the size")
            Ia, Ib = np.asarray(a.second_moment_mm5), np.asarray(b.second_moment_mm5)
            if np.linalg.norm(Ia - Ib) > GATE_MESH_REL_TOL * np.linalg.norm(Ia):
                raise BuildError(f"part {pt.label}: OCC and mesh inertia tensors differ by more than 1 %")
        done.append("OCC and mesh agree within 1 % (volume, centroid, inertia); meshes watertight")
    return done


# ----------------------------------------------------------------------------------------------- JSON
def _inertial_dict(it: Inertial, frame: str) -> dict:
    I = it.inertia
    return {"mass_kg": it.mass_kg, "com_m": list(it.com_m), "frame": frame,
            "inertia_kg_m2": {"ixx": I[0, 0], "iyy": I[1, 1], "izz": I[2, 2],
                              "ixy": I[0, 1], "ixz": I[0, 2], "iyz": I[1, 2]},
            "principal_moments_kg_m2": np.linalg.eigvalsh(I).tolist()}


def report_to_dict(params: Params, report: MassReport) -> dict:
    """Everything, as plain JSON types; floats are written by ``json`` with ``repr`` (all digits)."""
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
                      f"{params.hull.flooded_from_joint}): their closed outer envelope, plus the caudal fin behind "
                      "the hull end; flooded links: the solid volume of their parts only (printed parts are closed "
                      "shells), the water inside them moves with them (links[].entrained_water)"),
                  "cob_m": list(report.cob_m), "buoyancy_n": report.buoyancy_n, "weight_n": report.weight_n,
                  "net_buoyancy_n": report.buoyancy_n - report.weight_n,
                  "neutral_mass_kg": report.buoyancy_n / g,
                  "cob_com_distance_m": report.cob_com_distance_m,
                  "cob_above_com_m": report.cob_m[2] - report.total.com_m[2],
                  "com_ahead_of_cob_m": report.total.com_m[0] - report.cob_m[0],
                  "static_pitch_deg": static_pitch_deg(report.total.com_m, report.cob_m)}
    d["trim"] = _jsonable(report.trim)
    return d


def _jsonable(d: dict) -> dict:
    return {k: (float(v) if isinstance(v, (np.floating, float)) else int(v) if isinstance(v, (np.integer,))
                else v) for k, v in d.items()}
