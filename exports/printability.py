"""What a printed part asks of the printer in its print orientation: the area that needs support, the orientation
that needs least, the walls too thin to print and the bridges too long to print (issue 13, item 5).

**Overhang.** A face of the part's mesh in print orientation (bed at z = 0) needs support when it faces down more
steeply than the support angle: its outward normal n has ``n_z < -sin(support_angle)`` with the angle measured
from the vertical (``print.support_angle_deg``; 45 deg: a face at 45 deg from the vertical still prints on its
own, flatter needs support), and it does not lie on the bed. The support area is the sum of those faces' areas,
projected on the bed (what a slicer fills with support). A downward face whose lowest point is within
:data:`BED_CONTACT_MM` of the bed counts as bed contact.

**Orientation.** :func:`best_orientation` tries the part family's candidate rotations (``PartSpec.meta
["print_candidates"]`` if the family offers several, else only its own ``print_rotation``) and keeps the one with the
least support area that fits the bed; ties keep the family's own choice.

**Bridges.** :func:`bridges`: every nearly horizontal ceiling of the part in print orientation and the span the
slicer must string across it from its anchors, against ``print.max_bridge_mm``. Checked on closed forms (a tunnel
spans its width; a ledge twice its reach) and against PrusaSlicer's own bridge threads over the same tunnels.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

BED_CONTACT_MM = 0.05


@dataclass(frozen=True)
class Overhang:
    area_mm2: float                 # projected on the bed
    faces: int
    lowest_mm: float                # height of the lowest overhanging face above the bed
    centre_mm: tuple[float, float, float] | None   # area-weighted centre of the overhang (print frame)


def overhang(vertices: np.ndarray, faces: np.ndarray, support_angle_deg: float) -> Overhang:
    """Support area of a mesh as it lies on the bed (print frame: bed at its minimum z)."""
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    v = v - np.array([0.0, 0.0, v[:, 2].min()])
    tri = v[f]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area2 = np.linalg.norm(cross, axis=1)
    ok = area2 > 0
    n = np.zeros_like(cross)
    n[ok] = cross[ok] / area2[ok, None]
    down = n[:, 2] < -math.sin(math.radians(support_angle_deg))   # the face leans further than the angle
    on_bed = tri[:, :, 2].max(axis=1) <= BED_CONTACT_MM
    need = down & ~on_bed & ok
    proj = 0.5 * np.abs(cross[:, 2])
    area = float(proj[need].sum())
    if not need.any():
        return Overhang(0.0, 0, math.inf, None)
    centres = tri[need].mean(axis=1)
    c = tuple(float(x) for x in (centres * proj[need, None]).sum(axis=0) / max(area, 1e-12))
    return Overhang(area, int(need.sum()), float(tri[need][:, :, 2].min()), c)


def rotation_matrix(rx: float, ry: float, rz: float) -> np.ndarray:
    """R = Rz Ry Rx (degrees), the print rotation convention of exports/files.py."""
    ax, ay, az = (math.radians(a) for a in (rx, ry, rz))
    Rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    Ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    Rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


CANDIDATES: tuple[tuple[float, float, float], ...] = (
    (0.0, 0.0, 0.0), (180.0, 0.0, 0.0), (90.0, 0.0, 0.0), (-90.0, 0.0, 0.0), (0.0, 90.0, 0.0), (0.0, -90.0, 0.0))
"""The six faces of the bounding box down: what :func:`best_orientation` tries for a part that allows any."""


def fits_bed(size_mm, bed_mm) -> bool:
    """Fits the bed allowing a rotation about the vertical (the check of design_rules' bed rule)."""
    dx, dy, dz = size_mm
    bx, by, bz = bed_mm
    if dz > bz:
        return False
    for a in np.linspace(0.0, math.pi / 2, 181):
        if dx * math.cos(a) + dy * math.sin(a) <= bx and dx * math.sin(a) + dy * math.cos(a) <= by:
            return True
    return False


def best_orientation(vertices, faces, candidates, support_angle_deg: float, bed_mm) -> tuple[tuple, Overhang,
                                                                                             list[tuple]]:
    """(rotation, its overhang, [(rotation, overhang) for every candidate]) — the least support that fits the bed;
    the first candidate (the family's own) wins ties within 1 mm^2."""
    v = np.asarray(vertices, dtype=float)
    tried = []
    best = None
    for rot in candidates:
        r = rotation_matrix(*rot)
        w = v @ r.T
        size = w.max(axis=0) - w.min(axis=0)
        oh = overhang(w, faces, support_angle_deg)
        fits = fits_bed(size, bed_mm)
        tried.append((tuple(rot), oh, fits))
        if fits and (best is None or oh.area_mm2 < best[1].area_mm2 - 1.0):
            best = (tuple(rot), oh)
    if best is None:
        best = (tuple(candidates[0]), tried[0][1])
    return best[0], best[1], tried


# ----------------------------------------------------------------------------------------------- thin walls
WALL_PARALLEL_COS = 0.97
"""A probe's ray measures a wall when the face it leaves and the face it reaches are within 14 deg of antiparallel;
between faces at a wider angle it measures the tip of a wedge (a chamfer's edge, a foil's trailing edge), which is
thinner than any limit near its tip whatever the design, and is not a wall."""
PROBE_AREA_PER_SAMPLE_MM2 = 0.25
"""One probe point per this much surface (a 0.5 mm grid), at most :data:`PROBE_MAX_SAMPLES` per part."""
PROBE_MAX_SAMPLES = 200_000
CLUSTER_MM = 1.0
"""Thin probe points closer than this belong to one thin region."""
MIN_THIN_AREA_MM2 = 1.0
"""A thin region of less surface than this (four probe points) is not reported: the tessellation's chords and a
ray that grazes an edge make such specks."""


@dataclass(frozen=True)
class ThinWall:
    """A region of a part whose wall is thinner than ``limit_mm``: its thinnest point and how much surface is thin."""
    thickness_mm: float
    area_mm2: float
    at_mm: tuple[float, float, float]     # the thinnest probe point (the mesh's frame)
    limit_mm: float
    kind: str = "wall"                    # "web": a load-free web between two bores (held to one line width)

    def __str__(self) -> str:
        x, y, z = self.at_mm
        what = "web between bores" if self.kind == "web" else "wall"
        return (f"{self.thickness_mm:.2f} mm {what} (limit {self.limit_mm:.2f}) over {self.area_mm2:.1f} mm^2 at "
                f"({x:.1f}, {y:.1f}, {z:.1f}) mm")


def wall_thickness_samples(vertices: np.ndarray, faces: np.ndarray, seed: int = 0):
    """Probe points on the surface and the wall behind each: a ray from the point into the part along the inward
    normal to the first face it meets (trimesh with Embree). Returns (points, thickness_mm, is_wall, area per
    point mm^2, outward normals), a row per point whose ray met a face; ``is_wall``: the two faces are within
    14 deg of antiparallel."""
    import trimesh
    mesh = trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces), process=False)
    n = int(min(PROBE_MAX_SAMPLES, max(1000, mesh.area / PROBE_AREA_PER_SAMPLE_MM2)))
    points, face_index = trimesh.sample.sample_surface(mesh, n, seed=seed)
    normals = mesh.face_normals[face_index]
    lift = 1e-3                                    # start just inside the surface, so the ray leaves its own face
    origins = points - lift * normals
    hit, ray, tri = mesh.ray.intersects_location(origins, -normals, multiple_hits=False)
    thickness = np.linalg.norm(hit - origins[ray], axis=1) + lift
    is_wall = (mesh.face_normals[tri] * normals[ray]).sum(axis=1) < -WALL_PARALLEL_COS
    return points[ray], thickness, is_wall, mesh.area / n, normals[ray]


