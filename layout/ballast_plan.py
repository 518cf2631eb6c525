"""The trim ballast as numbers: where the lead that makes the fish neutral and level is poured, in the body frame at
rest (mm). No CAD kernel.

The mass model says how much lead the fish needs and where its centre of mass should be
(:func:`swiftfin.exports.water.trim_ballast`: the station that puts the centre of mass under the centre of buoyancy;
:func:`~swiftfin.exports.water.ballast_height`: the height that leaves its link no product of inertia). Lead cannot
be cast into a printed hull, so it is **lead shot set in epoxy** (``catalogues/ballast.toml``) poured into the hull's
own hollow: with the half that takes it lying on its back, the shot and the epoxy fill the hollow between the nose
cap (or a printed dam) and a printed dam, up to a level. Cured, the fill is one block bonded to the shell; its
outside is the shell's inner surface (shrunk by the bond gap, as the cradles': :func:`inner_semi_axes_mm`) and its
free face is the plane ``|z| = z_level`` parallel to the seam.

So the fill of volume ``V = m / rho_fill`` in a half ``sigma`` (+1 upper, -1 lower) is, per station, the segment of
the inner ellipse (half-width ``a``, half-height ``b``) beyond ``t = z_level / b``:
``A = a b (acos t - t sqrt(1 - t^2))`` and ``integral of z dA = sigma 2/3 a b^2 (1 - t^2)^(3/2)``, integrated over
``[s0, s1]`` on :data:`GRID_MM` steps. The plan picks the half, the level and the stations:

1. the centre of mass's station as near the trim's as the hollow allows (the fill cannot reach into the nose cap:
   on the default design the trim asks for s = 17 mm, 1.5 mm behind the cap, and no fill of 34 g is centred there);
2. then its height as near the wanted one (:func:`~swiftfin.exports.water.ballast_height`);
3. its level and its dams clear of every part inside (``keep_out``: the electronics under the nose's fill) by
   ``print.clearance_assembly_mm`` and of the seam's land, each dam :data:`DAM_RISE_MM` proud of the level: the fill
   keeps clear of every part over it that reaches past its level, a dam of every part that reaches past its edge,
   and each stretch of the hollow between such parts is tried (:func:`free_stretches`); every piece of the link is
   searched. A fill lies against the nose cap or a bulkhead with no dam; an open (spliced) end gets a dam clear of
   the splice (:func:`pour_range_mm`).

What the fill misses of the trim's place is not hidden: the build's mass model uses the fill, and the float rules
(``float.level``: the static pitch) say what it costs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.ballast import ballast_fill
from swiftfin.core.schema import Params
from swiftfin.layout.cradle_plan import bond_gap_mm, inner_semi_axes_mm, wall_mm
from swiftfin.layout.hull_plan import (SEAM_LAND_HEIGHT_MM, cavity_range_mm, hollow_clear_of_ends_mm, hull_pieces,
                                      part_label)

FILL_LABEL = "trim_ballast"
DAM_LABEL = "ballast_dam"
GRID_MM = 0.05
"""Station step of the fill's integrals [mm]."""
LEVEL_STEP_MM = 0.25
"""Step of the levels tried [mm]."""
DAM_RISE_MM = 2.0
"""A dam stands this far proud of the fill's level, toward the seam [mm]: the poured epoxy's meniscus and a
builder's unsteady hand. Engineering default."""
FILL = "lead_shot_epoxy"


@dataclass(frozen=True)
class BallastPlan:
    link: int
    piece: str                  # the hull piece whose hollow holds the fill
    bonded_to: str              # that piece's half
    sigma: int                  # +1: the upper half (z > 0), -1: the lower
    s_mm: tuple                 # (s0, s1): the fill's fore and aft ends
    dams: tuple                 # ((s_lo, s_hi), ...): the printed dams (none at an end against the nose cap)
    z_level_mm: float           # the fill's free face: |z| = z_level
    z_dam_mm: float             # the dams' edge toward the seam: |z| = z_dam
    gap_mm: float               # the fill and the dams stand this far inside the shell's inner surface
    volume_mm3: float
    mass_kg: float
    density_kg_m3: float
    lead_kg: float              # of the mass: the shot the builder weighs out
    binder_kg: float            # and the epoxy
    com_mm: tuple               # body frame
    target_x_mm: float          # where the trim wanted the centre of mass (body x)
    wanted_z_mm: float          # and its height

    @property
    def miss_x_mm(self) -> float:
        """How far the fill's centre of mass lies behind (+) or ahead of (-) the trim's station [mm]."""
        return self.target_x_mm - self.com_mm[0]


