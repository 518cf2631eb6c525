"""From a failing design to the nearest one that passes: a search over chosen parameters with the vectorised rules.

    result = solve(params, [parse_vary("cable.pretension_n=10:200"), parse_vary("motor.model=custom,23HS22-2804S")])
    result.passes, result.design, [(c.key, c.before, c.after, c.buys) for c in result.changes]

What "nearest" means (the issue's "fewest and smallest changes"): designs that change fewer of the varied keys come
first; among those, the smallest total change, each continuous key's change measured as a fraction of its search
range and a changed choice (a catalogue model, a material) as 1. The search:

1. **Fewest keys first.** For k = 1 and 2 it changes every set of k varied keys, the rest held at the design's
   values, on a scrambled Sobol sample of their ranges (``scipy.stats.qmc``; choices drawn evenly), and evaluates
   all of them at once (:func:`swiftfin.design_rules.vectorised.evaluate`: every kernel-free rule of ``swiftfin
   check``). It stops at the first k that has a design passing every rule (WARN and NOT_EVALUATED do not fail)
   which the loader also accepts (:func:`swiftfin.layout.design.check_design`: the motor fits the hull, ...).
2. **More keys.** From the closest design so far it sets one key or two at a time (re-tuning one already changed
   is allowed), each step the one that leaves the fewest failing rules and then the smallest shortfall, until the
   design passes or no step helps; then a differential evolution over every key (``scipy.optimize``, a whole
   population per vectorised call) minimising the shortfall first and the change second. A passing design found
   this way is thinned: changes are undone, one at a time, while it keeps passing.
3. **Smallest change.** The continuous changes are then pulled back toward the design's own values one key at a
   time by bisection (``REFINE_STEPS`` halvings), keeping it passing: the result sits on the boundary of the rule
   that binds, to ``range / 2^REFINE_STEPS``.
4. **What each change buys**: each change undone alone (the others kept), and the rules that then fail.
5. **The trade-offs** (:func:`pareto_front`): the Pareto front of the passing designs over predicted speed (up),
   electrical power at the design gait and the bought mass (down), grown from Sobol samples over every varied key
   by rounds of designs scattered round the front so far; for each front design the rule with the least margin and
   the rules that fail when its tail beats 5 % faster.

A catalogue model (``motor.model``, ``cable.model``) changes every number its entry gives, as the loader would.
When the tail-beat frequency changes and the speed is not searched, the speed follows it at constant stride
(``swimming.speed_m_s`` x f / f0: stride per beat held, the Strouhal number then set by the amplitude; Bainbridge
1958, speed proportional to frequency at constant amplitude). A catalogue motor runs at its rated current
with its rated torque (``catalogues/motors.py``); it comes without a pull-out curve (that depends on the driver
and the supply), so the design's curve scaled by the two holding torques stands in for it. When the phase current
changes, the holding torque and the pull-out curve scale with it from the motor's own (rated, or the design's)
current: a hybrid stepper's torque is about proportional to its current below saturation (Kenjo & Sugawara 1994,
Stepping Motors and Their Microprocessor Controls, ch. 4); above that current no torque is gained, only heat. A
named motor at another current is written as ``model = "custom"`` with its scaled numbers. The result lists
these assumptions (:attr:`SolveResult.notes`). Without a passing design the result is the closest
one found (fewest failing rules, then the smallest summed shortfall) and the rules it still fails.

No CAD kernel: the floating rules need a build's mass properties and are NOT_EVALUATED here; build the design the
search writes and run ``swiftfin check --mass-properties`` on it for those.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from swiftfin.catalogues.cables import cable_params, cable_spec
from swiftfin.catalogues.motors import motor_params
from swiftfin.core.errors import UserError
from swiftfin.core.params import ParamError, Problem, get_key, params_from_dict, to_dict
from swiftfin.core.schema import CUSTOM, SECTIONS, Params
from swiftfin.layout.geometry import inner_envelope_excess_mm
from swiftfin.design_rules.findings import Severity
from swiftfin.design_rules.vectorised import RULE_IDS, DesignArrays, evaluate

REFINE_STEPS = 24
SAMPLES_PER_KEY = 256
MAX_LAYOUT_CHECKS = 200     # passing designs put through the loader's layout checks, nearest first
THIN_CANDIDATES = 16        # passing designs of the evolution thinned to their fewest changes
EVOLVE_POPULATION = 40      # x the number of keys: scipy's popsize
EVOLVE_GENERATIONS = 60
LAYOUT_CHECKS_PER_GENERATION = 16
LAYOUT_PENALTY_FAILS = 2    # designs failing at most this many rules are put through the layout checks
LAYOUT_PENALTY = 5000.0     # cost of a design the loader refuses (a shortfall of log(1 + |margin|) = 5)
FRONT_SAMPLES = 1 << 12
"""Designs per stage of the Pareto front: Sobol over every varied key, then each round round the front so far."""
FRONT_ROUNDS = 6
"""Rounds of designs scattered round the front so far (:func:`pareto_front`)."""
FRONT_STEP = 0.2
FRONT_SHRINK = 0.6
"""First round's step, as a fraction of each key's range, and its shrink per round (0.2 ... 0.016)."""
FRONT_SEEDS = 32
"""Front designs, spread along it, that seed each round (each put through the loader's layout checks, ~60 ms)."""
FRONT_KEPT = 64
"""Front designs kept in the result, spread from the fastest to the slowest (a front of thousands of near-ties is
no more use to a designer and costs a layout check each)."""
FRONT_SHOWN = 10
SPEED_PROBE = 0.05
"""A front design's tail beats this much faster to find what stops it (:func:`_speed_limits`)."""
"""Front points the command prints, spread evenly from the fastest to the slowest."""

#: What ``swiftfin solve`` searches when no ``--vary`` is given: the levers the failing rules of the paper's design
#: point at (issue 16): the motor, the cable, the pretension, the drum, the moment arm, the gait, the printed
#: material and the battery. Ranges inside the schema's; a design may narrow or widen them with ``--vary``.
DEFAULT_VARY = (
    "motor.model=custom,17HS19-2004S1,23HS22-2804S",
    "cable.youngs_modulus_gpa=1:120",
    "cable.breaking_strength_n=100:3000",
    "cable.pretension_n=10:600",
    "spool.drum_diameter_mm=12:40",
    "joints.tendon_moment_arm_mm=8:30",
    "swimming.tail_beat_frequency_hz=0.2:3",
    "swimming.tail_amplitude_m=0.03:0.12",
    "motor.phase_current_a=0.3:1.5",
    "print.material=PLA,PETG,ASA",
    "power.battery_energy_wh=4.5:50",
)

_CATALOGUE = {"motor.model": lambda name: {f"motor.{k}": v for k, v in motor_params(name).items()},
              "cable.model": lambda name: {f"cable.{k}": v for k, v in cable_params(name).items()}}


@dataclass(frozen=True)
class Vary:
    """One searched key: a continuous range [lo, hi] or a list of choices (strings, or numbers of a choice key)."""
    key: str
    lo: float = math.nan
    hi: float = math.nan
    choices: tuple = ()

    @property
    def categorical(self) -> bool:
        return bool(self.choices)

    def text(self) -> str:
        return f"{self.key}={','.join(map(str, self.choices))}" if self.categorical else f"{self.key}={self.lo:g}:{self.hi:g}"


def _meta(key: str):
    section, _, name = key.partition(".")
    cls = SECTIONS.get(section)
    f = next((f for f in fields(cls) if f.name == name), None) if cls else None
    return f


def parse_vary(text: str, source: str = "--vary") -> Vary:
    """``KEY=LO:HI`` (a number key, within the schema's range) or ``KEY=A,B,C`` (values the key accepts: catalogue
    models, materials, a choice key's numbers). Raises ParamError naming the key, the value and what was expected."""
    key, eq, spec = text.partition("=")
    key, spec = key.strip(), spec.strip()
    f = _meta(key) if eq else None
    if f is None:
        raise ParamError(source, [Problem(key or text, text, "expected KEY=LO:HI or KEY=A,B,C with KEY a parameter "
                                          "of the schema (section.key, as in swiftfin params --dump)")])
    meta, default = f.metadata, f.default
    if isinstance(default, (tuple, bool)):
        raise ParamError(source, [Problem(key, spec, "this key cannot be searched (a list or a switch)")])
    if ":" in spec and not isinstance(default, str):
        lo_s, _, hi_s = spec.partition(":")
        try:
            lo, hi = float(lo_s), float(hi_s)
        except ValueError:
            raise ParamError(source, [Problem(key, spec, "expected LO:HI, two numbers")]) from None
        s_lo, s_hi = meta.get("lo"), meta.get("hi")
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ParamError(source, [Problem(key, spec, "expected LO:HI with LO < HI, both finite")])
        if (s_lo is not None and lo < s_lo) or (s_hi is not None and hi > s_hi) or meta.get("choices"):
            allowed = f"one of {meta['choices']}" if meta.get("choices") else f"within [{s_lo:g}, {s_hi:g}]"
            raise ParamError(source, [Problem(key, spec, f"the range must lie {allowed} (the schema's)")])
        if isinstance(default, int):
            raise ParamError(source, [Problem(key, spec, "an integer key: give its values as A,B,C")])
        return Vary(key, lo, hi)
    items = [s.strip() for s in spec.split(",") if s.strip()]
    if not items:
        raise ParamError(source, [Problem(key, spec, "expected LO:HI or a list A,B,C")])
    vals, bad = [], []
    for s in items:
        if isinstance(default, str):
            v = s
        else:
            try:
                v = int(s) if isinstance(default, int) else float(s)
            except ValueError:
                bad.append(s)
                continue
        ch = meta.get("choices")
        ok = (v in ch) if ch else (meta.get("lo") is None or meta["lo"] <= v) and (meta.get("hi") is None
                                                                                 or v <= meta["hi"])
        (vals if ok else bad).append(v)
    if bad:
        allowed = (f"one of {', '.join(map(str, meta['choices']))}" if meta.get("choices")
                   else f"numbers within [{meta.get('lo')}, {meta.get('hi')}]")
        raise ParamError(source, [Problem(key, ", ".join(map(str, bad)), f"expected {allowed}")])
    if key == "cable.model":
        short = [v for v in vals if v != CUSTOM and cable_spec(v).missing()]
        if short:
            raise ParamError(source, [Problem(key, ", ".join(short), "these entries hold only the fibre maker's "
                                              "figures, not the cable's strength and modulus: search the cable's "
                                              "own numbers instead (cable.breaking_strength_n=..., ...)")])
    return Vary(key, choices=tuple(dict.fromkeys(vals)))


@dataclass(frozen=True)
class Change:
    key: str
    before: object
    after: object
    buys: tuple            # rules that fail when this change alone is undone


@dataclass(frozen=True)
class FrontPoint:
    """A design on the Pareto front: its changes from the searched design, its figures and the rule that binds."""
    changes: tuple                 # ((key, value), ...) of the varied keys it changes
    speed_m_s: float               # predicted swimming speed (follows the frequency at the design's stride)
    mass_kg: float                 # the bought mass the search can change: motors + components (battery scaled)
    power_w: float                 # electrical draw at the design gait (the run-time rule's)
    binding: str                   # the passing rule with the least margin
    margin: float                  # its margin
    limits_speed: tuple = ()       # the rules that fail when its tail beats SPEED_PROBE faster (what stops it)


@dataclass(frozen=True)
class Front:
    """The Pareto front over speed (up), mass and electrical power (down) of the passing designs sampled."""
    points: tuple                  # FrontPoint, fastest first
    sampled: int                   # designs sampled over the varied keys' ranges
    passing: int                   # of those, passing every kernel-free rule
    refused: int                   # front candidates the loader's layout checks refused (and replaced)
    notes: tuple = ()
    size: int = 0                  # non-dominated designs found (points keeps at most FRONT_KEPT of them)

    def binding_counts(self) -> dict:
        """{rule id: how many front points it binds}, most first."""
        out: dict = {}
        for q in self.points:
            out[q.binding] = out.get(q.binding, 0) + 1
        return dict(sorted(out.items(), key=lambda kv: -kv[1]))


@dataclass(frozen=True)
class SolveResult:
    base_failing: tuple            # rule ids the design fails
    passes: bool                   # a design passing every kernel-free rule was found
    design: Params                 # that design (or the closest found)
    changes: tuple                 # Change, one per changed key
    failing: tuple                 # rule ids the result still fails (empty when it passes)
    binding: tuple                 # (rule id, margin) of the result's smallest margins among the rules it passes
    evaluated: int                 # designs evaluated
    varies: tuple = field(default=())
    notes: tuple = field(default=())   # the assumptions the changes brought in (speed, motor current, curve)
    front: Front | None = None         # the Pareto front over speed, mass and power (solve(front_samples=...))

    @property
    def keys_changed(self) -> int:
        return len(self.changes)


# ----------------------------------------------------------------------------------------------- columns
def _base_values(base: Params, varies) -> dict:
    return {v.key: get_key(base, v.key) for v in varies}


def _columns(base: Params, varies, rows: list[dict]) -> dict:
    """Design columns for ``rows`` (each a {key: value} of the varied keys), the catalogue entries expanded and the
    speed following the frequency at constant stride."""
    n = len(rows)
    cols: dict = {}
    f0, u0 = base.swimming.tail_beat_frequency_hz, base.swimming.speed_m_s
    i0, tau0, curve0 = base.motor.phase_current_a, base.motor.holding_torque_nm, base.motor.pullout_curve_torque_nm
    speed_free = not any(v.key == "swimming.speed_m_s" for v in varies)
    for i, row in enumerate(rows):
        expanded = dict(row)
        if row.get("cable.model", CUSTOM) != CUSTOM:
            expanded.update(_CATALOGUE["cable.model"](row["cable.model"]))
        tau_ref, i_ref, curve_ref = tau0, i0, curve0
        if row.get("motor.model", CUSTOM) != CUSTOM:
            expanded.update(_CATALOGUE["motor.model"](row["motor.model"]))
            tau_ref = expanded.get("motor.holding_torque_nm", tau0)
            i_ref = expanded.get("motor.phase_current_a", i0)
            # no catalogue entry carries a pull-out curve (it depends on the driver and supply): the design's
            # curve, scaled by the two holding torques (same shape), stands in for the named motor's
            curve_ref = tuple(t * tau_ref / tau0 for t in curve0)
            expanded["motor.pullout_curve_torque_nm"] = curve_ref
        if "motor.phase_current_a" in row:     # the torque numbers are the motor's at i_ref
            k_i = min(row["motor.phase_current_a"] / i_ref, 1.0)
            expanded["motor.phase_current_a"] = row["motor.phase_current_a"]
            expanded["motor.holding_torque_nm"] = tau_ref * k_i
            expanded["motor.pullout_curve_torque_nm"] = tuple(t * k_i for t in curve_ref)
        if speed_free and "swimming.tail_beat_frequency_hz" in row:
            expanded["swimming.speed_m_s"] = u0 * row["swimming.tail_beat_frequency_hz"] / f0
        for k, v in expanded.items():
            col = cols.get(k)
            if col is None:
                col = cols[k] = [get_key(base, k)] * n
            col[i] = v
    return {k: np.array(v, dtype=object if any(isinstance(x, str) for x in v) else float) for k, v in cols.items()}
    # (a list key, the pull-out curve, becomes an (N, K) float array: every row has the design's K points)


def _params_of(base: Params, varies, row: dict) -> Params:
    """The design of one row, through the loader (schema, cross-field checks): what the written file will read."""
    cols = _columns(base, varies, [row])
    raw = to_dict(base)
    for k, v in cols.items():
        sec, _, name = k.partition(".")
        val = v[0]
        raw[sec][name] = val.tolist() if isinstance(val, (np.ndarray, np.generic)) else val
    energy = raw["power"]["battery_energy_wh"]
    if energy != base.power.battery_energy_wh:
        raw["components"] = [_scaled_battery(c, energy / base.power.battery_energy_wh, base.power.battery_energy_wh)
                             if c["name"] == "battery" else c for c in raw["components"]]
    model = raw["motor"].get("model", CUSTOM)
    if model != CUSTOM and any(not math.isclose(raw["motor"][k], v, rel_tol=1e-9)
                               for k, v in motor_params(model).items()):
        raw["motor"]["model"] = CUSTOM      # the entry's numbers at another current: the design's own numbers
    return params_from_dict(raw, "<solve>")


def _scaled_battery(comp: dict, ratio: float, energy_wh: float) -> dict:
    """The battery component of a design whose energy the search changed by ``ratio``: more or fewer of the same
    cells, so its mass in proportion (what ``bought_mass_kg`` predicts) and its box by the cube root (the same
    shape). Its source says so."""
    k = ratio ** (1.0 / 3.0)
    size = [round(v * k, 3) for v in comp["size_mm"]]
    top = comp["z_mm"] + comp["size_mm"][2] / 2          # its top stays: the motors sit above it
    return {**comp, "mass_kg": round(comp["mass_kg"] * ratio, 6), "size_mm": size,
            "z_mm": round(top - size[2] / 2, 3),
            "source": f"{comp['source']}; scaled by swiftfin solve from {energy_wh:g} Wh: mass x {ratio:.4g} "
                      f"(same cells, same specific energy), box x {k:.4g}, its top where it was"}


def battery_fits(p: Params) -> bool:
    """Whether the design's battery box, every corner, lies inside the hull's inner surface by the assembly
    clearance (``layout.geometry.inner_envelope_excess_mm``, the build's own test of it), with room for its cradle
    under it (``layout.cradle_plan.cradles``): a battery the search grew must still go in. No battery: True."""
    from swiftfin.core.errors import UserError
    from swiftfin.layout.cradle_plan import cradles
    try:
        cradles(p)
    except UserError:
        return False
    for c in p.components:
        if c.name != "battery":
            continue
        sx, sy, sz = c.size_mm
        x = -c.station_fraction * p.body.length_mm
        corners = np.array([(x + i * sx / 2, j * sy / 2, c.z_mm + k * sz / 2)
                            for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
        if (inner_envelope_excess_mm(p, corners) > -p.print.clearance_assembly_mm).any():
            return False
    return True


# ----------------------------------------------------------------------------------------------- scoring
def _scores(res) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(passes, number of failing rules, summed shortfall) per design; shortfall: log(1 + |margin|) of each
    failing rule (a rule 849x past its limit counts more than one 4 % short, but not 800 times more)."""
    fail = res.severity == int(Severity.FAIL)
    nfail = fail.sum(axis=1) + res.error * len(RULE_IDS)
    short = np.where(fail, np.log1p(np.abs(np.nan_to_num(res.margin, nan=1.0))), 0.0).sum(axis=1)
    return (nfail == 0), nfail, short


def _distance(varies, base_vals: dict, rows: list[dict]) -> np.ndarray:
    out = np.zeros(len(rows))
    for v in varies:
        b = base_vals[v.key]
        for i, r in enumerate(rows):
            if v.key in r:
                out[i] += (r[v.key] != b) if v.categorical else abs(r[v.key] - b) / (v.hi - v.lo)
    return out


def _sample(varies_subset, m: int, rng_seed: int) -> list[dict]:
    from scipy.stats import qmc
    d = len(varies_subset)
    u = qmc.Sobol(d, scramble=True, seed=rng_seed).random(m)
    rows = []
    for s in u:
        row = {}
        for v, x in zip(varies_subset, s):
            if v.categorical:
                row[v.key] = v.choices[min(int(x * len(v.choices)), len(v.choices) - 1)]
            else:
                row[v.key] = v.lo + x * (v.hi - v.lo)
        rows.append(row)
    return rows


def _layout_ok(base: Params, varies, row: dict) -> bool:
    from swiftfin.layout.design import check_design
    try:
        p = _params_of(base, varies, row)
        check_design(p, "<solve>")
    except (ParamError, UserError):
        return False
    return p.power.battery_energy_wh == base.power.battery_energy_wh or battery_fits(p)


class _NoBar:
    """What a progress bar does where nobody asked for one: nothing (``solve``'s ``bar`` is optional)."""

    def __init__(self, total: int = 0, desc: str = "", unit: str = ""):
        self.total, self.n = total, 0

    def update(self, k: int = 1) -> None:
        self.n += k

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None


# ----------------------------------------------------------------------------------------------- search
def solve(base: Params, varies, samples_per_key: int = SAMPLES_PER_KEY, exhaustive_up_to: int = 2, seed: int = 0,
          progress=None, front_samples: int = FRONT_SAMPLES, bar=None) -> SolveResult:
    """The nearest design to ``base`` that passes every kernel-free rule, changing only the keys of ``varies``
    (see the module's docstring), and the Pareto front over speed, mass and power of the passing designs among
    ``front_samples`` sampled over all the varied keys (:func:`pareto_front`; 0: none). ``progress(text)`` is
    called as the search goes; ``bar(total, desc, unit)``, if given, makes a progress bar for the front's rounds
    (``swiftfin.progress.bar``: this layer draws nothing itself)."""
    res = _nearest(base, varies, samples_per_key, exhaustive_up_to, seed, progress)
    if front_samples:
        extra = [{c.key: c.after for c in res.changes}] if res.passes else []
        res = replace(res, front=pareto_front(base, res.varies, front_samples, seed, extra, progress, bar))
    return res


def _nearest(base: Params, varies, samples_per_key: int, exhaustive_up_to: int, seed: int,
             progress) -> SolveResult:
    varies = tuple(varies)
    if not varies:
        raise ParamError("--vary", [Problem("--vary", "(none)", "expected at least one key to search")])
    keys = [v.key for v in varies]
    dup = {k for k in keys if keys.count(k) > 1}
    if dup:
        raise ParamError("--vary", [Problem(k, "given twice", "search each key once") for k in sorted(dup)])
    say = progress or (lambda text: None)
    base_vals = _base_values(base, varies)
    base_res = evaluate(DesignArrays.from_columns(1, {}, base))
    base_failing = tuple(r for r, s in zip(RULE_IDS, base_res.severity[0]) if s == int(Severity.FAIL))
    counter = [1]
    best_fail = None     # (nfail, shortfall, distance, row) of the closest loader-valid design that fails
    stages = [list(itertools.combinations(varies, k)) for k in range(1, min(exhaustive_up_to, len(varies)) + 1)]
    for n_stage, subsets in enumerate(stages):
        rows: list[dict] = []
        for j, subset in enumerate(subsets):
            m = 2 ** math.ceil(math.log2(samples_per_key * len(subset) * (4 if len(subset) > 2 else 1)))
            rows += _sample(subset, m, seed * 1000 + n_stage * 100 + j)
        res = evaluate(DesignArrays.from_columns(len(rows), _columns(base, varies, rows), base))
        counter[0] += len(rows)
        ok, nfail, short = _scores(res)
        dist = _distance(varies, base_vals, rows)
        say(f"{len(subsets[0])} of {len(varies)} keys changed: {len(rows)} designs, {int(ok.sum())} pass the rules")
        order = np.lexsort((dist, short, nfail))
        for i0 in order[:MAX_LAYOUT_CHECKS]:
            i0 = int(i0)
            if _layout_ok(base, varies, rows[i0]):      # the closest design the loader also accepts
                cand = (int(nfail[i0]), float(short[i0]), float(dist[i0]), rows[i0])
                if best_fail is None or cand[:3] < best_fail[:3]:
                    best_fail = cand
                break
        passing = [rows[int(i)] for i in np.argsort(dist) if ok[i]]
        valid = [r for r in passing[:MAX_LAYOUT_CHECKS] if _layout_ok(base, varies, r)]
        if not valid:
            continue
        row = _refine(base, varies, base_vals, valid[0], counter)
        say(f"nearest passing design: {len(row)} key(s) changed")
        return _result(base, varies, base_vals, base_failing, row, counter[0])
    if best_fail is not None and len(varies) > exhaustive_up_to:
        # more keys: from the closest design so far, set one key or two at a time (a key already changed may be
        # re-tuned), each step the one that brings it nearest to passing (fewest failing rules, then the smallest
        # shortfall), until it passes or no step helps
        row, score = dict(best_fail[3]), best_fail[:2]
        while True:
            step = _forward_step(base, varies, base_vals, row, max(16, samples_per_key // 4), seed, counter)
            if step is None or step[1] >= score:
                break
            row, score = step
            say(f"{len(_changed(base_vals, row))} keys changed: {score[0]} rule(s) still fail")
            if score[0] == 0:
                row = _refine(base, varies, base_vals, _thin(base, varies, base_vals, row, counter), counter)
                say(f"nearest passing design: {len(row)} key(s) changed")
                return _result(base, varies, base_vals, base_failing, row, counter[0])
        if score < best_fail[:2]:
            best_fail = (*score, _distance(varies, base_vals, [row])[0], row)
    if len(varies) > exhaustive_up_to:
        # more keys at once: differential evolution over every varied key (vectorised: a whole population per
        # call), minimising the rules' shortfall first and the change second; its passing designs are then
        # thinned to their fewest changes and pulled back to the nearest
        say(f"all {len(varies)} keys: differential evolution")
        found, closest = _evolve(base, varies, base_vals, seed, counter, x0=best_fail[3] if best_fail else None)
        if closest is not None and _layout_ok(base, varies, closest[3]) and (
                best_fail is None or closest[:2] < best_fail[:2]):
            best_fail = closest
        valid = [r for r in found if _layout_ok(base, varies, r)]
        if valid:
            thinned = [_thin(base, varies, base_vals, r, counter) for r in valid[:THIN_CANDIDATES]]
            thinned.sort(key=lambda r: (len(r), _distance(varies, base_vals, [r])[0]))
            row = _refine(base, varies, base_vals, thinned[0], counter)
            say(f"nearest passing design: {len(row)} key(s) changed")
            return _result(base, varies, base_vals, base_failing, row, counter[0])
    if best_fail is None:
        raise UserError("solve: none of the searched designs is one the loader accepts (every one breaks a "
                        "cross-field or layout check): widen or move the --vary ranges")
    return _result(base, varies, base_vals, base_failing, best_fail[3], counter[0])


def _forward_step(base: Params, varies, base_vals: dict, row: dict, samples: int, seed: int, counter: list):
    """The best design that sets one key of ``varies``, or two at once, on top of ``row``: (row, (failing rules,
    shortfall)), or None when the loader accepts none of the best ``MAX_LAYOUT_CHECKS``."""
    rows = []
    for j, v in enumerate(varies):
        rows += [dict(row, **val) for val in _sample((v,), samples, seed * 1000 + 900 + j)]
    for j, pair in enumerate(itertools.combinations(varies, 2)):
        rows += [dict(row, **val) for val in _sample(pair, samples, seed * 1000 + 950 + j)]
    res = evaluate(DesignArrays.from_columns(len(rows), _columns(base, varies, rows), base))
    counter[0] += len(rows)
    _, nfail, short = _scores(res)
    dist = _distance(varies, base_vals, rows)
    for i in np.lexsort((dist, short, nfail))[:MAX_LAYOUT_CHECKS]:
        if _layout_ok(base, varies, rows[int(i)]):
            return rows[int(i)], (int(nfail[i]), float(short[i]))
    return None


def _evolve(base: Params, varies, base_vals: dict, seed: int, counter: list, x0: dict | None = None):
    """(passing designs, nearest first; the closest design that fails) of a differential evolution over all of
    ``varies`` (choices as integer genes). Objective: 1000 x the summed shortfall of the failing rules + the
    distance to the design + ``LAYOUT_PENALTY`` where the loader refuses it (checked where at most
    ``LAYOUT_PENALTY_FAILS`` rules fail)."""
    from scipy.optimize import differential_evolution

    def rows_of(x):
        rows = []
        for gene in np.atleast_2d(x):
            row = {}
            for v, g in zip(varies, gene):
                row[v.key] = v.choices[min(int(round(g)), len(v.choices) - 1)] if v.categorical else float(g)
            rows.append(row)
        return rows

    passing: dict = {}
    closest = [(math.inf, math.inf), None]   # the closest design the loader accepts: (nfail, shortfall, distance, row)

    def objective(x):           # x: (S, N) as scipy's vectorised mode passes it
        rows = rows_of(np.asarray(x).T)
        res = evaluate(DesignArrays.from_columns(len(rows), _columns(base, varies, rows), base))
        counter[0] += len(rows)
        ok, nfail, short = _scores(res)
        dist = _distance(varies, base_vals, rows)
        cost = 1000.0 * short + dist
        near = np.nonzero(nfail <= LAYOUT_PENALTY_FAILS)[0]       # the loader's layout checks cost ~3 ms a design:
        near = near[np.argsort(cost[near])][:LAYOUT_CHECKS_PER_GENERATION]   # only the best nearly-passing ones
        for i in near:
            if not _layout_ok(base, varies, rows[i]):
                cost[i] += LAYOUT_PENALTY
                ok[i] = False
            elif (nfail[i], short[i]) < closest[0]:
                closest[:] = [(int(nfail[i]), float(short[i])), (int(nfail[i]), float(short[i]), float(dist[i]),
                                                                   rows[i])]
        for i in near:
            if ok[i]:
                passing[tuple(sorted((k, str(v)) for k, v in rows[i].items()))] = (dist[i], rows[i])
        return cost

    bounds = [(0, len(v.choices) - 1) if v.categorical else (v.lo, v.hi) for v in varies]
    start = None
    if x0 is not None:          # the closest design so far joins the first generation
        start = []
        for v in varies:
            val = x0.get(v.key, base_vals[v.key])
            if v.categorical:
                start.append(v.choices.index(val) if val in v.choices else 0)
            else:
                start.append(min(max(val, v.lo), v.hi))
    differential_evolution(objective, bounds, integrality=[v.categorical for v in varies], vectorized=True,
                           updating="deferred", popsize=EVOLVE_POPULATION, maxiter=EVOLVE_GENERATIONS, tol=0.0,
                           polish=False, seed=seed, x0=start,
                           callback=lambda *a, **k: len(passing) >= THIN_CANDIDATES)   # enough to thin: stop
    return [r for _, r in sorted(passing.values(), key=lambda t: t[0])], closest[1]


def _changed(base_vals: dict, row: dict) -> dict:
    return {k: v for k, v in row.items()
            if (v != base_vals[k] if isinstance(v, str) else not math.isclose(v, base_vals[k], rel_tol=1e-12))}


def _thin(base: Params, varies, base_vals: dict, row: dict, counter: list) -> dict:
    """Greedily undo changes of a passing design (the one whose undoing leaves the smallest total change first)
    while it keeps passing: fewer keys changed. Returns the changed keys only."""
    row = _changed(base_vals, row)
    while len(row) > 1:
        trials = [{kk: vv for kk, vv in row.items() if kk != k} for k in row]
        ok = _passes(base, varies, trials)
        counter[0] += len(trials)
        good = [t for t, o in zip(trials, ok) if o and _layout_ok(base, varies, t)]
        if not good:
            break
        row = min(good, key=lambda t: _distance(varies, base_vals, [t])[0])
    return row


def _passes(base: Params, varies, rows: list[dict]) -> np.ndarray:
    res = evaluate(DesignArrays.from_columns(len(rows), _columns(base, varies, rows), base))
    return _scores(res)[0]


def _refine(base: Params, varies, base_vals: dict, row: dict, counter: list) -> dict:
    """Pull each continuous change back toward the design's value while the design keeps passing (bisection), the
    largest change (as a fraction of its range) first: it gets the room the smaller ones leave."""
    row = _changed(base_vals, row)
    todo = [v for v in varies if not v.categorical and v.key in row]
    todo.sort(key=lambda v: -abs(row[v.key] - base_vals[v.key]) / (v.hi - v.lo))
    for v in todo:
        b, target = base_vals[v.key], row[v.key]
        lo, hi = 0.0, 1.0          # fraction of the change kept: hi passes
        for _ in range(REFINE_STEPS):
            mid = (lo + hi) / 2
            trial = dict(row, **{v.key: b + mid * (target - b)})
            counter[0] += 1
            if _passes(base, varies, [trial])[0] and _layout_ok(base, varies, trial):
                hi = mid
            else:
                lo = mid
        row[v.key] = b + hi * (target - b)
    return row


def _result(base: Params, varies, base_vals: dict, base_failing: tuple, row: dict, evaluated: int) -> SolveResult:
    changed = _changed(base_vals, row)
    design = _params_of(base, varies, changed)
    res = evaluate([design])
    sev, margin = res.severity[0], res.margin[0]
    failing = tuple(r for r, s in zip(RULE_IDS, sev) if s == int(Severity.FAIL)) + (("(error)",) if res.error[0]
                                                                                     else ())
    passed = [(r, float(m)) for r, s, m in zip(RULE_IDS, sev, margin) if s == int(Severity.PASS) and not math.isnan(m)]
    binding = tuple(sorted(passed, key=lambda t: t[1])[:3])
    changes = []
    for k, after in changed.items():
        undone = {kk: vv for kk, vv in changed.items() if kk != k}
        r = evaluate([_params_of(base, varies, undone)])
        buys = tuple(rid for rid, s in zip(RULE_IDS, r.severity[0]) if s == int(Severity.FAIL) and rid not in failing)
        changes.append(Change(k, base_vals[k], after, buys))
    notes = []
    if "swimming.tail_beat_frequency_hz" in changed and not any(v.key == "swimming.speed_m_s" for v in varies):
        notes.append(f"swimming.speed_m_s follows the frequency at the design's stride "
                     f"({base.swimming.speed_m_s / base.swimming.tail_beat_frequency_hz:.3g} m per beat): "
                     f"{design.swimming.speed_m_s:.3g} m/s")
    if changed.get("motor.model", CUSTOM) != CUSTOM:
        notes.append(f"motor {changed['motor.model']}: no catalogue pull-out curve; the design's, scaled by the "
                     f"holding torques, stands in for it (measure yours)")
    if "motor.phase_current_a" in changed:
        notes.append(f"motor.phase_current_a {design.motor.phase_current_a:.3g} A: holding torque and pull-out "
                     f"curve scaled with the current to {design.motor.holding_torque_nm:.3g} N m")
    return SolveResult(base_failing, not failing, design, tuple(changes), failing, binding, evaluated, tuple(varies),
                       tuple(notes))


# ----------------------------------------------------------------------------------------------- Pareto front


def pareto_mask(objectives: np.ndarray) -> np.ndarray:
    """Which rows of ``objectives`` (N, K), every column to be minimised, no other row dominates (another row is no
    worse in every column and better in one). Rows with a NaN are never on the front. Sorted sweep: a row can only be
    dominated by rows before it in lexicographic order, and then by one on the front so far."""
    obj = np.asarray(objectives, float)
    n = len(obj)
    keep = np.zeros(n, bool)
    ok = ~np.isnan(obj).any(axis=1)
    idx = np.nonzero(ok)[0]
    order = idx[np.lexsort(obj[idx].T[::-1])]
    front: list[int] = []
    for i in order:
        if front:
            f = obj[front]
            if np.any(np.all(f <= obj[i], axis=1) & np.any(f < obj[i], axis=1)):
                continue
            if np.any(np.all(f == obj[i], axis=1)):     # a duplicate of a front row: one of them is enough
                continue
        front.append(int(i))
        keep[i] = True
    return keep


def bought_mass_kg(base: Params, cols: dict, n: int) -> np.ndarray:
    """The mass the searched keys change, per design [kg]: the motors (a catalogue motor's own mass) and every
    component of the design, the battery scaled with its energy at the design's own specific energy (the same
    kind of cell, more or fewer of them). The printed parts are left out: the material changes them by its density,
    the rest of the search not at all; the build's mass properties give the whole."""
    motors = np.broadcast_to(np.asarray(cols.get("motor.mass_kg", base.motor.mass_kg), float), (n,))
    energy = np.broadcast_to(np.asarray(cols.get("power.battery_energy_wh", base.power.battery_energy_wh), float),
                             (n,))
    total = motors * base.joints.count
    for c in base.components:
        if c.name == "battery":
            total = total + c.mass_kg * energy / base.power.battery_energy_wh
        else:
            total = total + c.mass_kg
    return np.asarray(total, float)


def _binding(res, i: int) -> tuple[str, float]:
    """The passing rule with the least margin of design ``i``."""
    m = np.where(res.severity[i] == int(Severity.PASS), res.margin[i], np.inf)
    m = np.where(np.isnan(m), np.inf, m)
    j = int(np.argmin(m))
    return RULE_IDS[j], float(m[j])


def _perturb(varies, base_vals: dict, seeds: list[dict], m: int, scale: float, rng) -> list[dict]:
    """``m`` designs near each seed: every continuous key moved by a normal step of ``scale`` x its range (kept in
    the range), every choice redrawn with probability ``scale``."""
    out = []
    for seed_row in seeds:
        for _ in range(m):
            row = {}
            for v in varies:
                val = seed_row.get(v.key, base_vals[v.key])
                if v.categorical:
                    row[v.key] = v.choices[rng.integers(len(v.choices))] if rng.random() < scale else val
                else:
                    row[v.key] = float(min(max(val + rng.normal(0.0, scale * (v.hi - v.lo)), v.lo), v.hi))
            out.append(row)
    return out


def pareto_front(base: Params, varies, samples: int = FRONT_SAMPLES, seed: int = 0, extra_rows=(),
                 progress=None, bar=None) -> Front:
    """The Pareto front over predicted speed (up), bought mass and electrical power (down) of designs passing every
    kernel-free rule. The passing region of a failing design is often a sliver of the searched box (the paper's fish:
    none of 16 384 Sobol designs over its 11 keys passes), so the front is grown from the passing designs found:
    ``samples`` Sobol designs over every varied key plus ``extra_rows`` (the nearest passing design), then
    :data:`FRONT_ROUNDS` rounds of ``samples`` designs scattered round the front so far, each round closer
    (a multi-objective evolution with :data:`FRONT_SEEDS` designs spread along the front as its parents). The
    result keeps :data:`FRONT_KEPT` designs spread along the front, each one the loader's layout checks accept (a
    refused one is dropped and the front taken again without it)."""
    say = progress or (lambda text: None)
    varies = tuple(varies)
    base_vals = _base_values(base, varies)
    rng = np.random.default_rng(seed)
    pool_rows: list[dict] = []
    pool_obj: list = []
    pool_bind: list = []
    sampled = 0

    def add(rows):
        nonlocal sampled
        cols = _columns(base, varies, rows)
        res = evaluate(DesignArrays.from_columns(len(rows), cols, base))
        sampled += len(rows)
        ok, _, _ = _scores(res)
        speed = np.broadcast_to(np.asarray(cols.get("swimming.speed_m_s", base.swimming.speed_m_s), float),
                                (len(rows),))
        mass = bought_mass_kg(base, cols, len(rows))
        for i in np.nonzero(ok & np.isfinite(res.power_w))[0]:
            pool_rows.append(rows[int(i)])
            pool_obj.append((-float(speed[i]), float(mass[i]), float(res.power_w[i])))
            pool_bind.append(_binding(res, int(i)))

    checked: dict[int, bool] = {}
    refused = 0

    def front_indices(keep: int) -> tuple[np.ndarray, int]:
        """At most ``keep`` designs of the pool's front, spread evenly from the fastest to the slowest, every one
        accepted by the loader (a refused one leaves the pool and the front is taken again); and the front's
        size."""
        nonlocal refused
        while True:
            obj = np.array(pool_obj, float).reshape(-1, 3)
            idx = np.nonzero(pareto_mask(obj))[0]
            idx = idx[np.argsort(obj[idx, 0], kind="stable")]
            if len(idx) > keep:
                idx = idx[np.unique(np.round(np.linspace(0, len(idx) - 1, keep)).astype(int))]
            bad = []
            for i in map(int, idx):
                if i not in checked:
                    checked[i] = _layout_ok(base, varies, pool_rows[i])
                if not checked[i]:
                    bad.append(i)
            if not bad:
                return idx, int(pareto_mask(obj).sum())
            refused += len(bad)
            for i in bad:
                pool_obj[i] = (math.nan, math.nan, math.nan)

    with (bar or _NoBar)(FRONT_ROUNDS + 2, "Pareto front", "round") as rounds:
        add(_sample(varies, samples, seed * 1000 + 777) + [dict(r) for r in extra_rows])
        rounds.update()
        for k in range(FRONT_ROUNDS):
            front = [pool_rows[int(i)] for i in front_indices(FRONT_SEEDS)[0]]
            if not front:
                break
            add(_perturb(varies, base_vals, front, max(1, samples // len(front)), FRONT_STEP * FRONT_SHRINK ** k,
                         rng))
            rounds.update()
        idx, size = front_indices(FRONT_KEPT)
        rounds.update(rounds.total - rounds.n)
    say(f"Pareto front: {sampled} designs sampled, {len(pool_rows)} pass the rules, {size} on the front")
    limits = _speed_limits(base, varies, [pool_rows[int(i)] for i in idx])
    pts = [FrontPoint(tuple(sorted(_changed(base_vals, pool_rows[int(i)]).items())), -pool_obj[int(i)][0],
                      pool_obj[int(i)][1], pool_obj[int(i)][2], *pool_bind[int(i)], lim)
           for i, lim in zip(idx, limits)]
    pts.sort(key=lambda q: (-q.speed_m_s, q.mass_kg, q.power_w))
    battery = next((c.mass_kg for c in base.components if c.name == "battery" and c.mass_kg > 0), None)
    notes = ("mass: the motors and the components only" + (
             f" (the battery scaled with its energy at the design's {base.power.battery_energy_wh / battery:.0f} "
             "Wh/kg)" if battery else "") + "; the printed parts are left out (the build's mass properties give them)",
             "power: the electrical draw at the design gait (the run-time rule's: losses, electronics and the "
             "power delivered to the joints)")
    return Front(tuple(pts), sampled, len(pool_rows), refused, notes, size)


def _speed_limits(base: Params, varies, rows: list[dict]) -> list[tuple]:
    """For each design, the rules that fail when its tail beats :data:`SPEED_PROBE` faster (the speed following, as
    in the search): what stops it from moving up the front."""
    if not rows:
        return []
    f0 = base.swimming.tail_beat_frequency_hz
    faster = [dict(r, **{"swimming.tail_beat_frequency_hz": r.get("swimming.tail_beat_frequency_hz", f0)
                         * (1 + SPEED_PROBE)}) for r in rows]
    if any(v.key == "swimming.speed_m_s" for v in varies):
        u0 = base.swimming.speed_m_s
        for r in faster:
            r["swimming.speed_m_s"] = r.get("swimming.speed_m_s", u0) * (1 + SPEED_PROBE)
    res = evaluate(DesignArrays.from_columns(len(faster), _columns(base, varies, faster), base))
    return [tuple(rid for rid, sv in zip(RULE_IDS, res.severity[i]) if sv == int(Severity.FAIL))
            for i in range(len(faster))]


def front_spread(front: Front, k: int = FRONT_SHOWN) -> list:
    """At most ``k`` front points spread evenly from the fastest to the slowest (all of them when there are fewer)."""
    pts = list(front.points)
    if len(pts) <= k:
        return pts
    return [pts[int(round(i))] for i in np.linspace(0, len(pts) - 1, k)]
