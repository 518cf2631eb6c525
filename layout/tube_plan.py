"""The PTFE tubes of the design as numbers: where each tube lies (its centre line from the mouth it is pushed in
by to the shoulder it seats on), and the loader's proof that every tube stays inside the hull.

Where the design puts a tube (:func:`tube_runs`):

* in every **guide channel**, over the stretch of the channel's centre line that lies inside its printed block,
  from the mouth where the channel opens to the tube's seat (:meth:`swiftfin.layout.guide_plan.GuideBlock.tube_seat`):
  ``tube_<guide>_<J>_<side>``, link 0;
* in every **bulkhead hole** of the hull (:func:`swiftfin.layout.gland_plan.bulkhead_passages`), from the bulkhead's
  front face to its seat: ``tube_<hull piece>_<J>_<side>``, on the piece's link.

:mod:`swiftfin.cad.cables` sweeps them into meshes for the build's assembly check, which refuses a tube standing
out of the hull's inner surface by more than twice the mesh tolerance. A guide channel is laid out by its centre
line, so a tube near the hull's clip can stand out of the block into the hull wall (``spool.drum_diameter_mm = 24``
put joint 4's left tube 0.25 mm into the head's wall, and the build failed at its end, 2026-12-07):
:func:`tubes_inside_hull` makes the same measurement on the same vertices before anything is built.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.guide_plan import arc_points, channel_centre_lines, guide_blocks, inside_block
from swiftfin.layout.sweep import dedupe_points, polyline_length_mm, sweep_outer_vertices

SIDE_NAME = {1: "left", -1: "right"}

TUBE_SIDES = 24
"""Polygon sides of a tube's section (its outer flats 0.9 % outside the true circle, 0.02 mm for a 4 mm tube)."""
ARC_STEP_DEG = 3.0
"""Angular step of the sampled arcs (bends, grooves): the chord lies r (1 - cos 1.5 deg) = 3.4e-4 r inside the arc."""
SAMPLE_STEP_MM = 0.2
"""Step along a guide channel when finding the stretch inside its block (tube ends within this of the face)."""


@dataclass(frozen=True)
class TubeRun:
    """A PTFE tube: centre line (body frame at rest, mm), rigid with ``link``, held by ``holder``."""
    label: str
    joint: int
    side: int
    link: int
    kind: str                    # "guide" (in a guide channel), "bulkhead" (in a hull bulkhead hole)
    holder: str                  # the guide's label, or the hull piece's name (its halves: <name>_upper/_lower)
    points_mm: tuple
    od_mm: float
    id_mm: float

    @property
    def length_mm(self) -> float:
        return polyline_length_mm(np.asarray(self.points_mm))


def _arc_samples(ch) -> np.ndarray:
    n = max(3, int(math.ceil(math.degrees(ch.angle_rad) / ARC_STEP_DEG)) + 1)
    return arc_points(ch, n)


