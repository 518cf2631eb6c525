"""Swimming loads the paper does not give: joint torques, cable tensions and motor torques at the design point.

Model (every coefficient in the ``[hydro]`` section of the parameter file, each overridable):

* **Kinematics.** The body wave of eq. 43-46 at the design frequency and amplitude; the rigid links are the
  chords of the wave between the nose, the joints and the fork (``physics.kinematics``, as ``swiftfin.layout.geometry`` uses
  for the joints' range). A point on a link moves with the linear interpolation of its end nodes; the link's yaw
  is phi = atan(dy/dx) of its chord. Time derivatives are spectral over one period.
* **Link inertia** (first estimate, replaced by the built parts' mass properties through ``link_masses``):
  each hull segment of ``swiftfin.layout.geometry.hull_segments`` as a thin elliptical shell of the hull wall at filament
  density plus its two bulkheads, and the caudal fin as a solid NACA 00tt plate of span b and area b^2/AR,
  on the last link. Joint hardware, cables and any water inside the shells are not included.
* **Added mass** (Lighthill 1960, strip theory): rho pi (h/2)^2 per unit length for a body section of height h
  moving laterally, and rho pi (b/2)^2 per unit chord on the fin; the reaction is m_a dw/dt with w the
  section's velocity normal to itself relative to the water, w = U sin(phi) + y_dot cos(phi). The convective
  term U d(m_a w)/dx of elongated-body theory is left out (it moves load between sections rather than adding).
* **Resistive drag** (Taylor 1952): 1/2 rho C_D h |w| w per unit length on the body.
* **Fin lift**, quasi-steady: normal force 1/2 rho S V^2 (a sin(alpha) cos(alpha) + C_D90 sin(alpha)|sin(alpha)|)
  capped at +/- C_N,max (stall), with a = 2 pi AR / (AR + 2) (lifting line) and alpha the angle between the fin
  chord (the last link's chord) and the relative flow.
* **Joint torque** = moment about the joint of what the links behind it need: sum of m a (x - x_j) + I phi_ddot
  over the links (lateral accelerations only) and r x F of the hydrodynamic normal forces over the strips and
  the fin behind the joint. In the horizontal plane: gravity and the axial drag of the body are not in it.

From the joint torque (``drive_loads``): the pull-pull tensions on each side (``physics.capstan.pull_pull_tensions``,
the two sides' stiffness from their route lengths in ``swiftfin.layout.geometry.cable_routes``), the tensions at the spool
through the PTFE bends of the route (friction e^(+/- mu theta) against the direction the cable moves), the
motor torque (tension difference x spool radius + rotor inertia x motor acceleration) and the step rate.
"""
from __future__ import annotations

import dataclasses

import math
from dataclasses import dataclass, field

import numpy as np

from swiftfin.layout.geometry import cable_routes, half_height_mm, hull_end_mm, hull_segments, joint_stations_mm, \
    naca_half_width_mm
from swiftfin.physics.capstan import cable_area_m2, cable_stiffness_n_m, pull_pull_tensions, tension_ratio
from swiftfin.physics.kinematics import full_step_rate, periodic_derivative, wave_from_params
from swiftfin.core.params import get_key, replace_key
from swiftfin.core.schema import Params

MM = 1e-3


@dataclass(frozen=True)
class LinkMass:
    """Mass properties of one kinematic link in the lateral plane (SI): mass, station of its centre of mass
    (distance aft of the nose) and yaw inertia about a vertical axis through that centre."""
    mass_kg: float
    com_station_m: float
    izz_com_kg_m2: float


@dataclass(frozen=True)
class FinGeometry:
    span_m: float
    area_m2: float
    chord_m: float
    aspect_ratio: float
    quarter_chord_station_m: float   # where the lift acts (mean quarter chord, swept planform)
    centroid_station_m: float        # where the added mass and the fin's own mass sit
    mass_kg: float
    izz_com_kg_m2: float


def ellipse_perimeter(a, b):
    """Ramanujan's approximation of the perimeter of an ellipse of half-axes a, b (rel. error < 1e-4 here);
    numbers or arrays."""
    return np.pi * (3 * (a + b) - np.sqrt((3 * a + b) * (a + 3 * b)))


