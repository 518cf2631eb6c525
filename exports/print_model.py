"""The mass model of one part: what a printed part weighs, where its mass sits, and its inertia, in SI units.

* **Solid geometry** comes from the exact B-rep (:mod:`swiftfin.exports.brep`); mm -> m in
  :mod:`swiftfin.core.units`.
* **Bought parts** (``PartSpec.printed`` False) carry a catalogue ``mass_kg``; their box/cylinder geometry is
  taken as a uniform-density body scaled to that mass.
* **Printed parts** are not solid. Mass model ``m = rho * (V_solid - (1 - infill) * V_core + V_extra)``: the B-rep
  solid minus ``(1 - infill)`` times the *core*, the region the slicer fills with sparse infill; the core's
  first and second moments are subtracted the same way (inertia about the part's COM by the parallel-axis
  theorem, :func:`combine`). The side walls are ``w = line_width / 2 + (perimeters - 1/2) * spacing``
  (:func:`perimeter_inset_mm`: where the slicer's infill begins), the skins
  ``t_top = top_layers * layer_height`` and ``t_bottom = bottom_layers * layer_height``, in the part's print
  orientation (``PartSpec.print_rotation``). Three core models, tried in this order (:data:`CORE_METHODS`):

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
     print (w = 1.24 mm > t = 0.8/1.0 mm) it under-predicts the core of a 40 x 30 x 20 mm block by about 5 % and
     over-predicts its printed volume by 6 % against PrusaSlicer, hence second. Used where the mesh is not a
     manifold.
  3. ``voxel``: voxel erosion of the mesh in print orientation (a horizontal disc of radius ``w`` and a
     vertical segment ``[-t_bottom, t_top]`` as the structuring element); coarse (surface voxels make the core
     a few % large) but it never fails.

  Every method that fails is named in the part's flags. An empty core (walls thinner than two side walls,
  e.g. the 2 mm hull shells) is legitimate: the part prints solid, as the slicer prints it.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core import units
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.exports.brep import VolumeProps, _props, _wrapped, solid_area_mm2, solid_volume_props
from swiftfin.exports.inertia import Inertial, combine
from swiftfin.exports.parallel import memoized  # noqa: F401  re-exported for the mass model


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
def extrusion_spacing_mm(width_mm: float, layer_height_mm: float) -> float:
    """Centre-to-centre distance of two touching extrusions of ``width`` laid ``layer_height`` high: the bead is
    a rectangle with semicircular sides, so neighbours overlap by ``h (1 - pi / 4)`` (PrusaSlicer's
    ``Flow::spacing``)."""
    return width_mm - layer_height_mm * (1.0 - math.pi / 4.0)


def perimeter_inset_mm(perimeters: int, width_mm: float, layer_height_mm: float) -> float:
    """How far inside the outline the infill begins: the external perimeter's centre line lies half a width in,
    each further loop one spacing further, and the infill's boundary half a spacing beyond the last loop
    (PrusaSlicer's PerimeterGenerator), ``w / 2 + (n - 1/2) s``. With 3 loops of 0.45 mm at 0.2 mm layers that
    is 1.243 mm, not ``n w`` = 1.35 mm. Measured on the split spool's drum: its core is 60.4 mm^2 by ``n w``,
    66.8 mm^2 by this inset and over 70 mm^2 with the overlap the slicer counts, and PrusaSlicer fills it sparse
    (the model with ``n w`` filled it solid and over-predicted the part by 8.4 %; now +1.3 %)."""
    if perimeters <= 0:
        return 0.0
    s = extrusion_spacing_mm(width_mm, layer_height_mm)
    return width_mm / 2.0 + (perimeters - 0.5) * s


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
        return cls(perimeter_inset_mm(pr.perimeters, pr.line_width_mm, pr.layer_height_mm),
                   pr.top_layers * pr.layer_height_mm,
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
default (70 mm^2), which exports/slicer.py leaves at its default. A region is measured as the slicer measures it:
grown by the infill overlap (:data:`INFILL_OVERLAP_FRACTION`), which its fill surfaces include."""


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


SECTION_SIMPLIFY_MM = 0.005
"""Each layer's section drops the vertices that lie closer than this to the line through their neighbours [mm]
(manifold3d's ``CrossSection.simplify``, as its documentation recommends before offsetting): a tenth of the
export's chord tolerance, far under a printed line, and the offsets that follow cost by the vertices (the
head's rear upper half 2.6 -> 1.0 s; its core volume moves by 2e-4, the fin's by 5e-4, a spool's by 4e-6)."""


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
    sections = [man.slice((i + 0.5) * h).simplify(SECTION_SIMPLIFY_MM) for i in range(n)]
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
        for k in [*range(1, nt + 1), *range(-1, -nb - 1, -1)]:
            if core.is_empty():
                break                              # a skin layer: nothing left to intersect
            core = core ^ (sections[i + k] if 0 <= i + k < n else empty)
        if EXTERNAL_INFILL_MARGIN_MM > 0 and not core.is_empty():
            skin = inner - core
            if not skin.is_empty():
                core = core - skin.offset(EXTERNAL_INFILL_MARGIN_MM, m3.JoinType.Round, 2.0, 64)
        # the slicer measures a region against the threshold with the infill's overlap on the perimeters grown
        # onto it (its fill surfaces reach into the last loop by the overlap)
        pieces = ([c for c in core.decompose()
                   if c.offset(o, m3.JoinType.Round, 2.0, 64).area() >= SOLID_INFILL_BELOW_AREA_MM2]
                  if not core.is_empty() else [])
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


def core_key(pm: PrintModel, layer_height_mm: float, print_rotation) -> list:
    """What a part's layer core depends on besides its mesh (JSON): the print model, the layer height and the
    print orientation; the key words under which the application stores it (stage ``part_core``)."""
    return [dataclasses.asdict(pm), float(layer_height_mm), [float(a) for a in print_rotation]]


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
              props: VolumeProps | None = None, core: Core | None = None) -> PartMass:
    """Mass properties of one :class:`cad.part.PartSpec`.

    ``mesh``: its tessellation in mm (trimesh), needed by the ``layers`` and ``voxel`` core models; ``props``:
    its B-rep volume properties when already known (:func:`solid_volume_props`); ``core``: its layer core when
    already known (:func:`layer_core` of this mesh in this orientation: the application's stage cache).
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
    flags: list[str] = []
    if core is None:
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
