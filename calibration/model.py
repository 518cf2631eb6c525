"""The calibration data model: what a family declares and what a fit returns, with no fitting in it.

:class:`Param` (one parameter, its unit and bounds), :class:`Context` (one record ready for fitting),
:class:`Effect` (a candidate physical mechanism and its regressors), :class:`Family` (data format, base model and
effect library), :class:`FittedEffect` (an effect as fitted) and :func:`concat_contexts`. The overview is in
:mod:`calibration.engine`; what the estimator does with these (the selection criterion) in
:mod:`calibration.selection`.

How to add a family
-------------------
1. Create ``calibration/<name>.py``. Declare the CSV columns it needs with :class:`calibration.io.Column`
   (name, unit, kind) and read files with :func:`calibration.io.read_log`, which checks names, units,
   time stamps and NaN gaps and raises :class:`swiftfin.core.errors.UserError` naming file, column and row.
2. Write a loader ``load(path, design, notes=None) -> Context`` (``notes``: a list the loader appends warnings
   to, e.g. :attr:`calibration.io.LogData.notes`; the CLI prints them): the measured ``target``
   (``Context.y``), the fixed part of
   the base prediction (``Context.base``, e.g. the rigid capstan angle; zeros if none), the base model's
   fitted regressors (``Context.base_columns``, e.g. acceleration for a rigid inertia; shape (n, 0) if none)
   and named signals the effects and diagnostics use. ``signals`` must hold ``"input"`` (what drives the
   system), ``"velocity"`` and ``"position"`` (the axes the residual is plotted and binned against); add any
   family-specific signal (smoothed derivatives, cumulative travel ...) there, computed once.
   Refuse data that cannot support a fit (too short, not excited) with a UserError.
3. Write each candidate as an :class:`Effect`: ``columns(ctx, nl)`` returns the regressors whose linear
   coefficients the engine solves by least squares for given nonlinear parameters ``nl`` (a dict; the engine
   searches them on a grid inside their bounds and refines them); ``plausible`` says what fitted values are
   physically impossible; ``physical`` converts fitted values to the quantities a user recognises.
   :mod:`calibration.effects` has the shared operators (play, fractional delay, filters, derivatives).
   The short way is keyword construction with plain functions::

       Effect(name="viscous_friction", meaning="...", fingerprint="...",
              linear=(Param("damping_n_s_m", "N s/m", 0.0, 1e4),),
              columns_fn=lambda ctx, nl: ctx.signals["velocity"])

   (``plausible_fn(values, ctx) -> list[str]`` and ``physical_fn(values, stds, ctx) -> dict`` likewise);
   subclass and override :meth:`Effect.grid` for a data-dependent grid (thresholds).
4. Build a :class:`Family` and add its module to :data:`swiftfin.calibration.FAMILY_MODULES` (the module must define ``FAMILY``).
   ``swiftfin fit <name> DATA`` then works, with the report, the plots and the JSON.
5. Test it like ``tests/test_calib_joint.py``: data made by each effect's own model plus white noise must give
   back the truth within 3 sigma; a physical simulation with each effect alone must name it first.

Model structure (what the engine assumes)
-----------------------------------------
    y_hat = base + base_columns(nl_shared) @ b0 + sum_e columns_e(ctx, nl_e + nl_shared) @ b_e

linear in every ``b`` for fixed ``nl``. ``nl_shared`` are the family's shared nonlinear parameters
(:attr:`Family.shared_params`) of the active effects: an effect may change the base model's shape (the body's
tail-beat frequency, envelope exponent, wavelength) through :attr:`Family.base_columns_fn`, and several effects
may hold one such parameter; a family without them has ``base_columns = ctx.base_columns`` and each effect's
columns depend on its own ``nl_e`` only. An effect may have no linear coefficient at all (it only reshapes). Columns are computed on a whole record (a run), so effects with state
(backlash, creep, delays, filters) see the full history; the train / holdout split selects rows afterwards.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

# ------------------------------------------------------------------------------------------- data structures


@dataclass(frozen=True)
class Param:
    """One parameter of an effect.

    name : str      identifier, carries its unit (``delay_s``, ``width_rad``); shown in the report.
    unit : str      unit string for the report (``"s"``, ``"rad"``, ``"-"``).
    lo, hi : float  bounds. For a nonlinear parameter the search never leaves them, and an optimum pinned at a
                    bound (within 1 % of the span) is flagged as not plausible. For a linear coefficient they
                    are the plausibility range (least squares is unconstrained; out of range = implausible).
    doc : str       physical meaning, one line.
    scale : str     ``"lin"`` or ``"log"``: how the search grid spaces the values (log needs lo > 0).
    grid : int      number of grid points of the profile search (nonlinear parameters only).
    refine : bool   refine the best grid point by a bounded 1-D/Powell search (False for parameters the model
                    depends on in steps, e.g. a threshold: the grid is then the set of distinct values,
                    see :meth:`Effect.grid`).
    """

    name: str
    unit: str
    lo: float
    hi: float
    doc: str = ""
    scale: str = "lin"
    grid: int = 16
    refine: bool = True

    def grid_values(self) -> np.ndarray:
        if self.scale == "log":
            return np.geomspace(self.lo, self.hi, self.grid)
        return np.linspace(self.lo, self.hi, self.grid)


@dataclass
class Context:
    """One record (a run) of one family, ready for fitting. Built by the family's loader.

    t : (n,) time [s], increasing within a series.
    y : (n,) measured target in the family's target unit.
    base : (n,) fixed part of the base prediction (no fitted coefficient), e.g. the rigid capstan angle.
    base_columns : (n, k0) regressors of the base model's fitted terms (k0 may be 0).
    signals : named (n,) arrays: at least ``input``, ``velocity``, ``position``; family-specific extras.
    source : str, the file (for messages and the report).
    series : optional (n,) int array; rows of one series are one contiguous time series (e.g. one marker).
             None means the whole record is one series.
    meta : dict of family data the effects need (design constants, sample period ...).
    """

    t: np.ndarray
    y: np.ndarray
    base: np.ndarray
    base_columns: np.ndarray
    signals: dict[str, np.ndarray]
    source: str = "<memory>"
    series: np.ndarray | None = None
    meta: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return int(self.y.shape[0])

    def select(self, rows: np.ndarray, series: np.ndarray | None = None) -> "Context":
        """The given rows (sorted indices) as a new context, e.g. a few contiguous windows of a long log for the
        fast selection pass. ``meta["parent"]`` keeps the full context, so an effect whose state depends on the
        whole history (a count of events since the start) can compute it there and read it at ``ctx.t``.
        Effects that filter in time restart at each window: the engine excludes a warm-up at every window start."""
        meta = dict(self.meta)
        meta["parent"] = self.meta.get("parent", self)
        return Context(self.t[rows], self.y[rows], self.base[rows], self.base_columns[rows],
                       {k: v[rows] for k, v in self.signals.items()}, self.source,
                       series if series is not None else (None if self.series is None else self.series[rows]), meta)


class Effect:
    """A physical effect the base model lacks: one candidate of a family's library.

    Subclass it (or instantiate with the keyword arguments) and give:

    name : str          the exact name used on the command line and in the report (``coulomb_friction``).
    meaning : str       the physical mechanism, one or two sentences.
    fingerprint : str   what it leaves in the residual (``a step at zero velocity``) and the axis to look at.
    linear : tuple[Param]     coefficients solved by least squares (their bounds are plausibility ranges).
    nonlinear : tuple[Param]  parameters searched on a grid with the linear ones solved inside, then refined.
    fingerprint_axis : str    name of a ``Context.signals`` entry to plot the residual against ("velocity").

    Methods to implement:

    columns(ctx, nl) -> (n, len(linear)) array
        The effect's contribution per unit of each linear coefficient, on the whole record, for nonlinear
        values ``nl`` (dict name -> float). Must be finite. Pure function of ``ctx`` and ``nl``.
    plausible(values, ctx) -> list[str]
        Reasons the fitted values (dict over linear and nonlinear names) are physically implausible; empty if
        fine. Default: linear coefficients inside their [lo, hi].
    physical(values, stds, ctx) -> dict[name, (value, std, unit)]
        Fitted values converted to physical quantities (e.g. a stiffness from a lag). Default: none.
    evidence(residual, ctx, nl) -> float
        Fingerprint score in [0, 1]: the share of the residual's variance the effect's columns can explain
        (least-squares projection). The engine reports it for every candidate at each step.
    """

    name: str = ""
    meaning: str = ""
    fingerprint: str = ""
    linear: tuple[Param, ...] = ()
    nonlinear: tuple[Param, ...] = ()
    fingerprint_axis: str = "velocity"
    #: names of the effects this one modifies (asymmetric friction refines viscous friction): it is a
    #: candidate only once they are in the model, and loses to any accepted primary effect (marginality)
    refines: tuple[str, ...] = ()
    #: what outside the library leaves the same fingerprint in this family's columns, and the measurement that
    #: separates them ("" if nothing known): the effect is then named with "medium" confidence at most, and the
    #: report says so
    twins_outside: str = ""

    def __init__(self, **kw: Any):
        for k, v in kw.items():
            if not hasattr(type(self), k) and k not in ("columns_fn", "plausible_fn", "physical_fn"):
                raise TypeError(f"Effect has no attribute {k!r}")
            setattr(self, k, v)

    # --- to implement -------------------------------------------------------------------------------------
    def columns(self, ctx: Context, nl: dict[str, float]) -> np.ndarray:
        fn = getattr(self, "columns_fn", None)
        if fn is None:
            raise NotImplementedError(f"effect {self.name}: columns() not implemented")
        return np.asarray(fn(ctx, nl), dtype=float).reshape(ctx.n, -1)

    def plausible(self, values: dict[str, float], ctx: Context) -> list[str]:
        out = []
        for p in self.linear:
            v = values[p.name]
            if not (p.lo <= v <= p.hi):
                out.append(f"{p.name} = {v:.4g} {p.unit} outside the plausible range [{p.lo:g}, {p.hi:g}]")
        fn = getattr(self, "plausible_fn", None)
        if fn is not None:
            out += list(fn(values, ctx))
        return out

    def physical(self, values: dict[str, float], stds: dict[str, float], ctx: Context) -> dict[str, tuple]:
        fn = getattr(self, "physical_fn", None)
        return dict(fn(values, stds, ctx)) if fn is not None else {}

    def grid(self, param: Param, ctx: Context) -> np.ndarray:
        """Values of nonlinear ``param`` searched on ``ctx``. Default: ``param.grid_values()``. Override for a
        data-dependent grid (e.g. thresholds between the distinct peaks of a signal)."""
        return param.grid_values()

    # --- provided ------------------------------------------------------------------------------------------
    def default_nl(self) -> dict[str, float]:
        """Middle of each nonlinear parameter's range (geometric middle for log scale)."""
        return {p.name: (math.sqrt(p.lo * p.hi) if p.scale == "log" else 0.5 * (p.lo + p.hi)) for p in self.nonlinear}

    def evidence(self, residual: np.ndarray, ctx: Context, nl: dict[str, float] | None = None,
                 rows: np.ndarray | None = None) -> float:
        X = self.columns(ctx, nl or self.default_nl())
        r = residual
        if rows is not None:
            X, r = X[rows], r[rows]
        X = X - X.mean(axis=0)
        r = r - r.mean()
        ss = float(r @ r)
        if ss <= 0 or not np.all(np.isfinite(X)):
            return 0.0
        coef, *_ = np.linalg.lstsq(X, r, rcond=None)
        return float(max(0.0, min(1.0, 1.0 - np.sum((r - X @ coef) ** 2) / ss)))

    def describe(self) -> dict:
        return {"name": self.name, "meaning": self.meaning, "fingerprint": self.fingerprint,
                "linear": [p.__dict__ for p in self.linear], "nonlinear": [p.__dict__ for p in self.nonlinear]}