def _ellipse_y2_line_integral(a, b, n: int = 256):
    """Integral of y^2 ds around the ellipse y = a cos u, z = b sin u [m^3]; numbers or arrays of a, b."""
    u = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    a, b = np.asarray(a, dtype=float)[..., None], np.asarray(b, dtype=float)[..., None]
    ds = np.sqrt((a * np.sin(u)) ** 2 + (b * np.cos(u)) ** 2) * (2 * np.pi / n)
    out = np.sum((a * np.cos(u)) ** 2 * ds, axis=-1)
    return float(out) if out.ndim == 0 else out


def fin_geometry(p: Params) -> FinGeometry:
    """Caudal fin from ``[caudal_fin]``: constant-chord swept plate whose root leading edge is at the hull end."""
    f = p.caudal_fin
    b = f.span_mm * MM
    S = b**2 / f.aspect_ratio
    c = S / b
    x_le = hull_end_mm(p) * MM
    sweep = math.tan(math.radians(f.sweep_deg)) * b / 4  # the half-spans' centroids lie at |z| = b/4
    rho = p.print.filament_density_kg_m3
    mass = rho * 0.685 * f.thickness_fraction * c**2 * b  # NACA 00tt section area = 0.685 t c^2
    izz = mass * (c**2 / 12 + math.tan(math.radians(f.sweep_deg)) ** 2 * b**2 / 48)
    return FinGeometry(b, S, c, f.aspect_ratio, x_le + c / 4 + sweep, x_le + c / 2 + sweep, mass, izz)


def shell_link_masses(p: Params, n_strips: int = 120) -> tuple[LinkMass, ...]:
    """First estimate of the mass properties of links 1..N: hull shells + bulkheads (+ the fin on the last link).

    Thin shell: mass per length rho t P(s) on the mid-wall ellipse; yaw inertia from the shell's x spread plus
    its width (integral of y^2 dm). Bulkheads: solid inner ellipses of the bulkhead thickness at both ends.
    """
    rho = p.print.filament_density_kg_m3
    t = p.hull.wall_thickness_mm * MM
    tb = p.hull.bulkhead_thickness_mm * MM
    fin = fin_geometry(p)
    out = []
    for k in range(1, p.joints.count + 1):
        m_tot = 0.0
        first = 0.0   # sum m x
        second = 0.0  # sum (m x^2 + y^2 dm)
        for seg in hull_segments(p):
            if seg.link != k:
                continue
            s = np.linspace(seg.s_start_mm, seg.s_end_mm, n_strips + 1) * MM
            sm = 0.5 * (s[1:] + s[:-1])
            ds = np.diff(s)
            a = np.asarray(naca_half_width_mm(p, sm / MM)) * MM - t / 2          # every strip at once
            bb = np.asarray(half_height_mm(p, sm / MM)) * MM - t / 2
            ok = (a > 0) & (bb > 0)
            a, bb, sm_ok, ds_ok = a[ok], bb[ok], sm[ok], ds[ok]
            dm = rho * t * ellipse_perimeter(a, bb) * ds_ok
            m_tot += float(np.sum(dm))
            first += float(np.sum(dm * sm_ok))
            second += float(np.sum(dm * sm_ok**2 + rho * t * ds_ok * _ellipse_y2_line_integral(a, bb)))
            for s_end in (seg.s_start_mm * MM, seg.s_end_mm * MM):
                a = float(naca_half_width_mm(p, s_end / MM)) * MM - t
                bb = float(half_height_mm(p, s_end / MM)) * MM - t
                if a <= 0 or bb <= 0:
                    continue
                dm = rho * tb * math.pi * a * bb
                m_tot += dm
                first += dm * s_end
                second += dm * s_end**2 + rho * tb * math.pi * a**3 * bb / 4
        if k == p.joints.count:
            m_tot += fin.mass_kg
            first += fin.mass_kg * fin.centroid_station_m
            second += fin.mass_kg * fin.centroid_station_m**2 + fin.izz_com_kg_m2
        x_c = first / m_tot
        out.append(LinkMass(m_tot, x_c, second - m_tot * x_c**2))
    return tuple(out)


