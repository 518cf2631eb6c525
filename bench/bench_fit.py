"""Benchmark of the calibration engine (issue 5, item 6). Run: ``.venv/bin/python bench/bench_fit.py [--quick]``.

1. Speed: the engine with the full ``joint`` library on a one-million-sample log (1000 s at 1 kHz, effects
   effective_radius + sensor_delay), timed: context (signals) and fit (selection on every k-th row, refit and
   uncertainties on all rows). Target: under 10 s on this machine.
2. Correct-effect rate, side by side with pysindy: the synthetic suite (every library effect alone at its default
   size, several seeds). pysindy's sparse regression (STLSQ, the SINDy optimiser) gets a custom library of the
   same terms: every linear column of every effect, and each nonlinear effect's column at three values of its
   nonlinear parameter spanning the realistic range (SINDy has no search over nonlinear parameters). The effect
   it names is the one whose surviving terms explain most of the residual. Several STLSQ thresholds are tried
   and the best is reported (favourable to pysindy). Both are timed per log (library building included).

Prints ratios measured in one run (house style rule 14); absolute times drift on a shared machine.
"""
from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from swiftfin.calibration.engine import Calibrator, _single_thread_blas  # noqa: E402
from swiftfin.calibration.bench import BARE_ARM  # noqa: E402
from swiftfin.calibration.joint import EQUIVALENT, FAMILY, joint_context  # noqa: E402
from swiftfin.calibration.synth import EFFECT_DEFAULTS, LIBRARY_EFFECTS, simulate_joint  # noqa: E402
from swiftfin.layout.design import load_design  # noqa: E402

SINDY_GRID = {
    "cable_compliance": ("stiffness_factor", (0.03, 0.1, 0.3)),
    "coulomb_friction": ("friction_torque_nm", (0.005, 0.02, 0.08)),
    "viscous_friction": ("damping_nm_s_rad", (0.005, 0.02, 0.08)),
    "quadratic_drag": ("drag_nm_s2_rad2", (0.001, 0.003, 0.01)),
    "added_mass": ("inertia_ratio", (17.0, 51.0, 170.0)),
    "backlash": ("gap_rad", (0.003, 0.01, 0.03)),
    "cable_slack": ("slack_rad", (0.0015, 0.005, 0.015)),
    "sensor_delay": ("delay_s", (0.003, 0.01, 0.03)),
    "lost_steps": ("slip_acceleration_rad_s2", (120.0, 150.0, 170.0)),
    "stepper_torque": ("torque_fraction", (0.003, 0.03, 0.3)),
}


def sindy_library(ctx):
    """Columns and the effect each belongs to."""
    cols, owner = [], []
    for eff in FAMILY.effects:
        if eff.nonlinear:
            pname, values = SINDY_GRID[eff.name]
            for v in values:
                X = eff.columns(ctx, {pname: v})
                cols.append(X)
                owner += [eff.name] * X.shape[1]
        else:
            X = eff.columns(ctx, {})
            cols.append(X)
            owner += [eff.name] * X.shape[1]
    return np.hstack(cols), owner


def sindy_name(ctx, thresholds, train):
    import pysindy as ps
    Z, owner = sindy_library(ctx)
    keep = np.linalg.norm(Z[train], axis=0) > 0          # e.g. a threshold no peak reaches: an empty column
    Z, owner = Z[:, keep], [o for o, k in zip(owner, keep) if k]
    r = (ctx.y - ctx.base)
    names = []
    for th in thresholds:
        opt = ps.STLSQ(threshold=th, normalize_columns=True, alpha=1e-6)
        with warnings.catch_warnings():   # "threshold eliminated all coefficients" is an answer here: none
            warnings.simplefilter("ignore", UserWarning)
            opt.fit(Z[train], r[train][:, None])
        coef = np.ravel(opt.coef_)
        share = {}
        for j, name in enumerate(owner):
            if coef[j] != 0:
                share[name] = share.get(name, 0.0) + float(np.sum((Z[train, j] * coef[j]) ** 2))
        names.append(max(share, key=share.get) if share else "none")
    return names


def correct(truth, named, indist=()):
    if named == truth:
        return True
    return any({truth, named} <= g for g in EQUIVALENT) and truth in indist


