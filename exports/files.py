"""STEP, STL and 3MF writers for one part, deterministic byte for byte (STEP: with a fixed header timestamp).

The mesh comes from OpenCascade's incremental mesher with the parameter file's linear and angular deflection
(``export.mesh_tolerance_mm``, ``export.mesh_angular_tolerance_deg``). Any triangulation already stored on the
shape is removed first, so a solid fresh from a part family and the same solid read back from the cache give
the same triangles. Vertices shared by neighbouring faces are welded, so the mesh is closed (watertight) when
the B-rep is.

Print orientation (cad/part.py): the part is turned by ``PartSpec.print_rotation`` = build123d
``Rotation(rx, ry, rz)`` (intrinsic X, then Y, then Z, degrees) about the body-frame origin, dropped onto the
bed (min z = 0) and centred on the bed in x and y (``print.bed_x_mm``, ``print.bed_y_mm``), so that a slicer
opening the 3MF finds it in the middle of the plate.

STL: binary, a fixed 80-byte header naming the part, float32 as the format requires.
3MF: the core specification's minimal package ([Content_Types].xml, _rels/.rels, 3D/3dmodel.model) in
millimetres, written with :mod:`zipfile` with fixed entry dates so that the same mesh gives the same bytes.
"""
from __future__ import annotations

import io
import re
import struct
import time
import zipfile
from dataclasses import dataclass
from xml.sax.saxutils import escape

import numpy as np

from swiftfin.exports.slicer import slicer_config
from swiftfin.exports.brep import Mesh, is_closed, solid_volume_props, tessellate, weld  # noqa: F401  re-exported

STEP_TIMESTAMP = "2000-01-01T00:00:00"   # fixed STEP header date: same part, same STEP bytes
ZIP_DATE = (1980, 1, 1, 0, 0, 0)         # earliest date a zip entry can carry


# --------------------------------------------------------------------------------------------- orientation
def rotation_matrix(print_rotation: tuple[float, float, float]) -> np.ndarray:
    """4x4 matrix of build123d ``Rotation(rx, ry, rz)`` (intrinsic XYZ, degrees)."""
    import build123d as bd

    t = bd.Rotation(*[float(a) for a in print_rotation]).wrapped.Transformation()
    m = np.eye(4)
    for i in range(3):
        for j in range(4):
            m[i, j] = t.Value(i + 1, j + 1)
    return m


def print_transform(mesh_at_rest: Mesh, print_rotation, bed_x_mm: float, bed_y_mm: float) -> np.ndarray:
    """4x4 body frame -> print frame: rotate, drop onto the bed (min z = 0), centre on the bed in x, y."""
    r = rotation_matrix(print_rotation)
    v = mesh_at_rest.vertices @ r[:3, :3].T
    lo, hi = v.min(axis=0), v.max(axis=0)
    shift = np.array([bed_x_mm / 2 - (lo[0] + hi[0]) / 2, bed_y_mm / 2 - (lo[1] + hi[1]) / 2, -lo[2]])
    t = np.eye(4)
    t[:3, 3] = shift
    return t @ r


def move_shape(shape, matrix: np.ndarray):
    """A copy of a build123d shape moved by a rigid 4x4 matrix (label kept)."""
    import build123d as bd
    from OCP.gp import gp_Trsf

    trsf = gp_Trsf()
    m = np.asarray(matrix, dtype=float)
    trsf.SetValues(*[float(m[i, j]) for i in range(3) for j in range(4)])
    moved = shape.moved(bd.Location(trsf))
    moved.label = shape.label
    return moved


# --------------------------------------------------------------------------------------------- writers
def stl_bytes(mesh: Mesh, name: str) -> bytes:
    """Binary STL, float32, fixed header."""
    v = mesh.vertices[mesh.faces].astype(np.float32)           # (m, 3, 3)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]).astype(np.float64)
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, ln, out=np.zeros_like(n), where=ln > 0).astype(np.float32)
    rec = np.zeros(len(v), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rec["n"] = n
    rec["v"] = v
    header = f"swiftfin {name} (mm)".encode("ascii", "replace")[:80].ljust(80, b" ")
    return header + struct.pack("<I", len(v)) + rec.tobytes()


_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    '</Types>\n')
_RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    '</Relationships>\n')


