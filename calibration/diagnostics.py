"""Residual diagnosis: what structure a residual still holds, and whether it counts as white.

:func:`diagnose` measures a residual's mean, its predictability from its own past (AR), its structure against
velocity and position (binned means) and its cross-correlation with the input's rate, and flags the residual as
white or as holding unexplained structure (:class:`Diagnosis`). Learnt on the train rows, scored on the
held-out rows.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from swiftfin.calibration.model import Context
from swiftfin.calibration.statistics import acf, ljung_box

# ------------------------------------------------------------------------------------------------ diagnostics


def _series_slices(ctx_series: np.ndarray | None, rows: np.ndarray) -> list[np.ndarray]:
    """Row-index runs that are contiguous in time: split at series changes and at gaps in ``rows``."""
    idx = np.flatnonzero(rows)
    if idx.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(idx) != 1) + 1
    if ctx_series is not None:
        s = ctx_series[idx]
        breaks = np.union1d(breaks, np.flatnonzero(np.diff(s) != 0) + 1)
    return [a for a in np.split(idx, breaks) if a.size > 0]


@dataclass
class Diagnosis:
    """What the residual still contains. Fractions are shares of held-out residual variance.

    mean_fraction : mean^2 / mean square of the held-out residual (a constant the model misses).
    ar_predictable : explained by an AR(p) model of its own past (fitted on train rows, scored on holdout).
    velocity_binned, position_binned : explained by its mean in 20 quantile bins of velocity / position.
    input_xcorr_max, input_xcorr_lag_s : largest |cross-correlation| with the input's rate, and its lag.
    ljung_box_q, ljung_box_p : whiteness test on the held-out residual (reported; with 1e4+ samples it rejects
                               structure far below anything a model could use, hence the effect-size test).
    white : structure_score < threshold (and, when set by the engine, structure_score_train too: the same
            diagnosis with train and held-out rows swapped).
    """

    rmse: float
    mean_fraction: float
    ar_predictable: float
    velocity_binned: float
    position_binned: float
    input_xcorr_max: float
    input_xcorr_lag_s: float
    ljung_box_q: float
    ljung_box_p: float
    acf: list
    structure_score: float
    white: bool
    structure_score_train: float = float("nan")

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def _binned_fraction(x: np.ndarray, r: np.ndarray, train: np.ndarray, hold: np.ndarray, nbins: int = 20,
                     max_rows: int = 200_000) -> float:
    ti, hi = np.flatnonzero(train), np.flatnonzero(hold)
    ti = ti[:: max(1, ti.size // max_rows)]          # bin means need no contiguity: thin very long logs
    hi = hi[:: max(1, hi.size // max_rows)]
    xt, rt = x[ti], r[ti]
    if xt.size < 4 * nbins or np.ptp(xt) <= 0:
        return 0.0
    edges = np.unique(np.quantile(xt, np.linspace(0, 1, nbins + 1)))
    if edges.size < 3:
        return 0.0
    bt = np.clip(np.searchsorted(edges, xt, side="right") - 1, 0, edges.size - 2)
    means = np.bincount(bt, weights=rt, minlength=edges.size - 1) / np.maximum(np.bincount(bt, minlength=edges.size - 1), 1)
    xh, rh = x[hi], r[hi]
    bh = np.clip(np.searchsorted(edges, xh, side="right") - 1, 0, edges.size - 2)
    ss = float(np.sum((rh - rh.mean()) ** 2))
    if ss <= 0:
        return 0.0
    pred = means[bh] - np.mean(means[bh]) + rh.mean()
    return float(max(0.0, 1.0 - np.sum((rh - pred) ** 2) / ss))


def _ar_fraction(r: np.ndarray, series: np.ndarray | None, train: np.ndarray, hold: np.ndarray, p: int = 10,
                 max_rows: int = 200_000) -> float:
    def lagged(rows):
        X, Y = [], []
        total = 0
        for idx in _series_slices(series, rows):
            if idx.size <= p + 1:
                continue
            if total >= max_rows:
                break
            idx = idx[: max_rows - total + p]
            total += idx.size
            seg = r[idx]
            X.append(np.column_stack([seg[p - k - 1: seg.size - k - 1] for k in range(p)]))
            Y.append(seg[p:])
        if not X:
            return None, None
        return np.vstack(X), np.concatenate(Y)

    Xt, Yt = lagged(train)
    Xh, Yh = lagged(hold)
    if Xt is None or Xh is None:
        return 0.0
    mu = Yt.mean()
    coef, *_ = np.linalg.lstsq(Xt - mu, Yt - mu, rcond=None)
    ss = float(np.sum((Yh - Yh.mean()) ** 2))
    if ss <= 0:
        return 0.0
    return float(max(0.0, 1.0 - np.sum((Yh - mu - (Xh - mu) @ coef) ** 2) / ss))


def diagnose(ctx: Context, residual: np.ndarray, train: np.ndarray, hold: np.ndarray,
             threshold: float = 0.15, nlags: int = 40) -> Diagnosis:
    """Diagnose a residual: whiteness, predictability from its own past, structure against velocity, position
    and the input (see :class:`Diagnosis`). ``structure_score`` = max(mean_fraction, ar_predictable,
    velocity_binned, position_binned); the residual is called white when it is below ``threshold`` (default 15 %
    of its mean square)."""
    rh = residual[hold]
    rmse = float(np.sqrt(np.mean(rh**2))) if rh.size else float("nan")
    slices = _series_slices(ctx.series, hold)
    longest = max(slices, key=len) if slices else np.arange(0)
    lags = min(nlags, max(1, longest.size // 5))
    a = acf(residual[longest], lags) if longest.size > 2 else np.ones(1)
    q, pv = ljung_box(residual[longest], lags) if longest.size > lags + 2 else (float("nan"), float("nan"))
    ar = _ar_fraction(residual, ctx.series, train, hold)
    vb = _binned_fraction(ctx.signals["velocity"], residual, train, hold)
    pb = _binned_fraction(ctx.signals["position"], residual, train, hold)
    # cross-correlation of the residual with the rate of the input, lags +-0.2 s
    xc_max, xc_lag = 0.0, 0.0
    if longest.size > 10:
        u = np.gradient(ctx.signals["input"][longest], ctx.t[longest])
        e = residual[longest] - residual[longest].mean()
        u = u - u.mean()
        den = float(np.sqrt(np.sum(u**2) * np.sum(e**2)))
        if den > 0:
            dt = float(np.median(np.diff(ctx.t[longest])))
            L = int(min(longest.size // 4, max(1, round(0.2 / dt))))
            cc = signal.correlate(e, u, mode="full", method="fft")[longest.size - 1 - L: longest.size + L] / den
            k = int(np.argmax(np.abs(cc)))
            xc_max, xc_lag = float(abs(cc[k])), float((k - L) * dt)
    ms = float(np.mean(rh**2)) if rh.size else 0.0
    mf = float(np.mean(rh) ** 2 / ms) if ms > 0 else 0.0
    score = max(mf, ar, vb, pb)
    return Diagnosis(rmse, mf, ar, vb, pb, xc_max, xc_lag, q, pv, [float(v) for v in a[: min(a.size, 41)]],
                     score, bool(score < threshold))


__all__ = ["Diagnosis", "diagnose"]
