"""The motor mounts' wall fixings as numbers: where each screw goes through the hull wall, the pad the hull grows
under its head, the boss of the mount its insert sits in, and the loads the screws carry. No CAD kernel: the hull
(:mod:`swiftfin.cad.hull`, pads), the mounts (:mod:`swiftfin.cad.mount`, bosses and fastener records) and
:func:`mount_fixings_mm` read the same numbers.

Arrangement (body frame at rest, mm). Per motor mount ``FIXINGS_PER_SIDE`` screws on each side (+y, -y), at the
motor's station +/- ``FIXING_SPREAD_FRACTION x frame``, each along the inner wall's outward normal n at its point
P: a cap screw ``hull.screw_diameter_mm`` driven from outside, its head sunk in a counterbore of a pad (a local
inward thickening of the hull wall, ``pad_mm`` thick, in the upper half: the fixings stand above the z = 0 split),
its thread in a brass heat-set insert in a boss of the mount that stands the assembly gap off the pad. The boss's
axis is as low as the insert's wall to the mount's print face (its bottom, on the bed) allows.

Loads (:func:`mount_wall_loads`). The cables pull each mount's assembly (motor, spool, the guides it carries) along
their routes: at every point of a route the assembly holds (the spool's tangent point, an exit or bay bend) the
cable pulls with ``T (u_out - u_in)``. The design tension of a side is its pretension plus half the largest
difference the motor can hold, ``T = cable.pretension_n + motor.holding_torque_nm / (2 r_spool)`` (45 + 21 = 66 N
by default: the pull-pull pair's sum stays 2 T0 while both sides are taut, and the motor slips beyond its holding
torque, so this bounds what the working loads of :mod:`swiftfin.layout.loads` can put on a mount; that module's
peak joint tensions, ~600 N at joint 1, need a torque the motor cannot hold). The mount's screws share the
resultant and the moment about their centroid as a rigid bolt group of equal stiffness (force ``F/n + w x r_i``).
The cables pull at the cable plane, ~15 mm above the screws, so the pitch moment dominates: it is why the screws
of a side are spread along x (two screws on one line through the motor's station, as before, made a pivot).
Each screw's shear is checked against the bearing of its shank on the pad's floor under the head and of its insert
in the boss, its axial load against the insert's pull-out and the head's pull-through, with the sustained-load
allowables of ``catalogues/printed_strength.toml``; the pad's floor under the head is as thick as the worst screw
needs (at least ``print.perimeters`` lines).

Load path. Mount -> screws -> the head's upper hull half -> its rear bulkhead -> joint 1's clevis and pin -> the
link the cables pull forward: the loop closes in compression through printed shells and screws (no glued seam). A
chassis tying the mounts to the rear bulkhead was weighed and not built: it must pass the bay guide and the
descending cables in the 30 mm before the bulkhead, and the shell carries the loop's compression at well under
1 MPa; the weak links were local (a 2 mm wall in bearing, two screws on one pivot line, pilots breaking out of the
print face), which this arrangement removes. The mounts ahead of the head's station splice load that splice in
shear; :func:`mount_wall_loads` gives the forces for the hull's owner to check.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.fasteners import ScrewSize, fastener
from swiftfin.catalogues.printed_strength import printed_strength
from swiftfin.core.errors import BuildError
from swiftfin.core.schema import Params
from swiftfin.layout import geometry as L
from swiftfin.layout.fastening import TAPPED_ENGAGEMENT_MIN_D, TAPPED_TIP_MARGIN_MM

FIXINGS_PER_SIDE = 2
"""Wall screws on each side of a mount [-]: two, spread along x, hold the cables' pitch moment."""
FIXING_SPREAD_FRACTION = 1.0 / 6.0
"""Offset of the wall screws from the motor's station / motor frame size [-] (7.05 mm for NEMA 17). As far apart
as the hull's station splice lets: ``swiftfin.layout.hull_plan._split_stations`` keeps a cut 15 mm from every
fixing, and two motors 45.3 mm apart leave 45.3 - 2 x 7.05 = 31.2 mm between their fixings. Engineering default."""
SKIN_SAG_MARGIN_MM = 0.2
"""The head's counterbore is this much deeper than the catalogue's: the skin curves away over its rim (< 0.1 mm
over a 4.3 mm counterbore on a 60 mm section radius). Engineering default."""
BOSS_MARGIN_MM = 0.2
"""Wall kept beyond each rule round an insert (the loft departs from the exact ellipse by < 0.05 mm)."""
LOAD_FLOOR_STEP_MM = 0.05
"""The pad's floor under the head is rounded up to this [mm]."""


