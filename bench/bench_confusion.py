"""The joint fit on a bench simulator written apart from it (tests/mujoco_bench.py: MuJoCo, a stepper with its
periodic torque, one-sided cable springs, its own command program): a confusion matrix over seeds, sizes 0.2x to 5x,
pairs, controls and effects outside the engine's library (issue 14, item 3). Prints, per case, what the engine
named first and how sure it said it was, whether it flagged unexplained structure, and how visible the truth was
(rms of its effect on the reading over the sensor noise); then the issue's measures.

    .venv/bin/python bench/bench_confusion.py [--seeds 0 1 2] [--sizes 0.2 1 5] [--duration 40] [--only EFFECT ...]
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.mujoco_bench import BenchDesign, cases, run_case, score, visible  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--sizes", type=float, nargs="+", default=[0.2, 1.0, 5.0])
    ap.add_argument("--duration", type=float, default=40.0)
    ap.add_argument("--only", nargs="+", default=None, metavar="EFFECT",
                    help="run only the cases with one of these effects (the matrix then covers those alone)")
    args = ap.parse_args(argv)
    from swiftfin.layout.design import load_design
    design = str(ROOT / "swiftfin.toml")
    d = BenchDesign.from_params(load_design(design))
    results, times = [], []
    print(f"{'case':<40} {'visible':>8} {'slips':>5}  {'named (first, confidence)':<44} flagged")
    with tempfile.TemporaryDirectory() as tmp:
        todo = [c for c in cases(tuple(args.seeds), tuple(args.sizes))
                if args.only is None or set(c.truth) & set(args.only)]
        for i, case in enumerate(todo):
            folder = Path(tmp) / f"c{i}"
            folder.mkdir()
            t0 = time.perf_counter()
            r = run_case(d, case, folder, design, args.duration)
            times.append(time.perf_counter() - t0)
            r["visible"] = visible(d, case, args.duration)
            results.append(r)
            named = "refused: " + " ".join(r["refused"]) if r["refused"] else (
                ", ".join(r["named"]) + (f" ({r['confidence']})" if r["named"] else "") or "-")
            print(f"{case.label:<40} {r['visible']:8.1f} {r['slips']:5d}  {named[:44]:<44} "
                  f"{'yes' if r['flagged'] else 'no'}", flush=True)
    s = score(results)
    seen = [r for r in results if r["case"].kind == "single" and r["visible"] >= 1.0]
    from tests.mujoco_bench import LIBRARY_NAMES
    seen_ok = sum(r["first"] in LIBRARY_NAMES[r["case"].truth[0]] for r in seen)
    print()
    print(f"single library effects named first: {s['single_first']} / {s['single_n']} "
          f"({seen_ok} / {len(seen)} of those that move the reading by at least the noise)")
    per = Counter()
    tot = Counter()
    for r in results:
        if r["case"].kind == "single":
            tot[r["case"].truth[0]] += 1
            per[r["case"].truth[0]] += r["first"] in LIBRARY_NAMES[r["case"].truth[0]]
    for name in tot:
        print(f"  {name:<18} {per[name]} / {tot[name]}")
    print(f"controls with nothing named: {s['controls_clean']} / {s['controls_n']}")
    print(f"pairs with both named: {s['pairs_both']} / {s['pairs_n']}")
    print(f"out-of-library effects flagged: {s['outside_flagged']} / {s['outside_n']}")
    print(f"wrong names at high confidence: {len(s['wrong_high'])}")
    for label, name in s["wrong_high"]:
        print(f"  {label}: {name}")
    print(f"time per case (simulate + fit): {min(times):.1f}-{max(times):.1f} s, median "
          f"{sorted(times)[len(times) // 2]:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
