"""Kernel-free design rules, designs per second: one design at a time (``run_rules``, what ``swiftfin check`` does)
against all at once (``design_rules.vectorised.evaluate``), on the same seeded designs in one run (house style rule
14: the ratio is what counts; absolute rates drift with the machine's load). Target (issue 16): >= 10 000 designs/s
on one core for the vectorised rules.

    .venv/bin/python bench/bench_rules.py [--designs 200] [--copies 50] [--per-design 20] [--runs 3]

Rates are per CPU second of this process (``time.process_time``), best of ``--runs``; the wall-clock rate is shown
beside. BLAS threads are held to one (the vectorised rules use none of it, but numpy is not asked twice).
"""
from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

TARGET = 10_000.0   # designs/s, issue 16


def timed(fn, runs: int) -> tuple[float, float]:
    """(best CPU seconds, best wall seconds) of ``runs`` calls."""
    cpu, wall = [], []
    for _ in range(runs):
        c0, w0 = time.process_time(), time.perf_counter()
        fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return min(cpu), min(wall)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=200, help="distinct seeded designs")
    ap.add_argument("--copies", type=int, default=50, help="the vectorised run takes the designs this many times")
    ap.add_argument("--per-design", type=int, default=20, help="designs run one at a time")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=16)
    args = ap.parse_args(argv)

    from swiftfin.design_rules.rules import RuleContext, run_rules
    from swiftfin.design_rules.vectorised import DesignArrays, evaluate, seeded_designs

    designs = seeded_designs(args.designs, args.seed)
    ok = []
    for p in designs:                      # the designs check evaluates (a fastener plan may refuse some)
        try:
            run_rules(RuleContext(p))
        except Exception:  # noqa: BLE001
            continue
        ok.append(p)
    one = ok[:args.per_design]
    batch = ok * args.copies
    arrays = DesignArrays.from_params(batch)
    evaluate(arrays.take(np.arange(min(len(batch), 512))))          # imports and first-call costs

    def per_design():
        for p in one:
            run_rules(RuleContext(p))

    rows = []
    cpu, wall = timed(per_design, 1)
    rows.append(("run_rules, one design at a time", len(one), cpu, wall))
    cpu, wall = timed(lambda: evaluate(arrays), args.runs)
    rows.append(("vectorised evaluate (struct of arrays)", len(batch), cpu, wall))
    cpu, wall = timed(lambda: evaluate(batch), args.runs)
    rows.append(("vectorised evaluate (from list of Params)", len(batch), cpu, wall))

    base = rows[0][1] / rows[0][2]
    print(f"{len(ok)} seeded designs (seed {args.seed}; {len(designs) - len(ok)} refused by the per-design run), "
          f"joints {sorted({p.joints.count for p in ok})}")
    print(f"{'method':44s} {'designs':>8s} {'cpu s':>8s} {'designs/s':>10s} {'wall /s':>9s} {'x run_rules':>12s}")
    for name, n, cpu, wall in rows:
        rate = n / cpu
        print(f"{name:44s} {n:8d} {cpu:8.3f} {rate:10.0f} {n / wall:9.0f} {rate / base:12.0f}")
    vec = rows[1][1] / rows[1][2]
    print(f"vectorised: {vec:.0f} designs/s, {vec / base:.0f} x the per-design run "
          f"(target >= {TARGET:.0f} designs/s: {'met' if vec >= TARGET else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
