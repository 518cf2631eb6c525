"""The ``body`` family: the swimming body's midline from video markers, against the paper's travelling wave.

Data: :class:`calibration.fishsim.MarkerData` (markers in the body frame, metres; see that module). Each valid
sample of a body marker (2..8) at arc position s [m] and time t [s] gives one lateral displacement y [m].
Markers 0 and 1 are the head, on the x axis by construction, and are not used.

Base model — the paper's wave (eq. 43-45), with its fixed choices kept fixed:
    y(s, t) = A_tail (s/L)^2 sin(k s - w t + phi),  k = 2 pi / (1.25 L),  w = 2 pi f_drive
(quadratic envelope with zero amplitude at the nose, wavelength 1.25 body lengths, tail-beat frequency = drive
frequency). L is the arc length to the tail tip. A_tail and phi are fitted (two linear coefficients
a = A cos phi, b = A sin phi): the paper's A_max is a design value for another robot, and the phase is the
video's time origin.

Candidate effects (how a real body departs from it), see :data:`ENGINE_EFFECTS`:
``tail_beat_frequency`` (tail beats at r * f_drive, r fitted), ``lateral_offset`` (asymmetric stroke / bent
rest shape, time-invariant c1 s/L + c2 (s/L)^2 + c3 (s/L)^3), ``envelope_shape`` (exponent p instead of 2: a
stiff front and a bending tail), ``rigid_front`` (no bending ahead of s = h L), ``wavelength`` (lambda/L fitted
instead of 1.25), ``phase_lag`` (extra phase kappa (s/L)^2: a wave speed that changes along the body),
``head_yaw`` (recoil: the head yaws, so in the head frame the body swings as a rigid lever,
(s/L) sin(w t + psi)), ``second_harmonic`` (an envelope-shaped wave at 2 w: a non-sinusoidal stroke), and
``amplitude_vs_frequency`` (the wave's coefficients linear in the drive frequency: identifiable across files
only; within one file it is the base wave again and never helps).

One model, fitted by the engine: the effects that reshape the wave (r, p, lambda/L, kappa, h) declare those
*shared* nonlinear parameters (:attr:`calibration.engine.Family.shared_params`), and the base columns are the
wave with their current values (:attr:`calibration.engine.Family.base_columns_fn`); ``head_yaw`` and
``second_harmonic`` swing at the fitted beat frequency. The engine searches the nonlinear values with the
linear ones solved inside (variable projection) and re-fits the earlier ones after each addition.

Selection criterion (:attr:`FAMILY.alpha <calibration.engine.Family.alpha>` = 0.01, ``min_relative_drop`` =
0.03), looser than the joint's and drive's (1e-3, 10 %), because a video is short: a 5-9 s record of 7 markers
at 60 fps has ~1000-3700 rows, but its residual is a smooth curve correlated over ~0.1-0.3 s, so the held-out
set (3 blocks of 0.5-0.9 s) holds few independent samples: measured n_eff of the held-out residual, summed over
the markers, 46-117 on the fishsim files (f2_25 base model 46, f1_75 final model 117). With n_eff = 46 and
one parameter, a 10 % drop of the RMSE (19 % of the SSE) gives F = 10.8, p = 0.002: the joint's 1e-3 would
refuse a departure that is plain to the eye, and on a 5 s video nothing short of an 11 % drop would count.
At alpha = 0.01 a drop must still be significant (a 3 % drop, 6 % of the SSE, needs n_eff > ~110), and the 3 %
margin (that of the family's first, stand-alone selection code) keeps the last, marginal effects out. On the
clean paper wave with noise (synthetic, tests) nothing is added. Override with ``swiftfin fit --alpha`` and
``--min-drop``.

Held-out error: contiguous time blocks within a file, or whole files across drive frequencies (``swiftfin fit
body A.csv B.csv ... --holdout C.csv``, and :func:`cross_file_rmse` for leave-one-file-out). Every file's clock
is synced to its own tail tip (:func:`align_to_tail`): the video's start is arbitrary, and across files that
phase is the one number a held-out video must supply. Error = RMSE of y [m] over held-out samples.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from swiftfin.calibration.fishsim import (BEAT_RATIO_RANGE, MarkerData, dominant_frequency_hz, load_marker_files,
                                          load_markers)
from swiftfin.calibration.model import Context, Effect, Family, Param, concat_contexts
from swiftfin.calibration.selection import Calibrator

BODY_MARKERS = tuple(range(2, 9))
TAIL_MARKER = 8
F_REF_HZ = 1.0
#: the paper's wave: beat ratio 1, envelope exponent 2, wavelength 1.25 L, no extra phase, no rigid front
PAPER_WAVE = {"ratio": 1.0, "p": 2.0, "lam": 1.25, "kappa": 0.0, "h": 0.0}
SHARED = tuple(PAPER_WAVE)


@dataclass(frozen=True)
class BodySamples:
    """Flattened samples: one row per (frame, marker). ``file`` indexes ``sources``."""
    t_s: np.ndarray
    s_m: np.ndarray
    y_m: np.ndarray
    L_m: np.ndarray
    f_drive_hz: np.ndarray
    marker: np.ndarray
    file: np.ndarray
    sources: tuple = ()

    def __len__(self) -> int:
        return len(self.y_m)

    def subset(self, mask) -> "BodySamples":
        mask = np.asarray(mask)
        return BodySamples(self.t_s[mask], self.s_m[mask], self.y_m[mask], self.L_m[mask],
                           self.f_drive_hz[mask], self.marker[mask], self.file[mask], self.sources)

    @staticmethod
    def concat(parts) -> "BodySamples":
        parts = list(parts)
        return BodySamples(*(np.concatenate([getattr(p, n) for p in parts])
                             for n in ("t_s", "s_m", "y_m", "L_m", "f_drive_hz", "marker", "file")),
                           sources=sum((tuple(p.sources) for p in parts), ()))


def samples_from_markers(data: MarkerData, file_index: int = 0, time_shift_s: float = 0.0) -> BodySamples:
    """Valid body-marker samples of one file (markers dropped by the cleaning have NaN arc and are skipped)."""
    rows = []
    for m in BODY_MARKERS:
        if not np.isfinite(data.arc_m[m]):
            continue
        ok = data.valid[:, m] & np.isfinite(data.y_m[:, m])
        n = int(ok.sum())
        rows.append((data.time_s[ok] + time_shift_s, np.full(n, data.arc_m[m]), data.y_m[ok, m],
                     np.full(n, data.body_length_m), np.full(n, data.drive_frequency_hz), np.full(n, m),
                     np.full(n, file_index)))
    cols = [np.concatenate(c) for c in zip(*rows)]
    return BodySamples(*cols, sources=(data.source,))


def align_to_tail(data: MarkerData, ratio: float | None = None) -> float:
    """Time shift [s] that puts the tail tip's fundamental at phase zero: the clock sync of a held-out video
    (its one free number; the video's start is arbitrary). The fundamental is taken at ratio * f_drive, or at
    the tail tip's spectral peak when ``ratio`` is None."""
    f = (dominant_frequency_hz(data.time_s, data.y_m[:, TAIL_MARKER]) if ratio is None
         else ratio * data.drive_frequency_hz)
    w = 2.0 * np.pi * f
    ok = data.valid[:, TAIL_MARKER]
    t, y = data.time_s[ok], data.y_m[ok, TAIL_MARKER]
    X = np.column_stack([np.ones_like(t), np.sin(w * t), np.cos(w * t)])
    c, *_ = np.linalg.lstsq(X, y, rcond=None)
    # y ~ A sin(w t + psi); with t' = t + psi / w the fundamental becomes A sin(w t')
    psi = np.arctan2(c[2], c[1])
    return float(psi / w)


def samples_context(S: BodySamples, spectral_ratio: float = 1.0, source: str = "<memory>") -> Context:
    """Engine context from samples: rows sorted by (file, marker, time), one series per marker and file.
    Signals: s_m, L_m, f_drive_hz, t_s, marker, position (= arc position s), velocity (lateral velocity by
    central differences), input (crank angle sin 2 pi f t). ``spectral_ratio``: tail-tip spectral peak / drive
    frequency, the centre of the beat-ratio search."""
    S = S.subset(np.lexsort((S.t_s, S.marker, S.file)))
    series = (S.file * 10 + S.marker).astype(int)
    vel = np.zeros(len(S))
    for sid in np.unique(series):
        m = series == sid
        if m.sum() > 2:
            vel[m] = np.gradient(S.y_m[m], S.t_s[m])
    signals = {"s_m": S.s_m, "L_m": S.L_m, "f_drive_hz": S.f_drive_hz, "t_s": S.t_s, "position": S.s_m,
               "velocity": vel, "input": np.sin(2.0 * np.pi * S.f_drive_hz * S.t_s),
               "marker": S.marker.astype(float)}
    ctx = Context(S.t_s, S.y_m, np.zeros(len(S)), np.zeros((len(S), 2)), signals, source, series,
                  meta={"spectral_ratio": float(spectral_ratio), "sources": list(S.sources)})
    ctx.base_columns = wave_columns(ctx, {})
    return ctx


def body_context(datas: list[MarkerData], time_shifts_s=None) -> Context:
    """Engine context from one or more marker files (each shifted by ``time_shifts_s``; default: synced to its
    own tail tip, :func:`align_to_tail`)."""
    shifts = [align_to_tail(d) for d in datas] if time_shifts_s is None else list(time_shifts_s)
    S = BodySamples.concat([samples_from_markers(d, i, float(sh)) for i, (d, sh) in enumerate(zip(datas, shifts))])
    ratios = [dominant_frequency_hz(d.time_s, d.y_m[:, TAIL_MARKER]) / d.drive_frequency_hz for d in datas]
    return samples_context(S, float(np.median(ratios)), " + ".join(d.source for d in datas))


# ------------------------------------------------------------------------------------------ the model

def wave_columns(ctx: Context, nl: dict, harmonic: int = 1) -> np.ndarray:
    """The travelling wave's two columns env(s) (sin, cos)(harmonic * theta) with the current shape values
    ``nl`` (missing = the paper's): theta = 2 pi s / (lam L) + kappa (s/L)^2 - 2 pi r f_drive t,
    env = clip((s/L - h) / (1 - h), 0)^p."""
    g = ctx.signals
    v = {**PAPER_WAVE, **{k: nl[k] for k in SHARED if k in nl}}
    u = g["s_m"] / g["L_m"]
    th = (2.0 * np.pi / (v["lam"] * g["L_m"]) * g["s_m"] + v["kappa"] * u**2
          - 2.0 * np.pi * v["ratio"] * g["f_drive_hz"] * g["t_s"])
    env = np.clip((u - v["h"]) / (1.0 - v["h"]), 0.0, None) ** v["p"]
    return np.column_stack([env * np.sin(harmonic * th), env * np.cos(harmonic * th)])


class _BodyEffect(Effect):
    def grid(self, param: Param, ctx: Context) -> np.ndarray:
        if param.name == "ratio":
            # fine steps around the tail tip's spectral peak, coarse over the whole range
            r0 = float(ctx.meta.get("spectral_ratio", 1.0))
            g = np.concatenate([r0 + np.linspace(-0.03, 0.03, 7), np.linspace(param.lo, param.hi, 12)])
            return np.unique(np.clip(g, param.lo + 1e-3, param.hi - 1e-3))
        return param.grid_values()


def _no_columns(ctx, nl):
    return np.zeros((ctx.n, 0))


def _lever(ctx, nl):
    g = ctx.signals
    w = 2.0 * np.pi * nl.get("ratio", 1.0) * g["f_drive_hz"] * g["t_s"]
    u = g["s_m"] / g["L_m"]
    return np.column_stack([u * np.sin(w), u * np.cos(w)])


def _offset_cols(ctx, nl):
    u = ctx.signals["s_m"] / ctx.signals["L_m"]
    return np.column_stack([u, u**2, u**3])


def _offset_plausible(v, ctx):
    """The three coefficients are nearly collinear over the tracked part of the body, so judge the offset
    itself: it must stay within half a body length where the markers are."""
    u = np.unique(ctx.signals["s_m"] / ctx.signals["L_m"])
    off = v["c1_m"] * u + v["c2_m"] * u**2 + v["c3_m"] * u**3
    L = float(np.median(ctx.signals["L_m"]))
    return [] if np.max(np.abs(off)) < 0.5 * L else [f"lateral offset {np.max(np.abs(off)):.3g} m > L/2"]


def _amp_plausible(a: str, b: str, what: str):
    def fn(v, ctx):
        amp = float(np.hypot(v[a], v[b]))
        L = float(np.median(ctx.signals["L_m"]))
        return [] if amp < 0.5 * L else [f"{what} amplitude {amp:.3g} m > L/2"]
    return fn


def _amp_physical(a: str, b: str, name: str):
    def fn(v, s, ctx):
        amp = float(np.hypot(v[a], v[b]))
        std = float(np.hypot(v[a] * s.get(a, np.nan), v[b] * s.get(b, np.nan)) / amp) if amp > 0 else float("nan")
        return {name: (amp, std, "m")}
    return fn


def _freq_wave(ctx, nl):
    phi = ctx.signals["f_drive_hz"] / F_REF_HZ - 1.0
    return phi[:, None] * wave_columns(ctx, nl)


def _pair(prefix: str, doc: str) -> tuple[Param, Param]:
    return (Param(f"{prefix}1_m", "m", -1.0, 1.0, doc + " (sine part)"),
            Param(f"{prefix}2_m", "m", -1.0, 1.0, doc + " (cosine part)"))


RATIO = Param("ratio", "-", *BEAT_RATIO_RANGE, "tail-beat frequency / drive frequency")
EXPONENT = Param("p", "-", 0.5, 14.0, "envelope exponent (paper: 2)", scale="log", grid=16)

ENGINE_EFFECTS: tuple[Effect, ...] = (
    _BodyEffect(name="tail_beat_frequency",
                meaning="the tail beats at r times the drive frequency, not at it (the whole wave's frequency)",
                fingerprint="the residual beats against the wave: a phase drift between model and tail over time",
                nonlinear=(RATIO,), fingerprint_axis="time", columns_fn=_no_columns),
    _BodyEffect(name="lateral_offset",
                meaning="asymmetric stroke or bent rest shape: a time-invariant lateral offset "
                        "c1 (s/L) + c2 (s/L)^2 + c3 (s/L)^3",
                fingerprint="a residual mean that differs from zero and grows along the body",
                linear=(Param("c1_m", "m", -100.0, 100.0, "offset coefficient of s/L"),
                        Param("c2_m", "m", -100.0, 100.0, "offset coefficient of (s/L)^2"),
                        Param("c3_m", "m", -100.0, 100.0, "offset coefficient of (s/L)^3")),
                fingerprint_axis="position", columns_fn=_offset_cols, plausible_fn=_offset_plausible),
    _BodyEffect(name="envelope_shape",
                meaning="amplitude grows as (s/L)^p, not (s/L)^2 (stiff front, bending tail)",
                fingerprint="residual amplitude that changes sign along the body against a u^2 envelope",
                nonlinear=(EXPONENT,), fingerprint_axis="position", columns_fn=_no_columns),
    _BodyEffect(name="rigid_front",
                meaning="the front fraction h of the body does not bend: the envelope starts at s = h L and grows "
                        "as ((s/L - h)/(1 - h))^p behind it (h and p fitted; p = 1 is a rigid tail on a hinge)",
                fingerprint="model motion where the body does not move (front markers), too little at the tail",
                nonlinear=(Param("h", "-", 0.0, 0.9, "rigid front fraction", grid=10),
                           Param("p", "-", 0.5, 14.0, "envelope exponent behind it", scale="log", grid=8)),
                fingerprint_axis="position", columns_fn=_no_columns),
    _BodyEffect(name="wavelength", meaning="wavelength lambda = (lambda/L) L fitted instead of 1.25 L",
                fingerprint="residual phase that grows linearly along the body",
                nonlinear=(Param("lam", "-", 0.3, 8.0, "wavelength / body length", scale="log", grid=16),),
                fingerprint_axis="position", columns_fn=_no_columns),
    _BodyEffect(name="phase_lag", meaning="extra phase kappa (s/L)^2 along the body: the wave speed changes along it",
                fingerprint="residual phase that grows quadratically along the body",
                nonlinear=(Param("kappa", "rad", -6.28, 6.28, "extra phase at the tail", grid=13),),
                fingerprint_axis="position", columns_fn=_no_columns),
    _BodyEffect(name="head_yaw",
                meaning="recoil: the head yaws against the body, so in the head frame the body swings as a rigid "
                        "lever about the nose with its own phase, (s/L)(h1 sin wt + h2 cos wt), at the beat "
                        "frequency. Where the front of the body is rigid (fishsim: markers 0-2), read it as a "
                        "standing, in-phase swing of the tail added to the travelling wave",
                fingerprint="residual at the beat frequency growing linearly along the body, one phase for all",
                linear=_pair("h", "lever swing at the tail"), fingerprint_axis="position", columns_fn=_lever,
                plausible_fn=_amp_plausible("h1_m", "h2_m", "head-yaw swing"),
                physical_fn=_amp_physical("h1_m", "h2_m", "head_yaw_swing_at_tail_m")),
    _BodyEffect(name="second_harmonic",
                meaning="a wave at twice the beat frequency with the same envelope (a non-sinusoidal stroke)",
                fingerprint="a residual peak at twice the beat frequency in the spectrum",
                linear=_pair("d", "second harmonic"), fingerprint_axis="time",
                columns_fn=lambda ctx, nl: wave_columns(ctx, nl, harmonic=2),
                plausible_fn=_amp_plausible("d1_m", "d2_m", "second-harmonic"),
                physical_fn=_amp_physical("d1_m", "d2_m", "second_harmonic_amplitude_m")),
    _BodyEffect(name="amplitude_vs_frequency",
                meaning="the wave's coefficients vary linearly with the drive frequency (f/1 Hz - 1) (only "
                        "identifiable across files)",
                fingerprint="held-out files at other drive frequencies beat with a different amplitude",
                linear=_pair("da", "wave coefficient per unit of f/1 Hz - 1"), fingerprint_axis="time",
                columns_fn=_freq_wave),
)


def tail_rows(ctx: Context) -> np.ndarray:
    """Rows of the tail-tip marker (the most posterior marker present): what the report plots."""
    m = ctx.signals["marker"]
    return m == m.max()


def _notes(d: MarkerData, path, notes):
    if notes is not None:
        c = d.cleaning
        notes.append(f"{path}: pixel scale {d.pixels_per_m:.1f} px/m; body axis turned "
                     f"{d.body_axis_rotation_deg:.2f} deg; invalid samples: merged {c['merged_samples_invalid']}, "
                     f"displaced {c['displaced_samples_invalid']}, jumps {c['jump_samples_invalid']}; "
                     f"interpolated {c['samples_interpolated']}; left out {c['samples_left_out']}; "
                     f"markers dropped {c['markers_dropped']}")


def load(path, design=None, notes: list | None = None) -> Context:
    """Engine loader: one ``markers_fX_YY.csv`` file (see :mod:`calibration.fishsim`). ``design`` unused.
    The cleaning report goes to ``notes``."""
    d = load_markers(path)
    _notes(d, path, notes)
    return body_context([d])


def load_many(paths, design=None, notes: list | None = None) -> list[Context]:
    """Several marker files of one body (nominal marker positions pooled, :func:`load_marker_files`): one
    context per file, each synced to its own tail tip."""
    datas = load_marker_files([Path(p) for p in paths])
    for d, p in zip(datas, paths):
        _notes(d, p, notes)
    return [body_context([d]) for d in datas]


FAMILY = Family(
    name="body",
    description="swimming body midline from video markers vs the paper's travelling wave (eq. 43-45)",
    columns=(),
    target="lateral_m",
    target_unit="m",
    base_terms=("travelling wave y = (s/L)^p (a sin + b cos)(2 pi s / (lam L) + kappa (s/L)^2 - 2 pi r f_drive t), "
                "paper: p = 2, lam = 1.25, kappa = 0, r = 1 (eq. 43-45)",),
    effects=ENGINE_EFFECTS,
    load=load,
    base_coef_names=("wave_sin_m", "wave_cos_m"),
    units={"lateral": "m", "position": "m", "arc_position": "m", "velocity": "m/s", "time": "s",
           "frequency": "Hz"},
    base_columns_fn=wave_columns,
    shared_params=SHARED,
    alpha=0.01,
    min_relative_drop=0.03,
    plot_rows_fn=tail_rows,
    load_many=load_many,
)


def cross_file_rmse(datas: list[MarkerData], effects=(), **calibrator_options) -> dict:
    """Leave one file out, with the engine: fit exactly ``effects`` (shared parameters) on the other files,
    predict the held-out one (every file's clock synced to its own tail tip). Returns {drive frequency [Hz]:
    held-out RMSE [m]} and the pooled RMSE under 'all', and the fitted models under 'models'."""
    ctxs = [body_context([d]) for d in datas]
    out, sse, n, models = {}, 0.0, 0, {}
    for i, d in enumerate(datas):
        train = concat_contexts([c for j, c in enumerate(ctxs) if j != i])
        cal = Calibrator(FAMILY, forced_effects=tuple(effects), **calibrator_options).fit(train, ctxs[i])
        r = cal.residual(ctxs[i])
        out[d.drive_frequency_hz] = float(np.sqrt(np.mean(r**2)))
        models[d.drive_frequency_hz] = cal
        sse += float(r @ r)
        n += r.size
    out["all"] = float(np.sqrt(sse / n))
    out["models"] = models
    return out
