"""Seals as physics: what a grease-packed cable gland holds, and the water pressure it must hold. SI units.

**Grease plug.** Below its yield stress ``tau_y`` a lubricating grease is a plastic solid. A plug of packed length
``L`` in the annulus between a cable (radius ``r_i``) and its sleeve (radius ``r_o = r_i + h``), with a pressure
difference ``dp`` on its faces, stays put while the shear on its two walls holds it:
``dp pi (r_o^2 - r_i^2) <= tau_y 2 pi (r_o + r_i) L``, so ``dp_hold = 2 tau_y L / h`` (Bingham plug in a slit;
the same result as a capillary plug of a yield-stress fluid). A sliding cable shears the grease next to it, so the
plug only holds while the wet stretch of cable that the stroke pulls into the sleeve stays short of the dry end.
"""
from __future__ import annotations


def grease_plug_hold_pa(yield_stress_pa: float, packed_length_mm: float, radial_gap_mm: float) -> float:
    """Largest pressure difference a grease plug of ``packed_length_mm`` in an annulus of ``radial_gap_mm`` holds
    [Pa]."""
    if radial_gap_mm <= 0:
        raise ValueError(f"radial gap {radial_gap_mm} mm: expected > 0")
    return 2.0 * yield_stress_pa * packed_length_mm / radial_gap_mm


def hydrostatic_pa(depth_m: float, water_density_kg_m3: float, gravity_m_s2: float) -> float:
    """Gauge pressure of still water at ``depth_m`` [Pa]."""
    return water_density_kg_m3 * gravity_m_s2 * depth_m


def rated_depth_m(hold_pa: float, safety_factor: float, water_density_kg_m3: float, gravity_m_s2: float) -> float:
    """Depth at which a seal that holds ``hold_pa`` keeps its safety factor [m]."""
    return hold_pa / (safety_factor * water_density_kg_m3 * gravity_m_s2)
