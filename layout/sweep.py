"""Swept tubes as numbers: a circle (or a ring) swept along a smooth polyline as a closed triangle mesh, and the
polyline helpers it needs. Pure numpy (no CAD kernel): the cables, tubes and leads of :mod:`swiftfin.cad.cables`
are meshed with it, and the loader (:mod:`swiftfin.layout.tube_plan`) proves the tubes inside the hull on the
same vertices the build's assembly check measures."""
from __future__ import annotations

import math

import numpy as np


def polyline_length_mm(pts: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1))) if len(pts) > 1 else 0.0


def dedupe_points(pts: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    """The polyline without consecutive repeated points (within ``eps`` mm)."""
    pts = np.asarray(pts)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > eps])
    return pts[keep]


def _frames(pts: np.ndarray):
    """Unit tangents (mean of the neighbouring segments) and a parallel-transported normal at each point."""
    d = np.diff(pts, axis=0)
    d = d / np.linalg.norm(d, axis=1)[:, None]
    t = np.vstack([d[:1], d[:-1] + d[1:], d[-1:]])
    t = t / np.linalg.norm(t, axis=1)[:, None]
    ref = np.array([0.0, 0.0, 1.0]) if abs(t[0][2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    n = np.cross(t[0], ref)
    n /= np.linalg.norm(n)
    ns = [n]
    for i in range(1, len(t)):
        n = n - (n @ t[i]) * t[i]
        n /= np.linalg.norm(n)
        ns.append(n)
    ns = np.asarray(ns)
    bs = np.cross(t, ns)
    # a section at a point where the line turns is stretched by 1 / cos(half the turn) so the swept radius holds
    half = np.zeros(len(pts))
    if len(pts) > 2:
        half[1:-1] = np.arccos(np.clip(np.einsum("ij,ij->i", d[:-1], d[1:]), -1, 1)) / 2
    return t, ns, bs, 1.0 / np.cos(half)


def _ring(c, n, b, stretch_dir, stretch, radius, sides):
    ang = 2 * math.pi * (np.arange(sides) + 0.5) / sides
    vec = np.outer(np.cos(ang), n) + np.outer(np.sin(ang), b)
    # stretch along the turn's in-plane direction (the miter): the component of vec along stretch_dir
    if stretch != 1.0:
        comp = vec @ stretch_dir
        vec = vec + np.outer(comp * (stretch - 1.0), stretch_dir)
    return c + radius * vec


def _section_rings(pts: np.ndarray, rad: float, sides: int) -> np.ndarray:
    """The polygon of ``sides`` at radius ``rad`` round each point of the (deduplicated) polyline, mitred at its
    turns (:func:`_frames`): ``len(pts) * sides`` vertices, ring by ring (:func:`_ring` at every point at once)."""
    t, ns, bs, st = _frames(pts)
    d = np.diff(pts, axis=0)
    d = d / np.linalg.norm(d, axis=1)[:, None]
    m = len(pts)
    sd, s = t.copy(), np.ones(m)          # the ends, and straight points, are not stretched
    if m > 2:
        w = d[1:] - d[:-1]
        turn = np.linalg.norm(w, axis=1) > 1e-12
        w = w - np.einsum("ij,ij->i", w, t[1:-1])[:, None] * t[1:-1]
        idx = np.flatnonzero(turn) + 1
        sd[idx] = w[turn] / np.linalg.norm(w[turn], axis=1)[:, None]
        s[idx] = st[idx]
    ang = 2 * math.pi * (np.arange(sides) + 0.5) / sides
    vec = np.cos(ang)[None, :, None] * ns[:, None, :] + np.sin(ang)[None, :, None] * bs[:, None, :]
    comp = np.einsum("mkj,mj->mk", vec, sd)
    vec = vec + (comp * (s - 1.0)[:, None])[:, :, None] * sd[:, None, :]
    return (pts[:, None, :] + rad * vec).reshape(-1, 3)


def sweep_outer_vertices(points, radius: float, sides: int) -> np.ndarray:
    """The vertices of :func:`sweep_mesh`'s outer surface along the line (its flat ends' centres left out): what a
    check of how far the swept solid reaches needs, without the faces."""
    pts = dedupe_points(np.asarray(points, float))
    if len(pts) < 2:
        raise ValueError("a sweep needs two distinct points")
    return _section_rings(pts, radius / math.cos(math.pi / sides), sides)


def sweep_mesh(points, radius: float, sides: int, inner_radius: float = 0.0, round_ends: bool = False
               ) -> tuple[np.ndarray, np.ndarray]:
    """Closed triangle mesh of a circle (or a ring ``inner_radius``..``radius``) swept along a smooth polyline:
    polygon circumscribed about the circle (inscribed in the bore), flat or half-sphere ends, outward normals."""
    pts = dedupe_points(np.asarray(points, float))
    if len(pts) < 2:
        raise ValueError("a sweep needs two distinct points")
    t, ns, bs, st = _frames(pts)
    r_out = radius / math.cos(math.pi / sides)
    m = len(pts)
    verts, faces = [], []

    def add_rings(rad):
        base = len(verts)
        verts.extend(_section_rings(pts, rad, sides))
        return base

    def side_faces(base, flip):
        for i in range(m - 1):
            for k in range(sides):
                a, b = base + i * sides + k, base + i * sides + (k + 1) % sides
                c, e = a + sides, b + sides
                tri = [(a, b, e), (a, e, c)]
                faces.extend([(x, z, y) for x, y, z in tri] if flip else tri)

    outer = add_rings(r_out)
    side_faces(outer, False)
    if inner_radius > 0:
        inner = add_rings(inner_radius)
        side_faces(inner, True)
        for i, flip in ((0, True), (m - 1, False)):
            for k in range(sides):
                a, b = outer + i * sides + k, outer + i * sides + (k + 1) % sides
                c, e = inner + i * sides + k, inner + i * sides + (k + 1) % sides
                tri = [(a, c, e), (a, e, b)]
                faces.extend([(x, z, y) for x, y, z in tri] if not flip else tri)
    else:
        for i, sgn in ((0, -1.0), (m - 1, 1.0)):
            ring0 = outer + i * sides
            if round_ends:
                prev = ring0
                lat = max(2, sides // 4)
                for q in range(1, lat):
                    phi = q * (math.pi / 2) / lat
                    base = len(verts)
                    # circumscribe the half sphere too: radius r_out / cos of the half latitude step
                    rr = r_out / math.cos(math.pi / 4 / lat)
                    c = pts[i] + sgn * t[i] * rr * math.sin(phi)
                    verts.extend(_ring(c, ns[i], bs[i], t[i], 1.0, rr * math.cos(phi), sides))
                    for k in range(sides):
                        a, b = prev + k, prev + (k + 1) % sides
                        c2, e = base + k, base + (k + 1) % sides
                        tri = [(a, b, e), (a, e, c2)]
                        faces.extend(tri if sgn > 0 else [(x, z, y) for x, y, z in tri])
                    prev = base
                pole = len(verts)
                verts.append(pts[i] + sgn * t[i] * r_out / math.cos(math.pi / 4 / lat))
                ring0 = prev
            else:
                pole = len(verts)
                verts.append(pts[i])
            for k in range(sides):
                a, b = ring0 + k, ring0 + (k + 1) % sides
                faces.append((a, b, pole) if sgn > 0 else (a, pole, b))
    return np.asarray(verts, float), np.asarray(faces, np.int64)
