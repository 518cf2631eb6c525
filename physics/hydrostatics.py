"""Hydrostatics of a floating body (SI): where it settles in still water."""
from __future__ import annotations

import math


def static_pitch_deg(com_m, cob_m) -> float:
    """Pitch the straight fish settles at in still water [deg], nose down positive: the COM hangs under the COB,
    so the body turns until the COB-COM line is vertical: atan(COM's lead over the COB / COB's height over it).
    90 (or more) when the COB is not above the COM."""
    dx = float(com_m[0] - cob_m[0])
    dz = float(cob_m[2] - com_m[2])
    return math.degrees(math.atan2(dx, dz))
