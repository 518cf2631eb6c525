"""The design rules, as data: ``RULES`` is a list of (id, function); each function takes a :class:`RuleContext`
and returns one :class:`~design_rules.findings.Finding`.

Three groups: the paper's guidelines (§7.2), what follows from the physics at the design point (the load model
of ``swiftfin.layout.loads``), and what a printed robot needs. Limits come from the ``[rules]`` section of the parameter
file; the default limits are the paper's where it gives one.
"""
from __future__ import annotations

import collections
import functools
import math
from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy as np

from swiftfin.layout.geometry import cable_routes, spool_dims
from swiftfin.design_rules.findings import Finding, Severity, at_least, at_most, not_evaluated, within
from swiftfin.physics.capstan import cable_area_m2
from swiftfin.physics.kinematics import joint_resolution_rad
from swiftfin.layout.loads import (DriveLoads, JointLoads, LinkMass, drive_loads, fin_geometry, joint_loads,
                                   with_hinge_losses)
from swiftfin.physics.strouhal import strouhal
from swiftfin.core.calibration import Calibration
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.params import Problem
from swiftfin.core.schema import Params

PAPER = "SwiftFin paper"
MIN_GUIDE_BEND_RAD = math.radians(1.0)   # a "bend" under 1 deg needs no redirecting guide


@dataclass(frozen=True)
class MassProperties:
    """Mass properties of the assembled robot in the body frame (SI): from the built parts (another issue)."""
    total_mass_kg: float
    com_m: tuple[float, float, float]
    cob_m: tuple[float, float, float]
    displaced_volume_m3: float

    @classmethod
    def from_dict(cls, d: dict, source: str = "<mass properties>") -> "MassProperties":
        """Validate ``{total_mass_kg, com_m: [x, y, z], cob_m: [x, y, z], displaced_volume_m3}``, or a build's own
        ``mass_properties.json`` (its ``total`` table: ``mass_kg``, ``com_m``, ``cob_m``, ``displaced_volume_m3``).

        Raises :class:`swiftfin.core.params.ParamError` listing every problem (exit 2 in the CLI)."""
        from swiftfin.core.params import ParamError
        kind = "the mass-properties file"
        probs = []
        want = {"total_mass_kg": "a positive number [kg]", "displaced_volume_m3": "a positive number [m^3]",
                "com_m": "a list of 3 finite numbers [m]", "cob_m": "a list of 3 finite numbers [m]"}
        if not isinstance(d, dict):
            raise ParamError(source, [Problem("(file)", type(d).__name__, "expected a JSON object")], kind)
        if "total" in d:                       # the build's mass_properties.json
            t = d["total"]
            if not isinstance(t, dict):
                raise ParamError(source, [Problem("total", t, "expected a table (a build's mass_properties.json)")],
                                 kind)
            d = {"total_mass_kg": t.get("mass_kg"), "com_m": t.get("com_m"), "cob_m": t.get("cob_m"),
                 "displaced_volume_m3": t.get("displaced_volume_m3")}
            d = {k: v for k, v in d.items() if v is not None}
        for k in d:
            if k not in want:
                probs.append(Problem(k, d[k], f"unknown key: expected {', '.join(want)}"))
        for k, what in want.items():
            v = d.get(k)
            if k.endswith("_m"):
                ok = isinstance(v, (list, tuple)) and len(v) == 3 and all(
                    isinstance(c, (int, float)) and not isinstance(c, bool) and math.isfinite(c) for c in v)
            else:
                ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0
            if not ok:
                probs.append(Problem(k, v if k in d else "(missing)", f"expected {what}"))
        if probs:
            raise ParamError(source, probs, kind)
        return cls(float(d["total_mass_kg"]), tuple(float(c) for c in d["com_m"]),
                   tuple(float(c) for c in d["cob_m"]), float(d["displaced_volume_m3"]))


class RuleContext:
    """Everything the rules read: the parameters, optional built-part data, and the loads (computed once)."""

    def __init__(self, params: Params, mass_properties: MassProperties | None = None,
                 part_bboxes_mm: dict[str, tuple[float, float, float]] | None = None,
                 link_masses: tuple[LinkMass, ...] | None = None, calibration: Calibration | None = None,
                 print_records: dict | None = None):
        """``calibration``: measured values (core.calibration); its revised design keys must already be in
        ``params`` (:meth:`Calibration.revised_params`), its hinge damping and friction join the loads here.
        ``print_records``: the built printed parts' :class:`swiftfin.design_rules.printing.PrintRecord` by label
        (the printability rules read them)."""
        self.p = params
        self.mass_properties = mass_properties
        self.part_bboxes_mm = part_bboxes_mm
        self.link_masses = link_masses
        self.calibration = calibration
        self.print_records = print_records

    @cached_property
    def loads(self) -> JointLoads:
        loads = joint_loads(self.p, self.link_masses)
        cal = self.calibration
        if cal is not None and cal.joints:
            n = self.p.joints.count
            loads = with_hinge_losses(loads, cal.per_joint("hinge_damping_nm_s_rad", n),
                                      cal.per_joint("hinge_friction_nm", n))
        return loads

    @cached_property
    def drive(self) -> DriveLoads:
        return drive_loads(self.p, self.loads)

    @cached_property
    def joint_amplitude_rad(self) -> np.ndarray:
        return np.max(np.abs(self.loads.joint_angle_rad), axis=0)

    @property
    def load_note(self) -> str:
        src = "built parts" if self.link_masses is not None else "hull-shell estimate"
        return f"load model layout/loads.py at {self.p.swimming.tail_beat_frequency_hz:g} Hz, link masses from {src}"


def _worst(values) -> tuple[int, float]:
    i = int(np.argmax(values))
    return i, float(values[i])


# ----------------------------------------------------------------------------------------------- paper §7.2
def drum_to_cable(ctx: RuleContext) -> Finding:
    p = ctx.p
    return at_least("paper.drum_to_cable", p.spool.drum_diameter_mm / p.cable.diameter_mm, p.rules.drum_to_cable_min,
                    f"{PAPER} §7.2 (drum >= 20 x cable diameter)",
                    detail=f"drum {p.spool.drum_diameter_mm:g} mm / cable {p.cable.diameter_mm:g} mm")