def assembly_gap_mm(p: Params) -> float:
    """The gap to leave between parts that must not touch: the assembly clearance plus what tessellation
    can take off it (each of the two meshes may lie up to ``export.mesh_tolerance_mm`` off its surface),
    since the assembly check measures on the meshes."""
    return p.print.clearance_assembly_mm + 2 * p.export.mesh_tolerance_mm


def wall_screw(p: Params) -> ScrewSize:
    return fastener(p.hull.screw_diameter_mm)


def design_tension_n(p: Params) -> float:
    """Design tension of one cable side at the mount [N]: pretension plus half what the motor can hold."""
    return p.cable.pretension_n + p.motor.holding_torque_nm / (2 * p.spool.drum_diameter_mm / 2 * 1e-3)


@dataclass(frozen=True)
class WallFixing:
    """One wall screw of a motor mount (body frame at rest, mm)."""
    label: str
    mount: str                 # motor_mount_<j>
    joint: int                 # 1-based
    side: int                  # +1: +y side
    fore: int                  # +1: ahead of the motor's station
    point_mm: tuple[float, float, float]   # on the hull's inner wall
    normal: tuple[float, float, float]     # outward unit normal there (the screw's axis is -normal)
    skin_mm: float             # the wall's thickness along the normal
    pad_mm: float              # the pad's inward thickness beyond the inner wall
    pad_radius_mm: float
    floor_mm: float            # pad under the head (the shank's bearing length in the hull)
    recess_mm: float           # head's bearing face below the skin
    face_mm: tuple[float, float, float]    # centre of the mount boss's end face (the insert's face)
    boss_radius_mm: float
    boss_length_mm: float      # along -normal from the face
    length_mm: float           # catalogue length
    grip_mm: float

    @property
    def axis(self) -> tuple[float, float, float]:
        return tuple(-float(v) for v in self.normal)

    @property
    def head_mm(self) -> tuple[float, float, float]:
        return tuple(float(q + (self.skin_mm - self.recess_mm) * n) for q, n in zip(self.point_mm, self.normal))


def _outer_distance(p: Params, s_mm: float, point, normal) -> float:
    """Distance from ``point`` (inside) along ``normal`` to the hull's outer ellipse at station s: the positive
    root of ((y + u n_y) / a)^2 + ((z + u n_z) / b)^2 = 1, at most ``4 wall + 5`` mm (the reach of the old
    bisection it replaces)."""
    a, b = float(L.naca_half_width_mm(p, s_mm)), float(L.half_height_mm(p, s_mm))
    y, z, ny, nz = float(point[1]), float(point[2]), float(normal[1]), float(normal[2])
    A = (ny / a) ** 2 + (nz / b) ** 2
    B = 2.0 * (y * ny / a**2 + z * nz / b**2)
    C = (y / a) ** 2 + (z / b) ** 2 - 1.0
    u = (-B + math.sqrt(max(0.0, B * B - 4.0 * A * C))) / (2.0 * A)
    return min(max(u, 0.0), 4 * p.hull.wall_thickness_mm + 5.0)


