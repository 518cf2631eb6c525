"""``swiftfin sweep DESIGN... --out DIR``: many designs as Dask tasks, one table of their verdicts
(:mod:`swiftfin.sweep`).

Exit codes: 0 every design ran and passes every rule; 1 a design fails a rule, was refused or failed to build
(its row says which and why); 2 bad input (no designs, a duplicate name, an unwritable DIR).
"""
from __future__ import annotations

import time


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    ap.add_argument("designs", nargs="+", help="parameter files, or folders whose *.toml files are designs")
    ap.add_argument("--out", required=True, help="folder for results/, builds/ and results.csv (other files in it "
                                                 "are left alone)")
    ap.add_argument("--stage", choices=("check", "build"), default="build",
                    help="check: the kernel-free rules; build: a full build per design, then every rule with its "
                         "mass properties (default)")
    ap.add_argument("--workers", type=int, default=None, help="local Dask worker processes (default: one per core)")
    ap.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="an existing Dask scheduler (e.g. tcp://10.0.0.5:8786) instead of a local cluster")
    ap.add_argument("--cache-dir", default=None,
                    help="rebuild cache the builds share (default: $SWIFTFIN_CACHE_DIR or .cache/swiftfin/ here)")
    ap.set_defaults(func=run)


def run(args) -> int:
    from swiftfin.core.errors import UserError
    from swiftfin.outdir import check_output_dir
    from swiftfin.progress import say
    from swiftfin.sweep import collect_designs, sweep
    if args.workers is not None and args.workers < 1:
        raise UserError(f"--workers {args.workers}: expected 1 or more worker processes")
    items = collect_designs(args.designs)
    check_output_dir(args.out)
    t0 = time.perf_counter()
    rows, ran = sweep(items, args.out, stage=args.stage, scheduler=args.scheduler, workers=args.workers,
                      cache_dir=args.cache_dir, progress=say)
    print(f"{'design':28} {'status':8} {'verdict':14} {'fails':>5}  failing rules / message")
    for r in rows:
        what = r["failing"] if r["status"] == "ok" else str(r["message"]).splitlines()[0][:100]
        print(f"{r['design']:28} {r['status']:8} {str(r['verdict']):14} {str(r['n_fail']):>5}  {what}")
    bad = [r for r in rows if r["status"] != "ok" or r["n_fail"]]
    print(f"{len(rows)} designs ({ran} run now, {len(rows) - ran} done before) in {time.perf_counter() - t0:.1f} s; "
          f"{len(rows) - len(bad)} pass every rule; table: {args.out}/results.csv")
    return 1 if bad else 0