def pretension_band(ctx: RuleContext) -> Finding:
    p = ctx.p
    return within("paper.pretension_fraction", p.cable.pretension_n / p.cable.breaking_strength_n,
                  p.rules.pretension_min_fraction, p.rules.pretension_max_fraction,
                  f"{PAPER} §7.2 (10-20 % of breaking strength)",
                  detail=f"{p.cable.pretension_n:g} N of {p.cable.breaking_strength_n:g} N")


def holding_torque(ctx: RuleContext) -> Finding:
    i, peak = _worst(ctx.drive.peak_motor_torque_nm)
    return at_least("paper.holding_torque", ctx.p.motor.holding_torque_nm / peak, ctx.p.rules.holding_torque_factor,
                    f"{PAPER} §7.2 (holding torque >= 2 x peak swimming load)",
                    detail=f"holding {ctx.p.motor.holding_torque_nm:g} N m / peak motor torque {peak:.3g} N m "
                           f"(joint {i + 1}); {ctx.load_note}")


def cable_diameter(ctx: RuleContext) -> Finding:
    return at_most("paper.cable_diameter", ctx.p.cable.diameter_mm, ctx.p.rules.cable_diameter_max_mm,
                   f"{PAPER} §7.2 (<= 1.5 mm)", unit="mm")


def cable_elongation(ctx: RuleContext) -> Finding:
    p = ctx.p
    i, t = _worst(ctx.drive.peak_tension_n)
    strain = t / (p.cable.youngs_modulus_gpa * 1e9 * cable_area_m2(p.cable.diameter_mm * 1e-3))
    return at_most("paper.cable_elongation", strain, p.rules.elongation_max_fraction,
                   f"{PAPER} §7.2 (< 0.5 % at working load)",
                   detail=f"peak tension {t:.4g} N (joint {i + 1}), E = {p.cable.youngs_modulus_gpa:g} GPa on the "
                          f"full {p.cable.diameter_mm:g} mm section")


def guide_friction(ctx: RuleContext) -> Finding:
    return at_most("paper.guide_friction", ctx.p.guides.mu_ptfe, ctx.p.rules.ptfe_mu_max,
                   f"{PAPER} §7.2 (PTFE guides with mu < 0.1)")


def guides_per_route(ctx: RuleContext) -> Finding:
    counts = {}
    for rt in cable_routes(ctx.p):
        counts[(rt.joint, rt.side)] = sum(1 for b in rt.bends if b.angle_rad > MIN_GUIDE_BEND_RAD)
    (j, side), n = max(counts.items(), key=lambda kv: kv[1])
    return at_most("paper.guides_per_route", n, ctx.p.rules.guides_per_route_max,
                   f"{PAPER} §7.2 (minimise redirecting guides); eq. 29 budgets 2",
                   detail=f"joint {j + 1} {'left' if side > 0 else 'right'} route: {n} bends over 1 deg "
                          f"(swiftfin.layout.geometry.cable_routes)", above=Severity.WARN)


# ----------------------------------------------------------------------------------------------- physics
def capstan_no_slip(ctx: RuleContext) -> Finding:
    cap = ctx.drive.capstan_capacity.min(axis=0)
    i = int(np.argmin(cap))
    return at_least("physics.capstan_no_slip", float(cap[i]), ctx.p.rules.capstan_slip_margin,
                    f"{PAPER} eq. 20: T_tight / T_slack <= e^(mu theta_w)",
                    detail=f"worst joint {i + 1}: min over the cycle of T_slack e^(mu theta_w) / T_tight at the spool "
                           f"(mu {ctx.p.spool.mu_cable_drum:g}, {ctx.p.spool.wraps:g} wraps); 0 means a side went "
                           f"slack; {ctx.load_note}")


def no_slack_side(ctx: RuleContext) -> Finding:
    p = ctx.p
    m = p.joints.tendon_moment_arm_mm * 1e-3
    need = ctx.loads.peak_torque_nm / (2 * m)
    i, worst = _worst(need)
    return at_least("physics.no_slack_side", p.cable.pretension_n, worst,
                    "pull-pull pair: T_slack = T0 - tau / (2 d_mount) (physics.capstan.pull_pull_tensions)", unit="N",
                    detail=f"pretension vs half the peak tension difference, joint {i + 1} "
                           f"(peak torque {ctx.loads.peak_torque_nm[i]:.3g} N m); {ctx.load_note}")


def cable_strength(ctx: RuleContext) -> Finding:
    i, t = _worst(ctx.drive.peak_spool_tension_n)
    return at_least("physics.cable_strength", ctx.p.cable.breaking_strength_n / t, ctx.p.rules.cable_safety_factor,
                    "breaking strength / peak tension (at the spool, after the guides' friction)",
                    detail=f"peak {t:.4g} N on joint {i + 1}; {ctx.load_note}")


def stepper_pullout(ctx: RuleContext) -> Finding:
    mo = ctx.p.motor
    rates = np.asarray(mo.pullout_curve_steps_per_s)
    torques = np.asarray(mo.pullout_curve_torque_nm)
    need_rate = ctx.drive.step_rate_full_steps_s
    need_torque = np.abs(ctx.drive.motor_torque_nm)
    src = "[motor] pull-out curve (speed-torque) at the full-step rate the wave demands (eq. 48 differentiated)"
    if need_rate.max() > rates[-1]:
        return Finding("physics.stepper_pullout", float(need_rate.max()), float(rates[-1]),
                       float((rates[-1] - need_rate.max()) / rates[-1]), Severity.FAIL, src, "full steps/s", "<=",
                       "the wave needs a step rate beyond the end of the pull-out curve")
    avail = np.interp(need_rate, rates, torques)
    ratio = np.where(need_torque > 0, avail / np.maximum(need_torque, 1e-12), np.inf)
    t_i, j = np.unravel_index(int(np.argmin(ratio)), ratio.shape)
    return at_least("physics.stepper_pullout", float(ratio[t_i, j]), ctx.p.rules.pullout_safety_factor, src,
                    detail=f"joint {j + 1}: needs {need_torque[t_i, j]:.3g} N m at {need_rate[t_i, j]:.0f} full steps/s, "
                           f"curve gives {avail[t_i, j]:.3g} N m; {ctx.load_note}")


