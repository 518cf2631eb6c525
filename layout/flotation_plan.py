"""Flotation foam as numbers: where each block goes and its section, in the body frame at rest (mm). No CAD kernel.

A buildable fish is heavier than its sealed displacement (four NEMA 17 motors fill the head; screws, inserts,
pins, tubes and cable add the rest), and lead cannot make a sinking fish neutral. The lift comes from blocks of
closed-cell foam (``environment.foam_density_kg_m3``) in the first ``environment.flotation_foam_segments``
flooded segments: a flooded segment displaces only its solids, so a block there lifts ``(rho_w - rho_foam) V``.
A sealed segment already displaces its whole envelope, so foam inside it would lift nothing (the loader refuses
more blocks than flooded segments).

Each block lies in the **lower half** of the segment's longest piece, glued to the shell where its curved sides
meet it, under every cable and tube that crosses the segment and clear of everything else by
``print.clearance_assembly_mm``:

* along the body: inside the piece's hollow (bulkheads, splice tabs, the fin's socket out), and out of the swing
  of the link behind (a vertical cylinder of the joint hardware's reach about the joint axis);
* across: inside the seam's screw columns and dowel bosses (|y| below the nearest one less its radius);
* up: below the lowest cable level of the joints whose cables cross or end in the segment, less the PTFE tube's
  radius (the larger of tube and cable);
* down: ``hull.vent_hole_diameter_mm`` above the inner keel, so the bottom vent still lets water in under it.

The section is the inner ellipse (wall thickness in, less half the sliding clearance, so glue contact is a
touch and not an overlap) cut by those four lines: a convex polygon of ``SECTION_POINTS`` points, the same
count at both ends, so :mod:`swiftfin.cad.bought` lofts it ruled. The NACA half-thickness is concave aft of its
maximum, so the ruled loft between the two end sections stays inside the hull.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.hull_plan import (
    HullPiece, flooded, hollow_clear_of_ends_mm, hull_pieces, hull_section_semi_axes_mm, part_label, seam_features)
from swiftfin.layout.joints import joint_hardware

SECTION_POINTS = 24            # points on each side of a section polygon (48 in all)
MIN_BLOCK_MM = 4.0             # a block thinner than this in any direction is not worth cutting


@dataclass(frozen=True)
class FoamBlock:
    """A flotation block: a ruled loft of two convex sections at stations s0 < s1, in one piece's lower half."""
    label: str
    link: int
    piece: str                 # the hull piece it sits in
    glued_to: str              # the printed part it is glued into (the piece's lower half)
    s0_mm: float
    s1_mm: float
    z_floor_mm: float
    z_top_mm: float
    y_max_mm: float
    inset_mm: float            # from the inner wall (half the sliding clearance)
    notches: tuple = ()        # (station, radius) of the vertical cylinders cut out of it: the swing of the
    #                            joint hardware about the joint axes at the piece's ends

    def excluded_half_width_mm(self, s_mm: float) -> float:
        """|y| below which the notches take the block away at station s (0: no notch there)."""
        out = 0.0
        for s_axis, r in self.notches:
            d = abs(s_mm - s_axis)
            if d < r:
                out = max(out, math.sqrt(r * r - d * d))
        return out

    def section_yz_mm(self, p: Params, s_mm: float) -> np.ndarray:
        """The block's section at station s: (2 * SECTION_POINTS, 2) points (y, z), counter-clockwise."""
        a, b = hull_section_semi_axes_mm(p, s_mm)
        ai = a - p.hull.wall_thickness_mm - self.inset_mm
        bi = b - p.hull.wall_thickness_mm - self.inset_mm
        z = np.linspace(self.z_floor_mm, self.z_top_mm, SECTION_POINTS)
        y = np.minimum(self.y_max_mm, ai * np.sqrt(np.clip(1.0 - (z / bi) ** 2, 0.0, None)))
        right = np.column_stack([y, z])
        left = np.column_stack([-y[::-1], z[::-1]])
        return np.vstack([right, left])

    def volume_mm3(self, p: Params, n: int = 801) -> float:
        """Volume of the block: the ruled loft less the notches, integrated numerically (the section's half-width
        is linear between its points in z and between the end sections in s)."""
        s = np.linspace(self.s0_mm, self.s1_mm, n)
        f = (s - self.s0_mm) / (self.s1_mm - self.s0_mm)
        y0 = self.section_yz_mm(p, self.s0_mm)[:SECTION_POINTS]
        y1 = self.section_yz_mm(p, self.s1_mm)[:SECTION_POINTS]
        zf = np.linspace(self.z_floor_mm, self.z_top_mm, 4 * SECTION_POINTS)
        w0, w1 = np.interp(zf, y0[:, 1], y0[:, 0]), np.interp(zf, y1[:, 1], y1[:, 0])
        area = [np.trapezoid(2.0 * np.maximum(0.0, (1 - fi) * w0 + fi * w1 - self.excluded_half_width_mm(si)), zf)
                for si, fi in zip(s, f)]
        return float(np.trapezoid(area, s))