@dataclass(frozen=True)
class HingeInertia:
    """Yaw inertia about a joint's hinge of everything behind it, held straight (SI), by source."""
    links_kg_m2: float            # the printed links and the fin (:func:`shell_link_masses`)
    added_mass_kg_m2: float       # the water the body and fin accelerate (strip theory, as :func:`joint_loads`)
    entrained_kg_m2: float        # the water inside the flooded shells, which moves with them
    medium: str

    @property
    def total_kg_m2(self) -> float:
        return self.links_kg_m2 + (self.added_mass_kg_m2 + self.entrained_kg_m2 if self.medium == "water" else 0.0)

    def describe(self, joint: int) -> str:
        text = (f"{self.total_kg_m2:.3g} kg m^2 about hinge {joint}: the design's links behind it with the fin "
                f"({self.links_kg_m2:.3g}, thin-shell estimate without the joint hardware)")
        if self.medium == "water":
            text += (f", in water with their added mass ({self.added_mass_kg_m2:.3g}, strip theory) and the water "
                     f"inside the flooded shells ({self.entrained_kg_m2:.3g})")
        return text + ", held straight"


def hinge_inertia(p: Params, joint: int, medium: str = "air", n_strips: int = 200) -> HingeInertia:
    """The inertia a bench holding the design's own tail sees about hinge ``joint`` (0-based) with the joints behind
    it locked: the links (:func:`shell_link_masses`, parallel axes to the hinge) and, in water, the added mass of
    the body strips (rho pi (h/2)^2 per unit length, x ``hydro.body_added_mass_coefficient``) and of the fin
    (rho pi (b/2)^2 per unit chord at its centroid, x ``hydro.fin_added_mass_coefficient``), the same strip model
    :func:`joint_loads` uses, and the water inside the link shells behind the hinge (the tail segments flood),
    each times the square of its lever arm."""
    if medium not in ("air", "water"):
        raise ValueError(f"medium {medium!r}: expected 'air' or 'water'")
    xj = joint_stations_mm(p)[joint] * MM
    links = sum(lm.izz_com_kg_m2 + lm.mass_kg * (lm.com_station_m - xj) ** 2
                for lm in shell_link_masses(p)[joint:])
    rho = p.environment.water_density_kg_m3
    hy = p.hydro
    edges = np.linspace(xj, hull_end_mm(p) * MM, n_strips + 1)
    xs = 0.5 * (edges[1:] + edges[:-1])
    dx = np.diff(edges)
    h = 2.0 * np.asarray(half_height_mm(p, xs / MM)) * MM
    added = float(np.sum(hy.body_added_mass_coefficient * rho * np.pi * (h / 2) ** 2 * dx * (xs - xj) ** 2))
    fin = fin_geometry(p)
    added += (hy.fin_added_mass_coefficient * rho * np.pi * (fin.span_m / 2) ** 2 * fin.chord_m
              * (fin.centroid_station_m - xj) ** 2)
    t = p.hull.wall_thickness_mm * MM
    a = np.maximum(np.asarray(naca_half_width_mm(p, xs / MM)) * MM - t, 0.0)
    b = np.maximum(np.asarray(half_height_mm(p, xs / MM)) * MM - t, 0.0)
    inside = float(np.sum(rho * np.pi * a * b * dx * ((xs - xj) ** 2 + a ** 2 / 4)))
    return HingeInertia(float(links), added, inside, medium)