def microstep_resolution(ctx: RuleContext) -> Finding:
    p = ctx.p
    q = joint_resolution_rad(math.radians(p.motor.full_step_deg), p.motor.microsteps,
                             p.joints.tendon_moment_arm_mm * 1e-3, p.spool.drum_diameter_mm / 2 * 1e-3)
    frac = (q / 2) / ctx.joint_amplitude_rad
    i, worst = _worst(frac)
    return at_most("physics.microstep_resolution", worst, p.rules.position_error_limit_fraction,
                   f"{PAPER} eq. 48 inverted: one microstep = {math.degrees(q):.4g} deg at the joint",
                   detail=f"half a microstep / joint {i + 1}'s amplitude {math.degrees(ctx.joint_amplitude_rad[i]):.3g} deg")


def cable_compliance(ctx: RuleContext) -> Finding:
    frac = ctx.drive.compliance_rad.max(axis=0) / ctx.joint_amplitude_rad
    i, worst = _worst(frac)
    return at_most("physics.cable_compliance", worst, ctx.p.rules.position_error_limit_fraction,
                   f"{PAPER} eq. 39 at the joint: stretch / d_mount",
                   detail=f"joint {i + 1}: {math.degrees(ctx.drive.compliance_rad[:, i].max()):.3g} deg of stretch at "
                          f"peak load vs {math.degrees(ctx.joint_amplitude_rad[i]):.3g} deg amplitude; {ctx.load_note}")


def strouhal_band(ctx: RuleContext) -> Finding:
    sw = ctx.p.swimming
    if sw.speed_m_s <= 0:
        return not_evaluated("physics.strouhal", f"{PAPER} eq. 41", "swimming.speed_m_s = 0: St = f A / U undefined")
    st = float(strouhal(sw.tail_beat_frequency_hz, 2 * sw.tail_amplitude_m, sw.speed_m_s))
    return within("physics.strouhal", st, ctx.p.rules.strouhal_min, ctx.p.rules.strouhal_max,
                  f"{PAPER} eq. 41 and §2.5.3 (0.25-0.35)",
                  detail=f"f = {sw.tail_beat_frequency_hz:g} Hz, A = 2 x {sw.tail_amplitude_m:g} m (peak to peak), "
                         f"U = {sw.speed_m_s:g} m/s")


def fin_root_section_mm3(p: Params) -> float:
    """Section modulus of the fin's root tang (``layout.fin_plan.tang_dims_mm``) bent about the vertical axis, the
    way the fin's side force bends it: height x thickness^2 / 6 [mm^3]."""
    from swiftfin.layout.fin_plan import tang_dims_mm
    td = tang_dims_mm(p)
    return td.height_mm * td.thickness_mm**2 / 6.0


def fin_root(ctx: RuleContext) -> Finding:
    """The fin's lift and added-mass forces (the load model's) about the mouth of its socket, over the tang's
    section there: its peak bending stress against the printed material's allowable along the layers (the fin is
    printed flat: the stress runs along them)."""
    from swiftfin.catalogues.printed_strength import printed_strength
    p = ctx.p
    m_nm = ctx.loads.peak_fin_root_moment_nm
    z = fin_root_section_mm3(p)
    ps = printed_strength(p.print.material)
    return at_most("physics.fin_root", m_nm * 1e3 / z, ps.bending_allowable_mpa,
                   "peak bending stress in the fin's root tang at its socket's mouth (the hull end)", unit="MPa",
                   detail=f"{m_nm:.3g} N m over the tang's {z:.3g} mm^3; {p.print.material} {ps.tensile_yield_mpa:g} "
                          f"MPa x {ps.sustained_fraction:g} (catalogues/printed_strength.toml); {ctx.load_note}")


HINGE_BEND_SOURCE = ("the cable's least bend radius rules.drum_to_cable_min x cable.diameter_mm / 2 (the paper's drum "
                     "rule); where a cable crosses a hinge line it turns round the edge of the link's pass-through "
                     "hole (layout.geometry.hinge_crossings)")


def hinge_bend(ctx: RuleContext) -> Finding:
    """``physics.hinge_bend``: where a cable crosses the hinge line of a joint it does not drive (on the axis, out of
    the pass-through hole of the link ahead into the one behind), it turns by its route's angle there plus up to the
    joint's stop, round the edge of the hole, which has no lead radius (0 mm: no joint hardware declares one)
    against the cable's least bend radius. WARN, not FAIL: no key of the design can give the edge a
    lead today (a lead alone couples the joints and slackens the pairs: README, *Cables and tubes*), and a FAIL would
    refuse every design of two joints or more, leaving ``swiftfin solve`` nothing to find; the builder is told to
    round the holes' edges. Not evaluated with one joint (no cable crosses a hinge line)."""
    from swiftfin.layout.geometry import hinge_crossings
    p = ctx.p
    limit = p.rules.drum_to_cable_min * p.cable.diameter_mm / 2
    crossings = hinge_crossings(p)
    if not crossings:
        return not_evaluated("physics.hinge_bend", HINGE_BEND_SOURCE, "one joint: no cable crosses a hinge line",
                             unit="mm")
    # no joint's hardware has a lead radius (layout/joints.py: JointHardware declares none; cad/cables.py reads one
    # where it would): every crossing's edge is sharp. Read without the hardware, which a design the loader refuses
    # may not have (the rules run on such designs too: the vectorised twin's fallback)
    lead_mm = 0.0
    worst = max(crossings, key=lambda c: c.worst_rad)
    turns = [math.degrees(c.worst_rad) for c in crossings]
    return at_least("physics.hinge_bend", lead_mm, limit, HINGE_BEND_SOURCE, unit="mm",
                    detail=f"{len(crossings)} of {len(crossings)} hinge-line crossings turn the cable by "
                           f"{min(turns):.1f}-{max(turns):.1f} deg over the joints' range round an edge of "
                           f"{lead_mm:g} mm radius (the worst: {worst.label} at joint {worst.joint}, "
                           f"{math.degrees(worst.worst_rad):.1f} deg); round the pass-through holes' edges as far "
                           f"as the links allow, and expect wear there", below=Severity.WARN)


