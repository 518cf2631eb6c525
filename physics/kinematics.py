"""Travelling-wave kinematics of the body (paper §3, eq. 43-48), in SI units.

The paper commands each joint with the *absolute* tangent angle of the wave at the joint (eq. 47). A joint
rotates one link relative to the next, so the physically right command is the *relative* angle between the
two links that meet there. This module gives both; the design uses the relative one (links approximated by
the chords of the wave between successive joints), and ``swiftfin audit`` reports the difference.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Wave:
    """y(x, t) = A(x) sin(k x - w t), A(x) = c0 + c1 x + c2 x^2 (eq. 43-44). Lengths in m, x from the nose."""
    length_m: float
    c0_m: float
    c1: float
    c2_per_m: float
    wavenumber_rad_m: float
    frequency_hz: float

    @property
    def omega_rad_s(self) -> float:
        return 2.0 * np.pi * self.frequency_hz

    def envelope_m(self, x_m):
        """A(x) [m] (eq. 44)."""
        x = np.asarray(x_m, dtype=float)
        return self.c0_m + self.c1 * x + self.c2_per_m * x**2

    def envelope_slope(self, x_m):
        """A'(x) [-]."""
        x = np.asarray(x_m, dtype=float)
        return self.c1 + 2.0 * self.c2_per_m * x

    def lateral_m(self, x_m, t_s):
        """y(x, t) [m] (eq. 43). Broadcasts x against t."""
        x = np.asarray(x_m, dtype=float)
        t = np.asarray(t_s, dtype=float)
        return self.envelope_m(x) * np.sin(self.wavenumber_rad_m * x - self.omega_rad_s * t)

    def slope(self, x_m, t_s):
        """dy/dx at (x, t) [-], the bracket of eq. 47."""
        x = np.asarray(x_m, dtype=float)
        t = np.asarray(t_s, dtype=float)
        ph = self.wavenumber_rad_m * x - self.omega_rad_s * t
        return self.envelope_slope(x) * np.sin(ph) + self.envelope_m(x) * self.wavenumber_rad_m * np.cos(ph)


def wave_from_params(swimming, body_length_m: float, frequency_hz: float | None = None) -> Wave:
    """The wave of eq. 43-46 from the ``[swimming]`` section: c2 chosen so that A(L) = A_max (eq. 45)."""
    L = body_length_m
    c0 = swimming.head_amplitude_m
    c1 = swimming.envelope_linear_coefficient
    c2 = (swimming.tail_amplitude_m - c0 - c1 * L) / L**2
    k = 2.0 * np.pi / (swimming.wavelength_body_lengths * L)
    f = swimming.tail_beat_frequency_hz if frequency_hz is None else frequency_hz
    return Wave(L, c0, c1, c2, k, f)


def absolute_tangent_angles_rad(wave: Wave, stations_m, t_s):
    """The paper's joint command theta_i(t) = arctan(dy/dx at x_i) (eq. 47). Shape (len(t), n_joints)."""
    x = np.asarray(stations_m, dtype=float)[None, :]
    t = np.asarray(t_s, dtype=float)[:, None]
    return np.arctan(wave.slope(x, t))


def link_angles_rad(wave: Wave, nodes_m, t_s):
    """Absolute yaw of each rigid link: the chord of the wave between successive nodes. Shape (len(t), n-1)."""
    x = np.asarray(nodes_m, dtype=float)
    t = np.asarray(t_s, dtype=float)[:, None]
    y = wave.lateral_m(x[None, :], t)
    return np.arctan2(np.diff(y, axis=1), np.diff(x)[None, :])


def relative_joint_angles_rad(wave: Wave, stations_m, tail_end_m: float, t_s):
    """Joint angles = yaw of the link behind minus yaw of the link ahead. Shape (len(t), n_joints).

    The links are the chords of the wave between nose (x=0), the joints, and the tail end.
    """
    nodes = np.concatenate([[0.0], np.asarray(stations_m, dtype=float), [tail_end_m]])
    phi = link_angles_rad(wave, nodes, t_s)
    return np.diff(phi, axis=1)


def max_relative_joint_angles_rad(wave: Wave, stations_m, tail_end_m: float, n_samples: int = 720):
    """Largest |relative joint angle| over one period for each joint [rad]."""
    t = np.linspace(0.0, 1.0 / wave.frequency_hz, n_samples, endpoint=False)
    return np.max(np.abs(relative_joint_angles_rad(wave, stations_m, tail_end_m, t)), axis=0)


# ----------------------------------------------------------------------------------------------- eq. 48
def motor_angle_rad(joint_angle_rad, moment_arm_m: float, spool_radius_m: float, gear_ratio: float = 1.0):
    """Motor-shaft angle that sets a joint angle through a pull-pull cable [rad] (the kinematics of eq. 48).

    The tendon sector of radius d_mount takes in d_mount theta of cable; the spool of radius r_spool pays it out
    by turning d_mount theta / r_spool; a gear ratio G between motor and spool multiplies that.
    """
    return np.asarray(joint_angle_rad, dtype=float) * moment_arm_m / spool_radius_m * gear_ratio


def motor_steps(joint_angle_rad, moment_arm_m: float, spool_radius_m: float, microsteps: int,
                full_step_rad: float, gear_ratio: float = 1.0):
    """Microstep count S = round(theta d_mount / r_spool G mu_s / alpha_step) (eq. 48), as integers.

    The paper's form is kinematically right (1.5 motor radians per joint radian for SwiftFin). Its Table 2
    'angular resolution 0.1125 deg' is the motor's; at the joint one microstep is
    :func:`joint_resolution_rad` = 0.075 deg.
    """
    s = motor_angle_rad(joint_angle_rad, moment_arm_m, spool_radius_m, gear_ratio) * microsteps / full_step_rad
    return np.rint(s).astype(np.int64)


def joint_resolution_rad(full_step_rad: float, microsteps: int, moment_arm_m: float, spool_radius_m: float,
                         gear_ratio: float = 1.0) -> float:
    """Joint angle of one microstep [rad]: alpha_step / mu_s x r_spool / (d_mount G) (inverse of eq. 48)."""
    return full_step_rad / microsteps * spool_radius_m / (moment_arm_m * gear_ratio)


def full_step_rate(joint_rate_rad_s, moment_arm_m: float, spool_radius_m: float, full_step_rad: float,
                   gear_ratio: float = 1.0):
    """Full steps per second the motor must make for a joint angular speed [steps/s] (time derivative of eq. 48)."""
    return np.abs(motor_angle_rad(joint_rate_rad_s, moment_arm_m, spool_radius_m, gear_ratio)) / full_step_rad


def periodic_derivative(samples, period_s: float):
    """Time derivative of one period of a periodic signal sampled uniformly (axis 0), by FFT (exact for
    band-limited signals)."""
    y = np.asarray(samples, dtype=float)
    n = y.shape[0]
    w = 2.0 * np.pi * np.fft.fftfreq(n, d=period_s / n)
    shape = (n,) + (1,) * (y.ndim - 1)
    dy = np.fft.ifft(1j * w.reshape(shape) * np.fft.fft(y, axis=0), axis=0).real
    if n % 2 == 0:  # the Nyquist bin of a real signal has no defined derivative: drop it
        spec = np.fft.fft(y, axis=0)
        spec[n // 2] = 0.0
        dy = np.fft.ifft(1j * w.reshape(shape) * spec, axis=0).real
    return dy
