"""The report's plots, recomputed from the models in ``physics/``; each function returns PNG bytes and the
numbers it drew (so the page and the tests can quote them).

Matplotlib is used through its object API on the Agg canvas (no pyplot, no global state, no display).
"""
from __future__ import annotations

import io
import math
from dataclasses import dataclass, field

import numpy as np

from swiftfin.physics import capstan, efficiency, servo_gear
from swiftfin.physics.kinematics import absolute_tangent_angles_rad, wave_from_params
from swiftfin.core.schema import Params

INK = "#1f2a37"
GRID = "#d9dee5"
JOINT_COLORS = ("#1f77b4", "#e07b1a", "#2a9d5c", "#c0392b", "#8e44ad", "#7f8c8d", "#b8860b", "#17becf")
DPI = 140

# The paper's own inputs for the servo-gear model of §2.2 (as in physics/paper_audit.py)
PAPER_POWER_W = 2.16            # Table 2, at 3 Hz
PAPER_FREQUENCY_HZ = 3.0
SERVO_J_KG_M2 = 5e-6            # §2.2.2
SERVO_THETA0_RAD = 0.96         # §2.2.2 (55 deg)
SERVO_BACKLASH_RAD = 0.0175     # §2.2.2 (1 deg)
SERVO_RESTITUTION = 0.7         # §2.2.2
SERVO_MU_G, SERVO_PRESSURE_ANGLE_RAD, SERVO_Z1, SERVO_Z2, SERVO_STAGES = 0.08, math.radians(20.0), 12, 48, 3
PAPER_BACKLASH_3HZ_W = 0.046    # eq. 12 as printed
CONTACT_DT_RATIO = 0.5          # §2.3.4: dT / T_avg of eq. 26


@dataclass
class Plot:
    """A rendered plot: PNG bytes, a caption, and the numbers drawn (for the page and the tests)."""
    png: bytes
    caption: str
    data: dict = field(default_factory=dict)


def _figure(w_in: float, h_in: float):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w_in, h_in), dpi=DPI)
    fig.patch.set_facecolor("white")
    return fig


def _style(ax):
    ax.grid(True, color=GRID, lw=0.7)
    ax.set_axisbelow(True)
    for s in ("top", "right"):
        ax.spines[s].set_visible(False)
    for s in ("left", "bottom"):
        ax.spines[s].set_color("#8a94a3")
    ax.tick_params(colors=INK, labelsize=9)
    ax.xaxis.label.set_color(INK)
    ax.yaxis.label.set_color(INK)
    ax.title.set_color(INK)


