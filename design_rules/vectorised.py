"""Every kernel-free design rule over many designs at once: numpy over arrays of designs, the same findings
(value, limit, margin, severity) as :func:`swiftfin.design_rules.rules.run_rules` gives one design at a time.

    from swiftfin.design_rules.vectorised import evaluate
    res = evaluate(list_of_params)                 # or a DesignArrays (struct of arrays)
    res.value[:, res.index("physics.cable_strength")], res.verdict()

What is the same and what is reorganised
----------------------------------------
The numbers are those of the per-design code, sample for sample: the wave on the same 256 (loads) and 720 (joint
range) time samples, the same 400 body strips, 120 shell strips per link, 400 wall stations, the same routes,
split plan and bed-fit bisection. What changes is the order of the arithmetic, never the model, so the findings
agree to rounding (tests/test_vectorised_rules.py proves it on seeded designs, relative 1e-9):

* **Wave kinematics in closed form.** y(x, t) at the nodes is one sinusoid in t, so its FFT derivative
  (``physics.kinematics.periodic_derivative``) is its analytic derivative to rounding. The links' yaw phi =
  atan(sigma), sigma the chord slope, is analytic with its nearest complex singularity at Im(w t) = asinh(1 /
  max|sigma|); on 256 samples its spectral and analytic derivatives agree to < 1e-20 for max|sigma| <
  ``SLOPE_MAX`` (a link yawed up to 68 deg). Beyond it a design goes to the per-design code.
* **Half a period.** Every load is odd under t -> t + T/2 (y, phi and the section velocity change sign), so the
  joint torques, rates and accelerations are computed on the first 128 samples and negated for the rest.
* **Strip sums as moments.** On link k the section's normal velocity is linear along the link, w = P(t) +
  Q(t) u (u in [0, 1] along the link), so the added-mass force of the strips is a sum of a few moments of
  rho pi (h/2)^2 dx over the link, and the drag |w| w is two quadratics split where w changes sign: prefix sums
  over the strips, one cut per link and sample. The moment about joint j is r x F summed over the links behind
  it, a suffix sum over links.
* **The ellipse's integral of y^2 ds** (``layout.loads._ellipse_y2_line_integral``, 256 points) is the
  trapezoid rule of a periodic analytic function: equal to its closed form 4 a^3 J(m), J(m) = ((2m - 1) E(m) +
  (1 - m) K(m)) / (3 m), m = 1 - (b/a)^2, to rounding while the ellipse's axis ratio is above 0.15 (the
  rule's error is e^(-256 atanh(ratio))); thinner sections are summed point by point.
* **Maxima over angle grids** (joint range, bed rotation): the quantity is monotone in a ratio whose maximum
  over the grid is found at a handful of candidate samples (the ends and the samples next to the one crossing
  point), then the same comparisons as the per-design code.

The loops over time samples, links and strips (``joint_loads``' time loop and strip moments, the cable drive, the
pull-out curve) run compiled (``design_rules.loads_kernel``, numba, imported on first use): the same operations,
sample by sample, with the designs innermost and no temporaries.

Designs outside the fast path's validity (a link yawed beyond ``SLOPE_MAX``, a route with no tangent, a
non-finite number) are evaluated by the per-design code; ``RuleArrays.error`` marks designs that it refuses too
(it raises), with every value NaN.

Inputs are schema-valid designs (``swiftfin.core.params``); the cross-field and layout checks of the loader
are not repeated here. The float.* rules need the built parts' mass properties (``mass_properties``);
without them they are NOT_EVALUATED, as in ``swiftfin check``. The load model uses the hull-shell link masses
(``link_masses`` of built parts are not taken).
"""
from __future__ import annotations

import inspect
import math
from dataclasses import dataclass, fields, replace
from functools import cache

import numpy as np

from swiftfin.catalogues.fasteners import screw_sizes
from swiftfin.catalogues.materials import material
from swiftfin.catalogues.printed_strength import printed_strength
from swiftfin.catalogues.seals import cable_gland, seam_gap_tolerance_mm, seam_gasket
from swiftfin.core.schema import SECTIONS, Params
from swiftfin.design_rules.findings import Severity
from swiftfin.design_rules.rules import (MIN_GUIDE_BEND_RAD, MOTOR_CASE_AREA_FACES, RULES, MassProperties,
                                         RuleContext, dry_wall_area_m2, fits_bed, run_rules)
from swiftfin.layout import loads as _loads
from swiftfin.layout.geometry import (BAY_AFTER_DROP_RADII, BAY_ARC_ALLOWANCE_LINES, LANE_DROP_PITCHES,
                                      MIN_TUBE_MM, MIN_WEB_LINES, MOTOR_PITCH_GAP_MM, RISE_MAX_PITCHES,
                                      crossing_rise_mm, plug_screw_size, LUG_GAP_MARGIN_MM)
from swiftfin.layout.fastening import WALL_PROBE_INSET_MM
from swiftfin.layout.gland_plan import passage_bore
from swiftfin.layout.hull_plan import SPLICE_LENGTH_MM
from swiftfin.layout.mount_plan import FIXING_SPREAD_FRACTION
from swiftfin.physics import kinematics as _kin

MM = 1e-3
RULE_IDS: tuple[str, ...] = tuple(r.rule_id for r in RULES)


def _default(fn, name: str):
    return inspect.signature(fn).parameters[name].default


# The sample counts of the per-design code, read from it so that the two stay the same
N_T = _default(_loads.joint_loads, "n_samples")                        # 256 time samples of the loads
N_STRIPS = _default(_loads.joint_loads, "n_strips")                    # 400 body strips
N_SHELL = _default(_loads.shell_link_masses, "n_strips")               # 120 shell strips per link
N_WAVE = _default(_kin.max_relative_joint_angles_rad, "n_samples")     # 720 samples of the joint range
N_WALL = _default(dry_wall_area_m2, "n")                               # 400 stations of the dry wall
N_ELLIPSE = _default(_loads._ellipse_y2_line_integral, "n")            # 256 points round an ellipse
N_BED = _default(fits_bed, "n_angles")                                 # 361 bed rotations
N_SEMI = 201            # stations of HullPiece.max_semi_axes_mm
BED_STEP_DEG = 0.5      # layout.hull_plan.bed_rotation_deg: np.arange(0, 90.01, 0.5)
FIT_BISECTIONS = 40     # design_rules.rules.fit_factor: 40 halvings of [0, 100]
FIT_HI = 100.0
SPLIT_SEARCH_MM = np.arange(0.0, 40.0, 0.5)   # layout.hull_plan._split_stations
MAX_SPLIT = 12          # layout.hull_plan.hull_pieces: up to 12 pieces
SLOPE_MAX = 2.5         # fast path's largest link chord slope (see the module docstring)
RATIO_MIN = 0.15        # closed form of the ellipse's y^2 integral above this axis ratio
CHUNK = 512             # designs evaluated together
ALLOC_ELEMENTS = 15 * 1024   # floats in a temporary array (120 KiB: under malloc's 128 KiB mmap threshold)

for _n in (N_T, N_WAVE):
    if _n % 2:
        raise RuntimeError(f"the half-period evaluation needs an even number of samples, got {_n}")


# ----------------------------------------------------------------------------------------------- inputs
_LISTS = ("joints.stations_fraction", "motor.pullout_curve_steps_per_s", "motor.pullout_curve_torque_nm")
_SKIP_SECTIONS = ("export", "domain_randomisation")
COMPONENTS = "components"
"""The column of each design's ``params.components`` (an object array of tuples): no rule reads it as a number,
but a design rebuilt from the columns (:meth:`DesignArrays.params`) must keep its battery where it was."""


def _objects(items) -> np.ndarray:
    """A 1-D object array of ``items`` (numpy would make a tuple of tuples two-dimensional)."""
    out = np.empty(len(items), dtype=object)
    for i, x in enumerate(items):
        out[i] = tuple(x)
    return out


def _scalar_keys() -> list[str]:
    out = []
    for name, cls in SECTIONS.items():
        if name in _SKIP_SECTIONS:
            continue
        for f in fields(cls):
            if not isinstance(f.default, tuple):
                out.append(f"{name}.{f.name}")
    return out


@dataclass(frozen=True)
class DesignArrays:
    """Designs as a struct of arrays: ``columns["section.key"]`` is one value per design (N,); the list keys
    (``joints.stations_fraction`` and the pull-out curve) are (N, K) padded with NaN. Build it with
    :meth:`from_params` or :meth:`from_columns`; :meth:`params` gives a design back as :class:`Params`."""
    columns: dict
    designs: tuple | None = None      # the Params it came from, when it did

    def __len__(self) -> int:
        return len(self.columns["body.length_mm"])

    @classmethod
    def from_params(cls, designs) -> "DesignArrays":
        designs = tuple(designs)
        cols = {}
        for name, cls_ in SECTIONS.items():
            if name in _SKIP_SECTIONS:
                continue
            secs = [getattr(p, name).__dict__ for p in designs]
            for f in fields(cls_):
                key = f"{name}.{f.name}"
                if isinstance(f.default, tuple):
                    rows = [s[f.name] for s in secs]
                    width = max((len(r) for r in rows), default=1)
                    arr = np.full((len(rows), width), np.nan)
                    for i, r in enumerate(rows):
                        arr[i, :len(r)] = r
                    cols[key] = arr
                elif isinstance(f.default, str):
                    cols[key] = np.array([s[f.name] for s in secs], dtype=object)
                else:
                    dt = bool if isinstance(f.default, bool) else (np.int64 if isinstance(f.default, int) else float)
                    cols[key] = np.fromiter((s[f.name] for s in secs), dtype=dt, count=len(secs))
        cols[COMPONENTS] = _objects([p.components for p in designs])
        return cls(cols, designs)

    @classmethod
    def from_columns(cls, n: int, columns: dict, base: Params | None = None) -> "DesignArrays":
        """``n`` designs: each key of ``columns`` (one value per design, or one for all) over ``base``
        (default: the paper's SwiftFin). Numbers outside the schema's range are refused, every key at once
        (:class:`swiftfin.core.params.ParamError`); the cross-field and layout checks are not made."""
        from swiftfin.core.params import ParamError, Problem
        base = base or Params()
        one = cls.from_params([base]).columns
        cols, probs = {}, []
        for key, v in one.items():
            given = key in columns
            if key == COMPONENTS:        # one tuple of tables per design: carried, not a number to range-check
                rows = list(columns[key]) if given else [base.components] * n
                if len(rows) != n:
                    probs.append(Problem(key, f"{len(rows)} row(s)", f"one tuple of components per design ({n})"))
                    continue
                cols[key] = _objects(rows)
                continue
            a = np.asarray(columns[key]) if given else v[0]
            if key in _LISTS:
                a = np.atleast_2d(np.asarray(a, dtype=float))
                cols[key] = np.broadcast_to(a, (n, a.shape[-1])).copy()
            else:
                cols[key] = np.broadcast_to(a, (n,)).copy() if np.ndim(a) == 0 or len(a) != n else np.array(a)
            if given:
                section, _, name = key.partition(".")
                meta = next(f.metadata for f in fields(SECTIONS[section]) if f.name == name)
                vals = cols[key]
                if meta.get("choices"):
                    bad = ~np.isin(vals, np.asarray(meta["choices"], dtype=vals.dtype))
                elif vals.dtype.kind in "fi":
                    lo, hi = meta.get("lo"), meta.get("hi")
                    with np.errstate(invalid="ignore"):
                        bad = ~np.isfinite(vals) if vals.dtype.kind == "f" else np.zeros(vals.shape, bool)
                        if key in _LISTS:
                            bad = bad & ~np.isnan(vals)
                        if lo is not None:
                            bad |= vals < lo
                        if hi is not None:
                            bad |= vals > hi
                else:
                    bad = np.zeros(vals.shape, bool)
                if bad.any():
                    rows = np.nonzero(bad.reshape(n, -1).any(axis=1))[0]
                    probs.append(Problem(key, f"{len(rows)} design(s), first row {rows[0]}",
                                         f"outside the schema's range {meta.get('lo')}..{meta.get('hi')}"
                                         + (f" / choices {meta['choices']}" if meta.get("choices") else "")))
        unknown = sorted(set(columns) - set(one))
        probs += [Problem(k, "...", "unknown key") for k in unknown]
        if probs:
            raise ParamError("<columns>", probs, "the design columns")
        return cls(cols)

    def take(self, rows) -> "DesignArrays":
        rows = np.asarray(rows)
        designs = None if self.designs is None else tuple(self.designs[i] for i in rows)
        return DesignArrays({k: v[rows] for k, v in self.columns.items()}, designs)

    def params(self, i: int) -> Params:
        """Design ``i`` as :class:`Params` (the one it came from, or rebuilt from the columns)."""
        if self.designs is not None:
            return self.designs[i]
        base = Params()
        secs = {}
        for name, cls_ in SECTIONS.items():
            if name in _SKIP_SECTIONS:
                continue
            kw = {}
            for f in fields(cls_):
                v = self.columns[f"{name}.{f.name}"][i]
                if isinstance(f.default, tuple):
                    v = tuple(float(x) for x in v if not np.isnan(x))
                elif isinstance(f.default, bool):
                    v = bool(v)
                elif isinstance(f.default, int):
                    v = int(v)
                elif isinstance(f.default, float):
                    v = float(v)
                kw[f.name] = v
            secs[name] = replace(getattr(base, name), **kw)
        if COMPONENTS in self.columns:
            secs[COMPONENTS] = tuple(self.columns[COMPONENTS][i])
        return replace(base, **secs)


