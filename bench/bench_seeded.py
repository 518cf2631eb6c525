"""Drawing seeded designs (``design_rules.vectorised.seeded_designs``, what the identity tests, the sweeps and this
folder's other benchmarks draw from): with the check that skips the designer's sizing of a draw the loader refuses
whatever the sizes (``_refused_whatever_the_sizes``) against without it, on the same seeds in one run, in turn
(house style rule 14: the ratio is what counts). Both must keep the same designs; the script says if they do not.

    .venv/bin/python bench/bench_seeded.py [--designs 40] [--seed 16] [--runs 2]

Times are CPU seconds of this process (``time.process_time``), best of ``--runs``; each run draws afresh (the layout's
memos are keyed on the params, so a redraw misses them only where a new design is made: the first run warms nothing
the second can use but the imports).
"""
from __future__ import annotations

import argparse
import sys
import time


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=40)
    ap.add_argument("--seed", type=int, default=16)
    ap.add_argument("--runs", type=int, default=2)
    args = ap.parse_args(argv)

    import swiftfin.design_rules.vectorised as V
    from swiftfin.core.params import to_dict

    skip = V._refused_whatever_the_sizes
    sized = [0]
    size = V._sized_as_a_designer_would

    def counted(p):
        sized[0] += 1
        return size(p)

    V._sized_as_a_designer_would = counted
    best = {"with the skip": float("inf"), "without it": float("inf")}
    count, kept = {}, {}
    for _ in range(args.runs):
        for name, check in (("with the skip", skip), ("without it", lambda p: False)):
            V._refused_whatever_the_sizes = check
            sized[0] = 0
            c0 = time.process_time()
            designs = V.seeded_designs(args.designs, args.seed)
            best[name] = min(best[name], time.process_time() - c0)
            count[name], kept[name] = sized[0], [to_dict(p) for p in designs]
    V._refused_whatever_the_sizes, V._sized_as_a_designer_would = skip, size
    print(f"seeded_designs({args.designs}, seed={args.seed}), best of {args.runs} (CPU s)")
    for name in best:
        print(f"  {name:14s} {best[name]:8.2f} s   {count[name]:5d} draws sized")
    same = kept["with the skip"] == kept["without it"]
    print(f"ratio without / with: {best['without it'] / best['with the skip']:.2f}; the same designs kept: "
          f"{'yes' if same else 'NO'}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