def _line_points_px(ax, per_segment: int = 24) -> np.ndarray:
    """Every drawn line of ``ax`` as points in display pixels, densified along each segment (so a line that
    crosses a box without a vertex in it is still seen)."""
    pts = []
    t = np.linspace(0.0, 1.0, per_segment)[None, :, None]
    for line in ax.get_lines():
        if not line.get_visible():
            continue
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        if len(xy) == 1:
            pts.append(xy)
        elif len(xy) > 1:      # every segment a to b at per_segment points, a and b included
            a, b = xy[:-1, None, :], xy[1:, None, :]
            pts.append((a + t * (b - a)).reshape(-1, 2))
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def _boxes_meet(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def _fixed_boxes(fig, ax, renderer) -> list:
    """What a legend of ``ax`` must not cover besides its lines: every other axes with its labels, and the
    axis labels of ``ax`` (none of them moves with the legend)."""
    boxes = [other.get_tightbbox(renderer) for other in fig.axes if other is not ax]
    boxes += [axis.get_tightbbox(renderer) for axis in (ax.xaxis, ax.yaxis)]
    return [b for b in boxes if b is not None]


def _legend_conflicts(fig, ax, renderer, fixed: list | None = None, pts: np.ndarray | None = None) -> int:
    """How much the legend of ``ax`` covers: plotted points under it, plus one for each other axes (with its
    labels) or own axis label it meets. ``fixed`` (:func:`_fixed_boxes`) and ``pts`` (:func:`_line_points_px`),
    when given, are those of ``ax`` already measured."""
    leg = ax.get_legend()
    box = leg.get_window_extent(renderer)
    pts = _line_points_px(ax) if pts is None else pts
    n = int(((pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)).sum())
    fixed = _fixed_boxes(fig, ax, renderer) if fixed is None else fixed
    return n + sum(_boxes_meet(box, b) for b in fixed)


def legend_overlaps(fig) -> list[tuple[str, int]]:
    """(axes title, what its legend covers) for every legend that covers plotted data, another plot or an
    axis's labels (see :func:`_legend_conflicts`)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    out = []
    for ax in fig.axes:
        if ax.get_legend() is None:
            continue
        n = _legend_conflicts(fig, ax, renderer)
        if n:
            out.append((ax.get_title(loc="left") or ax.get_title(), n))
    return out


_LEGEND_SPOTS = ("best", "upper right", "upper left", "lower left", "lower right", "center right", "center left",
                 "upper center", "lower center")


def _place_legends(fig) -> None:
    """Every legend where it covers no plotted line, no other plot and no axis label: the first free spot
    inside the axes, else right of them, else below them (the saved picture grows to hold it)."""
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        kw = {"fontsize": leg.get_texts()[0].get_fontsize() if leg.get_texts() else 8, "frameon": True,
              "framealpha": 0.92, "edgecolor": GRID}
        ncol = getattr(leg, "_ncols", 1)
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        tight = ax.get_tightbbox(renderer)
        W, H = fig.bbox.width, fig.bbox.height
        below = (ax.get_position().x0, (tight.y0 - 6) / H)
        candidates = [dict(loc=spot, ncol=ncol) for spot in _LEGEND_SPOTS]
        candidates += [dict(loc="upper left", bbox_to_anchor=((tight.x1 + 6) / W, ax.get_position().y1),
                            bbox_transform=fig.transFigure, borderaxespad=0.0, ncol=1),
                       dict(loc="upper left", bbox_to_anchor=below, bbox_transform=fig.transFigure,
                            borderaxespad=0.0, ncol=max(ncol, 2))]
        best = None
        fixed, pts = _fixed_boxes(fig, ax, renderer), _line_points_px(ax)
        for c in candidates:
            ax.legend(**kw, **c)       # the legend lays itself out for its extent: no draw of the figure needed
            n = _legend_conflicts(fig, ax, renderer, fixed, pts)
            if best is None or n < best[0]:
                best = (n, c)
            if n == 0:
                break
        if best[0]:
            ax.legend(**kw, **best[1])


def _png(fig) -> bytes:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    _place_legends(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, facecolor="white", bbox_inches="tight", pad_inches=0.08)
    return buf.getvalue()


# ----------------------------------------------------------------------------------------------- Figure 8
def efficiency_curves(p: Params, frequency_hz: np.ndarray) -> dict[str, np.ndarray]:
    """Transmission efficiency against tail-beat frequency: the paper's fits and the models of physics/.

    * ``capstan_paper_fit``: eq. 31. ``servo_paper_fit``: eq. 32.
    * ``capstan_model_paper``: eq. 28 with the paper's §2.3 inputs and the guides' own eq. 25 (two 90 deg PTFE
      bends): eta_c (eq. 26) x e^(-mu pi/2)^2 x eta_cable. No term of the model depends on frequency.
    * ``capstan_model_design_best`` / ``_worst``: eq. 28 for this design's cable routes (the total bend of each
      joint's route from layout/geometry.py, swiftfin.layout.loads.drive_loads), best and worst joint.
    * ``servo_model_derived``: eq. 18 with the three-stage mesh efficiency of eq. 4-5 and the backlash power
      derived from eq. 6-8 at the §2.2.2 inputs; P_mech = P0 f with P0 = 2.16 W / 3 Hz (the paper's operating
      point). Friction and inertia terms need Table 1's constants, which the paper leaves blank: omitted.
    * ``servo_model_as_printed``: the same with eq. 12's backlash as printed (0.046 W at 3 Hz), scaled as f^3.
    """
    from swiftfin.layout.loads import drive_loads, joint_loads

    f = np.asarray(frequency_hz, float)
    eta_c_paper = capstan.contact_efficiency(0.15, CONTACT_DT_RATIO)
    cap_paper = capstan.capstan_efficiency(eta_c_paper, float(capstan.guide_efficiency(0.05, math.pi / 2)), 2, 0.98)
    eta_c = capstan.contact_efficiency(p.spool.mu_dynamic, CONTACT_DT_RATIO)
    route = drive_loads(p, joint_loads(p, n_samples=64, n_strips=120)).route_efficiency
    cap_design = eta_c * np.asarray(route) * p.cable.eta_hysteresis
    train = servo_gear.train_efficiency(
        servo_gear.mesh_efficiency(SERVO_MU_G, SERVO_PRESSURE_ANGLE_RAD, SERVO_Z1, SERVO_Z2), SERVO_STAGES)
    p_mech = PAPER_POWER_W / PAPER_FREQUENCY_HZ * f
    p_bl = servo_gear.backlash_power(SERVO_J_KG_M2, f, SERVO_THETA0_RAD, SERVO_BACKLASH_RAD, SERVO_RESTITUTION)
    p_bl_printed = PAPER_BACKLASH_3HZ_W * (f / PAPER_FREQUENCY_HZ) ** 3
    ones = np.ones_like(f)
    return {
        "frequency_hz": f,
        "capstan_paper_fit": efficiency.capstan_efficiency_curve(f),
        "servo_paper_fit": efficiency.servo_efficiency_fit(f),
        "capstan_model_paper": cap_paper * ones,
        "capstan_model_design_best": float(cap_design.max()) * ones,
        "capstan_model_design_worst": float(cap_design.min()) * ones,
        "servo_model_derived": servo_gear.servo_efficiency(train, p_mech, p_bl, 0.0, 0.0),
        "servo_model_as_printed": servo_gear.servo_efficiency(train, p_mech, p_bl_printed, 0.0, 0.0),
    }


def efficiency_plot(p: Params) -> Plot:
    f = np.linspace(0.5, 10.0, 200)
    c = efficiency_curves(p, f)
    f_design = p.swimming.tail_beat_frequency_hz
    fig = _figure(8.6, 4.4)
    gs = fig.add_gridspec(1, 2, width_ratios=(1.7, 1.0), wspace=0.28, left=0.075, right=0.985, top=0.88, bottom=0.13)
    ax = fig.add_subplot(gs[0])
    _style(ax)
    cap, srv = "#1f77b4", "#c0392b"
    ax.plot(f, c["capstan_paper_fit"], color=cap, lw=2.2, label="capstan, paper fit (eq. 31)")
    ax.fill_between(f, c["capstan_model_design_worst"], c["capstan_model_design_best"], color=cap, alpha=0.18,
                    lw=0, label="capstan, model eq. 28, this design (joints' routes)")
    ax.plot(f, c["capstan_model_paper"], color=cap, lw=1.5, ls="--", label="capstan, model eq. 28, paper inputs")
    ax.plot(f, c["servo_paper_fit"], color=srv, lw=2.2, label="servo-gear, paper fit (eq. 32)")
    ax.plot(f, c["servo_model_derived"], color=srv, lw=1.5, ls="--", label="servo-gear, model eq. 18 (derived backlash)")
    ax.plot(f, c["servo_model_as_printed"], color=srv, lw=1.5, ls=":", label="servo-gear, eq. 18, backlash as printed")
    ax.axvline(f_design, color="#555", lw=1, ls="-.")
    ax.text(f_design + 0.12, 0.985, f"design point {f_design:g} Hz", color="#555", fontsize=8.5, rotation=90,
            va="top")
    ax.set_xlim(f[0], f[-1])
    ax.set_ylim(0.5, 1.0)
    ax.set_xlabel("tail-beat frequency [Hz]")
    ax.set_ylabel("transmission efficiency [-]")
    ax.set_title("Transmission efficiency (paper Fig. 8, recomputed)", fontsize=10.5, loc="left")
    ax.legend(fontsize=7.6, loc="lower left", frameon=True, framealpha=0.92, edgecolor=GRID)
    ax2 = fig.add_subplot(gs[1])
    _style(ax2)
    g_fit = c["capstan_paper_fit"] / c["servo_paper_fit"]
    g_mod = c["capstan_model_paper"] / c["servo_model_derived"]
    g_pr = c["capstan_model_paper"] / c["servo_model_as_printed"]
    ax2.plot(f, g_fit, color=INK, lw=2.2, label="paper fits (eq. 30)")
    ax2.plot(f, g_mod, color=INK, lw=1.5, ls="--", label="models, derived backlash")
    ax2.plot(f, g_pr, color=INK, lw=1.5, ls=":", label="models, backlash as printed")
    ax2.axhline(1.0, color="#888", lw=0.8)
    ax2.axvline(f_design, color="#555", lw=1, ls="-.")
    ax2.set_xlim(f[0], f[-1])
    ax2.set_xlabel("tail-beat frequency [Hz]")
    ax2.set_ylabel("capstan / servo-gear  \u0393 [-]")
    ax2.set_title("Efficiency ratio \u0393(f)", fontsize=10.5, loc="left")
    ax2.legend(fontsize=7.6, loc="upper left", frameon=True, framealpha=0.92, edgecolor=GRID)
    at = {k: float(np.interp(f_design, f, v)) for k, v in c.items() if k != "frequency_hz"}
    caption = (f"At {f_design:g} Hz the paper's fits give \u03b7 = {at['capstan_paper_fit']:.3f} (capstan) and "
               f"{at['servo_paper_fit']:.3f} (servo-gear), \u0393 = {at['capstan_paper_fit'] / at['servo_paper_fit']:.3f}. "
               f"The models they claim to fit do not reproduce them: eq. 28 with the paper's inputs gives a flat "
               f"{at['capstan_model_paper']:.3f} (this design's routes: {at['capstan_model_design_worst']:.3f}"
               f"\u2013{at['capstan_model_design_best']:.3f}), and eq. 18 with the backlash derived from eq. 6\u20138 stays at "
               f"{at['servo_model_derived']:.3f}: with the paper's inputs the backlash loss is negligible. "
               f"P_mech = P0 f with P0 = {PAPER_POWER_W:g} W / {PAPER_FREQUENCY_HZ:g} Hz; friction and inertia terms omitted "
               "(Table 1 of the paper gives no constants).")
    return Plot(_png(fig), caption, {"at_design": at, "curves": c})


# ----------------------------------------------------------------------------------------------- one tail-beat
def tail_beat(p: Params, n_samples: int = 256) -> dict:
    """Relative joint angles, the paper's eq. 47 command and the motors' full-step rates over one period."""
    from swiftfin.layout.loads import drive_loads, joint_loads

    jl = joint_loads(p, n_samples=n_samples, n_strips=120)
    dl = drive_loads(p, jl)
    L = p.body.length_mm / 1000.0
    wave = wave_from_params(p.swimming, L)
    xs = np.asarray(p.joints.stations_fraction[:p.joints.count]) * L
    ab = absolute_tangent_angles_rad(wave, xs, jl.t_s)
    return {"t_s": jl.t_s, "period_s": 1.0 / p.swimming.tail_beat_frequency_hz,
            "joint_angle_deg": np.degrees(jl.joint_angle_rad), "paper_eq47_deg": np.degrees(ab),
            "full_steps_s": dl.step_rate_full_steps_s, "microsteps_s": dl.step_rate_full_steps_s * p.motor.microsteps,
            "motor_torque_nm": dl.motor_torque_nm}


def joint_plot(p: Params) -> Plot:
    d = tail_beat(p)
    T = d["period_s"]
    phase = d["t_s"] / T
    n = d["joint_angle_deg"].shape[1]
    fig = _figure(8.6, 4.4)
    gs = fig.add_gridspec(1, 2, wspace=0.26, left=0.075, right=0.985, top=0.88, bottom=0.13)
    ax = fig.add_subplot(gs[0])
    ax2 = fig.add_subplot(gs[1])
    for a in (ax, ax2):
        _style(a)
    for j in range(n):
        col = JOINT_COLORS[j % len(JOINT_COLORS)]
        ax.plot(phase, d["joint_angle_deg"][:, j], color=col, lw=2, label=f"joint {j + 1}")
        ax.plot(phase, d["paper_eq47_deg"][:, j], color=col, lw=1, ls=":", alpha=0.9)
        ax2.plot(phase, d["full_steps_s"][:, j], color=col, lw=2, label=f"joint {j + 1}: peak "
                 f"{d['full_steps_s'][:, j].max():.0f} /s")
    ax.plot([], [], color="#666", lw=1, ls=":", label="paper eq. 47 (absolute slope)")
    ax.set_xlim(0, 1)
    ax.set_xlabel(f"time / period  (period {1000 * T:.0f} ms)")
    ax.set_ylabel("joint angle [deg]")
    ax.set_title("Joint angles over one tail-beat (relative, solid)", fontsize=10.5, loc="left")
    ax.legend(fontsize=7.6, ncol=2, loc="lower left", frameon=True, framealpha=0.92, edgecolor=GRID)
    ax2.set_xlim(0, 1)
    ax2.set_ylim(bottom=0)
    ax2.set_xlabel("time / period")
    ax2.set_ylabel(f"motor full-step rate [steps/s]  (x{p.motor.microsteps} microsteps)")
    ax2.set_title("Motor step rates", fontsize=10.5, loc="left")
    ax2.legend(fontsize=7.6, loc="upper right", frameon=True, framealpha=0.92, edgecolor=GRID)
    amp = np.abs(d["joint_angle_deg"]).max(axis=0)
    peak = d["full_steps_s"].max(axis=0)
    caption = (f"At {p.swimming.tail_beat_frequency_hz:g} Hz and a {1000 * p.swimming.tail_amplitude_m:g} mm tail "
               "amplitude the joints turn " + ", ".join(f"{a:.1f}\u00b0" for a in amp) + " (joints 1\u2013"
               f"{n}); the motors peak at " + ", ".join(f"{r:.0f}" for r in peak) +
               f" full steps/s ({p.motor.microsteps * peak.max():.0f} microsteps/s at most). Dotted: the paper's "
               "eq. 47 command (the wave's absolute slope), which is not what a joint between two links must do.")
    return Plot(_png(fig), caption, {"amplitude_deg": amp, "peak_full_steps_s": peak})


# ----------------------------------------------------------------------------------------------- body wave
def wave_plot(p: Params, n_phases: int = 8) -> Plot:
    """The body wave y(x, t) = A(x) sin(kx - wt): envelope, snapshots and the joint stations."""
    from swiftfin.layout.geometry import hull_end_mm, joint_stations_mm

    L = p.body.length_mm / 1000.0
    wave = wave_from_params(p.swimming, L)
    x = np.linspace(0.0, L, 300)
    A = wave.envelope_m(x)
    xs = np.asarray(joint_stations_mm(p)) / 1000.0
    fig = _figure(8.6, 3.5)
    ax = fig.add_axes((0.075, 0.15, 0.91, 0.72))
    _style(ax)
    ax.fill_between(x * 1000, -A * 1000, A * 1000, color="#1f77b4", alpha=0.12, lw=0, label="envelope \u00b1A(x)")
    ax.plot(x * 1000, A * 1000, color="#1f77b4", lw=1.6)
    ax.plot(x * 1000, -A * 1000, color="#1f77b4", lw=1.6)
    T = 1.0 / wave.frequency_hz
    for k in range(n_phases):
        y = wave.lateral_m(x, k * T / n_phases)
        ax.plot(x * 1000, y * 1000, color="#2a3f5f", lw=0.9, alpha=0.35 + 0.5 * k / n_phases)
    nodes = np.concatenate([[0.0], xs, [L]])
    yn = wave.lateral_m(nodes, 0.0)
    ax.plot(nodes * 1000, yn * 1000, color="#e07b1a", lw=2, marker="o", ms=4, label="links (chords), t = 0")
    for j, s in enumerate(xs):
        ax.axvline(s * 1000, color=JOINT_COLORS[j % len(JOINT_COLORS)], lw=1, ls="--")
        ax.text(s * 1000, A.max() * 1000 * 1.08, f"J{j + 1}", ha="center", fontsize=8.5,
                color=JOINT_COLORS[j % len(JOINT_COLORS)], bbox=dict(fc="white", ec="none", pad=1.0))
    ax.axvline(hull_end_mm(p), color="#888", lw=0.8, ls=":")
    ax.text(hull_end_mm(p), -A.max() * 1000 * 1.15, "hull end", ha="center", fontsize=8, color="#666",
            bbox=dict(fc="white", ec="none", pad=1.0))
    ax.set_xlim(0, L * 1000)
    ax.set_ylim(-A.max() * 1000 * 1.25, A.max() * 1000 * 1.25)
    ax.set_xlabel("station from the nose [mm]")
    ax.set_ylabel("lateral displacement [mm]")
    ax.set_title(f"Body wave: A(x) = c\u2080 + c\u2081x + c\u2082x\u00b2, \u03bb = {p.swimming.wavelength_body_lengths:g} L, "
                 f"{n_phases} snapshots over one period", fontsize=10.5, loc="left")
    ax.legend(fontsize=7.6, loc="upper left", frameon=True, framealpha=0.92, edgecolor=GRID)
    amp_j = wave.envelope_m(xs)
    caption = (f"Envelope c\u2082 = {wave.c2_per_m:.3f} 1/m (A(L) = {1000 * p.swimming.tail_amplitude_m:g} mm), "
               f"wavenumber k = {wave.wavenumber_rad_m:.2f} rad/m. Envelope at the joints: " +
               ", ".join(f"{1000 * a:.1f} mm" for a in amp_j) + ".")
    return Plot(_png(fig), caption, {"envelope_at_joints_m": amp_j, "c2_per_m": wave.c2_per_m})


# ----------------------------------------------------------------------------------------------- trade-offs
PARETO_MARKERS = "osD^v<>pXh*"


def pareto_plot(front: dict) -> Plot:
    """The Pareto front of ``swiftfin solve`` (its JSON's ``front``): predicted speed against electrical power,
    coloured by mass, one marker per rule of least margin."""
    pts = list(front.get("points") or [])
    fig = _figure(7.2, 4.3)
    ax = fig.add_subplot(1, 1, 1)
    _style(ax)
    counts: dict = {}
    for q in pts:
        counts[q["binding"]] = counts.get(q["binding"], 0) + 1
    rules = sorted(counts, key=lambda r: -counts[r])
    mass = [q["mass_kg"] for q in pts]
    lo, hi = (min(mass), max(mass)) if mass else (0.0, 1.0)
    hi = hi if hi > lo else lo + 1e-6
    sc = None
    for k, r in enumerate(rules):
        sel = [q for q in pts if q["binding"] == r]
        sc = ax.scatter([q["power_w"] for q in sel], [q["speed_m_s"] for q in sel], c=[q["mass_kg"] for q in sel],
                        vmin=lo, vmax=hi, cmap="viridis", marker=PARETO_MARKERS[k % len(PARETO_MARKERS)],
                        edgecolors=INK, linewidths=0.3, label=f"{r} ({len(sel)})")
    if sc is not None:
        fig.colorbar(sc, ax=ax, label="mass of motors and components [kg]")
        ax.legend(title="rule of least margin", fontsize=7, title_fontsize=7)
    ax.set_xlabel("electrical power at the design gait [W]")
    ax.set_ylabel("predicted speed [m/s]")
    caption = (f"Pareto front of swiftfin solve: {len(pts)} of its {front.get('size', len(pts))} designs (of "
               f"{front.get('passing', '?')} passing among {front.get('sampled', '?')} sampled), speed against "
               f"power, coloured by the mass of the motors and components, marked by the rule with the least margin.")
    return Plot(_png(fig), caption, {"points": len(pts), "rules": counts})
