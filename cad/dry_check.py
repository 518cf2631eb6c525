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
that touch, each of which needs a seal of its own.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.schema import Params
from swiftfin.layout.hull_plan import hull_pieces, hull_section_semi_axes_mm, nose_cap

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
    out = []
    for pc in sealed_pieces(p):
        out += [f"{pc.name}_upper", f"{pc.name}_lower"] if p.hull.split_halves else [pc.name]
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
    pieces = sealed_pieces(p)
    if not pieces:
        raise ValueError("no sealed hull piece: hull.flooded_from_joint = 0")
    s_end = max(pc.s_end_mm for pc in pieces)
    t, w = p.hull.bulkhead_thickness_mm, p.hull.wall_thickness_mm
    s_cap = nose_cap(p).s_cap_mm
    last = max(pieces, key=lambda pc: pc.s_end_mm)
    c1 = s_end - t if last.rear_joint is not None else s_end - 1.0
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