def _inner_point(p: Params, s_mm: float, z_mm: float, side: int):
    """The inner wall's point at station s, height z on ``side``, and its outward unit normal."""
    a = float(L.naca_half_width_mm(p, s_mm)) - p.hull.wall_thickness_mm
    b = float(L.half_height_mm(p, s_mm)) - p.hull.wall_thickness_mm
    y = L.interior_half_width_at_height_mm(p, s_mm, z_mm)
    ny, nz = side * y / a**2, z_mm / b**2
    k = math.hypot(ny, nz)
    return np.array([-s_mm, side * y, z_mm]), np.array([0.0, ny / k, nz / k])


def _place(p: Params, floor_mm: float) -> tuple[WallFixing, ...]:
    s = wall_screw(p)
    lw = p.print.line_width_mm
    g = assembly_gap_mm(p)
    recess = s.counterbore_depth_mm + SKIN_SAG_MARGIN_MM
    r_boss = s.insert_boss_od_mm(lw) / 2 + BOSS_MARGIN_MM
    wall_need = max(2 * lw, s.insert_wall_min_mm) + BOSS_MARGIN_MM
    r_pad = max(s.counterbore_diameter_mm / 2 + p.print.perimeters * lw, r_boss)
    dx = FIXING_SPREAD_FRACTION * p.motor.frame_size_mm
    grip = floor_mm + g
    length = s.length_for(grip + s.insert_length_mm)
    if length is None:
        raise BuildError(f"hull.screw_diameter_mm = {p.hull.screw_diameter_mm:g}: no {s.name} screw of "
                         f"{grip + s.insert_length_mm:.1f} mm for the motor mounts' wall fixings (the worst screw's "
                         f"load needs a {floor_mm:.2f} mm floor under its head, for a design tension of "
                         f"{design_tension_n(p):.0f} N a side): use a larger screw, or a smaller "
                         f"motor.holding_torque_nm or cable.pretension_n, or a larger spool.drum_diameter_mm")
    past = length - grip
    depth = max(s.insert_pocket_depth_mm, past + 0.5)        # the pocket, or the screw's tip beyond it
    out = []
    for mp in L.motor_placements(p):
        z0 = mp.z_face_mm
        label = f"motor_mount_{mp.joint + 1}"
        for side in (1, -1):
            for fore in (1, -1):
                st = mp.s_mm - fore * dx
                z = z0 + 4.0
                for _ in range(8):   # the boss's face as low as the pocket's wall to the print face allows
                    P, n = _inner_point(p, st, z, side)
                    pad = recess + floor_mm - _outer_distance(p, st, P, n)
                    nz = float(n[2])
                    face_z = z0 + wall_need + s.insert_hole_mm / 2 * math.sqrt(1 - nz * nz) + depth * nz
                    z = face_z + (pad + g) * nz
                P, n = _inner_point(p, st, z, side)
                t_n = _outer_distance(p, st, P, n)
                pad = recess + floor_mm - t_n
                face = P - (pad + g) * n
                tag = f"{'p' if side > 0 else 'm'}y_{'fore' if fore > 0 else 'aft'}"
                out.append(WallFixing(f"{label}_wall_{tag}", label, mp.joint + 1, side, fore,
                                      tuple(float(v) for v in P), tuple(float(v) for v in n), t_n, pad, r_pad,
                                      floor_mm, recess, tuple(float(v) for v in face), r_boss, depth + wall_need,
                                      length, grip))
    return tuple(out)


@dataclass(frozen=True)
class MountLoads:
    """The cables' pull on one mount's assembly and how its wall screws share it (N, N m)."""
    mount: str
    force_n: tuple[float, float, float]             # resultant the cables put on the assembly
    moment_nm: tuple[float, float, float]           # about the screws' centroid
    shear_n: tuple[float, ...]                      # per screw, in the order of ``fixings``
    axial_n: tuple[float, ...]                      # per screw, + pulls the boss off the screw (outward)
    fixings: tuple[str, ...]
    hull_shear_capacity_n: float      # the shank's bearing on the pad's floor under the head
    hull_axial_capacity_n: float      # the head pulling through that floor
    boss_shear_capacity_n: float      # the insert's knurl bearing in the mount's boss
    boss_axial_capacity_n: float      # the insert pulling out of the boss

    def usage_of(self, where: str) -> float:
        """Worst screw's shear / capacity + |axial| / capacity in the hull's pad or the mount's boss (linear
        interaction; <= 1 holds)."""
        cs, ca = ((self.hull_shear_capacity_n, self.hull_axial_capacity_n) if where == "hull" else
                  (self.boss_shear_capacity_n, self.boss_axial_capacity_n))
        return max(sh / cs + abs(ax) / ca for sh, ax in zip(self.shear_n, self.axial_n))

    @property
    def usage(self) -> float:
        return max(self.usage_of("hull"), self.usage_of("boss"))

    @property
    def worst_shear_n(self) -> float:
        return max(self.shear_n)


