"""Capstan transmission (paper §2.3, eq. 20-29), SI units: tensions in N, angles in rad, lengths in m."""
from __future__ import annotations

import math

import numpy as np


def tension_ratio(mu: float, wrap_rad):
    """Largest tension ratio a wrapped drum holds without slip, T_load / T_hold = e^(mu theta_w) (eq. 20)."""
    return np.exp(mu * np.asarray(wrap_rad, dtype=float))


def bending_corrected_tension(hold_tension_n: float, mu: float, wrap_rad: float, bending_stiffness_n_m2: float,
                              radius_m: float) -> float:
    """Eq. 23 as the paper gives it: T1 = T0 e^(mu theta) (1 + EI / (T0 r^2)) [N]."""
    return hold_tension_n * math.exp(mu * wrap_rad) * (1.0 + bending_stiffness_n_m2 / (hold_tension_n * radius_m**2))


def guide_efficiency(mu: float, bend_rad):
    """Tension out / tension in across one guide or pulley of wrap theta: e^(-mu theta) (eq. 24)."""
    return np.exp(-mu * np.asarray(bend_rad, dtype=float))


def route_efficiency(mu: float, bends_rad) -> float:
    """Efficiency of a cable route through several guides: e^(-mu sum(theta)) (eq. 24 compounded, eq. 28)."""
    return float(np.exp(-mu * float(np.sum(bends_rad))))


def contact_efficiency(mu_dynamic: float, tension_variation_ratio: float) -> float:
    """Continuous-contact efficiency of the drum, 1 - (2 mu_d / pi) asin(dT / T_avg) (eq. 26).

    ``tension_variation_ratio`` = dT / T_avg must lie in [0, 1] (asin's domain; beyond it the slack side has
    gone slack and the model does not apply): ValueError otherwise.
    """
    if not 0.0 <= tension_variation_ratio <= 1.0:
        raise ValueError(f"dT/T_avg = {tension_variation_ratio:g} outside [0, 1]: eq. 26 does not apply")
    return 1.0 - 2.0 * mu_dynamic / math.pi * math.asin(tension_variation_ratio)


def capstan_efficiency(contact_eff: float, guide_eff: float, n_guides: int, cable_eff: float) -> float:
    """Total capstan transmission efficiency eta_c eta_pulley^n_p eta_cable (eq. 28)."""
    return contact_eff * guide_eff**n_guides * cable_eff


def cable_area_m2(diameter_m: float) -> float:
    """Full cross-section of a cable of diameter d [m^2] (the section the schema's modulus refers to)."""
    return math.pi * diameter_m**2 / 4.0


def cable_stiffness_n_m(youngs_modulus_pa: float, diameter_m: float, length_m: float) -> float:
    """Axial stiffness E A / L of a free cable length [N/m]."""
    return youngs_modulus_pa * cable_area_m2(diameter_m) / length_m


def pull_pull_tensions(torque_nm, moment_arm_m: float, pretension_n: float, stiffness_a_n_m: float = 1.0,
                       stiffness_b_n_m: float = 1.0):
    """Tensions (T_a, T_b) [N] of a pretensioned pull-pull pair holding joint torque tau (positive: side a pulls).

    With the spool held, a joint rotation d theta stretches side a by m d theta and relaxes side b by the same, so
    tau = m (k_a + k_b) m d theta and T_a = T0 + tau k_a / ((k_a + k_b) m), T_b = T0 - tau k_b / ((k_a + k_b) m)
    (equal stiffness: T0 +/- tau / (2 m)). Once T_b would fall below zero that side is slack and side a alone
    carries T_a = tau / m. Vectorised over ``torque_nm``; negative torque swaps the roles.
    """
    tau = np.asarray(torque_nm, dtype=float)
    m = moment_arm_m
    ka, kb = stiffness_a_n_m, stiffness_b_n_m
    ta = pretension_n + tau * ka / ((ka + kb) * m)
    tb = pretension_n - tau * kb / ((ka + kb) * m)
    ta = np.where(tb < 0.0, tau / m, ta)
    tb = np.where(tb < 0.0, 0.0, tb)
    tb = np.where(ta < 0.0, -tau / m, tb)
    ta = np.where(ta < 0.0, 0.0, ta)
    return ta, tb