@dataclass(frozen=True)
class MassPropertyArrays:
    """Mass properties of N built designs (SI, body frame): the float.* rules' input."""
    total_mass_kg: np.ndarray         # (N,)
    com_m: np.ndarray                 # (N, 3)
    cob_m: np.ndarray                 # (N, 3)
    displaced_volume_m3: np.ndarray   # (N,)

    @classmethod
    def from_list(cls, mps) -> "MassPropertyArrays":
        mps = list(mps)
        return cls(np.array([m.total_mass_kg for m in mps]), np.array([m.com_m for m in mps]),
                   np.array([m.cob_m for m in mps]), np.array([m.displaced_volume_m3 for m in mps]))

    def take(self, rows) -> "MassPropertyArrays":
        return MassPropertyArrays(self.total_mass_kg[rows], self.com_m[rows], self.cob_m[rows],
                                  self.displaced_volume_m3[rows])

    def item(self, i: int) -> MassProperties:
        return MassProperties(float(self.total_mass_kg[i]), tuple(float(v) for v in self.com_m[i]),
                              tuple(float(v) for v in self.cob_m[i]), float(self.displaced_volume_m3[i]))


# ----------------------------------------------------------------------------------------------- outputs
@dataclass(frozen=True)
class RuleArrays:
    """Findings of N designs, one column per rule of ``RULES`` (``rule_ids``), in the units of the findings.

    ``value``, ``margin``: (N, R), NaN where a rule is not evaluated; ``limit``: (N, R), a band's low end;
    ``limit_hi``: (N, R), a band's high end (NaN for one-sided rules); ``severity``: (N, R) int8 of
    :class:`Severity`; ``error``: (N,) designs the rules cannot evaluate (the per-design run raises);
    ``fallback``: (N,) designs evaluated by the per-design code (outside the fast path's validity); ``power_w``: (N,)
    the drive's and electronics' electrical draw at the design gait [W], the figure the run-time rule divides the
    battery's energy by (NaN where the rules cannot evaluate the design)."""
    rule_ids: tuple
    value: np.ndarray
    limit: np.ndarray
    limit_hi: np.ndarray
    margin: np.ndarray
    severity: np.ndarray
    error: np.ndarray
    fallback: np.ndarray
    power_w: np.ndarray | None = None   # (N,): electrical draw at the design gait (the run-time rule's), NaN: error

    def index(self, rule_id: str) -> int:
        return self.rule_ids.index(rule_id)

    def verdict(self) -> np.ndarray:
        """The worst severity of each design (int8 of :class:`Severity`)."""
        return self.severity.max(axis=1)

    def row(self, i: int) -> dict:
        """``{rule_id: (value, limit, margin, Severity)}`` of design ``i`` (limit a (lo, hi) tuple for a band)."""
        out = {}
        for r, rid in enumerate(self.rule_ids):
            v, lo, hi, m = (float(x) for x in (self.value[i, r], self.limit[i, r], self.limit_hi[i, r],
                                                self.margin[i, r]))
            lim = (lo, hi) if not math.isnan(hi) else (None if math.isnan(lo) else lo)
            out[rid] = (None if math.isnan(v) else v, lim, None if math.isnan(m) else m,
                        Severity(int(self.severity[i, r])))
        return out


class _Out:
    """Per-chunk result columns being filled."""

    def __init__(self, n: int):
        r = len(RULE_IDS)
        self.value = np.full((n, r), np.nan)
        self.limit = np.full((n, r), np.nan)
        self.limit_hi = np.full((n, r), np.nan)
        self.margin = np.full((n, r), np.nan)
        self.severity = np.full((n, r), int(Severity.NOT_EVALUATED), dtype=np.int8)
        self.bad = np.zeros(n, bool)      # outside the fast path: to the per-design code
        self.power_w = np.full(n, np.nan)

    def _col(self, rid):
        return RULE_IDS.index(rid)

    def at_least(self, rid, value, limit, below=Severity.FAIL):
        value, limit = np.broadcast_arrays(np.asarray(value, float), np.asarray(limit, float))
        c = self._col(rid)
        with np.errstate(divide="ignore", invalid="ignore"):
            margin = np.where(limit != 0, (value - limit) / np.where(limit != 0, limit, 1.0), value - limit)
        self.value[:, c], self.limit[:, c], self.margin[:, c] = value, limit, margin
        self.severity[:, c] = np.where(value >= limit, int(Severity.PASS), int(below))

    def at_most(self, rid, value, limit, above=Severity.FAIL):
        value, limit = np.broadcast_arrays(np.asarray(value, float), np.asarray(limit, float))
        c = self._col(rid)
        with np.errstate(divide="ignore", invalid="ignore"):
            margin = np.where(limit != 0, (limit - value) / np.where(limit != 0, limit, 1.0), limit - value)
        self.value[:, c], self.limit[:, c], self.margin[:, c] = value, limit, margin
        self.severity[:, c] = np.where(value <= limit, int(Severity.PASS), int(above))

    def within(self, rid, value, lo, hi, outside=Severity.FAIL):
        value, lo, hi = np.broadcast_arrays(np.asarray(value, float), np.asarray(lo, float), np.asarray(hi, float))
        c = self._col(rid)
        with np.errstate(divide="ignore", invalid="ignore"):
            m_lo = np.where(lo != 0, (value - lo) / np.where(lo != 0, lo, 1.0), value - lo)
            m_hi = np.where(hi != 0, (hi - value) / np.where(hi != 0, hi, 1.0), hi - value)
        self.value[:, c], self.limit[:, c], self.limit_hi[:, c] = value, lo, hi
        self.margin[:, c] = np.minimum(m_lo, m_hi)
        self.severity[:, c] = np.where((lo <= value) & (value <= hi), int(Severity.PASS), int(outside))

    def not_evaluated(self, rid, rows):
        c = self._col(rid)
        for a in (self.value, self.limit, self.limit_hi, self.margin):
            a[rows, c] = np.nan
        self.severity[rows, c] = int(Severity.NOT_EVALUATED)


# ----------------------------------------------------------------------------------------------- shapes
def _naca_w(s_mm, L_mm, t):
    """Outer hull half-width at station s [mm] (``layout.geometry.naca_half_width_mm``), Horner's form."""
    xi = np.clip(s_mm / L_mm, 0.0, 1.0)
    return 5.0 * t * (0.2969 * np.sqrt(xi) + xi * (-0.1260 + xi * (-0.3516 + xi * (0.2843 - 0.1015 * xi)))) * L_mm


@cache
def _naca_peak() -> float:
    """xi of the NACA 00xx thickness maximum (about 0.30), Newton on the derivative."""
    x = 0.3
    for _ in range(60):
        d1 = 0.14845 / math.sqrt(x) - 0.1260 - 0.7032 * x + 0.8529 * x * x - 0.4060 * x**3
        d2 = -0.074225 / x**1.5 - 0.7032 + 1.7058 * x - 1.2180 * x * x
        x -= d1 / d2
    return x


def _linspace_pt(s0, s1, num: int, i):
    """Point ``i`` of ``np.linspace(s0, s1, num)``, the same floating-point operations."""
    step = (s1 - s0) / (num - 1)
    return np.where(i == num - 1, s1, i * step + s0)


def _ellipse_y2(a, b):
    """``layout.loads._ellipse_y2_line_integral`` (256-point sum of (a cos u)^2 ds round the ellipse) [m^3]."""
    from scipy.special import ellipe, ellipk
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    out = np.empty(np.broadcast(a, b).shape)
    a, b = np.broadcast_arrays(a, b)
    m = 1.0 - (b / a) ** 2
    small = np.abs(m) <= 1e-2
    big = ~small
    mb = m[big]
    out[big] = ((2 * mb - 1) * ellipe(mb) + (1 - mb) * ellipk(mb)) / (3 * mb)
    if small.any():
        out[small] = np.polyval(_J_SERIES[::-1], m[small])
    out *= 4 * a * a * a
    thin = np.minimum(a, b) < RATIO_MIN * np.maximum(a, b)
    if thin.any():
        u = np.linspace(0.0, 2 * np.pi, N_ELLIPSE, endpoint=False)
        at, bt = a[thin][:, None], b[thin][:, None]
        ds = np.sqrt((at * np.sin(u)) ** 2 + (bt * np.cos(u)) ** 2) * (2 * np.pi / N_ELLIPSE)
        out[thin] = np.sum((at * np.cos(u)) ** 2 * ds, axis=1)
    return out


def _j_series(n: int = 10) -> np.ndarray:
    """Taylor coefficients of J(m) = int_0^(pi/2) sin^2 v sqrt(1 - m sin^2 v) dv about m = 0."""
    out = []
    for k in range(n):
        binom = math.prod(0.5 - i for i in range(k)) / math.factorial(k)
        wallis = math.prod(range(2 * k + 1, 0, -2)) / math.prod(range(2 * k + 2, 0, -2))
        out.append((-1) ** k * binom * math.pi / 2 * wallis)
    return np.array(out)


_J_SERIES = _j_series()
EM_NODES = 12           # Gauss-Legendre nodes of the shell's y^2 integral (Group._shell_y2)
_GL_X, _GL_W = np.polynomial.legendre.leggauss(EM_NODES)


def _grid_best(dx, dy, X, Y, n_grid: int, angle):
    """Candidate samples of an angle grid (indices, shape (..., 6)) among which the grid's largest
    min(X / (dx cos a + dy sin a), Y / (dx sin a + dy cos a)) lies: the grid's ends and the samples about the
    one angle in [0, pi/2] where the two ratios cross (each is convex in a, so on either side of the crossing
    its largest value over grid samples is at an end). ``angle(i)`` gives the grid's angle of index i."""
    p = X * dx - Y * dy
    q = Y * dx - X * dy
    r = np.arctan2(q, p)
    r = np.where(r < 0, r + np.pi, r)
    i0 = np.floor(r / (np.pi / 2) * (n_grid - 1))
    i0 = np.where(r <= np.pi / 2, i0, 0.0)
    cand = np.stack([np.zeros_like(i0), np.full_like(i0, n_grid - 1), i0 - 1, i0, i0 + 1, i0 + 2], axis=-1)
    cand = np.clip(cand, 0, n_grid - 1)
    a = angle(cand)
    return a, np.cos(a), np.sin(a)


