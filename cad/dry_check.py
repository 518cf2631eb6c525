"""Openings in the dry compartment's wall, found on the solids (issue 13: "a check, on the solids, that the dry
cavity is closed").

The dry compartment is the hull of the sealed links (every link ahead of ``hull.flooded_from_joint``): its shell
from the nose to the rear face of the last sealed piece, and that piece's rear bulkhead. The check builds, from
the layout's numbers alone (numpy rings, no CAD kernel), the **wall zone**: the outer envelope shrunk by
:data:`INSET_MM` less the cavity envelope (shrunk by the wall, stopped a bulkhead short of the rear face) grown by
it, so the zone lies strictly inside the wall where the printed wall should be solid. What of that zone the
sealed hull parts do not fill is a cut in the wall: a screw's counterbore, a vent, a tube hole, a window left by
a clearance cut. Each connected piece of it (manifold3d ``decompose``) is an :class:`Opening`; it goes **through**
when it reaches both the outer and the inner skin layer of the zone (a layer :data:`LAYER_MM` thick on each side)
and the cavity's air there (the largest piece of the cavity, grown into that skin, less the parts), rather than
material behind the wall: a screw's counterbore that ends in a column is not an opening.

Seams (the faces where two sealed pieces meet) are not cuts: :func:`seams` lists the pairs of sealed hull parts
that touch, each of which needs a seal of its own. On a hull split into halves the sealed pieces' lower halves stop
the seam gasket's gap below the seam plane (:mod:`swiftfin.cad.seal`), so the halves meet only through the gasket,
which is one of the wall's parts here (:func:`sealed_part_labels`): without it the gap is an opening all round the
head and the build is refused. The splice between the head's pieces is bonded (``bonded_seam``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from swiftfin.core.schema import Params
from swiftfin.layout.hull_plan import dry_bulkhead, hull_pieces, hull_section_semi_axes_mm, nose_cap

INSET_MM = 0.25
"""The wall zone keeps this far inside the printed wall's faces: the loft between its stations (< 0.05 mm), the
tessellation (``export.mesh_tolerance_mm``) and the envelope's polygon (< 0.03 mm) stay outside it."""
LAYER_MM = 0.1
"""Thickness of the skin layers that tell a through-opening from a pocket: a pocket that leaves more than
INSET_MM + LAYER_MM of wall under it is blind."""
RING_POINTS = 128
STATION_STEP_MM = 2.0
MIN_OPENING_MM3 = 0.05
"""Pieces of the wall zone smaller than this are tessellation slivers, not openings."""


@dataclass(frozen=True)
class Opening:
    part: str                                  # the sealed hull part nearest to it
    centre_mm: tuple[float, float, float]
    size_mm: tuple[float, float, float]        # its bounding box
    volume_mm3: float
    through: bool

    def __str__(self) -> str:
        c = ", ".join(f"{v:.1f}" for v in self.centre_mm)
        s = " x ".join(f"{v:.1f}" for v in self.size_mm)
        kind = "opening through the dry wall" if self.through else "pocket in the dry wall"
        return f"{self.part}: {kind} at ({c}) mm, {s} mm, {self.volume_mm3:.1f} mm^3"


def sealed_pieces(p: Params):
    return tuple(pc for pc in hull_pieces(p) if pc.link < p.hull.flooded_from_joint)


def sealed_part_labels(p: Params) -> tuple[str, ...]:
    """The parts whose union is the dry compartment's wall: the sealed pieces' halves (or whole pieces), and the
    seam gasket between the halves when they have one (:mod:`swiftfin.cad.seal`)."""
    from swiftfin.cad.seal import gasket_label
    from swiftfin.layout.hull_plan import seam_gasket_gap_mm
    out = []
    for pc in sealed_pieces(p):
        out += [f"{pc.name}_upper", f"{pc.name}_lower"] if p.hull.split_halves else [pc.name]
    out += [gasket_label(link) for link in sorted({pc.link for pc in sealed_pieces(p)
                                                   if seam_gasket_gap_mm(p, pc) > 0})]
    return tuple(out)