WALL_TOLERANCE_MM = 0.005
"""A wall drawn at exactly the limit (the two-line webs between bores) reads a few micrometres under it on the mesh."""
LAYERED_WALL_DEG = 30.0
"""A wall whose thickness runs within this angle of the print's vertical is made of layers, not of lines."""


BORE_SURFACE_MM = 0.1
"""A probe point (or its ray's end) within this of a bore's surface lies on that bore (the mesh's chords stand a
few hundredths inside the true cylinder)."""


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each point (n, 3) to each segment a[k]-b[k] (k, 3): (n, k)."""
    ab = b - a
    t = np.einsum("nkd,kd->nk", points[:, None, :] - a[None], ab) / np.maximum((ab * ab).sum(axis=1), 1e-12)
    q = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - q, axis=2)


def between_bores(points: np.ndarray, hits: np.ndarray, bores) -> np.ndarray:
    """Whether each probe point lies on the surface of one of ``bores`` and its ray ends on another's: the web
    between two bores. ``bores``: ``[[x, y, z], [x, y, z], radius]`` segments (a part's load-free bores)."""
    if not bores or len(points) == 0:
        return np.zeros(len(points), bool)
    a = np.array([s[0] for s in bores], float)
    b = np.array([s[1] for s in bores], float)
    r = np.array([s[2] for s in bores], float)
    on_p = np.abs(_segment_distance(points, a, b) - r[None]) <= BORE_SURFACE_MM
    on_h = np.abs(_segment_distance(hits, a, b) - r[None]) <= BORE_SURFACE_MM
    # two different bores: segments of one channel meet at its tangents, so "different" is "not the same segment
    # and not both ends on segments sharing a point" -- a web needs its two faces on bores that do not touch
    touch = ((np.linalg.norm(b[None] - a[:, None], axis=2) < 1e-6)
             | (np.linalg.norm(a[None] - b[:, None], axis=2) < 1e-6))
    np.fill_diagonal(touch, True)
    pair = (on_p.astype(np.int32) @ (~touch).astype(np.int32)) * on_h
    return pair.any(axis=1)


def thin_walls(vertices: np.ndarray, faces: np.ndarray, limit_mm: float, seed: int = 0,
               up: np.ndarray | None = None, layered_limit_mm: float | None = None,
               bores=None, web_limit_mm: float | None = None) -> list[ThinWall]:
    """The regions of a closed mesh whose walls are thinner than ``limit_mm`` (probe points within
    :data:`CLUSTER_MM` of each other are one region; regions under :data:`MIN_THIN_AREA_MM2` are dropped),
    thinnest first. With ``up`` (the print's vertical, in the mesh's frame) a wall whose thickness runs within
    :data:`LAYERED_WALL_DEG` of it is a stack of layers and is held to ``layered_limit_mm`` instead (a plate printed
    flat is as thick as its layers, whatever the line width). With ``bores`` (the part's load-free bores, see
    :func:`between_bores`) a web between two of them carries no load and is held to ``web_limit_mm`` (one line
    width: the issue's "ridges that carry no load"); its region is of kind "web"."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    points, thickness, is_wall, per_point, normals = wall_thickness_samples(vertices, faces, seed)
    limit = np.full(len(points), float(limit_mm))
    if up is not None and layered_limit_mm is not None:
        u = np.asarray(up, dtype=float) / np.linalg.norm(up)
        layered = np.abs(normals @ u) >= math.cos(math.radians(LAYERED_WALL_DEG))
        limit[layered] = float(layered_limit_mm)
    web = np.zeros(len(points), bool)
    if bores and web_limit_mm is not None:
        cand = np.nonzero(is_wall & (thickness < limit - WALL_TOLERANCE_MM))[0]
        hits = points[cand] - thickness[cand, None] * normals[cand]
        web[cand] = between_bores(points[cand], hits, bores)
        limit[web] = np.minimum(limit[web], float(web_limit_mm))
    thin = np.nonzero(is_wall & (thickness < limit - WALL_TOLERANCE_MM))[0]
    if len(thin) == 0:
        return []
    pairs = cKDTree(points[thin]).query_pairs(CLUSTER_MM, output_type="ndarray")
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(thin), len(thin)))
    _, label = connected_components(graph, directed=False)
    out = []
    for k in np.unique(label):
        members = thin[label == k]
        area = len(members) * per_point
        if area < MIN_THIN_AREA_MM2:
            continue
        i = members[np.argmin(thickness[members])]
        out.append(ThinWall(float(thickness[i]), float(area), tuple(float(v) for v in points[i]), float(limit[i]),
                            "web" if web[i] else "wall"))
    return sorted(out, key=lambda w: w.thickness_mm)


# ----------------------------------------------------------------------------------------------- bridges
BRIDGE_TILT_DEG = 10.0
"""A downward face within this angle of horizontal is laid as a bridge: the slicer strings its first layer across
from wherever there is material below to hold the ends (steeper faces are overhangs, each layer stepping out
from the one below)."""
BRIDGE_SAMPLE_MM = 0.25
"""The bridge's surface and its anchoring edges are sampled this finely."""
MIN_BRIDGE_AREA_MM2 = 1.0
"""A bridge region of less area than this is not reported (the tessellation's slivers)."""


@dataclass(frozen=True)
class Bridge:
    """A downward, nearly horizontal region of a part in its print orientation, and how far it must bridge.

    ``span_mm``: twice the largest distance (in plan) from a point of the region to the nearest edge of it that
    has material below (an anchor): a bridge between two walls W apart spans W; a ledge sticking out L spans 2 L
    (its tip is L from the one anchor, as the middle of a 2 L bridge is). ``inf`` when no edge is anchored: a
    ceiling hanging in mid-air, which only support can start."""
    span_mm: float
    area_mm2: float
    at_mm: tuple[float, float, float]     # farthest from an anchor (a hanging one: its lowest point); mesh frame
    limit_mm: float

    @property
    def hanging(self) -> bool:
        """No edge of it has material below: only support can start it."""
        return math.isinf(self.span_mm)

    def __str__(self) -> str:
        x, y, z = self.at_mm
        span = "no anchored edge" if self.hanging else f"{self.span_mm:.1f} mm span"
        return (f"{span} (limit {self.limit_mm:.1f}) over {self.area_mm2:.1f} mm^2, farthest from an anchor at "
                f"({x:.1f}, {y:.1f}, {z:.1f}) mm")


def _triangle_samples(tri: np.ndarray, step_mm: float) -> np.ndarray:
    """Points on each triangle of ``tri`` (k, 3, 3): its vertices and a barycentric grid no coarser than ``step_mm``."""
    out = [tri.reshape(-1, 3)]
    edge = np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2).max(axis=1)
    div = np.maximum(1, np.ceil(edge / step_mm)).astype(int)
    for k in np.unique(div):
        if k < 2:
            continue
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        a, b = i[keep] / k, j[keep] / k
        w = np.stack([1 - a - b, a, b], axis=1)                   # (m, 3) barycentric weights
        t = tri[div == k]
        out.append(np.einsum("mk,tkd->tmd", w, t).reshape(-1, 3))
    return np.vstack(out)


