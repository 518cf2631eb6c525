"""The hull's plan as numbers: the nose cap, the section at a station, the split into printable pieces, which
links flood, and the fasteners that hold the pieces together. No CAD kernel: the bed-fit rule and the mass model
read it without building a solid; the solids are made by :mod:`swiftfin.cad.hull` from the same numbers.

Fasteners (:func:`hull_fasteners`, registered in ``cad/fastening.py``; body frame at rest, mm):

* **Seams** (``hull.split_halves``): along each side (+y and -y) of every piece, ``ceil(length /
  hull.seam_screw_spacing_mm)`` (at least one) vertical cap screws ``hull.screw_diameter_mm`` driven from the
  belly: the head sits in a counterbore of a column of the lower half that grows from the seam face down to the
  skin, the thread in a brass heat-set insert in a boss of the upper half that grows from the seam face up
  (``insert_pocket_depth`` + a floor of ``print.top_layers`` layers: the pocket is blind, so the dry head's cavity
  stays closed). Heads from below because above the seam the motor-mount plates reach the side walls
  (z = 9.6-21 mm) while below it the motors keep 10 mm from the walls; the driver's path is outside the hull.
  The axis is as far out as the insert's wall to the skin allows (:func:`seam_axis_y_mm`); the screw is the
  longest catalogue length whose head still sinks fully below the skin there. One ISO 8734 dowel pin per side
  (``hull.seam_dowel_diameter_mm``; the first feature on +y, the last on -y) in reamed bores of bosses on both
  halves aligns them; its record names the upper half (press fit) and ``meta["joins_parts"]`` the lower half,
  whose bore :mod:`swiftfin.cad.hull` cuts from the same record. Features keep out of the bulkheads and out of
  the swing of the link behind (the link's sector radius + ``print.clearance_assembly_mm``), and from under the
  PTFE guides in plan (``print.clearance_sliding_mm``: the lid's bosses rise past them,
  :func:`_clear_of_the_guides`).
* **Station splices** (a segment cut to fit the bed): per half two screws entering the skin at
  ``y = +-SPLICE_Y_FRACTION`` of the inner half-width, along the shell's inward normal, heads in
  counterbores of a local thickening (pad) of the rear piece's shell, threads in inserts in two tabs of the
  front piece that slide under the pads (:func:`splice_joint`).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.fasteners import dowel, fastener
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.fastening import Fastener
from swiftfin.layout.guide_plan import bare_guide_blocks
from swiftfin.layout.joints import joint_hardware
from swiftfin.layout.mount_plan import mount_fixings_mm

SPLICE_LENGTH_MM = 10.0      # splice tab length on each side of a station cut
SPLICE_Y_FRACTION = 0.7      # splice screws enter the skin at this fraction of the inner half-width off the centre
                             # line; along the shell's normal their tabs then lie at |y| = 14-25 mm: clear of the
                             # battery on the keel (|y| <= 13.2 mm) and of the motors (|z| <= 34 mm) on the crest
SEAM_MARGIN_MM = 0.2         # wall kept beyond each rule: the loft departs from the exact ellipse by < 0.05 mm and
                             # the hull tapers under a boss
BOSS_OVERLAP_MM = 0.5        # a seam boss overlaps a bulkhead by this, or keeps this from a cut end
BORE_OVERRUN_MM = 0.5        # the fastener cutters run this far past a pin's ends (cad.fastening.OVERCUT_MM)


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


def hull_half_widths_mm(p: Params, s_mm: np.ndarray) -> np.ndarray:
    """:func:`hull_section_semi_axes_mm`'s half-width at many stations at once (numpy; the same formulas)."""
    cap = nose_cap(p)
    s = np.asarray(s_mm, dtype=float)
    v = (cap.a_mm - s) / cap.a_mm
    in_cap = cap.b_mm * np.sqrt(np.maximum(0.0, 1 - v * v))
    return np.where(s < cap.s_cap_mm, in_cap, L.naca_half_width_mm(p, s))


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
        w = float(np.max(hull_half_widths_mm(p, np.linspace(self.s_start_mm, self.s_end_mm, 201))))
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
    fix = [-f.point_mm[0] for f in mount_fixings_mm(p)]
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