@dataclass(frozen=True)
class JointLoads:
    """Joint kinematics and torques over one period at the design point. Arrays are (n_samples, n_joints)."""
    t_s: np.ndarray
    joint_angle_rad: np.ndarray
    joint_rate_rad_s: np.ndarray
    joint_accel_rad_s2: np.ndarray
    torque_nm: np.ndarray
    components_nm: dict = field(default_factory=dict)   # name -> (n_samples, n_joints)
    link_masses: tuple = ()
    fin_root_moment_nm: np.ndarray | None = None        # (n_samples,) the fin's forces about its socket's mouth

    @property
    def peak_fin_root_moment_nm(self) -> float:
        """Largest |moment| of the caudal fin's lift and added-mass forces about the mouth of its root socket (the
        hull end, on the last link): what bends the fin's root tang where it leaves the peduncle."""
        return float(np.max(np.abs(self.fin_root_moment_nm))) if self.fin_root_moment_nm is not None else 0.0

    @property
    def peak_torque_nm(self) -> np.ndarray:
        return np.max(np.abs(self.torque_nm), axis=0)

    @property
    def peak_components_nm(self) -> dict:
        return {k: np.max(np.abs(v), axis=0) for k, v in self.components_nm.items()}

    @property
    def mean_power_w(self) -> float:
        """Cycle-mean mechanical power delivered by all joints [W] (sum of <tau theta_dot>)."""
        return float(np.sum(np.mean(self.torque_nm * self.joint_rate_rad_s, axis=0)))

    @property
    def mean_positive_power_w(self) -> float:
        """Cycle-mean of the positive part of each joint's power [W]: what drives that cannot recover energy need."""
        return float(np.sum(np.mean(np.clip(self.torque_nm * self.joint_rate_rad_s, 0.0, None), axis=0)))


