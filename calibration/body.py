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

Candidate effects (how a real body departs from it), see :data:`EFFECTS`:
``tail_beat_frequency`` (tail beats at r * f_drive, r fitted), ``lateral_offset`` (asymmetric stroke / bent
rest shape, time-invariant c1 s/L + c2 (s/L)^2), ``envelope_shape`` (exponent p instead of 2: a stiff front
and a bending tail), ``wavelength`` (lambda/L fitted instead of 1.25), ``phase_lag`` (extra phase
kappa (s/L)^2: a wave speed that changes along the body), ``head_yaw`` (recoil: the head yaws, so in the head
frame the body swings as a rigid lever, (s/L) sin(w t + psi)), ``second_harmonic`` (an envelope-shaped wave at
2 w: a non-sinusoidal stroke), and, across files only, ``amplitude_vs_frequency`` (the wave's coefficients
linear in the drive frequency).

Every model is linear in its coefficients once the nonlinear parameters (r, p, lambda/L, kappa) are fixed:
those are searched (a grid for the one being added, then a bounded Powell search over all of them) with
the linear ones solved by least squares inside (variable projection).
Uncertainties: Gauss-Newton covariance sigma^2 (J'J)^-1 over all parameters at the optimum; the residuals are
correlated in time, so these are lower bounds.
Held-out error: contiguous time blocks within a file (k-fold over blocks), or whole files across drive
frequencies. Error = RMSE of y [m] over held-out samples.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from calibration.engine import Context, Effect, Family, Param
from calibration.fishsim import MarkerData, dominant_frequency_hz, load_markers

BODY_MARKERS = tuple(range(2, 9))
DEFAULT_NL = {"ratio": 1.0, "p": 2.0, "lam": 1.25, "kappa": 0.0, "h": 0.0}
NL_BOUNDS = {"ratio": (0.3, 2.0), "p": (0.5, 14.0), "lam": (0.3, 8.0), "kappa": (-2 * np.pi, 2 * np.pi),
             "h": (0.0, 0.9)}
NL_GRID = {"ratio": np.linspace(0.3, 2.0, 69), "p": np.geomspace(0.7, 12.0, 25),
           "lam": np.geomspace(0.35, 6.0, 30), "kappa": np.linspace(-6.0, 6.0, 25), "h": np.linspace(0.0, 0.85, 35)}
F_REF_HZ = 1.0


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
                           sources=parts[0].sources)


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


# ------------------------------------------------------------------------------------------ effects

@dataclass(frozen=True)
class BodyEffect:
    name: str
    meaning: str
    linear: tuple[str, ...]     # names of its linear coefficients
    nonlinear: tuple[str, ...]  # names of its nonlinear parameters (keys of DEFAULT_NL)
    across_files_only: bool = False


EFFECTS: dict[str, BodyEffect] = {e.name: e for e in [
    BodyEffect("tail_beat_frequency", "the tail beats at r times the drive frequency, not at it", (), ("ratio",)),
    BodyEffect("lateral_offset", "asymmetric stroke or bent rest shape: a time-invariant lateral offset "
               "c1 (s/L) + c2 (s/L)^2 + c3 (s/L)^3", ("c1_m", "c2_m", "c3_m"), ()),
    BodyEffect("envelope_shape", "amplitude grows as (s/L)^p, not (s/L)^2 (stiff front, bending tail)",
               (), ("p",)),
    BodyEffect("rigid_front", "the front fraction h of the body does not bend: the envelope starts at s = h L "
               "and grows as ((s/L - h)/(1 - h))^p behind it (h and p fitted; p = 1 is a rigid tail on a hinge)",
               (), ("h", "p")),
    BodyEffect("wavelength", "wavelength lambda = (lambda/L) L fitted instead of 1.25 L", (), ("lam",)),
    BodyEffect("phase_lag", "extra phase kappa (s/L)^2 along the body: the wave speed changes along it",
               (), ("kappa",)),
    BodyEffect("head_yaw", "recoil: the head yaws against the body, so in the head frame the body swings as a "
               "rigid lever about the nose with its own phase, (s/L)(h1 sin wt + h2 cos wt). Where the front of "
               "the body is rigid (fishsim: markers 0-2), read it as a standing, in-phase swing of the tail "
               "added to the travelling wave", ("h1_m", "h2_m"), ()),
    BodyEffect("second_harmonic", "a wave at twice the beat frequency with the same envelope "
               "(a non-sinusoidal stroke)", ("d1_m", "d2_m"), ()),
    BodyEffect("amplitude_vs_frequency", "the wave's coefficients vary linearly with drive frequency "
               "(only identifiable across files)", ("da_m", "db_m"), (), across_files_only=True),
]}