@functools.lru_cache(maxsize=64)
def hull_pieces(p: Params) -> tuple[HullPiece, ...]:
    """The segments of :func:`swiftfin.layout.geometry.hull_segments`, split at stations until each fits the bed.

    Raises UserError naming the segment, its printed size and the bed when even its cross-section does not fit.
    Memoised on the params (every plan reads it; a family cache's recording view is equal only to itself, so it
    never receives pieces computed without recording its reads).
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
                            f"print.bed_z_mm; or a smaller body.length_mm{_halves_hint(p)})")
    return tuple(out)


def _halves_hint(p: Params) -> str:
    """For a hull printed whole that fits no bed: the other way out when its halves would fit (a seeded design,
    2026-11-29: 118 x 162 mm sections on a 108 mm-wide bed, whose halves fit)."""
    if p.hull.split_halves:
        return ""
    from swiftfin.core.params import replace_key
    try:
        hull_pieces(replace_key(p, "hull.split_halves", True))
    except UserError:
        return ""
    return "; or hull.split_halves = true: its halves fit"


def cavity_range_mm(p: Params, pc: HullPiece) -> tuple[float, float]:
    """Stations [s0, s1] of the piece's hollow: inside its bulkheads (ahead of the dry compartment's rear wall,
    :func:`dry_bulkhead`), behind the nose cap, ahead of the fin's socket; an open (cut) end runs 1 mm past the
    piece."""
    s0, s1 = _cavity_range(p, pc)
    dry = dry_bulkhead(p) if not flooded(p, pc.link) else None
    if dry is not None and dry.piece == pc.name:
        s1 = min(s1, dry.s_front_mm)
    return s0, s1


def hollow_clear_of_ends_mm(p: Params, pc: HullPiece, margin_mm: float) -> tuple[float, float]:
    """Stations [s0, s1] where a part may stand in the piece's hollow (:func:`cavity_range_mm`, within the piece):
    ``margin_mm`` from its ends, and at a station cut clear of the splice's tabs and screws
    (:data:`SPLICE_LENGTH_MM` behind the cut). The flotation's foam blocks and the trim ballast's fill and dams."""
    c0, c1 = cavity_range_mm(p, pc)
    s0, s1 = max(c0, pc.s_start_mm) + margin_mm, min(c1, pc.s_end_mm) - margin_mm
    if pc.front_cut:
        s0 = max(s0, pc.s_start_mm + SPLICE_LENGTH_MM + margin_mm)
    if pc.rear_cut:
        s1 = min(s1, pc.s_end_mm - SPLICE_LENGTH_MM - margin_mm)
    return s0, s1


def _cavity_range(p: Params, pc: HullPiece) -> tuple[float, float]:
    t = p.hull.bulkhead_thickness_mm
    if pc.nose:
        s0 = nose_cap(p).s_cap_mm
    elif pc.front_joint is not None:
        s0 = pc.s_start_mm + t
    else:
        s0 = pc.s_start_mm - 1.0
    if pc.tail:
        s1 = pc.s_end_mm - p.caudal_fin.mount_length_mm - p.print.clearance_sliding_mm - t
    elif pc.rear_joint is not None:
        s1 = pc.s_end_mm - t
    else:
        s1 = pc.s_end_mm + 1.0
    return s0, s1


def clevis_room_reach_mm(p: Params, joint: int) -> float:
    """How far ahead of joint ``joint``'s axis the room its parent's rear end leaves for the link reaches (mm): the
    largest of the sector's, knuckle's and tongue's radii plus ``print.clearance_assembly_mm``
    (:func:`swiftfin.cad.clevis.clevis_cut` cuts those cylinders)."""
    h = joint_hardware(p, joint)
    return max(h.sector_radius_mm, h.knuckle_radius_mm, h.tongue_radius_mm) + p.print.clearance_assembly_mm


@dataclass(frozen=True)
class DryBulkhead:
    """The wall that closes the dry compartment at the rear (stations, mm): the rear end of the last sealed piece,
    solid from ``s_front_mm`` to the piece's end ``s_back_mm``. It is as thick as the cable glands need
    (``hull.cable_gland_length_mm`` of potted tube plus its seat's shoulder, and never thinner than
    ``hull.bulkhead_thickness_mm``), so each cable's gland runs through solid wall; joint ``rear_joint``'s clevis room
    is a pocket in its back face, and the cables that cross the joint on its hinge line leave through the back face
    (:func:`swiftfin.layout.gland_plan.bulkhead_passages`)."""
    piece: str
    rear_joint: int | None
    s_front_mm: float
    s_back_mm: float

    @property
    def s_dry_end_mm(self) -> float:
        """Where the dry cavity ends (the wall's front face)."""
        return self.s_front_mm


def dry_bulkhead(p: Params) -> DryBulkhead | None:
    """The rear wall of the dry compartment (:class:`DryBulkhead`), None when no hull piece is sealed."""
    sealed = [pc for pc in hull_pieces(p) if not flooded(p, pc.link)]
    if not sealed:
        return None
    last = max(sealed, key=lambda pc: pc.s_end_mm)
    if last.rear_joint is None:              # the whole hull is sealed: the fin socket's plug closes it
        return DryBulkhead(last.name, None, _cavity_range(p, last)[1], last.s_end_mm)
    return DryBulkhead(last.name, last.rear_joint, last.s_end_mm - dry_wall_thickness_mm(p), last.s_end_mm)


def dry_wall_thickness_mm(p: Params, gland_length_mm: float | None = None) -> float:
    """Thickness of the dry compartment's rear wall: the cable glands' length (``hull.cable_gland_length_mm``, or
    ``gland_length_mm``) and their seat's shoulder, never thinner than ``hull.bulkhead_thickness_mm``."""
    gland = p.hull.cable_gland_length_mm if gland_length_mm is None else gland_length_mm
    return max(p.hull.bulkhead_thickness_mm, gland + L.tube_seat_shoulder_mm(p))


def dry_wall_span_mm(p: Params) -> tuple[float, float, int | None] | None:
    """(front face, back face, joint behind) of the dry compartment's rear wall from the hull's segments alone
    (what :func:`dry_bulkhead` gives, without splitting the segments for the bed; so it never refuses a design the
    bed cannot hold): the last sealed segment's end, the wall :func:`dry_wall_thickness_mm` ahead of it. A hull
    sealed throughout: (its end, its end, None). None when nothing is sealed."""
    sealed = [seg for seg in L.hull_segments(p) if not flooded(p, seg.link)]
    if not sealed:
        return None
    last = max(sealed, key=lambda seg: seg.s_end_mm)
    if last.link + 1 > p.joints.count:
        return last.s_end_mm, last.s_end_mm, None
    return last.s_end_mm - dry_wall_thickness_mm(p), last.s_end_mm, last.link + 1


def flooded(p: Params, link: int) -> bool:
    """Whether the hull segments of ``link`` flood (``hull.flooded_from_joint``)."""
    return link >= p.hull.flooded_from_joint


SEAM_LAND_HEIGHT_MM = 1.0
"""How far a seam land stands above (upper half) and below the gasket's gap (lower half) [mm]: five layers. It
carries the sponge's push, about 0.1 N per mm of seam, as a ledge about 1 mm long, and it prints on the bed with
the seam face (both halves print cut face down), so it needs no support (engineering default)."""
SEAM_LAND_MARGIN_MM = 0.25
"""The seam face is this much wider than the sheet's least strip: a die-cut edge's placement (+/- 0.2 mm)."""


def _seam_land_need_mm(p: Params, s_mm: float) -> float:
    """How far the shell's wall falls short of the gasket's strip at station ``s_mm`` (may be negative)."""
    from swiftfin.catalogues.seals import seam_gasket
    ds = 0.25
    slope = (hull_section_semi_axes_mm(p, s_mm + ds)[0] - hull_section_semi_axes_mm(p, max(s_mm - ds, 0.0))[0]) / (
        s_mm + ds - max(s_mm - ds, 0.0))
    need = (seam_gasket().min_width_mm() + SEAM_LAND_MARGIN_MM) * math.sqrt(1.0 + slope**2)
    return need - p.hull.wall_thickness_mm


@functools.lru_cache(maxsize=64)
def _piece_needs_land(p: Params, pc: HullPiece) -> bool:
    """Whether the wall falls short of the gasket's strip anywhere on the piece's cavity (every
    :data:`LAND_PROBE_STEP_MM`, both ends included)."""
    c0, c1 = cavity_range_mm(p, pc)
    n = max(2, int(math.ceil((c1 - c0) / LAND_PROBE_STEP_MM)) + 1)
    return any(_seam_land_need_mm(p, float(s)) > 0.0 for s in np.linspace(c0, c1, n))


LAND_PROBE_STEP_MM = 0.5
"""Station step at which a piece's cavity is probed for a wall narrower than the gasket's strip [mm]."""


def seam_land_mm(p: Params, pc: HullPiece, s_mm: float) -> float:
    """How far inward from the shell's inner wall a sealed piece's seam face is widened at station ``s_mm`` (both
    halves, at the seam plane, measured across the body like the wall), so that the gasket's strip, measured square
    to the skin's line in the plane, is the sheet's least width (catalogues/seals.toml ``min_width_thicknesses``) plus
    :data:`SEAM_LAND_MARGIN_MM`: where the skin's line runs at slope w'(s) to the axis the strip is w / sqrt(1 + w'^2)
    wide. 0 when the piece has no gasket or its wall is wide enough along the whole cavity.

    A piece that needs a land anywhere gets one along its whole cavity, never narrower than one line width
    (``print.line_width_mm``): the land is a loft of the inner sections shrunk by it, and where it came to nothing
    that loft met the cavity's own surface, which OpenCascade cannot fuse (a design with a 2.9 mm wall, short by
    0.03 mm at the cavity's front end only, built no head at all: "expected one solid, got 0"). Narrower than a
    line, a land would not print anyway."""
    if seam_gasket_gap_mm(p, pc) <= 0 or not _piece_needs_land(p, pc):
        return 0.0
    return max(_seam_land_need_mm(p, s_mm), p.print.line_width_mm)


def seam_gasket_gap_mm(p: Params, pc: HullPiece) -> float:
    """How far below the seam plane the lower half of ``pc`` stops [mm]: the seam gasket's compressed thickness, the
    length of the compression limiters round the seam screws (catalogues/seals.toml ``[seam_gasket]``), for a sealed
    piece split into halves; 0 otherwise (the halves meet face to face). The gap spans the piece from its front to
    its rear end (the dry wall's back face); the clevis lugs behind it keep the seam plane."""
    from swiftfin.catalogues.seals import seam_gasket
    if not p.hull.split_halves or flooded(p, pc.link):
        return 0.0
    return seam_gasket().limiter_length_mm()


# ----------------------------------------------------------------------------------------------- fasteners
def head_hollow_mm(p: Params) -> tuple[float, float] | None:
    """Stations [s0, s1] of the head's hollow (link 0's pieces: behind the nose cap, ahead of the dry compartment's
    rear wall), where the components ride; None when no hull piece is on the head."""
    head = [pc for pc in hull_pieces(p) if pc.link == 0]
    if not head:
        return None
    return (min(cavity_range_mm(p, pc)[0] for pc in head), max(cavity_range_mm(p, pc)[1] for pc in head))


def component_problems(p: Params) -> list:
    """The components of ``params.components`` that cannot be where they are. They ride on the head (link 0:
    ``swiftfin.cad.bought`` and the mass model put them there), so each box must lie in the head's hollow, between
    the nose cap and the dry compartment's rear wall, with every corner inside the hull's inner surface by
    ``print.clearance_assembly_mm`` (:func:`swiftfin.layout.geometry.inner_envelope_excess_mm`, the assembly
    check's own test). Found when the design loads, naming the key, instead of by the assembly check at the end of
    a build. (The mass placeholder ``fasteners``, if a design still has one, is not a box in the hull.)"""
    hollow = head_hollow_mm(p)
    if hollow is None:
        return []
    found = (component_problem(p, i, comp, hollow) for i, comp in enumerate(p.components))
    return [pr for pr in found if pr is not None]


def component_problem(p: Params, i: int, comp, hollow: tuple[float, float]):
    """The problem of component ``comp`` (``components[i]``) in the head's hollow ``hollow`` (:func:`head_hollow_mm`),
    or None where it fits (see :func:`component_problems`)."""
    from swiftfin.core.params import Problem
    if comp.name == "fasteners":
        return None
    lo, hi = hollow
    c = p.print.clearance_assembly_mm
    sx, sy, sz = comp.size_mm
    sc = comp.station_fraction * p.body.length_mm
    if sc - sx / 2 < lo + c or sc + sx / 2 > hi - c:
        return Problem(f"components[{i}].station_fraction", comp.station_fraction,
                       f"{comp.name!r} ({sx:g} mm long) at s = {sc - sx / 2:.1f}..{sc + sx / 2:.1f} mm leaves "
                       f"the head's hollow (s = {lo + c:.1f}..{hi - c:.1f} mm with the assembly clearance): "
                       f"components ride on the head, between the nose and the dry compartment's rear wall")
    corners = np.array([(-sc + i_ * sx / 2, j * sy / 2, comp.z_mm + k * sz / 2)
                        for i_ in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
    worst = float(L.inner_envelope_excess_mm(p, corners).max())
    if worst > -c:
        return Problem(f"components[{i}].z_mm", comp.z_mm,
                       f"{comp.name!r} ({sx:g} x {sy:g} x {sz:g} mm at s = {sc:.1f} mm) has a corner "
                       f"{worst + c:.1f} mm past the hull's inner surface less print.clearance_assembly_mm "
                       f"({c:g} mm): move it (z_mm, station_fraction) or make it smaller (size_mm)")
    return None


def part_label(p: Params, pc: HullPiece, half: str) -> str:
    """Label of the printed part of ``pc`` holding its ``half`` ("upper"/"lower"): the half, or the whole piece."""
    return f"{pc.name}_{half}" if p.hull.split_halves else pc.name


def head_lid_labels(p: Params) -> tuple[str, ...]:
    """The upper halves of the head's pieces (link 0), in order: the lid that closes the head last. The drive is
    built in the lower halves first (motors on their mounts, spools fixed on their shafts, cables wound and
    tensioned at the split spools), then the upper halves go on (their wall screws into the mounts are driven from
    outside, through them). The drive's screws inside the head are driven before the lid is on; a record lists
    these labels in its ``installed_after``. Empty for a hull that is not split (there is no lid to leave off)."""
    if not p.hull.split_halves:
        return ()
    return tuple(part_label(p, pc, "upper") for pc in hull_pieces(p) if pc.link == 0)


def _y_out(a: float, b: float, z: float) -> float:
    """Outer half-width at height z of the section with semi-axes a, b (0 beyond the section)."""
    return a * math.sqrt(max(0.0, 1.0 - (z / b) ** 2))


def _z_out(a: float, b: float, y: float) -> float:
    """Outer half-height at lateral offset y (0 beyond the section)."""
    return b * math.sqrt(max(0.0, 1.0 - (y / a) ** 2))


def _semi_axes_under(p: Params, s_mm: float, r_mm: float) -> tuple[float, float]:
    """The smallest outer section over [s - r, s + r] (a boss of radius r there must fit the narrowest)."""
    return min((hull_section_semi_axes_mm(p, s_mm + d) for d in (-r_mm, 0.0, r_mm)), key=lambda ab: ab[0])


def seam_screw_radius_mm(p: Params) -> float:
    """Radius of a seam screw's boss (upper half) and column (lower half): the insert boss rule and two perimeters
    round the counterbore, plus the margin."""
    s, lw = fastener(p.hull.screw_diameter_mm), p.print.line_width_mm
    return max(s.insert_boss_od_mm(lw) / 2, s.counterbore_diameter_mm / 2 + 2 * lw) + SEAM_MARGIN_MM


def seam_dowel_radius_mm(p: Params) -> float:
    return p.hull.seam_dowel_diameter_mm / 2 + 2 * p.print.line_width_mm + SEAM_MARGIN_MM


def boss_floor_mm(p: Params) -> float:
    """Material closing a blind pocket: its end is a top surface in print orientation (print.top_layers)."""
    return p.print.top_layers * p.print.layer_height_mm


def seam_dowel_length_mm(p: Params, gap_mm: float = 0.0) -> float:
    """ISO 8734 length: at least 2 d in each half, across the seam gasket's gap ``gap_mm`` (centred on it)."""
    d = p.hull.seam_dowel_diameter_mm
    length = dowel(d).length_for(4 * d + gap_mm)
    if length is None:
        raise BuildError(f"no {d:g} mm dowel of {4 * d + gap_mm:g} mm or more in catalogues/pins.toml")
    return length


def seam_dowel_depth_mm(p: Params, gap_mm: float = 0.0) -> float:
    """How deep a seam dowel's bore runs from the seam plane into the lower half (the deeper of the two: the pin is
    centred on the gasket's gap, ``gap_mm`` below the plane), with the bore's overrun [mm]."""
    return (seam_dowel_length_mm(p, gap_mm) + gap_mm) / 2 + BORE_OVERRUN_MM


def seam_axis_y_mm(p: Params, s_mm: float, kind: str, gap_mm: float = 0.0) -> float:
    """|y| of a seam screw's (or dowel's) vertical axis at station s: as far out as its hole's wall to the skin
    allows (insert: the insert maker's wall over the pocket's depth; dowel: two perimeters over the bore, which
    crosses the seam gasket's gap ``gap_mm``)."""
    lw = p.print.line_width_mm
    if kind == "screw":
        s = fastener(p.hull.screw_diameter_mm)
        r, depth = seam_screw_radius_mm(p), s.insert_pocket_depth_mm
        need = s.insert_hole_mm / 2 + max(2 * lw, s.insert_wall_min_mm)
    else:
        r, depth = seam_dowel_radius_mm(p), seam_dowel_depth_mm(p, gap_mm)
        need = p.hull.seam_dowel_diameter_mm / 2 + 2 * lw
    a, b = _semi_axes_under(p, s_mm, r)
    return _y_out(a, b, depth) - need - SEAM_MARGIN_MM


@dataclass(frozen=True)
class SeamFeature:
    """A screw or dowel across the seam of a piece: vertical axis at (x = -s, y), bosses grown from the seam face."""
    kind: str                 # "screw" | "dowel"
    piece: str
    side: int                 # +1: on the +y side, -1: on the -y side
    index: int                # along the side, nose to tail
    s_mm: float
    y_mm: float
    boss_radius_mm: float
    upper_height_mm: float    # boss above the seam face in the upper half
    lower_depth_mm: float     # boss below it in the lower half (a screw's column: down to the skin)


def _seam_range(p: Params, pc: HullPiece) -> tuple[float, float]:
    """Stations [lo, hi] the features' centres may take: out of the bulkheads and the tail plug, and the feature
    out of the swing of the link behind."""
    t = p.hull.bulkhead_thickness_mm
    r = max(seam_screw_radius_mm(p), seam_dowel_radius_mm(p))
    e = BOSS_OVERLAP_MM    # a boss reaches this far into a bulkhead (solids that overlap fuse cleanly; tangent ones
    #                        leave faces that touch along a line) and stays this far from a cut end
    lo = pc.s_start_mm + (t + r - e if pc.front_joint is not None else r + e)
    if pc.front_cut:      # a station splice: its tabs and screws take SPLICE_LENGTH_MM on each side of the cut
        lo = max(lo, pc.s_start_mm + SPLICE_LENGTH_MM + r + e)
    if pc.nose:
        lo = max(lo, nose_cap(p).s_cap_mm + r - e)
    hi = pc.s_end_mm - (t + r - e if pc.rear_joint is not None else r + e)
    if pc.rear_cut:
        hi = min(hi, pc.s_end_mm - SPLICE_LENGTH_MM - r - e)
    if pc.tail:
        hi = min(hi, pc.s_end_mm - p.caudal_fin.mount_length_mm - p.print.clearance_sliding_mm - t - r + e)
    if pc.rear_joint is not None:
        h = joint_hardware(p, pc.rear_joint)
        reach = max(h.sector_radius_mm, h.block_outer_radius_mm, h.tongue_radius_mm) + p.print.clearance_assembly_mm
        s_axis = -h.x_mm
        while hi > lo and math.hypot(s_axis - hi, seam_axis_y_mm(p, hi, "screw")) - r < reach:
            hi -= 0.5
    return lo, hi


def _guide_footprints(p: Params, pc: HullPiece) -> list[tuple[str, float, float, float, float]]:
    """(label, x0, x1, y0, y1) of each PTFE guide over the seam of ``pc`` in plan (its box: it holds the guide,
    which the hull's clip and the spools' keep-outs only cut down); none off the head, or where the guides cannot be
    laid out (their own plan says why)."""
    if pc.link != 0:
        return []
    try:
        blocks = bare_guide_blocks(p)
    except UserError:
        return []
    return [(b.label, *b.x_mm, *b.y_mm) for b in blocks
            if b.z_mm[0] > 0 and -b.x_mm[1] < pc.s_end_mm and -b.x_mm[0] > pc.s_start_mm]


def _plan_gap_mm(s_mm: float, y_mm: float, r_mm: float, box) -> float:
    """Gap in plan between a boss (circle of ``r_mm`` at x = -s, y) and a guide's box (<= 0: it stands under it)."""
    _, x0, x1, y0, y1 = box
    x = -s_mm
    dx, dy = max(x0 - x, 0.0, x - x1), max(y0 - y_mm, 0.0, y_mm - y1)
    return math.hypot(dx, dy) - r_mm


SEAM_NUDGE_STEP_MM = 0.5
"""Step along the seam by which a feature standing under a guide is moved out from under it."""


def _clear_of_the_guides(p: Params, pc: HullPiece, ss: list[float], side_kinds: dict, lo: float, hi: float,
                         gap: float) -> list[float]:
    """The seam stations ``ss`` with each feature whose upper-half boss would stand under a PTFE guide in plan, or
    within ``print.clearance_sliding_mm`` of it, moved along the seam until it clears (toward the nearer free
    station, keeping [lo, hi] and its neighbours' bosses apart): lifted off, the upper half's bosses rise past the
    guides, which stay on the motors' mounts. ``hull.seam_screw_spacing_mm = 30`` put a boss 0.27 mm under the bay
    guide and the assembly steps found no way to open the head (2026-12-07). Raises BuildError when none clears."""
    boxes = _guide_footprints(p, pc)
    if not boxes:
        return ss
    need = p.print.clearance_sliding_mm
    radius = {"screw": seam_screw_radius_mm(p), "dowel": seam_dowel_radius_mm(p)}

    def clear(i: int, s: float) -> bool:
        for side, kinds in side_kinds.items():
            kind = kinds[i]
            y = side * seam_axis_y_mm(p, s, kind, gap)
            if any(_plan_gap_mm(s, y, radius[kind], b) < need for b in boxes):
                return False
        return True

    def apart(i: int, s: float, out: list[float]) -> bool:
        r_i = max(radius[kinds[i]] for kinds in side_kinds.values())
        for j in (i - 1, i + 1):
            if 0 <= j < len(out):
                r_j = max(radius[kinds[j]] for kinds in side_kinds.values())
                if (s - out[j]) * (i - j) < r_i + r_j:      # its side of the neighbour, the bosses apart
                    return False
        return True

    out = list(ss)
    for i, s0 in enumerate(ss):
        if clear(i, s0):
            continue
        tries = [s0 + sign * SEAM_NUDGE_STEP_MM * k for k in range(1, 400) for sign in (-1, 1)]
        s_new = next((s for s in tries if lo <= s <= hi and clear(i, s) and apart(i, s, out)), None)
        if s_new is None:
            over = ", ".join(b[0] for b in boxes if any(
                _plan_gap_mm(s0, side * seam_axis_y_mm(p, s0, kinds[i], gap), radius[kinds[i]], b) < need
                for side, kinds in side_kinds.items()))
            raise BuildError(f"hull.seam_screw_spacing_mm = {p.hull.seam_screw_spacing_mm:g}: {pc.name}'s seam "
                             f"{side_kinds[1][i]} at s = {s0:.1f} mm stands under a PTFE guide ({over}) in plan, and "
                             f"no station between {lo:.1f} and {hi:.1f} mm clears it by print.clearance_sliding_mm "
                             f"({need:g} mm) away from its neighbours: the head's lid could not be lifted off past it; "
                             f"choose another spacing")
        out[i] = s_new
    return out


def seam_features(p: Params, pc: HullPiece) -> tuple[SeamFeature, ...]:
    """Screws and dowels along both sides of the seam of ``pc`` (none when the hull is not split)."""
    if not p.hull.split_halves:
        return ()
    lo, hi = _seam_range(p, pc)
    rs, rd = seam_screw_radius_mm(p), seam_dowel_radius_mm(p)
    if hi < lo:
        raise BuildError(f"{pc.name}: no room for a seam screw between its bulkheads ({lo:.1f} > {hi:.1f} mm)")
    n = max(1, math.ceil((hi - lo) / p.hull.seam_screw_spacing_mm - 1e-9))
    with_dowel = (hi - lo) / n >= rs + rd
    k = n + (1 if with_dowel else 0)
    ss = [0.5 * (lo + hi)] if k == 1 else [lo + i * (hi - lo) / (k - 1) for i in range(k)]
    screw = fastener(p.hull.screw_diameter_mm)
    floor = boss_floor_mm(p)
    gap = seam_gasket_gap_mm(p, pc)
    ld = seam_dowel_length_mm(p, gap)
    side_kinds = {}
    for side in (1, -1):
        kinds = ["screw"] * n
        if with_dowel:
            kinds = ["dowel"] + kinds if side > 0 else kinds + ["dowel"]
        side_kinds[side] = kinds
    ss = _clear_of_the_guides(p, pc, ss, side_kinds, lo, hi, gap)
    out = []
    for side in (1, -1):
        for i, (kind, s) in enumerate(zip(side_kinds[side], ss)):
            y = side * seam_axis_y_mm(p, s, kind, gap)
            if kind == "screw":
                a, b = _semi_axes_under(p, s, rs)
                out.append(SeamFeature(kind, pc.name, side, i, s, y, rs, screw.insert_pocket_depth_mm + floor,
                                       b + 1.0))
            else:                   # the pin centred on the gasket's gap: (ld - gap) / 2 in each half
                out.append(SeamFeature(kind, pc.name, side, i, s, y, rd, (ld - gap) / 2 + BORE_OVERRUN_MM + floor,
                                       seam_dowel_depth_mm(p, gap) + floor))
    return tuple(out)


def _seam_fasteners(p: Params, pc: HullPiece) -> list[Fastener]:
    s = fastener(p.hull.screw_diameter_mm)
    up, lo = part_label(p, pc, "upper"), part_label(p, pc, "lower")
    out = []
    for f in seam_features(p, pc):
        tag = f"{pc.name}_seam_{'p' if f.side > 0 else 'm'}y_{f.index + 1}"
        if f.kind == "dowel":
            gap = seam_gasket_gap_mm(p, pc)
            ld = seam_dowel_length_mm(p, gap)
            out.append(Fastener(tag, f"{p.hull.seam_dowel_diameter_mm:g}", "dowel", "press",
                                (-f.s_mm, f.y_mm, -(ld + gap) / 2),
                                (0.0, 0.0, 1.0), ld, 0.0, None, up, f"aligns the halves of {pc.name}", pc.link,
                                meta={"joins_parts": (lo,), "slip_part": lo}))
            continue
        a, b = _semi_axes_under(p, f.s_mm, f.boss_radius_mm)
        y = abs(f.y_mm)
        r_head = s.head_diameter_mm / 2
        # the head (its counterbore depth) sinks fully below the skin; the clearance hole keeps two perimeters
        g_head = _z_out(a, b, y + r_head + SEAM_MARGIN_MM) - s.counterbore_depth_mm
        g_hole = _z_out(a, b, y + s.clearance_hole_mm / 2 + 2 * p.print.line_width_mm + SEAM_MARGIN_MM)
        length = s.length_at_most(min(g_head, g_hole) + s.insert_length_mm)
        grip = None if length is None else length - s.insert_length_mm
        if grip is None or grip < 2 * p.print.line_width_mm:
            raise BuildError(f"{tag}: no {s.name} length leaves its head under the skin (room {g_head:.1f} mm)")
        recess = _z_out(a, b, max(0.0, y - s.counterbore_diameter_mm / 2)) - grip
        out.append(Fastener(tag, s.name, "cap_screw", "insert", (-f.s_mm, f.y_mm, -grip), (0.0, 0.0, 1.0), length,
                            grip, lo, up, f"closes the seam of {pc.name} (from the belly)", pc.link,
                            recess_mm=recess, recess_open_toward=(0.0, float(f.side), 0.0)))
    return out


@dataclass(frozen=True)
class SpliceJoint:
    """The screwed splice at a station cut (front piece: tabs; rear piece: pads). Depths are the shrinks of the
    hull's loft (both semi-axes reduced), which the solids use directly."""
    s_cut_mm: float
    s_screw_mm: float
    y_abs_mm: float            # the screws and tabs at y = +-y_abs
    tab_half_width_mm: float
    pad_half_width_mm: float
    pad_shrink_mm: float       # the rear piece's shell is this thick under the tabs' zone
    tab_outer_shrink_mm: float
    tab_inner_shrink_mm: float
    normal_yz: tuple[float, float]   # inward unit normal of the skin at the +y, upper screw (the screw's axis)


def _shrink_for_depth(a: float, b: float, point, normal, depth: float) -> float:
    """The loft shrink whose ellipse the ray point + u normal meets at u = depth (bisection)."""
    y0, z0 = point
    ny, nz = normal
    y, z = y0 + depth * ny, z0 + depth * nz
    lo, hi = 0.0, 2 * depth + 1.0
    for _ in range(60):
        d = 0.5 * (lo + hi)
        if (y / (a - d)) ** 2 + (z / (b - d)) ** 2 > 1.0:
            hi = d          # the point is outside the shrunk ellipse: shrink less
        else:
            lo = d
    return 0.5 * (lo + hi)


def _splice_axis(p: Params, s_mm: float, upper: bool) -> tuple[tuple[float, float], tuple[float, float], float]:
    """(skin point (y, z) at +y, inward unit normal (ny, nz), y_abs) of a splice screw at station s."""
    a, b = hull_section_semi_axes_mm(p, s_mm)
    y = SPLICE_Y_FRACTION * (a - p.hull.wall_thickness_mm)
    z = _z_out(a, b, y) * (1 if upper else -1)
    ny, nz = -y / a**2, -z / b**2
    n = math.hypot(ny, nz)
    return (y, z), (ny / n, nz / n), y


def splice_screw_length_mm(p: Params) -> tuple[float, float]:
    """(length, grip): the shortest screw clamping a wall's thickness of pad plus the sliding gap into an insert."""
    s = fastener(p.hull.screw_diameter_mm)
    length = s.length_for(p.hull.wall_thickness_mm + p.hull.splice_fit_clearance_mm + s.insert_length_mm)
    if length is None:
        raise BuildError(f"no {s.name} screw long enough for the hull splice")
    return length, length - s.insert_length_mm


def splice_recess_mm(p: Params) -> float:
    """Head below the skin: the counterbore depth and the margin for the skin's curvature over the head."""
    return fastener(p.hull.screw_diameter_mm).counterbore_depth_mm + 0.3


def splice_joint(p: Params, front: HullPiece) -> SpliceJoint:
    """Numbers of the splice behind ``front`` (a piece with ``rear_cut``)."""
    s = fastener(p.hull.screw_diameter_mm)
    sc = front.s_end_mm + SPLICE_LENGTH_MM / 2
    a, b = hull_section_semi_axes_mm(p, sc)
    pt, n, y = _splice_axis(p, sc, True)
    _, grip = splice_screw_length_mm(p)
    u_tab = splice_recess_mm(p) + grip
    outer = _shrink_for_depth(a, b, pt, n, u_tab)
    inner = _shrink_for_depth(a, b, pt, n, u_tab + s.insert_pocket_depth_mm + boss_floor_mm(p))
    w = seam_screw_radius_mm(p) + 1.0
    return SpliceJoint(front.s_end_mm, sc, y, w, w + p.hull.splice_fit_clearance_mm + 2 * p.print.line_width_mm,
                       outer - p.hull.splice_fit_clearance_mm, outer, inner, n)


def _splice_fasteners(p: Params, front: HullPiece, rear: HullPiece) -> list[Fastener]:
    s = fastener(p.hull.screw_diameter_mm)
    sj = splice_joint(p, front)
    length, grip = splice_screw_length_mm(p)
    recess = splice_recess_mm(p)
    out = []
    for half, upper in (("upper", True), ("lower", False)):
        (y, z), (ny, nz), _ = _splice_axis(p, sj.s_screw_mm, upper)
        for sg, tag in ((1, "py"), (-1, "my")):
            head = (-sj.s_screw_mm, sg * (y + recess * ny), z + recess * nz)
            out.append(Fastener(f"{front.name}_splice_{half}_{tag}", s.name, "cap_screw", "insert", head,
                                (0.0, sg * ny, nz), length, grip, part_label(p, rear, half),
                                part_label(p, front, half), f"splices {front.name} to {rear.name} ({half})",
                                front.link, recess_mm=recess))
    return out


def hull_fasteners(p: Params) -> tuple[Fastener, ...]:
    """Every fastener joining hull parts: the seams' screws and dowels and the station splices' screws."""
    pieces = hull_pieces(p)
    out: list[Fastener] = []
    for pc in pieces:
        out += _seam_fasteners(p, pc)
    for front, rear in zip(pieces[:-1], pieces[1:]):
        if front.rear_cut:
            out += _splice_fasteners(p, front, rear)
    return tuple(out)
