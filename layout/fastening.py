"""Every screw and pin of the robot as numbers: where it goes, which way it points, what it joins, its length.

A part family's plan (``layout/hull_plan.py``, ``layout/joints.py``, ...) places its fasteners as
:class:`Fastener` records through the catalogue (``swiftfin.catalogues.fasteners``); the part modules cut the
holes from the same records (``swiftfin.cad.fastening``), the assembly checks them on the solids
(``swiftfin.exports.fastener_check``) and the bill of materials counts them. Nothing here imports the CAD kernel.

Conventions (body frame at rest, mm):

* ``head_mm`` is the centre of the head's bearing face (where the head meets the part it clamps) for a cap
  screw, and the entry point of the hole for a set screw or a pin; ``axis`` is the unit vector from there into
  the thread (the direction the screw advances when it is driven).
* ``grip_mm``: from ``head_mm`` along the axis to where the thread starts holding: the face of the insert, the
  bearing face of the nut, or the start of a self-tapped pilot. A set screw's grip is the material it passes
  before its thread (0 when it starts in its insert or nut).
* ``seat``: what the thread is cut in: ``"insert"`` (brass heat-set insert in ``thread_part``), ``"nut"`` (hex
  nut in a trap in ``thread_part``), ``"self_tap"`` (a thread-forming screw in a printed pilot; never a set
  screw), ``"press"`` / ``"slip"`` (a dowel pressed into, or turning in, a reamed bore).
* ``installed_after``: labels of parts that go on after this fastener is driven; the key's path from the head
  outward may cross where they will be (a link screwed on from inside a segment whose upper half is still off).
* ``recess_mm``: how far the head (or the nut, for ``seat = "nut"`` at the far end) sinks below the part's
  surface in a counterbore; 0 for a head that sits on the surface.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from swiftfin.catalogues.fasteners import ScrewSize, fastener

KINDS = ("cap_screw", "set_screw", "dowel")
SEATS = ("insert", "nut", "self_tap", "press", "slip", "tapped")
"""``"tapped"``: the thread part is bought with its own tapped hole (a motor's face): ``meta["hole_depth_mm"]`` is
the depth of its thread; the screw reaches at least 1 d into it (a steel screw in an aluminium or steel thread:
ISO 898-2 nuts are 0.8 d high) and stops ``TAPPED_TIP_MARGIN_MM`` short of its end."""
WALL_PROBE_INSET_MM = 0.05
"""The fastener check's wall rays start this far outside a hole's nominal radius (inside the wall, past the
tessellation of the hole; ``cad/fastener_check.py``): a wall it reads is the wall less this. Parts that keep the
check's wall round a hole add it."""
TAPPED_ENGAGEMENT_MIN_D = 1.0
TAPPED_TIP_MARGIN_MM = 0.3
"""A screw's tip stops this far short of the end of a blind tapped thread (the last pitch of a tapped thread is
incomplete) [mm]. Engineering default."""


PILOT_PAST_TIP_MM = 1.0
"""A self-tap pilot runs this far past the screw's tip (room for the chips and the tip's taper)."""


@dataclass(frozen=True)
class Fastener:
    """One screw, set screw or pin, placed (body frame at rest, mm)."""
    label: str                         # unique over the robot: "hull_head_seam_3"
    size: str                          # catalogue name: "M2", or the pin diameter "3" for a dowel
    kind: str                          # one of KINDS
    seat: str                          # one of SEATS
    head_mm: tuple[float, float, float]
    axis: tuple[float, float, float]   # unit, from the head into the thread
    length_mm: float                   # the catalogue length
    grip_mm: float                     # head face -> start of the thread's hold
    head_part: str | None              # part under the head (None: set screw, pin)
    thread_part: str                   # part holding the thread (insert, nut, pilot, press fit)
    joins: str                         # what it is for, in words (the BOM's "where")
    link: int = 0                      # kinematic link of the parts it joins
    recess_mm: float = 0.0
    recess_open_toward: tuple[float, float, float] | None = None   # unit, normal to the axis: the counterbore
    # opens to the part's surface that way (a slot), where it would otherwise leave a knife edge on a steep skin
    pilot_past_tip_mm: float = PILOT_PAST_TIP_MM     # a self-tap pilot runs this far past the tip (or through)
    installed_after: tuple[str, ...] = ()   # parts put on after it is driven: its key may pass where they go
    meta: dict = field(default_factory=dict, compare=False, hash=False)

    @property
    def parts(self) -> frozenset[str]:
        """The parts it joins: under its head, holding its thread, and (a dowel) the part it slips in."""
        return frozenset({self.head_part, self.thread_part, self.meta.get("slip_part")} - {None})

    @property
    def screw(self) -> ScrewSize:
        return fastener(self.size)

    @property
    def tip_mm(self) -> tuple[float, float, float]:
        return tuple(float(h + self.length_mm * a) for h, a in zip(self.head_mm, self.axis))

    def point_mm(self, distance_mm: float) -> np.ndarray:
        """The point ``distance_mm`` along the axis from the head."""
        return np.asarray(self.head_mm, dtype=float) + distance_mm * np.asarray(self.axis, dtype=float)

    @property
    def engagement_mm(self) -> float:
        """Length of thread that holds: in an insert at most the insert's length, in a nut the nut's height."""
        past = self.length_mm - self.grip_mm
        if self.seat == "insert":
            return min(past, self.screw.insert_length_mm)
        if self.seat == "nut":
            return min(past, self.screw.nut_height_mm)
        return past

    @property
    def mass_kg(self) -> float:
        """The bought metal of this record: the screw (or pin) and its insert or nut [kg]."""
        if self.kind == "dowel":
            from swiftfin.catalogues.fasteners import dowel
            return dowel(float(self.size)).mass_kg(self.length_mm)
        s = self.screw
        m = s.screw_mass_kg(self.length_mm, set_screw=self.kind == "set_screw")
        if self.seat == "insert":
            m += s.insert_mass_kg
        elif self.seat == "nut":
            m += s.nut_mass_kg
        return m

    @property
    def centre_mm(self) -> tuple[float, float, float]:
        """Where its mass sits: the middle of its length."""
        return tuple(float(c) for c in self.point_mm(self.length_mm / 2))

    def problems(self) -> list[str]:
        """What is wrong with the numbers alone (the solids are checked elsewhere)."""
        out = []
        if self.kind not in KINDS:
            out.append(f"{self.label}: kind {self.kind!r} is not one of {KINDS}")
        if self.seat not in SEATS:
            out.append(f"{self.label}: seat {self.seat!r} is not one of {SEATS}")
        if abs(math.hypot(*self.axis) - 1.0) > 1e-6:
            out.append(f"{self.label}: axis {self.axis} is not a unit vector")
        if self.kind == "set_screw" and self.seat == "self_tap":
            out.append(f"{self.label}: a set screw cannot cut its own thread (seat it in an insert or a nut)")
        if self.kind != "dowel":
            s = self.screw
            offer = s.set_screw_lengths_mm if self.kind == "set_screw" else s.lengths_mm
            if not any(abs(self.length_mm - x) < 1e-9 for x in offer):
                out.append(f"{self.label}: {self.size} x {self.length_mm:g} mm is not a catalogue length "
                           f"({', '.join(f'{x:g}' for x in offer)})")
            if self.seat == "nut":
                if self.length_mm - self.grip_mm < s.nut_height_mm + s.pitch_mm - 1e-9:
                    out.append(f"{self.label}: {self.size} x {self.length_mm:g} mm reaches "
                               f"{self.length_mm - self.grip_mm:.2f} mm past the nut's face; the nut needs "
                               f"{s.nut_height_mm + s.pitch_mm:.2f} mm (its height and one pitch)")
            elif self.seat == "tapped":
                depth = float(self.meta.get("hole_depth_mm", 0.0))
                if not TAPPED_ENGAGEMENT_MIN_D * s.nominal_diameter_mm - 1e-9 <= self.engagement_mm \
                        <= depth - TAPPED_TIP_MARGIN_MM + 1e-9:
                    out.append(f"{self.label}: {self.engagement_mm:.2f} mm into a {depth:g} mm deep tapped thread "
                               f"(needs {TAPPED_ENGAGEMENT_MIN_D * s.nominal_diameter_mm:.2f} mm, at most "
                               f"{depth - TAPPED_TIP_MARGIN_MM:.2f} mm)")
            elif self.engagement_mm < s.engagement_min_mm - 1e-9:
                out.append(f"{self.label}: thread engagement {self.engagement_mm:.2f} mm < 1.5 x {self.size} = "
                           f"{s.engagement_min_mm:.2f} mm")
        return out


def screw_length(size: ScrewSize, grip_mm: float, seat: str, room_mm: float | None = None,
                 set_screw: bool = False) -> float | None:
    """The catalogue length for a screw clamping ``grip_mm`` into ``seat``: the shortest that gives full
    engagement (the insert's length, the nut and one pitch, or 1.5 d of self-tapped thread), and no longer
    than ``room_mm`` (the depth the thread part offers past the head face) when that is given; None if none
    fits."""
    need = {"insert": size.insert_length_mm, "nut": size.nut_height_mm + size.pitch_mm}.get(
        seat, size.engagement_min_mm)
    length = size.length_for(grip_mm + max(need, size.engagement_min_mm if seat != "nut" else need),
                             set_screw=set_screw)
    if length is None or (room_mm is not None and length > room_mm + 1e-9):
        return None
    return length


def check_unique(fasteners) -> list[str]:
    seen, out = set(), []
    for f in fasteners:
        if f.label in seen:
            out.append(f"fastener label {f.label!r} is used twice")
        seen.add(f.label)
    return out


def bores_in_part(f: Fastener, label: str) -> list[tuple[str, float]]:
    """The round holes fastener ``f`` asks of part ``label``, as ``(what, diameter_mm)``, the same ones
    ``cad/fastening.py`` cuts: under the head the clearance hole (and the counterbore of a recessed head); in the
    thread part the insert's hole (and the clearance hole on past it for a screw longer than its pocket), the self-tap pilot, or the clearance hole and the nut's hex trap (its circle
    across the corners); a dowel's bore (printed under size) in the part it is pressed into and the one it slips in."""
    out: list[tuple[str, float]] = []
    if f.kind == "dowel":
        if label in (f.thread_part, f.meta.get("slip_part")):
            from swiftfin.catalogues.fasteners import dowel
            pin = dowel(float(f.size))
            out.append(("pin bore", pin.diameter_mm - pin.ream_stock_mm))
        return out
    s = f.screw
    if f.head_part == label:
        out.append(("clearance hole", s.clearance_hole_mm))
        if f.recess_mm > 0:
            out.append(("counterbore", s.counterbore_diameter_mm))
    if f.thread_part == label:
        if f.seat == "insert":
            out.append(("insert hole", s.insert_hole_mm))
            if f.length_mm - f.grip_mm > s.insert_pocket_depth_mm:     # the tip runs on past the insert's pocket
                out.append(("clearance hole", s.clearance_hole_mm))
        elif f.seat == "self_tap":
            out.append(("pilot", s.pilot_hole_mm))
        elif f.seat == "nut":
            out += [("clearance hole", s.clearance_hole_mm),
                    ("nut trap", s.nut_trap_width_mm / math.cos(math.radians(30.0)))]
    return out
