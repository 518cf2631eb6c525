"""Hydrodynamic derivatives of each link for simulators that take them (Gazebo's Hydrodynamics system), in
Fossen's notation (Fossen 2011, *Handbook of Marine Craft Hydrodynamics and Motion Control*, §6–7): the added
mass ``X_u̇ Y_v̇ Z_ẇ K_ṗ M_q̇ N_ṙ`` and the quadratic damping ``X_u|u| Y_v|v| Z_w|w| K_p|p| M_q|q| N_r|r|`` of
the link, about its frame (origin on its joint axis, axes of the body frame at rest), all negative (forces
that oppose the motion), SI units.

From the same strip theory the load model uses (layout/loads.py, ``[hydro]``):

* **sway and yaw** (lateral motion of a section of half-height ``b``): added mass per unit length
  ``C_a rho pi b^2`` (Lighthill 1960; Newman 1977 §4.13, an ellipse moving across its other half-axis), drag
  per unit length ``1/2 rho C_D (2 b) |v| v`` (Taylor 1952); ``Y_v̇ = -int m_a ds``, ``N_ṙ = -int m_a d^2 ds``,
  ``Y_v|v| = -int 1/2 rho C_D 2b ds``, ``N_r|r| = -int 1/2 rho C_D 2b |d|^3 ds`` with ``d`` the strip's lever
  arm from the link origin;
* **heave and pitch**: the same with the half-width ``a`` in place of ``b``;
* **roll**: ``K_ṗ = -int rho pi/8 (a^2 - b^2)^2 ds`` (an ellipse turning about its centre, Newman 1977 §4.13);
  no roll drag term (a smooth elliptic section sheds little in roll);
* **surge**: ``X_u̇ = -k_1 rho V`` with Lamb's ``k_1`` of the prolate spheroid of the whole body's length and
  largest diameter (Lamb 1932 §373), shared by the links in proportion to their envelope volume;
  ``X_u|u| = -1/2 rho C_Dx A_front`` on the head alone (``C_Dx`` = 0.1 on the frontal area of a streamlined
  body of fineness ~6, Hoerner 1965 ch. 6; the links behind it are in its shadow);
* **the caudal fin** (on the last link): lateral added mass ``C_fin rho pi (span/2)^2`` per unit chord over
  its mean chord ``S / span``, at the planform's area centroid; its broadside drag ``1/2 rho C_D90 S``;
* **a flooded link** carries the water inside it: its mass joins the translational added masses and its
  inertia about the link origin the rotational ones (the water is neutrally buoyant; Gazebo sees the dry
  link and its displaced solids, and moves this water with it through these terms).

These are linear-in-acceleration, quadratic-in-speed coefficients of a rigid link: they leave out the
memory of the wake and the interaction of the links (see the swim model in physics/swim_sim.py).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from swiftfin.core.schema import Params
from swiftfin.layout import geometry as layout

SURGE_DRAG_COEFFICIENT = 0.1   # C_Dx on the frontal area, streamlined body of fineness ~6 (Hoerner 1965, ch. 6)
N_STRIPS = 801

FOSSEN_ADDED_MASS = ("xDotU", "yDotV", "zDotW", "kDotP", "mDotQ", "nDotR")
FOSSEN_QUADRATIC = ("xUabsU", "yVabsV", "zWabsW", "kPabsP", "mQabsQ", "nRabsR")


@dataclass(frozen=True)
class LinkHydro:
    """One link's derivatives, Fossen's notation (all <= 0), about the link frame."""
    link: str
    added_mass: tuple[float, float, float, float, float, float]     # X_u̇ Y_v̇ Z_ẇ K_ṗ M_q̇ N_ṙ [kg, kg m^2]
    quadratic: tuple[float, float, float, float, float, float]      # X_u|u| ... N_r|r| [kg/m, kg m^2]

    def as_fossen(self) -> dict[str, float]:
        return dict(zip(FOSSEN_ADDED_MASS + FOSSEN_QUADRATIC, self.added_mass + self.quadratic))


def lamb_k1(length_m: float, diameter_m: float) -> float:
    """Lamb's longitudinal added-mass coefficient of a prolate spheroid of the given length and diameter."""
    a, b = length_m / 2, diameter_m / 2
    if a <= b:
        return 0.5                                   # a sphere (or oblate): k1 = 1/2
    e = math.sqrt(1 - (b / a) ** 2)
    alpha0 = 2 * (1 - e * e) / e**3 * (0.5 * math.log((1 + e) / (1 - e)) - e)
    return alpha0 / (2 - alpha0)


