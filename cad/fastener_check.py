"""The fastener rules, checked on the built solids (meshes of the parts at rest, body frame, mm).

For every :class:`~swiftfin.layout.fastening.Fastener` of the design (issue 12, item 2):

1. **Wall round every hole** >= ``rules.wall_min_line_widths`` extrusion lines (two perimeters); round a heat-set
   insert's pocket the larger of that and the insert maker's wall (``ScrewSize.insert_wall_min_mm``), which is
   the boss rule "insert boss OD >= insert + walls" measured on the solid. Measured by rays: at several depths
   along the hole and in :data:`RAY_DIRECTIONS` directions round its axis, a ray starts just inside the hole's
   wall and runs outward; the distance to the first surface it leaves the material through is the wall there.
   A ray that starts in empty space (the hole breaks out of the part, or the boss is missing) measures 0.
2. **Thread engagement**: the thread part has material round the seat over the whole engagement (every depth
   sampled in the insert, the nut trap or the pilot starts in material); the numbers (>= 1.5 d, or a nut's
   height and a pitch) are checked by :meth:`Fastener.problems`, the catalogue length too.
3. **The tool's path**: a cylinder of the driver's shank (``key_reach_diameter_mm``) from the head's top (a set
   screw's entry) outward along the axis for :data:`TOOL_REACH_MM` meets no part but those put on after the
   fastener is driven (``installed_after``).

Depths of the head part where every ray starts in empty space (an air gap between the clamped parts) are
skipped; the head part must have material at one depth at least (the head bears on something). The same holds for
a pin's bore in each of the two parts it joins (``thread_part`` and ``meta["slip_part"]``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import WALL_PROBE_INSET_MM, Fastener

RAY_DIRECTIONS = 12
"""Rays round the axis at each depth (every 30 deg)."""
DEPTHS = 4
"""Depths sampled along each hole (evenly, 0.3 mm inside its ends)."""
RAY_LENGTH_MM = 25.0
"""How far a wall ray looks: a wall thicker than this is reported as this."""
START_INSET_MM = WALL_PROBE_INSET_MM
"""Rays start this far outside the hole's nominal radius (inside the wall, past the tessellation of the hole)."""
TOOL_REACH_MM = 50.0
"""Length of the driver that must reach the head: a precision screwdriver's shank (Wera/Wiha: 40-60 mm)."""
TOOL_OVERLAP_MM3 = 0.5
"""Overlap of the tool's cylinder with a part that counts as a collision [mm^3] (tessellation noise is far less)."""


@dataclass(frozen=True)
class WallMeasure:
    """The thinnest wall found round one hole of one fastener in one part."""
    fastener: str
    part: str
    feature: str              # "clearance hole", "counterbore", "insert pocket", "nut trap", "pilot", "pin bore"
    wall_mm: float
    limit_mm: float
    where_mm: tuple[float, float, float]

    @property
    def ok(self) -> bool:
        return self.wall_mm >= self.limit_mm - 1e-6

    def __str__(self) -> str:
        at = ", ".join(f"{c:.1f}" for c in self.where_mm)
        return (f"{self.part}: wall round the {self.feature} of {self.fastener} is {self.wall_mm:.2f} mm at ({at}) mm, "
                f"needs {self.limit_mm:.2f} mm")


