"""The wiring harness as numbers: the leads that join the electronics to each stepper motor and to the battery,
as centre lines in the body frame at rest (mm). No CAD kernel: :mod:`swiftfin.cad.cables` sweeps them into meshes
for the assembly's clearance proof, :mod:`swiftfin.exports.line_masses` weighs them, :mod:`swiftfin.exports.bom`
lists them (cut lengths and connectors).

Leads (``catalogues/wiring.toml``): a motor's own flying leads (4 x AWG 26) and the battery snap's (2 x AWG 22),
each modelled as the circle round its wires, bent nowhere tighter than its least radius (its innermost wire at
2 x its OD, IPC/WHMA-A-620): every corner of a route is an arc of exactly that radius
(:func:`rounded_centre_line`), and a route whose straight stretches are too short for its arcs is refused.

Arrangement (the default design's head: the board on edge in the nose, the four motors in a row behind it, the
battery low under the middle two):

* a **motor lead** leaves its motor's side face (alternate sides: ``motor_1`` +y, ``motor_2`` -y, ...; the fish
  carries as much copper on each side) through the strain relief near the back face, turns up, rises beside the
  motor while it closes in to the motor's flank (the seam's screw bosses stand against the wall there), runs forward
  along the flank at its **level** and turns in to the electronics' side face just ahead of the front motor. The
  leads of one side are stacked: the nearest motor's lowest, each further one a lead and a clearance above, so a
  lead from further aft passes over the risers of those ahead. The levels start a clearance above the electronics'
  cradle walls (the board's side face is free above them) and must stay under its top;
* the **power lead** leaves the battery's fore end through its snap, runs forward under the front motor, steps out
  beside the electronics' cradle before reaching it, runs forward, rises and turns in to the electronics' side
  face, ahead of where the motor leads come in.

What holds a lead along its run is not designed: it lies where its route says (lace the leads of a side
together with waxed lacing cord; nothing printed holds them); the connectors are inside the components' boxes. The route
is proved clear of every part by the assembly check (:func:`swiftfin.pipeline.check_cables_built`), which refuses a
build whose leads do not fit and names the lead, the part and the gap.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.wiring import Lead, lead
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout.cradle_plan import cradles
from swiftfin.layout.geometry import motor_placements

ARC_STEP_DEG = 3.0
"""Angular step of a route's sampled arcs: the chord lies R (1 - cos 1.5 deg) = 3.4e-4 R inside the arc."""
ROUTE_MARGIN_MM = 0.1
"""A route keeps this much beyond ``print.clearance_assembly_mm`` from what it passes: its swept mesh (a 12-sided
polygon round the circle, :mod:`swiftfin.cad.cables`) stands 3.5 % of the lead's radius (0.06 mm) outside it."""
LEVEL_STEP_MM = 0.05
"""Step of the power lead's level while it is raised clear of the electronics' cradle wall."""
ELECTRONICS = "electronics"
BATTERY = "battery"
"""The components (``params.components`` names) the harness joins: without an electronics box there is no harness,
without a battery no power lead."""


@dataclass(frozen=True)
class HarnessLead:
    """One lead: its corners (body frame at rest, mm; the first where it leaves its strain relief, the last at the
    electronics' face) and the centre line with every corner rounded at ``bend_radius_mm``."""
    label: str                    # lead_motor_<j> or lead_power
    kind: str                     # wiring.toml entry: "motor_lead", "power_lead"
    joint: int                    # the motor's joint (1-based), 0 for the power lead
    side: int                     # +1 (+y) or -1
    corners_mm: tuple
    centre_line_mm: tuple
    diameter_mm: float
    bend_radius_mm: float
    length_mm: float              # of the rounded centre line, from the strain relief to the electronics' face

    @property
    def spec(self) -> Lead:
        return lead(self.kind)

    @property
    def cut_length_mm(self) -> float:
        """What the builder leaves of the lead: the route, the service allowance and a termination at each end."""
        s = self.spec
        return self.length_mm * (1.0 + s.service_fraction) + 2 * s.termination_mm

    @property
    def mass_kg(self) -> float:
        return self.spec.linear_density_kg_m * self.cut_length_mm * 1e-3


