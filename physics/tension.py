"""Cable pretension as numbers (SI): stretch, stiffness and how far a tensioner must take a cable loop in.

A pull-pull loop of free length L (both sides, spool to tendon sector) pretensioned to T stretches by
T L / (E A); over its life it also creeps by ``creep_fraction`` L, and each side is assembled ``tolerance`` long
or short. A tensioner that shortens the loop must cover the sum. Pure functions, floats in, floats out.
"""
from __future__ import annotations

import math

from swiftfin.physics.capstan import cable_area_m2


def axial_rigidity_n(youngs_modulus_pa: float, diameter_m: float) -> float:
    """E A of a cable on its full section [N]."""
    return youngs_modulus_pa * cable_area_m2(diameter_m)


def stretch_at_tension_m(tension_n: float, youngs_modulus_pa: float, diameter_m: float, length_m: float) -> float:
    """Elastic stretch T L / (E A) of a free length L at tension T [m]."""
    return tension_n * length_m / axial_rigidity_n(youngs_modulus_pa, diameter_m)


def take_up_need_m(tension_n: float, youngs_modulus_pa: float, diameter_m: float, loop_length_m: float,
                   creep_fraction: float, tolerance_per_side_m: float, sides: int = 2) -> float:
    """Loop shortening a tensioner must offer [m]: stretch at pretension + creep allowance + one assembly
    tolerance per side: T L / (E A) + c L + n t."""
    return (stretch_at_tension_m(tension_n, youngs_modulus_pa, diameter_m, loop_length_m)
            + creep_fraction * loop_length_m + sides * tolerance_per_side_m)


def loop_take_up_per_newton_m(youngs_modulus_pa: float, diameter_m: float, loop_length_m: float) -> float:
    """Loop shortening that raises the pretension of both sides by 1 N: L / (E A) [m/N] (the loop's two sides
    are in series, and the joint settles where both carry the same tension)."""
    return loop_length_m / axial_rigidity_n(youngs_modulus_pa, diameter_m)


def relative_turn_per_newton_rad(youngs_modulus_pa: float, diameter_m: float, loop_length_m: float,
                                 drum_radius_m: float) -> float:
    """Relative rotation of the two halves of a split drum of radius r that raises the pretension by 1 N:
    L / (E A r) [rad/N]."""
    return loop_take_up_per_newton_m(youngs_modulus_pa, diameter_m, loop_length_m) / drum_radius_m


def vernier_step_rad(holes_a: int, holes_b: int) -> float:
    """Least relative step of two rings of index holes (a and b holes, equally spaced): 2 pi / lcm-free product
    when the counts are coprime, 2 pi gcd / (a b) in general [rad]."""
    return 2 * math.pi * math.gcd(holes_a, holes_b) / (holes_a * holes_b)
