"""The ``drive`` family: a one-degree-of-freedom drive identified by its inverse dynamics.

Data: CSV with header ``time_s,position_m,force_n`` (a linear drive) or ``time_s,position_rad,torque_nm``
(a rotary drive); extra columns are ignored. The measured force is what the actuator applies.

Base model: rigid inertia, ``force = M * acceleration``. Velocity and acceleration are not measured: they come
from the position by the IDIM-LS recipe of the EMPS benchmark (Janot, Gautier, Brunot 2019,
``Script_IDIM_LS.m``), which this module follows step by step so that its numbers can be checked against the
published ones:

1. zero-phase low-pass: 4th-order Butterworth run forward and backward (``scipy.signal.filtfilt``),
   cutoff ``cutoff_hz`` (default fs/10, i.e. 100 Hz at the EMPS 1 kHz rate, the reference value);
2. central differences twice (``numpy.gradient``) for velocity and acceleration;
3. the first ``border`` samples are dropped (the reference drops 49 for edge effects);
4. every column of the regressor and the force are decimated by ``decimation`` (default round(fs/cutoff),
   10 at EMPS: 0.8 * 500 Hz / 40 Hz), with the zero-phase order-8 Chebyshev-I anti-alias filter that MATLAB's
   ``decimate`` uses (``scipy.signal.decimate(..., ftype='iir', zero_phase=True)``).

The model is linear in its coefficients once the few nonlinear shape parameters (the Stribeck velocity) are
fixed, so every fit is an ordinary least-squares solve (with a 1-D search for the Stribeck velocity).

Error measure: the EMPS one, relative force error ``100 * ||F - F_hat||_2 / ||F||_2`` [%] on the decimated
samples (``rel_err_LS`` of ``Script_IDIM_LS.m``); RMSE [N] is reported beside it.

Candidate effects (each a named term with physical meaning, bounds, a plausibility rule and a fingerprint):
``viscous_friction``, ``coulomb_friction``, ``asymmetric_friction``, ``stribeck``, ``offset``,
``position_dependent``, ``cubic_stiffness``. See :data:`EFFECTS`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from swiftfin.calibration.drive_data import (  # noqa: F401  re-exported: the drive family's data
    LINEAR_COLUMNS, ROTARY_COLUMNS, DriveLog, InverseDynamicsData, decimate_columns, inverse_dynamics_data,
    read_drive_csv)
from swiftfin.calibration.emps import load_emps, load_emps_pair
from swiftfin.calibration.model import Context, Effect, Family, Param
from swiftfin.core.errors import UserError

# ------------------------------------------------------------------------------------------ effects

@dataclass(frozen=True)
class DriveEffect:
    """A named term of the inverse-dynamics model.

    ``columns(d, nl)`` gives the regressor columns (undecimated) for data ``d`` and nonlinear parameters
    ``nl``; the effect's linear coefficients multiply them. ``nonlinear`` maps a nonlinear parameter name to
    the grid it is searched over (or a callable of the data returning that grid).
    ``plausible(params)`` returns a list of reasons why the fitted values are not physical (empty = fine).
    ``fingerprint(residual, d)`` returns a number that is large when the residual has this effect's shape.
    """
    name: str
    meaning: str
    params: tuple[str, ...]
    units: tuple[str, ...]
    columns: Callable
    bounds: tuple[tuple[float, float], ...]
    plausible: Callable
    fingerprint: Callable
    nonlinear: dict = field(default_factory=dict)
    replaces: tuple[str, ...] = ()


def _v_scale(d) -> float:
    return float(np.percentile(np.abs(d.velocity), 95)) or 1.0


def _fp_linear_in(x_fn):
    """Fingerprint: |correlation| of the residual with a signal."""
    def fp(res, d):
        x = x_fn(d)
        x = x - x.mean()
        r = res - res.mean()
        den = np.linalg.norm(x) * np.linalg.norm(r)
        return float(abs(x @ r) / den) if den > 0 else 0.0
    return fp


def _fp_step_at_zero(res, d):
    """Coulomb fingerprint: jump of the residual across v = 0 (means in small bands either side) over its std."""
    v, s = d.velocity, _v_scale(d)
    lo = res[(v < 0) & (v > -0.1 * s)]
    hi = res[(v > 0) & (v < 0.1 * s)]
    if len(lo) < 5 or len(hi) < 5:
        return 0.0
    return float(abs(hi.mean() - lo.mean()) / (res.std() + 1e-300))


def _fp_slope_change(res, d):
    """Asymmetric friction fingerprint: residual slope vs velocity differs for v>0 and v<0."""
    v = d.velocity
    out = []
    for m in (v > 0, v < 0):
        if m.sum() < 10:
            return 0.0
        out.append(np.polyfit(v[m], res[m], 1)[0])
    return float(abs(out[0] - out[1]) * _v_scale(d) / (res.std() + 1e-300))


def _fp_stribeck(res, d):
    """Stribeck fingerprint: residual*sign(v) larger at low speed than at high speed."""
    v, s = d.velocity, _v_scale(d)
    a = np.abs(v)
    sr = res * np.sign(v)
    lo, hi = sr[(a > 0) & (a < 0.1 * s)], sr[a > 0.3 * s]
    if len(lo) < 5 or len(hi) < 5:
        return 0.0
    return float(abs(lo.mean() - hi.mean()) / (res.std() + 1e-300))


def _centred(d):
    q = d.position
    mid = 0.5 * (q.max() + q.min())
    half = 0.5 * (q.max() - q.min()) or 1.0
    return (q - mid) / half, mid, half


def _cols_position(d, nl):
    z, mid, half = _centred(d)
    return np.column_stack([z, z**2 - 1.0 / 3.0])


def _cols_cubic(d, nl):
    z, mid, half = _centred(d)
    return (z**3)[:, None]


def _stribeck_grid(d):
    s = _v_scale(d)
    return np.geomspace(0.005 * s, 0.5 * s, 25)


def _positive(*names):
    def check(p):
        return [f"{n} = {p[n]:.4g} should be > 0" for n in names if not p[n] > 0]
    return check


def _nothing(p):
    return []


def _asym_check(p):
    # direction-dependent viscous friction: both directions must stay dissipative
    out = []
    if "viscous_friction.Fv" in p and not p["viscous_friction.Fv"] + min(p["asymmetric_friction.dFv_neg"], 0) > 0:
        out.append("viscous coefficient for v<0 would be <= 0")
    return out


EFFECTS: dict[str, DriveEffect] = {e.name: e for e in [
    DriveEffect(
        "viscous_friction", "force proportional to velocity (lubricated contact, motor back-EMF damping)",
        ("Fv",), ("N s/m",), lambda d, nl: d.velocity[:, None], ((0.0, np.inf),), _positive("Fv"),
        _fp_linear_in(lambda d: d.velocity)),
    DriveEffect(
        "coulomb_friction", "constant force opposing motion, Fc*sign(v) (dry friction in screw and guides)",
        ("Fc",), ("N",), lambda d, nl: np.sign(d.velocity)[:, None], ((0.0, np.inf),), _positive("Fc"),
        _fp_step_at_zero),
    DriveEffect(
        "asymmetric_friction", "viscous friction that differs with the direction of motion: coefficient "
        "Fv for v>0 and Fv + dFv_neg for v<0 (a direction-dependent preload or seal). A direction-dependent "
        "*Coulomb* level alone is the same regressor as coulomb_friction + offset, so it is not a separate term",
        ("dFv_neg",), ("N s/m",), lambda d, nl: (d.velocity * (d.velocity < 0))[:, None],
        ((-np.inf, np.inf),), _nothing, _fp_slope_change),
    DriveEffect(
        "stribeck", "extra friction at low speed decaying with speed: Fs*sign(v)*exp(-(|v|/vs)^2)",
        ("Fs", "vs"), ("N", "m/s"),
        lambda d, nl: (np.sign(d.velocity) * np.exp(-(np.abs(d.velocity) / nl["vs"]) ** 2))[:, None],
        ((0.0, np.inf), (0.0, np.inf)), _positive("Fs"), _fp_stribeck, nonlinear={"vs": _stribeck_grid}),
    DriveEffect(
        "offset", "constant force independent of motion (gravity on a tilted axis, amplifier or sensor offset)",
        ("F0",), ("N",), lambda d, nl: np.ones((len(d.velocity), 1)), ((-np.inf, np.inf),), _nothing,
        lambda res, d: float(abs(res.mean()) / (res.std() + 1e-300))),
    DriveEffect(
        "position_dependent", "force varying smoothly with position (cable drag, spring, uneven guide): "
        "K1*z + K2*(z^2 - 1/3), z = position scaled to [-1, 1] over the travel",
        ("K1", "K2"), ("N", "N"), _cols_position, ((-np.inf, np.inf), (-np.inf, np.inf)), _nothing,
        _fp_linear_in(lambda d: _centred(d)[0])),
    DriveEffect(
        "cubic_stiffness", "hardening/softening restoring force K3*z^3 (z = position scaled to [-1, 1])",
        ("K3",), ("N",), _cols_cubic, ((-np.inf, np.inf),), _nothing,
        _fp_linear_in(lambda d: _centred(d)[0] ** 3)),
]}


# -------------------------------------------------------------------------------------------- model

@dataclass
class DriveModel:
    """Rigid inertia plus the named ``effects``: an estimator (``fit(data) -> self``).

    Learned: ``coef_`` (name -> value), ``stderr_`` (name -> standard deviation, the IDIM-LS formula
    sigma * sqrt(diag((X'X)^-1)) on decimated samples; residuals are coloured, so these are lower bounds),
    ``nonlinear_`` (e.g. Stribeck velocity), ``rel_error_train_`` [%], ``rmse_train_``.
    """
    effects: tuple[str, ...] = ()

    def _design(self, d: InverseDynamicsData, nl: dict):
        cols, names = [d.acceleration[:, None]], ["inertia.M"]
        for e in self.effects:
            eff = EFFECTS[e]
            cols.append(eff.columns(d, nl))
            lin = [p for p in eff.params if p not in eff.nonlinear]
            names += [f"{e}.{p}" for p in lin]
        return np.column_stack(cols), names

    def _solve(self, d, nl):
        X, names = self._design(d, nl)
        Xd = decimate_columns(X, d.decimation)
        yd = decimate_columns(d.force, d.decimation)
        theta, *_ = np.linalg.lstsq(Xd, yd, rcond=None)
        res = yd - Xd @ theta
        return theta, names, Xd, yd, res

    def fit(self, d: InverseDynamicsData) -> "DriveModel":
        grids = {}
        for e in self.effects:
            for p, g in EFFECTS[e].nonlinear.items():
                grids[p] = g(d) if callable(g) else np.asarray(g)
        best = None
        # the nonlinear parameters are few and 1-D each: a grid search with the linear ones solved inside,
        # then a golden-section refinement in log space around the best grid point
        nl_names = list(grids)
        if nl_names:
            from itertools import product
            for combo in product(*[grids[n] for n in nl_names]):
                nl = dict(zip(nl_names, combo))
                sol = self._solve(d, nl)
                sse = float(sol[4] @ sol[4])
                if best is None or sse < best[0]:
                    best = (sse, nl, sol)
            if len(nl_names) == 1:
                n = nl_names[0]
                g = grids[n]
                i = int(np.argmin(np.abs(g - best[1][n])))
                lo, hi = np.log(g[max(i - 1, 0)]), np.log(g[min(i + 1, len(g) - 1)])
                from scipy.optimize import minimize_scalar
                r = minimize_scalar(lambda u: float(np.sum(self._solve(d, {n: np.exp(u)})[4] ** 2)),
                                    bounds=(lo, hi), method="bounded", options={"xatol": 1e-3})
                if r.fun < best[0]:
                    nl = {n: float(np.exp(r.x))}
                    best = (float(r.fun), nl, self._solve(d, nl))
        else:
            best = (None, {}, self._solve(d, {}))
        _, nl, (theta, names, Xd, yd, res) = best
        self.nonlinear_ = dict(nl)
        self.names_ = names
        self.coef_ = dict(zip(names, map(float, theta)))
        dof = max(len(yd) - len(theta), 1)
        sigma = float(np.sqrt(res @ res / dof))
        cov = sigma**2 * np.linalg.pinv(Xd.T @ Xd)
        self.stderr_ = dict(zip(names, map(float, np.sqrt(np.diag(cov)))))
        self.rmse_train_ = float(np.sqrt(np.mean(res**2)))
        self.rel_error_train_ = relative_error_pct(yd, yd - res)
        return self

    def params(self) -> dict:
        """Coefficients keyed ``effect.param`` plus the nonlinear ones, for plausibility checks."""
        out = dict(self.coef_)
        for e in self.effects:
            for p in EFFECTS[e].nonlinear:
                out[f"{e}.{p}"] = self.nonlinear_[p]
        return out

    def predict_decimated(self, d: InverseDynamicsData) -> tuple[np.ndarray, np.ndarray]:
        """(measured force, model force) on the decimated samples of ``d``."""
        X, _ = self._design(d, self.nonlinear_)
        Xd = decimate_columns(X, d.decimation)
        yd = decimate_columns(d.force, d.decimation)
        return yd, Xd @ np.array([self.coef_[n] for n in self.names_])

    def relative_error_pct(self, d: InverseDynamicsData) -> float:
        y, yhat = self.predict_decimated(d)
        return relative_error_pct(y, yhat)

    def rmse(self, d: InverseDynamicsData) -> float:
        y, yhat = self.predict_decimated(d)
        return float(np.sqrt(np.mean((y - yhat) ** 2)))

    def implausible(self) -> list[str]:
        p = self.params()
        out = [] if p["inertia.M"] > 0 else [f"inertia M = {p['inertia.M']:.4g} should be > 0"]
        for e in self.effects:
            eff = EFFECTS[e]
            local = {q: p[f"{e}.{q}"] for q in eff.params}
            out += [f"{e}: {r}" for r in eff.plausible(local)]
            for q, (lo, hi) in zip(eff.params, eff.bounds):
                if not lo <= local[q] <= hi:
                    out.append(f"{e}.{q} = {local[q]:.4g} outside [{lo}, {hi}]")
        if "asymmetric_friction" in self.effects:
            out += _asym_check(p)
        return out


def relative_error_pct(force, force_hat) -> float:
    """EMPS relative force error: 100 * ||F - F_hat|| / ||F|| [%] (``rel_err_LS`` in Script_IDIM_LS.m)."""
    force = np.asarray(force, dtype=float)
    return float(100.0 * np.linalg.norm(force - np.asarray(force_hat)) / np.linalg.norm(force))


# ----------------------------------------------------------------------------- forward selection

@dataclass
class SelectionStep:
    name: str
    params: dict
    stderr: dict
    rel_error_holdout_before: float
    rel_error_holdout_after: float
    rmse_holdout_before: float
    rmse_holdout_after: float
    rel_error_train_after: float
    fingerprint: float
    candidates: dict  # name -> holdout relative error when tried at this step (nan if implausible)


@dataclass
class DriveSelection:
    """Forward selection: from rigid inertia alone, add the candidate that lowers the held-out relative
    force error most, provided it lowers it by at least ``min_gain`` (relative, default 3 %) and its fitted
    values are plausible; stop when none does."""
    candidates: tuple[str, ...] = tuple(EFFECTS)
    min_gain: float = 0.03
    max_effects: int = 6

    def fit(self, train: InverseDynamicsData, holdout: InverseDynamicsData) -> "DriveSelection":
        chosen: list[str] = []
        base = DriveModel(()).fit(train)
        self.baseline_ = base
        self.baseline_rel_error_ = (base.rel_error_train_, base.relative_error_pct(holdout))
        self.baseline_rmse_ = (base.rmse_train_, base.rmse(holdout))
        current, cur_err = base, self.baseline_rel_error_[1]
        self.steps_: list[SelectionStep] = []
        while len(chosen) < self.max_effects:
            tried, models = {}, {}
            for c in self.candidates:
                if c in chosen:
                    continue
                m = DriveModel(tuple(chosen + [c])).fit(train)
                if m.implausible():
                    tried[c] = float("nan")
                    continue
                tried[c] = m.relative_error_pct(holdout)
                models[c] = m
            if not models:
                break
            best = min(models, key=lambda c: tried[c])
            if not tried[best] < (1.0 - self.min_gain) * cur_err:
                break
            m = models[best]
            X, _ = current._design(train, current.nonlinear_)
            # fingerprint on the undecimated residual of the current model
            full_res = train.force - X @ np.array([current.coef_[n] for n in current.names_])
            p = {k: v for k, v in m.params().items() if k.startswith(best + ".")}
            se = {k: v for k, v in m.stderr_.items() if k.startswith(best + ".")}
            self.steps_.append(SelectionStep(
                best, p, se, cur_err, tried[best], current.rmse(holdout), m.rmse(holdout), m.rel_error_train_,
                EFFECTS[best].fingerprint(full_res, train), tried))
            chosen.append(best)
            current, cur_err = m, tried[best]
        self.model_ = current
        self.effects_ = tuple(chosen)
        self.final_rel_error_ = (current.rel_error_train_, cur_err)
        return self


# ------------------------------------------------------------------------------- the engine's family
#
# The engine (calibration.engine) fits  y = base_columns @ b0 + sum_e columns_e @ b_e  on the rows of a
# Context. For the drive the rows are the *decimated* samples of the IDIM-LS recipe; each effect's regressor
# is formed at the full rate and then decimated (as Script_IDIM_LS.m does with sign(dq)), from the
# full-rate signals kept in ``ctx.meta['full']``. On windows of a very long log (``Context.select``), whose rows
# no longer match the decimated record, the columns fall back to the decimated signals themselves.



def drive_context(d: InverseDynamicsData) -> Context:
    """Engine context from pre-processed drive signals: target = decimated force, base column = decimated
    acceleration (the rigid inertia M is the base model's one coefficient)."""
    q = d.decimation
    dec = decimate_columns(np.column_stack([d.time_s, d.position, d.velocity, d.acceleration, d.force]), q)
    t = d.time_s[::q][: dec.shape[0]] if q > 1 else d.time_s
    t = t[: dec.shape[0]]
    signals = {"input": dec[:, 1], "position": dec[:, 1], "velocity": dec[:, 2], "acceleration": dec[:, 3]}
    meta = {"full": d, "decimation": q, "rotary": d.rotary}
    if d.rotary:
        meta.update(ROTARY_REPORT)
    return Context(t, dec[:, 4], np.zeros(len(t)), dec[:, 3:4], signals, d.source, meta=meta)


#: a rotary log (position_rad, torque_nm): the report's units and unit-carrying names follow its columns
#: (the engine reads these from ``Context.meta``): m -> rad, N -> N m, N s/m -> N m s/rad, kg -> kg m^2.
ROTARY_REPORT = {
    "target_unit": "N m",
    "units": {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s^2", "force": "N m",
              "inertia": "kg m^2"},
    "unit_map": {"N": "N m", "N s/m": "N m s/rad", "m/s": "rad/s", "m": "rad", "kg": "kg m^2", "m/s^2": "rad/s^2"},
    "param_names": {"mass_kg": "inertia_kg_m2", "Fv_n_s_m": "Fv_nm_s_rad", "dFv_neg_n_s_m": "dFv_neg_nm_s_rad", "Fc_n": "Fc_nm", "Fs_n": "Fs_nm",
                    "vs_m_s": "vs_rad_s", "F0_n": "F0_nm", "K1_n": "K1_nm", "K2_n": "K2_nm", "K3_n": "K3_nm"},
}


def _engine_columns(name: str, nl_map: Callable = lambda nl: {}):
    eff = EFFECTS[name]

    def cols(ctx: Context, nl: dict) -> np.ndarray:
        full = ctx.meta.get("full")
        q = ctx.meta.get("decimation", 1)
        mine = nl_map(nl)
        if full is not None and len(decimate_columns(np.zeros(len(full)), q)) == ctx.n:
            return decimate_columns(eff.columns(full, mine), q).reshape(ctx.n, -1)
        d = InverseDynamicsData(ctx.t, ctx.signals["position"], ctx.signals["velocity"],
                                ctx.signals["acceleration"], ctx.y, 0.0, 1)
        return eff.columns(d, mine).reshape(ctx.n, -1)
    return cols


def _pos(name):
    return lambda v, ctx: [] if v[name] > 0 else [f"{name} = {v[name]:.4g} must be > 0 (friction dissipates)"]


_BIG = 1e7
ENGINE_EFFECTS: tuple[Effect, ...] = (
    Effect(name="viscous_friction", meaning=EFFECTS["viscous_friction"].meaning,
           fingerprint="residual proportional to velocity: a straight line through zero in residual vs velocity",
           linear=(Param("Fv_n_s_m", "N s/m", 0.0, _BIG, "viscous coefficient"),),
           fingerprint_axis="velocity", columns_fn=_engine_columns("viscous_friction"),
           plausible_fn=_pos("Fv_n_s_m")),
    Effect(name="coulomb_friction", meaning=EFFECTS["coulomb_friction"].meaning,
           fingerprint="a step of the residual at zero velocity, flat on either side",
           linear=(Param("Fc_n", "N", 0.0, _BIG, "Coulomb friction level"),),
           fingerprint_axis="velocity", columns_fn=_engine_columns("coulomb_friction"),
           plausible_fn=_pos("Fc_n")),
    Effect(name="asymmetric_friction", meaning=EFFECTS["asymmetric_friction"].meaning,
           fingerprint="residual vs velocity with different slopes for v > 0 and v < 0",
           linear=(Param("dFv_neg_n_s_m", "N s/m", -_BIG, _BIG,
                         "viscous coefficient for v < 0 minus that for v > 0"),),
           fingerprint_axis="velocity", columns_fn=_engine_columns("asymmetric_friction"),
           refines=("viscous_friction",)),
    Effect(name="stribeck", meaning=EFFECTS["stribeck"].meaning,
           fingerprint="residual * sign(v) larger at low speed, decaying over a characteristic velocity",
           linear=(Param("Fs_n", "N", 0.0, _BIG, "extra static friction at rest"),),
           nonlinear=(Param("vs_m_s", "m/s", 1e-4, 1.0, "Stribeck velocity", scale="log", grid=25),),
           fingerprint_axis="velocity", columns_fn=_engine_columns("stribeck", lambda nl: {"vs": nl["vs_m_s"]}),
           plausible_fn=_pos("Fs_n"), refines=("coulomb_friction",)),
    Effect(name="offset", meaning=EFFECTS["offset"].meaning,
           fingerprint="a nonzero mean of the residual, independent of velocity and position",
           linear=(Param("F0_n", "N", -_BIG, _BIG, "constant force"),),
           fingerprint_axis="time", columns_fn=_engine_columns("offset")),
    Effect(name="position_dependent", meaning=EFFECTS["position_dependent"].meaning,
           fingerprint="residual varying smoothly with position (slope and curvature over the travel)",
           linear=(Param("K1_n", "N", -_BIG, _BIG, "linear term over the half travel"),
                   Param("K2_n", "N", -_BIG, _BIG, "quadratic term over the half travel")),
           fingerprint_axis="position", columns_fn=_engine_columns("position_dependent")),
    Effect(name="cubic_stiffness", meaning=EFFECTS["cubic_stiffness"].meaning,
           fingerprint="residual odd and cubic in position, largest at the ends of the travel",
           linear=(Param("K3_n", "N", -_BIG, _BIG, "cubic term at the end of the travel"),),
           fingerprint_axis="position", columns_fn=_engine_columns("cubic_stiffness")),
)


def load(path, design=None, notes: list | None = None, cutoff_hz: float | None = None,
         decimation: int | None = None) -> Context:
    """Engine loader: a ``drive`` CSV, or an EMPS ``.mat`` file (``DATA_EMPS.mat``, ``DATA_EMPS_PULSES.mat``).
    ``design`` is not used (a drive log carries everything)."""
    path = Path(path)
    mat = path.suffix.lower() == ".mat"
    if mat:
        log = load_emps(path).log
    else:
        log = read_drive_csv(path, notes)
    tname, pname = ("t", "qm") if mat else ("time_s", "position_rad" if log.rotary else "position_m")
    check_sample_interval(log, path, tname)
    d = inverse_dynamics_data(log, cutoff_hz, decimation)
    v = d.velocity
    if np.ptp(log.position) <= 0 or np.sum(np.diff(np.sign(v[np.abs(v) > 0.05 * np.abs(v).max()])) != 0) < 2:
        raise UserError(f"{path}: column '{pname}' barely moves or "
                        "never reverses: friction and inertia cannot be identified (need motion both ways)")
    check_position_units(log, d, path, pname)
    return drive_context(d)


#: Slowest sample rate a drive log for inverse dynamics can have: one sample per 50 ms (20 Hz). IDIM-LS
#: differentiates the position twice after a low-pass at fs/10; EMPS logs at 1 kHz (dt 1 ms). A time column
#: in milliseconds makes dt 1000 x too large (EMPS: 1 "s").
DRIVE_MAX_SAMPLE_INTERVAL_S = 0.05
#: Linear drives: largest plausible travel [m] and speed [m/s]. Ball-screw axes travel up to a few metres and
#: move at 0.1-2 m/s (EMPS: 0.25 m, 0.13 m/s); the fastest linear-motor stages reach ~10 m/s. A position column in
#: millimetres makes both 1000 x too large (EMPS: 246 "m", 128 "m/s"), so the mass comes out 1000 x too small.
LINEAR_MAX_TRAVEL_M = 50.0
LINEAR_MAX_SPEED_M_S = 20.0
#: Rotary drives: largest plausible speed [rad/s] (~95,000 rpm, beyond almost any motor); degrees read as radians
#: multiply it by 57.3. Travel is not bounded (a rotary axis may turn many times).
ROTARY_MAX_SPEED_RAD_S = 1.0e4


def check_sample_interval(log: DriveLog, path, tname: str) -> None:
    """Refuse a drive log sampled more slowly than :data:`DRIVE_MAX_SAMPLE_INTERVAL_S` (time in ms?)."""
    dt = float(np.median(np.diff(log.time_s)))
    if dt > DRIVE_MAX_SAMPLE_INTERVAL_S:
        raise UserError(f"{path}: column '{tname}': sample interval {dt:.4g} s ({1 / dt:.3g} Hz), expected at most "
                        f"{DRIVE_MAX_SAMPLE_INTERVAL_S:g} s (inverse dynamics needs >= {1 / DRIVE_MAX_SAMPLE_INTERVAL_S:g} "
                        f"Hz; EMPS logs at 1 kHz); likely cause: time in milliseconds (then it is {dt / 1000:.4g} s) "
                        f"- convert to seconds")


def check_position_units(log: DriveLog, d: InverseDynamicsData, path, pname: str) -> None:
    """Refuse a position column whose travel or speed is implausible in its unit (millimetres in a metre column,
    degrees in a radian column): see :data:`LINEAR_MAX_TRAVEL_M`, :data:`ROTARY_MAX_SPEED_RAD_S`."""
    travel = float(np.ptp(log.position))
    speed = float(np.percentile(np.abs(d.velocity), 99.5))
    if log.rotary:
        if speed > ROTARY_MAX_SPEED_RAD_S:
            raise UserError(f"{path}: column '{pname}': speed {speed:.4g} rad/s, expected below "
                            f"{ROTARY_MAX_SPEED_RAD_S:g} rad/s for a rotary drive; likely cause: the angle is in "
                            f"degrees (then {speed * np.pi / 180:.4g} rad/s) - convert to radians")
        return
    if travel > LINEAR_MAX_TRAVEL_M or speed > LINEAR_MAX_SPEED_M_S:
        raise UserError(f"{path}: column '{pname}': travel {travel:.4g} m and speed {speed:.4g} m/s, expected at "
                        f"most {LINEAR_MAX_TRAVEL_M:g} m and {LINEAR_MAX_SPEED_M_S:g} m/s for a linear drive (EMPS: "
                        f"0.25 m, 0.13 m/s); likely cause: the position is in millimetres (then {travel / 1000:.4g} m, "
                        f"{speed / 1000:.4g} m/s; fitted in mm the mass would come out 1000 x too small) - "
                        f"convert to metres")


FAMILY = Family(
    name="drive",
    description="one-degree-of-freedom drive: measured position -> actuator force (inverse dynamics, IDIM-LS "
                "pre-processing: Butterworth filtfilt at fs/10, central differences, decimation by fs/cutoff)",
    columns=LINEAR_COLUMNS,
    target="force_n",
    target_unit="N",
    base_terms=("rigid inertia: force = M * acceleration",),
    effects=ENGINE_EFFECTS,
    load=load,
    base_coef_names=("mass_kg",),
    equivalent_effects=(),
    units={"position": "m", "velocity": "m/s", "acceleration": "m/s^2", "force": "N",
           "note": "a rotary log (position_rad, torque_nm) is reported in its own units (ROTARY_REPORT): N -> N m, "
                   "m -> rad, "
                   "kg -> kg m^2"},
)


# ------------------------------------------------------------------------------- the published recipe
def idim_ls(project_root=None, asymmetric: bool = False) -> dict:
    """The reference IDIM-LS: M*qdd + Fv*qd + Fc*sign(qd) + offset, fit on the estimation run, evaluated on
    both runs. ``asymmetric`` adds the direction-dependent viscous term (Fv for v>0, Fv+dFv_neg for v<0),
    which is the asymmetric model that reproduces the published 3.1 % / 5.4 %.
    Returns fitted values, standard deviations and relative errors [%]."""
    est, val = load_emps_pair(project_root)
    de, dv = inverse_dynamics_data(est.log), inverse_dynamics_data(val.log)
    effects = ("viscous_friction", "coulomb_friction", "offset")
    if asymmetric:
        effects = effects + ("asymmetric_friction",)
    m = DriveModel(effects).fit(de)
    c, s = m.coef_, m.stderr_
    out = {"M": c["inertia.M"], "Fv": c["viscous_friction.Fv"], "Fc": c["coulomb_friction.Fc"],
           "offset": c["offset.F0"],
           "stderr": {"M": s["inertia.M"], "Fv": s["viscous_friction.Fv"], "Fc": s["coulomb_friction.Fc"],
                      "offset": s["offset.F0"]},
           "rel_error_estimation_pct": m.rel_error_train_, "rel_error_validation_pct": m.relative_error_pct(dv),
           "cutoff_hz": de.cutoff_hz, "decimation": de.decimation, "model": m}
    if asymmetric:
        out["Fv_neg"] = c["viscous_friction.Fv"] + c["asymmetric_friction.dFv_neg"]
    return out