# ----------------------------------------------------------------------------------------------- printing
def _wall(rule_id: str, thickness_mm: float, what: str):
    def rule(ctx: RuleContext) -> Finding:
        lw = ctx.p.print.line_width_mm
        return at_least(rule_id, thickness_mm(ctx.p) / lw, ctx.p.rules.wall_min_line_widths,
                        "FDM: a closed wall needs two perimeters", unit="line widths",
                        detail=f"{what} {thickness_mm(ctx.p):g} mm / line width {lw:g} mm")
    rule.__name__ = rule_id.split(".")[-1]
    return rule


@functools.lru_cache(maxsize=4)
def _bed_angles(n_angles: int) -> tuple[np.ndarray, np.ndarray]:
    a = np.linspace(0.0, np.pi / 2, n_angles)
    return np.cos(a), np.sin(a)


def fits_bed(size_mm, bed_mm, n_angles: int = 361) -> bool:
    """Whether a box (dx, dy, dz) fits the bed (X, Y, Z), turned by any angle about z."""
    dx, dy, dz = size_mm
    X, Y, Z = bed_mm
    if dz > Z:
        return False
    c, s = _bed_angles(n_angles)
    w = dx * c + dy * s
    h = dx * s + dy * c
    return bool(np.any((w <= X) & (h <= Y)))


def fit_factor(size_mm, bed_mm) -> float:
    """Largest scale k such that k x the box still fits the bed (>= 1: fits)."""
    lo, hi = 0.0, 100.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if fits_bed(tuple(mid * s for s in size_mm), bed_mm):
            lo = mid
        else:
            hi = mid
    return lo


def layout_part_boxes_mm(p: Params) -> dict[str, tuple[float, float, float]]:
    """Print-orientation bounding boxes of the parts the layout already sizes: hull segments (halves, flat face
    down, when split), the caudal fin (flat) and the spool (axis up). An estimate until the parts are built."""
    from swiftfin.layout.hull_plan import hull_pieces, printed_size_mm  # the hull's split plan
    out = {}
    for pc in hull_pieces(p):
        size = printed_size_mm(p, pc)
        for label in ((f"{pc.name}_upper", f"{pc.name}_lower") if p.hull.split_halves else (pc.name,)):
            out[label] = size
    fin = fin_geometry(p)
    sweep = math.tan(math.radians(p.caudal_fin.sweep_deg)) * fin.span_m / 2
    out["caudal_fin"] = ((fin.chord_m + sweep) * 1e3 + p.caudal_fin.mount_length_mm, fin.span_m * 1e3,
                         p.caudal_fin.thickness_fraction * fin.chord_m * 1e3)
    d = spool_dims(p)
    out["spool"] = (2 * d.flange_radius_mm, 2 * d.flange_radius_mm, d.top_mm - d.hub_bottom_mm)
    return out


PRINT_SOURCE = "exports/printability.py on the built parts' meshes in their print orientations"
NEEDS_BUILD = "needs the built parts: swiftfin check --build DIR (a build folder), or the report of a build"


def support_area(ctx: RuleContext) -> Finding:
    """``print.support``: the overhang the slicer must support, summed over the printed parts, each in the
    orientation the build chose for least support. A number to know, not a pass/fail (INFO)."""
    recs = ctx.print_records
    if not recs:
        return not_evaluated("print.support", PRINT_SOURCE, NEEDS_BUILD, "mm^2")
    total = sum(r.support_area_mm2 for r in recs.values())
    top = sorted(recs.values(), key=lambda r: -r.support_area_mm2)[:3]
    worst = ", ".join(f"{r.label} {r.support_area_mm2:.0f}" for r in top if r.support_area_mm2 > 0)
    return Finding("print.support", float(total), None, None, Severity.INFO,
                   f"overhang steeper than print.support_angle_deg = {ctx.p.print.support_angle_deg:g} deg from the "
                   f"vertical, projected on the bed; " + PRINT_SOURCE, "mm^2", "",
                   f"{sum(r.support_area_mm2 > 0 for r in recs.values())} of {len(recs)} printed parts need "
                   f"support" + (f"; most: {worst} mm^2" if worst else ""))


def _count(rule_id: str, n: int, source: str, unit: str, detail: str, above: Severity = Severity.FAIL) -> Finding:
    """A count that must be zero: no relative margin to give (None), PASS at zero, ``above`` otherwise."""
    return Finding(rule_id, float(n), 0.0, None, Severity.PASS if n == 0 else above, source, unit, "<=", detail)


def printable_minimum_mm(w) -> float:
    """The least a region must be to print at all: one line (or one layer, where its limit is two layers) for a
    wall held to two; a load-free web's limit is already one line."""
    return w.limit_mm if w.kind == "web" else w.limit_mm / 2


def thin_walls(ctx: RuleContext) -> Finding:
    """``print.thin_walls``: regions thinner than two perimeters (two layers where the thickness runs along the
    print's vertical; one line width for a load-free web between two bores), over every printed part. FAIL where
    one would not print at all (under one line, or one layer: :func:`printable_minimum_mm`; the slicer leaves a
    hole there), WARN where every one prints, thinner than the rule asks."""
    recs = ctx.print_records
    if not recs:
        return not_evaluated("print.thin_walls", PRINT_SOURCE, NEEDS_BUILD, "regions")
    lw = ctx.p.print.line_width_mm
    walls = [(r.label, w) for r in recs.values() for w in r.walls]
    src = f"FDM: a wall needs two perimeters ({2 * lw:g} mm); the ray-cast wall probe, " + PRINT_SOURCE
    if not walls:
        return _count("print.thin_walls", 0, src, "regions", f"none on the {len(recs)} printed parts")
    lb, w = min(walls, key=lambda t: t[1].thickness_mm / t[1].limit_mm)
    per = collections.Counter(label for label, _ in walls)
    lost = [(label, x) for label, x in walls if x.thickness_mm < printable_minimum_mm(x) - 1e-9]
    return _count("print.thin_walls", len(walls), src, "regions",
                  (f"{len(lost)} too thin to print at all (under one line or one layer); " if lost else
                   "each prints (one line or layer at least), thinner than two; ") +
                  f"on {len(per)} of {len(recs)} printed parts (" + ", ".join(f"{k} {v}" for k, v in per.items())
                  + f"); thinnest against its limit: {lb}, {w.text()}", above=Severity.FAIL if lost else Severity.WARN)


