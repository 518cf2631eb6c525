"""The cable tensioner as numbers: how far each joint's loop must be taken in, how far the split spool can take
it, and the count that sets the pretension.

The tensioner is the **split spool** (:mod:`swiftfin.cad.spool`): the lower half (hub, set screw) carries the
right cable, the upper half the left one; the halves turn against each other on the shaft and are locked by one
screw through a vernier of index holes. Turning the upper half clockwise (seen from above) against the lower
winds both cables in, each on its own half, the wraps turning with the anchor (the cable never slides round the
drum, so the capstan friction that holds it does not fight the tensioner). The stepper then re-centres the
joint, so each half takes half of the relative turn, and the groove holds half of
``spool.tension_storage_turns`` beyond the travel at each end.

Why this design (for the README): the take-up a loop needs is large (joint 4: 19 mm of stretch at 45 N on 677 mm
of free cable, plus 3 % creep and the assembly tolerance: 46 mm) and a split drum gives r per radian without
limit, where a screw slider or turnbuckle is limited to its screw's stroke (a 46 mm stroke has no room in the
head; the straight runs beside the spools are 31-144 mm long). A screw at a cable end *on* the drum cannot
tension through the wraps: pulling the end means sliding the cable round a turn of drum against
e^(mu 2 pi) = 9 x the friction (405 N for 45 N, beyond the 300 N cable). The split drum turns the wraps with
the anchor. Its count is steps of the vernier: 360 / (upper x lower holes) degrees each, a known loop
shortening r x step, so a known change of pretension (E A / L per metre of loop), re-set after creep by
counting more steps.

``tensioner_numbers(p)`` gives per joint: the loop's free length, the take-up need (stretch + creep +
tolerance), the take-up available, the pretension change per vernier step and the steps per newton.
Nothing here imports the CAD kernel.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout.geometry import cable_routes
from swiftfin.physics import tension as T


@dataclass(frozen=True)
class JointTension:
    """One joint's pull-pull loop and its split-spool tensioner [mm, N, deg]."""
    joint: int                      # 1-based
    loop_length_mm: float           # free cable, both sides (spool tangent to tendon sector)
    stretch_mm: float               # T L / (E A) at the pretension
    creep_mm: float                 # creep allowance x L
    tolerance_mm: float             # one assembly tolerance per side
    need_mm: float                  # stretch + creep + tolerance
    available_mm: float             # storage turns x 2 pi r
    stiffness_n_mm: float           # E A / L of the loop (pretension change per mm of take-up)
    step_deg: float                 # relative turn of the halves per vernier step
    step_mm: float                  # loop take-up per step (r x step)
    newton_per_step: float          # pretension change per step
    steps_per_newton: float
    steps_to_pretension: float      # from just taut to the pretension
    degrees_per_newton: float

    @property
    def margin_mm(self) -> float:
        return self.available_mm - self.need_mm


def tensioner_numbers(p: Params, *, check: bool = True) -> tuple[JointTension, ...]:
    """The tensioner of every joint (index j-1 for joint j). With ``check``, a UserError if the split spool's
    storage does not cover a joint's need, naming the parameter and the turns it must reach."""
    c, s = p.cable, p.spool
    e_pa, d_m, r_m = c.youngs_modulus_gpa * 1e9, c.diameter_mm / 1000, s.drum_diameter_mm / 2000
    ea = T.axial_rigidity_n(e_pa, d_m)
    step = T.vernier_step_rad(s.index_holes_upper, s.index_holes_lower)
    routes = cable_routes(p)
    out = []
    for j in range(p.joints.count):
        loop_m = sum(r.length_mm for r in routes if r.joint == j) / 1000
        stretch = T.stretch_at_tension_m(c.pretension_n, e_pa, d_m, loop_m)
        creep = c.creep_allowance_fraction * loop_m
        tol = 2 * c.assembly_tolerance_mm / 1000
        need = T.take_up_need_m(c.pretension_n, e_pa, d_m, loop_m, c.creep_allowance_fraction,
                                c.assembly_tolerance_mm / 1000)
        k = ea / loop_m                                  # N/m
        per_n = T.relative_turn_per_newton_rad(e_pa, d_m, loop_m, r_m)
        out.append(JointTension(
            joint=j + 1, loop_length_mm=1000 * loop_m, stretch_mm=1000 * stretch, creep_mm=1000 * creep,
            tolerance_mm=1000 * tol, need_mm=1000 * need,
            available_mm=1000 * s.tension_storage_turns * 2 * math.pi * r_m, stiffness_n_mm=k / 1000,
            step_deg=math.degrees(step), step_mm=1000 * r_m * step, newton_per_step=k * r_m * step,
            steps_per_newton=per_n / step, steps_to_pretension=c.pretension_n * per_n / step,
            degrees_per_newton=math.degrees(per_n)))
    if check:
        short = [t for t in out if t.margin_mm < -1e-9]
        if short:
            worst = max(t.need_mm / (2 * math.pi * s.drum_diameter_mm / 2) for t in short)
            raise UserError("; ".join(
                f"joint {t.joint}: the split spool takes up {t.available_mm:.1f} mm of its cable loop, which needs "
                f"{t.need_mm:.1f} mm (stretch {t.stretch_mm:.1f} at {c.pretension_n:g} N + creep {t.creep_mm:.1f} + "
                f"assembly {t.tolerance_mm:.1f})" for t in short)
                + f": raise spool.tension_storage_turns = {s.tension_storage_turns:g} to at least "
                  f"{math.ceil(worst * 100) / 100:g}")
    return tuple(out)
