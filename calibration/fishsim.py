"""Loader for video-tracked body markers in the format of ``../shared/data/fishsim`` (``markers_fX_YY.csv``).

Format: no header, one row per frame (60 fps), 18 columns ``x0,y0,...,x8,y8`` in pixels. Markers 0 (front)
and 1 sit on the rigid head, 0.142 m apart; markers 2..8 run down the body to the tail tip (8). The drive
frequency is in the file name: ``markers_f0_75.csv`` = 0.75 Hz.

What :func:`load_markers` does, in order (each step is counted in :attr:`MarkerData.cleaning`):

1. **Pixel scale** [px/m] = median over frames of |marker1 - marker0| / 0.142 m (the head is rigid, so one
   scale per file; the frame-to-frame spread of that distance is tracking noise).
2. **Head markers**: frames whose head-marker spacing is off the median by more than 8 % are marked and the
   two head markers are interpolated linearly in time there.
3. **Head frame**: origin at marker 0; x axis along the head, from marker 0 toward marker 1 (so x grows from
   the nose to the tail like the paper's x); y axis 90 degrees from x, counter-clockwise in image pixel
   coordinates. The head's pose (marker 0 and the heading angle) is low-passed at ``head_cutoff_hz``
   (6 Hz, zero phase, 2nd-order Butterworth; above the 3rd harmonic of the fastest beat here): with the two
   head markers only 0.142 m apart, 1 px of jitter on them would otherwise swing the tail tip, 0.45 m
   behind, by ~5 mm. Then one constant rotation per file turns x onto the **body axis**: the line from marker 0
   to the time-mean of marker 2 (the rear end of the rigid body). The head markers are not glued exactly on
   the body's midline, and this removes that mounting angle (reported as ``body_axis_rotation_deg``). The
   sign of y is a camera convention; the wave fits do not depend on it.
4. **Merged and displaced markers** (a tracker that lost a marker puts it on another one): each marker has
   a nominal distance from marker 2 (median over the frames where all body markers are at least
   ``merge_distance_m`` = 10 mm apart, a third of the smallest true spacing; from the other files when fewer
   than 20 % of this file's frames qualify). In each frame, consecutive markers closer than 10 mm form a
   cluster: the member nearest its own nominal distance is kept if within 40 % of the smallest spacing of
   it, the others are invalid. A marker that sits nearer another marker's nominal place than its own (by
   more than that tolerance) is invalid too.
5. **Swaps**: two neighbours whose order along the body is inverted are swapped back when that brings both
   closer to their previous-frame positions.
6. **Jumps**: a sample that departs from the running median (7 frames) of its own coordinate by more than
   max(6 robust sigma, 8 mm) is marked invalid.
7. **Gaps**: invalid stretches up to ``max_gap_s`` (0.2 s) are interpolated linearly in time; longer ones
   stay NaN and are left out of every fit. A marker with less than half of its frames valid is dropped.

The drive frequency read from the file name is checked against the spectrum of the tail-tip lateral motion
(:func:`dominant_frequency_hz`), and a tail that barely moves is refused (:func:`check_motion`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy import signal
from scipy.ndimage import median_filter

from swiftfin.core.errors import UserError

HEAD_MARKER_SPACING_M = 0.142  # fishsim README: true spacing of markers 0 and 1
FRAME_RATE_HZ = 60.0           # fishsim README
N_MARKERS = 9
_NAME = re.compile(r"f(\d+)_(\d+)")
#: Nominal distance of each marker from marker 2 as a fraction of the tail tip's (marker 8) distance from it:
#: median over the four fishsim files whose markers stay apart (f0_50, f0_75, f1_00, f1_75), measured with
#: this module (pass 1 of :func:`load_all`). Used for a single file that cannot tell where its markers belong.
DEFAULT_NOMINAL_RATIO = (1.553, 0.91, 0.0, 0.248, 0.349, 0.485, 0.592, 0.702, 1.0)


def fishsim_dir(project_root=None) -> Path:
    root = Path(project_root) if project_root is not None else Path(__file__).resolve().parents[1]
    return root.parent / "shared" / "data" / "fishsim"


def drive_frequency_from_name(path) -> float:
    """``markers_f0_75.csv`` -> 0.75 [Hz]."""
    m = _NAME.search(Path(path).stem)
    if not m:
        raise UserError(f"{path}: cannot read the drive frequency from the file name "
                        "(expected e.g. markers_f0_75.csv for 0.75 Hz)")
    f = float(f"{m.group(1)}.{m.group(2)}")
    if not f > 0:
        raise UserError(f"{path}: the file name says a drive frequency of {f:g} Hz; expected a positive frequency "
                        "(e.g. markers_f0_75.csv for 0.75 Hz); likely cause: a misnamed file")
    return f


@dataclass(frozen=True)
class MarkerData:
    """Markers of one video in the body frame, SI units.

    ``x_m``, ``y_m``: (n_frames, 9) head/body-frame coordinates [m], NaN where invalid after cleaning;
    ``valid``: (n_frames, 9) bool, True where the sample is measured or interpolated over a short gap;
    ``arc_m``: (9,) arc-length position of each marker from marker 0 along the body [m] (median over
    frames of the summed segment lengths), NaN for a dropped marker; ``body_length_m`` = arc of marker 8.
    """
    time_s: np.ndarray
    x_m: np.ndarray
    y_m: np.ndarray
    valid: np.ndarray
    arc_m: np.ndarray
    drive_frequency_hz: float
    pixels_per_m: float
    body_axis_rotation_deg: float
    cleaning: dict = field(default_factory=dict)
    source: str = ""

    @property
    def body_length_m(self) -> float:
        return float(self.arc_m[-1])

    @property
    def n_frames(self) -> int:
        return len(self.time_s)


def read_marker_csv(path) -> np.ndarray:
    """(n_frames, 9, 2) pixel array; rejects a wrong column count or non-numbers naming the row."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError:
        raise UserError(f"{path}: not a text CSV file") from None
    except OSError as exc:
        raise UserError(f"{path}: cannot read marker file ({exc.strerror})") from None
    rows, problems = [], []
    for r, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        parts = [p for p in line.strip().rstrip(",").split(",")]
        if len(parts) != 2 * N_MARKERS:
            problems.append(f"row {r}: {len(parts)} columns, expected {2 * N_MARKERS} (x0,y0,...,x8,y8)")
            continue
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            problems.append(f"row {r}: a value is not a number")
    if len(rows) < 2 * FRAME_RATE_HZ:
        problems.append(f"{len(rows)} frames; at least {int(2 * FRAME_RATE_HZ)} (2 s) are needed")
    if problems:
        raise UserError(f"{path}: " + "; ".join(problems[:10]) + (" ..." if len(problems) > 10 else ""))
    a = np.asarray(rows).reshape(len(rows), N_MARKERS, 2)
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        raise UserError(f"{path}: row {bad[0] + 1}, marker {bad[1]}: missing coordinate")
    return a