def joint_loads(p: Params, link_masses: tuple[LinkMass, ...] | None = None, mass_scale: float = 1.0,
                n_samples: int = 256, n_strips: int = 400) -> JointLoads:
    """Torque at every joint over one tail-beat period at the design point of ``[swimming]``.

    ``link_masses``: mass properties of links 1..N (e.g. from the built parts); default
    :func:`shell_link_masses`. ``mass_scale`` multiplies the link masses and inertias (for sensitivities).
    """
    sw, env, hy = p.swimming, p.environment, p.hydro
    L = p.body.length_mm * MM
    wave = wave_from_params(sw, L)
    T = 1.0 / wave.frequency_hz
    U = sw.speed_m_s
    rho = env.water_density_kg_m3
    t = np.linspace(0.0, T, n_samples, endpoint=False)
    xj = np.asarray(joint_stations_mm(p)) * MM
    nodes = np.concatenate([[0.0], xj, [L]])
    y = wave.lateral_m(nodes[None, :], t[:, None])                 # (nt, nn)
    yd = periodic_derivative(y, T)
    ydd = periodic_derivative(yd, T)
    phi = np.arctan2(np.diff(y, axis=1), np.diff(nodes)[None, :])  # (nt, n_links) link yaw
    phid = periodic_derivative(phi, T)
    phidd = periodic_derivative(phid, T)
    theta = np.diff(phi, axis=1)
    thetad = np.diff(phid, axis=1)
    thetadd = np.diff(phidd, axis=1)
    n = len(xj)

    def at(xq):
        """(y, y_dot, y_ddot, phi, phi_dot) at stations xq (1-d), interpolated on the link chain."""
        xq = np.atleast_1d(np.asarray(xq, dtype=float))
        link = np.clip(np.searchsorted(nodes, xq, side="right") - 1, 0, len(nodes) - 2)
        w = (xq - nodes[link]) / (nodes[link + 1] - nodes[link])
        def lin(v):
            return v[:, link] * (1 - w) + v[:, link + 1] * w
        return lin(y), lin(yd), lin(ydd), phi[:, link], phid[:, link]

    masses = link_masses if link_masses is not None else shell_link_masses(p)
    if len(masses) != n:
        raise ValueError(f"link_masses has {len(masses)} links, the design has {n} joints")
    masses = tuple(LinkMass(m.mass_kg * mass_scale, m.com_station_m, m.izz_com_kg_m2 * mass_scale) for m in masses)

    comps = {name: np.zeros((n_samples, n)) for name in ("link_inertia", "body_added_mass", "body_drag",
                                                         "fin_added_mass", "fin_lift")}
    # link inertia (d'Alembert): m a_com (x_com - x_j) + I phi_ddot, for every link behind joint j
    for k, lm in enumerate(masses, start=1):
        _, _, a_c, _, _ = at([lm.com_station_m])
        f_lat = lm.mass_kg * a_c[:, 0]
        for j in range(n):
            if k >= j + 1:
                comps["link_inertia"][:, j] += f_lat * (lm.com_station_m - xj[j]) + lm.izz_com_kg_m2 * phidd[:, k]
    # body strips from joint 1 to the hull end
    s_edges = np.linspace(xj[0], hull_end_mm(p) * MM, n_strips + 1)
    xs = 0.5 * (s_edges[1:] + s_edges[:-1])
    dx = np.diff(s_edges)
    h = 2.0 * np.asarray(half_height_mm(p, xs / MM)) * MM
    ys, vs, _, ph, phd = at(xs)
    w = U * np.sin(ph) + vs * np.cos(ph)
    wd = periodic_derivative(w, T)
    f_am = hy.body_added_mass_coefficient * rho * np.pi * (h / 2) ** 2 * wd * dx     # (nt, ns) needed normal force
    f_dr = 0.5 * rho * hy.body_drag_coefficient * h * np.abs(w) * w * dx

    def moment(f_normal, x_pt, y_pt, phi_pt, j):
        """Moment about joint j of normal forces f_n (-sin phi, cos phi) at points (x, y): r x F, only for the
        points behind the joint."""
        lever = np.asarray(x_pt) - xj[j]
        m_ = f_normal * (lever * np.cos(phi_pt) + (y_pt - y[:, j + 1: j + 2]) * np.sin(phi_pt))
        return np.sum(np.where(lever > 0, m_, 0.0), axis=1)

    for j in range(n):
        comps["body_added_mass"][:, j] = moment(f_am, xs, ys, ph, j)
        comps["body_drag"][:, j] = moment(f_dr, xs, ys, ph, j)
    # caudal fin
    fin = fin_geometry(p)
    yf, vf, _, pf, _ = at([fin.quarter_chord_station_m])
    vf, pf = vf[:, 0], pf[:, 0]
    wf = U * np.sin(pf) + vf * np.cos(pf)
    uf = U * np.cos(pf) - vf * np.sin(pf)
    alpha = np.arctan2(wf, uf)
    a_slope = hy.fin_lift_slope_factor * 2 * np.pi * fin.aspect_ratio / (fin.aspect_ratio + 2)
    cn = a_slope * np.sin(alpha) * np.cos(alpha) + hy.fin_drag_coefficient_90 * np.sin(alpha) * np.abs(np.sin(alpha))
    cn = np.clip(cn, -hy.fin_normal_coefficient_max, hy.fin_normal_coefficient_max)
    f_lift = 0.5 * rho * fin.area_m2 * (uf**2 + wf**2) * cn                          # needed normal force
    yfc, vfc, _, pfc, _ = at([fin.centroid_station_m])
    wfc = U * np.sin(pfc[:, 0]) + vfc[:, 0] * np.cos(pfc[:, 0])
    m_af = hy.fin_added_mass_coefficient * rho * np.pi * (fin.span_m / 2) ** 2 * fin.chord_m
    f_fam = m_af * periodic_derivative(wfc, T)
    for j in range(n):
        comps["fin_lift"][:, j] = moment(f_lift[:, None], [fin.quarter_chord_station_m], yf, pf[:, None], j)
        comps["fin_added_mass"][:, j] = moment(f_fam[:, None], [fin.centroid_station_m], yfc, pfc, j)
    # the same forces about the socket's mouth (the hull end, on the last link), r x F as in moment()
    x_m = hull_end_mm(p) * MM
    y_m = at([x_m])[0]
    root = np.zeros(n_samples)
    for f_n, x_f, y_f, p_f in ((f_lift, fin.quarter_chord_station_m, yf[:, 0], pf),
                               (f_fam, fin.centroid_station_m, yfc[:, 0], pfc[:, 0])):
        if x_f > x_m:
            root += f_n * ((x_f - x_m) * np.cos(p_f) + (y_f - y_m[:, 0]) * np.sin(p_f))
    torque = sum(comps.values())
    return JointLoads(t, theta, thetad, thetadd, torque, comps, masses, root)


