"""The labelled part every part family returns."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class PartSpec:
    """One part of the robot.

    ``solid``: a build123d ``Solid``/``Part`` in the **body frame at rest, in millimetres** (see layout/geometry.py).
    ``label``: unique, snake_case; becomes the STEP product name and the file stem (``hull_head_upper``).
    ``link``: kinematic link index (0 = head/base, j = behind joint j).
    ``family``: the module that made it ("hull", "fin", "link", "spool", "guide", "mount", "cradle",
    "bought").
    ``printed``: True for parts to print; False for bought parts (motors, battery, ...).
    ``print_rotation``: rotation (rx, ry, rz) in degrees, applied about the origin before the part is dropped
    onto the bed (min z = 0) for the printable STL/3MF/STEP: the print orientation.
    ``mass_kg``: catalogue mass for bought parts (None for printed ones; those come from geometry).
    ``meta``: anything else worth recording (e.g. joint index, source of a catalogue mass).
    """
    label: str
    solid: Any
    link: int
    family: str
    printed: bool = True
    print_rotation: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass_kg: float | None = None
    meta: dict = field(default_factory=dict, compare=False, hash=False)