def _interp_gaps(v: np.ndarray, ok: np.ndarray, max_gap: int) -> tuple[np.ndarray, int, int]:
    """Fill runs of ~ok up to max_gap samples (bounded on both sides) by linear interpolation.
    Returns (filled array with NaN elsewhere, samples filled, samples left NaN)."""
    out = np.where(ok, v, np.nan)
    n = len(v)
    filled = left = 0
    i = 0
    idx = np.arange(n)
    while i < n:
        if ok[i]:
            i += 1
            continue
        j = i
        while j < n and not ok[j]:
            j += 1
        run = j - i
        if i > 0 and j < n and run <= max_gap:
            out[i:j] = np.interp(idx[i:j], [i - 1, j], [v[i - 1], v[j]])
            filled += run
        else:
            left += run
        i = j
    return out, filled, left


def load_markers(path, merge_distance_m: float = 0.010, max_gap_s: float = 0.2,
                 nominal_ratio: np.ndarray | None = None, head_cutoff_hz: float = 6.0) -> MarkerData:
    """Read, scale, transform to the body frame and clean one marker file (see module docstring).

    ``nominal_ratio`` (9,): nominal distance of each marker from marker 2 as a fraction of the tail tip's,
    used only when fewer than 20 % of this file's frames have all markers apart (then this file cannot
    tell where its markers belong); :func:`load_all` takes it from the other files, a single file uses
    :data:`DEFAULT_NOMINAL_RATIO`."""
    path = Path(path)
    f_drive = drive_frequency_from_name(path)
    P = read_marker_csv(path).copy()
    n = len(P)
    t = np.arange(n) / FRAME_RATE_HZ
    report: dict = {}

    # 1-2. pixel scale and head markers
    spacing = np.linalg.norm(P[:, 1] - P[:, 0], axis=1)
    med = float(np.median(spacing))
    if med <= 0:
        raise UserError(f"{path}: head markers 0 and 1 coincide; cannot set the pixel scale")
    bad_head = np.abs(spacing / med - 1.0) > 0.08
    report["head_frames_interpolated"] = int(bad_head.sum())
    if bad_head.any():
        if bad_head.mean() > 0.5:
            raise UserError(f"{path}: head-marker spacing unstable in {bad_head.mean():.0%} of frames")
        for k in (0, 1):
            for c in (0, 1):
                P[:, k, c] = np.interp(t, t[~bad_head], P[~bad_head, k, c])
        spacing = np.linalg.norm(P[:, 1] - P[:, 0], axis=1)
    scale = float(np.median(spacing)) / HEAD_MARKER_SPACING_M

    # 3. head frame (its pose smoothed: the head is rigid and turns slowly), then body axis
    d01 = P[:, 1] - P[:, 0]
    yaw = np.unwrap(np.arctan2(d01[:, 1], d01[:, 0]))
    origin = P[:, 0].copy()
    if head_cutoff_hz and n > 30:
        b, a = signal.butter(2, head_cutoff_hz / (FRAME_RATE_HZ / 2.0))
        yaw = signal.filtfilt(b, a, yaw)
        origin = signal.filtfilt(b, a, origin, axis=0)
    report["head_pose_lowpass_hz"] = head_cutoff_hz
    ex = np.column_stack([np.cos(yaw), np.sin(yaw)])
    ey = np.column_stack([-ex[:, 1], ex[:, 0]])
    R = (P - origin[:, None, :]) / scale
    x = np.einsum("fmc,fc->fm", R, ex)
    y = np.einsum("fmc,fc->fm", R, ey)
    rot = float(np.arctan2(np.median(y[:, 2]), np.median(x[:, 2])))
    c, s = np.cos(rot), np.sin(rot)
    x, y = c * x + s * y, -s * x + c * y

    valid = np.ones((n, N_MARKERS), dtype=bool)
    body = list(range(2, N_MARKERS))

    # 4. merged and displaced markers
    def dist_from_2(xx, yy):
        return np.hypot(xx - xx[:, 2:3], yy - yy[:, 2:3])
    d2 = dist_from_2(x, y)
    gap = np.hypot(np.diff(x[:, 2:], axis=1), np.diff(y[:, 2:], axis=1))  # (n, 6): segment 2-3 ... 7-8
    close = gap < merge_distance_m
    separated = ~close.any(axis=1)
    if separated.mean() >= 0.2:
        nominal = np.median(d2[separated], axis=0)
        report["nominal_source"] = f"this file ({separated.mean():.0%} of frames with all markers apart)"
    else:
        ratio = DEFAULT_NOMINAL_RATIO if nominal_ratio is None else nominal_ratio
        nominal = np.asarray(ratio, dtype=float) * float(np.median(d2[:, 8]))
        report["nominal_source"] = (f"other files (only {separated.mean():.0%} of frames here have all "
                                    "markers apart)")
    report["nominal_from_marker2_m"] = [round(float(v), 4) for v in nominal]
    spacing_nom = np.abs(np.diff(nominal[2:]))
    tol = 0.4 * float(np.min(spacing_nom))
    merged_dropped = np.zeros(N_MARKERS, dtype=int)
    for fr in np.flatnonzero(close.any(axis=1)):
        m = 3
        while m < N_MARKERS:
            if not close[fr, m - 3]:
                m += 1
                continue
            j = m
            while j < N_MARKERS and close[fr, j - 3]:
                j += 1
            cluster = list(range(m - 1, j))  # markers m-1 .. j-1 are mutually close
            dev = np.abs(d2[fr, cluster] - nominal[cluster])
            keep = cluster[int(np.argmin(dev))]
            for k, dk in zip(cluster, dev):
                if k != 2 and (k != keep or dk > tol) and valid[fr, k]:
                    valid[fr, k] = False
                    merged_dropped[k] += 1
            m = j + 1
    report["merged_samples_invalid"] = {int(k): int(v) for k, v in enumerate(merged_dropped) if v}
    # a marker sitting at another marker's place along the body (drifted onto it) is wrong
    displaced = np.zeros(N_MARKERS, dtype=int)
    own = np.abs(d2 - nominal[None, :])
    for m in range(3, N_MARKERS):
        others = [k for k in range(3, N_MARKERS) if k != m]
        nearest_other = np.min(np.abs(d2[:, m:m + 1] - nominal[None, others]), axis=1)
        bad = valid[:, m] & (own[:, m] > 2.5 * tol) & (nearest_other < own[:, m])
        displaced[m] = int(bad.sum())
        valid[:, m] &= ~bad
    report["displaced_samples_invalid"] = {int(k): int(v) for k, v in enumerate(displaced) if v}

    # 5. swaps of neighbours (order along the body inverted)
    swaps = 0
    for fr in range(1, n):
        for m in range(3, N_MARKERS - 1):
            if not (valid[fr, m] and valid[fr, m + 1]):
                continue
            if d2[fr, m] > d2[fr, m + 1] + 0.25 * spacing_nom[m - 2]:
                here = np.hypot(x[fr, [m, m + 1]] - x[fr - 1, [m, m + 1]], y[fr, [m, m + 1]] - y[fr - 1, [m, m + 1]])
                there = np.hypot(x[fr, [m + 1, m]] - x[fr - 1, [m, m + 1]],
                                 y[fr, [m + 1, m]] - y[fr - 1, [m, m + 1]])
                if there.sum() < here.sum():
                    x[fr, [m, m + 1]] = x[fr, [m + 1, m]]
                    y[fr, [m, m + 1]] = y[fr, [m + 1, m]]
                    d2[fr, [m, m + 1]] = d2[fr, [m + 1, m]]
                    swaps += 1
    report["swaps_fixed"] = swaps

    # 6. jumps: departures from a running median of the valid samples
    jumps = np.zeros(N_MARKERS, dtype=int)
    for m in body:
        ok = valid[:, m]
        if ok.sum() < 10:
            continue
        for v in (x[:, m], y[:, m]):
            filled = np.interp(t, t[ok], v[ok])
            rm = median_filter(filled, size=7, mode="nearest")
            dev = np.abs(filled - rm)
            sig = 1.4826 * np.median(dev[ok])
            bad = ok & (dev > max(6.0 * sig, 0.008))
            jumps[m] += int(bad.sum())
            valid[:, m] &= ~bad
            ok = valid[:, m]
    report["jump_samples_invalid"] = {int(k): int(v) for k, v in enumerate(jumps) if v}

    # 7. gaps
    max_gap = int(round(max_gap_s * FRAME_RATE_HZ))
    interp, left = {}, {}
    dropped = []
    for m in body:
        if valid[:, m].mean() < 0.5:
            dropped.append(m)
            x[:, m] = y[:, m] = np.nan
            valid[:, m] = False
            continue
        x[:, m], fi, le = _interp_gaps(x[:, m], valid[:, m], max_gap)
        y[:, m], _, _ = _interp_gaps(y[:, m], valid[:, m], max_gap)
        if fi:
            interp[m] = fi
        if le:
            left[m] = le
        valid[:, m] = np.isfinite(x[:, m])
    report["samples_interpolated"] = interp
    report["samples_left_out"] = left
    report["markers_dropped"] = dropped

    # arc-length positions: median over frames of summed valid segment lengths
    seg = np.hypot(np.diff(x, axis=1), np.diff(y, axis=1))
    seg_med = np.array([np.nanmedian(seg[:, k]) if np.isfinite(seg[:, k]).sum() >= 10 else np.nan
                        for k in range(N_MARKERS - 1)])
    arc = np.full(N_MARKERS, np.nan)
    arc[0] = 0.0
    for m in range(1, N_MARKERS):
        if m in dropped:
            continue
        prev = max(k for k in range(m) if k not in dropped)
        if prev == m - 1:
            arc[m] = arc[prev] + seg_med[m - 1]
        else:  # skip over a dropped marker: distance from the previous kept one
            dd = np.hypot(x[:, m] - x[:, prev], y[:, m] - y[:, prev])
            arc[m] = arc[prev] + float(np.nanmedian(dd))
    if np.isnan(arc[-1]):
        raise UserError(f"{path}: the tail-tip marker 8 could not be tracked; no body length")
    data = MarkerData(t, x, y, valid, arc, f_drive, scale, float(np.degrees(rot)), report, str(path))
    check_motion(data)
    return data