def _envelope(p: Params, s0: float, s1: float, shrink_mm: float, s_apex: float | None = None):
    """Closed mesh of the hull's ellipses between stations s0 and s1, both semi-axes less ``shrink_mm`` (negative:
    grown). ``s_apex``: close the front in a point at that station instead of a flat cap."""
    import manifold3d as m3d

    n = max(3, int(math.ceil((s1 - s0) / STATION_STEP_MM)) + 1)
    ss = np.linspace(s0, s1, n)
    t = np.linspace(0.0, 2 * math.pi, RING_POINTS, endpoint=False)
    rings = []
    for s in ss:
        a, b = hull_section_semi_axes_mm(p, float(s))
        a, b = max(a - shrink_mm, 1e-3), max(b - shrink_mm, 1e-3)
        rings.append(np.column_stack([np.full(RING_POINTS, -s), a * np.cos(t), b * np.sin(t)]))
    verts = np.vstack(rings)
    faces = []
    for i in range(n - 1):
        for k in range(RING_POINTS):
            a0, a1 = i * RING_POINTS + k, i * RING_POINTS + (k + 1) % RING_POINTS
            b0, b1 = a0 + RING_POINTS, a1 + RING_POINTS
            faces += [(a0, b0, b1), (a0, b1, a1)]
    front = len(verts)
    back = front + 1
    fx = -(s_apex if s_apex is not None else s0)
    verts = np.vstack([verts, [[fx, 0.0, 0.0], [-s1, 0.0, 0.0]]])
    last = (n - 1) * RING_POINTS
    for k in range(RING_POINTS):
        faces.append((front, k, (k + 1) % RING_POINTS))
        faces.append((back, last + (k + 1) % RING_POINTS, last + k))
    mesh = m3d.Mesh(vert_properties=np.asarray(verts, dtype=np.float32), tri_verts=np.asarray(faces, dtype=np.uint32))
    man = m3d.Manifold(mesh)
    if man.status() != m3d.Error.NoError or man.volume() <= 0:      # wound the other way round
        mesh = m3d.Mesh(vert_properties=np.asarray(verts, dtype=np.float32),
                        tri_verts=np.asarray([f[::-1] for f in faces], dtype=np.uint32))
        man = m3d.Manifold(mesh)
    return man


def wall_zone(p: Params, inset_mm: float = INSET_MM, with_cavity: bool = False):
    """(zone, outer layer, inner layer) as manifolds: the part of the dry wall that must be solid, and its skins;
    ``with_cavity``: also the cavity grown into the zone's inner skin."""
    dry = dry_bulkhead(p)
    if dry is None:
        raise ValueError("no sealed hull piece: hull.flooded_from_joint = 0")
    s_end, c1 = dry.s_back_mm, dry.s_dry_end_mm
    w = p.hull.wall_thickness_mm
    s_cap = nose_cap(p).s_cap_mm
    tip = 0.5                      # the apex: a small step behind the nose tip
    outer = _envelope(p, tip + inset_mm, s_end - inset_mm, inset_mm, s_apex=inset_mm)
    outer2 = _envelope(p, tip + inset_mm + LAYER_MM, s_end - inset_mm - LAYER_MM, inset_mm + LAYER_MM,
                       s_apex=inset_mm + LAYER_MM)
    inner = _envelope(p, s_cap - inset_mm, c1 + inset_mm, w - inset_mm)
    inner2 = _envelope(p, s_cap - inset_mm - LAYER_MM, c1 + inset_mm + LAYER_MM, w - inset_mm - LAYER_MM)
    zone = outer - inner
    if with_cavity:
        return zone, zone - outer2, inner2 - inner, inner2
    return zone, zone - outer2, inner2 - inner


def wall_openings(p: Params, manifolds: dict) -> list[Opening]:
    """Every cut in the dry wall of the built sealed hull parts (``manifolds``: label -> manifold3d.Manifold)."""
    import manifold3d as m3d

    labels = [lb for lb in sealed_part_labels(p) if lb in manifolds]
    if not labels:
        raise ValueError(f"none of the sealed hull parts {sealed_part_labels(p)} was built")
    union = m3d.Manifold.batch_boolean([manifolds[lb] for lb in labels], m3d.OpType.Add)
    zone, outer_layer, inner_layer, cavity = wall_zone(p, with_cavity=True)
    holes = zone - union
    # the cavity's air: the cavity grown into the wall zone's inner skin, less the parts; its largest piece is the
    # dry volume itself (air in a counterbore that ends in a boss is a piece of its own)
    air_pieces = (cavity - union).decompose()
    air = max(air_pieces, key=lambda m: m.volume()) if air_pieces else cavity
    out = []
    for piece in holes.decompose():
        vol = piece.volume()
        if vol < MIN_OPENING_MM3:
            continue
        through = (piece ^ outer_layer).volume() > 1e-3 and (piece ^ air).volume() > 1e-3
        bb = np.asarray(piece.bounding_box(), dtype=float)
        lo, hi = bb[:3], bb[3:]
        centre = tuple(float(c) for c in (lo + hi) / 2)
        near = min(labels, key=lambda lb: manifolds[lb].min_gap(piece, 5.0))
        out.append(Opening(near, centre, tuple(float(v) for v in hi - lo), float(vol), bool(through)))
    return sorted(out, key=lambda o: (not o.through, o.centre_mm[0]))


