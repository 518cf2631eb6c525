"""The hull's plan as numbers: the nose cap, the section at a station, the split into printable pieces and
which links flood. No CAD kernel: the bed-fit rule and the mass model read it without building a solid; the
solids are made by :mod:`swiftfin.cad.hull` from the same numbers.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L

SPLICE_LENGTH_MM = 10.0      # splice tab length on each side of a station cut
SPLICE_WIDTH_MM = 14.0


# ----------------------------------------------------------------------------------------------- numbers
@dataclass(frozen=True)
class NoseCap:
    s_cap_mm: float   # cap ends (meets the NACA loft) here
    a_mm: float       # ellipse semi-axis along the body axis; the ellipse centre is at s = a_mm
    b_mm: float       # ellipse semi-axis across (half-width)


def nose_cap(p: Params) -> NoseCap:
    """The elliptic-arc nose profile tangent to the NACA curve at s_c (see the module docstring)."""
    L_ = p.body.length_mm
    sc = p.body.nose_cap_fraction * L_
    t = p.body.naca_thickness_fraction
    xi = sc / L_
    w = float(L.naca_half_thickness(xi, t)) * L_
    dw = 5 * t * (0.2969 / (2 * math.sqrt(xi)) - 0.1260 - 2 * 0.3516 * xi + 3 * 0.2843 * xi**2 - 4 * 0.1015 * xi**3)
    k = sc * dw / w
    if not 0 < k < 0.5:
        raise UserError(f"body.nose_cap_fraction = {p.body.nose_cap_fraction}: no tangent elliptic nose cap "
                        f"(slope ratio {k:.3f} not in (0, 0.5))")
    u = k / (1 - k)
    A = sc / (1 - u)
    return NoseCap(sc, A, w / math.sqrt(1 - u * u))


def hull_section_semi_axes_mm(p: Params, s_mm: float) -> tuple[float, float]:
    """Outer half-width and half-height of the hull at station s [mm], nose cap included."""
    cap = nose_cap(p)
    if s_mm < cap.s_cap_mm:
        v = (cap.a_mm - s_mm) / cap.a_mm
        w = cap.b_mm * math.sqrt(max(0.0, 1 - v * v))
    else:
        w = float(L.naca_half_width_mm(p, s_mm))
    return w, p.body.height_to_width * w


@dataclass(frozen=True)
class HullPiece:
    """One printed hull piece (before the split into halves): stations, link and what its ends carry."""
    name: str
    s_start_mm: float
    s_end_mm: float
    link: int
    nose: bool = False
    tail: bool = False
    front_joint: int | None = None      # child of this joint: front bulkhead with the link's bolts
    rear_joint: int | None = None       # parent of this joint: rear bulkhead with the clevis
    front_cut: bool = False             # station cut at the front (open end)
    rear_cut: bool = False              # station cut at the rear (open end, splice tab)

    def max_semi_axes_mm(self, p: Params) -> tuple[float, float]:
        ss = np.linspace(self.s_start_mm, self.s_end_mm, 201)
        w = max(hull_section_semi_axes_mm(p, float(s))[0] for s in ss)
        return w, p.body.height_to_width * w


def printed_size_mm(p: Params, piece: HullPiece) -> tuple[float, float, float]:
    """Size (x, y, z) of the printed part(s) of a piece in print orientation."""
    a, b = piece.max_semi_axes_mm(p)
    length = piece.s_end_mm - piece.s_start_mm + (SPLICE_LENGTH_MM if piece.rear_cut else 0.0)
    if p.hull.split_halves:
        return length, 2 * a, b
    return 2 * a, 2 * b, length


def bed_rotation_deg(p: Params, size: tuple[float, float, float]) -> float | None:
    """Rotation about the vertical [deg] that fits a (dx, dy, dz) box on the bed, or None."""
    dx, dy, dz = size
    bx, by, bz = p.print.bed_x_mm, p.print.bed_y_mm, p.print.bed_z_mm
    if dz > bz:
        return None
    for a in np.arange(0.0, 90.01, 0.5):
        r = math.radians(a)
        if dx * math.cos(r) + dy * math.sin(r) <= bx and dx * math.sin(r) + dy * math.cos(r) <= by:
            return float(a)
    return None


def _split_stations(p: Params, seg: L.Segment, n: int) -> list[float]:
    """n-1 cut stations, near equal spacing, moved away from mount fixings (screw + splice tab)."""
    fix = [-f.point_mm[0] for f in L.mount_fixings_mm(p)]
    keep = SPLICE_LENGTH_MM + p.hull.screw_diameter_mm + 3.0
    out = []
    for i in range(1, n):
        s0 = seg.s_start_mm + i * (seg.s_end_mm - seg.s_start_mm) / n
        best = s0
        lo, hi = seg.s_start_mm + (i - 0.5) * (seg.s_end_mm - seg.s_start_mm) / n, \
            seg.s_start_mm + (i + 0.5) * (seg.s_end_mm - seg.s_start_mm) / n
        for d in np.arange(0.0, 40.0, 0.5):
            cands = [c for c in (s0 + d, s0 - d) if lo < c < hi]
            ok = [c for c in cands if all(abs(c - f) >= keep for f in fix)]
            if ok:
                best = ok[0]
                break
        out.append(float(best))
    return out


def hull_pieces(p: Params) -> tuple[HullPiece, ...]:
    """The segments of :func:`swiftfin.layout.geometry.hull_segments`, split at stations until each fits the bed.

    Raises UserError naming the segment, its printed size and the bed when even its cross-section does not fit.
    """
    segs = L.hull_segments(p)
    n_j = p.joints.count
    bed = f"{p.print.bed_x_mm:g} x {p.print.bed_y_mm:g} x {p.print.bed_z_mm:g} mm"
    out = []
    for i, seg in enumerate(segs):
        base = HullPiece(seg.name, seg.s_start_mm, seg.s_end_mm, seg.link, nose=(i == 0), tail=(i == len(segs) - 1),
                         front_joint=seg.link if seg.link >= 1 else None,
                         rear_joint=seg.link + 1 if seg.link + 1 <= n_j else None)
        size = printed_size_mm(p, base)
        if bed_rotation_deg(p, size) is not None:
            out.append(base)
            continue
        for n in range(2, 13):
            cuts = [seg.s_start_mm] + _split_stations(p, seg, n) + [seg.s_end_mm]
            names = (["front", "rear"] if n == 2 else ["front", "mid", "rear"] if n == 3
                     else [str(k + 1) for k in range(n)])
            pieces = [HullPiece(f"{seg.name}_{names[k]}", cuts[k], cuts[k + 1], seg.link,
                                nose=base.nose and k == 0, tail=base.tail and k == n - 1,
                                front_joint=base.front_joint if k == 0 else None,
                                rear_joint=base.rear_joint if k == n - 1 else None,
                                front_cut=k > 0, rear_cut=k < n - 1) for k in range(n)]
            if all(bed_rotation_deg(p, printed_size_mm(p, pc)) is not None for pc in pieces):
                out += pieces
                break
        else:
            sx, sy, sz = size
            raise UserError(f"{seg.name}: printed size {sx:.0f} x {sy:.0f} x {sz:.0f} mm does not fit the print bed "
                            f"{bed} even when cut into 12 pieces along its length (print.bed_x_mm, print.bed_y_mm, "
                            f"print.bed_z_mm; or a smaller body.length_mm)")
    return tuple(out)


def flooded(p: Params, link: int) -> bool:
    """Whether the hull segments of ``link`` flood (``hull.flooded_from_joint``)."""
    return link >= p.hull.flooded_from_joint