def long_bridges(ctx: RuleContext) -> Finding:
    """``print.bridges``: ceilings spanning more than ``print.max_bridge_mm`` between edges with material below
    (or with no such edge). WARN, not FAIL: the slicer supports what it cannot bridge (it is in ``print.support``)."""
    recs = ctx.print_records
    if not recs:
        return not_evaluated("print.bridges", PRINT_SOURCE, NEEDS_BUILD, "bridges")
    limit = ctx.p.print.max_bridge_mm
    found = [(r.label, b) for r in recs.values() for b in r.bridges]
    src = f"longest bridge print.max_bridge_mm = {limit:g} mm; " + PRINT_SOURCE
    if not found:
        return _count("print.bridges", 0, src, "bridges", f"none on the {len(recs)} printed parts")
    spans = [(lb, b) for lb, b in found if b.span_mm is not None]
    hanging = len(found) - len(spans)
    detail = f"on {len({lb for lb, _ in found})} of {len(recs)} printed parts"
    if spans:
        lb, b = max(spans, key=lambda t: t[1].span_mm)
        detail += (f"; longest: {lb}, {b.span_mm:.1f} mm over {b.area_mm2:.0f} mm^2 at "
                   f"({', '.join(f'{v:.1f}' for v in b.at_mm)}) mm")
    if hanging:
        detail += f"; {hanging} with no edge on material below (support starts them)"
    return _count("print.bridges", len(found), src, "bridges", detail, above=Severity.WARN)


def supported_bores(ctx: RuleContext) -> Finding:
    """``print.bores``: no support inside a fastener's hole. A round hole whose axis leans more than the support
    angle off the print's vertical has a ceiling that leans past it too; one no wider than ``print.max_bridge_mm``
    closes over it unsupported (the slicer bridges it), a wider one needs support inside, which a screw, an insert
    or a pin then meets."""
    recs = ctx.print_records
    if not recs:
        return not_evaluated("print.bores", PRINT_SOURCE, NEEDS_BUILD, "bores")
    pr = ctx.p.print
    found = [(r.label, b) for r in recs.values() for b in r.supported_bores]
    checked = sum(r.bores_checked for r in recs.values())
    src = (f"a hole leaning over print.support_angle_deg = {pr.support_angle_deg:g} deg from the vertical and wider "
           f"than print.max_bridge_mm = {pr.max_bridge_mm:g} mm needs support inside; the fasteners' holes in each "
           f"part's print orientation")
    if not found:
        return _count("print.bores", 0, src, "bores",
                      f"none of the {checked} fastener holes in the {len(recs)} printed parts")
    lb, b = max(found, key=lambda t: t[1].diameter_mm)
    return _count("print.bores", len(found), src, "bores",
                  f"of {checked} fastener holes; widest: {b.what} of {b.fastener} in {lb}, {b.diameter_mm:.2f} mm "
                  f"at {b.tilt_deg:.0f} deg from the vertical")


def bed_fit(ctx: RuleContext) -> Finding:
    pr = ctx.p.print
    bed = (pr.bed_x_mm, pr.bed_y_mm, pr.bed_z_mm)
    if ctx.part_bboxes_mm:
        boxes, src = ctx.part_bboxes_mm, "built parts"
    else:
        try:
            boxes, src = layout_part_boxes_mm(ctx.p), "the part families' split plan"
        except UserError as exc:  # a hull segment that no split makes fit
            return at_least("print.bed_fit", 0.0, 1.0, "every printed part fits the bed (turned about z if need be)",
                            detail=str(exc))
    factors = {k: fit_factor(v, bed) for k, v in boxes.items()}
    name = min(factors, key=factors.get)
    size = boxes[name]
    return at_least("print.bed_fit", factors[name], 1.0, "every printed part fits the bed (turned about z if need be)",
                    detail=f"tightest: {name} {size[0]:.0f} x {size[1]:.0f} x {size[2]:.0f} mm on a "
                           f"{bed[0]:g} x {bed[1]:g} x {bed[2]:g} mm bed ({src}; value = how much it could grow)")


def floats_upright(ctx: RuleContext) -> Finding:
    src = "centre of buoyancy above the centre of mass (hydrostatic stability in roll)"
    mp = ctx.mass_properties
    if mp is None:
        return not_evaluated("float.upright", src, "needs the built parts' mass properties (com, cob): "
                                                   "pass --mass-properties FILE", unit="mm")
    dz = (mp.cob_m[2] - mp.com_m[2]) * 1e3
    return at_least("float.upright", dz, 0.0, src, unit="mm", detail="z_cob - z_com in the body frame")


def net_buoyancy(ctx: RuleContext) -> Finding:
    src = "near-neutral trim: |rho V - m| / m within environment.buoyancy_band_fraction"
    mp = ctx.mass_properties
    if mp is None:
        return not_evaluated("float.net_buoyancy", src, "needs the built parts' mass and displaced volume: "
                                                        "pass --mass-properties FILE")
    rho = ctx.p.environment.water_density_kg_m3
    frac = (rho * mp.displaced_volume_m3 - mp.total_mass_kg) / mp.total_mass_kg
    return at_most("float.net_buoyancy", abs(frac), ctx.p.environment.buoyancy_band_fraction, src,
                   detail=f"buoyancy {rho * mp.displaced_volume_m3:.3g} kg vs mass {mp.total_mass_kg:.3g} kg "
                          f"({'floats' if frac > 0 else 'sinks'})")


def floats_level(ctx: RuleContext) -> Finding:
    src = "static pitch in still water within environment.max_static_pitch_deg: atan(COM's lead over the COB / " \
          "COB's height over the COM)"
    mp = ctx.mass_properties
    if mp is None:
        return not_evaluated("float.level", src, "needs the built parts' mass properties (com, cob): "
                                                 "pass --mass-properties FILE", unit="deg")
    from swiftfin.physics.hydrostatics import static_pitch_deg
    pitch = static_pitch_deg(mp.com_m, mp.cob_m)
    lead_mm = (mp.com_m[0] - mp.cob_m[0]) * 1e3
    return at_most("float.level", abs(pitch), ctx.p.environment.max_static_pitch_deg, src, unit="deg",
                   detail=f"COM {abs(lead_mm):.1f} mm {'ahead of' if lead_mm >= 0 else 'behind'} the COB: settles "
                          f"{abs(pitch):.1f} deg nose-{'down' if pitch >= 0 else 'up'}")