@dataclass(frozen=True)
class Family:
    """A model family: data format, base model and candidate effects.

    name : str                   ``swiftfin fit NAME``.
    description : str            one line for the report.
    columns : tuple              required CSV columns (:class:`calibration.io.Column`: name, unit, kind).
    target : str                 the measured quantity the model predicts (a column name, e.g. ``joint_angle_rad``).
    target_unit : str            its unit (``rad``, ``N``, ``m``).
    base_terms : tuple[str]      names of the base model's terms (paper's physics), for the report.
    effects : tuple[Effect]      the candidate library.
    load : callable(path, design, **options) -> Context   read, validate, build the context (UserError on bad data).
    base_coef_names : tuple[str] names/units of the fitted base coefficients (one per base column), e.g.
                                 ("mass_kg",); empty if the base model has none.
    equivalent_effects : tuple[frozenset[str]]  groups of effects whose fingerprints the physics makes
                                 identical in this family's data (documented; the engine still decides from
                                 the data, this is for the report and the tests).
    units : dict                 unit of every quantity the report prints ({"time": "s", "target": "rad", ...}).
                                 A loader may override them per record in ``Context.meta["units"]`` (and the
                                 target's unit in ``Context.meta["target_unit"]``), e.g. a rotary drive log.
    base_columns_fn : callable(ctx, nl_all) -> (n, k0) array, optional
                                 base regressors as a function of the active effects' nonlinear parameters
                                 (``nl_all``: every active effect's values merged; a name missing means the base
                                 model's own value). For a base model whose *shape* the effects change (the body's
                                 wave: its frequency, envelope exponent, wavelength). None: ``ctx.base_columns``.
    shared_params : tuple[str]   nonlinear parameter names that are one physical quantity wherever they appear:
                                 several effects may declare the same one (``p`` of ``envelope_shape`` and
                                 ``rigid_front``), an effect may use one it does not declare (``head_yaw`` swings
                                 at the fitted beat ``ratio``); every effect's columns and the base columns see
                                 the single current value. Fitting a candidate that declares a shared parameter
                                 re-fits it for the whole model.
    alpha, min_relative_drop : the family's default selection criterion (see :mod:`calibration.selection`); the
                                 :class:`Calibrator` and ``swiftfin fit --alpha/--min-drop`` override it.
    plot_rows_fn : callable(ctx) -> bool mask, optional   the rows (one series) the report's time plots show;
                                 default: the first series with held-out rows.
    load_many : callable(paths, design, notes=None) -> list[Context], optional   when set, ``swiftfin fit``
                                 accepts several files (or a folder) as DATA and as --holdout: one context per
                                 file (loaded together, so a loader can pool what the files share), stacked
                                 with :func:`concat_contexts`, one series per file and series. Only for records
                                 without state carried between rows (video markers); None: one file only.
    """

    name: str
    description: str
    columns: tuple
    target: str
    target_unit: str
    base_terms: tuple[str, ...]
    effects: tuple[Effect, ...]
    load: Callable[..., Context]
    base_coef_names: tuple[str, ...] = ()
    equivalent_effects: tuple[frozenset, ...] = ()
    units: dict = field(default_factory=dict)
    base_columns_fn: Callable[[Context, dict], np.ndarray] | None = None
    shared_params: tuple[str, ...] = ()
    alpha: float = 1e-3
    min_relative_drop: float = 0.10
    plot_rows_fn: Callable[[Context], np.ndarray] | None = None
    load_many: Callable[..., list] | None = None

    def effect(self, name: str) -> Effect:
        for e in self.effects:
            if e.name == name:
                return e
        raise KeyError(name)