def rounded_centre_line(corners, radius_mm: float) -> tuple[np.ndarray, float]:
    """The polyline through ``corners`` with every inner corner replaced by a circular arc of ``radius_mm``
    tangent to both legs (sampled every :data:`ARC_STEP_DEG`), and its exact length. ValueError when two arcs (or
    an arc and an end) need more of a leg than it has."""
    P = np.asarray(corners, dtype=float)
    n = len(P)
    legs = np.diff(P, axis=0)
    lengths = np.linalg.norm(legs, axis=1)
    if np.any(lengths <= 1e-9):
        raise ValueError("two corners coincide")
    u = legs / lengths[:, None]
    turn = np.zeros(n)
    tang = np.zeros(n)
    for k in range(1, n - 1):
        c = float(np.clip(u[k - 1] @ u[k], -1.0, 1.0))
        turn[k] = math.acos(c)
        tang[k] = radius_mm * math.tan(turn[k] / 2)
    for k in range(n - 1):
        if tang[k] + tang[k + 1] > lengths[k] + 1e-9:
            raise ValueError(f"the leg from corner {k} to {k + 1} ({lengths[k]:.2f} mm) is shorter than its bends "
                             f"need at {radius_mm:.2f} mm ({tang[k] + tang[k + 1]:.2f} mm)")
    out = [P[0]]
    length = float(lengths.sum())
    for k in range(1, n - 1):
        if turn[k] <= 1e-9:
            out.append(P[k])
            continue
        a, b = u[k - 1], u[k]
        t1 = P[k] - a * tang[k]
        inward = b - (a @ b) * a
        inward /= np.linalg.norm(inward)
        centre = t1 + radius_mm * inward
        m = max(2, int(math.ceil(math.degrees(turn[k]) / ARC_STEP_DEG)))
        for phi in np.linspace(0.0, turn[k], m + 1):
            out.append(centre - radius_mm * inward * math.cos(phi) + radius_mm * a * math.sin(phi))
        length += radius_mm * turn[k] - 2 * tang[k]
    out.append(P[-1])
    pts = np.asarray(out)
    keep = [0] + [i for i in range(1, len(pts)) if np.linalg.norm(pts[i] - pts[i - 1]) > 1e-9]
    return pts[keep], length


def _component(p: Params, name: str):
    return next((c for c in p.components if c.name == name), None)


def _box(p: Params, c) -> tuple[tuple[float, float], float, tuple[float, float]]:
    """Station range (s, mm), half width (y) and height range (z) of a component's box."""
    sx, sy, sz = c.size_mm
    s = c.station_fraction * p.body.length_mm
    return (s - sx / 2, s + sx / 2), sy / 2, (c.z_mm - sz / 2, c.z_mm + sz / 2)


def _lead(label, kind, joint, side, corners) -> HarnessLead:
    spec = lead(kind)
    R = spec.min_bend_radius_mm
    try:
        pts, length = rounded_centre_line(corners, R)
    except ValueError as exc:
        raise BuildError(f"{label}: no room to route it with its least bend radius {R:.2f} mm "
                         f"(catalogues/wiring.toml): {exc}") from exc
    return HarnessLead(label, kind, joint, side, tuple(tuple(float(c) for c in q) for q in corners),
                       tuple(tuple(float(c) for c in q) for q in pts), spec.bundle_diameter_mm, R, float(length))


