"""Motor mounts' plates as numbers (body frame, mm): the outline, the guide posts and the screws of every
mount, made from the wall fixings of :mod:`swiftfin.layout.mount_plan` and the guide blocks of
:mod:`swiftfin.layout.guide_plan` (which stand on these plates, so this module sits above both). No CAD
kernel: the loader makes them, so a plate that cannot fit is refused when the design loads, naming the key;
:mod:`swiftfin.cad.mount` makes the solids from the same numbers. Numbers first (:func:`mount_numbers`), solid
second (:func:`swiftfin.cad.mount.mount_solid`), fasteners third (:func:`mount_fasteners`, registered in
``cad/fastening.py``; the registry cuts every screw's hole from the same records).

The plate (``swiftfin.layout.geometry.plate_thickness_mm`` thick) lies on the motor's face, z_face .. z_face + plate,
over the motor's frame along x and out toward the hull's inner wall along y (less the assembly gap and the wall
pads' thickness). It has the hole for the motor's pilot boss (a sliding fit: it centres the motor, so the spool axis
lies exactly on ``motor_placements()``), and the spool above it is free (its hub starts ``spool_dims().hub_bottom_mm``
above the face). Its joints:

* **Motor <-> mount**: the four NEMA screws (``motor.mount_screw_diameter_mm``) from above through the plate into
  the motor's own tapped holes (seat ``"tapped"``, ``motor.mount_hole_depth_mm`` deep): the shortest catalogue
  length that reaches 1 d into the thread, with a spot face raised under each head (whole layers) where it would
  otherwise reach the thread's end (:func:`swiftfin.layout.mount_plan.motor_screw_fit`: M3 x 8 over a 3.6 mm plate
  and a 0.2 mm spot face, 4.2 mm into a 4.5 mm thread). They are driven from above before the head's upper halves
  go on (:func:`swiftfin.layout.hull_plan.head_lid_labels`; a splice tab of the front piece reaches over the rear
  piece's motors, so the whole lid, not only the piece at the screw's station, is left off).
* **Mount <-> hull wall**: two screws on each side, spread along x about the motor's station, from outside through
  a pad of the upper hull half into heat-set inserts in bosses of the mount (:mod:`swiftfin.layout.mount_plan`
  argues the arrangement and checks the loads: the cables' pull at the cable plane makes a pitch moment that two
  screws on one line could not hold). A boss is a cylinder along the screw's axis over a block down to the print
  face, so the insert's pocket has the insert maker's wall all round it, the print face included.
* **Guides <-> mount**: posts (:func:`swiftfin.layout.guide_plan.post_radius_mm` across: the insert boss rule)
  under the guide blocks' screw points (:func:`swiftfin.layout.guide_plan.guide_blocks`; motor_mount_1 reaches aft
  under the bay guide), inserts in their tops, screws from the guides' tops
  (:func:`swiftfin.layout.guide_screws.guide_fasteners`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from swiftfin.catalogues.fasteners import fastener
from swiftfin.core.errors import UserError
from swiftfin.core.schema import Params
from swiftfin.layout.fastening import Fastener
from swiftfin.layout.geometry import interior_half_width_at_height_mm, motor_placements, spool_dims
from swiftfin.layout.guide_plan import bare_guide_blocks, post_radius_mm
from swiftfin.layout.mount_plan import WallFixing, assembly_gap_mm, motor_screw_fit, wall_fixings, wall_screw


BOSS_BELOW_FACTOR = 3.0
"""Length of the boss under the plate at guide screws outside the motor's frame / guide screw diameter [-], for a
guide seated on the plate itself (not the default layout). Engineering default (room for the insert's pocket)."""
PLATE_OUTLINE_SAMPLES = 9
"""Stations along x at which the plate's edge follows the hull's inner wall (a polygon through them lies
inside the wall, whose half-width is concave in x)."""


@dataclass(frozen=True)
class Post:
    x_mm: float
    y_mm: float
    z_bottom_mm: float        # bottom of the boss below the plate, or the plate's bottom
    z_top_mm: float           # the guide block's underside
    radius_mm: float
    guide: str


@dataclass(frozen=True)
class MountNumbers:
    joint: int                                 # 1-based
    axis_xy_mm: tuple[float, float]
    z_bottom_mm: float                         # motor face
    z_top_mm: float
    outline_xy_mm: tuple[tuple[float, float], ...]   # plate outline (counter-clockwise)
    motor_holes_xy_mm: tuple[tuple[float, float], ...]
    spot_face_mm: float                        # raised seat under each motor screw's head
    spot_face_radius_mm: float
    pilot_hole_diameter_mm: float
    fixings: tuple[WallFixing, ...]
    posts: tuple[Post, ...]
    bed_face: str             # "bottom" (the motor face side) or "top": the flat face to print on

    @property
    def print_rotation(self) -> tuple[float, float, float]:
        return (0.0, 0.0, 0.0) if self.bed_face == "bottom" else (180.0, 0.0, 0.0)


def mount_numbers(p: Params) -> tuple[MountNumbers, ...]:
    """The numbers of every mount (index j-1 for motor j). Raises UserError where a mount cannot fit."""
    d = spool_dims(p)
    m, pr = p.motor, p.print
    c = assembly_gap_mm(p)
    F = m.frame_size_mm
    wall = pr.perimeters * pr.line_width_mm
    fixings = wall_fixings(p)
    fit = motor_screw_fit(p)
    blocks = bare_guide_blocks(p)
    r_post = post_radius_mm(p)
    out = []
    for mp in motor_placements(p):
        label = f"motor_mount_{mp.joint + 1}"
        z0, z1 = mp.z_face_mm, mp.z_face_mm + d.plate_mm
        # posts for the guides this mount carries
        posts = []
        x_back = mp.x_mm - F / 2
        for b in blocks:
            if b.mount != label:
                continue
            for x, y in b.screw_points_mm:
                # a guide sitting on the plate gets bosses under the plate for the insert, where the motor
                # leaves room for them; a guide on posts has room in its post
                outside_frame = x < mp.x_mm - F / 2 - r_post or x > mp.x_mm + F / 2 + r_post
                on_plate = b.seat_mm <= z1 + 1e-9
                zb = z0 - BOSS_BELOW_FACTOR * b.screw_diameter_mm if outside_frame and on_plate else z0
                posts.append(Post(x, y, zb, b.seat_mm, r_post, b.label))
                x_back = min(x_back, x - r_post - wall)
        fx = tuple(f for f in fixings if f.mount == label)
        pad = max(f.pad_mm for f in fx)
        x_front = mp.x_mm + F / 2
        xs = np.linspace(x_back, x_front, PLATE_OUTLINE_SAMPLES)
        hw = [min(interior_half_width_at_height_mm(p, -x, z0), interior_half_width_at_height_mm(p, -x, z1)) - c - pad
              for x in xs]
        if min(hw) < F / 2:
            raise UserError(f"{label}: the hull is only {min(hw) + c + pad:.1f} mm wide (half) at the mount plate, "
                            f"narrower than the motor frame ({F / 2:g} mm) and the wall screws' pads ({pad:.1f} mm): a "
                            f"fuller hull (body.naca_thickness_fraction, body.height_to_width) or a smaller "
                            f"motor.frame_size_mm")
        outline = [(float(x), -float(h)) for x, h in zip(xs, hw)] + \
                  [(float(x), float(h)) for x, h in zip(xs[::-1], hw[::-1])]
        hs = m.hole_spacing_mm / 2
        holes = tuple((mp.x_mm + sx * hs, sy * hs) for sx in (1, -1) for sy in (1, -1))
        up = any(q.z_top_mm > z1 + 1e-9 for q in posts)
        down = any(q.z_bottom_mm < z0 - 1e-9 for q in posts)
        if up and down:
            raise UserError(f"{label}: the guide posts would stand both above and below the plate (no flat face "
                            f"to print it on); this layout of guides is not supported")
        if down:
            raise UserError(f"{label}: the guide posts stand below the plate, so it would print upside down and its "
                            f"wall-screw bosses (which stand on the plate's bottom face) would hang; this layout of "
                            f"guides is not supported")
        out.append(MountNumbers(mp.joint + 1, (mp.x_mm, 0.0), z0, z1, tuple(outline), holes, fit.spot_face_mm,
                                fit.spot_face_radius_mm, m.pilot_diameter_mm + pr.clearance_sliding_mm, fx,
                                tuple(posts), "bottom"))
    return tuple(out)


def mount_fasteners(p: Params) -> tuple[Fastener, ...]:
    """The wall screws (hull's upper half -> insert in the mount's boss) and the motor's face screws (mount plate
    -> the motor's tapped holes) of every mount."""
    from swiftfin.layout.hull_plan import head_lid_labels, hull_pieces, part_label
    pieces = hull_pieces(p)
    lid = head_lid_labels(p)      # the head's upper halves go on after the motors are screwed to their mounts
    blocks = bare_guide_blocks(p)
    s = wall_screw(p)
    fit = motor_screw_fit(p)
    key_r = fastener(fit.size).key_reach_diameter_mm / 2

    def piece_at(x: float):
        return next(q for q in pieces if q.s_start_mm <= -x <= q.s_end_mm)

    out = []
    for n in mount_numbers(p):
        label = f"motor_mount_{n.joint}"
        for f in n.fixings:
            half = "upper" if f.point_mm[2] > 0 else "lower"
            out.append(Fastener(f.label, s.name, "cap_screw", "insert", f.head_mm, f.axis, f.length_mm, f.grip_mm,
                                part_label(p, piece_at(f.point_mm[0]), half), label,
                                f"holds {label} to the hull wall (from outside)", 0, recess_mm=f.recess_mm))
        for k, (x, y) in enumerate(n.motor_holes_xy_mm):
            over = tuple(b.label for b in blocks
                         if b.x_mm[0] - key_r < x < b.x_mm[1] + key_r and b.y_mm[0] - key_r < y < b.y_mm[1] + key_r)
            out.append(Fastener(f"{label}_motor_{k + 1}", fit.size, "cap_screw", "tapped",
                                (x, y, n.z_top_mm + fit.spot_face_mm), (0.0, 0.0, -1.0), fit.length_mm, fit.grip_mm,
                                label, f"motor_{n.joint}", f"holds motor_{n.joint}'s face on {label}", 0,
                                installed_after=over + lid,
                                meta={"hole_depth_mm": fit.hole_depth_mm}))
    return tuple(out)