@dataclass
class FittedEffect:
    """An effect as fitted: values and standard uncertainties of its parameters, and how it was selected."""

    name: str
    nl: dict[str, float]
    values: dict[str, float]                 # linear and nonlinear, by parameter name
    stds: dict[str, float]                   # 1-sigma, same keys (nan if not estimable)
    units: dict[str, str]
    physical: dict[str, tuple] = field(default_factory=dict)   # name -> (value, std, unit)
    rmse_holdout_before: float = float("nan")
    rmse_holdout_after: float = float("nan")
    rmse_train_after: float = float("nan")
    evidence: dict = field(default_factory=dict)
    indistinguishable_from: list[str] = field(default_factory=list)
    confidence: str = "high"

    def to_dict(self) -> dict:
        params = {k: {"value": self.values[k], "std": self.stds.get(k, float("nan")), "unit": self.units.get(k, "")}
                  for k in self.values}
        return {"name": self.name, "params": params,
                "physical": {k: {"value": v[0], "std": v[1], "unit": v[2]} for k, v in self.physical.items()},
                "rmse_holdout_before": self.rmse_holdout_before, "rmse_holdout_after": self.rmse_holdout_after,
                "rmse_train_after": self.rmse_train_after, "evidence": self.evidence,
                "indistinguishable_from": self.indistinguishable_from, "confidence": self.confidence}


def concat_contexts(ctxs: list[Context]) -> Context:
    """Stack records into one context for diagnostics; each record becomes its own series."""
    series = []
    offset = 0
    for c in ctxs:
        s = np.zeros(c.n, int) if c.series is None else c.series - c.series.min()
        series.append(s + offset)
        offset = int(series[-1].max()) + 1 if c.n else offset
    keys = set(ctxs[0].signals)
    for c in ctxs[1:]:
        keys &= set(c.signals)
    return Context(np.concatenate([c.t for c in ctxs]), np.concatenate([c.y for c in ctxs]),
                   np.concatenate([c.base for c in ctxs]),
                   np.vstack([c.base_columns.reshape(c.n, -1) for c in ctxs]),
                   {k: np.concatenate([c.signals[k] for c in ctxs]) for k in keys},
                   " + ".join(c.source for c in ctxs), np.concatenate(series),
                   {k: v for k, v in ctxs[0].meta.items() if not k.startswith("_")})   # "_": per-record caches


__all__ = ["Param", "Context", "Effect", "Family", "FittedEffect", "concat_contexts"]