@functools.lru_cache(maxsize=16)
def harness(p: Params) -> tuple[HarnessLead, ...]:
    """Every lead of the design (module docstring), motors first in joint order, then the power lead."""
    elec = _component(p, ELECTRONICS)
    if elec is None:
        return ()
    clr = p.print.clearance_assembly_mm + ROUTE_MARGIN_MM
    (e0, e1), e_half, (ez0, ez1) = _box(p, elec)
    cradle = next((c for c in cradles(p) if c.component == ELECTRONICS), None)
    band_lo, band_hi = ez0, ez1
    if cradle is not None and not cradle.hangs:
        band_lo = max(band_lo, cradle.z_top_mm)
    elif cradle is not None:
        band_hi = min(band_hi, -cradle.z_top_mm)
    m = p.motor
    half = m.frame_size_mm / 2
    motor = lead("motor_lead")
    r, R = motor.bundle_diameter_mm / 2, motor.min_bend_radius_mm
    y_flank = half + clr + r                        # a lead along a motor's flank
    y_face = e_half + clr                           # where a lead ends, at the electronics' side face
    s_in = e1 - r - clr                             # the station the motor leads turn in at
    out = []
    placements = motor_placements(p)
    for side in (1, -1):
        mine = sorted((mp for mp in placements if (1 if mp.joint % 2 == 0 else -1) == side), key=lambda mp: mp.s_mm)
        for k, mp in enumerate(mine):
            level = band_lo + clr + r + k * (2 * r + clr + ROUTE_MARGIN_MM)    # two meshes' polygons between
            if level + r > band_hi + 1e-9:
                raise BuildError(f"lead_motor_{mp.joint + 1}: the {len(mine)} motor leads of the "
                                 f"{'+' if side > 0 else '-'}y "
                                 f"side, stacked a lead ({2 * r:.2f} mm) and a clearance ({clr:g} mm) apart from "
                                 f"z = {band_lo + clr + r:.2f} mm, reach z = {level + r:.2f} mm, over the top of the "
                                 f"electronics' side face ({band_hi:.2f} mm) they must come in through")
            z_exit = mp.z_face_mm - m.body_length_mm + motor.exit_height_mm
            y_out = half + motor.exit_proud_mm
            corners = [(-mp.s_mm, side * y_out, z_exit),
                       (-mp.s_mm, side * (y_out + R), z_exit),                # out of the relief, turn up
                       (-mp.s_mm, side * (y_out + R), z_exit + 2 * R),        # up, then in to the flank
                       (-mp.s_mm, side * y_flank, level),                     # turn forward
                       (-s_in, side * y_flank, level),                        # forward, turn in
                       (-s_in, side * y_face, level)]
            out.append(_lead(f"lead_motor_{mp.joint + 1}", "motor_lead", mp.joint + 1, side, corners))
    batt = _component(p, BATTERY)
    if batt is not None:
        power = lead("power_lead")
        rp, Rp = power.bundle_diameter_mm / 2, power.min_bend_radius_mm
        (b0, _), _, (bz0, bz1) = _box(p, batt)
        zb = 0.5 * (bz0 + bz1)
        s_cradle = -min(cradle.x_mm) if cradle is not None else e1    # the aft end of the electronics' cradle
        y_side = max((cradle.half_width_mm if cradle is not None else e_half) + clr + rp, y_face + Rp)
        s_out = s_cradle + clr + rp + Rp                   # steps out beside the cradle before it
        s_up = s_in - r - clr - rp                         # rises ahead of the motor leads' turn

        def corners(level):
            return [(-(b0 - power.exit_proud_mm), 0.0, zb), (-s_out, 0.0, zb), (-s_out, y_side, zb),
                    (-s_up, y_side, zb), (-s_up, y_side, level), (-s_up, y_face, level)]
        level = band_lo + clr + rp
        if cradle is not None and not cradle.hangs:
            # its turn in over the cradle's wall: the lead's arc keeps its clearance from the wall's top edge
            edge = np.array([cradle.half_width_mm, cradle.z_top_mm])
            while level + rp <= band_hi:
                line = np.asarray(_lead("lead_power", "power_lead", 0, 1, corners(level)).centre_line_mm)
                if np.min(np.linalg.norm(line[:, 1:] - edge, axis=1)) >= rp + clr:
                    break
                level += LEVEL_STEP_MM
        if level + rp > band_hi + 1e-9:
            raise BuildError(f"lead_power: no level under the top of the electronics' side face ({band_hi:.2f} mm) "
                             f"lets it turn in over its cradle's wall")
        out.append(_lead("lead_power", "power_lead", 0, 1, corners(level)))
    return tuple(out)
