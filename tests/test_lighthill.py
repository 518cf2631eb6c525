"""Lighthill's reactive force at the caudal fin's trailing edge (physics.swim_sim.lighthill_edge_force_n), issue 15.

(a) and (b) are pure: the instantaneous large-amplitude force (Lighthill 1971) for a prescribed small travelling
wave, averaged over a period, against Lighthill's (1960) closed-form mean thrust, and its zero when the wave
runs back at the swimming speed. (c) swims the REAL exported default design in MuJoCo, free in all six degrees
of freedom, at 1, 2 and 3 Hz with and without the reactive force, and prints its speed, stride length and slip
beside published thunniform swimmers. Only what must hold physically is asserted; nothing is tuned to the
published numbers.
"""
from __future__ import annotations

import numpy as np
import pytest

from swiftfin.physics.swim_sim import PUBLISHED_STRIDES, added_mass_per_length_kg_m, lighthill_edge_force_n

RHO = 1000.0
SPAN_M = 0.16                          # about the default fin's span
M_A = added_mass_per_length_kg_m(RHO, SPAN_M)
N_SAMPLES = 720                        # per period: the mean of a trigonometric polynomial is exact


def _travelling_wave_edge(a_m, k_rad_m, omega_rad_s, U_m_s, x_edge_m=0.52, n=N_SAMPLES):
    """The edge of a fish swimming along +X at U, its midline h(x, t) = a sin(k x - omega t) (x from the
    nose back): velocity relative to still water and forward unit tangent, over one period, in the world."""
    t = np.arange(n) / n * 2 * np.pi / omega_rad_s
    ph = k_rad_m * x_edge_m - omega_rad_s * t
    hdot = -a_m * omega_rad_s * np.cos(ph)            # dh/dt
    hx = a_m * k_rad_m * np.cos(ph)                   # dh/dx, toward the tail
    z = np.zeros_like(t)
    V = np.stack([np.full_like(t, U_m_s), hdot, z], axis=1)
    # world position of material point x: (U t - x, h): the forward tangent is -d/dx = (1, -h')
    tau = np.stack([np.ones_like(t), -hx, z], axis=1)
    return V, tau, hdot, hx


def test_a_mean_force_is_lighthills_closed_form_thrust():
    """For a small travelling wave the time mean of the instantaneous force along the swimming direction is
    T = 1/2 m_a [<(dh/dt)^2> - U^2 <(dh/dx)^2>] = m_a a^2 (omega^2 - U^2 k^2) / 4 (Lighthill 1960), to 1e-6;
    its lateral mean is zero."""
    lam = 1.25 * 0.52
    k = 2 * np.pi / lam
    a = 1e-4 / k                                        # slope amplitude a k = 1e-4: the small-amplitude limit
    for f in (1.0, 2.0, 3.0):
        omega = 2 * np.pi * f
        for U in (0.0, 0.2, 0.5 * omega / k, 1.5 * omega / k):
            V, tau, hdot, hx = _travelling_wave_edge(a, k, omega, U)
            F = lighthill_edge_force_n(M_A, V, tau)
            closed = 0.5 * M_A * (a**2 * omega**2 / 2 - U**2 * a**2 * k**2 / 2)
            # the sampled means are the closed form's (uniform samples of one period)
            assert 0.5 * M_A * np.mean(hdot**2 - U**2 * hx**2) == pytest.approx(closed, rel=1e-12)
            assert np.mean(F[:, 0]) == pytest.approx(closed, rel=1e-6), (f, U)
            assert abs(np.mean(F[:, 1])) < 1e-6 * abs(closed)
            assert np.all(F[:, 2] == 0.0)


def test_a_force_is_the_wake_momentum_and_the_edge_pressure():
    """The force at one instant, by hand: a plate edge moving sideways at w through still water, with the
    tangential speed u: F = m w (1/2 w tau - u n), whichever way n points, and no force from motion along the
    span."""
    tau = np.array([1.0, 0.0, 0.0])
    V = np.array([0.3, -0.8, 0.5])                        # u = 0.3, w = -0.8 along n = +y, 0.5 along the span
    F = lighthill_edge_force_n(M_A, V, tau)
    assert F == pytest.approx(M_A * -0.8 * (0.5 * -0.8 * tau - 0.3 * np.array([0.0, 1.0, 0.0])), rel=1e-12)
    assert lighthill_edge_force_n(M_A, V, tau, span_axis=(0, 0, -1)) == pytest.approx(F, rel=1e-12)


