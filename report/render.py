"""Off-screen pictures of triangle meshes: a small z-buffer rasteriser (numpy, its inner loop compiled by numba),
no display, no GPU.

Why not mplot3d: it sorts whole polygons by depth (painter's algorithm), so interpenetrating or nested parts
(spools inside the hull, links between the hull halves) show through each other. A z-buffer resolves every
pixel. Why not pyrender/OSMesa: they need an OpenGL stack that CI images do not reliably have. This module needs
only numpy, numba and Pillow (a matplotlib dependency), so it runs anywhere the rest of the project does.

Pipeline (:func:`render`): orthographic camera from an azimuth and an elevation (degrees; body frame of
layout/geometry.py: +x forward, +y left, +z up) -> every triangle rasterised over its screen bounding box (edge
functions at pixel centres, :mod:`swiftfin.report.raster_kernel`) into a depth buffer, a face-index buffer and
barycentric coordinates -> shading per pixel: crease-aware smooth normals (corners whose faces differ by more
than ``crease_deg`` keep their own normal), Lambert key + fill light, a small Blinn-Phong highlight, ambient ->
outlines where the part, the depth or the normal jumps -> ``supersample`` x downsampling (anti-aliasing) ->
RGBA PNG with a transparent background.

Scenes of more than ``max_faces`` triangles (400 000; the default design has about 330 000) are decimated
first by vertex clustering (:func:`cluster_decimate`), a guard for very fine tessellations: clustering can fold
triangles and speckle the shading, so it is not used below that budget.

Cost: an assembly view (1200 x 430, 2x supersampled) of the default design's 33 printed parts (479 000
triangles) took 11.0 s with the rasteriser's loop in numpy and takes 3.3 s compiled (2026-11-25, side by side,
under load; the pixels differ only where two coincident faces tie, 0.7 % of them).
"""
from __future__ import annotations

import io
import math
from dataclasses import dataclass, field

import numpy as np



@dataclass(frozen=True)
class MeshItem:
    """One mesh to draw: ``vertices`` (n, 3) [mm], ``faces`` (m, 3) int, ``color`` RGB in [0, 1]."""
    vertices: np.ndarray
    faces: np.ndarray
    color: tuple[float, float, float]
    name: str = ""
    normals: np.ndarray | None = field(default=None, compare=False)   # corner_normals(vertices, faces), if known