def _segment_samples(seg: np.ndarray, step_mm: float) -> np.ndarray:
    """Points along each segment of ``seg`` (s, 2, d), its ends included, no farther apart than ``step_mm``."""
    n = np.maximum(1, np.ceil(np.linalg.norm(seg[:, 1] - seg[:, 0], axis=1) / step_mm)).astype(int)
    t = np.concatenate([np.linspace(0.0, 1.0, k + 1) for k in n])
    i = np.repeat(np.arange(len(seg)), n + 1)
    return seg[i, 0] + t[:, None] * (seg[i, 1] - seg[i, 0])


def bridges(vertices: np.ndarray, faces: np.ndarray, limit_mm: float, up=(0.0, 0.0, 1.0)) -> list[Bridge]:
    """Every bridge region of a mesh printed with ``up`` as the vertical, with its span (:class:`Bridge`); the
    regions on the bed are not bridges. All of them, not only those over ``limit_mm`` (which each carries).

    A region is a connected set of faces whose outward normal is within :data:`BRIDGE_TILT_DEG` of straight down.
    An edge of it is anchored when the face beyond it lies lower (a wall going down from it: material below, where
    the slicer anchors the bridge's threads); an edge whose neighbour rises (the outside of a ledge, the end of a
    tunnel open at a face) holds nothing."""
    import trimesh
    from scipy.spatial import cKDTree

    v0 = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64)
    u = np.asarray(up, dtype=float)
    u = u / np.linalg.norm(u)
    # a print frame: z along up (the inverse rotation brings the points back to the mesh's frame)
    e1 = np.cross(u, [1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.cross(u, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    R = np.stack([e1, np.cross(u, e1), u])                       # rows: print x, y, z in the mesh's frame
    v = v0 @ R.T
    z0 = float(v[:, 2].min())
    v[:, 2] -= z0
    # one vertex where B-rep faces meet (a tessellation repeats them per face): adjacency across a ceiling's edges
    mesh = trimesh.Trimesh(v, f, process=True)
    v, f = mesh.vertices, mesh.faces
    n = mesh.face_normals
    tri = v[f]
    ceiling = (n[:, 2] < -math.cos(math.radians(BRIDGE_TILT_DEG))) & (tri[:, :, 2].max(axis=1) > BED_CONTACT_MM)
    if not ceiling.any():
        return []
    adj, edges = mesh.face_adjacency, mesh.face_adjacency_edges
    regions = trimesh.graph.connected_components(adj[ceiling[adj[:, 0]] & ceiling[adj[:, 1]]],
                                                 nodes=np.nonzero(ceiling)[0], min_len=1)
    rim = ceiling[adj[:, 0]] ^ ceiling[adj[:, 1]]
    inner = np.where(ceiling[adj[:, 0]], adj[:, 0], adj[:, 1])[rim]
    outer = np.where(ceiling[adj[:, 0]], adj[:, 1], adj[:, 0])[rim]
    rim_edges = edges[rim]
    anchored = tri[outer].mean(axis=1)[:, 2] < v[rim_edges].mean(axis=1)[:, 2] - 1e-6
    region_of = np.full(len(f), -1)
    for k, r in enumerate(regions):
        region_of[r] = k
    area = mesh.area_faces
    out = []
    for k, r in enumerate(regions):
        a = float(area[r].sum())
        if a < MIN_BRIDGE_AREA_MM2:
            continue
        pts = _triangle_samples(tri[r], BRIDGE_SAMPLE_MM)
        mine = anchored & (region_of[inner] == k)
        if not mine.any():
            at = pts[np.argmin(pts[:, 2])]
            out.append(Bridge(math.inf, a, tuple(float(x) for x in (at + [0.0, 0.0, z0]) @ R), float(limit_mm)))
            continue
        anchors = _segment_samples(v[rim_edges[mine]][:, :, :2], BRIDGE_SAMPLE_MM)      # in plan
        d, _ = cKDTree(anchors).query(pts[:, :2])
        j = int(np.argmax(d))
        at = tuple(float(x) for x in (pts[j] + [0.0, 0.0, z0]) @ R)
        out.append(Bridge(2.0 * float(d[j]), a, at, float(limit_mm)))
    return out
