"""Steady heat flow out of a closed printed compartment into the water, and the electrical losses that feed it.
SI units throughout.

**Losses.** A stepper on a chopper driver (A4988 and its kind) is held at its set phase current whether it moves
or not. With microstepping the two phase currents follow a sine and a cosine of peak ``I``, so the copper loss is
``I^2 R`` in total (``2 I^2 R`` at full step, both phases on at ``I``); the driver's bridge dissipates the same
currents in its on-resistance (source + sink, ``R_ds``). The mechanical power the motors deliver leaves the
compartment through the cables and is not heat inside it. Iron losses are left out (small at the step rates of a
tail-beat; they would add to the heat).

**Heat path.** Everything dissipated inside reaches the water through three resistances in series: natural
convection from the inside air to the wall (``1 / (h_air A)``), conduction through the printed wall
(``t / (k A)``) and convection from the wall to the water (``1 / (h_water A)``), ``A`` the compartment's wall area
(Incropera & DeWitt, Fundamentals of Heat and Mass Transfer, ch. 3: the plane wall with convection on both
sides; the wall is thin next to the head's radii, so one area serves all three). A motor's case sits above the
air by its own loss over its surface's convection (``P_motor / (h_air A_case)``); its mounting face, and the
printed mount touching it, are at about that temperature (the conduction into the thin plastic is neglected, which
errs on the warm side).
"""
from __future__ import annotations


def stepper_copper_loss_w(phase_current_a: float, phase_resistance_ohm: float, microstepping: bool = True) -> float:
    """Copper loss of a two-phase stepper held at ``phase_current_a`` peak by a chopper driver [W]."""
    return (1.0 if microstepping else 2.0) * phase_current_a**2 * phase_resistance_ohm


def driver_bridge_loss_w(phase_current_a: float, rds_on_ohm: float, microstepping: bool = True) -> float:
    """Conduction loss of the driver's two H-bridges (``rds_on_ohm``: source plus sink on-resistance) [W]."""
    return (1.0 if microstepping else 2.0) * phase_current_a**2 * rds_on_ohm


def compartment_resistance_k_w(walls, k_wall_w_m_k: float, h_air_w_m2_k: float, h_water_w_m2_k: float) -> float:
    """Thermal resistance from the inside air to the water [K/W] through ``walls``, ``[(area m^2, thickness m),
    ...]`` side by side: each a plane wall with convection on both faces, ``A / (1/h_air + t/k + 1/h_water)``
    conductances in parallel."""
    walls = [(float(a), float(t)) for a, t in walls]
    if sum(a for a, _ in walls) <= 0 or any(a < 0 for a, _ in walls):
        raise ValueError(f"compartment walls {walls} (m^2, m): expected areas >= 0 and some > 0")
    return 1.0 / sum(a / (1.0 / h_air_w_m2_k + t / k_wall_w_m_k + 1.0 / h_water_w_m2_k) for a, t in walls)


def case_rise_k(power_w: float, case_area_m2: float, h_air_w_m2_k: float) -> float:
    """Rise of a motor's case over the air round it [K]."""
    return power_w / (h_air_w_m2_k * case_area_m2)


def run_time_s(battery_energy_j: float, usable_fraction: float, power_w: float) -> float:
    """How long a battery lasts at a steady draw [s]."""
    return battery_energy_j * usable_fraction / power_w
