"""What a printed part asks of the printer in its print orientation: the area that needs support, and the orientation
that needs least (issue 13, item 5).

**Overhang.** A face of the part's mesh in print orientation (bed at z = 0) needs support when it faces down more
steeply than the support angle: its outward normal n has ``n_z < -sin(support_angle)`` with the angle measured
from the vertical (``print.support_angle_deg``; 45 deg: a face at 45 deg from the vertical still prints on its
own, flatter needs support), and it does not lie on the bed. The support area is the sum of those faces' areas,
projected on the bed (what a slicer fills with support). A downward face whose lowest point is within
:data:`BED_CONTACT_MM` of the bed counts as bed contact.

**Orientation.** :func:`best_orientation` tries the part family's candidate rotations (``PartSpec.meta
["print_candidates"]`` if the family offers several, else only its own ``print_rotation``) and keeps the one with the
least support area that fits the bed; ties keep the family's own choice.
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
