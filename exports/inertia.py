"""Inertial algebra (SI): a rigid body's mass, centre of mass and inertia tensor; shifting, rotating and summing
bodies (the parallel-axis theorem). Pure numpy, no CAD kernel."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Inertial:
    """Mass [kg], centre of mass [m] and inertia tensor about the COM [kg m^2], in one frame's axes."""
    mass_kg: float
    com_m: tuple[float, float, float]
    inertia_kg_m2: tuple[tuple[float, float, float], ...]

    @property
    def com(self) -> np.ndarray:
        return np.asarray(self.com_m, dtype=float)

    @property
    def inertia(self) -> np.ndarray:
        return np.asarray(self.inertia_kg_m2, dtype=float)

    def shifted(self, origin_m) -> "Inertial":
        """The same body with its COM expressed relative to ``origin_m`` (same axes)."""
        return make_inertial(self.mass_kg, self.com - np.asarray(origin_m, dtype=float), self.inertia)

    def rotated(self, R) -> "Inertial":
        """The body rotated by R about the frame origin: COM -> R c, I -> R I R^T."""
        R = np.asarray(R, dtype=float)
        return make_inertial(self.mass_kg, R @ self.com, R @ self.inertia @ R.T)

    def scaled_mass(self, factor: float) -> "Inertial":
        return make_inertial(self.mass_kg * factor, self.com, self.inertia * factor)


def make_inertial(mass_kg, com_m, inertia_kg_m2) -> Inertial:
    I = np.asarray(inertia_kg_m2, dtype=float)
    I = 0.5 * (I + I.T)
    return Inertial(float(mass_kg), tuple(float(v) for v in np.asarray(com_m, dtype=float)),
                    tuple(tuple(float(v) for v in row) for row in I))


def parallel_axis(I_com, mass, d) -> np.ndarray:
    """Inertia about a point at offset ``-d`` from the COM (d = COM - point): I + m (|d|^2 E - d d^T)."""
    d = np.asarray(d, dtype=float)
    return np.asarray(I_com, dtype=float) + mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))


def combine(items) -> Inertial:
    """Sum of bodies (masses may be negative: a removed core) about the combined COM, same axes."""
    items = list(items)
    M = sum(it.mass_kg for it in items)
    if M <= 0:
        raise ValueError(f"combined mass {M!r} kg is not positive")
    c = sum(it.mass_kg * it.com for it in items) / M
    I = sum(parallel_axis(it.inertia, it.mass_kg, it.com - c) for it in items)
    return make_inertial(M, c, I)