def _columns(S: BodySamples, effects, nl: dict, freq_dependent=()):
    """Design matrix and coefficient names for the base wave plus ``effects``."""
    u = S.s_m / S.L_m
    k = 2.0 * np.pi / (nl["lam"] * S.L_m)
    w = 2.0 * np.pi * nl["ratio"] * S.f_drive_hz
    th = k * S.s_m + nl["kappa"] * u**2 - w * S.t_s
    env = np.clip((u - nl["h"]) / (1.0 - nl["h"]), 0.0, None) ** nl["p"]
    cols = [env * np.sin(th), env * np.cos(th)]
    names = ["wave.a_m", "wave.b_m"]
    phi = S.f_drive_hz / F_REF_HZ - 1.0
    for e in effects:
        if e == "lateral_offset":
            c = [u, u**2, u**3]
        elif e == "head_yaw":
            c = [u * np.sin(w * S.t_s), u * np.cos(w * S.t_s)]
        elif e == "second_harmonic":
            c = [env * np.sin(2 * th), env * np.cos(2 * th)]
        elif e == "amplitude_vs_frequency":
            c = [phi * cols[0], phi * cols[1]]
        else:
            c = []
        cols += c
        names += [f"{e}.{p}" for p in EFFECTS[e].linear]
        if e in freq_dependent and c:
            cols += [phi * ci for ci in c]
            names += [f"{e}.{p}_per_rel_hz" for p in EFFECTS[e].linear]
    return np.column_stack(cols), names