def seams(p: Params, manifolds: dict, gap_mm: float = 0.05) -> list[tuple[str, str]]:
    """Pairs of sealed hull parts that touch (their joint faces need a seal)."""
    labels = [lb for lb in sealed_part_labels(p) if lb in manifolds]
    out = []
    for i, a in enumerate(labels):
        for b in labels[i + 1:]:
            if manifolds[a].min_gap(manifolds[b], gap_mm) <= gap_mm:
                out.append((a, b))
    return out


# ----------------------------------------------------------------------------------------------- sealed crossings
@dataclass(frozen=True)
class SealedCrossing:
    """A declared crossing of the dry wall and how it is sealed (catalogues/seals.toml): an axis, a radius round it
    that the hole stays inside, and the seal."""
    kind: str                                   # "cable_gland" | "bedded_screw"
    label: str
    start_mm: tuple[float, float, float]
    end_mm: tuple[float, float, float]
    radius_mm: float
    packed_mm: float = 0.0                      # a cable gland's potted tube length through the wall
    stroke_mm: float = 0.0                      # its cable's stroke (moment arm x stop angle)
    joint: int = 0


AXIS_TOLERANCE_MM = 0.3
"""A hole belongs to a declared crossing when it lies within the crossing's radius plus this of its axis (the
tessellation and the loft's departure from the exact ellipse stay under it)."""


def cable_glands(p: Params) -> tuple[SealedCrossing, ...]:
    """The cable glands through the dry compartment's rear wall (:func:`swiftfin.layout.gland_plan.cable_glands`) as
    declared crossings: along each cable's bore from ahead of the wall's dry face (where the bore is cut from) to
    2 mm past its back face, the bore's radius round it; ``packed_mm`` is the tube's length from its mouth on the
    dry face to its seat."""
    from swiftfin.layout import gland_plan
    from swiftfin.layout.geometry import tube_bore_diameter_mm
    r = tube_bore_diameter_mm(p, "bulkhead") / 2
    out = []
    for g in gland_plan.cable_glands(p):
        u = g.axis
        ahead = gland_plan.bore_ahead_mm(p, u[0])
        out.append(SealedCrossing("cable_gland", g.label, tuple(map(float, np.asarray(g.front_mm) - ahead * u)),
                                  tuple(map(float, np.asarray(g.back_mm) + 2 * u)), r, g.packed_mm, g.stroke_mm,
                                  g.joint))
    return tuple(out)


def bedded_screws(p: Params) -> tuple[SealedCrossing, ...]:
    """Every cap screw with a sealed hull part under its head or round its thread: where its hole crosses the dry
    wall it is bedded in sealant (catalogues/seals.toml ``[bedded_screw]``)."""
    from swiftfin.cad.fastening import all_fasteners
    from swiftfin.catalogues.fasteners import fastener
    sealed = set(sealed_part_labels(p))
    out = []
    for f in all_fasteners(p):
        if f.kind != "cap_screw" or not ({f.head_part, f.thread_part} & sealed):
            continue
        a = np.asarray(f.axis, float)
        h = np.asarray(f.head_mm, float)
        r = fastener(f.size).counterbore_diameter_mm / 2
        out.append(SealedCrossing("bedded_screw", f.label, tuple(map(float, h - 6.0 * a)),
                                  tuple(map(float, h + (f.length_mm + 1.0) * a)), r))
    return tuple(out)