def cable_forces(p: Params) -> dict[str, list[tuple[np.ndarray, np.ndarray]]]:
    """Mount label -> [(point, force)]: where the design tension of every route pulls each mount's assembly."""
    T = design_tension_n(p)
    out: dict[str, list] = {f"motor_mount_{mp.joint + 1}": [] for mp in L.motor_placements(p)}
    for r in L.cable_routes(p):
        pts = [np.asarray(q, dtype=float) for q in r.points_mm]
        holders = [f"motor_mount_{r.joint + 1}"]
        for b in r.bends:
            holders.append(f"motor_mount_{r.joint + 1}" if b.kind == "exit" else
                           "motor_mount_1" if b.kind in L.BAY_GUIDE_BENDS else None)
        for k, who in enumerate(holders):
            if who is None:
                continue
            u_out = (pts[k + 1] - pts[k]) / np.linalg.norm(pts[k + 1] - pts[k])
            u_in = np.zeros(3) if k == 0 else (pts[k] - pts[k - 1]) / np.linalg.norm(pts[k] - pts[k - 1])
            out[who].append((pts[k], T * (u_out - u_in)))
    return out


def _loads(p: Params, fixings: tuple[WallFixing, ...]) -> tuple[MountLoads, ...]:
    s = wall_screw(p)
    ps = printed_strength(p.print.material)
    sig, tau = ps.bearing_allowable_mpa, ps.shear_allowable_mpa
    out = []
    for label, fl in cable_forces(p).items():
        fx = [f for f in fixings if f.mount == label]
        r = np.array([f.point_mm for f in fx])
        c = r.mean(axis=0)
        F = sum(f for _, f in fl)
        M = sum(np.cross(q - c, f) for q, f in fl) * 1e-3     # N m
        rho = (r - c) * 1e-3
        J = sum(float(v @ v) * np.eye(3) - np.outer(v, v) for v in rho)
        w = np.linalg.solve(J, M)
        shear, axial = [], []
        for f, v in zip(fx, rho):
            react = F / len(fx) + np.cross(w, v)          # what the screw takes from the assembly
            n = np.asarray(f.normal)
            ax = float(react @ n)
            axial.append(ax)
            shear.append(float(np.linalg.norm(react - ax * n)))
        floor = fx[0].floor_mm
        out.append(MountLoads(label, tuple(float(v) for v in F), tuple(float(v) for v in M), tuple(shear),
                              tuple(axial), tuple(f.label for f in fx),
                              sig * s.nominal_diameter_mm * floor, tau * math.pi * s.head_diameter_mm * floor,
                              sig * s.insert_outer_diameter_mm * s.insert_length_mm,
                              tau * math.pi * s.insert_outer_diameter_mm * s.insert_length_mm))
    return tuple(out)


def _floor_needed(p: Params, loads: tuple[MountLoads, ...]) -> float:
    """The pad's floor under the head the worst screw needs: shear / (sigma d) + |axial| / (tau pi d_head)."""
    s = wall_screw(p)
    ps = printed_strength(p.print.material)
    need = max(sh / (ps.bearing_allowable_mpa * s.nominal_diameter_mm)
               + abs(ax) / (ps.shear_allowable_mpa * math.pi * s.head_diameter_mm)
               for ml in loads for sh, ax in zip(ml.shear_n, ml.axial_n))
    least = p.print.perimeters * p.print.line_width_mm
    return max(least, math.ceil(need / LOAD_FLOOR_STEP_MM - 1e-9) * LOAD_FLOOR_STEP_MM)


