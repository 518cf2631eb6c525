"""The ``body`` family: recovery of a known wave on synthetic markers, then the real fishsim files."""
from __future__ import annotations

import numpy as np
import pytest

from calibration.body import (BodySamples, BodySelection, BodyWave, EFFECTS, FAMILY,
                              cross_file_rmse, samples_from_markers)
from tests.conftest import ROOT, require_shared

ARC = np.array([0.34, 0.39, 0.42, 0.45, 0.48, 0.51, 0.58])   # body markers 2..8 [m]
L = 0.58


def _synthetic(ratio=0.8, amp=0.09, lam=1.25, offset=(0.0, 0.0, 0.0), yaw=0.0, noise=0.003, f=1.0,
               seconds=6.0, seed=0) -> BodySamples:
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 1 / 60.0)
    T, S = np.meshgrid(t, ARC, indexing="ij")
    u = S / L
    w = 2 * np.pi * ratio * f
    y = amp * u**2 * np.sin(2 * np.pi / (lam * L) * S - w * T + 0.7)
    y += offset[0] * u + offset[1] * u**2 + offset[2] * u**3 + yaw * u * np.sin(w * T + 2.0)
    y += noise * rng.standard_normal(y.shape)
    n = y.size
    return BodySamples(T.ravel(), S.ravel(), y.ravel(), np.full(n, L), np.full(n, f),
                       np.tile(np.arange(2, 9), len(t)), np.zeros(n, int))


def test_recovers_known_wave():
    S = _synthetic(ratio=0.8, amp=0.09, lam=1.0, offset=(-0.05, 0.02, 0.0))
    m = BodyWave(("tail_beat_frequency", "wavelength", "lateral_offset")).fit(S)
    assert m.nl_["ratio"] == pytest.approx(0.8, abs=0.002)
    assert m.nl_["lam"] == pytest.approx(1.0, rel=0.05)
    assert m.summary_["tail_amplitude_m"] == pytest.approx(0.09, rel=0.05)
    assert m.summary_["lateral_offset_at_tail_m"] == pytest.approx(-0.03, abs=0.003)
    assert m.rmse_train_ == pytest.approx(0.003, rel=0.1)                  # down to the noise
    # uncertainties are reported for every parameter and cover the truth
    assert abs(m.nl_["ratio"] - 0.8) < 4 * m.stderr_["nl.ratio"] + 1e-4
    assert set(m.stderr_) >= {"wave.a_m", "wave.b_m", "nl.ratio", "nl.lam", "lateral_offset.c1_m"}


def test_selection_names_the_injected_departures():
    S = _synthetic(ratio=0.75, offset=(-0.04, 0.0, 0.0), yaw=0.03)
    sel = BodySelection().fit(S)
    assert set(sel.effects_) == {"tail_beat_frequency", "lateral_offset", "head_yaw"}
    assert sel.final_rmse_[1] < 1.15 * 0.003                              # held-out error at the noise level
    assert sel.baseline_rmse_[1] > 5 * sel.final_rmse_[1]


def test_selection_adds_nothing_to_the_paper_wave():
    S = _synthetic(ratio=1.0)
    sel = BodySelection().fit(S)
    assert sel.effects_ == ()
    assert sel.baseline_rmse_[1] == pytest.approx(0.003, rel=0.1)


def test_library_names():
    assert {e.name for e in FAMILY.effects} | {"amplitude_vs_frequency"} == set(EFFECTS)


# --------------------------------------------------------------------------------------------- real data

@pytest.fixture(scope="module")
def real():
    require_shared("data", "fishsim", "markers_f1_00.csv")
    from calibration.fishsim import load_all
    return load_all(ROOT)


def test_real_within_file_fastest_drive(real):
    """f2_25 (markers 4-6 dropped by the cleaning). Held-out = each of 5 contiguous time blocks in turn.
    Measured: 44.6 mm (paper wave) -> 3.0 mm; the tail beats at 0.74 x the drive frequency."""
    d = real[-1]
    sel = BodySelection().fit(samples_from_markers(d))
    assert sel.effects_[0] == "tail_beat_frequency"
    assert {"tail_beat_frequency", "head_yaw", "lateral_offset"} <= set(sel.effects_)
    assert sel.model_.nl_["ratio"] == pytest.approx(0.74, abs=0.01)
    assert sel.baseline_rmse_[1] == pytest.approx(0.0446, abs=0.002)
    assert sel.final_rmse_[1] < 0.004


@pytest.mark.slow
def test_real_within_each_file(real):
    """All six files (~50 s). Measured held-out RMSE, paper wave -> final [mm]:
    0.50 Hz 52.1 -> 12.9, 0.75 Hz 69.0 -> 7.3, 1.00 Hz 52.7 -> 6.0, 1.50 Hz 47.1 -> 5.1, 1.75 Hz 55.5 -> 8.9,
    2.25 Hz 44.6 -> 3.0; tail_beat_frequency (0.74-0.75), lateral_offset and head_yaw in every file."""
    for d in real:
        sel = BodySelection().fit(samples_from_markers(d))
        assert {"tail_beat_frequency", "lateral_offset", "head_yaw"} <= set(sel.effects_), d.source
        assert 0.73 < sel.model_.nl_["ratio"] < 0.76
        assert sel.baseline_rmse_[1] > 0.04
        assert sel.final_rmse_[1] < 0.014
        assert sel.final_rmse_[1] < 0.25 * sel.baseline_rmse_[1]


@pytest.mark.slow
def test_real_across_files(real):
    """Leave one drive frequency out (~40 s): shared parameters fitted on the other five files, every file's
    clock synced to its own tail tip. Pooled RMSE: paper wave 50.5 mm -> 16.7 mm with the three effects found
    within files. Making the wave amplitude a function of frequency does not help (the tail amplitude is
    ~0.07-0.09 m at every frequency); what must scale with the drive frequency is the beat frequency itself."""
    base = cross_file_rmse(real, ())
    best = cross_file_rmse(real, ("tail_beat_frequency", "lateral_offset", "head_yaw"))
    amp_f = cross_file_rmse(real, ("tail_beat_frequency", "lateral_offset", "head_yaw", "amplitude_vs_frequency"))
    assert base["all"] == pytest.approx(0.0505, abs=0.002)
    assert best["all"] == pytest.approx(0.0167, abs=0.0015)
    assert amp_f["all"] > 0.98 * best["all"]


def test_engine_family_on_a_real_file():
    """The engine's version of the family (effects with their own beat-frequency copy, see body.py) on f1_75:
    the first effect it adds is the beat frequency, at 0.75 x the drive."""
    path = require_shared("data", "fishsim", "markers_f1_75.csv")
    from calibration.body import load
    from calibration.engine import Calibrator
    cal = Calibrator(FAMILY, max_effects=3).fit(load(path))
    assert cal.added_effects_[0].name == "tail_beat_frequency"
    assert cal.added_effects_[0].values["ratio"] == pytest.approx(0.75, abs=0.01)
    assert cal.final_["rmse_holdout"] < 0.5 * cal.baseline_["rmse_holdout"]