def test_b_no_mean_thrust_when_the_wave_runs_at_the_swimming_speed():
    """U = omega / k: the body slides along its own wave (w = 0 at every instant), so the reactive force and its
    mean vanish, at small and at large amplitude; slower swimming gives thrust, faster gives drag."""
    lam = 1.25 * 0.52
    k = 2 * np.pi / lam
    for ak in (1e-4, 0.5):
        for f in (1.0, 3.0):
            omega = 2 * np.pi * f
            V, tau, _, _ = _travelling_wave_edge(ak / k, k, omega, omega / k)
            F = lighthill_edge_force_n(M_A, V, tau)
            scale = M_A * (omega / k) ** 2                  # m U^2: round-off in w is eps U, in F eps m U^2
            assert np.abs(F).max() < 1e-12 * scale
            assert abs(np.mean(F[:, 0])) < 1e-12 * scale
            slow = lighthill_edge_force_n(M_A, *_travelling_wave_edge(ak / k, k, omega, 0.5 * omega / k)[:2])
            fast = lighthill_edge_force_n(M_A, *_travelling_wave_edge(ak / k, k, omega, 1.5 * omega / k)[:2])
            assert np.mean(slow[:, 0]) > 0 > np.mean(fast[:, 0])


# ------------------------------------------------------------------------------------- (c) the real fish
# Published thunniform swimmers, for the printed comparison only (nothing is fitted to them)
LITERATURE = PUBLISHED_STRIDES
RUN_S = 6.0                            # as the MuJoCo speed table (tests/test_mujoco_swim.py)


@pytest.fixture(scope="module")
def real_robot(request):
    """The default design's robot folder (conftest.default_robot, written once per session)."""
    from tests.conftest import require_module
    require_module("mujoco", "MuJoCo (the mujoco package) runs the swimming model")
    out, _ = request.getfixturevalue("default_robot")
    return out / "robot" / "swiftfin.xml"


@pytest.mark.slow
def test_c_real_fish_swims_faster_with_the_reactive_force(real_robot, default_params, capsys):
    """Self-propelled, free in six degrees of freedom, RUN_S at 1, 2 and 3 Hz, with MuJoCo's quasi-steady model
    alone and with Lighthill's reactive force added at the fin's trailing edge. Asserted: finite, no warnings,
    forward, level, faster with frequency, slip U / (f lambda) < 1 (slower than the body wave), the reactive
    force a mean thrust, and faster with it than without. Printed: speed, stride U / (f L), slip."""
    from swiftfin.physics.swim_sim import swim
    p = default_params
    L = p.body.length_mm / 1000
    lam = p.swimming.wavelength_body_lengths * L
    rows = {}
    for reactive in (False, True):
        for f in (1.0, 2.0, 3.0):
            r = swim(real_robot, p, frequency_hz=f, duration_s=RUN_S, reactive=reactive)
            assert r.finite and r.warnings == {}, (f, reactive)
            assert np.all(np.isfinite(r.com_xyz_m))
            u = r.forward_speed_m_s()
            assert u > 0, (f, reactive)
            assert u / (f * lam) < 1.0, (f, reactive, u)
            pitch = np.degrees(np.arcsin(r.head_axis[:, 2]))
            assert np.abs(pitch).max() < 10.0, (f, reactive, pitch.min(), pitch.max())
            thrust = np.nan
            if reactive:
                w = r.window()
                heading = r.head_axis[w].mean(axis=0)
                heading /= np.linalg.norm(heading)
                thrust = float(np.mean(r.reactive_force_n[w] @ heading))
                assert thrust > 0, f
            else:
                assert r.reactive_force_n is None
            rows[reactive, f] = (u, u / (f * L), u / (f * lam), thrust)
    for reactive in (False, True):
        assert rows[reactive, 1.0][0] < rows[reactive, 2.0][0] < rows[reactive, 3.0][0], reactive
    for f in (1.0, 2.0, 3.0):
        assert rows[True, f][0] > rows[False, f][0], f
    with capsys.disabled():
        print(f"\n  MuJoCo, real default design, free (6 DOF), {RUN_S:.0f} s runs (mean over the last half); "
              f"L = {L:.3f} m, lambda = {lam:.3f} m")
        print("  f      quasi-steady only: U, U/(fL), U/(f lambda)    + Lighthill at the fin: U, U/(fL), "
              "U/(f lambda), mean reactive thrust")
        for f in (1.0, 2.0, 3.0):
            q, s = rows[False, f], rows[True, f]
            print(f"  {f:.0f} Hz   {q[0]:.3f} m/s  {q[1]:.3f}  {q[2]:.3f}"
                  f"                      {s[0]:.3f} m/s  {s[1]:.3f}  {s[2]:.3f}  {s[3]:.2f} N")
        print("  published stride lengths U/(fL) [BL per cycle]:")
        for name, stride, source in LITERATURE:
            print(f"    {name:30s} {stride:.2f}   ({source})")