def _trapz(y, x) -> float:
    return float(np.trapezoid(y, x))


def link_hydrodynamics(p: Params, link_names: list[str], entrained_water=None) -> list[LinkHydro]:
    """The derivatives of every link (``link_names`` in order: head, link_1, ...). ``entrained_water``: per
    link, the Inertial (link frame) of the water a flooded link carries, or None."""
    rho = p.environment.water_density_kg_m3
    h = p.hydro
    js = layout.joint_stations_mm(p)
    bounds = [0.0, *js, layout.hull_end_mm(p)]
    L_m = p.body.length_mm / 1000
    s_all = np.linspace(0.0, bounds[-1], 4 * N_STRIPS)
    d_max = 2 * float(np.max(layout.half_height_mm(p, s_all))) / 1000
    v_env = [_trapz(math.pi * layout.naca_half_width_mm(p, s) * layout.half_height_mm(p, s), s) * 1e-9
             for s in (np.linspace(bounds[j], bounds[j + 1], N_STRIPS) for j in range(len(bounds) - 1))]
    x_added = lamb_k1(L_m, d_max) * rho * sum(v_env)
    out = []
    waters = list(entrained_water) if entrained_water is not None else [None] * len(link_names)
    for j, name in enumerate(link_names):
        s_mm = np.linspace(bounds[j], bounds[j + 1], N_STRIPS)
        s = s_mm / 1000
        a = np.asarray(layout.naca_half_width_mm(p, s_mm), dtype=float) / 1000
        b = np.asarray(layout.half_height_mm(p, s_mm), dtype=float) / 1000
        origin = 0.0 if j == 0 else js[j - 1] / 1000             # station of the link origin [m]
        d = s - origin                                            # lever arm (aft positive; squared or cubed)
        my = h.body_added_mass_coefficient * rho * math.pi * b**2
        mz = h.body_added_mass_coefficient * rho * math.pi * a**2
        cy = 0.5 * rho * h.body_drag_coefficient * 2 * b
        cz = 0.5 * rho * h.body_drag_coefficient * 2 * a
        am = [-x_added * v_env[j] / sum(v_env), -_trapz(my, s), -_trapz(mz, s),
              -_trapz(rho * math.pi / 8 * (a**2 - b**2) ** 2, s), -_trapz(mz * d**2, s), -_trapz(my * d**2, s)]
        qd = [0.0, -_trapz(cy, s), -_trapz(cz, s), 0.0, -_trapz(cz * np.abs(d) ** 3, s),
              -_trapz(cy * np.abs(d) ** 3, s)]
        if j == 0:
            a0 = float(np.max(a))
            qd[0] = -0.5 * rho * SURGE_DRAG_COEFFICIENT * math.pi * a0 * float(np.max(b))
        if j == len(link_names) - 1:                             # the caudal fin rides on the last link
            from swiftfin.layout.fin_plan import planform

            pf = planform(p)
            span, area = pf.span_mm / 1000, pf.area_mm2 * 1e-6
            eta = np.linspace(-1.0, 1.0, 2001)
            c = pf.chord_mm(eta)
            s_c = _trapz((pf.s_le_mm(eta) + c / 2) * c, eta) / _trapz(c, eta) / 1000
            m_fin = h.fin_added_mass_coefficient * rho * math.pi * (span / 2) ** 2 * (area / span)
            d_fin = s_c - origin
            am[1] -= m_fin
            am[5] -= m_fin * d_fin**2
            c_fin = 0.5 * rho * h.fin_drag_coefficient_90 * area
            qd[1] -= c_fin
            qd[5] -= c_fin * abs(d_fin) ** 3
        w = waters[j]
        if w is not None:                                         # flooded: the water moves with the link
            I = w.inertia + w.mass_kg * (np.dot(w.com, w.com) * np.eye(3) - np.outer(w.com, w.com))
            for k in range(3):
                am[k] -= w.mass_kg
                am[3 + k] -= float(I[k, k])
        out.append(LinkHydro(name, tuple(float(v) for v in am), tuple(float(v) for v in qd)))
    return out
