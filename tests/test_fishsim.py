"""fishsim marker loader: pixel scale, head/body frame, cleaning of tracking faults, drive frequency.

Synthetic videos with known geometry and injected faults first; then the six real files."""
from __future__ import annotations

import numpy as np
import pytest

from swiftfin.calibration.fishsim import (FRAME_RATE_HZ, HEAD_MARKER_SPACING_M, drive_frequency_from_name,
                                 dominant_frequency_hz, load_markers, read_marker_csv, tail_frequency_hz)
from swiftfin.core.errors import UserError
from tests.conftest import ROOT, require_shared

ARC = np.array([0.0, 0.142, 0.34, 0.39, 0.42, 0.45, 0.48, 0.51, 0.58])  # marker arc positions [m]


def _body(t, f_hz=1.25, amp=0.08):
    """Body-frame marker positions (n, 9, 2) [m]: rigid front to marker 2, a wave behind it."""
    L = ARC[-1]
    u = np.clip((ARC - ARC[2]) / (L - ARC[2]), 0, None)
    y = amp * u[None, :] ** 1.5 * np.sin(2 * np.pi * (ARC[None, :] / (1.25 * L)) - 2 * np.pi * f_hz * t[:, None])
    return np.stack([np.broadcast_to(ARC, y.shape), y], axis=-1)


def _to_pixels(B, px_per_m=950.0, seed=0, noise_px=0.5):
    """Swim: rotate each frame by a slowly varying heading and translate it; scale; add pixel noise."""
    rng = np.random.default_rng(seed)
    n = B.shape[0]
    k = np.arange(n)
    yaw = 0.6 + 0.3 * np.sin(2 * np.pi * k / 400.0)
    c, s = np.cos(yaw), np.sin(yaw)
    R = np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)     # (n, 2, 2)
    P = np.einsum("nij,nmj->nmi", R, B) * px_per_m
    P += np.stack([1500 + 0.4 * k, 900 + 0.2 * k], -1)[:, None, :]
    return P + noise_px * rng.standard_normal(P.shape)


def _write(path, P):
    np.savetxt(path, P.reshape(P.shape[0], -1), delimiter=",", fmt="%.3f")
    return path


@pytest.fixture
def synthetic(tmp_path):
    t = np.arange(360) / FRAME_RATE_HZ
    B = _body(t)
    P = _to_pixels(B)
    P[100, 5] += [40.0, -35.0]                 # a jump of one sample
    P[200:206, 6] = P[200:206, 7]              # marker 6 drifts onto marker 7 for 0.1 s
    path = _write(tmp_path / "markers_f1_25.csv", P)
    return load_markers(path), B, t


def test_file_name_frequency():
    assert drive_frequency_from_name("markers_f0_75.csv") == 0.75
    assert drive_frequency_from_name("/x/markers_f2_25.csv") == 2.25
    with pytest.raises(UserError, match="drive frequency"):
        drive_frequency_from_name("markers.csv")


def test_synthetic_scale_frame_and_cleaning(synthetic):
    d, B, t = synthetic
    assert d.x_m.shape == d.y_m.shape == (360, 9)
    assert d.pixels_per_m == pytest.approx(950.0, rel=0.002)            # from the 0.142 m head spacing
    assert np.median(d.x_m[:, 1]) == pytest.approx(HEAD_MARKER_SPACING_M, rel=2e-3)
    assert np.abs(d.y_m[:, :2]).max() < 0.003 and abs(d.body_axis_rotation_deg) < 0.5
    # the body-frame positions match the truth (pixel noise 0.5 px ~ 0.5 mm at the tail after the frame)
    ok = d.valid
    err = np.hypot(d.x_m - B[..., 0], d.y_m - B[..., 1])[ok]
    assert np.percentile(err, 99) < 0.004
    # arc positions: median over frames of the summed segment lengths (the synthetic body stretches as it
    # bends, so compare with the same statistic of the truth)
    seg_true = np.median(np.hypot(*np.diff(B, axis=1).transpose(2, 0, 1)), axis=0)
    assert d.arc_m == pytest.approx(np.r_[0.0, np.cumsum(seg_true)], abs=0.003)
    # the jump and the merge were found and repaired by interpolation
    assert d.cleaning["jump_samples_invalid"].get(5, 0) >= 1
    assert d.cleaning["merged_samples_invalid"].get(6, 0) == 6
    assert d.valid[100, 5] and d.valid[203, 6]                        # interpolated over the short gaps
    assert abs(d.y_m[203, 6] - B[203, 6, 1]) < 0.005
    assert d.cleaning["markers_dropped"] == []


def test_synthetic_spectrum_matches_drive(synthetic):
    d, _, _ = synthetic
    assert tail_frequency_hz(d) == pytest.approx(1.25, rel=0.01)
    t = np.arange(0, 5, 1 / 60)
    assert dominant_frequency_hz(t, np.sin(2 * np.pi * 0.83 * t)) == pytest.approx(0.83, abs=0.005)


def test_bad_marker_file(tmp_path):
    p = tmp_path / "markers_f1_00.csv"
    p.write_text("\n".join(",".join(["1"] * 17) for _ in range(200)))
    with pytest.raises(UserError, match="17 columns"):
        read_marker_csv(p)


@pytest.fixture(scope="module")
def real():
    require_shared("data", "fishsim", "markers_f1_00.csv")
    from swiftfin.calibration.fishsim import load_all
    return load_all(ROOT)


def test_real_files_load(real):
    assert [d.drive_frequency_hz for d in real] == [0.5, 0.75, 1.0, 1.5, 1.75, 2.25]
    for d in real:
        assert d.x_m.shape[1] == 9 and d.n_frames in (301, 351, 541)   # wc -l of the files
        assert 930 < d.pixels_per_m < 1010                   # ~1 px/mm camera
        assert 0.54 < d.body_length_m < 0.62                 # README: about 0.55 m
        assert np.median(np.hypot(d.x_m[:, 1], d.y_m[:, 1])) == pytest.approx(0.142, rel=3e-3)


def test_real_tail_beats_at_three_quarters_of_the_named_frequency(real):
    """Measured, not assumed: in all six files the tail tip's spectral peak is 0.75 x the frequency in the file
    name (0.737-0.753). Either a 4:3 reduction between motor and crank, or videos at 45 fps, not 60."""
    ratios = np.array([tail_frequency_hz(d) / d.drive_frequency_hz for d in real])
    assert np.all(np.abs(ratios - 0.75) < 0.02), ratios


def test_real_cleaning_report(real):
    by_f = {d.drive_frequency_hz: d for d in real}
    # files f1_50 and f2_25: markers sit on each other most of the time -> dropped, not invented
    assert set(by_f[1.5].cleaning["markers_dropped"]) == {4, 6}
    assert set(by_f[2.25].cleaning["markers_dropped"]) == {4, 5, 6}
    assert by_f[1.0].cleaning["markers_dropped"] == [] and by_f[0.75].cleaning["markers_dropped"] == []
    for d in real:
        assert d.valid[:, [0, 1, 2, 8]].all()                # head, rigid-body end and tail tip always usable