# ----------------------------------------------------------------------------------------------- geometry
def camera_axes(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    """Rows: screen right, screen up, towards the viewer (world coordinates, z up). A camera at azimuth 0 and
    elevation 0 looks along -x (from in front of the nose); azimuth 90 looks along -y (from the fish's left)."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    d = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross(-d, [0.0, 0.0, 1.0])
    n = np.linalg.norm(right)
    right = np.array([-math.sin(az), math.cos(az), 0.0]) if n < 1e-9 else right / n
    up = np.cross(right, -d)
    return np.vstack([right, up, d])


def face_normals(v: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit face normals and face areas."""
    cr = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    area2 = np.linalg.norm(cr, axis=1)
    n = cr / np.maximum(area2, 1e-300)[:, None]
    return n, 0.5 * area2


def corner_normals(v: np.ndarray, f: np.ndarray, crease_deg: float = 35.0) -> np.ndarray:
    """Normal at each face corner (m, 3, 3): the area-weighted mean normal of the faces at the corner's vertex
    that lie within ``crease_deg`` of this face (smooth surfaces look smooth, sharp edges stay sharp).

    Vertices whose faces all lie within ``crease_deg / 2`` of their mean normal take that mean directly; the
    others (on edges and corners, a minority) compare every pair of faces around them."""
    fn, area = face_normals(v, f)
    m = f.shape[0]
    cos_c = math.cos(math.radians(crease_deg))
    w = fn * area[:, None]
    idx = f.reshape(-1)
    vn = np.column_stack([np.bincount(idx, weights=np.repeat(w[:, k], 3), minlength=len(v)) for k in range(3)])
    vn /= np.maximum(np.linalg.norm(vn, axis=1), 1e-300)[:, None]
    corner_f = np.repeat(np.arange(m), 3)
    dots = np.einsum("ij,ij->i", fn[corner_f], vn[idx])
    worst = np.ones(len(v))
    np.minimum.at(worst, idx, dots)
    out = vn[idx].copy()
    sharp_corner = worst[idx] < math.cos(math.radians(crease_deg / 2))
    sel = np.flatnonzero(sharp_corner)
    if sel.size:
        cv, cf = idx[sel], corner_f[sel]
        order = np.argsort(cv, kind="stable")
        sv, sf, ssel = cv[order], cf[order], sel[order]
        starts = np.flatnonzero(np.r_[True, sv[1:] != sv[:-1]])
        counts = np.diff(np.r_[starts, sv.size])
        group_of = np.repeat(np.arange(starts.size), counts)
        reps = counts[group_of]
        a_ = np.repeat(np.arange(sv.size), reps)
        offs = np.arange(a_.size) - np.repeat(np.cumsum(reps) - reps, reps)
        b_ = starts[group_of[a_]] + offs
        fa, fb = sf[a_], sf[b_]
        keep = np.einsum("ij,ij->i", fn[fa], fn[fb]) >= cos_c
        acc = np.zeros((sv.size, 3))
        for k in range(3):
            acc[:, k] = np.bincount(a_[keep], weights=w[fb[keep], k], minlength=sv.size)
        out[ssel] = acc
    nrm = np.linalg.norm(out, axis=1)
    bad = nrm < 1e-300
    out[bad] = fn[corner_f[bad]]
    out[~bad] /= nrm[~bad, None]
    return out.reshape(m, 3, 3)


def cluster_decimate(v: np.ndarray, f: np.ndarray, max_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertex-clustering decimation: snap vertices to a grid, merge each cell's vertices into their mean, drop
    collapsed and duplicate faces. The cell grows (x1.4 per try) from 1/400 of the box diagonal until at most
    ``max_faces`` faces remain."""
    v = np.asarray(v, float)
    f = np.asarray(f, np.int64)
    if f.shape[0] <= max_faces:
        return v, f
    lo = v.min(axis=0)
    diag = float(np.linalg.norm(v.max(axis=0) - lo)) or 1.0
    cell = diag / 400.0
    for _ in range(30):
        key = np.floor((v - lo) / cell).astype(np.int64)
        _, inv = np.unique(key, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        nv = np.bincount(inv).astype(float)
        nvert = np.column_stack([np.bincount(inv, weights=v[:, k]) for k in range(3)]) / nv[:, None]
        nf = inv[f]
        ok = (nf[:, 0] != nf[:, 1]) & (nf[:, 1] != nf[:, 2]) & (nf[:, 0] != nf[:, 2])
        nf = nf[ok]
        srt = np.sort(nf, axis=1)
        _, first = np.unique(srt, axis=0, return_index=True)
        nf = nf[np.sort(first)]
        if nf.shape[0] <= max_faces:
            return nvert, nf
        cell *= 1.4
    return nvert, nf


# ----------------------------------------------------------------------------------------------- rasteriser
def rasterize(tri_xy: np.ndarray, tri_z: np.ndarray, width: int, height: int):
    """Z-buffer of screen triangles. ``tri_xy`` (m, 3, 2) in pixels (x right, y down), ``tri_z`` (m, 3), larger
    = nearer. Returns (depth (H, W), face index (H, W), -1 where empty, barycentric in that face (H, W, 3)).
    The loop over triangles and their pixels is compiled (:mod:`swiftfin.report.raster_kernel`)."""
    from swiftfin.report.raster_kernel import fill

    zbuf = np.full(height * width, -np.inf)
    fbuf = np.full(height * width, -1, np.int64)
    bbuf = np.zeros((height * width, 3))
    xy = np.ascontiguousarray(tri_xy, dtype=np.float64)
    fill(np.ascontiguousarray(xy[..., 0]), np.ascontiguousarray(xy[..., 1]),
         np.ascontiguousarray(tri_z, dtype=np.float64), int(width), int(height), zbuf, fbuf, bbuf)
    return zbuf.reshape(height, width), fbuf.reshape(height, width), bbuf.reshape(height, width, 3)


def load_kernel() -> None:
    """Load the compiled z-buffer loop into this process (numba reads it from its cache: about 0.7 s the first
    time in a process). Called before the pictures are handed to forked workers, which then inherit it instead
    of each loading it again."""
    rasterize(np.zeros((1, 3, 2)), np.zeros((1, 3)), 2, 2)


# ----------------------------------------------------------------------------------------------- picture
CREASE_DEG = 30.0
"""Faces meeting at more than this keep their own normals at a shared corner (:func:`corner_normals`)."""


def render(items: list[MeshItem], width: int = 640, height: int = 400, azimuth_deg: float = 62.0,
           elevation_deg: float = 24.0, supersample: int = 2, max_faces: int = 400_000, margin: float = 0.06,
           crease_deg: float = CREASE_DEG, outline: bool = True, cull_back_faces: bool = True) -> np.ndarray:
    """RGBA image (height, width, 4) uint8 of the meshes, fitted to the frame with ``margin`` on each side."""
    items = [it for it in items if len(it.faces)]
    if not items:
        raise ValueError("nothing to render: no triangles")
    total = sum(len(it.faces) for it in items)
    verts, faces, colors, part, corners = [], [], [], [], []
    offset = 0
    for k, it in enumerate(items):
        v, f = np.asarray(it.vertices, float), np.asarray(it.faces, np.int64)
        if total > max_faces:
            v, f = cluster_decimate(v, f, max(200, int(max_faces * len(it.faces) / total)))
        # an item's corner normals are its own (items share no vertex): the item's, when it brings them
        given = it.normals is not None and total <= max_faces and crease_deg == CREASE_DEG
        corners.append(it.normals if given else corner_normals(v, f, crease_deg))
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
        colors.append(np.broadcast_to(np.asarray(it.color, float), (len(f), 3)))
        part.append(np.full(len(f), k))
    V = np.vstack(verts)
    F = np.vstack(faces)
    C = np.vstack(colors)
    P = np.concatenate(part)
    R = camera_axes(azimuth_deg, elevation_deg)
    S = V @ R.T                                   # screen right, up, depth (towards viewer)
    W, H = width * supersample, height * supersample
    lo, hi = S[:, :2].min(axis=0), S[:, :2].max(axis=0)
    ext = np.maximum(hi - lo, 1e-9)
    scale = min(W * (1 - 2 * margin) / ext[0], H * (1 - 2 * margin) / ext[1])
    centre = 0.5 * (lo + hi)
    sx = (S[:, 0] - centre[0]) * scale + W / 2
    sy = H / 2 - (S[:, 1] - centre[1]) * scale
    tri_xy = np.stack([sx[F], sy[F]], axis=-1)
    tri_z = S[:, 2][F]
    fnorm = face_normals(V, F)[0] @ R.T
    front = fnorm[:, 2] > 0                       # closed, outward-wound solids: back faces are never seen
    front_ids = np.flatnonzero(front) if cull_back_faces else np.arange(len(F))
    zbuf, fbuf, bary = rasterize(tri_xy[front_ids], tri_z[front_ids], W, H)
    fbuf = np.where(fbuf >= 0, front_ids[np.maximum(fbuf, 0)], -1)
    hit = fbuf >= 0
    # ---- shading (camera space: the viewer is along +z)
    cn = np.concatenate(corners) @ R.T            # (m, 3, 3)
    fi = fbuf[hit]
    n = np.einsum("pk,pkj->pj", bary[hit], cn[fi])
    n /= np.maximum(np.linalg.norm(n, axis=1), 1e-12)[:, None]
    flip = fnorm[fi, 2] < 0                      # back faces (open or inside views): light them as front faces
    n[flip] *= -1.0
    key = np.array([-0.45, 0.65, 0.62])
    key /= np.linalg.norm(key)
    fill = np.array([0.7, -0.2, 0.68])
    fill /= np.linalg.norm(fill)
    view = np.array([0.0, 0.0, 1.0])
    half = (key + view) / np.linalg.norm(key + view)
    diff = 0.62 * np.clip(n @ key, 0, None) + 0.22 * np.clip(n @ fill, 0, None)
    spec = 0.18 * np.clip(n @ half, 0, None) ** 40
    rim = 0.10 * (1.0 - np.clip(n[:, 2], 0, 1)) ** 3
    shade = 0.30 + diff
    rgb = np.clip(C[fi] * shade[:, None] + spec[:, None] + rim[:, None], 0, 1)
    img = np.zeros((H, W, 4))
    img[hit, :3] = rgb
    img[hit, 3] = 1.0
    if outline:
        edge = _edges(zbuf, fbuf, P, fnorm, scale, hit)
        img[edge, :3] *= 0.28
        img[edge & ~hit, :3] = 0.12
        img[edge & ~hit, 3] = 1.0
    out = (img.reshape(height, supersample, width, supersample, 4).mean(axis=(1, 3)))
    # un-premultiplied colour where coverage is partial
    a = out[..., 3:4]
    out[..., :3] = np.where(a > 0, out[..., :3] / np.maximum(a, 1e-6), 0.0)
    return np.clip(np.round(out * 255), 0, 255).astype(np.uint8)


def _edges(zbuf, fbuf, part_of_face, fnorm, scale_px_per_mm, hit):
    """Outline pixels: silhouettes, part boundaries, depth steps and creases (normal jumps > 40 deg)."""
    H, W = fbuf.shape
    pid = np.where(hit, part_of_face[np.maximum(fbuf, 0)], -1)
    nrm = np.where(hit[..., None], fnorm[np.maximum(fbuf, 0)], 0.0)
    z = np.where(hit, zbuf, -1e30)
    edge = np.zeros((H, W), bool)
    depth_step = max(2.0, 8.0 / max(scale_px_per_mm, 1e-9))   # mm: 2 mm or 8 pixels' width, the larger
    for dy, dx in ((0, 1), (1, 0)):
        a = (slice(0, H - dy), slice(0, W - dx))
        b = (slice(dy, H), slice(dx, W))
        e = pid[a] != pid[b]
        both = hit[a] & hit[b]
        e |= both & (np.abs(z[a] - z[b]) > depth_step)
        e |= both & (np.einsum("ijk,ijk->ij", nrm[a], nrm[b]) < math.cos(math.radians(40)))
        edge[a] |= e
        edge[b] |= e & hit[b]
    return edge


def png_bytes(rgba: np.ndarray) -> bytes:
    """PNG file bytes of an RGBA (or RGB) uint8 image."""
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgba).save(buf, format="PNG", optimize=True)
    return buf.getvalue()
