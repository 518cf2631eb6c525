"""The paper's efficiency curves and their ratio (eq. 30-35). Frequencies in Hz."""
from __future__ import annotations

import numpy as np


def capstan_efficiency_curve(frequency_hz):
    """eta_capstan(f) ~ 0.95 - 0.003 f (eq. 31), the paper's fit."""
    return 0.95 - 0.003 * np.asarray(frequency_hz, dtype=float)


def servo_efficiency_fit(frequency_hz):
    """eta_servo(f) ~ 0.92 - 0.025 f - 0.002 f^2 (eq. 32), the paper's fit."""
    f = np.asarray(frequency_hz, dtype=float)
    return 0.92 - 0.025 * f - 0.002 * f**2


def efficiency_ratio(eta_capstan, eta_servo):
    """Oscillatory efficiency ratio Gamma = eta_capstan / eta_servo (eq. 30)."""
    return np.asarray(eta_capstan, dtype=float) / np.asarray(eta_servo, dtype=float)


def paper_ratio_at(frequency_hz):
    """Gamma(f) from the two fits (eq. 33-35)."""
    return efficiency_ratio(capstan_efficiency_curve(frequency_hz), servo_efficiency_fit(frequency_hz))