def _block(p: Params, pc: HullPiece, index: int) -> FoamBlock:
    c = p.print.clearance_assembly_mm
    inset = 0.5 * p.print.clearance_sliding_mm
    s0, s1 = hollow_clear_of_ends_mm(p, pc, c)
    # (station, radius): vertical cylinders about the joint axes at its ends, clear of the swinging link by the
    # assembly clearance plus twice the tessellation's deflection (the notch's facets stand inside its circle; the
    # assembly check measures the meshes: 0.5 mm of exact clearance read 0.487 mm on a 3-joint design)
    axes = []
    for joint in (pc.front_joint, pc.rear_joint):
        if joint is not None:
            h = joint_hardware(p, joint)
            axes.append((-h.x_mm, max(h.sector_radius_mm, h.block_outer_radius_mm, h.tongue_radius_mm) + c
                         + 2 * p.export.mesh_tolerance_mm))
    # up: under the lowest cable (or tube) of the joints whose cables cross or end in this link
    n = p.joints.count
    joints = range(max(0, pc.link - 1), n)
    r = max(p.guides.ptfe_tube_od_mm, p.cable.diameter_mm) / 2
    z_top = min(L.tendon_level_mm(p, j, side) for j in joints for side in (-1, 1)) - r - c
    # across: inside the seam's columns and bosses
    feats = seam_features(p, pc)
    a_min, b_min = (min(v) for v in zip(*(hull_section_semi_axes_mm(p, s) for s in (s0, s1))))
    y_max = min((abs(f.y_mm) - f.boss_radius_mm - c for f in feats), default=a_min)
    # down: the vent's height above the inner keel where the section is smallest (a ruled loft between the
    # ends: the keel's chord lies above the hull's)
    z_floor = -(b_min - p.hull.wall_thickness_mm) + p.hull.vent_hole_diameter_mm
    blk = FoamBlock(f"flotation_{index}", pc.link, pc.name, part_label(p, pc, "lower"), s0, s1, z_floor, z_top,
                    y_max, inset, tuple(axes))
    if _centre_cut_all_along(s0, s1, axes):
        swing = ", ".join(f"radius {r:.1f} mm about s = {sa:.1f} mm" for sa, r in axes)
        raise UserError(f"environment.flotation_foam_segments = {p.environment.flotation_foam_segments}: the foam "
                        f"block in {pc.name} (s = {s0:.1f}..{s1:.1f} mm) would come apart in two: the swing of the "
                        f"joint hardware at its ends ({swing}) takes its middle away all along: ask for fewer blocks, "
                        f"or spread the joints apart (joints.stations_fraction)")
    thin = {"length": s1 - s0, "height": z_top - z_floor, "width": 2 * y_max}
    small = {k: v for k, v in thin.items() if v < MIN_BLOCK_MM}
    if small:
        what = ", ".join(f"{k} {v:.1f} mm" for k, v in small.items())
        raise UserError(f"environment.flotation_foam_segments = {p.environment.flotation_foam_segments}: no room "
                        f"for a foam block in {pc.name} ({what}; at least {MIN_BLOCK_MM:g} mm): ask for fewer "
                        f"blocks, or make room (a larger body.naca_thickness_fraction, a lower hull.flooded_from_joint)")
    return blk


def _centre_cut_all_along(s0: float, s1: float, notches) -> bool:
    """Whether the notches (station, radius) cover the block's centre line (y = 0) from s0 to s1: the block would
    then be two pieces, one each side (a five-joint seeded design's, 2026-11-29: its 7.8 mm block between two
    17.2 mm notches 31 mm apart). The default's first block keeps 1.9 mm of centre line between its notches."""
    covered = sorted((sa - r, sa + r) for sa, r in notches)
    reach = s0
    for lo, hi in covered:
        if lo > reach:
            break
        reach = max(reach, hi)
    return reach >= s1


def foam_blocks(p: Params) -> tuple[FoamBlock, ...]:
    """One block in the longest piece of each of the first ``environment.flotation_foam_segments`` flooded links."""
    k = p.environment.flotation_foam_segments
    if k <= 0:
        return ()
    pieces = hull_pieces(p)
    links = [j for j in range(1, p.joints.count + 1) if flooded(p, j)][:k]
    out = []
    for i, link in enumerate(links, start=1):
        mine = [pc for pc in pieces if pc.link == link]
        pc = max(mine, key=lambda q: (q.s_end_mm - q.s_start_mm, -q.s_start_mm))
        out.append(_block(p, pc, i))
    return tuple(out)


def foam_block_size_mm(p: Params, blk: FoamBlock) -> tuple[float, float, float]:
    """Length, width and height of the block's bounding box (the foam a builder cuts it from)."""
    sec = np.vstack([blk.section_yz_mm(p, blk.s0_mm), blk.section_yz_mm(p, blk.s1_mm)])
    return (blk.s1_mm - blk.s0_mm, float(np.ptp(sec[:, 0])), float(np.ptp(sec[:, 1])))


def foam_lift_n(p: Params, blk: FoamBlock) -> float:
    """Net lift of a block in water [N]: (rho_w - rho_foam) g V."""
    e = p.environment
    return (e.water_density_kg_m3 - e.foam_density_kg_m3) * e.gravity_m_s2 * blk.volume_mm3(p) * 1e-9


__all__ = ["FoamBlock", "foam_blocks", "foam_block_size_mm", "foam_lift_n", "SECTION_POINTS"]