# ----------------------------------------------------------------------------------------------- heat and power
MOTOR_CASE_AREA_FACES = 5
"""Faces of a motor's frame that give heat to the air: four sides and the back (the front is on its mount)."""


def dry_wall_m2(p: Params, n: int = 400) -> tuple[float, float, float]:
    """The dry compartment's wall, as heat leaves it: (side wall [m^2], rear wall's face [m^2], rear wall's
    thickness [m]). The side wall is the hull's outer surface from the nose to where the cavity ends, the front face
    of the rear wall (:func:`swiftfin.layout.hull_plan.dry_wall_span_mm`: as thick as the cable glands need, 14.9 mm
    on the default design, where the side wall is ``hull.wall_thickness_mm``); a hull sealed throughout is skinned
    to its end and has no rear wall (0, 0). The ellipse perimeters by Ramanujan's second formula, integrated along the stations."""
    from swiftfin.layout.geometry import half_height_mm, hull_end_mm, naca_half_width_mm
    from swiftfin.layout.hull_plan import dry_wall_span_mm
    dry = dry_wall_span_mm(p)
    if dry is None:
        return 0.0, 0.0, 0.0
    s_front, s_back, rear_joint = dry
    s_end = s_front if rear_joint is not None else hull_end_mm(p)
    s = np.linspace(0.0, s_end, n)
    a = np.asarray(naca_half_width_mm(p, s))
    b = np.asarray(half_height_mm(p, s))
    h = ((a - b) / (a + b + 1e-12)) ** 2
    per = math.pi * (a + b) * (1 + 3 * h / (10 + np.sqrt(4 - 3 * h)))
    da = np.gradient(0.5 * (a + b), s)                       # the surface is slanted where the section grows
    side = float(np.trapezoid(per * np.sqrt(1 + da**2), s))
    if rear_joint is None:
        return side * 1e-6, 0.0, 0.0
    return side * 1e-6, math.pi * a[-1] * b[-1] * 1e-6, (s_back - s_front) * 1e-3


def dry_wall_area_m2(p: Params, n: int = 400) -> float:
    """Wall of the dry compartment [m^2]: its side wall and its rear wall's face (:func:`dry_wall_m2`)."""
    side, rear, _ = dry_wall_m2(p, n)
    return side + rear


def _heat(ctx: RuleContext) -> dict:
    """The dry compartment's heat balance at the design gait (physics/thermal.py)."""
    from swiftfin.catalogues.materials import material
    from swiftfin.physics.thermal import (case_rise_k, compartment_resistance_k_w, driver_bridge_loss_w,
                                          stepper_copper_loss_w)
    p = ctx.p
    micro = p.motor.microsteps > 1
    n = p.joints.count
    motor_w = stepper_copper_loss_w(p.motor.phase_current_a, p.motor.phase_resistance_ohm, micro)
    driver_w = driver_bridge_loss_w(p.motor.phase_current_a, p.power.driver_rds_on_ohm, micro)
    total_w = n * (motor_w + driver_w) + p.power.electronics_power_w
    mat = material(p.print.material)
    side, rear, rear_m = dry_wall_m2(p)
    area = side + rear
    env = p.environment
    r = compartment_resistance_k_w([(side, p.hull.wall_thickness_mm * 1e-3), (rear, rear_m)],
                                   mat.thermal_conductivity_w_m_k, env.heat_transfer_air_w_m2_k,
                                   env.heat_transfer_water_w_m2_k)
    air_c = env.water_temperature_c + total_w * r
    case_area = (MOTOR_CASE_AREA_FACES - 1) * p.motor.frame_size_mm * p.motor.body_length_mm * 1e-6 \
        + p.motor.frame_size_mm ** 2 * 1e-6
    case_c = air_c + case_rise_k(motor_w, case_area, env.heat_transfer_air_w_m2_k)
    return {"motor_w": motor_w, "driver_w": driver_w, "total_w": total_w, "area_m2": area, "r_k_w": r,
            "rear_m2": rear, "rear_m": rear_m,
            "air_c": air_c, "case_c": case_c, "material": mat, "limit_c": mat.heat_deflection_temperature_c
            - p.rules.softening_margin_k}


def dry_compartment_temperature(ctx: RuleContext) -> Finding:
    h = _heat(ctx)
    p = ctx.p
    return at_most("heat.dry_compartment", h["air_c"], h["limit_c"],
                   f"steady heat balance (physics/thermal.py): inside air below the printed {h['material'].name}'s "
                   f"heat deflection temperature less rules.softening_margin_k", unit="C",
                   detail=f"{h['total_w']:.1f} W inside ({p.joints.count} motors x {h['motor_w']:.2f} W copper + "
                          f"drivers x {h['driver_w']:.2f} W + electronics {p.power.electronics_power_w:g} W at "
                          f"{p.motor.phase_current_a:g} A) through {h['area_m2'] * 1e4:.0f} cm^2 of wall (the rear wall's "
                          f"{h['rear_m2'] * 1e4:.0f} cm^2 {1000 * h['rear_m']:.1f} mm thick), "
                          f"{h['r_k_w']:.2f} K/W: {h['total_w'] * h['r_k_w']:.0f} K over the "
                          f"{p.environment.water_temperature_c:g} C water")


def motor_mount_temperature(ctx: RuleContext) -> Finding:
    h = _heat(ctx)
    return at_most("heat.motor_mount", h["case_c"], h["limit_c"],
                   f"a motor's case (and the printed mount on its face) below the {h['material'].name}'s heat "
                   f"deflection temperature less rules.softening_margin_k", unit="C",
                   detail=f"case {h['case_c'] - h['air_c']:.0f} K above the {h['air_c']:.0f} C air "
                          f"({h['motor_w']:.2f} W through its {MOTOR_CASE_AREA_FACES} free faces)")