def _capsule_manifold(c: SealedCrossing):
    import manifold3d as m3d
    a, b = np.asarray(c.start_mm), np.asarray(c.end_mm)
    length = float(np.linalg.norm(b - a))
    cyl = m3d.Manifold.cylinder(length, c.radius_mm + AXIS_TOLERANCE_MM, c.radius_mm + AXIS_TOLERANCE_MM, 48)
    z = (b - a) / length
    x = np.cross(z, [0.0, 0.0, 1.0]) if abs(z[2]) < 0.9 else np.cross(z, [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    m = np.column_stack([x, y, z, a])                         # 3 x 4: columns are the new axes and the origin
    return cyl.transform(m)


@dataclass(frozen=True)
class DryReport:
    openings: tuple[Opening, ...]               # every through-opening of the dry wall
    sealed: tuple[tuple[Opening, str], ...]     # (opening, the crossing that seals it)
    unsealed: tuple[Opening, ...]               # openings no declared crossing accounts for
    glands: tuple[SealedCrossing, ...]
    screws: tuple[SealedCrossing, ...]          # the bedded screws whose hole crosses the wall


def check_dry_wall(p: Params, manifolds: dict) -> DryReport:
    """Every through-opening of the dry wall, each matched to the declared crossing that seals it: the part of the
    opening on the cavity's side (its mouth, in the zone's inner skin) must lie inside a declared crossing's hole.
    What no crossing accounts for is unsealed; :func:`refuse_unsealed` turns that into a build error."""
    import manifold3d as m3d

    glands, screws = cable_glands(p), bedded_screws(p)
    crossings = list(glands) + list(screws)
    shapes = [_capsule_manifold(c) for c in crossings]
    labels = [lb for lb in sealed_part_labels(p) if lb in manifolds]
    union = m3d.Manifold.batch_boolean([manifolds[lb] for lb in labels], m3d.OpType.Add)
    zone, outer_layer, inner_layer, cavity = wall_zone(p, with_cavity=True)
    air_pieces = (cavity - union).decompose()
    air = max(air_pieces, key=lambda m: m.volume()) if air_pieces else cavity
    openings, sealed, unsealed, used = [], [], [], set()
    for piece in (zone - union).decompose():
        if piece.volume() < MIN_OPENING_MM3:
            continue
        if not ((piece ^ outer_layer).volume() > 1e-3 and (piece ^ air).volume() > 1e-3):
            continue                                              # a pocket: it does not go through
        bb = np.asarray(piece.bounding_box(), dtype=float)
        near = min(labels, key=lambda lb: manifolds[lb].min_gap(piece, 5.0))
        mouth = piece ^ inner_layer
        rest = mouth
        by = []
        for c, shape in zip(crossings, shapes):
            if (mouth ^ shape).volume() > 1e-6:
                rest = rest - shape
                by.append(c.label)
        op = Opening(near, tuple(float(v) for v in (bb[:3] + bb[3:]) / 2), tuple(float(v) for v in bb[3:] - bb[:3]),
                     float(piece.volume()), True)
        openings.append(op)
        if rest.volume() > MIN_OPENING_MM3 * 0.1 or not by:
            rb = np.asarray(rest.bounding_box(), dtype=float) if rest.volume() > 0 else bb
            unsealed.append(replace(op, centre_mm=tuple(float(v) for v in (rb[:3] + rb[3:]) / 2)))
        else:
            sealed.append((op, ", ".join(by)))
            used.update(by)
    return DryReport(tuple(openings), tuple(sealed), tuple(unsealed), glands,
                     tuple(c for c in screws if c.label in used))


def dry_wall_problems(p: Params, report: DryReport) -> list[str]:
    """What makes the build refuse the dry compartment: an opening no declared crossing seals (its part, place and
    size), and a cable gland whose packing the cable's stroke wets through (the wet stretch reaches the dry side)."""
    out = [f"{o}: not a declared sealed crossing (catalogues/seals.toml): no clearance cut, hole or vent may break "
           f"the dry wall" for o in report.unsealed]
    for g in report.glands:
        if g.packed_mm <= g.stroke_mm:
            out.append(f"{g.label}: its potted tube through the dry wall is {g.packed_mm:.1f} mm long, no longer than "
                       f"the cable's stroke {g.stroke_mm:.1f} mm: the wet stretch of cable reaches the dry side "
                       f"(hull.cable_gland_length_mm, or the clevis room of joint {p.hull.flooded_from_joint})")
    return out