#: The tail tip must swing sideways (5th to 95th percentile of its lateral position) by at least this fraction of
#: the body length. The fishsim videos swing 0.19-0.21 m on a 0.55-0.61 m body (a third of it); a still fish
#: filmed with tracking noise (~1 px, ~1 mm) swings a few millimetres.
MIN_TAIL_SWING_FRACTION = 0.02
#: Tail-beat frequency / drive frequency the body family can represent (its ``tail_beat_frequency`` ratio bounds).
#: The fishsim tails beat at 0.74-0.75 x the file name's frequency.
BEAT_RATIO_RANGE = (0.3, 2.0)


def check_motion(data: MarkerData) -> None:
    """Refuse a video whose tail barely moves (:data:`MIN_TAIL_SWING_FRACTION`) or whose tail-beat frequency
    contradicts the drive frequency of its file name (ratio outside :data:`BEAT_RATIO_RANGE`)."""
    y = data.y_m[:, 8]
    ok = np.isfinite(y)
    swing = float(np.percentile(y[ok], 95) - np.percentile(y[ok], 5))
    L = data.body_length_m
    if swing < MIN_TAIL_SWING_FRACTION * L:
        raise UserError(f"{data.source}: marker 8 (tail tip, columns x8,y8) swings {1000 * swing:.3g} mm sideways "
                        f"(5th-95th percentile), expected at least {100 * MIN_TAIL_SWING_FRACTION:g} % of the "
                        f"{L:.3g} m body ({1000 * MIN_TAIL_SWING_FRACTION * L:.3g} mm; fishsim: ~200 mm); likely "
                        f"cause: the fish did not swim in this video (motor off, or a still recording): nothing to fit")
    f_tail = tail_frequency_hz(data)
    r = f_tail / data.drive_frequency_hz
    lo, hi = BEAT_RATIO_RANGE
    if not lo <= r <= hi:
        raise UserError(f"{data.source}: the file name says a drive frequency of {data.drive_frequency_hz:g} Hz but "
                        f"the tail tip (marker 8) beats at {f_tail:.3g} Hz, {r:.3g} x that; expected "
                        f"{lo:g}-{hi:g} x (fishsim: 0.74-0.75 x); likely cause: a misnamed file "
                        f"(markers_fX_YY.csv = X.YY Hz)")


