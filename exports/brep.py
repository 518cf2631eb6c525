"""The one place where B-rep solids become numbers: OpenCascade's volume properties and its tessellation.

Both the exporters (STL, 3MF, link meshes) and the mass model use these functions, so that a part's exported
mesh and the mesh its mass was checked against are the same triangles, and every B-rep volume is integrated
the same way. The kernel (OCP) is imported inside the functions.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.cad.kernel import VOLUME_EPS
from swiftfin.core import units
from swiftfin.exports.inertia import Inertial, make_inertial


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh in millimetres: ``vertices`` (n, 3) float64, ``faces`` (m, 3) int64, outward winding."""
    vertices: np.ndarray
    faces: np.ndarray

    def transformed(self, matrix: np.ndarray) -> "Mesh":
        m = np.asarray(matrix, dtype=float)
        v = self.vertices @ m[:3, :3].T + m[:3, 3]
        return Mesh(v, self.faces)

    @property
    def volume_mm3(self) -> float:
        """Signed volume (divergence theorem); positive for outward winding."""
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)

    @property
    def area_mm2(self) -> float:
        a, b, c = (self.vertices[self.faces[:, k]] for k in range(3))
        return float(np.linalg.norm(np.cross(b - a, c - a), axis=1).sum() / 2.0)

    @property
    def bbox_mm(self) -> tuple[np.ndarray, np.ndarray]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)


# --------------------------------------------------------------------------------------------- tessellation
def tessellate(shape, tolerance_mm: float, angular_tolerance_deg: float) -> Mesh:
    """Welded triangle mesh of a build123d shape (or a TopoDS_Shape) in its own coordinates [mm]."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS

    topo = getattr(shape, "wrapped", shape)
    BRepTools.Clean_s(topo)  # forget any triangulation made with other settings: same input, same mesh
    BRepMesh_IncrementalMesh(topo, tolerance_mm, False, math.radians(angular_tolerance_deg), False)
    verts: list[np.ndarray] = []
    tris: list[np.ndarray] = []
    offset = 0
    exp = TopExp_Explorer(topo, TopAbs_FACE)
    while exp.More():
        face = TopoDS.Face(exp.Current()) if hasattr(TopoDS, "Face") else TopoDS.Face_s(exp.Current())
        loc = TopLoc_Location()
        tri = BRep_Tool.Triangulation_s(face, loc)
        exp.Next()
        if tri is None:
            continue
        trsf = loc.Transformation()
        n = tri.NbNodes()
        pts = np.empty((n, 3))
        for i in range(n):
            q = tri.Node(i + 1).Transformed(trsf)
            pts[i] = (q.X(), q.Y(), q.Z())
        m = tri.NbTriangles()
        idx = np.empty((m, 3), dtype=np.int64)
        for i in range(m):
            idx[i] = tri.Triangle(i + 1).Get()
        idx -= 1
        if face.Orientation() == TopAbs_REVERSED:
            idx = idx[:, ::-1]
        verts.append(pts)
        tris.append(idx + offset)
        offset += n
    if not tris:
        raise ValueError("the shape has no faces to tessellate")
    pts = np.concatenate(verts)
    lo, hi = _exact_box(topo)
    # no point of the surface lies outside its exact bounding box: a mesh node there is the mesher's error (seen
    # at a revolved nose's apex cut through its axis, 0.5 mm past the cut plane, which lifted the half off the bed)
    pts = np.clip(pts, lo, hi)
    return close_pinholes(weld(pts, np.concatenate(tris)), tolerance_mm)


def _exact_box(topo) -> tuple[np.ndarray, np.ndarray]:
    """The shape's bounding box from its geometry (not its triangulation) [mm]."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(topo, box, False, False)
    lo_p, hi_p = box.CornerMin(), box.CornerMax()
    x0, y0, z0, x1, y1, z1 = lo_p.X(), lo_p.Y(), lo_p.Z(), hi_p.X(), hi_p.Y(), hi_p.Z()
    gap = 1e-7
    return np.array([x0 - gap, y0 - gap, z0 - gap]), np.array([x1 + gap, y1 + gap, z1 + gap])


WELD_TOLERANCE_MM = 1e-4
"""Mesh nodes closer than this are one node. OpenCascade leaves clusters of nodes a few 1e-6 mm apart where many
faces meet at one point (a revolved cutter's pivot on a link plate's face); written as float32 (3e-5 mm steps at
500 mm) they fall on one point and the STL's edges pinch. 1e-4 mm is above both and far below any feature."""


