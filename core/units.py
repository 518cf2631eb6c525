"""Millimetre (CAD) <-> SI (physics, mass properties, simulator files) conversions, in one place.

CAD works in millimetres (the kernel's tolerances assume it); everything written for a simulator or used by
physics is SI (house style rule 3). A quantity of dimension length^n converts with the factor 1e-3^n:

=====================  ==========  ==================
quantity               CAD unit    SI unit
=====================  ==========  ==================
length, point          mm          m        (1e-3)
area                   mm^2        m^2      (1e-6)
volume                 mm^3        m^3      (1e-9)
second moment of vol.  mm^5        m^5      (1e-15)
inertia (mass-scaled)  kg mm^2     kg m^2   (1e-6)
=====================  ==========  ==================

Tests check these by scaling (volume ~ k^3, inertia ~ k^5), not by restating the factors.
"""
from __future__ import annotations

import numpy as np

M_PER_MM = 1.0e-3


def length_m(value_mm):
    """Length(s) or point(s) [mm] -> [m]. Accepts scalars and arrays; returns the same kind."""
    return np.asarray(value_mm, dtype=float) * M_PER_MM if np.ndim(value_mm) else float(value_mm) * M_PER_MM


def length_mm(value_m):
    """Length(s) or point(s) [m] -> [mm]."""
    return np.asarray(value_m, dtype=float) / M_PER_MM if np.ndim(value_m) else float(value_m) / M_PER_MM


def area_m2(value_mm2):
    """Area [mm^2] -> [m^2]."""
    return _scale(value_mm2, M_PER_MM**2)


def volume_m3(value_mm3):
    """Volume [mm^3] -> [m^3]."""
    return _scale(value_mm3, M_PER_MM**3)


def volume_mm3(value_m3):
    """Volume [m^3] -> [mm^3]."""
    return _scale(value_m3, M_PER_MM**-3)


def second_moment_m5(value_mm5):
    """Second moment of volume (inertia per unit density) [mm^5] -> [m^5]."""
    return _scale(value_mm5, M_PER_MM**5)


def inertia_kg_m2(value_kg_mm2):
    """Mass moment of inertia [kg mm^2] -> [kg m^2]."""
    return _scale(value_kg_mm2, M_PER_MM**2)


def _scale(value, factor: float):
    return np.asarray(value, dtype=float) * factor if np.ndim(value) else float(value) * factor