def _max_abs_angle(num, den):
    """max over the samples (axis 0) of |atan2(num, den)| (T, N) -> (N,): the angle between two links' chords
    (num = sigma' - sigma, den = 1 + sigma sigma' for chord slopes sigma, sigma'). One arctan of the largest
    |num| / den where den > 0 throughout (the angle is monotone in the ratio), atan2 sample by sample
    elsewhere."""
    pos = (den > 0).all(axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.arctan((np.abs(num) / den).max(axis=0))
    if not pos.all():
        out[~pos] = np.abs(np.arctan2(num[:, ~pos], den[:, ~pos])).max(axis=0)
    return out


def _first_clear_cut(base, lo, hi, fixings, keep):
    """``layout.hull_plan._split_stations``' search for each cut (M, K): the first of ``base`` + D, ``base`` - D for
    D over ``SPLIT_SEARCH_MM`` (a grid of step ``h`` from 0), in that order, strictly between ``lo`` and ``hi`` and at
    least ``keep`` (M,) from every wall screw's station ``fixings`` (M, F); ``base`` where none is.

    Without trying all of them: going one way from ``base`` (inside (lo, hi), its middle) a candidate is refused only
    inside a screw's keep-out, so the first one taken is D = 0 or the first grid point past the far end of a keep-out
    (e = f + keep - base going up, base - f + keep going down). Those, and a grid step either side of each (for the
    rounding of e / h), are the only candidates tried, with the very test of the search; the least D taken wins,
    up before down."""
    h = float(SPLIT_SEARCH_MM[1] - SPLIT_SEARCH_MM[0])
    last = len(SPLIT_SEARCH_MM) - 1
    f = fixings[:, None, :]                                              # (M, 1, F)
    kp = keep[:, None, None]
    b = base[..., None]
    steps = {}
    for sign in (1.0, -1.0):
        e = (f + kp - b) / h if sign > 0 else (b - f + kp) / h        # (M, K, F): the keep-outs' far ends, in steps
        k = np.ceil(e)
        k = np.concatenate([np.zeros_like(b), k - 1, k, k + 1], axis=-1)   # (M, K, 3F + 1)
        k = np.where((k >= 0) & (k <= last), k, np.nan)
        c = b + sign * (np.nan_to_num(k) * h)
        far = (np.abs(c[..., None] - f[:, :, None, :]) >= kp[..., None]).all(axis=-1)
        ok = ~np.isnan(k) & (lo[..., None] < c) & (c < hi[..., None]) & far
        steps[sign] = np.where(ok, k, np.inf).min(axis=-1)           # (M, K)
    up, down = steps[1.0], steps[-1.0]
    return np.where(np.isfinite(up) & (up <= down), base + np.where(np.isfinite(up), up, 0.0) * h,
                    np.where(np.isfinite(down), base - np.where(np.isfinite(down), down, 0.0) * h, base))


def _fixing_stations_mm(motor_s, frame_mm):
    """Stations of the motor mounts' wall screws (``layout.mount_plan.mount_fixings_mm``), which the hull's split
    plan keeps its cuts away from: (N, n) motor stations -> (N, k): two per side at the motor's station -/+
    ``FIXING_SPREAD_FRACTION`` x the frame size."""
    dx = (FIXING_SPREAD_FRACTION * frame_mm)[:, None]
    return np.concatenate([motor_s - dx, motor_s + dx], axis=1)


def _kernels():
    """``design_rules.loads_kernel``, imported on first use: numba (and scipy, which it loads) stays out of commands
    that only name the vectorised rules (``swiftfin solve --help``)."""
    from swiftfin.design_rules import loads_kernel
    return loads_kernel


def _c64(v, N: int):
    """``v`` as the compiled kernels take it: float64, C-contiguous, the designs (N) on the last axis (a number is
    repeated for every design)."""
    v = np.asarray(v, dtype=np.float64)
    v = np.broadcast_to(v, v.shape[:-1] + (N,)) if v.ndim else np.full(N, float(v))
    return np.require(v, np.float64, ["C", "W"])     # one signature: never a read-only view (numba types it apart)


def _row_blocks(rows: int, cols: int):
    """Slices of ``rows`` such that a (block, cols) float array stays under 128 KiB: glibc's malloc maps
    larger blocks from the kernel afresh each time (page faults at every temporary), smaller ones it reuses."""
    size = max(1, min(rows, ALLOC_ELEMENTS // max(cols, 1)))
    return [slice(i, min(i + size, rows)) for i in range(0, rows, size)]


def _bed_angle(i):
    return np.radians(BED_STEP_DEG * i)


def _fit_angle(i):
    return _linspace_pt(0.0, np.pi / 2, N_BED, i)


def _fits_bed_rotation(size, X, Y, Z):
    """``layout.hull_plan.bed_rotation_deg(...) is not None`` for boxes (..., 3)."""
    dx, dy, dz = size[..., 0:1], size[..., 1:2], size[..., 2]
    n_grid = int(round(90.0 / BED_STEP_DEG)) + 1
    _, c, s = _grid_best(dx[..., 0], dy[..., 0], X, Y, n_grid, _bed_angle)
    ok = ((dx * c + dy * s <= X[..., None]) & (dx * s + dy * c <= Y[..., None])).any(axis=-1)
    return ok & (dz <= Z)


def _fit_scale(size, X, Y, Z):
    """Largest scale at which boxes (..., 3) fit the bed on the 361-angle grid of ``fits_bed``."""
    dx, dy, dz = size[..., 0], size[..., 1], size[..., 2]
    _, c, s = _grid_best(dx, dy, X, Y, N_BED, _fit_angle)
    dxe, dye = dx[..., None], dy[..., None]
    with np.errstate(divide="ignore"):
        k = np.minimum(X[..., None] / (dxe * c + dye * s), Y[..., None] / (dxe * s + dye * c)).max(axis=-1)
        return np.minimum(k, Z / dz)


def _bisect(box, X, Y, Z):
    """``rules.fit_factor`` of boxes (N, 3): its 40 halvings of [0, 100], each deciding ``fits_bed`` as it does
    (the scaled box's sides against the bed) at the grid angles where the answer lies."""
    dx, dy, dz = box[:, 0], box[:, 1], box[:, 2]
    _, c, s = _grid_best(dx, dy, X, Y, N_BED, _fit_angle)
    lo = np.zeros(len(box))
    hi = np.full(len(box), FIT_HI)
    for _ in range(FIT_BISECTIONS):
        mid = 0.5 * (lo + hi)
        sx, sy, sz = (mid * dx)[:, None], (mid * dy)[:, None], mid * dz
        ok = ((sx * c + sy * s <= X[:, None]) & (sx * s + sy * c <= Y[:, None])).any(axis=1) & (sz <= Z)
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    return lo


# ----------------------------------------------------------------------------------------------- the group
class _Group:
    """One chunk of designs with the same joint count ``n``. Arrays keep the design axis last (N), so every
    numpy loop runs along it: nodes (n+2, N), time series (link, sample, N), strips (strip, N)."""

    def __init__(self, cols: dict, n: int, work: dict | None = None):
        self.c = cols
        self.n = n
        self.N = len(cols["body.length_mm"])
        self._work = {} if work is None else work

    def work(self, name: str, shape) -> np.ndarray:
        """A scratch array kept between the chunks of one evaluation (a large fresh array costs its page
        faults again every time)."""
        size = math.prod(shape)
        buf = self._work.get(name)
        if buf is None or buf.size < size:
            buf = self._work[name] = np.empty(size)
        return buf[:size].reshape(shape)

    def col(self, key):
        return self.c[key]

    # ---------------------------------------------------------------- the wave at the nodes
    def _node_coeffs(self, nodes, L):
        """y(node, t) = a cos(w t) + b sin(w t) at each node (eq. 43-45; ``physics.kinematics.Wave``)."""
        c = self.col
        c0, c1 = c("swimming.head_amplitude_m"), c("swimming.envelope_linear_coefficient")
        c2 = (c("swimming.tail_amplitude_m") - c0 - c1 * L) / L**2
        k = 2.0 * np.pi / (c("swimming.wavelength_body_lengths") * L)
        A = c0 + c1 * nodes + c2 * nodes**2
        ph = k * nodes
        return A * np.sin(ph), -A * np.cos(ph)

    def joint_max_angles(self):
        """``layout.geometry.joint_max_angles_rad``: largest |relative joint angle| on the 720-sample grid
        (its first half: the angles change sign half a period later)."""
        c, n, N = self.col, self.n, self.N
        L = c("body.length_mm") / 1000.0
        st = self.c["joints.stations_fraction"][:n]
        nodes = np.concatenate([np.zeros((1, N)), st * c("body.length_mm") / 1000.0, L[None]], axis=0)
        a, b = self._node_coeffs(nodes, L)
        ang = 2 * np.pi * np.arange(N_WAVE // 2) / N_WAVE
        C, S = np.cos(ang)[:, None], np.sin(ang)[:, None]
        dxn = np.diff(nodes, axis=0)
        sa, sb = np.diff(a, axis=0) / dxn, np.diff(b, axis=0) / dxn              # chord slope = sa cos + sb sin
        out = np.empty((n, N))
        prev = sa[0] * C + sb[0] * S
        for j in range(n):
            cur = sa[j + 1] * C + sb[j + 1] * S
            out[j] = _max_abs_angle(cur - prev, 1.0 + prev * cur)
            prev = cur
        return out

    # ---------------------------------------------------------------- layout numbers
    def layout(self):
        c, n, N = self.col, self.n, self.N
        L_mm = c("body.length_mm")
        self.L_mm = L_mm
        self.t_naca = c("body.naca_thickness_fraction")
        self.H = c("body.height_to_width")
        self.js = self.c["joints.stations_fraction"][:n] * L_mm                 # (n, N)
        self.hend = c("body.hull_end_fraction") * L_mm
        self.stop = self.joint_max_angles() + np.radians(c("joints.stop_margin_deg"))
        w = _naca_w(self.js, L_mm, self.t_naca)
        ca, lw = c("print.clearance_assembly_mm"), c("print.line_width_mm")
        pin = c("joints.pin_diameter_mm")
        plugs = {d: plug_screw_size(d) or screw_sizes()[-1] for d in np.unique(pin)}
        boss_od = np.vectorize(lambda d, w_: plugs[d].insert_boss_od_mm(w_))(pin, lw)
        column = np.maximum(pin / 2 + c("print.clearance_sliding_mm") + np.maximum(2.0, 4 * lw),
                            boss_od / 2 + 2 * WALL_PROBE_INSET_MM)
        gap = np.maximum(w * np.sin(self.stop) + 2.0 * ca + c("hull.wall_thickness_mm"),
                         2.0 * (column + ca + LUG_GAP_MARGIN_MM))   # layout.geometry.joint_gaps_mm
        self.seg_start = np.concatenate([np.zeros((1, N)), self.js + gap / 2], axis=0)       # (n+1, N) hull segs
        self.seg_end = np.concatenate([self.js - gap / 2, self.hend[None]], axis=0)
        # spool (layout.geometry.spool_dims)
        m_mm = c("joints.tendon_moment_arm_mm")
        drum = c("spool.drum_diameter_mm")
        travel = (self.stop * m_mm / (drum / 2) / (2 * math.pi)).max(axis=0)
        turns = c("spool.wraps") + 2 * travel + c("spool.groove_margin_turns")
        turns = turns + c("spool.tension_storage_turns")
        groove = turns * c("spool.groove_pitch_mm") + c("cable.diameter_mm")
        lw = c("print.line_width_mm")
        plate = np.maximum(3.0, 8 * lw)
        hub_bottom = plate + np.maximum(c("motor.pilot_height_mm") - plate, 0.0) + 0.5
        hub, fl = c("spool.hub_length_mm"), c("spool.flange_thickness_mm")
        self.cable_plane = hub_bottom + hub + fl + groove / 2
        self.top = hub_bottom + hub + 2 * fl + groove
        self.hub_bottom = hub_bottom
        self.drum_r = drum / 2
        self.flange_r = self.drum_r + c("spool.flange_height_mm")
        self.end_offset = c("spool.wraps") * c("spool.groove_pitch_mm") / 2
        # motors (layout.geometry.motor_placements)
        F = c("motor.frame_size_mm")
        pitch = F + MOTOR_PITCH_GAP_MM
        s_rear = self.js[0] - self.col("hull.drive_bay_length_mm") - F / 2
        j = np.arange(n)[:, None]
        self.motor_s = s_rear - j * pitch                                        # (n, N)
        z_face = (c("motor.body_length_mm") - self.top) / 2
        self.z_cable = z_face + self.cable_plane
        od = c("guides.ptfe_tube_od_mm")
        lane = self.flange_r + c("print.clearance_assembly_mm") + od / 2 + (j - 1) * (od + 2 * lw)
        self.lane = np.where(j == 0, 0.0, lane)
        self.drop_s = self.motor_s[0] + F / 2                                  # layout.geometry.drop_station_mm
        self.bay_end = self.drop_s + BAY_AFTER_DROP_RADII * c("guides.min_bend_radius_mm")   # bay_end_station_mm

    # ---------------------------------------------------------------- cable routes
    @staticmethod
    def _tangent(px, py, cx, cy, r, side):
        """``layout.geometry._tangent_point``; NaN where there is none."""
        d = np.hypot(px - cx, py - cy)
        beta = np.arctan2(py - cy, px - cx)
        gamma = np.arccos(r / d)
        out_x, out_y = np.full(d.shape, np.nan), np.full(d.shape, np.nan)
        done = d <= r
        for ang in (beta + gamma, beta - gamma):
            qx, qy = cx + r * np.cos(ang), cy + r * np.sin(ang)
            take = ~done & ((qy - cy) * side > 0)
            out_x, out_y = np.where(take, qx, out_x), np.where(take, qy, out_y)
            done |= take
        return out_x, out_y

    def sector_radius(self):
        """``layout.geometry.sector_radius_mm``: (N,)."""
        c = self.col
        dc, cs = c("cable.diameter_mm"), c("print.clearance_sliding_mm")
        return c("joints.tendon_moment_arm_mm") - dc / 2 + 1.3 * (dc / 2 + cs / 2)

    def _joint1_lift(self, pitch_t):
        """``layout.geometry.joint1_lift_mm``: (N,)."""
        c, n = self.col, self.n
        if n < 2:
            return np.zeros(self.N)
        cs, od = c("print.clearance_sliding_mm"), c("guides.ptfe_tube_od_mm")
        r_bore = od / 2 + cs
        reach = self.sector_radius() + c("print.clearance_assembly_mm") + r_bore
        x_h, x_bay = -self.js[0], -self.bay_end
        top = np.full(self.N, -np.inf)
        for j in range(1, n):
            run = np.hypot(x_h - x_bay, self.lane[j])
            f = np.maximum(0.0, 1.0 - reach / run)
            for side in (1, -1):
                z_a = self.z_cable + side * self.end_offset - j * LANE_DROP_PITCHES * pitch_t
                z_b = (n - 1 - j) * 2 * pitch_t + side * pitch_t / 2
                top = np.maximum(top, np.maximum(z_a + f * (z_b - z_a), z_b))
        floor = (n - 1) * 2 * pitch_t - pitch_t / 2 - od / 2 - cs                  # sector_room_floor_mm
        lift = top + r_bore - floor
        return np.where(lift > 0.0, np.ceil(lift * 100.0) / 100.0, 0.0)

    def _joint1_straight_run(self, side, z_s, z_t0):
        """``layout.geometry._joint1_straight_run``: (the bay corner's point, the tangent point), each (x, y, z)."""
        x_bay, x_drop = -self.bay_end, -self.drop_s
        y0 = side * self.drum_r
        tx, ty = self._tangent(x_drop, y0, -self.js[0], 0.0, self.col("joints.tendon_moment_arm_mm"), side)
        f = (x_drop - x_bay) / (x_drop - tx)
        return (x_bay, y0 + f * (ty - y0), z_s + f * (z_t0 - z_s)), (tx, ty, z_t0)

    def _joint1_rise(self, side, z_s, z_t0, pitch_t):
        """``layout.geometry.joint1_rise_mm`` for one side: (N,)."""
        c, n = self.col, self.n
        x_bay = -self.bay_end
        a0, tangent = self._joint1_straight_run(side, z_s, z_t0)
        need = (c("guides.ptfe_tube_od_mm") + c("print.clearance_assembly_mm")
                + BAY_ARC_ALLOWANCE_LINES * c("print.line_width_mm"))            # bay_crossing_gap_mm
        rise = np.zeros(self.N)
        for j in range(1, n):
            b0 = (x_bay, side * self.lane[j], z_s - j * LANE_DROP_PITCHES * pitch_t)
            b1 = (-self.js[0], 0.0, (n - 1 - j) * 2 * pitch_t + side * pitch_t / 2)
            rise = np.maximum(rise, np.nan_to_num(crossing_rise_mm(a0, tangent, b0, b1, need,
                                                                   RISE_MAX_PITCHES * pitch_t)))
        return np.where(rise > 0.01, rise, 0.0)

    def routes(self):
        """Bends over 1 deg, total bend [rad] and length [m] of every route (``layout.geometry.cable_routes``):
        (2, n, N), sides (+1, -1); and the designs with a route that has no tangent."""
        c, n, N = self.col, self.n, self.N
        m = c("joints.tendon_moment_arm_mm")
        x_bay, x_drop = -self.bay_end, -self.drop_s
        lw, od = c("print.line_width_mm"), c("guides.ptfe_tube_od_mm")
        pitch_t = od + 2 * c("print.clearance_sliding_mm") + MIN_WEB_LINES * lw
        mb = c("guides.min_bend_radius_mm")
        count, bend, length = (np.zeros((2, n, N)) for _ in range(3))
        bad = np.zeros(N, bool)
        zeros = np.zeros(N)
        self.guide_turn = np.zeros(N)      # layout.geometry.max_guide_turn_rad: exit, or drop + bay, in one guide
        lift = self._joint1_lift(pitch_t)  # layout.geometry.joint1_lift_mm
        self.lift, self.pitch_t = lift, pitch_t
        self.route_pts = {}                # (joint, side) -> (K, 3, N): the route's points, for the glands
        for j in range(n):
            x_m = -self.motor_s[j]
            for si, side in enumerate((1, -1)):
                z_s = self.z_cable + side * self.end_offset
                z_t = (n - 1 - j) * 2 * pitch_t + side * pitch_t / 2 + (lift if j == 0 else 0.0)
                pts = []
                if j == 0:
                    y_lane = side * self.drum_r
                    pts += [(x_m, y_lane, z_s), (x_drop, y_lane, z_s)]
                    rise = self._joint1_rise(side, z_s, z_t, pitch_t)   # layout.geometry.joint1_rise_mm
                    bay, _ = self._joint1_straight_run(side, z_s, z_t)
                    pts.append((bay[0] + zeros, bay[1], bay[2] + rise))
                else:
                    y_lane = side * self.lane[j]
                    x_in = x_m - self.flange_r - mb / 2
                    sx, sy = self._tangent(x_in, y_lane, x_m, 0.0, self.drum_r, side)
                    pts += [(sx, sy, z_s), (x_in, y_lane, z_s), (x_drop, y_lane, z_s),
                            (x_bay, y_lane, z_s - j * LANE_DROP_PITCHES * pitch_t)]   # lane_drop_mm
                for k in range(j):
                    pts.append((-self.js[k], zeros, z_t))
                last = pts[-1]
                tx, ty = self._tangent(last[0], last[1], -self.js[j], 0.0, m, side)
                pts.append((tx, ty, z_t))
                P = np.array([np.broadcast_arrays(*q, zeros) for q in pts])[:, :3]       # (K, 3, N)
                self.route_pts[j, side] = P
                seg = np.diff(P, axis=0)
                norm = np.sqrt((seg**2).sum(axis=1))                                     # (K-1, N)
                cosang = (seg[:-1] * seg[1:]).sum(axis=1) / (norm[:-1] * norm[1:])
                ang = np.arccos(np.clip(cosang, -1.0, 1.0))
                count[si, j] = (ang > MIN_GUIDE_BEND_RAD).sum(axis=0)
                if j == 0:    # no rise: a point on the straight line, whose arccos is rounding noise (1e-8 rad)
                    ang[1] = np.where(rise > 0.0, ang[1], 0.0)
                # bends: bay, rise | exit, drop, bay
                held = ang[0] + ang[1] if j == 0 else np.maximum(ang[0], ang[1] + ang[2])
                self.guide_turn = np.maximum(self.guide_turn, np.nan_to_num(held))
                tot = zeros
                for q in range(len(ang)):      # sum(b.angle_rad for b in bends), in order
                    tot = tot + ang[q]
                bend[si, j] = tot
                length[si, j] = norm.sum(axis=0) * MM
                bad |= ~np.isfinite(P).all(axis=(0, 1))
        return count, bend, length, bad

    # ---------------------------------------------------------------- link masses (layout.loads.shell_link_masses)
    def shell_masses(self):
        """``layout.loads.shell_link_masses``: mass, centre-of-mass station and yaw inertia of links 1..n (n, N)."""
        c = self.col
        rho = c("print.filament_density_kg_m3")
        t = c("hull.wall_thickness_mm") * MM
        tb = c("hull.bulkhead_thickness_mm") * MM
        L_mm, tn, H = self.L_mm, self.t_naca, self.H
        s0, s1 = self.seg_start[1:], self.seg_end[1:]                   # (n, N): the segment of link k
        sums = (rho * t) * self._shell_sums(s0, s1)                     # the shell: sum of dm {1, s, s^2} + y^2
        m_tot, first, second = sums[0], sums[1], sums[2]
        for s_end in (s0 * MM, s1 * MM):                                # bulkheads
            wb = _naca_w(s_end / MM, L_mm, tn)
            a = wb * MM - t
            bb = (H * wb) * MM - t
            ok = (a > 0) & (bb > 0)
            dm = np.where(ok, rho * tb * math.pi * a * bb, 0.0)
            m_tot = m_tot + dm
            first = first + dm * s_end
            second = second + dm * s_end**2 + np.where(ok, rho * tb * math.pi * a**3 * bb / 4, 0.0)
        f = self.fin
        m_tot[-1] += f["mass"]
        first[-1] += f["mass"] * f["centroid"]
        second[-1] += f["mass"] * f["centroid"] ** 2 + f["izz"]
        x_c = first / m_tot
        return m_tot, x_c, second - m_tot * x_c**2

    def _shell_g(self, s):
        """The shell's integrands at stations s [m]: perimeter P, P s and P s^2 + I (I the ellipse's 256-point
        integral of y^2 ds), on the mid-wall ellipse (a, b); and a mask of where a, b > 0."""
        t = self.col("hull.wall_thickness_mm") * MM
        w = _naca_w(s / MM, self.L_mm, self.t_naca)
        a = w * MM - t / 2
        b = (self.H * w) * MM - t / 2
        ok = (a > 0) & (b > 0)
        if not ok.all():
            a, b = np.where(ok, a, 1.0), np.where(ok, b, 1.0)
        per = math.pi * (3 * (a + b) - np.sqrt((3 * a + b) * (a + 3 * b)))
        ps = per * s
        return np.stack([per, ps, ps * s + _ellipse_y2(a, b)]), a, b, ok

    def _shell_sums(self, s0, s1):
        """Sums over each link's 120 shell strips of ds {P, P s, P s^2 + I} [m^2, m^3, m^4]: (3, n, N).

        The strips are the midpoint rule of smooth functions g(s) on [S0, S1], so each sum is the integral
        (Gauss-Legendre, ``EM_NODES`` nodes) plus the Euler-Maclaurin end corrections -h^2/24 (g'(S1) - g'(S0))
        + 7 h^4/5760 (g'''(S1) - g'''(S0)) (h the strip width; the next term is below 1e-16 of the sum), the end
        derivatives by five-point differences. Valid while g is analytic well beyond the segment: a, b > 0 and an
        axis ratio above ``RATIO_MIN`` at the end strips (the ratio is least where the hull is narrowest, at an
        end), and the zeros of a and b (extrapolated from the end strips) at least half a segment past its ends;
        other links are summed strip by strip, as the per-design code does."""
        S0, S1 = s0 * MM, s1 * MM
        ell = S1 - S0
        h = ell / N_SHELL
        offs = np.array([-2.0, -1.0, 1.0, 2.0, 0.5, 1.5])[:, None, None]
        pts = np.concatenate([0.5 * (S0 + S1) + 0.5 * ell * _GL_X[:, None, None], S0 + offs * h, S1 - offs * h])
        g, a, b, ok = self._shell_g(pts)
        K = len(_GL_X)
        good = ok.all(axis=0)
        for v in (a, b):
            e0, e0b, e1, e1b = v[K + 4], v[K + 5], v[K + 10], v[K + 11]        # the end strips and the next
            good &= np.minimum(a, b)[[K + 4, K + 10]].min(axis=0) >= RATIO_MIN * np.maximum(a, b)[[K + 4, K + 10]].max(axis=0)
            good &= (e0 >= 0.5 * ell / h * np.maximum(e0b - e0, 0.0)) & (e1 >= 0.5 * ell / h * np.maximum(e1b - e1, 0.0))
        integral = 0.5 * ell * np.tensordot(_GL_W, g[:, :K], axes=([0], [1]))
        lo_, hi_ = g[:, K:K + 4], g[:, K + 6:K + 10][:, ::-1]      # S0 - 2h .. S0 + 2h and S1 - 2h .. S1 + 2h

        def d1(q):
            return (q[:, 0] - 8 * q[:, 1] + 8 * q[:, 2] - q[:, 3]) / (12 * h)

        def d3(q):
            return (-q[:, 0] + 2 * q[:, 1] - 2 * q[:, 2] + q[:, 3]) / (2 * h**3)

        out = integral - h**2 / 24 * (d1(hi_) - d1(lo_)) + 7 * h**4 / 5760 * (d3(hi_) - d3(lo_))
        if not good.all():                                               # strip by strip
            bad = ~good
            i = np.arange(N_SHELL + 1)[:, None]
            s = _linspace_pt(s0[bad], s1[bad], N_SHELL + 1, i) * MM       # (121, M)
            sm = 0.5 * (s[1:] + s[:-1])
            gs, _, _, oks = self._shell_g_cols(sm, np.nonzero(bad)[1])
            out[:, bad] = (np.where(oks, gs, 0.0) * np.diff(s, axis=0)).sum(axis=1)
        return out

    def _shell_g_cols(self, s, cols):
        """:meth:`_shell_g` at stations s (rows, M) of the designs ``cols`` (M,)."""
        saved = self.L_mm, self.t_naca, self.H
        t_all = self.c["hull.wall_thickness_mm"]
        self.L_mm, self.t_naca, self.H = self.L_mm[cols], self.t_naca[cols], self.H[cols]
        self.c["hull.wall_thickness_mm"] = t_all[cols]
        try:
            return self._shell_g(s)
        finally:
            self.L_mm, self.t_naca, self.H = saved
            self.c["hull.wall_thickness_mm"] = t_all

    def fin_geometry(self):
        """``layout.loads.fin_geometry``."""
        c = self.col
        b = c("caudal_fin.span_mm") * MM
        S = b**2 / c("caudal_fin.aspect_ratio")
        ch = S / b
        x_le = self.hend * MM
        tan_sw = np.tan(np.radians(c("caudal_fin.sweep_deg")))
        sweep = tan_sw * b / 4
        mass = c("print.filament_density_kg_m3") * 0.685 * c("caudal_fin.thickness_fraction") * ch**2 * b
        izz = mass * (ch**2 / 12 + tan_sw**2 * b**2 / 48)
        self.fin = {"span": b, "area": S, "chord": ch, "ar": c("caudal_fin.aspect_ratio"),
                    "quarter": x_le + ch / 4 + sweep, "centroid": x_le + ch / 2 + sweep, "mass": mass, "izz": izz,
                    "tan_sweep": tan_sw}

    # ---------------------------------------------------------------- joint loads (layout.loads.joint_loads)
    def joint_loads(self):
        """Joint torque, rate and acceleration on the first half period (``layout.loads.joint_loads``), link by
        link: every array is (sample, design), small enough to stay in the cache."""
        c, n, N = self.col, self.n, self.N
        U = c("swimming.speed_m_s")
        rho = c("environment.water_density_kg_m3")
        hy = "hydro."
        L = self.L_mm * MM
        xj = self.js * MM                                                          # (n, N)
        nodes = np.concatenate([np.zeros((1, N)), xj, L[None]], axis=0)            # (n+2, N)
        T2 = N_T // 2
        ang = 2 * np.pi * np.arange(T2) / N_T
        C_all, S_all = np.cos(ang)[:, None], np.sin(ang)[:, None]
        om = 2 * np.pi * c("swimming.tail_beat_frequency_hz")
        a, b = self._node_coeffs(nodes, L)           # y(node) = a cos(w t) + b sin(w t)
        dxn = np.diff(nodes, axis=0)                                               # (n+1, N)
        sa, sb = np.diff(a, axis=0) / dxn, np.diff(b, axis=0) / dxn                # chord slopes' coefficients

        def link_of(xq):
            """Link (0..n) of stations xq (m, N) on the chain, and the weight along it."""
            k = np.full(xq.shape, -1)
            for q in range(n + 2):
                k += xq >= nodes[q]
            np.clip(k, 0, n, out=k)
            x0 = np.take_along_axis(nodes, k, axis=0)
            return k, (xq - x0) / (np.take_along_axis(nodes, k + 1, axis=0) - x0)

        def coeffs_at(xq):
            """Wave coefficients (a, b) at stations xq (m, N), linear along the link chain, and the link's."""
            k, w = link_of(xq)
            ta = np.take_along_axis
            return (ta(a, k, axis=0) * (1 - w) + ta(a, k + 1, axis=0) * w,
                    ta(b, k, axis=0) * (1 - w) + ta(b, k + 1, axis=0) * w, ta(sa, k, axis=0), ta(sb, k, axis=0))

        # body strips from joint 1 to the hull end (S, N) and the moments the forces need:
        # added mass alpha {1, u, u^2} and drag beta {1, u, u^2, u^3} (u along the link; x = x_link + u l_link),
        # (S, 7, N), with their prefix sums over the strips (S+1, 7, N)
        e0 = xj[0]
        e_end = self.hend * MM
        c_am = c(hy + "body_added_mass_coefficient") * rho * np.pi
        c_dr = 0.5 * rho * c(hy + "body_drag_coefficient")
        f64 = lambda v: _c64(v, N)  # noqa: E731
        cum = self.work("cum", (N_STRIPS + 1, 7, N))
        lo, hi = np.empty((n, N), np.int64), np.empty((n, N), np.int64)
        w_first, w_last = np.empty((n, N)), np.empty((n, N))
        _kernels().strip_moments(f64(e0), f64(e_end), N_STRIPS, f64(nodes), f64(self.H), f64(self.L_mm),
                                   f64(self.t_naca), f64(c_am), f64(c_dr), cum, lo, hi, w_first, w_last)
        nn = np.arange(N)
        tot = cum[hi, :, nn].transpose(0, 2, 1) - cum[lo, :, nn].transpose(0, 2, 1)   # (n, 7, N)
        step = (e_end - e0) / N_STRIPS

        masses, x_c, izz = self.shell_masses()                                     # (n, N)
        a_c, b_c, _, _ = coeffs_at(x_c)
        f = self.fin
        xq = np.stack([f["quarter"], f["centroid"]])                               # (2, N)
        aq, bq, saq, sbq = coeffs_at(xq)
        ar = f["ar"]
        a_slope = c(hy + "fin_lift_slope_factor") * 2 * np.pi * ar / (ar + 2)
        m_af = c(hy + "fin_added_mass_coefficient") * rho * np.pi * (f["span"] / 2) ** 2 * f["chord"]
        tau, thetad, thetadd = (np.empty((n, T2, N)) for _ in range(3))
        ratio = np.zeros((n, N))
        den_bad = np.zeros((n, N), bool)
        root_peak = np.zeros(N)
        smax = _kernels().time_loop(
            np.ascontiguousarray(C_all[:, 0]), np.ascontiguousarray(S_all[:, 0]), f64(om), f64(U),
            f64(a), f64(b), f64(sa), f64(sb), f64(nodes), f64(dxn), f64(tot), f64(w_first), f64(w_last),
            lo, hi, cum, f64(e0), f64(step),
            f64(masses), f64(a_c), f64(b_c), f64(x_c), f64(izz), f64(aq), f64(bq), f64(saq), f64(sbq), f64(xq),
            f64(rho), f64(f["area"]), f64(a_slope), f64(c(hy + "fin_drag_coefficient_90")),
            f64(c(hy + "fin_normal_coefficient_max")), f64(m_af), f64(e_end), tau, thetad, thetadd, ratio, den_bad,
            root_peak)
        amp = np.arctan(ratio)
        for j, d in zip(*np.nonzero(den_bad)):      # a relative angle past 90 deg: atan2 sample by sample
            cur, prev = sa[j + 1, d] * C_all + sb[j + 1, d] * S_all, sa[j, d] * C_all + sb[j, d] * S_all
            amp[j, d] = np.abs(np.arctan2(cur - prev, 1.0 + cur * prev)).max()
        self.slope_ok = smax <= SLOPE_MAX
        self.tau_half, self.thetad_half, self.thetadd_half, self.amp = tau, thetad, thetadd, amp
        self.fin_root_nm = root_peak

    # ---------------------------------------------------------------- drive loads (layout.loads.drive_loads)
    def drive(self, bend, length):
        """Tensions, motor torque and step rate over the period (``layout.loads.drive_loads``), reduced to what
        the rules read, joint by joint in blocks of samples. The second half period is the first with the
        torque, rate and acceleration negated."""
        c, n, N = self.col, self.n, self.N
        m = c("joints.tendon_moment_arm_mm") * MM
        r = c("spool.drum_diameter_mm") / 2 * MM
        T0 = c("cable.pretension_n")
        d = c("cable.diameter_mm") * MM
        EA = c("cable.youngs_modulus_gpa") * 1e9 * (math.pi * d**2 / 4.0)
        mu = c("guides.mu_ptfe")
        Jm = c("motor.rotor_inertia_kg_m2") * (m / r)
        ratio_w = np.exp(c("spool.mu_cable_drum") * (2 * math.pi * c("spool.wraps")))
        inv_step = (m / r) / np.radians(c("motor.full_step_deg"))
        T2 = N_T // 2
        peak_motor, peak_tension, peak_spool, comp_max, cap_min = (np.empty((n, N)) for _ in range(5))
        self.d = {"steps": np.empty((n, T2, N)), "need": np.empty((n, T2, N))}
        f64 = lambda v: _c64(v, N)  # noqa: E731
        _kernels().drive(f64(m), f64(r), f64(T0), f64(EA), f64(mu), f64(Jm), f64(ratio_w), f64(inv_step),
                           f64(bend), f64(length), self.tau_half, self.thetad_half, self.thetadd_half,
                           self.d["need"], self.d["steps"], peak_motor, peak_tension, peak_spool, comp_max, cap_min)
        self.d.update(peak_motor=peak_motor, peak_tension=peak_tension, peak_spool=peak_spool, comp_max=comp_max,
                      cap_min=cap_min,
                      mean_pos_power=np.clip(self.tau_half * self.thetad_half, 0.0, None).mean(axis=1).sum(axis=0))

    def shoulder_mm(self):
        """``layout.geometry.tube_seat_shoulder_mm``: whole lines, at least two, holding the most turned guide's
        friction at the cable's breaking strength (after :meth:`routes`)."""
        c = self.col
        lw = c("print.line_width_mm")
        drag = c("cable.breaking_strength_n") * (1.0 - np.exp(-c("guides.mu_ptfe") * self.guide_turn))
        mats = c("print.material")
        shear = np.empty(self.N)
        for name in set(mats.tolist()):
            shear[mats == name] = printed_strength(name).shear_allowable_mpa
        per_mm = shear * math.pi * (c("guides.ptfe_tube_od_mm") + c("print.clearance_sliding_mm"))
        return np.maximum(MIN_WEB_LINES, np.ceil(drag / per_mm / lw - 1e-9)) * lw

    def dry_wall(self):
        """``layout.hull_plan.dry_wall_span_mm`` (after :meth:`routes`): which designs have a dry wall with a joint
        behind it (``hull.flooded_from_joint`` within the joints), and its front and back faces' stations (N,): the
        last sealed segment's end, less the wall, as thick as the cable glands and their seat's shoulder need and
        never thinner than a bulkhead."""
        c, n = self.col, self.n
        k = c("hull.flooded_from_joint")
        inside = k <= n
        kk = np.clip(k - 1, 0, n - 1)
        s_back = np.take_along_axis(self.seg_end, kk[None], axis=0)[0]
        thick = np.maximum(c("hull.bulkhead_thickness_mm"), c("hull.cable_gland_length_mm") + self.shoulder_mm())
        return inside, s_back - thick, s_back

    def gland_ratings(self):
        """``design_rules.rules.cable_gland`` over ``layout.gland_plan.cable_glands`` (after :meth:`routes`): the
        least rated depth [m] over the glands through the dry wall, each its own packed length (the route's segment
        across the wall's mid-plane, through ``layout.gland_plan.passage_bore``, cut short by joint k's clevis room,
        k = ``hull.flooded_from_joint``) less its joint's stroke; and which designs have a gland (N,)."""
        c, n, N = self.col, self.n, self.N
        inside, s_front, s_back = self.dry_wall()
        k = c("hull.flooded_from_joint")
        kk = np.clip(k - 1, 0, n - 1)
        cs, ca, lw = c("print.clearance_sliding_mm"), c("print.clearance_assembly_mm"), c("print.line_width_mm")
        od, P = c("guides.ptfe_tube_od_mm"), self.pitch_t
        m = c("joints.tendon_moment_arm_mm")
        # joint k's hardware (layout.joints._joint_hardware): its own levels, the sector's and the knuckle's heights
        own_hi = (n - k) * 2 * P + P / 2 + np.where(k == 1, self.lift, 0.0)
        behind = k < n                                      # cables of the joints behind cross its hinge line
        z_sec_lo = own_hi - P - np.where(behind, od / 2, P / 2)
        z_sec_hi = own_hi + P / 2
        z_win_lo = np.where(behind, -P / 2 - (od / 2 + cs) - MIN_WEB_LINES * lw, z_sec_lo)
        z_k0 = z_win_lo - c("joints.link_thickness_mm")
        r_knuckle = c("joints.pin_diameter_mm") / 2 + cs + np.maximum(2.0, 4 * lw)
        r_sector = self.sector_radius()
        cuts = ((r_sector + ca, z_sec_lo - cs, z_sec_hi + cs), (r_knuckle + ca, z_k0 - cs, z_sec_lo))
        x_axis = -np.take_along_axis(self.js, kk[None], axis=0)[0]
        xf, xb = -s_front, -s_back
        xm = (xf + xb) / 2
        shoulder = self.shoulder_mm()
        g = cable_gland()
        per_mm = 2.0 * g.grease_yield_stress_pa / g.radial_gap_mm / (
            g.pressure_safety_factor * c("environment.water_density_kg_m3") * c("environment.gravity_m_s2"))
        least = np.full(N, np.inf)
        for (j, _), pts in self.route_pts.items():
            stroke = m * self.stop[j]
            for a, b in zip(pts[:-1], pts[1:]):
                cross = inside & ((a[0] - xm) * (b[0] - xm) < 0)
                if not cross.any():
                    continue
                with np.errstate(divide="ignore", invalid="ignore"):
                    run = passage_bore(a, b, xf, xb, od / 2, shoulder, cuts, x_axis, od / 2 + cs)[3]
                packed = np.where(run >= MIN_TUBE_MM, run, 0.0)
                rated = per_mm * np.maximum(packed - stroke, 0.0)
                least = np.where(cross, np.minimum(least, rated), least)
        return least, np.isfinite(least)

    # ---------------------------------------------------------------- heat (design_rules.rules._heat)
    def heat(self):
        c, n, N = self.col, self.n, self.N
        inside, s_front, s_back = self.dry_wall()
        # dry_wall_m2: the cavity ends at the rear wall's front face
        rear_m = np.where(inside, s_back - s_front, 0.0)
        s_end = np.where(inside, s_front, self.hend)
        rear_m = rear_m * 1e-3
        # the perimeter of the section (a, H a) is pi (1 + H) a R(H) (Ramanujan II with its
        # h = ((1 - H)/(1 + H))^2 the same at every station), the slant sqrt(1 + (d(0.5 (a + b))/ds)^2) by central
        # differences, the trapezoid rule over the 400 equal steps
        a = self.work("wall", (N_WALL, N))
        for blk in _row_blocks(N_WALL, N):
            a[blk] = _naca_w(_linspace_pt(0.0, s_end, N_WALL, np.arange(blk.start, blk.stop)[:, None]),
                             self.L_mm, self.t_naca)
        H = self.H
        ds = s_end / (N_WALL - 1)
        kap = 0.5 * (1 + H)
        acc = np.zeros(N)
        for blk in _row_blocks(N_WALL - 2, N):
            i0, i1 = blk.start + 1, blk.stop + 1
            da = (a[i0 + 1:i1 + 1] - a[i0 - 1:i1 - 1]) * (kap / (2 * ds))
            acc += (a[i0:i1] * np.sqrt(1 + da * da)).sum(axis=0)
        d0, d1 = (a[1] - a[0]) * (kap / ds), (a[-1] - a[-2]) * (kap / ds)
        acc += 0.5 * (a[0] * np.sqrt(1 + d0 * d0) + a[-1] * np.sqrt(1 + d1 * d1))
        hh = ((1 - H) / (1 + H)) ** 2
        side = math.pi * (1 + H) * (1 + 3 * hh / (10 + np.sqrt(4 - 3 * hh))) * ds * acc
        side = side * 1e-6
        rear = np.where(inside, math.pi * a[-1] * (H * a[-1]), 0.0) * 1e-6
        micro = np.where(c("motor.microsteps") > 1, 1.0, 2.0)
        I = c("motor.phase_current_a")
        motor_w = micro * I**2 * c("motor.phase_resistance_ohm")
        driver_w = micro * I**2 * c("power.driver_rds_on_ohm")
        total_w = n * (motor_w + driver_w) + c("power.electronics_power_w")
        mats = c("print.material")
        kw, hdt = np.empty(N), np.empty(N)
        for name in set(mats.tolist()):
            sel = mats == name
            mt = material(name)
            kw[sel], hdt[sel] = mt.thermal_conductivity_w_m_k, mt.heat_deflection_temperature_c
        h_air, h_w = c("environment.heat_transfer_air_w_m2_k"), c("environment.heat_transfer_water_w_m2_k")
        r = 1.0 / (side / (1.0 / h_air + c("hull.wall_thickness_mm") * 1e-3 / kw + 1.0 / h_w)
                   + rear / (1.0 / h_air + rear_m / kw + 1.0 / h_w))
        air = c("environment.water_temperature_c") + total_w * r
        F, bl = c("motor.frame_size_mm"), c("motor.body_length_mm")
        case_area = (MOTOR_CASE_AREA_FACES - 1) * F * bl * 1e-6 + F**2 * 1e-6
        case = air + motor_w / (h_air * case_area)
        return air, case, hdt - c("rules.softening_margin_k"), total_w

    # ---------------------------------------------------------------- bed fit (design_rules.rules.bed_fit)
    def bed_fit(self):
        """Fit factor of the tightest printed part on the layout's split plan, and a mask of designs whose
        hull_pieces raise (value 0 then)."""
        c, n, N = self.col, self.n, self.N
        seg_start, seg_end, motor_s = self.seg_start.T, self.seg_end.T, self.motor_s.T     # design axis first
        X, Y, Z = c("print.bed_x_mm"), c("print.bed_y_mm"), c("print.bed_z_mm")
        L, tn, H = self.L_mm, self.t_naca, self.H
        split = c("hull.split_halves").astype(bool)
        # nose cap (layout.hull_plan.nose_cap)
        sc = c("body.nose_cap_fraction") * L
        xi = sc / L
        w_c = _naca_w(sc, L, tn)
        dw = 5 * tn * (0.2969 / (2 * np.sqrt(xi)) - 0.1260 - 2 * 0.3516 * xi + 3 * 0.2843 * xi**2 - 4 * 0.1015 * xi**3)
        kcap = sc * dw / w_c
        err = ~((0 < kcap) & (kcap < 0.5))
        u = kcap / (1 - kcap)
        A = sc / (1 - u)
        B = w_c / np.sqrt(np.abs(1 - u * u))
        s_peak = _naca_peak() * L

        def semi(s, rows):
            v = (A[rows][..., None] - s) / A[rows][..., None]
            cap = B[rows][..., None] * np.sqrt(np.maximum(0.0, 1 - v * v))
            return np.where(s < sc[rows][..., None], cap, _naca_w(s, L[rows][..., None], tn[rows][..., None]))

        def sizes(s0, s1, rear_cut, rows):
            """Printed size (..., 3) of pieces [s0, s1] (layout.hull_plan.printed_size_mm)."""
            step = (s1 - s0) / (N_SEMI - 1)
            with np.errstate(divide="ignore", invalid="ignore"):
                ip = np.floor((s_peak[rows][..., None] - s0) / step)
            ip = np.where(np.isfinite(ip), ip, 0.0)
            cand = np.clip(np.stack([np.zeros_like(ip), np.full_like(ip, N_SEMI - 1), ip - 1, ip, ip + 1, ip + 2],
                                    axis=-1), 0, N_SEMI - 1)
            pts = _linspace_pt(s0[..., None], s1[..., None], N_SEMI, cand)
            sh = pts.shape
            a = semi(pts.reshape(len(rows), -1), rows).reshape(sh).max(axis=-1)
            b = H[rows][..., None] * a
            length = s1 - s0 + np.where(rear_cut, SPLICE_LENGTH_MM, 0.0)
            sp = split[rows][..., None]
            return np.stack([np.where(sp, length, 2 * a), np.where(sp, 2 * a, 2 * b),
                             np.where(sp, b, length)], axis=-1)

        kmin = np.full(N, np.inf)
        box = np.ones((N, 3))                # the tightest box so far

        def tighter(rows, k, sz):
            better = k < kmin[rows]
            kmin[rows[better]] = k[better]
            box[rows[better]] = sz[better]

        keep = SPLICE_LENGTH_MM + c("hull.screw_diameter_mm") + 3.0
        fixings = _fixing_stations_mm(motor_s, c("motor.frame_size_mm"))     # what the split plan keeps away from
        allr = np.arange(N)
        for g in range(n + 1):
            st, en = seg_start[:, g:g + 1], seg_end[:, g:g + 1]
            size = sizes(st, en, np.zeros((N, 1), bool), allr)                  # (N, 1, 3)
            fits = _fits_bed_rotation(size, X[:, None], Y[:, None], Z[:, None])[:, 0]
            rf = np.nonzero(fits)[0]
            tighter(rf, _fit_scale(size[rf, 0], X[rf], Y[rf], Z[rf]), size[rf, 0])
            todo = np.nonzero(~fits & ~err)[0]
            for npc in range(2, MAX_SPLIT + 1):
                if not len(todo):
                    break
                s0, s1 = seg_start[todo, g], seg_end[todo, g]
                i = np.arange(1, npc)
                diff = s1 - s0
                base = s0[:, None] + i * diff[:, None] / npc                           # (M, npc-1)
                lo = s0[:, None] + (i - 0.5) * diff[:, None] / npc
                hi = s0[:, None] + (i + 0.5) * diff[:, None] / npc
                best = _first_clear_cut(base, lo, hi, fixings[todo], keep[todo])
                cuts = np.concatenate([s0[:, None], best, s1[:, None]], axis=1)          # (M, npc+1)
                rear = np.arange(npc) < npc - 1
                sz = sizes(cuts[:, :-1], cuts[:, 1:], np.broadcast_to(rear, (len(todo), npc)), todo)
                ok_all = _fits_bed_rotation(sz, X[todo][:, None], Y[todo][:, None], Z[todo][:, None]).all(axis=1)
                done = todo[ok_all]
                if len(done):
                    k_p = _fit_scale(sz[ok_all], X[done][:, None], Y[done][:, None], Z[done][:, None])
                    arg = k_p.argmin(axis=1)
                    tighter(done, k_p[np.arange(len(done)), arg], sz[ok_all][np.arange(len(done)), arg])
                todo = todo[~ok_all]
            err[todo] = True
        f = self.fin
        span_mm = f["span"] * 1e3
        sweep = f["tan_sweep"] * f["span"] / 2
        fin_box = np.stack([(f["chord"] + sweep) * 1e3 + c("caudal_fin.mount_length_mm"), span_mm,
                            c("caudal_fin.thickness_fraction") * f["chord"] * 1e3], axis=-1)
        spool_box = np.stack([2 * self.flange_r, 2 * self.flange_r, self.top - self.hub_bottom], axis=-1)
        for b in (fin_box, spool_box):
            tighter(allr, _fit_scale(b, X, Y, Z), b)
        return np.where(err, 0.0, _bisect(box, X, Y, Z)), err


def _pullout(g: _Group, out: _Out):
    """physics.stepper_pullout: the pull-out curve (padded with NaN) at every sample's full-step rate."""
    c = g.col
    rates_all = g.c["motor.pullout_curve_steps_per_s"]                         # (W, N)
    torques_all = g.c["motor.pullout_curve_torque_nm"]
    N = g.N
    n_pts = (~np.isnan(rates_all)).sum(axis=0)
    last = rates_all[n_pts - 1, np.arange(N)]
    ratio, max_rate = np.empty(N), np.empty(N)
    _kernels().pullout_ratio(_c64(rates_all, N), _c64(torques_all, N), g.d["steps"].reshape(-1, N),
                               g.d["need"].reshape(-1, N), ratio, max_rate)
    beyond = max_rate > last
    rid = "physics.stepper_pullout"
    col = out._col(rid)
    out.at_least(rid, ratio, c("rules.pullout_safety_factor"))
    out.value[beyond, col] = max_rate[beyond]
    out.limit[beyond, col] = last[beyond]
    out.margin[beyond, col] = (last[beyond] - max_rate[beyond]) / last[beyond]
    out.severity[beyond, col] = int(Severity.FAIL)


def _evaluate_group(cols: dict, n: int, mass: MassPropertyArrays | None, work: dict | None = None) -> _Out:
    g = _Group(cols, n, work)
    out = _Out(g.N)
    c = g.col
    r = "rules."
    # paper guidelines without loads
    out.at_least("paper.drum_to_cable", c("spool.drum_diameter_mm") / c("cable.diameter_mm"), c(r + "drum_to_cable_min"))
    out.within("paper.pretension_fraction", c("cable.pretension_n") / c("cable.breaking_strength_n"),
               c(r + "pretension_min_fraction"), c(r + "pretension_max_fraction"))
    out.at_most("paper.cable_diameter", c("cable.diameter_mm"), c(r + "cable_diameter_max_mm"))
    out.at_most("paper.guide_friction", c("guides.mu_ptfe"), c(r + "ptfe_mu_max"))
    lw = c("print.line_width_mm")
    for rid, key in (("print.hull_wall", "hull.wall_thickness_mm"), ("print.fin_min_thickness", "caudal_fin.min_thickness_mm"),
                     ("print.spool_flange", "spool.flange_thickness_mm")):
        out.at_least(rid, c(key) / lw, c(r + "wall_min_line_widths"))
    U = c("swimming.speed_m_s")
    with np.errstate(divide="ignore", invalid="ignore"):
        st = c("swimming.tail_beat_frequency_hz") * (2 * c("swimming.tail_amplitude_m")) / U
    out.within("physics.strouhal", st, c(r + "strouhal_min"), c(r + "strouhal_max"))
    out.not_evaluated("physics.strouhal", U <= 0)
    # layout, routes, loads
    g.layout()
    g.fin_geometry()
    count, bend, length, bad_route = g.routes()
    out.bad |= bad_route
    out.at_most("paper.guides_per_route", count.reshape(-1, g.N).max(axis=0), c(r + "guides_per_route_max"),
                above=Severity.WARN)
    g.joint_loads()
    out.bad |= ~g.slope_ok
    g.drive(bend, length)
    d = g.d
    out.at_least("paper.holding_torque", c("motor.holding_torque_nm") / d["peak_motor"].max(axis=0),
                 c(r + "holding_torque_factor"))
    E = c("cable.youngs_modulus_gpa") * 1e9
    area = math.pi * (c("cable.diameter_mm") * 1e-3) ** 2 / 4.0
    out.at_most("paper.cable_elongation", d["peak_tension"].max(axis=0) / (E * area), c(r + "elongation_max_fraction"))
    out.at_least("physics.capstan_no_slip", d["cap_min"].min(axis=0), c(r + "capstan_slip_margin"))
    m = c("joints.tendon_moment_arm_mm") * 1e-3
    peak_tau = np.abs(g.tau_half).max(axis=1)
    out.at_least("physics.no_slack_side", c("cable.pretension_n"), (peak_tau / (2 * m)).max(axis=0))
    out.at_least("physics.cable_strength", c("cable.breaking_strength_n") / d["peak_spool"].max(axis=0),
                 c(r + "cable_safety_factor"))
    _pullout(g, out)
    q = np.radians(c("motor.full_step_deg")) / c("motor.microsteps") * (c("spool.drum_diameter_mm") / 2 * 1e-3) \
        / (m * 1.0)
    out.at_most("physics.microstep_resolution", ((q / 2) / g.amp).max(axis=0),
                c(r + "position_error_limit_fraction"))
    out.at_most("physics.cable_compliance", (d["comp_max"] / g.amp).max(axis=0), c(r + "position_error_limit_fraction"))
    w_end = _naca_w(g.hend, g.L_mm, g.t_naca)                  # design_rules.rules.fin_root_section_mm3
    thick = np.maximum(2 * c("caudal_fin.min_thickness_mm"), 0.5 * w_end)
    mats = c("print.material")
    allow = np.empty(g.N)
    for name in set(mats.tolist()):
        allow[mats == name] = printed_strength(name).bending_allowable_mpa
    out.at_most("physics.fin_root", g.fin_root_nm * 1e3 / (g.H * w_end * thick**2 / 6.0), allow)
    # design_rules.rules.hinge_bend: no joint hardware declares a lead radius, so every crossing's edge is 0 mm
    out.at_least("physics.hinge_bend", np.zeros(g.N), c("rules.drum_to_cable_min") * c("cable.diameter_mm") / 2,
                 below=Severity.WARN)
    if n == 1:
        out.not_evaluated("physics.hinge_bend", slice(None))
    bed, _ = g.bed_fit()
    out.at_least("print.bed_fit", bed, 1.0)
    air, case, limit, total_w = g.heat()
    out.at_most("heat.dry_compartment", air, limit)
    out.at_most("heat.motor_mount", case, limit)
    draw = total_w + np.maximum(d["mean_pos_power"], 0.0)
    out.power_w = np.asarray(draw, float)
    minutes = c("power.battery_energy_wh") * 3600.0 * c("power.battery_usable_fraction") / draw / 60.0
    out.at_least("power.run_time", minutes, c("power.run_time_required_min"))
    rated, has_gland = g.gland_ratings()
    out.at_least("seal.cable_gland", rated, c("environment.design_depth_m"))
    out.not_evaluated("seal.cable_gland", ~has_gland)
    sheet = seam_gasket()
    least = sheet.compression_range(sheet.limiter_length_mm(), seam_gap_tolerance_mm())[0]
    pressure_kpa = c("environment.water_density_kg_m3") * c("environment.gravity_m_s2") * c(
        "environment.design_depth_m") / 1000.0
    out.at_least("seal.seam_gasket", np.full(pressure_kpa.shape, sheet.stress_kpa(least)),
                 sheet.pressure_safety_factor * pressure_kpa)
    out.not_evaluated("seal.seam_gasket", ~c("hull.split_halves").astype(bool))
    # floating
    if mass is None:
        for rid in ("float.upright", "float.net_buoyancy", "float.level"):
            out.not_evaluated(rid, slice(None))
    else:
        out.at_least("float.upright", (mass.cob_m[:, 2] - mass.com_m[:, 2]) * 1e3, 0.0)
        rho = c("environment.water_density_kg_m3")
        frac = (rho * mass.displaced_volume_m3 - mass.total_mass_kg) / mass.total_mass_kg
        out.at_most("float.net_buoyancy", np.abs(frac), c("environment.buoyancy_band_fraction"))
        pitch = np.degrees(np.arctan2(mass.com_m[:, 0] - mass.cob_m[:, 0], mass.cob_m[:, 2] - mass.com_m[:, 2]))
        out.at_most("float.level", np.abs(pitch), c("environment.max_static_pitch_deg"))
    evaluated = out.severity != int(Severity.NOT_EVALUATED)
    finite = np.isfinite(np.where(evaluated, out.value, 0.0)) & np.isfinite(np.where(evaluated, out.margin, 0.0))
    out.bad |= ~finite.all(axis=1)
    return out


# ----------------------------------------------------------------------------------------------- entry point
def evaluate(designs, mass_properties=None, chunk: int = CHUNK) -> RuleArrays:
    """Every rule of ``RULES`` for every design: a list of :class:`Params` or a :class:`DesignArrays`.

    ``mass_properties``: a :class:`MassPropertyArrays` (or a list of :class:`MassProperties`, one per design)
    for the float.* rules; without it they are NOT_EVALUATED. Returns a :class:`RuleArrays`."""
    arr = designs if isinstance(designs, DesignArrays) else DesignArrays.from_params(designs)
    N = len(arr)
    mass = mass_properties
    if mass is not None and not isinstance(mass, MassPropertyArrays):
        mass = MassPropertyArrays.from_list(mass)
    R = len(RULE_IDS)
    value, limit, limit_hi, margin = (np.full((N, R), np.nan) for _ in range(4))
    severity = np.full((N, R), int(Severity.NOT_EVALUATED), dtype=np.int8)
    error = np.zeros(N, bool)
    fallback = np.zeros(N, bool)
    power_w = np.full(N, np.nan)
    counts = arr.columns["joints.count"]
    work: dict = {}
    for n in np.unique(counts):
        rows_all = np.nonzero(counts == n)[0]
        for k in range(0, len(rows_all), chunk):
            rows = rows_all[k:k + chunk]
            cols = {key: (v[rows].T if v.ndim == 2 else v[rows]) for key, v in arr.columns.items()}
            with np.errstate(all="ignore"):
                o = _evaluate_group(cols, int(n), None if mass is None else mass.take(rows), work)
            value[rows], limit[rows], limit_hi[rows], margin[rows], severity[rows] = \
                o.value, o.limit, o.limit_hi, o.margin, o.severity
            fallback[rows] = o.bad
            power_w[rows] = o.power_w
    for i in np.nonzero(fallback)[0]:
        try:
            fs = run_rules(RuleContext(arr.params(int(i)), mass_properties=None if mass is None else mass.item(int(i))))
        except Exception:  # noqa: BLE001 - a design the per-design code refuses: marked, never a crash here
            error[i] = True
            value[i] = limit[i] = limit_hi[i] = margin[i] = np.nan
            severity[i] = int(Severity.NOT_EVALUATED)
            continue
        power_w[i] = _draw_of_run_time(arr.params(int(i)), fs)
        for r, f in enumerate(fs):
            value[i, r] = np.nan if f.value is None else f.value
            if isinstance(f.limit, tuple):
                limit[i, r], limit_hi[i, r] = f.limit
            else:
                limit[i, r], limit_hi[i, r] = (np.nan if f.limit is None else f.limit), np.nan
            margin[i, r] = np.nan if f.margin is None else f.margin
            severity[i, r] = int(f.severity)
    power_w[error] = np.nan
    return RuleArrays(RULE_IDS, value, limit, limit_hi, margin, severity, error, fallback, power_w)


def _draw_of_run_time(p: Params, findings) -> float:
    """The electrical draw [W] behind the per-design run-time finding: the usable energy over the minutes."""
    f = next(f for f in findings if f.rule_id == "power.run_time")
    if f.value is None or not f.value > 0:
        return math.nan
    return p.power.battery_energy_wh * 3600.0 * p.power.battery_usable_fraction / (f.value * 60.0)


# ----------------------------------------------------------------------------------------------- seeded designs
def _sized_as_a_designer_would(p: Params) -> Params:
    """``p`` with two sizes a designer picks from the rest rather than by chance: the smallest catalogue hull screw
    its motor mounts' wall fixings can be made with (a strong motor on a small drum pulls its mount so hard that an
    M2's pad floor outgrows every M2 length), front bulkheads at least as thick as that screw's inserts are long
    (the link flanges' inserts go in them), and as many foam blocks (up to the default's) as its flooded segments
    have room for, and cable glands as long as its stroke and design depth need (:func:`gland_length_needed_mm`). A
    size that cannot be made stays as drawn (the loader then says why). No draw: the random stream stays as it
    was."""
    from swiftfin.catalogues.fasteners import fastener, screw_diameters_mm
    from swiftfin.core.errors import BuildError, UserError
    from swiftfin.core.params import replace_key
    from swiftfin.layout.flotation_plan import foam_blocks
    from swiftfin.layout.mount_plan import wall_fixings

    def first_made(key: str, values, plan) -> Params:
        for v in values:
            q = replace_key(p, key, v)
            try:
                plan(q)
            except (BuildError, UserError):
                continue
            except Exception:  # noqa: BLE001 - a layout the loader refuses for its own reason: it says which
                return p
            return q
        return p

    p = first_made("hull.screw_diameter_mm", screw_diameters_mm(), wall_fixings)
    # the front bulkheads hold the link flange screws' inserts: at least as thick as they are long
    insert = fastener(p.hull.screw_diameter_mm).insert_length_mm
    if p.hull.bulkhead_thickness_mm < insert:
        p = replace_key(p, "hull.bulkhead_thickness_mm", insert)
    p = first_made("environment.flotation_foam_segments",
                   range(p.environment.flotation_foam_segments, -1, -1), foam_blocks)
    p = replace_key(p, "hull.cable_gland_length_mm", gland_length_needed_mm(p))
    return _components_placed(p)


COMPONENT_HEIGHT_STEPS = 8
"""Heights a designer tries for a component of a drawn design: its height in the default design scaled to this hull's
depth at its station, then that height stepped toward the axis in this many equal steps (the first that fits)."""


def _components_placed(p: Params) -> Params:
    """``p`` with each component (the default's, in millimetres) where it fits this hull, as a designer would move
    it: its station moved aft or forward, if need be, into the head's hollow with room for its cradle's ends (the
    nose cap and the dry compartment's rear wall move with the body), then its height, the default design's scaled
    by the ratio of the hulls' half-heights at its station or, where that leaves a corner through the wall or no
    floor for its cradle, the first of that height's steps toward the axis that lies inside with room for its cradle
    (:func:`swiftfin.layout.hull_plan.component_problems` and :func:`swiftfin.layout.cradle_plan.cradles`, the
    loader's own checks). A component that fits nowhere on that line stays where the scaling put it: the loader then
    refuses the design, naming the component."""
    import dataclasses

    from swiftfin.layout.cradle_plan import end_room_mm
    from swiftfin.layout.geometry import half_height_mm
    from swiftfin.layout.hull_plan import component_problem, head_hollow_mm
    base = Params()
    try:
        hollow = head_hollow_mm(p)
    except Exception:  # noqa: BLE001 - a hull the plans cannot cut (even a division by zero in a drawn design's
        return p       # mount fixings): the loader's guarded layout checks say why, naming the key
    if hollow is None:
        return p
    c_mm = max(p.print.clearance_assembly_mm, end_room_mm(p))     # room round the box, or for its cradle's ends
    length = p.body.length_mm
    comps = list(p.components)
    for i, c in enumerate(comps):
        if c.name == "fasteners":
            continue
        half = c.size_mm[0] / 2 + c_mm + 1e-6    # (a hair inside, so the check's own rounding does not refuse it)
        s_mm = min(max(c.station_fraction * length, hollow[0] + half), hollow[1] - half)
        scale = float(half_height_mm(p, s_mm)) / float(half_height_mm(base, c.station_fraction * base.body.length_mm))
        c = dataclasses.replace(c, station_fraction=s_mm / length, z_mm=c.z_mm * scale)
        comps[i] = c
        for k in range(COMPONENT_HEIGHT_STEPS + 1):
            trial = dataclasses.replace(c, z_mm=c.z_mm * (1 - k / COMPONENT_HEIGHT_STEPS))
            if component_problem(p, i, trial, hollow) is None and _cradle_made(p, i, trial):
                comps[i] = trial
                break
    return dataclasses.replace(p, components=tuple(comps))


def _cradle_made(p: Params, i: int, c) -> bool:
    """Whether component ``c`` (entry ``i`` of ``p.components``) gets its cradle where it stands."""
    from swiftfin.core.errors import UserError
    from swiftfin.layout.cradle_plan import PLACEHOLDERS, cradle_of
    if c.name in PLACEHOLDERS:
        return True
    try:
        cradle_of(p, i, c)
    except UserError:
        return False
    return True


def gland_length_needed_mm(p: Params) -> float:
    """The cable glands' packed length a designer would give the design: its longest stroke (moment arm x stop
    angle) plus the grease plug that holds its design depth with the seal table's safety factor, rounded up to the
    millimetre (within the key's range); then as much longer as joint 1's own glands need to be that long over
    their own stroke, where its sector's room in the wall's back face shortens them
    (:func:`swiftfin.layout.gland_plan.cable_glands`), a millimetre at a time, as far as the bay guide leaves the
    wall room. A design whose glands cannot be measured keeps the first length (the loader says why)."""
    from swiftfin.layout.geometry import joint_stop_angles_rad
    from swiftfin.layout.gland_plan import cable_glands, wall_room_mm
    from swiftfin.layout.hull_plan import dry_wall_thickness_mm
    g = cable_gland()
    stroke = p.joints.tendon_moment_arm_mm * max(joint_stop_angles_rad(p))
    env = p.environment
    plug = (g.pressure_safety_factor * env.water_density_kg_m3 * env.gravity_m_s2 * env.design_depth_m
            * g.radial_gap_mm / (2.0 * g.grease_yield_stress_pa))
    first = float(min(60.0, max(2.0, math.ceil(stroke + plug))))
    length = first
    try:
        # the room the bay guide leaves the wall shrinks by what the wall grows
        most = min(60.0, first + wall_room_mm(p) + dry_wall_thickness_mm(p) - dry_wall_thickness_mm(p, first))
        for _ in range(6):
            short = max(((gl.stroke_mm + plug - gl.packed_mm) * abs(gl.axis[0]) for gl in cable_glands(p, length)),
                        default=0.0)
            if short <= 0.0:
                return length
            nxt = float(min(math.ceil(length + short), math.floor(most)))
            if nxt <= length:
                return length
            length = nxt
    except Exception:  # noqa: BLE001 - routes the layout cannot draw (a hinge point inside the next joint's
        return first   # sector): the loader's guarded checks say why, naming the key
    return length


def _laid_out_nowhere(p: Params) -> bool:
    """Whether the loader's first layout check (:func:`swiftfin.layout.geometry.layout_problems`: motors, tendon
    sectors and segments inside the hull, stops) refuses ``p`` or cannot measure it. The designer's sizing
    (:func:`_sized_as_a_designer_would`) changes none of what it reads but the bulkhead's thickness, and only
    upward, which the check asks more room for: a draw it refuses is refused after sizing too, so skipping the
    sizing keeps the sample as it was. It refused 152 of the 331 draws behind ``seeded_designs(40)``, whose
    sizing took three quarters of the draw's time."""
    from swiftfin.layout.geometry import layout_problems
    try:
        return bool(layout_problems(p))
    except Exception:  # noqa: BLE001 - check_design's guard refuses a design the check cannot measure
        return True


def _refused_whatever_the_sizes(p: Params) -> bool:
    """Whether the loader refuses ``p`` for a reason the designer's sizing (:func:`_sized_as_a_designer_would`: hull
    screw, bulkhead thickness, foam blocks, gland length, components) cannot change, so that sizing it, three fifths
    of a draw's time, is not worth it: the joints' hardware has a problem under ``joints.tendon_moment_arm_mm`` (the
    tendon groove's wrap past its tangent within the gap, its anchor inside the groove's root: the moment arm, the
    cable, the routes' tangents, the stop angles and the gaps), or the spools' plan refuses it (drum, grooves, index
    holes and screws, crimp seats). Neither reads a sized key, and the loader's levels before theirs only ask more
    of the sized design (the spools' plan is made even where the hull cannot be cut to fit the bed). Measured
    2026-11-30, side by side: ``seeded_designs`` of 300, 100 and 40 designs (seeds 16, 2027, 20261124) sized 2708
    draws without it, 733 with it (154 s against 56 s for the 300) and kept the same designs."""
    from swiftfin.core.errors import BuildError, UserError
    from swiftfin.layout.joints import joint_link_problems
    from swiftfin.layout.spool_plan import spool_plan
    try:
        if any(pr.key == "joints.tendon_moment_arm_mm" for pr in joint_link_problems(p)):
            return True
        try:
            spool_plan(p)
        except (UserError, BuildError):
            return True
    except Exception:  # noqa: BLE001 - a design the checks cannot measure: the sizing and the loader say why
        return False
    return False


def seeded_designs(n: int, seed: int = 16, check_layout: bool = True, max_draws: int | None = None) -> list[Params]:
    """``n`` designs drawn around the paper's SwiftFin, reproducibly: 2-5 joints spread over the tail, and the
    numbers the rules read (body, hull, motor and its pull-out curve, spool, cable, fin, gait, water, coefficients,
    battery, printer, some limits) drawn within their documented ranges. Only designs the loader accepts are kept
    (``params_from_dict``, and with ``check_layout`` the layout checks of ``swiftfin.layout.design``), so each one
    is a design ``swiftfin check`` would take. For the identity test, the benchmark and design searches."""
    from swiftfin.core.params import ParamError, params_from_dict, to_dict
    from swiftfin.layout.design import check_design
    rng = np.random.default_rng(seed)
    u = rng.uniform
    out: list[Params] = []
    draws = 0
    while len(out) < n:
        draws += 1
        if max_draws is not None and draws > max_draws:
            break
        d = to_dict(Params())
        k = int(rng.integers(2, 6))
        first, last = u(0.50, 0.58), u(0.70, 0.80)
        st = np.linspace(first, last, k)
        st[1:-1] += u(-0.01, 0.01, k - 2)
        d["joints"].update(count=k, stations_fraction=[float(x) for x in st], tendon_moment_arm_mm=u(10, 20),
                           stop_margin_deg=u(2, 10))
        d["body"].update(length_mm=u(420, 700), naca_thickness_fraction=u(0.12, 0.20), height_to_width=u(1.2, 2.0),
                         nose_cap_fraction=u(0.02, 0.06), hull_end_fraction=u(0.88, 0.95))
        d["hull"].update(wall_thickness_mm=u(1.2, 3.0), bulkhead_thickness_mm=u(2, 4),
                         split_halves=True, flooded_from_joint=1)
        rng.random()                # (drawn as the split once was: a whole hull is refused, core/params.py)
        rng.integers(1, k + 2)      # (drawn as the sealed joint once was: the stream stays as it was; only the
        #                             head can be sealed, core/params.py)
        rates = np.unique(np.sort(u(0, 9000, int(rng.integers(4, 8)))) * u(0.5, 2.0))
        if rng.random() < 0.7:
            rates[0] = 0.0
        torques = np.sort(u(0.05, 0.5, len(rates)))[::-1] * u(0.5, 2.0)
        d["motor"].update(holding_torque_nm=u(0.2, 1.5), rotor_inertia_kg_m2=u(3e-6, 1.2e-5),
                          phase_current_a=u(0.8, 2.2), phase_resistance_ohm=u(0.8, 3.0),
                          full_step_deg=float(rng.choice([0.9, 1.8])), microsteps=int(rng.choice([1, 2, 4, 8, 16, 32])),
                          pullout_curve_steps_per_s=[float(x) for x in rates],
                          pullout_curve_torque_nm=[float(x) for x in torques])
        cd = u(0.5, 1.4)
        breaking = u(150, 800)
        d["cable"].update(diameter_mm=cd, breaking_strength_n=breaking, pretension_n=breaking * u(0.05, 0.3),
                          youngs_modulus_gpa=float(np.exp(u(0.0, np.log(120)))))
        d["spool"].update(drum_diameter_mm=u(14, 32), wraps=u(1.0, 4.0), groove_pitch_mm=cd + u(0.5, 1.2),
                          flange_thickness_mm=u(1.0, 2.5), mu_cable_drum=u(0.15, 0.6), groove_depth_mm=min(0.5, cd))
        d["guides"].update(mu_ptfe=u(0.02, 0.2))
        d["caudal_fin"].update(span_mm=u(100, 220), aspect_ratio=u(4, 8), sweep_deg=u(15, 45),
                               thickness_fraction=u(0.08, 0.16), min_thickness_mm=u(1.0, 2.0))
        d["swimming"].update(tail_beat_frequency_hz=u(0.5, 5.0), tail_amplitude_m=u(0.02, 0.14),
                             head_amplitude_m=u(0, 0.01), envelope_linear_coefficient=u(-0.03, 0.03),
                             wavelength_body_lengths=u(0.8, 2.0),
                             speed_m_s=0.0 if rng.random() < 0.08 else u(0.2, 2.5))
        d["environment"].update(water_density_kg_m3=u(995, 1030), water_temperature_c=u(10, 30),
                                heat_transfer_water_w_m2_k=u(100, 1000), heat_transfer_air_w_m2_k=u(3, 15),
                                buoyancy_band_fraction=u(0.02, 0.1), max_static_pitch_deg=u(2, 10),
                                # the default's foam blocks, as many as the design has flooded segments (no draw:
                                # the sample's random stream stays as it was)
                                flotation_foam_segments=min(Params().environment.flotation_foam_segments,
                                                            k + 1 - d["hull"]["flooded_from_joint"]))
        for key in ("body_added_mass_coefficient", "body_drag_coefficient", "fin_added_mass_coefficient",
                    "fin_lift_slope_factor", "fin_drag_coefficient_90", "fin_normal_coefficient_max"):
            d["hydro"][key] *= u(0.6, 1.4)
        d["power"].update(battery_energy_wh=u(2, 30), battery_usable_fraction=u(0.6, 0.95),
                          driver_rds_on_ohm=u(0.2, 1.5), electronics_power_w=u(0.1, 2.0),
                          run_time_required_min=u(5, 60))
        d["print"].update(bed_x_mm=u(100, 350), bed_y_mm=u(100, 350), bed_z_mm=u(100, 350), line_width_mm=u(0.4, 0.6),
                          filament_density_kg_m3=u(1050, 1300), material=str(rng.choice(["PLA", "PETG", "ASA"])))
        d["rules"].update(capstan_slip_margin=u(1.0, 3.0), cable_safety_factor=u(1.5, 5),
                          pullout_safety_factor=u(1.0, 2.5), position_error_limit_fraction=u(0.01, 0.2),
                          elongation_max_fraction=u(0.002, 0.05), guides_per_route_max=int(rng.integers(1, 6)))
        try:
            p = params_from_dict(d, f"seeded design {draws}")
            if check_layout:
                if _laid_out_nowhere(p) or _refused_whatever_the_sizes(p):   # not worth sizing
                    continue
                p = check_design(_sized_as_a_designer_would(p), f"seeded design {draws}")
        except ParamError:
            continue
        out.append(p)
    return out