@dataclass(frozen=True)
class DriveLoads:
    """Cable and motor loads of every joint over one period. Arrays (n_samples, n_joints) unless noted."""
    tension_left_joint_n: np.ndarray
    tension_right_joint_n: np.ndarray
    tension_tight_spool_n: np.ndarray
    tension_slack_spool_n: np.ndarray
    motor_torque_nm: np.ndarray
    step_rate_full_steps_s: np.ndarray
    route_bend_rad: np.ndarray           # (n_joints, 2): total bend angle of the left and right routes
    route_length_m: np.ndarray           # (n_joints, 2)
    compliance_rad: np.ndarray           # joint rotation from the tight side's stretch beyond pretension
    capstan_capacity: np.ndarray         # T_slack_spool e^(mu theta) / T_tight_spool (slip if < 1)
    route_efficiency: np.ndarray         # (n_joints,): e^(-mu_ptfe theta) of the worse route (eq. 24 over its bends)

    @property
    def peak_tension_n(self) -> np.ndarray:
        return np.maximum(self.tension_left_joint_n, self.tension_right_joint_n).max(axis=0)

    @property
    def min_tension_n(self) -> np.ndarray:
        return np.minimum(self.tension_left_joint_n, self.tension_right_joint_n).min(axis=0)

    @property
    def peak_spool_tension_n(self) -> np.ndarray:
        return self.tension_tight_spool_n.max(axis=0)

    @property
    def peak_motor_torque_nm(self) -> np.ndarray:
        return np.max(np.abs(self.motor_torque_nm), axis=0)



def with_hinge_losses(loads: JointLoads, damping_nm_s_rad, friction_nm) -> JointLoads:
    """``loads`` with the hinges' own losses added to every joint's torque: a viscous ``c w`` and a dry
    ``tau_c sign(w)`` per joint (arrays of length n_joints [N m s/rad], [N m]; measured on a bench and read
    from a calibration file, :mod:`swiftfin.core.calibration`), as the component ``hinge``. The drive then
    carries them through the spools and routes like any other joint torque."""
    c = np.asarray(damping_nm_s_rad, dtype=float)[None, :]
    tc = np.asarray(friction_nm, dtype=float)[None, :]
    w = loads.joint_rate_rad_s
    hinge = c * w + tc * np.sign(w)
    comps = dict(loads.components_nm)
    comps["hinge"] = hinge
    return dataclasses.replace(loads, torque_nm=loads.torque_nm + hinge, components_nm=comps)


def simple_motor_torque_nm(joint_torque_nm, spool_radius_m: float, moment_arm_m: float, route_eff) -> np.ndarray:
    """Motor torque through the spool with the route as a plain efficiency: tau r_spool / (d_mount eta) [N m].

    Ignores the friction that the *pretension* itself creates in the bends (see :func:`drive_loads`).
    """
    return np.asarray(joint_torque_nm, dtype=float) * spool_radius_m / (moment_arm_m * np.asarray(route_eff))