@functools.lru_cache(maxsize=64)
def wall_fixings(p: Params) -> tuple[WallFixing, ...]:
    """Every mount's wall screws, the pad's floor sized for the worst one's load. Memoised on the params (the
    hull's cuts, the mounts and the loader read it; see :func:`swiftfin.layout.hull_plan.hull_pieces`)."""
    floor = p.print.perimeters * p.print.line_width_mm
    for _ in range(6):
        fx = _place(p, floor)
        need = _floor_needed(p, _loads(p, fx))
        if need <= floor + 1e-9:
            return fx
        floor = need
    return _place(p, floor)


def mount_wall_loads(p: Params) -> tuple[MountLoads, ...]:
    """The loads of every mount's wall screws (see the module docstring)."""
    return _loads(p, wall_fixings(p))


# ----------------------------------------------------------------------------------------------- motor screws
@dataclass(frozen=True)
class MotorScrewFit:
    """The NEMA face screws: through the mount's plate (and a spot face raised on it) into the motor's own tapped
    holes, reaching at least ``TAPPED_ENGAGEMENT_MIN_D`` d and stopping short of the thread's end (mm)."""
    size: str
    length_mm: float
    grip_mm: float             # plate + spot face
    spot_face_mm: float        # raised seat under each head on the plate's top (0: the head on the plate)
    spot_face_radius_mm: float
    hole_depth_mm: float
    head_height_mm: float

    @property
    def engagement_mm(self) -> float:
        return self.length_mm - self.grip_mm


def motor_screw_fit(p: Params) -> MotorScrewFit:
    """The shortest catalogue screw that reaches 1 d into the motor's thread; where it would reach past the thread's
    end less the margin, a spot face (whole layers) under its head takes up the difference."""
    s = fastener(p.motor.mount_screw_diameter_mm)
    plate = L.plate_thickness_mm(p)
    depth = p.motor.mount_hole_depth_mm
    least, most = TAPPED_ENGAGEMENT_MIN_D * s.nominal_diameter_mm, depth - TAPPED_TIP_MARGIN_MM
    length = s.length_for(plate + least)
    if length is None or least > most:
        raise BuildError(f"no {s.name} screw reaches {least:g} mm into the motor's {depth:g} mm deep thread through "
                         f"the {plate:g} mm mount plate (motor.mount_hole_depth_mm)")
    layer = p.print.layer_height_mm
    raise_mm = max(0.0, math.ceil((length - plate - most) / layer - 1e-9) * layer)
    fit = MotorScrewFit(s.name, length, plate + raise_mm, raise_mm, s.head_diameter_mm / 2 + p.print.line_width_mm,
                        depth, s.head_height_mm)
    if fit.engagement_mm < least - 1e-9:
        raise BuildError(f"{s.name} x {length:g} mm: the spot face leaves {fit.engagement_mm:.2f} mm in the motor's "
                         f"thread, less than {least:g} mm (motor.mount_hole_depth_mm = {depth:g})")
    return fit


@dataclass(frozen=True)
class Fixing:
    """A screw through the hull wall into an internal part: point on the hull's inner surface and the
    outward unit normal there (body frame, mm). The hull drills a clearance hole; the part has a tab there."""
    point_mm: tuple[float, float, float]
    normal: tuple[float, float, float]
    part: str


def mount_fixings_mm(p: Params) -> tuple[Fixing, ...]:
    """The motor mounts' wall screws: two on each side of every mount, spread along x about the motor's station,
    as high as the insert boss on the mount's print face needs (:func:`wall_fixings`
    has their pads, bosses, screws and loads)."""
    return tuple(Fixing(f.point_mm, f.normal, f.mount) for f in wall_fixings(p))
