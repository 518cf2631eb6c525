"""Strouhal number and its efficiency penalty (paper §2.5.3, eq. 41-42)."""
from __future__ import annotations

import numpy as np


def strouhal(frequency_hz, amplitude_m, speed_m_s):
    """St = f A / U (eq. 41). A is the peak-to-peak tail excursion (Triantafyllou et al. 1993), i.e. twice the
    A_max of eq. 44-45."""
    return np.asarray(frequency_hz, dtype=float) * np.asarray(amplitude_m, dtype=float) / np.asarray(
        speed_m_s, dtype=float)


def strouhal_penalty(k_st: float, relative_amplitude_error):
    """Hydrodynamic efficiency change -k_St (dA / A)^2 (eq. 42) [-, absolute efficiency]."""
    return -k_st * np.asarray(relative_amplitude_error, dtype=float) ** 2