def _straight_samples(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    n = max(2, int(math.ceil(np.linalg.norm(b - a) / SAMPLE_STEP_MM)) + 1)
    return a + np.linspace(0, 1, n)[:, None] * (b - a)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True in ``mask``."""
    edge = np.diff(np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]]))
    return [(int(i), int(k) - 1) for i, k in zip(np.flatnonzero(edge == 1), np.flatnonzero(edge == -1))]


def _cut_at(pts: np.ndarray, seat: np.ndarray) -> np.ndarray:
    """The polyline up to ``seat`` (a point on its last straight), ending exactly there."""
    k = int(np.argmin(np.linalg.norm(pts - seat, axis=1)))
    d = pts[-1] - pts[-2] if len(pts) > 1 else np.zeros(3)
    if k > 0 and float((pts[k] - seat) @ d) >= -1e-6:
        k -= 1       # a sample at (or past) the seat goes: the last segment ends on the seat, never a zero-length one
    return np.vstack([pts[:k + 1], seat[None, :]])


def _suffix(k: int, n: int) -> str:
    return "" if n == 1 else "_" + "abcdefghijklmnopqrstuvwxyz"[k]


@functools.lru_cache(maxsize=64)
def tube_runs(p: Params) -> tuple[TubeRun, ...]:
    """Every PTFE tube of the design (see the module docstring): guide channels, then bulkhead holes. Memoised on
    the params, as :func:`swiftfin.layout.geometry.cable_routes` (a build asks for them five times, 0.3 s each)."""
    g = p.guides
    out = []
    for b in guide_blocks(p):
        for joint, side, line in channel_centre_lines(b, _arc_samples, _straight_samples):
            line = dedupe_points(line)
            inside = inside_block(b, line, g.ptfe_tube_od_mm / 2)
            runs = [(i, k) for i, k in _runs(inside) if polyline_length_mm(line[i:k + 1]) >= L.MIN_TUBE_MM]
            seat = b.tube_seat(joint, side)
            for n, (i, k) in enumerate(runs):
                pts = line[i:k + 1]
                if seat is not None and n == len(runs) - 1:     # the last piece ends on the shoulder
                    pts = _cut_at(pts, np.asarray(seat, float))
                label = f"tube_{b.label}_{joint}_{SIDE_NAME[side]}{_suffix(n, len(runs))}"
                out.append(TubeRun(label, joint, side, 0, "guide", b.label, tuple(map(tuple, pts)),
                                   g.ptfe_tube_od_mm, g.ptfe_tube_id_mm))
    from swiftfin.layout.gland_plan import bulkhead_passages   # the hull cuts its holes from the same records
    from swiftfin.layout.hull_plan import hull_pieces
    for pc in hull_pieces(p):
        found: dict[tuple, list] = {}
        for route, q0, _, seat in bulkhead_passages(p, pc):
            if seat is not None:
                found.setdefault((route.joint + 1, route.side), []).append((q0, seat))
        for (J, side), items in found.items():
            for n, (q0, q1) in enumerate(items):
                label = f"tube_{pc.name}_{J}_{SIDE_NAME[side]}{_suffix(n, len(items))}"
                out.append(TubeRun(label, J, side, pc.link, "bulkhead", pc.name, (tuple(q0), tuple(q1)),
                                   g.ptfe_tube_od_mm, g.ptfe_tube_id_mm))
    return tuple(out)


SCREEN_REACH = 3.0
"""A tube whose centre line lies deeper inside the hull than this many of its (circumscribed) radii is not swept
for :func:`tube_outside_hull_mm`, which then returns that bound. The excess measure changes by at most 1 mm per mm
across the body (its gradient in y, z has unit length) and by the hull's slope along it; a tube's vertices lie one
radius from its centre line, so 3 radii hold for slopes up to 2 (the default's tubes: their vertices 1.2-1.9 mm
beyond their centre lines for 2.02 mm radii; tests/test_tube_plan.py checks the bound on seeded designs)."""


def tube_outside_hull_mm(p: Params, t: TubeRun) -> tuple[float, tuple]:
    """How far the tube's outer surface stands out of the hull's inner surface at its worst vertex [mm] (<= 0
    inside; for a tube deep inside, a bound: :data:`SCREEN_REACH`), and where: the outer vertices of the mesh the
    build checks (:func:`swiftfin.layout.sweep.sweep_mesh`, polygon circumscribed about the tube; its bore lies
    within them), measured as the assembly check measures a part
    (:func:`swiftfin.layout.geometry.inner_envelope_excess_mm`)."""
    centre = np.asarray(t.points_mm, float)
    reach = SCREEN_REACH * t.od_mm / 2 / math.cos(math.pi / TUBE_SIDES)
    ex = L.inner_envelope_excess_mm(p, centre)
    if float(ex.max()) < -reach:        # deep inside: no vertex can reach the surface (see SCREEN_REACH)
        i = int(np.argmax(ex))
        return float(ex[i]) + reach, tuple(float(c) for c in centre[i])
    v = sweep_outer_vertices(t.points_mm, t.od_mm / 2, TUBE_SIDES)
    ex = L.inner_envelope_excess_mm(p, v)
    i = int(np.argmax(ex))
    return float(ex[i]), tuple(float(c) for c in v[i])


def tubes_inside_hull(p: Params) -> None:
    """Refuse (UserError) a design with a PTFE tube standing out of the hull's inner surface by more than the
    assembly check allows (twice ``export.mesh_tolerance_mm``), naming each tube, how far and where."""
    limit = 2 * p.export.mesh_tolerance_mm
    bad = []
    for t in tube_runs(p):
        ex, at = tube_outside_hull_mm(p, t)
        if ex > limit:
            bad.append(f"{t.label} by {ex:.3f} mm near ({', '.join(f'{c:.1f}' for c in at)}) mm")
    if bad:
        raise UserError(f"spool.drum_diameter_mm = {p.spool.drum_diameter_mm:g}: the PTFE tubes would stand out of "
                        f"the hull's inner surface into its wall (the build refuses more than {limit:.3f} mm, twice "
                        f"export.mesh_tolerance_mm): {'; '.join(bad)}; the guide channels follow the spools' lanes, "
                        f"so a smaller drum, a longer hull.drive_bay_length_mm or a fuller body leaves them room")
