"""Servo-gear transmission losses under oscillation (paper §2.2, eq. 4-19), SI units throughout.

Angles in rad, frequencies in Hz, inertias in kg m^2, torques in N m, powers in W.
Where the paper's printed equation does not follow from its own derivation, the function here is the derived
form and a ``paper_*`` function keeps the printed one so that ``swiftfin audit`` can show the difference.
"""
from __future__ import annotations

import math

import numpy as np


def mesh_efficiency(mu_g: float, pressure_angle_rad: float, z1: int, z2: int) -> float:
    """Efficiency of one involute mesh [-] (eq. 4): 1 - pi mu_g / cos(alpha) (1/z1 + 1/z2)."""
    return 1.0 - math.pi * mu_g / math.cos(pressure_angle_rad) * (1.0 / z1 + 1.0 / z2)


def train_efficiency(stage_efficiency: float, n_stages: int) -> float:
    """Multi-stage gear train efficiency [-] (§2.2.1): the stages compound multiplicatively."""
    return stage_efficiency ** n_stages


def reversal_acceleration(frequency_hz, amplitude_rad):
    """Angular acceleration at the amplitude extremes of theta0 sin(2 pi f t) [rad/s^2] (eq. 8)."""
    return (2.0 * np.pi * frequency_hz) ** 2 * amplitude_rad


def backlash_impact_speed(acceleration_rad_s2, backlash_rad):
    """Speed reached after crossing the backlash zone phi_b at constant acceleration [rad/s] (eq. 7)."""
    return np.sqrt(2.0 * acceleration_rad_s2 * backlash_rad)


def backlash_impact_energy(inertia_kg_m2, impact_speed_rad_s, restitution):
    """Energy lost in one impact [J] (eq. 6): 1/2 J w^2 (1 - e^2)."""
    return 0.5 * inertia_kg_m2 * impact_speed_rad_s**2 * (1.0 - restitution**2)


def backlash_power(inertia_kg_m2, frequency_hz, amplitude_rad, backlash_rad, restitution):
    """Backlash power loss [W], derived from eq. 6-8 with two reversals per cycle (eq. 9, corrected).

    2 f E_impact with w^2 = 2 alpha phi_b and alpha = (2 pi f)^2 theta0 gives
    P = 2 f J (2 pi f)^2 theta0 phi_b (1 - e^2). The paper's eq. 9 prints half of this
    (see :func:`paper_backlash_power`).
    """
    w = backlash_impact_speed(reversal_acceleration(frequency_hz, amplitude_rad), backlash_rad)
    return 2.0 * frequency_hz * backlash_impact_energy(inertia_kg_m2, w, restitution)


def paper_backlash_power(inertia_kg_m2, frequency_hz, amplitude_rad, backlash_rad, restitution):
    """Eq. 9 as printed: f J (2 pi f)^2 theta0 phi_b (1 - e^2) [W] (half the value eq. 6-8 give)."""
    return frequency_hz * inertia_kg_m2 * (2 * np.pi * frequency_hz) ** 2 * amplitude_rad * backlash_rad * (
        1 - restitution**2)


def friction_power(coulomb_torque_nm, viscous_nm_s_rad, frequency_hz, amplitude_rad):
    """Cycle-mean power of Coulomb + viscous friction (eq. 13-14, corrected) [W].

    With theta_dot = w theta0 cos(w t): <|theta_dot|> = (2/pi) w theta0 and <theta_dot^2> = (w theta0)^2 / 2, so
    P = tau_c (2/pi) 2 pi f theta0 + b (2 pi f theta0)^2 / 2 = 4 f theta0 tau_c + 2 pi^2 f^2 theta0^2 b.
    The paper's eq. 14-15 have 4/pi (i.e. 8 f theta0 tau_c): twice the Coulomb term.
    """
    w0 = 2.0 * np.pi * frequency_hz * amplitude_rad
    return coulomb_torque_nm * (2.0 / np.pi) * w0 + 0.5 * viscous_nm_s_rad * w0**2


def paper_friction_power(coulomb_torque_nm, viscous_nm_s_rad, frequency_hz, amplitude_rad):
    """Eq. 15 as printed: 8 f theta0 tau_c + 2 pi^2 f^2 theta0^2 b [W]."""
    return 8 * frequency_hz * amplitude_rad * coulomb_torque_nm + 2 * np.pi**2 * frequency_hz**2 * amplitude_rad**2 \
        * viscous_nm_s_rad


def inertia_at_output(motor_inertia_kg_m2: float, load_inertia_kg_m2: float, ratio: float) -> float:
    """Inertia seen at the output shaft [kg m^2] (eq. 16, corrected): J_load + N^2 J_motor.

    A reduction N multiplies the *motor's* inertia by N^2 when referred to the output; the load referred to the
    motor is J_load / N^2. The paper's eq. 16 (J_m + N^2 J_load) mixes the two.
    """
    return load_inertia_kg_m2 + ratio**2 * motor_inertia_kg_m2


def load_inertia_at_motor(load_inertia_kg_m2: float, ratio: float) -> float:
    """The load's inertia referred to the motor shaft [kg m^2]: J_load / N^2 (the paper's eq. 16 has N^2 J_load)."""
    return load_inertia_kg_m2 / ratio**2


def inertia_power(inertia_kg_m2, frequency_hz, amplitude_rad):
    """Power to re-accelerate an inertia twice per cycle with no energy recovery [W] (eq. 17).

    1/2 J (2 pi f theta0)^2 x 2 f = 4 pi^2 f^3 theta0^2 J, with J and theta0 referred to the *same* shaft
    (use :func:`inertia_at_output` with the output amplitude). An upper bound: a drive that recovers kinetic
    energy loses less.
    """
    return 4.0 * np.pi**2 * frequency_hz**3 * amplitude_rad**2 * inertia_kg_m2


def servo_efficiency(train_eff: float, p_mech_w, p_backlash_w, p_friction_w, p_inertia_w):
    """Servo-gear transmission efficiency for oscillatory motion [-] (eq. 18)."""
    return train_eff * p_mech_w / (p_mech_w + p_backlash_w + p_friction_w + p_inertia_w)


def servo_efficiency_curve(frequency_hz, train_eff: float, p0_w_per_hz: float, k1: float, k2: float, k3: float,
                           k4: float):
    """Eq. 19: eta_g^n P0 f / (P0 f + k1 f^3 + k2 f + k3 f^2 + k4 f^3) [-]."""
    f = np.asarray(frequency_hz, dtype=float)
    return train_eff * p0_w_per_hz * f / (p0_w_per_hz * f + k1 * f**3 + k2 * f + k3 * f**2 + k4 * f**3)
