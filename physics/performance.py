"""Whole-robot performance metrics as the paper defines them (§5-6), SI units."""
from __future__ import annotations


def quasi_propulsive_efficiency(towed_drag_n: float, speed_m_s: float, electric_power_w: float) -> float:
    """eta_QP = R_towed U / P_elec (eq. 49) [-] (the paper multiplies by 100 %). Above 1 is impossible."""
    return towed_drag_n * speed_m_s / electric_power_w


def cost_of_transport(power_w: float, mass_kg: float, speed_m_s: float) -> float:
    """COT = P / (m U) [J/(kg m)] (the paper's §6.2 unit, J/kg/m)."""
    return power_w / (mass_kg * speed_m_s)


def transport_economy(speed_m_s: float, power_w: float) -> float:
    """Distance per joule, U / P [m/J] (§6.2)."""
    return speed_m_s / power_w


def range_m(energy_j: float, economy_m_per_j: float) -> float:
    """Distance covered with an energy store at a transport economy [m]."""
    return energy_j * economy_m_per_j


def body_lengths_per_s(speed_m_s: float, length_m: float) -> float:
    """Speed in body lengths per second [1/s]."""
    return speed_m_s / length_m


def relative_reduction(reference: float, value: float) -> float:
    """(reference - value) / reference [-], e.g. '52 % lower'."""
    return (reference - value) / reference


def relative_improvement(value: float, reference: float) -> float:
    """(value - reference) / reference [-], e.g. '17 % improvement'."""
    return (value - reference) / reference


def wave_speed_m_s(frequency_hz: float, wavelength_m: float) -> float:
    """Body-wave phase speed V = f lambda [m/s] (eq. 43: omega / k)."""
    return frequency_hz * wavelength_m


def slip_ratio(speed_m_s: float, wave_speed: float) -> float:
    """U / V. Elongated-body theory (Lighthill 1960) gives thrust only for U / V < 1."""
    return speed_m_s / wave_speed