def _model_xml(mesh: Mesh, name: str) -> str:
    v = np.round(mesh.vertices, 6) + 0.0
    vlines = "".join(f'<vertex x="{x:.6f}" y="{y:.6f}" z="{z:.6f}"/>' for x, y, z in v.tolist())
    tlines = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in mesh.faces.tolist())
    nm = escape(name, {'"': "&quot;"})
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<model unit="millimeter" xml:lang="en-US" '
            'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
            f'<metadata name="Title">{nm}</metadata>'
            f'<resources><object id="1" name="{nm}" type="model"><mesh>'
            f"<vertices>{vlines}</vertices><triangles>{tlines}</triangles>"
            '</mesh></object></resources>'
            '<build><item objectid="1"/></build></model>\n')


PRUSA_CONFIG = "Metadata/Slic3r_PE.config"   # where PrusaSlicer keeps a project's print settings in a 3MF


def prusa_config_text(config: dict[str, str]) -> str:
    """PrusaSlicer's project configuration as it stores it in a 3MF: ``; key = value`` lines."""
    return "; generated by swiftfin: the design's print settings ([print])\n" + \
        "".join(f"; {k} = {v}\n" for k, v in sorted(config.items()))


def threemf_bytes(mesh: Mesh, name: str, print_config: dict[str, str] | None = None) -> bytes:
    """A 3MF package (core spec) holding one object, in millimetres, with fixed zip dates. ``print_config``:
    PrusaSlicer settings (exports.slicer.slicer_config) stored as its project configuration, so that opening or
    slicing the 3MF alone uses the design's walls, infill and layers."""
    entries = [("[Content_Types].xml", _CONTENT_TYPES), ("_rels/.rels", _RELS),
               ("3D/3dmodel.model", _model_xml(mesh, name))]
    if print_config:
        entries.append((PRUSA_CONFIG, prusa_config_text(print_config)))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for arcname, text in entries:
            info = zipfile.ZipInfo(arcname, date_time=ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            info.create_system = 3
            z.writestr(info, text.encode("utf-8"), compresslevel=6)
    return buf.getvalue()


def step_bytes(shape, name: str) -> bytes:
    """STEP AP214 of one shape in mm with product name ``name`` and a fixed header timestamp."""
    import build123d as bd

    shape = shape.moved(bd.Location())
    shape.label = name
    buf = io.BytesIO()
    if not bd.export_step(shape, buf, unit=bd.Unit.MM, timestamp=STEP_TIMESTAMP):
        raise RuntimeError(f"STEP export of {name} failed")
    return _renumber_nauo(buf.getvalue())


_NAUO = re.compile(rb"NEXT_ASSEMBLY_USAGE_OCCURRENCE\('[^']*'(.*?)\);", re.DOTALL)


def _renumber_nauo(data: bytes) -> bytes:
    """OpenCascade numbers assembly occurrences with a counter that lives as long as the process, so the
    second STEP written in one run differs from the first; number them 1, 2, ... per file instead, each
    entity on one line (OpenCascade wraps lines by their length, which the number changes)."""
    counter = iter(range(1, 1 << 30))

    def one(m: re.Match) -> bytes:
        rest = re.sub(rb"\r?\n\s*", b"", m.group(1))
        return b"NEXT_ASSEMBLY_USAGE_OCCURRENCE('%d'%s);" % (next(counter), rest)

    return _NAUO.sub(one, data)


# --------------------------------------------------------------------------------------------- one part
@dataclass
class PartExport:
    """Everything written for one part: the rest mesh (body frame, for the assembly checks), the B-rep's
    volume and area, the size in print orientation and the file bytes (printed parts only)."""
    mesh: Mesh
    volume_mm3: float
    area_mm2: float
    print_size_mm: tuple[float, float, float]
    files: dict[str, bytes]
    volume_props: object = None     # exports.brep.VolumeProps of the B-rep (the mass model reuses it)
    print_rotation: tuple[float, float, float] | None = None   # the orientation written (printed parts)
    support_area_mm2: float | None = None      # overhang needing support in it (exports/printability.py)
    orientations: tuple = ()        # (rotation, support area mm^2, fits the bed) of every candidate tried
    thin_walls: tuple = ()          # exports.printability.ThinWall: walls under two perimeters (body frame)
    checks_s: float = 0.0           # seconds of the print checks in it (orientation, wall probe): not CAD work
    bridges: tuple = ()             # exports.printability.Bridge: ceilings spanning over print.max_bridge_mm


LAYERED_WALL_LAYERS = 2
"""The least wall whose thickness lies along the print's vertical, in layers (a plate printed flat: two layers
hold together; one is a film)."""


def export_part(spec, p) -> PartExport:
    """Tessellate one PartSpec and, for a printed part, write its STL, 3MF and STEP in print orientation."""
    e = p.export
    mesh = tessellate(spec.solid, e.mesh_tolerance_mm, e.mesh_angular_tolerance_deg)
    files: dict[str, bytes] = {}
    size = tuple(float(v) for v in (mesh.bbox_mm[1] - mesh.bbox_mm[0]))
    rot, support, tried, thin, checks_s, long_bridges = None, None, (), (), 0.0, ()
    if spec.printed:
        from swiftfin.exports.printability import bridges, thin_walls
        t0 = time.perf_counter()
        rot, support, tried = choose_orientation(spec, mesh, p)
        up = rotation_matrix(rot)[:3, :3].T @ np.array([0.0, 0.0, 1.0])     # the print's vertical, at rest
        thin = tuple(thin_walls(mesh.vertices, mesh.faces, 2 * p.print.line_width_mm, up=up,
                                layered_limit_mm=LAYERED_WALL_LAYERS * p.print.layer_height_mm,
                                bores=spec.meta.get("load_free_bores_mm"), web_limit_mm=p.print.line_width_mm))
        limit = p.print.max_bridge_mm
        long_bridges = tuple(b for b in bridges(mesh.vertices, mesh.faces, limit, up=up) if b.span_mm > limit)
        checks_s = time.perf_counter() - t0
        m = print_transform(mesh, rot, p.print.bed_x_mm, p.print.bed_y_mm)
        pm = mesh.transformed(m)
        size = tuple(float(v) for v in (pm.bbox_mm[1] - pm.bbox_mm[0]))
        files[".stl"] = stl_bytes(pm, spec.label)
        files[".3mf"] = threemf_bytes(pm, spec.label, slicer_config(p))
        files[".step"] = step_bytes(move_shape(spec.solid, m), spec.label)
    props = solid_volume_props(spec.solid)   # the adaptive integration, not Shape.volume's fixed rule
    return PartExport(mesh, props.volume_mm3, float(spec.solid.area), size, files, props, rot, support, tried,
                      thin, checks_s, long_bridges)


def choose_orientation(spec, mesh: Mesh, p):
    """The print orientation of a printed part: its family's own ``print_rotation``, or of the rotations its family
    allows (``spec.meta["print_candidates"]``) the one that needs least support and fits the bed
    (exports/printability.py). Returns (rotation, support area mm^2, every candidate as (rotation, area, fits))."""
    from swiftfin.exports.printability import best_orientation

    own = tuple(float(a) for a in spec.print_rotation)
    cands = [own] + [tuple(float(a) for a in c) for c in spec.meta.get("print_candidates", ()) if tuple(c) != own]
    bed = (p.print.bed_x_mm, p.print.bed_y_mm, p.print.bed_z_mm)
    rot, oh, tried = best_orientation(mesh.vertices, mesh.faces, cands, p.print.support_angle_deg, bed)
    return rot, oh.area_mm2, tuple((r, round(o.area_mm2, 1), fits) for r, o, fits in tried)