def speed(d, n=1_000_000):
    t0 = time.perf_counter()
    log = simulate_joint(d, {"effective_radius": 1.05, "sensor_delay": 0.010}, duration_s=n / 1000.0, seed=3)
    t1 = time.perf_counter()
    ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, "1M-sample log",
                        tension=log.cable_tension_n)
    t2 = time.perf_counter()
    cal = Calibrator(FAMILY).fit(ctx)
    t3 = time.perf_counter()
    print(f"1. one-million-sample log ({ctx.n} samples, full library of {len(FAMILY.effects)} effects)")
    print(f"   simulate {t1 - t0:.2f} s ({log.integrator}); context {t2 - t1:.2f} s; fit {t3 - t2:.2f} s "
          f"(selection on {cal.search_rows_} rows in windows); context + fit {t3 - t1:.2f} s (target < 10 s)")
    print(f"   found: {[fe.name for fe in cal.added_effects_]}; held-out RMSE {cal.baseline_['rmse_holdout']:.3g} -> "
          f"{cal.final_['rmse_holdout']:.3g} rad")
    for fe in cal.added_effects_:
        print(f"     {fe.name}: " + ", ".join(f"{k} = {v:.5g} +- {fe.stds[k]:.2g}" for k, v in fe.values.items()))
    return t3 - t1


def suite(d, seeds, thresholds):
    rows = []
    t_engine = t_sindy = 0.0
    for name in LIBRARY_EFFECTS:
        for seed in seeds:
            log = simulate_joint(d, {name: EFFECT_DEFAULTS[name][0]}, seed=100 + seed)
            # the bench log with its load cell (the engine uses it to tell friction from a dead band; pysindy's
            # library of terms cannot, and is counted correct on either twin)
            ctx = joint_context(log.t, log.motor_angle_rad, log.joint_angle_rad, d, tension=log.cable_tension_n)
            t0 = time.perf_counter()
            cal = Calibrator(FAMILY).fit(ctx)
            t1 = time.perf_counter()
            train = ~cal._holdout_mask(ctx)
            with _single_thread_blas():
                snames = sindy_name(ctx, thresholds, train)
            t2 = time.perf_counter()
            t_engine += t1 - t0
            t_sindy += t2 - t1
            first = cal.added_effects_[0] if cal.added_effects_ else None
            rows.append((name, seed, first.name if first else "none",
                         first.indistinguishable_from if first else [], snames))
    return rows, t_engine, t_sindy


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="one seed, 200k-sample speed log")
    args = ap.parse_args()
    d = BARE_ARM.design(load_design(ROOT / "swiftfin.toml"))     # the bare printed arm, as in earlier runs
    speed(d, 200_000 if args.quick else 1_000_000)
    seeds = [0] if args.quick else [0, 1, 2]
    thresholds = (0.02, 0.05, 0.1, 0.2, 0.5)
    rows, te, ts = suite(d, seeds, thresholds)
    n = len(rows)
    eng = sum(correct(t, e, ind) for t, _, e, ind, _ in rows)
    eng_exact = sum(t == e for t, _, e, _, _ in rows)
    sind = [sum(s[k] == t or any({t, s[k]} <= g for g in EQUIVALENT) for t, _, _, _, s in rows)
            for k in range(len(thresholds))]
    sind_exact = [sum(s[k] == t for t, _, _, _, s in rows) for k in range(len(thresholds))]
    kbest = int(np.argmax(sind))
    print(f"\n2. synthetic suite: {len(LIBRARY_EFFECTS)} effects x {len(seeds)} seeds = {n} logs of 40 000 samples")
    print(f"   {'truth':18s} {'seed':>4s}  {'engine (first named)':34s} pysindy STLSQ (threshold {thresholds[kbest]})")
    for t, s, e, ind, sn in rows:
        tag = f"{e}" + (f" ~{'/'.join(ind)}" if ind else "")
        print(f"   {t:18s} {s:4d}  {tag:34s} {sn[kbest]}")
    print("\n   correct-effect rate (twin counted when reported indistinguishable / for pysindy: always):")
    print(f"     engine : {eng}/{n} = {100 * eng / n:.0f} %  (exact name {eng_exact}/{n}); "
          f"{te / n:.2f} s per log")
    for k, th in enumerate(thresholds):
        print(f"     pysindy threshold {th:<5g}: {sind[k]}/{n} = {100 * sind[k] / n:.0f} % "
              f"(exact name {sind_exact[k]}/{n})")
    print(f"     pysindy: {ts / n / len(thresholds):.2f} s per log and threshold")
    print(f"   ratio of correct-effect rates engine / best pysindy: {eng / max(sind[kbest], 1):.2f}; "
          f"time ratio engine / pysindy (one threshold): {te / max(ts / len(thresholds), 1e-9):.1f}")


if __name__ == "__main__":
    main()
