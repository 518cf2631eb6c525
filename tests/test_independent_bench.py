"""The joint fit measured on a bench simulator written apart from it (tests/mujoco_bench.py, MuJoCo; issue 14,
item 3). First the bench itself against closed forms, then the engine on it: nothing named on a control, no wrong
name at high confidence, and the single library effects named first at least as often as measured when this test
was written (a floor against regressions; the issue's 90 % is not met, see the README)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import DEFAULT_DESIGN, require_module
from tests.mujoco_bench import BenchDesign, cases, run_case, score

mujoco = require_module("mujoco", "integrates the independent bench")


@pytest.fixture(scope="module")
def d():
    from swiftfin.layout.design import load_design
    return BenchDesign.from_params(load_design(DEFAULT_DESIGN))


def test_the_bench_rings_at_the_drive_stiffness_in_series_with_the_stepper(d, monkeypatch):
    """A step of the command: the link rings at sqrt(K / J) with K the cable pair (2 k d^2) in series with the
    stepper held at its step (T_hold pi / (2 theta_fs) (d / r)^2 at the joint), the stiffness the engine's base
    model now uses (calibration/joint.py). With the cable pair alone it would ring 2 % faster."""
    import tests.mujoco_bench as mb
    monkeypatch.setattr(mb, "command", lambda t, seed: np.where(t > 0.2, 0.05, 0.0))
    heavy = BenchDesign(**{**d.__dict__, "link_inertia_kg_m2": 2e-4, "bearing_damping_nm_s_rad": 0.0})
    log = mb.simulate(heavy, {}, duration_s=0.6, seed=0)
    x = log.true_joint_angle_rad[220:] - np.mean(log.true_joint_angle_rad[400:])
    crossings = np.flatnonzero(np.diff(np.sign(x)) != 0)
    period_s = 2 * np.mean(np.diff(crossings)) / mb.RATE_HZ
    cable = 2 * d.side_stiffness_n_m * d.arm_m**2
    motor = d.holding_torque_nm * math.pi / (2 * d.full_step_rad) * (d.arm_m / d.spool_radius_m) ** 2
    K = 1 / (1 / cable + 1 / motor)
    # the rotor behind the stepper's spring adds a little: its inertia seen at the joint is tiny next to 2e-4
    assert 2 * math.pi / period_s == pytest.approx(math.sqrt(K / 2e-4), rel=0.01)
    assert 2 * math.pi / period_s < 0.99 * math.sqrt(cable / 2e-4)


def test_a_slack_cable_is_a_dead_band_and_the_load_cell_reads_its_pretension(d):
    import tests.mujoco_bench as mb
    log = mb.simulate(d, {}, duration_s=2.0, seed=0)
    assert np.median(log.cable_tension_n) == pytest.approx(d.pretension_n, abs=1.0)
    slack = mb.simulate(d, {"cable_slack": 0.3}, duration_s=2.0, seed=0)
    assert np.median(slack.cable_tension_n) < 1.0          # no pretension left
    # a dead band of 2 s / d in joint angle: the link lags the command by up to s / d either way
    # (each reading against the command that acted before it: the bench reads, then commands)
    lag = slack.true_joint_angle_rad[1:] - slack.motor_angle_rad[:-1] * d.spool_radius_m / d.arm_m
    assert np.max(np.abs(lag[200:])) == pytest.approx(0.3e-3 / d.arm_m, rel=0.35)


@pytest.mark.slow
def test_the_engine_on_the_independent_bench(d, tmp_path):
    """One seed of bench/bench_confusion.py (which runs three): every size, the pairs, a control and the
    out-of-library effects. The issue's measures that hold are asserted as such; the share of single effects named
    first (the issue asks 90 %) as a floor at what was measured."""
    results = []
    for i, case in enumerate(cases(seeds=(0,), sizes=(0.2, 1.0, 5.0))):
        folder = tmp_path / f"c{i}"
        folder.mkdir()
        results.append(run_case(d, case, folder, str(DEFAULT_DESIGN)))
    s = score(results)
    table = "\n".join(f"{r['case'].label}: {r['named']} {r.get('confidences')} flagged={r['flagged']}"
                      for r in results)
    assert s["controls_clean"] == s["controls_n"], table
    assert not s["wrong_high"], table
    assert s["outside_flagged"] == s["outside_n"], table
    assert s["single_first"] >= FLOOR_SINGLE_FIRST, table


FLOOR_SINGLE_FIRST = 26
"""Single library effects named first of the 30 cases of seed 0: 27 measured 2026-11-26 (second session) with the
drag and dry friction simulated in the drive and the dense search at the log's resonance (bench_confusion.py: 81
of 90 over three seeds; 25 and 74 before them, 22 and 67 before the design's drive was the base model). A
regression floor one case below the measurement."""