def run_time(ctx: RuleContext) -> Finding:
    from swiftfin.physics.thermal import run_time_s
    h = _heat(ctx)
    p = ctx.p
    mech_w = max(ctx.loads.mean_positive_power_w, 0.0)
    draw_w = h["total_w"] + mech_w
    minutes = run_time_s(p.power.battery_energy_wh * 3600.0, p.power.battery_usable_fraction, draw_w) / 60.0
    return at_least("power.run_time", minutes, p.power.run_time_required_min,
                    "battery energy x usable share / the drive's electrical draw at the design gait", unit="min",
                    detail=f"{p.power.battery_energy_wh:g} Wh x {p.power.battery_usable_fraction:g} over "
                           f"{draw_w:.1f} W ({h['total_w']:.1f} W of losses and electronics + {mech_w:.2f} W "
                           f"delivered to the joints; {ctx.load_note})")


def gland_rating_m(p: Params, packed_length_mm: float, stroke_mm: float) -> float:
    """Depth a grease-packed cable gland is good for (physics/sealing.py, catalogues/seals.toml ``[cable_gland]``):
    the stretch of its packing the cable's stroke never wets, ``packed - stroke``, must hold the water's pressure with
    the table's safety factor; a gland the stroke wets through holds nothing [m]."""
    from swiftfin.catalogues.seals import cable_gland
    from swiftfin.physics.sealing import grease_plug_hold_pa, rated_depth_m
    g = cable_gland()
    dry_len = max(packed_length_mm - stroke_mm, 0.0)
    hold = grease_plug_hold_pa(g.grease_yield_stress_pa, dry_len, g.radial_gap_mm)
    env = p.environment
    return rated_depth_m(hold, g.pressure_safety_factor, env.water_density_kg_m3, env.gravity_m_s2)


def cable_gland(ctx: RuleContext) -> Finding:
    """``seal.cable_gland``: the least depth the cable glands through the dry wall hold (:func:`gland_rating_m`), each
    its own packed length (:func:`swiftfin.layout.gland_plan.cable_glands`: the wall's thickness along its cable's
    route, less where joint ``hull.flooded_from_joint``'s clevis room in the wall's back face cuts it short) less its
    own joint's stroke."""
    from swiftfin.catalogues.seals import cable_gland as gland_row
    from swiftfin.layout.gland_plan import cable_glands
    p = ctx.p
    g = gland_row()
    what = ("each cable gland through the dry wall (catalogues/seals.toml): the packing its cable's stroke never "
            "wets holds 2 tau_y L / h (physics/sealing.py) with the safety factor, down to this depth (the least of "
            "them); against environment.design_depth_m")
    try:
        glands = cable_glands(p)
    except (UserError, BuildError) as exc:      # a design the loader refuses (joint_hardware's problems)
        return not_evaluated("seal.cable_gland", "layout/gland_plan.py",
                             f"the joints' hardware cannot be laid out, so neither can the glands: {exc}", unit="m")
    if not glands:
        return not_evaluated("seal.cable_gland", "layout/gland_plan.py",
                             "no cable crosses a dry wall (the whole hull is sealed, or none of it)", unit="m")
    rates = [gland_rating_m(p, gl.packed_mm, gl.stroke_mm) for gl in glands]
    worst = glands[int(np.argmin(rates))]
    return at_least("seal.cable_gland", min(rates), p.environment.design_depth_m, what, unit="m",
                    detail=f"{worst.label}: {worst.packed_mm:.1f} mm packed (hull.cable_gland_length_mm "
                           f"{p.hull.cable_gland_length_mm:g} mm) less joint {worst.joint}'s stroke "
                           f"{worst.stroke_mm:.1f} mm (moment arm x stop angle); tau_y {g.grease_yield_stress_pa:g} "
                           f"Pa (an assumed low-end grease), gap {g.radial_gap_mm:g} mm, safety factor "
                           f"{g.pressure_safety_factor:g}; "
                           + ", ".join(f"{gl.label} {r:.2f} m" for gl, r in zip(glands, rates)))


def seam_gasket(ctx: RuleContext) -> Finding:
    """``seal.seam_gasket``: the head's seam gasket (catalogues/seals.toml ``[seam_gasket]``, cad/seal.py) seated at
    its least compression: the sheet's contact stress there over the water's pressure at the design depth times the
    table's safety factor. The gap is the limiter's length (the band's middle) +/- the limiter's and both printed
    faces' tolerances. The build measures the rest on the gasket's solid (``seal.seam_gasket_*``)."""
    from swiftfin.catalogues.seals import seam_gap_tolerance_mm
    from swiftfin.catalogues.seals import seam_gasket as sheet_row
    p = ctx.p
    if not p.hull.split_halves:
        return not_evaluated("seal.seam_gasket", "catalogues/seals.toml [seam_gasket]",
                             "the hull is not split into halves (hull.split_halves): no seam gasket", unit="kPa")
    g = sheet_row()
    lo, hi = g.compression_range(g.limiter_length_mm(), seam_gap_tolerance_mm())
    env = p.environment
    pressure_kpa = env.water_density_kg_m3 * env.gravity_m_s2 * env.design_depth_m / 1000.0
    return at_least("seal.seam_gasket", g.stress_kpa(lo), g.pressure_safety_factor * pressure_kpa,
                    "the head's seam gasket (catalogues/seals.toml [seam_gasket]): its contact stress at the least "
                    "compression over the water's pressure at environment.design_depth_m times the safety factor",
                    unit="kPa",
                    detail=f"{g.sheet_thickness_mm:g} mm sheet on {g.limiter_length_mm():.3g} mm limiters +/- "
                           f"{seam_gap_tolerance_mm():.3g} mm: compressed {lo * 100:.1f}-{hi * 100:.1f} % (band "
                           f"{g.compression_min_fraction * 100:.0f}-{g.compression_max_fraction * 100:.0f} %); "
                           f"{pressure_kpa:.2f} kPa x {g.pressure_safety_factor:g}. The build measures the gasket")


