"""An audit of the SwiftFin paper: every number it derives from its own inputs, recomputed.

Each :class:`AuditEntry` holds the paper's value, the recomputed value and whether the paper's value holds.
Tolerance (``TOLERANCE``): a value holds when it is within 1 % of the recomputed one or within half a unit of
the last digit the paper quotes, whichever is wider. Physical-consistency entries (a bound, not a value) say
so in their reason. Entries that the paper's data cannot decide have ``holds = None``.

The inputs below are the paper's own (section and equation in each comment); nothing is fitted.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from swiftfin.physics import capstan, efficiency, fidelity, performance, servo_gear, strouhal
from swiftfin.physics.kinematics import absolute_tangent_angles_rad, joint_resolution_rad, relative_joint_angles_rad, \
    wave_from_params

TOLERANCE = "holds if |paper - recomputed| <= max(1 % of the paper's value, half a unit of its last quoted digit)"

# --- the paper's inputs
L_M = 0.52                 # Table 2, body length
MASS_KG = 1.2              # Table 2
F_HZ = 3.0                 # Table 2, max tail-beat frequency (the operating point of §2)
U_M_S = 1.97               # Table 2, max speed
P_W = 2.16                 # Table 2 / §5.6, max power
A_MAX_M = 0.10             # §3.1, tail amplitude A(L)
LAMBDA_BL = 1.25           # §3.2
R_TOWED_N = 3.72           # §5.5, rigid-body drag at 1.0 m/s
R_ACTIVE_N = 2.70          # §5.5
U_TOW_M_S = 1.0            # §5.5
ETA_QP = 0.63              # §5.4
# §2.2.2 numerical example
J_EQ = 5e-6
THETA0_RAD = 0.96          # "55 deg = 0.96 rad"
PHI_B_RAD = 0.0175         # "1 deg = 0.0175 rad"
E_REST = 0.7
# §2.2.1
MU_G, ALPHA_P, Z1, Z2 = 0.08, math.radians(20.0), 12, 48
# §2.3
MU_DRUM, WRAP = 0.35, 4 * math.pi
MU_PTFE, BEND_90 = 0.05, math.pi / 2
MU_D, DT_RATIO = 0.15, 0.5
ETA_C, ETA_PULLEY_29, ETA_CABLE = 0.95, 0.95, 0.98
# §2.5
THETA0_DEG = 55.0
PHI_B_DEG = 1.0
STEP_DEG = 1.8 / 16
STRETCH_TERM_29 = 0.10     # eq. 40's (dL / r_drum) term: with r_drum = 10 mm it is dL = 1 mm, i.e. 0.10 rad
SPOOL_R_M, MOMENT_ARM_M = 0.010, 0.015   # Table 2 (20 mm spool), §3.4 (15 mm)


@dataclass(frozen=True)
class AuditEntry:
    entry_id: str
    where: str
    quantity: str
    paper: float | None
    recomputed: float
    unit: str
    holds: bool | None
    reason: str

    def to_dict(self) -> dict:
        return asdict(self)


def agrees(paper: float, recomputed: float, decimals: int) -> bool:
    """The audit's tolerance: within 1 % or half a unit of the paper's last quoted digit (``decimals`` places)."""
    return abs(paper - recomputed) <= max(0.01 * abs(paper), 0.5 * 10.0 ** (-decimals)) + 1e-12


def _e(entry_id, where, quantity, paper, recomputed, unit, reason, decimals=None, holds=None):
    recomputed = float(recomputed)
    if holds is None and decimals is not None and paper is not None:
        holds = agrees(paper, recomputed, decimals)
    return AuditEntry(entry_id, where, quantity, paper, recomputed, unit, holds, reason)


def audit_entries() -> list[AuditEntry]:
    """Every audited number, in the order of the paper."""
    from swiftfin.core.schema import Params   # the default design = the paper's SwiftFin (for eq. 47 and the loads)

    out: list[AuditEntry] = []
    add = out.append
    # ---------------------------------------------------------------- §2.2 servo-gear
    eta_g = servo_gear.mesh_efficiency(MU_G, ALPHA_P, Z1, Z2)
    add(_e("eq5_mesh_efficiency", "eq. 5", "gear mesh efficiency", 0.972, eta_g, "-",
           "1 - pi 0.08 / cos 20 deg x (1/12 + 1/48) = 1 - 0.0279", 3))
    add(_e("eq5_three_stages", "§2.2.1", "three-stage efficiency", 0.918, servo_gear.train_efficiency(eta_g, 3), "-",
           "0.9721^3", 3))
    p_printed = servo_gear.paper_backlash_power(J_EQ, F_HZ, THETA0_RAD, PHI_B_RAD, E_REST)
    p_derived = servo_gear.backlash_power(J_EQ, F_HZ, THETA0_RAD, PHI_B_RAD, E_REST)
    add(_e("eq9_factor", "eq. 6-9", "backlash power at the §2.2.2 inputs, eq. 9 as printed vs derived",
           p_printed, p_derived, "W",
           "2 f E_impact with E = 1/2 J w^2 (1 - e^2), w^2 = 2 alpha phi_b gives 2 f J alpha phi_b (1 - e^2): eq. 9 "
           "drops the 2 (and eq. 7's tau_m/J_m is replaced by eq. 8's kinematic acceleration)", holds=False))
    add(_e("eq12_backlash_power", "eq. 10-12", "backlash power at 3 Hz (arithmetic of eq. 10)", 0.046, p_printed, "W",
           "3 x 5e-6 x 355.3 x 0.96 x 0.0175 x 0.51 = 4.57e-5 W, not 0.046 W (a factor 1000)", 3))
    add(_e("backlash_share_3hz", "§2.2.2", "backlash loss / 2.16 W at 3 Hz", 0.021, p_derived / P_W, "-",
           "with the derived 9.1e-5 W: 0.004 % of the power, not 2.1 %", 3))
    add(_e("backlash_6hz", "§2.2.2", "backlash power at 6 Hz", 0.37,
           servo_gear.backlash_power(J_EQ, 6.0, THETA0_RAD, PHI_B_RAD, E_REST), "W",
           "f^3 scaling of the derived 9.1e-5 W: x8 = 7.3e-4 W", 2))
    add(_e("backlash_share_6hz", "§2.2.2", "backlash loss / 2.16 W at 6 Hz", 0.17,
           servo_gear.backlash_power(J_EQ, 6.0, THETA0_RAD, PHI_B_RAD, E_REST) / P_W, "-",
           "0.034 %, not 17 %", 2))
    add(_e("backlash_penalty_claim", "abstract, §1, §7.1", "backlash efficiency penalty at 2-4 Hz (lower end)", 0.12,
           servo_gear.backlash_power(J_EQ, 4.0, THETA0_RAD, PHI_B_RAD, E_REST) / P_W, "-",
           "the paper's own example inputs give at most 0.01 % of 2.16 W at 4 Hz; 12-28 % does not follow", 2))
    add(_e("eq14_coulomb_coefficient", "eq. 14-15", "Coulomb friction power / (f theta0 tau_c)", 8.0,
           servo_gear.friction_power(1.0, 0.0, 1.0, 1.0), "-",
           "<|theta_dot|> = (2/pi) 2 pi f theta0 = 4 f theta0: eq. 14 has 4/pi (and eq. 15 copies its 8); "
           "the viscous term 2 pi^2 f^2 theta0^2 b is right", 0))
    add(_e("eq16_reflected_load", "eq. 16", "load inertia 1e-6 kg m^2 referred to the motor through N = 100", 1e-2,
           servo_gear.load_inertia_at_motor(1e-6, 100.0), "kg m^2",
           "a reduction divides the load's inertia by N^2 at the motor (1e-10); N^2 multiplies the motor's inertia "
           "seen at the output", holds=False))
    add(_e("eq17_coefficient", "eq. 17", "inertia power / (f^3 theta0^2 J)", 4 * math.pi**2,
           servo_gear.inertia_power(1.0, 1.0, 1.0), "-",
           "the algebra holds; but J_eff (motor side, eq. 16) needs the motor speed N x 2 pi f theta0: use the output "
           "inertia J_load + N^2 J_m with the output amplitude; and it is an upper bound (no energy recovery)", 2))
    # ---------------------------------------------------------------- §2.3 capstan
    add(_e("eq21_tension_ratio", "eq. 21", "e^(0.35 x 4 pi)", 81.5, capstan.tension_ratio(MU_DRUM, WRAP), "-",
           "exponent 4.398 (rounded to 4.40 in the paper): 81.3", 1))
    add(_e("eq25_guide_efficiency", "eq. 25", "e^(-0.05 pi/2)", 0.924, capstan.guide_efficiency(MU_PTFE, BEND_90),
           "-", "0.9245", 3))
    add(_e("eq27_contact_efficiency", "eq. 27", "1 - (2 x 0.15 / pi) asin(0.5)", 0.950,
           capstan.contact_efficiency(MU_D, DT_RATIO), "-", "asin 0.5 = 0.5236: 0.9500", 3))
    add(_e("eq29_arithmetic", "eq. 29", "0.95 x 0.95^2 x 0.98", 0.840,
           capstan.capstan_efficiency(ETA_C, ETA_PULLEY_29, 2, ETA_CABLE), "-", "0.8402", 3))
    eta29 = capstan.capstan_efficiency(ETA_C, float(capstan.guide_efficiency(MU_PTFE, BEND_90)), 2, ETA_CABLE)
    add(_e("eq29_with_eq25", "eq. 25 vs 29", "capstan efficiency with the guides' own eq. 25 (0.924 each)", 0.840,
           eta29, "-", "eq. 29 takes 0.95 per guide where eq. 25 gives 0.924 for a 90 deg PTFE bend: 0.796", 3))
    add(_e("eq33_vs_eq29", "eq. 31/33 vs 28-29", "capstan efficiency at 3 Hz", 0.941,
           capstan.capstan_efficiency(ETA_C, ETA_PULLEY_29, 2, ETA_CABLE), "-",
           "the fit of eq. 31 (and Fig. 8's '> 90 %') starts from 0.95 = eta_c alone; the paper's own total "
           "(eq. 29) is 0.840", 3))
    # ---------------------------------------------------------------- §2.4 curves
    add(_e("eq33", "eq. 33", "eta_capstan(3 Hz)", 0.941, efficiency.capstan_efficiency_curve(3.0), "-",
           "0.95 - 0.009", 3))
    add(_e("eq34", "eq. 34", "eta_servo(3 Hz)", 0.827, efficiency.servo_efficiency_fit(3.0), "-",
           "0.92 - 0.075 - 0.018", 3))
    add(_e("eq35", "eq. 35", "Gamma(3 Hz)", 1.138, efficiency.paper_ratio_at(3.0), "-", "0.941 / 0.827", 3))
    add(_e("gamma_5hz", "§2.4.1", "advantage at 5 Hz", 0.255, efficiency.paper_ratio_at(5.0) - 1, "-",
           "0.935 / 0.745 - 1", 3))
    g8 = float(efficiency.paper_ratio_at(8.0) - 1)
    add(_e("gamma_8hz", "§2.4.1", "advantage at 8 Hz ('exceeds 35 %')", 0.35, g8, "-",
           "0.926 / 0.592 - 1 = 56 %: the claim (a lower bound) holds", holds=g8 > 0.35))
    g_lo = float(efficiency.paper_ratio_at(2.0) - 1)
    add(_e("advantage_range_2_8hz", "§8", "transmission advantage at 2 Hz (paper: 15-35 % at 2-8 Hz)", 0.15, g_lo,
           "-", f"the paper's own fits give {100 * g_lo:.1f} % at 2 Hz to {100 * g8:.0f} % at 8 Hz", 2))
    # ---------------------------------------------------------------- §2.5 fidelity
    rms_servo = float(fidelity.backlash_rms_error(PHI_B_DEG))
    add(_e("eq38_rms", "eq. 37-38", "servo RMS position error for 1 deg backlash", 0.71, rms_servo, "deg",
           "eq. 37's error is +/- phi_b/2 at every instant: RMS phi_b/2 = 0.5 deg, not phi_b/sqrt 2", 2))
    f_servo = float(fidelity.position_fidelity(rms_servo, THETA0_DEG))
    add(_e("eq38_fidelity", "§2.5.1", "servo infidelity 1 - F (paper F = 0.987)", 0.013, 1 - f_servo, "-",
           "0.5/55 = 0.0091 (F = 0.991); compared as 1 - F because 1 % of F near 1 hides a 30 % error", 3))
    add(_e("eq40_arithmetic", "eq. 40", "sqrt(0.1125^2 + 0.10^2) as printed", 0.15,
           math.hypot(STEP_DEG, STRETCH_TERM_29), "-", "0.1505: the arithmetic holds (units do not, next entry)", 2))
    rms_cap = math.hypot(STEP_DEG, math.degrees(STRETCH_TERM_29))
    add(_e("eq40_units", "eq. 39-40", "capstan RMS error with both terms in degrees", 0.15, rms_cap, "deg",
           "0.1125 is degrees but dL/r_drum = 0.10 is radians (1 mm / 10 mm) = 5.73 deg; and at the joint the step "
           "is 0.075 deg (x r/d) with RMS q/sqrt 12, the stretch dL/d_mount", 2))
    f_cap = float(fidelity.position_fidelity(rms_cap, THETA0_DEG))
    add(_e("capstan_fidelity", "§2.5.2", "capstan infidelity 1 - F (paper F = 0.997)", 0.003, 1 - f_cap, "-",
           "5.73/55 = 0.104 (F = 0.896)", 3))
    add(_e("fidelity_ratio", "§2.5.2", "error ratio servo / capstan ('4.7x improvement')", 4.7, rms_servo / rms_cap,
           "-", "0.5 / 5.73: with consistent units the capstan's stretch error is the larger", 1))
    pen = float(-strouhal.strouhal_penalty(0.4, 0.02))
    add(_e("eq42_penalty", "eq. 42", "servo Strouhal efficiency penalty, k_St 0.4, 2 % amplitude error", None, pen,
           "-", "0.4 x 0.02^2 = 0.016 percentage points per cycle (a rate, not cumulative): not 'substantial'",
           holds=False))
    add(_e("amplitude_variation_servo", "§2.5.3", "servo amplitude variation phi_b / theta0", 0.02,
           PHI_B_DEG / THETA0_DEG, "-", "1/55 = 1.8 %", 2))
    # ---------------------------------------------------------------- §3 kinematics
    add(_e("eq45_c2", "eq. 45", "c2 = A_max / L^2", 0.37, A_MAX_M / L_M**2, "1/m", "0.10 / 0.52^2 = 0.3698", 2))
    add(_e("amax_fraction", "§3.1", "A_max / L", 0.19, A_MAX_M / L_M, "-", "0.192", 2))
    lam = LAMBDA_BL * L_M
    add(_e("eq46_wavelength", "eq. 46", "lambda", 0.65, lam, "m", "1.25 x 0.52", 2))
    add(_e("eq46_wavenumber", "eq. 46", "k", 9.67, 2 * math.pi / lam, "rad/m", "2 pi / 0.65 = 9.666", 2))
    p = Params()
    wave = wave_from_params(p.swimming, p.body.length_mm / 1000)
    xs = np.asarray(p.joints.stations_fraction) * L_M
    t = np.linspace(0, 1 / F_HZ, 720, endpoint=False)
    ab = np.degrees(np.abs(absolute_tangent_angles_rad(wave, xs, t)).max(axis=0))
    rel = np.degrees(np.abs(relative_joint_angles_rad(wave, xs, L_M, t)).max(axis=0))
    for j in range(len(xs)):
        add(_e(f"eq47_joint{j + 1}", "eq. 47", f"joint {j + 1} amplitude (default stations): eq. 47's absolute "
               "tangent angle vs the relative angle the joint must make", float(ab[j]), float(rel[j]), "deg",
               "a joint turns one link relative to the one ahead: its command is the difference of the links' yaw "
               "(chords of the wave), not the absolute slope", 1))
    err = np.degrees(np.abs(absolute_tangent_angles_rad(wave, xs, t) - relative_joint_angles_rad(wave, xs, L_M, t)))
    add(_e("eq47_command_error", "eq. 47", "largest error over a cycle and the joints if eq. 47 is the joint "
           "command", 0.0, float(err.max()), "deg", f"worst at joint {int(np.argmax(err.max(axis=0))) + 1}: "
           "amplitude and phase both differ", 1))
    q = math.degrees(joint_resolution_rad(math.radians(1.8), 16, MOMENT_ARM_M, SPOOL_R_M))
    add(_e("table2_resolution_at_joint", "Table 2, eq. 48", "angular resolution at the joint", 0.1125, q, "deg",
           "0.1125 deg is the motor's microstep; through r_spool/d_mount = 10/15 the joint moves 0.075 deg "
           "(eq. 48 itself is right)", 4))
    add(_e("reversals_per_s", "§7.1 vs §1", "reversals per second at 8 Hz", 8.0, 2 * 8.0, "1/s",
           "two per cycle: 2-8 Hz gives 4-16 (as §1 says), not 4-8", 0))
    # ---------------------------------------------------------------- §5 results
    add(_e("speed_bl_s", "abstract, Table 3", "1.97 m/s / 0.52 m", 3.79,
           performance.body_lengths_per_s(U_M_S, L_M), "BL/s", "3.788", 2))
    add(_e("speed_fit", "Fig. 3", "U* = 1.26 f at 3 Hz", 3.79, 1.26 * F_HZ, "BL/s", "3.78", 2))
    st = float(strouhal.strouhal(F_HZ, 2 * A_MAX_M, U_M_S))
    add(_e("strouhal_max_speed", "§5.3, Table 3", "St = f A / U at 3 Hz, A = 2 x 0.10 m, 1.97 m/s", 0.28, st, "-",
           f"0.305 with the peak-to-peak excursion (0.152 with A_max); 0.28 needs A = {0.28 * U_M_S / F_HZ:.3f} m "
           "peak to peak", 2))
    v = performance.wave_speed_m_s(F_HZ, lam)
    add(_e("speed_vs_wave_speed", "§3 vs Table 2", "body-wave speed f lambda, the bound on U", U_M_S, v, "m/s",
           f"slip U/V = {U_M_S / v:.3f} > 1: an undulating swimmer makes thrust only for U < V (Lighthill 1960)",
           holds=U_M_S < v))
    add(_e("drag_reduction_1ms", "§5.5", "(3.72 - 2.70) / 3.72", 0.274,
           performance.relative_reduction(R_TOWED_N, R_ACTIVE_N), "-", "27.4 %", 3))
    add(_e("drag_reduction_mean", "abstract, §5.5", "mean drag reduction across speeds", 0.255,
           performance.relative_reduction(R_TOWED_N, R_ACTIVE_N), "-",
           "only the 1.0 m/s pair is given (27.4 %); the mean over speeds cannot be checked", holds=None))
    add(_e("amplitude_reduction", "§5.8", "(65 - 55) / 65", 0.154, (65 - 55) / 65, "-", "15.4 %", 3))
    eta_qp = performance.quasi_propulsive_efficiency(R_TOWED_N, U_TOW_M_S, P_W)
    add(_e("eta_qp_from_towing", "eq. 49, §5.5", "R_towed U / P at 1.0 m/s with the maximum power 2.16 W", ETA_QP,
           eta_qp, "-", "3.72 W of towing power from 2.16 W electric: above 1, impossible (and P at 1 m/s is lower "
           "still)", 2))
    add(_e("power_for_towed_drag", "§5.5-5.6", "power to overcome 3.72 N at 1.97 m/s (no drag growth)", P_W,
           R_TOWED_N * U_M_S, "W", f"7.33 W at least; with drag ~U^2 it is {R_TOWED_N * U_M_S**3 / U_TOW_M_S**2:.1f} W",
           holds=R_TOWED_N * U_M_S <= P_W))
    add(_e("implied_drag_eta_qp", "eq. 49", "towing drag eta_QP = 63 % implies at 1.97 m/s", R_TOWED_N,
           ETA_QP * P_W / U_M_S, "N", "0.69 N at 1.97 m/s, yet 3.72 N was measured at 1.0 m/s", 2))
    add(_e("power_vs_tunabot", "§5.6", "(4.5 - 2.16) / 4.5", 0.52, performance.relative_reduction(4.5, P_W), "-",
           "52.0 %", 2))
    add(_e("power_vs_openfish", "§5.6", "(3.2 - 2.16) / 3.2", 0.32, performance.relative_reduction(3.2, P_W), "-",
           "32.5 %", 2))
    add(_e("eta_qp_vs_tunabot", "abstract, §5.4", "(63 - 54) / 54", 0.17, performance.relative_improvement(63, 54), "-",
           "16.7 % relative (9 percentage points)", 2))
    add(_e("eta_qp_vs_openfish", "abstract, §5.4", "(63 - 48) / 48", 0.31, performance.relative_improvement(63, 48),
           "-", "31.3 % relative (15 percentage points)", 2))
    # ---------------------------------------------------------------- §6
    cot = performance.cost_of_transport(P_W, MASS_KG, U_M_S)
    add(_e("cot", "§6.2", "COT = P / (m U)", 18.4, cot, "J/(kg m)", "2.16 / (1.2 x 1.97) = 0.914: a factor 20", 1))
    add(_e("cot_vs_tuna", "§6.2", "COT / tuna COT (1.1-2.1, midpoint 1.6)", 12.0, cot / 1.6, "-",
           "with the recomputed COT SwiftFin would beat tuna (0.57x), itself implausible", 0))
    add(_e("cot_closest", "§6.2 vs §1", "Tunabot Flex COT (the paper's §1) vs SwiftFin's 18.4", 18.4, 4.5,
           "J/(kg m)", "the paper's own Tunabot COT 4.5 is 4x lower: 18.4 is not 'the closest approach'",
           holds=False))
    te = performance.transport_economy(U_M_S, P_W)
    add(_e("transport_economy", "abstract, §6.2", "U / P", 0.93, te, "m/J", "1.97 / 2.16 = 0.912", 2))
    add(_e("transport_economy_vs_cot", "§6.2", "1 / (COT m) with the paper's COT 18.4", 0.93,
           1 / (18.4 * MASS_KG), "m/J", "the paper's COT and transport economy disagree by a factor 20", 2))
    rng = performance.range_m(50 * 3600.0, 0.93) / 1000
    add(_e("range_50wh", "§6.2", "range on 50 Wh at 0.93 m/J ('over 160 km')", 160.0, rng, "km",
           "167 km (164 km at 0.912 m/J; 8.2 km at the paper's COT; 14.8 km on the 4.5 Wh battery of Table 2)",
           holds=rng > 160))
    # ---------------------------------------------------------------- load model vs power
    from swiftfin.layout.loads import joint_loads
    jl = joint_loads(p)
    add(_e("load_model_power", "Table 2 vs layout/loads.py", "joint mechanical power at 3 Hz, A = 0.10 m, 1.97 m/s",
           P_W, jl.mean_positive_power_w, "W",
           f"this project's load model (strip added mass, drag, quasi-steady fin) needs "
           f"{jl.mean_positive_power_w / P_W:.0f}x the electric power the paper reports; model-dependent: see "
           "`swiftfin check --loads` for its sensitivities",
           holds=jl.mean_positive_power_w <= P_W))
    return out
