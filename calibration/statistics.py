"""Statistics of residuals: autocorrelation, whiteness, effective sample size and the selection's tests.

Pure functions of arrays (no model, no family): :func:`acf`, :func:`ljung_box`,
:func:`effective_sample_fraction` and :func:`effective_sample_size` (autocorrelated series, one or several
stacked), and the two tests the selection uses on held-out errors, :func:`heldout_f_test` (the criterion) and
:func:`block_test` (reported beside it).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import stats


def acf(x: np.ndarray, nlags: int) -> np.ndarray:
    """Sample autocorrelation at lags 0..nlags (biased estimator, FFT)."""
    x = np.asarray(x, float) - np.mean(x)
    n = x.size
    if n < 2 or not np.any(x):
        return np.r_[1.0, np.zeros(nlags)]
    m = 1 << int(math.ceil(math.log2(2 * n)))
    f = np.fft.rfft(x, m)
    r = np.fft.irfft(f * np.conj(f), m)[: nlags + 1]
    return r / r[0]


def ljung_box(x: np.ndarray, nlags: int) -> tuple[float, float]:
    """Ljung-Box statistic Q and its p-value (chi-square, ``nlags`` dof) for whiteness of ``x``."""
    n = x.size
    r = acf(x, nlags)[1:]
    q = n * (n + 2) * float(np.sum(r**2 / (n - np.arange(1, nlags + 1))))
    return q, float(stats.chi2.sf(q, nlags))


def effective_sample_fraction(x: np.ndarray, max_lag: int = 200) -> float:
    """n_eff / n of an autocorrelated series: 1 / (1 + 2 sum rho_k), summed until rho first drops below 0.05."""
    r = acf(x, min(max_lag, max(1, x.size // 4)))
    s = 0.0
    for k in range(1, r.size):
        if r[k] < 0.05:
            break
        s += r[k]
    return 1.0 / (1.0 + 2.0 * s)


def _group_runs(groups: np.ndarray | None, n: int) -> list[np.ndarray]:
    """Index runs of equal consecutive ``groups`` labels (one run per contiguous series); all rows if None."""
    if groups is None:
        return [np.arange(n)]
    g = np.asarray(groups)
    br = np.flatnonzero(g[1:] != g[:-1]) + 1
    return [a for a in np.split(np.arange(n), br) if a.size]


def block_test(e_before: np.ndarray, e_after: np.ndarray, n_blocks: int = 40,
               groups: np.ndarray | None = None) -> float:
    """One-sided p-value that the mean squared error dropped, from a paired t-test on contiguous block means.

    ``groups``: a label per row; rows of one contiguous series carry one label. Blocks are then cut inside each
    series (in proportion to its length), so the test does not depend on the order the series are stacked in."""
    d = e_before**2 - e_after**2
    n_blocks = int(max(4, min(n_blocks, d.size // 10)))
    if d.size < 2 * n_blocks:
        return 1.0
    runs = _group_runs(groups, d.size)
    chunks = []
    for r in runs:
        k = max(1, int(round(n_blocks * r.size / d.size)))
        chunks += [d[c] for c in np.array_split(r, min(k, r.size)) if c.size]
    means = np.array([b.mean() for b in chunks])
    n_blocks = means.size
    if n_blocks < 3:
        return 1.0
    sd = means.std(ddof=1)
    if sd == 0:
        return 0.0 if means.mean() > 0 else 1.0
    tstat = means.mean() / (sd / math.sqrt(n_blocks))
    return float(stats.t.sf(tstat, n_blocks - 1))


def effective_sample_size(e: np.ndarray, groups: np.ndarray | None = None) -> float:
    """n_eff of a residual made of one or more contiguous series: the sum over series of
    n_i x :func:`effective_sample_fraction` of that series' own residual (its own autocorrelation; a series too
    short to estimate one, under 8 rows, counts as one sample). Independent of the order the series are stacked
    in; ``groups`` labels the rows (consecutive equal labels = one series), None = one series."""
    total = 0.0
    for r in _group_runs(groups, e.size):
        total += r.size * effective_sample_fraction(e[r]) if r.size >= 8 else 1.0
    return total


def heldout_f_test(e_before: np.ndarray, e_after: np.ndarray, k: int, groups: np.ndarray | None = None) -> float:
    """p-value of the held-out error drop: F = ((SSE_before - SSE_after) / k) / (SSE_after / n_eff) on (k, n_eff)
    degrees of freedom, n_eff = :func:`effective_sample_size` of the after-residual, computed per contiguous
    series (``groups``) and summed (autocorrelation shrinks the information a long log holds; estimating it on
    series glued end to end would make the p-value depend on their order). Unlike the block t-test it keeps its
    power when the gain is concentrated in a few moments (slips, reversals)."""
    sb, sa = float(e_before @ e_before), float(e_after @ e_after)
    n = e_after.size
    if n < 4 or sa <= 0:
        return 0.0 if sb > sa else 1.0
    n_eff = max(2.0, effective_sample_size(e_after, groups))
    k = max(int(k), 1)
    f = ((sb - sa) / k) / (sa / n_eff)
    return float(stats.f.sf(f, k, n_eff)) if f > 0 else 1.0


__all__ = ["acf", "ljung_box", "effective_sample_fraction", "effective_sample_size", "block_test",
           "heldout_f_test"]