def _lstsq(X: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Least squares by the normal equations on unit-norm columns (50x faster than an SVD for these tall,
    narrow, well-scaled problems); falls back to the SVD solver if the system is singular."""
    scale = np.linalg.norm(X, axis=0)
    scale[scale == 0] = 1.0
    Xs = X / scale
    try:
        theta = np.linalg.solve(Xs.T @ Xs, Xs.T @ y)
    except np.linalg.LinAlgError:
        theta = np.linalg.lstsq(Xs, y, rcond=None)[0]
    return theta / scale


def _nl_names(effects) -> list[str]:
    out: list[str] = []
    for e in effects:
        out += [p for p in EFFECTS[e].nonlinear if p not in out]
    return out


@dataclass
class BodyWave:
    """The travelling wave plus named ``effects``: an estimator, ``fit(samples) -> self``.

    Learned: ``coef_`` (linear coefficients), ``nl_`` (nonlinear parameters, defaults for those not fitted),
    ``stderr_`` (all parameters), ``rmse_train_`` [m], ``summary_`` (physical quantities: tail amplitude [m],
    ratio, exponent, lambda/L, ...).
    """
    effects: tuple[str, ...] = ()
    freq_dependent: tuple[str, ...] = ()
    init: dict | None = None

    def _sse(self, S, nl):
        X, _ = _columns(S, self.effects, nl, self.freq_dependent)
        theta = _lstsq(X, S.y_m)
        r = S.y_m - X @ theta
        return float(r @ r)

    def fit(self, S: BodySamples) -> "BodyWave":
        names = _nl_names(self.effects)
        nl = dict(DEFAULT_NL)
        if self.init:
            nl.update({k: v for k, v in self.init.items() if k in nl})
        # grid over each nonlinear parameter not given a start value, the others held
        for n in names:
            if self.init and n in self.init:
                continue
            best = min(NL_GRID[n], key=lambda v: self._sse(S, {**nl, n: v}))
            nl[n] = float(best)
        if names:
            def obj(z):
                return self._sse(S, {**nl, **dict(zip(names, z))}) / len(S)
            bounds = [NL_BOUNDS[n] for n in names]
            z0 = [min(max(nl[n], lo), hi) for n, (lo, hi) in zip(names, bounds)]
            r = minimize(obj, z0, method="Powell", bounds=bounds, options={"xtol": 1e-4, "ftol": 1e-10})
            if r.fun * len(S) <= self._sse(S, nl):
                nl.update(dict(zip(names, map(float, r.x))))
        X, lin = _columns(S, self.effects, nl, self.freq_dependent)
        theta = _lstsq(X, S.y_m)
        res = S.y_m - X @ theta
        self.nl_ = nl
        self.coef_ = dict(zip(lin, map(float, theta)))
        self.rmse_train_ = float(np.sqrt(np.mean(res**2)))
        self.stderr_ = self._stderr(S, names, lin, theta, res)
        self.summary_ = self._summary()
        return self

    def _stderr(self, S, nl_names, lin, theta, res):
        dof = max(len(res) - len(theta) - len(nl_names), 1)
        sigma2 = float(res @ res) / dof

        def pred(full):
            nl = {**self.nl_, **dict(zip(nl_names, full[len(lin):]))}
            X, _ = _columns(S, self.effects, nl, self.freq_dependent)
            return X @ full[:len(lin)]
        full = np.concatenate([theta, [self.nl_[n] for n in nl_names]])
        J = np.empty((len(res), len(full)))
        X, _ = _columns(S, self.effects, self.nl_, self.freq_dependent)
        J[:, :len(lin)] = X
        for j in range(len(lin), len(full)):
            h = 1e-6 * max(abs(full[j]), 1e-2)
            up, dn = full.copy(), full.copy()
            up[j] += h
            dn[j] -= h
            J[:, j] = (pred(up) - pred(dn)) / (2 * h)
        cov = sigma2 * np.linalg.pinv(J.T @ J)
        se = np.sqrt(np.clip(np.diag(cov), 0, None))
        return dict(zip(list(lin) + [f"nl.{n}" for n in nl_names], map(float, se)))

    def _summary(self) -> dict:
        c = self.coef_
        out = {"tail_amplitude_m": float(np.hypot(c["wave.a_m"], c["wave.b_m"])),
               "tail_beat_ratio": self.nl_["ratio"], "envelope_exponent": self.nl_["p"],
               "wavelength_body_lengths": self.nl_["lam"], "phase_lag_rad": self.nl_["kappa"],
               "rigid_front_fraction": self.nl_["h"]}
        if "head_yaw.h1_m" in c:
            out["head_yaw_amplitude_at_tail_m"] = float(np.hypot(c["head_yaw.h1_m"], c["head_yaw.h2_m"]))
        if "second_harmonic.d1_m" in c:
            out["second_harmonic_amplitude_m"] = float(np.hypot(c["second_harmonic.d1_m"],
                                                                c["second_harmonic.d2_m"]))
        if "lateral_offset.c1_m" in c:
            out["lateral_offset_at_tail_m"] = (c["lateral_offset.c1_m"] + c["lateral_offset.c2_m"]
                                               + c["lateral_offset.c3_m"])
        return out

    def predict(self, S: BodySamples) -> np.ndarray:
        X, lin = _columns(S, self.effects, self.nl_, self.freq_dependent)
        return X @ np.array([self.coef_[n] for n in lin])

    def rmse(self, S: BodySamples) -> float:
        return float(np.sqrt(np.mean((S.y_m - self.predict(S)) ** 2)))

    def implausible(self, L_m: float) -> list[str]:
        """Reasons the fitted values are not physical (empty = plausible)."""
        s, out = self.summary_, []
        if not 0.0 < s["tail_amplitude_m"] < 0.5 * L_m:
            out.append(f"tail amplitude {s['tail_amplitude_m']:.3g} m outside (0, L/2)")
        for n in _nl_names(self.effects):
            lo, hi = NL_BOUNDS[n]
            v = self.nl_[n]
            if not lo + 1e-3 * (hi - lo) < v < hi - 1e-3 * (hi - lo):
                out.append(f"{n} = {v:.4g} at its search bound [{lo:.3g}, {hi:.3g}]")
        if s.get("second_harmonic_amplitude_m", 0.0) > s["tail_amplitude_m"]:
            out.append("second harmonic larger than the fundamental")
        if s.get("head_yaw_amplitude_at_tail_m", 0.0) > s["tail_amplitude_m"] + 1e-12:
            out.append("head-yaw lever swing larger than the wave itself")
        if abs(s.get("lateral_offset_at_tail_m", 0.0)) > 0.5 * L_m:
            out.append("lateral offset larger than half a body length")
        return out


# --------------------------------------------------------------------------------------- validation

def time_blocks(S: BodySamples, n_blocks: int = 5) -> np.ndarray:
    """Block index (0..n_blocks-1) of each sample: contiguous equal spans of time within each file."""
    out = np.zeros(len(S), dtype=int)
    for f in np.unique(S.file):
        m = S.file == f
        t0, t1 = S.t_s[m].min(), S.t_s[m].max()
        out[m] = np.minimum(((S.t_s[m] - t0) / (t1 - t0 + 1e-12) * n_blocks).astype(int), n_blocks - 1)
    return out


def blocked_cv_rmse(S: BodySamples, effects, n_blocks: int = 5, init: dict | None = None,
                    freq_dependent=()) -> float:
    """RMSE [m] over all held-out samples, each contiguous time block held out once."""
    blk = time_blocks(S, n_blocks)
    sse, n = 0.0, 0
    for b in range(n_blocks):
        tr, te = S.subset(blk != b), S.subset(blk == b)
        m = BodyWave(tuple(effects), tuple(freq_dependent), init).fit(tr)
        r = te.y_m - m.predict(te)
        sse += float(r @ r)
        n += len(r)
    return float(np.sqrt(sse / n))


@dataclass
class BodySelectionStep:
    name: str
    rmse_holdout_before_m: float
    rmse_holdout_after_m: float
    params: dict
    candidates: dict


@dataclass
class BodySelection:
    """Forward selection on one file with blocked cross-validation: add the candidate that lowers the
    held-out RMSE most, if by at least ``min_gain`` (relative) and its fit is plausible; stop otherwise."""
    candidates: tuple[str, ...] = tuple(n for n, e in EFFECTS.items() if not e.across_files_only)
    min_gain: float = 0.03
    n_blocks: int = 5
    steps_: list = field(default_factory=list)

    def fit(self, S: BodySamples) -> "BodySelection":
        L = float(np.median(S.L_m))
        chosen: list[str] = []
        base = BodyWave(()).fit(S)
        self.baseline_ = base
        self.baseline_rmse_ = (base.rmse_train_, blocked_cv_rmse(S, (), self.n_blocks))
        cur, cur_model = self.baseline_rmse_[1], base
        self.steps_ = []
        while True:
            tried, models = {}, {}
            for c in self.candidates:
                if c in chosen:
                    continue
                eff = tuple(chosen + [c])
                warm = {k: v for k, v in cur_model.nl_.items() if k in _nl_names(chosen)}
                m = BodyWave(eff, init=warm).fit(S)
                if m.implausible(L):
                    tried[c] = float("nan")
                    continue
                tried[c] = blocked_cv_rmse(S, eff, self.n_blocks, init=m.nl_)
                models[c] = m
            if not models:
                break
            best = min(models, key=lambda c: tried[c])
            if not tried[best] < (1.0 - self.min_gain) * cur:
                break
            m = models[best]
            self.steps_.append(BodySelectionStep(best, cur, tried[best], dict(m.summary_), tried))
            chosen.append(best)
            cur, cur_model = tried[best], m
        self.model_ = cur_model
        self.effects_ = tuple(chosen)
        self.final_rmse_ = (cur_model.rmse_train_, cur)
        return self


# ----------------------------------------------------------------------------------- across files

def align_to_tail(data: MarkerData, ratio: float | None = None) -> float:
    """Time shift [s] that puts the tail tip's fundamental at phase zero: the clock sync of a held-out video
    (its one free number; the video's start is arbitrary). The fundamental is taken at ratio * f_drive, or at
    the tail tip's spectral peak when ``ratio`` is None."""
    f = (dominant_frequency_hz(data.time_s, data.y_m[:, 8]) if ratio is None
         else ratio * data.drive_frequency_hz)
    w = 2.0 * np.pi * f
    ok = data.valid[:, 8]
    t, y = data.time_s[ok], data.y_m[ok, 8]
    X = np.column_stack([np.ones_like(t), np.sin(w * t), np.cos(w * t)])
    c, *_ = np.linalg.lstsq(X, y, rcond=None)
    # y ~ A sin(w t + psi); with t' = t + psi / w the fundamental becomes A sin(w t')
    psi = np.arctan2(c[2], c[1])
    return float(psi / w)


def cross_file_rmse(datas: list[MarkerData], effects, freq_dependent=(), ratio_for_alignment: float | None = None,
                    init: dict | None = None) -> dict:
    """Leave one file out: fit on the others (shared parameters, or linear in frequency for the effects in
    ``freq_dependent``), predict the held-out file after aligning every file's clock to its tail tip.
    Returns {file: rmse [m]} and the pooled RMSE under 'all'."""
    aligned = [samples_from_markers(d, i, align_to_tail(d, ratio_for_alignment)) for i, d in enumerate(datas)]
    out, sse, n = {}, 0.0, 0
    for i, d in enumerate(datas):
        tr = BodySamples.concat([a for j, a in enumerate(aligned) if j != i])
        m = BodyWave(tuple(effects), tuple(freq_dependent), init).fit(tr)
        r = aligned[i].y_m - m.predict(aligned[i])
        out[d.drive_frequency_hz] = float(np.sqrt(np.mean(r**2)))
        sse += float(r @ r)
        n += len(r)
    out["all"] = float(np.sqrt(sse / n))
    return out


# ------------------------------------------------------------------------------- the engine's family
#
# The engine (calibration.engine) fits  y = base_columns @ b0 + sum_e columns_e(ctx, nl_e) @ b_e, where an
# effect's nonlinear parameters shape only its own columns. The body's departures mostly change the *wave's*
# nonlinear parameters (its frequency, envelope exponent, wavelength), which the base columns cannot take
# from the effects. Within that API each effect below therefore adds its own wave term with its own copy of
# the beat-frequency ratio (searched on a grid centred on the tail tip's spectral peak): e.g.
# ``envelope_shape`` adds (s/L)^p (a sin + b cos)(k s - r w t), so the envelope becomes c2 u^2 + cp u^p.
# :class:`BodyWave` / :class:`BodySelection` above implement the shared-parameter model (one wave whose
# r, p, lambda, kappa, h the effects change), which is what the reported numbers use.



def body_context(datas: list[MarkerData], time_shifts_s=None) -> Context:
    """Engine context from one or more marker files (rows: valid body-marker samples; one series per marker
    and file). Signals: s_m, L_m, f_drive_hz, t_s (time, shifted per file by ``time_shifts_s``), position
    (= arc position s), velocity (lateral velocity by central differences), input (crank angle sin 2 pi f t)."""
    parts = []
    for i, d in enumerate(datas):
        shift = 0.0 if time_shifts_s is None else float(time_shifts_s[i])
        S = samples_from_markers(d, i, shift)
        parts.append(S)
    S = BodySamples.concat(parts)
    order = np.lexsort((S.t_s, S.marker, S.file))
    S = S.subset(order)
    series = (S.file * 10 + S.marker).astype(int)
    vel = np.zeros(len(S))
    for sid in np.unique(series):
        m = series == sid
        if m.sum() > 2:
            vel[m] = np.gradient(S.y_m[m], S.t_s[m])
    u = S.s_m / S.L_m
    k = 2.0 * np.pi / (1.25 * S.L_m)
    th = k * S.s_m - 2.0 * np.pi * S.f_drive_hz * S.t_s
    base_cols = np.column_stack([u**2 * np.sin(th), u**2 * np.cos(th)])
    ratios = []
    for d in datas:
        ratios.append(dominant_frequency_hz(d.time_s, d.y_m[:, 8]) / d.drive_frequency_hz)
    signals = {"s_m": S.s_m, "L_m": S.L_m, "f_drive_hz": S.f_drive_hz, "t_s": S.t_s, "position": S.s_m,
               "velocity": vel, "input": np.sin(2.0 * np.pi * S.f_drive_hz * S.t_s), "marker": S.marker.astype(float)}
    return Context(S.t_s, S.y_m, np.zeros(len(S)), base_cols, signals,
                   " + ".join(d.source for d in datas), series,
                   meta={"spectral_ratio": float(np.median(ratios)), "sources": [d.source for d in datas]})


def _wave(ctx: Context, nl: dict, p: float = 2.0, harmonic: int = 1) -> np.ndarray:
    g = ctx.signals
    u = g["s_m"] / g["L_m"]
    h = nl.get("h", 0.0)
    lam = nl.get("lam", 1.25)
    th = (2.0 * np.pi / (lam * g["L_m"]) * g["s_m"] + nl.get("kappa", 0.0) * u**2
          - 2.0 * np.pi * nl.get("ratio", 1.0) * g["f_drive_hz"] * g["t_s"])
    env = np.clip((u - h) / (1.0 - h), 0.0, None) ** nl.get("p", p)
    return np.column_stack([env * np.sin(harmonic * th), env * np.cos(harmonic * th)])


class _BodyEffect(Effect):
    def grid(self, param: Param, ctx: Context) -> np.ndarray:
        if param.name == "ratio":
            r0 = float(ctx.meta.get("spectral_ratio", 1.0))
            g = np.concatenate([r0 + np.linspace(-0.03, 0.03, 7), np.linspace(param.lo, param.hi, 12)])
            return np.unique(np.clip(g, param.lo + 1e-3, param.hi - 1e-3))
        return param.grid_values()


def _ratio() -> Param:
    return Param("ratio", "-", 0.3, 2.0, "tail-beat frequency / drive frequency")


def _amp(prefix: str, doc: str) -> tuple[Param, Param]:
    return (Param(f"{prefix}_sin_m", "m", -1.0, 1.0, doc + " (sine part)"),
            Param(f"{prefix}_cos_m", "m", -1.0, 1.0, doc + " (cosine part)"))


def _lever(ctx, nl):
    g = ctx.signals
    w = 2.0 * np.pi * nl["ratio"] * g["f_drive_hz"] * g["t_s"]
    u = g["s_m"] / g["L_m"]
    return np.column_stack([u * np.sin(w), u * np.cos(w)])


def _offset_plausible(v, ctx):
    """The three coefficients are nearly collinear over the tracked part of the body, so judge the offset
    itself: it must stay within half a body length where the markers are."""
    u = np.unique(ctx.signals["s_m"] / ctx.signals["L_m"])
    off = v["c1_m"] * u + v["c2_m"] * u**2 + v["c3_m"] * u**3
    L = float(np.median(ctx.signals["L_m"]))
    return [] if np.max(np.abs(off)) < 0.5 * L else [f"lateral offset {np.max(np.abs(off)):.3g} m > L/2"]


def _offset_cols(ctx, nl):
    u = ctx.signals["s_m"] / ctx.signals["L_m"]
    return np.column_stack([u, u**2, u**3])


ENGINE_EFFECTS: tuple[Effect, ...] = (
    _BodyEffect(name="tail_beat_frequency", meaning=EFFECTS["tail_beat_frequency"].meaning,
                fingerprint="the residual beats against the wave: a phase drift between model and tail over time",
                linear=_amp("wave_r", "wave at the fitted beat frequency"), nonlinear=(_ratio(),),
                fingerprint_axis="time", columns_fn=lambda ctx, nl: _wave(ctx, nl)),
    _BodyEffect(name="lateral_offset", meaning=EFFECTS["lateral_offset"].meaning,
                fingerprint="a residual mean that differs from zero and grows along the body",
                linear=(Param("c1_m", "m", -100.0, 100.0, "offset coefficient of s/L"),
                        Param("c2_m", "m", -100.0, 100.0, "offset coefficient of (s/L)^2"),
                        Param("c3_m", "m", -100.0, 100.0, "offset coefficient of (s/L)^3")),
                fingerprint_axis="position", columns_fn=_offset_cols, plausible_fn=_offset_plausible),
    _BodyEffect(name="envelope_shape", meaning=EFFECTS["envelope_shape"].meaning,
                fingerprint="residual amplitude that changes sign along the body against a u^2 envelope",
                linear=_amp("wave_p", "wave with envelope (s/L)^p"),
                nonlinear=(_ratio(), Param("p", "-", 0.5, 14.0, "envelope exponent", scale="log", grid=10)),
                fingerprint_axis="position", columns_fn=lambda ctx, nl: _wave(ctx, nl)),
    _BodyEffect(name="rigid_front", meaning=EFFECTS["rigid_front"].meaning,
                fingerprint="model motion where the body does not move (front markers), too little at the tail",
                linear=_amp("wave_h", "wave starting at s = h L"),
                nonlinear=(_ratio(), Param("h", "-", 0.0, 0.9, "rigid front fraction", grid=10),
                           Param("p", "-", 0.5, 14.0, "envelope exponent behind it", scale="log", grid=6)),
                fingerprint_axis="position", columns_fn=lambda ctx, nl: _wave(ctx, nl)),
    _BodyEffect(name="wavelength", meaning=EFFECTS["wavelength"].meaning,
                fingerprint="residual phase that grows linearly along the body",
                linear=_amp("wave_lam", "wave with fitted wavelength"),
                nonlinear=(_ratio(), Param("lam", "-", 0.3, 8.0, "wavelength / body length", scale="log", grid=12)),
                fingerprint_axis="position", columns_fn=lambda ctx, nl: _wave(ctx, nl)),
    _BodyEffect(name="phase_lag", meaning=EFFECTS["phase_lag"].meaning,
                fingerprint="residual phase that grows quadratically along the body",
                linear=_amp("wave_kappa", "wave with extra phase kappa (s/L)^2"),
                nonlinear=(_ratio(), Param("kappa", "rad", -6.28, 6.28, "extra phase at the tail", grid=12)),
                fingerprint_axis="position", columns_fn=lambda ctx, nl: _wave(ctx, nl)),
    _BodyEffect(name="head_yaw", meaning=EFFECTS["head_yaw"].meaning,
                fingerprint="residual at the beat frequency growing linearly along the body, one phase for all",
                linear=_amp("yaw", "lever swing at the tail"), nonlinear=(_ratio(),),
                fingerprint_axis="position", columns_fn=_lever),
    _BodyEffect(name="second_harmonic", meaning=EFFECTS["second_harmonic"].meaning,
                fingerprint="a residual peak at twice the beat frequency in the spectrum",
                linear=_amp("harm2", "second harmonic"), nonlinear=(_ratio(),),
                fingerprint_axis="time", columns_fn=lambda ctx, nl: _wave(ctx, nl, harmonic=2)),
)


def load(path, design=None, notes: list | None = None) -> Context:
    """Engine loader: one ``markers_fX_YY.csv`` file (see :mod:`calibration.fishsim`). ``design`` unused.
    The cleaning report goes to ``notes``."""
    d = load_markers(path)
    if notes is not None:
        c = d.cleaning
        notes.append(f"{path}: pixel scale {d.pixels_per_m:.1f} px/m; body axis turned "
                     f"{d.body_axis_rotation_deg:.2f} deg; invalid samples: merged {c['merged_samples_invalid']}, "
                     f"displaced {c['displaced_samples_invalid']}, jumps {c['jump_samples_invalid']}; "
                     f"interpolated {c['samples_interpolated']}; left out {c['samples_left_out']}; "
                     f"markers dropped {c['markers_dropped']}")
    return body_context([d])


FAMILY = Family(
    name="body",
    description="swimming body midline from video markers vs the paper's travelling wave (eq. 43-45)",
    columns=(),
    target="lateral_m",
    target_unit="m",
    base_terms=("travelling wave y = (s/L)^2 (a sin + b cos)(k s - w t), k = 2 pi / (1.25 L), w = 2 pi f_drive "
                "(paper eq. 43-45)",),
    effects=ENGINE_EFFECTS,
    load=load,
    base_coef_names=("wave_sin_m", "wave_cos_m"),
    units={"lateral": "m", "arc_position": "m", "time": "s", "frequency": "Hz"},
)
