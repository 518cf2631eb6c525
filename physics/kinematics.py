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