@dataclass
class FastenerReport:
    fasteners: tuple[Fastener, ...]
    walls: list[WallMeasure]
    problems: list[str]
    mating_pairs: tuple = ()       # (a, b, how joined, why they touch) of every touching pair (mating_pairs)

    def worst_wall(self) -> WallMeasure | None:
        return min(self.walls, key=lambda w: w.wall_mm - w.limit_mm, default=None)

    def per_part(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for f in self.fasteners:
            for part in {f.head_part, f.thread_part} - {None}:
                out[part] = out.get(part, 0) + 1
        return dict(sorted(out.items()))


def _frame(axis) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(axis, dtype=float)
    ref = np.array([0.0, 0.0, 1.0]) if abs(a[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(a, ref)
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def _holes(f: Fastener, line_width_mm: float, walls: float) -> list[tuple[str, str, float, float, float, float]]:
    """(part, feature, radius, depth0, depth1, limit) of every hole the fastener makes (depths along the axis
    from ``head_mm``)."""
    need = walls * line_width_mm
    out = []
    if f.kind == "dowel":
        out = [(f.thread_part, "pin bore", float(f.size) / 2, 0.0, f.length_mm, need)]
        if f.meta.get("slip_part"):
            out.append((f.meta["slip_part"], "pin bore", float(f.size) / 2, 0.0, f.length_mm, need))
        return out
    s = f.screw
    if f.head_part is not None and f.grip_mm > 0:
        out.append((f.head_part, "clearance hole", s.clearance_hole_mm / 2, 0.0, f.grip_mm, need))
    g = f.grip_mm
    if f.seat == "insert":
        out.append((f.thread_part, "insert pocket", s.insert_hole_mm / 2, g, g + s.insert_length_mm,
                    max(need, s.insert_wall_min_mm)))
    elif f.seat == "nut":
        out.append((f.thread_part, "nut trap", s.nut_trap_width_mm / math.sqrt(3.0), g, g + s.nut_height_mm, need))
    elif f.seat == "self_tap":
        out.append((f.thread_part, "pilot", s.pilot_hole_mm / 2, g, f.length_mm, need))
    return out


def _ray_wall(man, start: np.ndarray, direction: np.ndarray) -> float:
    """Distance from ``start`` (just inside a hole's wall) to where the ray leaves the material; 0 if it starts
    in empty space."""
    end = start + RAY_LENGTH_MM * direction
    hits = man.ray_cast(tuple(map(float, start)), tuple(map(float, end)))
    if not hits:
        # no surface within reach: either the start is outside the part, or the wall is thicker than the reach
        far = man.ray_cast(tuple(map(float, start)), tuple(map(float, start + 100 * RAY_LENGTH_MM * direction)))
        return RAY_LENGTH_MM if far and float(np.dot(far[0].normal, direction)) > 0 else 0.0
    h = hits[0]
    if float(np.dot(h.normal, direction)) <= 0:
        return 0.0                         # the first surface is entered: the start was in empty space
    return float(h.distance) * RAY_LENGTH_MM


def measure_walls(f: Fastener, manifolds: dict, line_width_mm: float, walls: float = 2.0
                  ) -> tuple[list[WallMeasure], list[str]]:
    """The thinnest wall round each hole of ``f`` (one measure per hole), and the problems found on the way."""
    u, v = _frame(f.axis)
    a = np.asarray(f.axis, dtype=float)
    out, problems = [], []
    for part, feature, r, d0, d1, limit in _holes(f, line_width_mm, walls):
        man = manifolds.get(part)
        if man is None:
            problems.append(f"{f.label}: its {feature} is in {part!r}, which is not a part of the build")
            continue
        lo, hi = d0 + 0.3, d1 - 0.3
        depths = np.linspace(lo, hi, DEPTHS) if hi > lo else np.array([(d0 + d1) / 2])
        worst, where, in_material = math.inf, None, 0
        spans_parts = feature == "clearance hole" or (feature == "pin bore" and f.meta.get("slip_part"))
        for d in depths:
            centre = np.asarray(f.head_mm, dtype=float) + d * a
            row = []
            for k in range(RAY_DIRECTIONS):
                ang = 2 * math.pi * k / RAY_DIRECTIONS
                w = math.cos(ang) * u + math.sin(ang) * v
                start = centre + (r + START_INSET_MM) * w
                row.append((_ray_wall(man, start, w), start))
            if all(x[0] == 0.0 for x in row):
                continue                   # all void: an air gap between clamped parts (a thread part: see below)
            in_material += 1
            wall, pt = min(row, key=lambda x: x[0])
            if wall < worst:
                worst, where = wall, pt
        if in_material == 0 or (not spans_parts and in_material < len(depths)):
            near = tuple(round(float(c), 1) for c in f.point_mm(d0))
            what = "no material" if in_material == 0 else f"material at only {in_material} of {len(depths)} depths"
            problems.append(f"{f.label}: {what} of {part} round its {feature} (between {d0:.1f} and "
                            f"{d1:.1f} mm from the head, from {near} mm)")
            if in_material == 0:
                continue
        m = WallMeasure(f.label, part, feature, worst, limit, tuple(float(c) for c in where))
        out.append(m)
        if not m.ok:
            problems.append(str(m))
    return out, problems


def tool_path_problems(f: Fastener, manifolds: dict, goes_in_with: dict | None = None) -> list[str]:
    """Parts the driver's cylinder meets on its way to the head (none but those put on after ``f``, and the parts
    that go in with one of those: ``goes_in_with`` maps a part to the part it is glued into)."""
    goes_in_with = goes_in_with or {}
    if f.kind == "dowel":
        return []
    import manifold3d as m3d

    s = f.screw
    a = np.asarray(f.axis, dtype=float)
    start = f.point_mm(-(s.head_height_mm if f.kind == "cap_screw" else 0.0) - 0.1)
    r = s.key_reach_diameter_mm / 2
    tool = m3d.Manifold.cylinder(TOOL_REACH_MM, r, r, 24)
    # cylinder along +z from the origin -> along -axis from ``start``
    z = -a
    x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    mat = np.column_stack([x, y, z, start])
    tool = tool.transform(mat)
    lo, hi = np.asarray(tool.bounding_box()[:3]), np.asarray(tool.bounding_box()[3:])
    out = []
    for label, man in manifolds.items():
        if label in f.installed_after or goes_in_with.get(label) in f.installed_after:
            continue
        bb = man.bounding_box()
        if np.any(np.asarray(bb[:3]) > hi) or np.any(np.asarray(bb[3:]) < lo):
            continue
        vol = (tool ^ man).volume()
        if vol > TOOL_OVERLAP_MM3:
            out.append(f"{f.label}: the driver's path to its head ({2 * r:g} mm shank, {TOOL_REACH_MM:g} mm along "
                       f"the axis from ({', '.join(f'{float(c):.1f}' for c in start)}) mm) runs into {label} "
                       f"({vol:.1f} mm^3)")
    return out


def check_fasteners(p: Params, fasteners, manifolds: dict, raise_on_failure: bool = True,
                    goes_in_with: dict | None = None, placed=None) -> FastenerReport:
    """Every fastener rule on the solids. ``manifolds``: label -> manifold3d.Manifold of every part at rest;
    ``goes_in_with``: label -> the part it is glued into (it goes on when that part does: a flotation block with
    its lower half); ``placed`` (cad.assembly.Placed of every part, optional): every pair of the contact table that
    touches must be joined by a fastener or declared in :data:`GLUED` (:func:`unfastened_contacts`). Raises
    BuildError listing every failure (``raise_on_failure``), else returns them in the report."""
    fasteners = tuple(fasteners)
    walls, problems = [], []
    lw, n = p.print.line_width_mm, p.rules.wall_min_line_widths
    for f in fasteners:
        problems += f.problems()
        w, pr = measure_walls(f, manifolds, lw, n)
        walls += w
        problems += pr
        problems += tool_path_problems(f, manifolds, goes_in_with)
    mates = ()
    if placed is not None:
        mates = tuple(mating_pairs(p, placed, fasteners))
        problems += _unjoined(mates)
    report = FastenerReport(fasteners, walls, problems, mates)
    if problems and raise_on_failure:
        raise BuildError(f"{len(problems)} fastener check(s) failed:\n" + "\n".join(f"  - {x}" for x in problems))
    return report


# --------------------------------------------------------------------------------------------- mating pairs
@dataclass(frozen=True)
class Glued:
    """A pair of parts joined by something other than a fastener record (glue, a pad, a bearing fit), with the
    bonded area where it is sized and why."""
    a: str                 # regular expressions over the labels, as in cad/assembly.py's Contact (a named group
    b: str                 # must capture the same text in both)
    area_mm2: float
    reason: str
    how: str = "glued"     # "glued" | "pad" | "bearing" | "clamped"

    def matches(self, la: str, lb: str) -> bool:
        from swiftfin.cad.assembly import Contact
        return Contact(self.a, self.b, self.reason).matches(la, lb)


GLUED: tuple[Glued, ...] = (
    Glued(r"flotation_\d+", r"hull_.+", 0.0,
          "a flotation foam block is glued into its flooded segment's lower shell (its lift, under 0.2 N, needs "
          "no rated bond area: any contact glue holds it; area 0 = not sized). Every other joint comes apart "
          "for service"),
    Glued(r"trim_ballast|ballast_dam(_fore|_aft)?", r"hull_.+", 0.0,
          "the trim ballast's epoxy sets the shot and bonds it and its dams to the shell it is poured against "
          "(the load, its weight under a few g of handling, is a few kPa over the shell: not sized)"),
    Glued(r"trim_ballast", r"ballast_dam(_fore|_aft)?", 0.0,
          "the trim ballast's epoxy bonds it to its dams"),
    Glued(r"cradle_.+", r"hull_.+", 0.0,
          "a component's cradle is bonded with epoxy into the hull's lower half along its whole underside (its "
          "footprint, in cm^2, on the bill of materials; the load, the component's weight under a few g of "
          "handling, is under 1 kPa a g over it: not sized)"),
    Glued(r"cradle_(?P<c>.+)", r"(?P<c>.+)", 0.0,
          "a component is held in its cradle's pocket by a self-adhesive hook-and-loop pad under it "
          "(catalogues/mounting.toml): it pulls out to be charged or swapped", how="pad"),
    Glued(r"seam_gasket(_\d+)?", r"hull_.+", 0.0,
          "the seam gasket is clamped between the sealed pieces' halves by the seam screws, which pass through its "
          "holes and the compression limiters in them (cad/seal.py)", how="clamped"),
    Glued(r"spool_(?P<j>\d+)_upper", r"motor_(?P<j>\d+)", 0.0,
          "the split spool's upper half turns on its motor's shaft (a bearing fit, sliding clearance): it is held "
          "to the lower half, which the set screw fixes on the shaft, by the index screw", how="bearing"),
)
"""Pairs joined otherwise than by a fastener record: glued (with the bonded area where the joint carries a load
worth sizing), on a pad, or turning on a bearing fit."""


def joined_parts(f: Fastener) -> set[str]:
    """The parts a fastener holds together: the head's and the thread's, and what its record names in
    ``meta["joins_parts"]`` (the shaft a set screw bears on, the lug a pin turns in)."""
    return ({f.head_part, f.thread_part} | set(f.meta.get("joins_parts", ()))) - {None}


def _meet_on_an_edge(p: Params, pieces: set[str], la: str, lb: str) -> bool:
    """Two hull parts (``pieces``: the hull pieces' names) of different pieces and different halves (the front upper
    half and the rear lower half): they meet only on the line where the halves' seam plane crosses the pieces'
    splice, and each is fastened to the two parts it meets face to face."""
    if not p.hull.split_halves:
        return False
    split = []
    for label in (la, lb):
        piece, _, half = label.rpartition("_")
        if piece not in pieces or half not in ("upper", "lower"):
            return False
        split.append((piece, half))
    (pa, ha), (pb, hb) = split
    return pa != pb and ha != hb


def mating_pairs(p: Params, placed, fasteners, glued=GLUED) -> list[tuple[str, str, str, str]]:
    """Every pair of the contact table (cad/assembly.py) that touches at rest (gap <= print.clearance_sliding_mm):
    (a, b, how it is joined, the table's reason it touches). How: ``"fastener"`` (a record joins both),
    ``"glued"``/``"pad"``/``"bearing"``/``"clamped"`` (declared in ``glued``), ``"edge"`` (two hull halves that meet on a line
    only) or ``""`` (nothing: a fault)."""
    from swiftfin.cad.assembly import contact_reason
    from swiftfin.layout.hull_plan import hull_pieces

    pieces = {pc.name for pc in hull_pieces(p)}
    pairs = [joined_parts(f) for f in fasteners]
    gap = p.print.clearance_sliding_mm
    out = []
    for i, a in enumerate(placed):
        for b in placed[i + 1:]:
            reason = contact_reason(a, b, p=p)
            if reason is None:
                continue
            lo = np.maximum(a.bounds[0], b.bounds[0])
            hi = np.minimum(a.bounds[1], b.bounds[1])
            if np.any(lo - hi > gap):
                continue
            if a.manifold.min_gap(b.manifold, 2 * gap) > gap:   # (it returns its search length when nothing is
                continue                                         # nearer: search beyond the gap)
            if _meet_on_an_edge(p, pieces, a.label, b.label):
                how = "edge"
            elif any({a.label, b.label} <= j for j in pairs):
                how = "fastener"
            else:
                how = next((g.how for g in glued if g.matches(a.label, b.label)), "")
            out.append((a.label, b.label, how, reason))
    return out


def _unjoined(mates) -> list[str]:
    return [f"{a} and {b} touch ({reason}) but no fastener joins them and they are not declared glued"
            for a, b, how, reason in mates if not how]


def unfastened_contacts(p: Params, placed, fasteners, glued=GLUED) -> list[str]:
    """Pairs of the contact table that touch at rest and are neither joined by a fastener nor declared in
    ``glued`` (:func:`mating_pairs`)."""
    return _unjoined(mating_pairs(p, placed, fasteners, glued))