def built_seam_gasket_findings(p: Params, g) -> list[Finding]:
    """``seal.seam_gasket_*``: the built seam gasket (``cad.seal.gasket_numbers``, measured on its solid): its
    compression at the gap's extremes in the sheet's band, its contact stress at the least compression over the
    water's pressure at the design depth times the safety factor, its sealing ring's narrowest strip and the least
    web of sponge a hole leaves. Build-time findings."""
    src = "catalogues/seals.toml [seam_gasket], measured on the built gasket (cad/seal.py)"
    lo, hi = g.compression_range
    span = (f"gap {g.gap_mm:.3f} mm (the limiters' length) +/- the limiter's and both printed faces' tolerances: "
            f"{lo * 100:.1f}-{hi * 100:.1f} % of the sheet")
    return [
        at_least("seal.seam_gasket_least_compression", lo, g.band[0], "the seam gasket's least compression: " + src,
                 detail=span),
        at_most("seal.seam_gasket_most_compression", hi, g.band[1], "the seam gasket's most compression: " + src,
                detail=span),
        at_least("seal.seam_gasket_seating", g.contact_stress_min_kpa, g.safety_factor * g.water_pressure_kpa,
                 "the seam gasket's contact stress at its least compression over the water's pressure at the design "
                 "depth times the safety factor: " + src, unit="kPa",
                 detail=f"{g.water_pressure_kpa:.2f} kPa at {p.environment.design_depth_m:g} m x "
                        f"{g.safety_factor:g}; {g.screws} seam screws each carry about {g.load_per_screw_n:.0f} N"),
        at_least("seal.seam_gasket_strip", g.strip_mm, g.min_width_mm,
                 "the seam gasket's sealing ring, its narrowest strip (the widest disc that travels all round its "
                 "section) against the sheet's least strip: " + src, unit="mm",
                 detail=("" if g.narrow_at_mm is None else
                         f"narrowest at ({g.narrow_at_mm[0]:.1f}, {g.narrow_at_mm[1]:.1f}) mm; ")
                 + f"{g.area_mm2 / 100:.1f} cm^2 of sponge"),
        at_least("seal.seam_gasket_web", g.web_mm, g.min_web_mm,
                 "the least sponge a hole of the seam gasket leaves to an edge: " + src, unit="mm",
                 detail=f"at {g.web_at}"),
    ]


@dataclass(frozen=True)
class Rule:
    rule_id: str
    group: str
    check: Callable[[RuleContext], Finding]


RULES: list[Rule] = [
    Rule("paper.drum_to_cable", "paper", drum_to_cable),
    Rule("paper.pretension_fraction", "paper", pretension_band),
    Rule("paper.holding_torque", "paper", holding_torque),
    Rule("paper.cable_diameter", "paper", cable_diameter),
    Rule("paper.cable_elongation", "paper", cable_elongation),
    Rule("paper.guide_friction", "paper", guide_friction),
    Rule("paper.guides_per_route", "paper", guides_per_route),
    Rule("physics.capstan_no_slip", "physics", capstan_no_slip),
    Rule("physics.no_slack_side", "physics", no_slack_side),
    Rule("physics.cable_strength", "physics", cable_strength),
    Rule("physics.stepper_pullout", "physics", stepper_pullout),
    Rule("physics.microstep_resolution", "physics", microstep_resolution),
    Rule("physics.cable_compliance", "physics", cable_compliance),
    Rule("physics.strouhal", "physics", strouhal_band),
    Rule("physics.fin_root", "physics", fin_root),
    Rule("physics.hinge_bend", "physics", hinge_bend),
    Rule("print.hull_wall", "print", _wall("print.hull_wall", lambda p: p.hull.wall_thickness_mm, "hull wall")),
    Rule("print.fin_min_thickness", "print",
         _wall("print.fin_min_thickness", lambda p: p.caudal_fin.min_thickness_mm, "fin's thinnest section")),
    Rule("print.spool_flange", "print",
         _wall("print.spool_flange", lambda p: p.spool.flange_thickness_mm, "spool flange")),
    Rule("print.bed_fit", "print", bed_fit),
    Rule("print.support", "print", support_area),
    Rule("print.thin_walls", "print", thin_walls),
    Rule("print.bridges", "print", long_bridges),
    Rule("print.bores", "print", supported_bores),
    Rule("heat.dry_compartment", "heat", dry_compartment_temperature),
    Rule("heat.motor_mount", "heat", motor_mount_temperature),
    Rule("power.run_time", "power", run_time),
    Rule("seal.cable_gland", "seal", cable_gland),
    Rule("seal.seam_gasket", "seal", seam_gasket),
    Rule("float.upright", "float", floats_upright),
    Rule("float.net_buoyancy", "float", net_buoyancy),
    Rule("float.level", "float", floats_level),
]


def run_rules(ctx: RuleContext, rules: list[Rule] | None = None) -> list[Finding]:
    """Apply every rule (default: all of ``RULES``) and return their findings in order."""
    out = []
    for rule in rules if rules is not None else RULES:
        f = rule.check(ctx)
        if f.rule_id != rule.rule_id:
            raise RuntimeError(f"rule {rule.rule_id} returned a finding for {f.rule_id}")
        out.append(f)
    return out


# --------------------------------------------------------------------------------------------- entry points
def mass_properties_from_json(mp: dict | None) -> "MassProperties | None":
    """``design_rules.MassProperties`` from a mass_properties.json (exports.massprops.report_to_dict or the
    flat ``swiftfin check --mass-properties`` form); None when absent or incomplete."""
    if not mp:
        return None
    try:
        if "total" in mp:
            t = mp["total"]
            return MassProperties(float(t["mass_kg"]), tuple(t["com_m"]), tuple(t["cob_m"]),
                                  float(t["displaced_volume_m3"]))
        return MassProperties.from_dict({k: mp[k] for k in ("total_mass_kg", "com_m", "cob_m", "displaced_volume_m3")})
    except (KeyError, TypeError, ValueError):
        return None


def design_findings(p: Params, mass_properties_json: dict | None = None,
                    part_bboxes_mm: dict | None = None, calibration: Calibration | None = None,
                    print_records: dict | None = None) -> list:
    """Every rule's finding for a design: what ``swiftfin check`` prints and the report shows. The float rules
    need a build's ``mass_properties.json`` content; the bed-fit rule uses the built parts' print boxes if given."""
    return run_rules(RuleContext(p, mass_properties=mass_properties_from_json(mass_properties_json),
                                 part_bboxes_mm=part_bboxes_mm or None, calibration=calibration,
                                 print_records=print_records or None))