def weld(vertices: np.ndarray, faces: np.ndarray, tolerance_mm: float = WELD_TOLERANCE_MM) -> Mesh:
    """Merge vertices within ``tolerance_mm`` of each other (chains of them: connected components of the pairs,
    each represented by its lowest-numbered vertex) and drop degenerate triangles."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    v = np.asarray(vertices, dtype=float) + 0.0  # + 0.0 turns -0.0 into 0.0
    pairs = cKDTree(v).query_pairs(tolerance_mm, output_type="ndarray")
    n = len(v)
    if len(pairs):
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        first = np.full(label.max() + 1, n, dtype=np.int64)
        np.minimum.at(first, label, np.arange(n))
        rep = first[label]
    else:
        rep = np.arange(n)
    f = rep[np.asarray(faces)]
    keep = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])
    f = f[keep]
    used = np.unique(f)
    remap = np.full(n, -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return Mesh(v[used], remap[f])


MAX_PINHOLE_EDGES = 64
"""More open edges than this is not a pinhole or two the mesher left but an open shape: left to the checks, which
refuse it. (The bay guide's hole had 7.)"""


def close_pinholes(mesh: Mesh, size_mm: float) -> Mesh:
    """``mesh`` with every hole smaller than ``size_mm`` across (its boundary loop's bounding box diagonal) closed
    by a fan of triangles, when that leaves it closed (:func:`is_closed`); otherwise ``mesh`` unchanged.

    Why: a boolean can leave a sliver face on the B-rep (a seeded design's bay guide, 2026-11-29: a cylindrical face
    of 1.7 x 0.7 um, area ~0, where a channel meets a plane), which OpenCascade's mesher leaves untriangulated; the
    mesh then has a hole a few micrometres across (7 open edges) and the build refused the part. A hole smaller
    than the chordal tolerance is the mesher's, not the shape's: its fan lies within the tolerance of the surface.
    A closed mesh comes back as it was."""
    f = mesh.faces
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64)
    n = len(mesh.vertices)
    open_mask = ~np.isin(e[:, 0] * n + e[:, 1], e[:, 1] * n + e[:, 0])   # no twin running the other way
    if not open_mask.any() or open_mask.sum() > MAX_PINHOLE_EDGES:
        return mesh
    nxt: dict[int, int] = {}
    for a, b in e[open_mask].tolist():
        if b in nxt:            # two open edges leave one vertex: not a simple pinhole
            return mesh
        nxt[b] = a              # the fill runs each open edge backwards
    fill, seen = [], set()
    for start in list(nxt):
        if start in seen:
            continue
        loop, v = [], start
        while v not in seen:
            seen.add(v)
            loop.append(v)
            v = nxt.get(v, -1)
            if v < 0:
                return mesh
        if v != start or len(loop) < 3:
            return mesh
        pts = mesh.vertices[loop]
        if float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) >= size_mm:
            return mesh
        fill += [(loop[0], loop[i], loop[i + 1]) for i in range(1, len(loop) - 1)]
    closed = Mesh(mesh.vertices, np.vstack([f, np.asarray(fill, dtype=np.int64)]))
    return closed if is_closed(closed) else mesh


def is_closed(mesh: Mesh) -> bool:
    """Every edge shared by exactly two triangles, in opposite directions (closed, consistently wound)."""
    f = mesh.faces
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed, counts = np.unique(e, axis=0, return_counts=True)
    if np.any(counts != 1):
        return False
    rev = np.unique(e[:, ::-1], axis=0)
    return len(rev) == len(directed) and bool(np.all(rev == directed))


# --------------------------------------------------------------------------------------------- volume properties
@dataclass(frozen=True)
class VolumeProps:
    """Volume [mm^3], centroid [mm] and second moment of volume about the centroid [mm^5] (inertia / density)."""
    volume_mm3: float
    centroid_mm: tuple[float, float, float]
    second_moment_mm5: tuple[tuple[float, float, float], ...]

    def inertial(self, density_kg_m3: float) -> Inertial:
        """As a uniform body of the given density, in SI."""
        m = density_kg_m3 * units.volume_m3(self.volume_mm3)
        return make_inertial(m, units.length_m(np.asarray(self.centroid_mm)),
                             density_kg_m3 * units.second_moment_m5(np.asarray(self.second_moment_mm5)))


def _props(volume, centroid, second) -> VolumeProps:
    return VolumeProps(float(volume), tuple(float(v) for v in centroid),
                       tuple(tuple(float(v) for v in row) for row in np.asarray(second)))


def _wrapped(shape):
    return shape.wrapped if hasattr(shape, "wrapped") else shape




def solid_volume_props(shape) -> VolumeProps:
    """B-rep volume properties (OpenCascade, adaptive Gauss integration to :data:`VOLUME_EPS`) in mm."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.VolumeProperties_s(_wrapped(shape), g, VOLUME_EPS)
    c = g.CentreOfMass()
    M = g.MatrixOfInertia()
    second = [[M.Value(i, j) for j in (1, 2, 3)] for i in (1, 2, 3)]
    return _props(g.Mass(), (c.X(), c.Y(), c.Z()), second)


def solid_area_mm2(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    g = GProp_GProps()
    BRepGProp.SurfaceProperties_s(_wrapped(shape), g)
    return float(g.Mass())


def mesh_volume_props(mesh) -> VolumeProps:
    """Volume properties of a closed triangle mesh (trimesh), density 1, about its centroid."""
    mesh = mesh.copy()
    mesh.density = 1.0
    return _props(mesh.volume, mesh.center_mass, mesh.moment_inertia)


def tessellate_trimesh(shape, tolerance_mm: float, angular_tolerance_deg: float):
    """The shape as a trimesh.Trimesh (mm): the same triangles as the exported STL (:func:`tessellate`)."""
    import trimesh
    m = tessellate(shape, tolerance_mm, angular_tolerance_deg)
    return trimesh.Trimesh(np.asarray(m.vertices, dtype=float), np.asarray(m.faces, dtype=np.int64), process=False)