def dominant_frequency_hz(t_s, v, f_min_hz: float = 0.2, f_max_hz: float = 6.0, n: int = 6000) -> float:
    """Frequency of the largest peak of the periodogram of ``v`` (NaNs skipped), on a fine grid [Hz]:
    the least-squares sinusoid fit over frequency, so resolution is not limited to 1/duration bins."""
    t_s, v = np.asarray(t_s, dtype=float), np.asarray(v, dtype=float)
    ok = np.isfinite(v)
    t_s, v = t_s[ok], v[ok] - np.mean(v[ok])
    f = np.linspace(f_min_hz, f_max_hz, n)
    ph = 2.0 * np.pi * f[:, None] * t_s[None, :]
    power = (np.cos(ph) @ v) ** 2 + (np.sin(ph) @ v) ** 2
    i = int(np.argmax(power))
    # refine with a 3-point parabola
    if 0 < i < n - 1:
        a, b, c = power[i - 1:i + 2]
        den = a - 2 * b + c
        if den != 0:
            return float(f[i] + 0.5 * (a - c) / den * (f[1] - f[0]))
    return float(f[i])


def tail_frequency_hz(data: MarkerData) -> float:
    """Dominant frequency of the tail-tip (marker 8) lateral motion [Hz]."""
    return dominant_frequency_hz(data.time_s, data.y_m[:, 8])


def load_all(project_root=None) -> list[MarkerData]:
    """Every ``markers_f*.csv`` of the fishsim folder, sorted by drive frequency. Two passes: the nominal
    marker positions (as fractions of the tail tip's distance from marker 2) of the files that can tell them
    are pooled (median) and given to the files that cannot."""
    folder = fishsim_dir(project_root)
    files = sorted(folder.glob("markers_f*.csv"), key=drive_frequency_from_name)
    if not files:
        raise UserError(f"{folder}: no markers_f*.csv files")
    return load_marker_files(files)


def load_marker_files(files) -> list[MarkerData]:
    """Several marker files of one body, in the given order, with the nominal marker positions pooled as in
    :func:`load_all` (files whose markers overlap too often borrow them from the others)."""
    files = list(files)
    first = [load_markers(p) for p in files]
    ratios = [np.array(d.cleaning["nominal_from_marker2_m"]) / d.cleaning["nominal_from_marker2_m"][8]
              for d in first if d.cleaning["nominal_source"].startswith("this file (")]
    if not ratios:
        return first
    ratio = np.median(ratios, axis=0)
    return [d if d.cleaning["nominal_source"].startswith("this file (") else load_markers(p, nominal_ratio=ratio)
            for d, p in zip(first, files)]