def fill_density_kg_m3(p: Params) -> float:
    """The cured fill's density: lead shot (``environment.ballast_density_kg_m3``) packed in epoxy [kg/m^3]."""
    return ballast_fill(FILL).density_kg_m3(p.environment.ballast_density_kg_m3)


def segment(a: np.ndarray, b: np.ndarray, level: float) -> tuple[np.ndarray, np.ndarray]:
    """Area and first moment about the seam plane (|z|) of the elliptic sections' parts beyond ``|z| = level``."""
    t = np.clip(level / np.maximum(b, 1e-9), -1.0, 1.0)
    ok = (a > 0) & (b > 0)
    area = np.where(ok, a * b * (np.arccos(t) - t * np.sqrt(1.0 - t * t)), 0.0)
    moment = np.where(ok, 2.0 / 3.0 * a * b * b * (1.0 - t * t) ** 1.5, 0.0)
    return area, moment


def _window(s: np.ndarray, area: np.ndarray, moment: np.ndarray, volume: float, s_target: float):
    """The stations [s0, s1] on the grid ``s`` whose fill holds ``volume`` with its centroid nearest ``s_target``:
    (s0, s1, volume, centroid s, |z| centroid), or None when the whole range holds less."""
    ds = np.diff(s)
    cv = np.concatenate([[0.0], np.cumsum(0.5 * (area[1:] + area[:-1]) * ds)])
    cs = np.concatenate([[0.0], np.cumsum(0.5 * (area[1:] * s[1:] + area[:-1] * s[:-1]) * ds)])
    cm = np.concatenate([[0.0], np.cumsum(0.5 * (moment[1:] + moment[:-1]) * ds)])
    if cv[-1] < volume:
        return None
    ends = np.interp(cv + volume, cv, s)                # each start's end (cv increasing where the area is > 0)
    starts = s[cv + volume <= cv[-1]]
    ends = ends[:len(starts)]

    def at(s0, s1):
        v = np.interp(s1, s, cv) - np.interp(s0, s, cv)
        return v, (np.interp(s1, s, cs) - np.interp(s0, s, cs)) / v, (np.interp(s1, s, cm) - np.interp(s0, s, cm)) / v

    k = int(np.argmin(np.abs(at(starts, ends)[1] - s_target)))
    v, sc, zc = (float(u) for u in at(starts[k], ends[k]))
    return float(starts[k]), float(ends[k]), float(v), float(sc), float(zc)


def pour_range_mm(p: Params, pc) -> tuple[float, float, bool]:
    """Stations [lo, hi] a fill and its dams may take in the piece ``pc`` (inside its shell by the bond gap), and
    whether the front end is closed (the nose cap or a bulkhead: the fill may lie against it without a dam). An open
    (spliced) end holds neither fill nor dam: the fill would run out of the piece, and the splice's tabs and screws
    take :data:`~swiftfin.layout.hull_plan.SPLICE_LENGTH_MM` there (as the flotation's blocks keep clear of them)."""
    lo, hi = hollow_clear_of_ends_mm(p, pc, bond_gap_mm(p))
    return lo, hi, bool(pc.nose or pc.front_joint is not None)


def free_stretches(lo: float, hi: float, blocked) -> list[tuple[float, float]]:
    """[lo, hi] less the station ranges ``blocked`` ((s0, s1), ...), as the stretches left, fore to aft."""
    out, u = [], lo
    for b0, b1 in sorted(blocked):
        if b0 > u:
            out.append((u, min(b0, hi)))
        u = max(u, b1)
        if u >= hi:
            break
    if u < hi:
        out.append((u, hi))
    return [(a, b) for a, b in out if b > a]


