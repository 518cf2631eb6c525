"""Position fidelity (paper §2.5, eq. 36-40). Angles in rad unless a name says otherwise."""
from __future__ import annotations

import math

import numpy as np


def position_fidelity(rms_error_rad, amplitude_rad):
    """F = 1 - RMS(theta_cmd - theta_act) / theta0 (eq. 36)."""
    return 1.0 - np.asarray(rms_error_rad, dtype=float) / amplitude_rad


def fidelity_from_signals(commanded_rad, actual_rad, amplitude_rad: float) -> float:
    """Eq. 36 evaluated on sampled signals."""
    err = np.asarray(commanded_rad, dtype=float) - np.asarray(actual_rad, dtype=float)
    return float(1.0 - math.sqrt(float(np.mean(err**2))) / amplitude_rad)


def backlash_output(commanded_rad, commanded_rate, backlash_rad: float):
    """The backlash dead zone of eq. 37: the output lags the command by phi_b / 2 against the motion."""
    cmd = np.asarray(commanded_rad, dtype=float)
    return cmd - np.sign(np.asarray(commanded_rate, dtype=float)) * backlash_rad / 2.0


def backlash_rms_error(backlash_rad):
    """RMS error of eq. 37 [rad]: the error is +/- phi_b / 2 at every instant, so its RMS is phi_b / 2.

    The paper's eq. 38 gives phi_b / sqrt(2).
    """
    return np.asarray(backlash_rad, dtype=float) / 2.0


def quantisation_rms(step_rad):
    """RMS error of rounding to a grid of step q (uniform error in +/- q/2): q / sqrt(12) [rad]."""
    return np.asarray(step_rad, dtype=float) / math.sqrt(12.0)


def capstan_rms_error(step_angle, stretch_m: float, radius_m: float):
    """Eq. 39 as printed: sqrt(theta_step^2 + (dL / r)^2). Both terms must be in the same unit (rad)."""
    return np.sqrt(np.asarray(step_angle, dtype=float) ** 2 + (stretch_m / radius_m) ** 2)


def joint_error_capstan_rad(full_step_rad: float, microsteps: int, spool_radius_m: float, moment_arm_m: float,
                            stretch_m: float) -> float:
    """Joint RMS error of a capstan drive, eq. 39 derived at the joint [rad].

    A motor microstep q_m = full step / microsteps turns the joint by q_m r_spool / d_mount; its rounding error is
    uniform, RMS q / sqrt(12). Cable stretch dL rotates the *joint* by dL / d_mount (eq. 39 divides by r_drum,
    which is the motor-shaft angle). Combined in quadrature.
    """
    q_joint = full_step_rad / microsteps * spool_radius_m / moment_arm_m
    return math.hypot(float(quantisation_rms(q_joint)), stretch_m / moment_arm_m)