def drive_loads(p: Params, jl: JointLoads) -> DriveLoads:
    """Tensions, motor torque and step rate of every joint from its torque history (see module docstring)."""
    n = p.joints.count
    m = p.joints.tendon_moment_arm_mm * MM
    r = p.spool.drum_diameter_mm / 2 * MM
    T0 = p.cable.pretension_n
    E = p.cable.youngs_modulus_gpa * 1e9
    d = p.cable.diameter_mm * MM
    mu_g = p.guides.mu_ptfe
    wrap = 2 * math.pi * p.spool.wraps
    full_step = math.radians(p.motor.full_step_deg)
    routes = {(rt.joint, rt.side): rt for rt in cable_routes(p)}
    bend = np.array([[routes[(j, s)].total_bend_rad for s in (1, -1)] for j in range(n)])
    length = np.array([[routes[(j, s)].length_mm * MM for s in (1, -1)] for j in range(n)])
    shape = jl.torque_nm.shape
    tl, tr, tt, ts, tm, comp, cap = (np.zeros(shape) for _ in range(7))
    for j in range(n):
        kl = cable_stiffness_n_m(E, d, length[j, 0])
        kr = cable_stiffness_n_m(E, d, length[j, 1])
        tau = jl.torque_nm[:, j]
        a, b = pull_pull_tensions(tau, m, T0, kl, kr)          # left pulls for positive torque
        tl[:, j], tr[:, j] = a, b
        toward = jl.joint_rate_rad_s[:, j] >= 0.0              # left cable moves toward the spool
        fl = np.where(toward, np.exp(mu_g * bend[j, 0]), np.exp(-mu_g * bend[j, 0]))
        fr = np.where(toward, np.exp(-mu_g * bend[j, 1]), np.exp(mu_g * bend[j, 1]))
        sl, sr = a * fl, b * fr
        tt[:, j] = np.maximum(sl, sr)
        ts[:, j] = np.minimum(sl, sr)
        alpha_m = jl.joint_accel_rad_s2[:, j] * m / r
        tm[:, j] = (sl - sr) * r + p.motor.rotor_inertia_kg_m2 * alpha_m
        k_t = np.where(a >= b, kl, kr)
        comp[:, j] = (np.maximum(a, b) - T0) / (k_t * m)
        cap[:, j] = ts[:, j] * float(tension_ratio(p.spool.mu_cable_drum, wrap)) / np.maximum(tt[:, j], 1e-12)
    rate = full_step_rate(jl.joint_rate_rad_s, m, r, full_step)
    return DriveLoads(tl, tr, tt, ts, tm, rate, bend, length, comp, cap, np.exp(-mu_g * bend.max(axis=1)))


def cable_strain(p: Params, tension_n) -> np.ndarray:
    """Cable strain T / (E A) [-] on the full section."""
    return np.asarray(tension_n, dtype=float) / (p.cable.youngs_modulus_gpa * 1e9 * cable_area_m2(p.cable.diameter_mm * MM))


# ----------------------------------------------------------------------------------------------- sensitivity
UNCERTAIN_COEFFICIENTS = ("hydro.body_added_mass_coefficient", "hydro.body_drag_coefficient",
                          "hydro.fin_added_mass_coefficient", "hydro.fin_lift_slope_factor",
                          "hydro.fin_drag_coefficient_90", "hydro.fin_normal_coefficient_max",
                          "spool.mu_cable_drum", "guides.mu_ptfe",
                          "cable.youngs_modulus_gpa", "link_mass_scale")


def load_outputs(p: Params, link_masses=None, mass_scale: float = 1.0) -> dict[str, float]:
    """The headline outputs of the load model: worst joint's peak torque, tension, motor torque, and the
    capstan's worst holding capacity."""
    jl = joint_loads(p, link_masses, mass_scale)
    dl = drive_loads(p, jl)
    return {"peak_joint_torque_nm": float(jl.peak_torque_nm.max()),
            "peak_cable_tension_n": float(dl.peak_tension_n.max()),
            "peak_motor_torque_nm": float(dl.peak_motor_torque_nm.max()),
            "min_capstan_capacity": float(dl.capstan_capacity.min())}


def sensitivity_table(p: Params, coefficients=UNCERTAIN_COEFFICIENTS, link_masses=None,
                      rel_step: float = 0.05) -> dict[str, dict[str, float]]:
    """d log(output) / d log(coefficient) by central differences at +/- ``rel_step`` (elasticities, [-]).

    ``link_mass_scale`` scales the link masses and inertias. Outputs that are zero at either step (e.g. a slack
    side's capacity) give an elasticity of 0 for that pair, never NaN.
    """
    out: dict[str, dict[str, float]] = {}
    lo_f, hi_f = 1 - rel_step, 1 + rel_step
    for key in coefficients:
        if key == "link_mass_scale":
            y_lo, y_hi = load_outputs(p, link_masses, lo_f), load_outputs(p, link_masses, hi_f)
        else:
            v = get_key(p, key)
            y_lo = load_outputs(replace_key(p, key, v * lo_f), link_masses)
            y_hi = load_outputs(replace_key(p, key, v * hi_f), link_masses)
        row = {}
        for name in y_lo:
            a, b = y_lo[name], y_hi[name]
            row[name] = math.log(b / a) / math.log(hi_f / lo_f) if a > 0 and b > 0 else 0.0
        out[key] = row
    return out