def plan_ballast(p: Params, mass_kg: float, target_x_mm: float, wanted_z_mm: float, link: int,
                 keep_out=(), prefer: tuple | None = None) -> tuple[BallastPlan | None, str]:
    """The fill of ``mass_kg`` (module docstring) for a trim that wants its centre of mass at body x
    ``target_x_mm`` and height ``wanted_z_mm`` in link ``link``; ``keep_out``: ``(label, (x0, y0, z0), (x1, y1,
    z1))`` boxes in mm of the parts inside. ``prefer``: (piece, sigma, level) of an earlier plan, kept whenever it
    centres the fill as well as any other (the height's criterion then does not choose again: the application's
    rounds of trim and plan settle instead of flipping between two levels a grid step apart, each moving the dams
    and so the trim; seen 2026-11-28 with the fill between two dams). Returns (plan, "") or (None, the reason no
    fill fits)."""
    rho = fill_density_kg_m3(p)
    volume = mass_kg / rho * 1e9
    gap, dam_t, clr = bond_gap_mm(p), wall_mm(p), p.print.clearance_assembly_mm
    s_t = -target_x_mm
    pieces = [pc for pc in hull_pieces(p) if pc.link == link]
    pieces.sort(key=lambda pc: max(0.0, cavity_range_mm(p, pc)[0] - s_t, s_t - cavity_range_mm(p, pc)[1]))
    best, why = None, []
    for pc in pieces:
        lo, hi, closed_front = pour_range_mm(p, pc)
        for sigma in ((1, -1) if wanted_z_mm >= 0 else (-1, 1)):
            s_all = np.arange(lo, hi + 1e-9, GRID_MM)
            ab = np.array([inner_semi_axes_mm(p, float(si), gap) for si in s_all]).reshape(-1, 2)
            # (station range, |z| reach toward the fill's half) of each part inside
            parts = [(lab, -hi_[0], -lo_[0], hi_[2] if sigma > 0 else -lo_[2]) for lab, lo_, hi_ in keep_out
                     if -hi_[0] < hi + clr and -lo_[0] > lo - clr]
            floor = SEAM_LAND_HEIGHT_MM + clr + DAM_RISE_MM     # the dams' edge clear of the land
            half, met, fitted = ("upper" if sigma > 0 else "lower"), set(), False
            for level in np.arange(floor, float(np.max(ab[:, 1], initial=0.0)), LEVEL_STEP_MM):
                # the fill (|z| >= level) keeps clear of every part reaching past level - clr; a dam (|z| >= level -
                # DAM_RISE_MM) of every part reaching past that less clr
                fill_block = [q for q in parts if q[3] > level - clr]
                dam_block = [q for q in parts if q[3] > level - DAM_RISE_MM - clr]
                held = False
                for u, v in free_stretches(lo, hi, [(q[1] - clr, q[2] + clr) for q in fill_block]):
                    # against the nose cap or a bulkhead the fill may start with no dam (then at the stretch's
                    # start exactly: the least target picks it); anywhere else a dam stands ahead of it
                    starts = ((u + dam_t, s_t, True),) + (((u, -math.inf, False),) if closed_front and u <= lo + 1e-9
                                                          else ())
                    for first, target, front_dam in starts:
                        grid = (s_all >= first - 1e-9) & (s_all <= v - dam_t + 1e-9)
                        if np.count_nonzero(grid) < 2:
                            continue
                        area, moment = segment(ab[grid, 0], ab[grid, 1], level)
                        w = _window(s_all[grid], area, moment, volume, target)
                        if w is None:
                            continue
                        held = True
                        s0, s1, v_, sc, zc = w
                        dams = (((s0 - dam_t, s0),) if front_dam else ()) + ((s1, s1 + dam_t),)
                        blocked = [q[0] for q in dam_block for d0, d1 in dams if q[1] < d1 + clr and q[2] > d0 - clr]
                        if blocked:
                            met.update(blocked)
                            continue
                        fitted = True
                        kept = (prefer is not None and (pc.name, sigma) == tuple(prefer[:2])
                                and abs(level - prefer[2]) < 1e-9)
                        key = (round(abs(sc - s_t), 1), not kept, abs(sigma * zc - wanted_z_mm))
                        if best is None or key < best[0]:
                            best = (key, pc, sigma, s0, s1, dams, float(level), v_, sc, zc)
                met.update(q[0] for q in fill_block)
                if not held and not fill_block:
                    break                                       # higher levels hold less
            if not fitted:
                why.append(f"{pc.name}'s {half} half: " + (f"every level that holds {volume / 1000:.2f} cm^3 of fill "
                                                         f"meets {', '.join(sorted(met))}" if met else
                                                         f"no level holds {volume / 1000:.2f} cm^3 of fill"))
    if best is None:
        return None, "; ".join(dict.fromkeys(why)) or f"link {link} has no hull piece"
    _, pc, sigma, s0, s1, dams, level, v, sc, zc = best
    fill = ballast_fill(FILL)
    m = v * 1e-9 * rho
    lead = m * fill.lead_fraction(p.environment.ballast_density_kg_m3)
    return BallastPlan(link, pc.name, part_label(p, pc, "upper" if sigma > 0 else "lower"), sigma, (s0, s1),
                       dams, level, level - DAM_RISE_MM, gap, v, m, rho, lead, m - lead,
                       (-sc, 0.0, sigma * zc), target_x_mm, wanted_z_mm), ""

