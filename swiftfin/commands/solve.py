"""``swiftfin solve [PARAMS] [--vary KEY=RANGE ...] [--out FILE]``: the nearest design that passes every kernel-free
rule, changing only the keys searched (:mod:`swiftfin.design_rules.synthesis`), and the Pareto front over speed, mass
and electrical power of the passing designs, with the rule that binds along it (``--front-plot`` draws it).

With ``--build DIR`` the written design is then built (a Dask task, as ``swiftfin sweep --stage build``) and
checked with its mass properties, the floating rules included; ``--build-front K`` builds K front designs beside it.

Exit codes: 0 a passing design was found and written to ``--out`` (and, with ``--build``, passes every rule once
built); 1 none passes within the ranges (nothing is written; the closest design found and the rules it still fails
are printed), or the written design fails a rule once built; 2 bad input (the parameter file, a
``--vary``, an ``--out`` that exists or cannot be written).
"""
from __future__ import annotations

import json
import math
import os
import sys
import time
from pathlib import Path

from swiftfin.commands import DESIGN_HELP
from swiftfin.core.errors import UserError
from swiftfin.core.params import dump_toml
from swiftfin.layout.design import load_design
from swiftfin.outdir import check_output_file, write_text_atomic
from swiftfin.progress import bar, say


#: what ``--objective`` may ask for: the nearest passing design, or the front's best in one objective
OBJECTIVES = ("nearest", "speed", "power", "mass")


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    from swiftfin.design_rules.synthesis import DEFAULT_VARY
    ap.add_argument("params_file", nargs="?", default=None, help=DESIGN_HELP)
    ap.add_argument("--vary", action="append", default=[], metavar="KEY=LO:HI|KEY=A,B,C",
                    help="a key to search, a range of numbers or a list of values (repeatable). Default: "
                         + "; ".join(DEFAULT_VARY))
    ap.add_argument("--out", default="solved.toml",
                    help="parameter file to write the passing design to (default solved.toml; an existing file "
                         "is never overwritten)")
    ap.add_argument("--json", metavar="FILE", help="also write the result as JSON")
    ap.add_argument("--seed", type=int, default=0, help="seed of the samples and the evolution (default 0)")
    ap.add_argument("--samples", type=int, default=256, help="samples per searched key and stage (default 256)")
    ap.add_argument("--front-samples", type=int, default=4096, metavar="N",
                    help="designs per stage of the Pareto front over speed, mass and power (default 4096; 0: no "
                         "front)")
    ap.add_argument("--objective", choices=OBJECTIVES, default="nearest",
                    help="which passing design to write: nearest (default: fewest and smallest changes), or the "
                         "Pareto front's fastest (speed), least electrical power (power) or lightest (mass)")
    ap.add_argument("--front-plot", metavar="FILE.png", help="also draw the Pareto front (speed against power, "
                    "coloured by mass, marked by the rule that binds)")
    ap.add_argument("--build", metavar="DIR", default=None,
                    help="then build the written design (a Dask task, as `swiftfin sweep --stage build`: parts, "
                         "assembly proof, mass properties) into DIR/builds/ and apply every rule, the floating ones "
                         "included; exit 1 when the built design fails one")
    ap.add_argument("--build-front", type=int, default=0, metavar="K",
                    help="with --build, also build K designs spread along the Pareto front (default 0)")
    ap.add_argument("--workers", type=int, default=None, help="local Dask worker processes for --build "
                                                              "(default: one per core)")
    ap.add_argument("--scheduler", default=None, metavar="ADDRESS",
                    help="an existing Dask scheduler for --build instead of a local cluster")
    ap.add_argument("--cache-dir", default=None,
                    help="rebuild cache the builds share (default: $SWIFTFIN_CACHE_DIR or .cache/swiftfin/ here)")
    ap.set_defaults(func=run)


def _fmt(v) -> str:
    if isinstance(v, str):
        return v
    return f"{v:.4g}"


def _margin(m: float) -> str:
    return f"{100 * m:+.1f} %" if math.isfinite(m) else "-"


def run(args) -> int:
    from swiftfin.design_rules.synthesis import DEFAULT_VARY, parse_vary, solve
    if args.samples < 8 or args.samples > 1 << 16:
        raise UserError(f"--samples {args.samples}: expected 8 to 65536 samples per key")
    base = load_design(args.params_file)
    varies = [parse_vary(v) for v in (args.vary or DEFAULT_VARY)]
    out = Path(args.out)
    if out.exists():
        raise UserError(f"--out {out}: exists; swiftfin solve never overwrites a file (give another name)")
    check_output_file(out)
    if args.json:
        check_output_file(args.json, "--json")
    if args.front_samples != 0 and not 64 <= args.front_samples <= 1 << 18:
        raise UserError(f"--front-samples {args.front_samples}: expected 0 (no front) or 64 to 262144 designs")
    if args.objective != "nearest" and not args.front_samples:
        raise UserError(f"--objective {args.objective}: picks from the Pareto front, and there is none with "
                        f"--front-samples 0")
    if args.front_plot:
        if not args.front_samples:
            raise UserError("--front-plot: there is no front to draw with --front-samples 0")
        check_output_file(args.front_plot, "--front-plot")
    if args.build_front < 0 or (args.build_front and not args.build):
        raise UserError(f"--build-front {args.build_front}: expected 0 or more designs, and --build DIR to build "
                        f"them in")
    if args.build_front and not args.front_samples:
        raise UserError("--build-front: there is no front to build with --front-samples 0")
    if args.workers is not None and args.workers < 1:
        raise UserError(f"--workers {args.workers}: expected 1 or more worker processes")
    if args.build:
        from swiftfin.outdir import check_output_dir
        check_output_dir(args.build, "--build")
    t0 = time.perf_counter()
    res = solve(base, varies, samples_per_key=args.samples, seed=args.seed, front_samples=args.front_samples,
                progress=lambda text: say(f"  [{time.perf_counter() - t0:5.1f} s] {text}"), bar=bar)
    wall = time.perf_counter() - t0
    name = args.params_file or "the default design"
    print(f"swiftfin solve: {name}, {len(varies)} key(s) searched, {res.evaluated} designs evaluated in {wall:.1f} s")
    print(f"the design fails {len(res.base_failing)} rule(s): {', '.join(res.base_failing) or 'none'}")
    print()
    print("passes every kernel-free rule" if res.passes else
          f"NO design within the ranges passes; the closest found still fails: {', '.join(res.failing)}")
    print(f"{'change':38} {'from':>14} {'to':>14}  what it buys (fails when undone alone)")
    for c in res.changes:
        print(f"{c.key:38} {_fmt(c.before):>14} {_fmt(c.after):>14}  {', '.join(c.buys) or '-'}")
    if res.binding:
        print("binding: " + ", ".join(f"{r} {_margin(m)}" for r, m in res.binding))
    for n in res.notes:
        print(f"note: {n}")
    if res.front is not None:
        _print_front(res.front)
        if args.front_plot:
            _plot_front(res, varies, args.front_plot)
            print(f"drew the front: {args.front_plot}")
    chosen = _best_on_front(res.front, args.objective) if args.objective != "nearest" else None
    if args.json:
        doc = _as_json(res, varies, wall)
        doc["objective"] = args.objective
        if chosen is not None:
            doc["written"] = _point_json(chosen)
        write_text_atomic(args.json, json.dumps(doc, indent=2) + "\n")
    if args.objective != "nearest":
        if chosen is None:
            print(f"\nnothing written: no design on the Pareto front to pick the best {args.objective} from")
            return 1
        from swiftfin.design_rules.synthesis import _params_of
        design = _params_of(base, varies, dict(chosen.changes))
        what = {"speed": "the fastest", "power": "the least electrical power", "mass": "the lightest"}[args.objective]
        print(f"\n--objective {args.objective}: {what} design on the Pareto front, {chosen.speed_m_s:.3g} m/s, "
              f"{chosen.power_w:.3g} W, {chosen.mass_kg:.3g} kg of motors and components; binds: {chosen.binding}")
        header = [f"# Written by `swiftfin solve --objective {args.objective}`: {what} design on the Pareto front "
                  f"of the designs passing every kernel-free rule ({chosen.speed_m_s:.3g} m/s, "
                  f"{chosen.power_w:.3g} W, {chosen.mass_kg:.3g} kg of motors and components).",
                  f"# From {name}; changed: {_changes_text(chosen.changes)}"]
        header += [f"# Note: {n}" for n in res.front.notes]
    elif not res.passes:
        print("\nnothing written: widen the ranges or search other keys (--vary)")
        return 1
    else:
        design = res.design
        header = ["# Written by `swiftfin solve`: the nearest design passing every kernel-free rule.",
                  f"# From {name}; changed: " + "; ".join(f"{c.key} {_fmt(c.before)} -> {_fmt(c.after)}"
                                                       for c in res.changes)]
        header += [f"# Note: {n}" for n in res.notes]
    header += ["# Build it and check the floating rules: swiftfin build THIS --out DIR, then",
               "# swiftfin check THIS --mass-properties DIR/mass_properties.json", ""]
    write_text_atomic(out, "\n".join(header) + dump_toml(design), new_only=True)
    print(f"\nwrote {out}")
    if args.build:
        return _build(args, res, varies, base, out)
    return 0


def _build(args, res, varies, base, out: Path) -> int:
    """The written design (and ``--build-front`` front designs) built as Dask tasks into ``--build`` and checked
    with their mass properties: exit 0 when the written design passes every rule, 1 when it does not."""
    from swiftfin.design_rules.synthesis import _params_of, front_spread
    from swiftfin.sweep import SweepItem, sweep

    root = Path(args.build)
    items = [SweepItem(out.stem, str(out))]
    if args.build_front and res.front is not None and res.front.points:
        for k, q in enumerate(front_spread(res.front, args.build_front)):
            path = root / "designs" / f"front_{k + 1}.toml"
            head = (f"# Written by `swiftfin solve`: a design on the Pareto front, {q.speed_m_s:.3g} m/s, "
                    f"{q.power_w:.3g} W, {q.mass_kg:.3g} kg of motors and components\n")
            write_text_atomic(path, head + dump_toml(_params_of(base, varies, dict(q.changes))))
            items.append(SweepItem(path.stem, str(path)))
    print(f"\nbuilding {len(items)} design(s) as Dask tasks into {root}/builds/ (then every rule, the floating ones "
          f"included) ...")
    sys.stdout.flush()
    rows, _ = sweep(items, root, stage="build", scheduler=args.scheduler,
                    workers=args.workers or min(len(items), os.cpu_count() or 1), cache_dir=args.cache_dir,
                    progress=lambda text: say(f"  {text}"))
    print(f"{'design':24} {'status':8} {'verdict':10} {'mass kg':>8}  failing rules / message")
    for r in rows:
        what = r["failing"] if r["status"] == "ok" else str(r["message"]).splitlines()[0][:100]
        mass = f"{r['total_mass_kg']:.3f}" if isinstance(r["total_mass_kg"], float) else "-"
        print(f"{r['design']:24} {r['status']:8} {str(r['verdict']):10} {mass:>8}  {what or '-'}")
    first = rows[0]
    if first["status"] == "ok" and not first["n_fail"]:
        print(f"{out} built and passes every rule, the floating ones included ({root}/builds/{out.stem}/)")
        return 0
    print(f"{out} passes the kernel-free rules but not its build: "
          + (first["failing"] if first["status"] == "ok" else str(first["message"]).splitlines()[0]))
    return 1


def _best_on_front(front, objective: str):
    """The front's design best in ``objective`` (speed up, power or mass down; ties to the faster, then the
    lighter and less hungry), or None when the front is empty."""
    if front is None or not front.points:
        return None
    key = {"speed": lambda q: (-q.speed_m_s, q.power_w, q.mass_kg),
           "power": lambda q: (q.power_w, -q.speed_m_s, q.mass_kg),
           "mass": lambda q: (q.mass_kg, -q.speed_m_s, q.power_w)}[objective]
    return min(front.points, key=key)


def _changes_text(changes) -> str:
    return ", ".join(f"{k.split('.', 1)[1]}={_fmt(v)}" for k, v in changes) or "(the design itself)"


def _print_front(front) -> None:
    from swiftfin.design_rules.synthesis import front_spread
    print()
    if not front.points:
        print(f"Pareto front: none of {front.sampled} designs sampled passes every rule")
        return
    print(f"Pareto front over speed (up), mass and electrical power (down): {front.size} designs, of "
          f"{front.passing} passing among {front.sampled} sampled ({front.refused} refused by the layout checks); "
          f"{len(front.points)} kept, spread from the fastest to the slowest")
    print(f"{'speed m/s':>9} {'mass kg':>8} {'power W':>8}  {'binds (least margin)':28} {'stops it 5 % faster':28} "
          f"changes")
    for q in front_spread(front):
        print(f"{q.speed_m_s:9.3f} {q.mass_kg:8.3f} {q.power_w:8.2f}  {q.binding:28} "
              f"{', '.join(q.limits_speed) or '-':28} {_changes_text(q.changes)}")
    counts = {}
    for q in front.points:
        for r in q.limits_speed or ("(none: power or mass, not a rule)",):
            counts[r] = counts.get(r, 0) + 1
    print("binding along the front (least margin): " + ", ".join(f"{r} {n}" for r, n in front.binding_counts().items()))
    print("what stops each front design from beating 5 % faster: "
          + ", ".join(f"{r} {n}" for r, n in sorted(counts.items(), key=lambda kv: -kv[1])))
    for n in front.notes:
        print(f"note: {n}")


def _plot_front(res, varies, path) -> None:
    """The front as the report draws it (report/plots.py pareto_plot), from the JSON this command writes."""
    from swiftfin.outdir import write_bytes_atomic
    from swiftfin.report.plots import pareto_plot
    write_bytes_atomic(path, pareto_plot(_as_json(res, varies, 0.0)["front"]).png)


def _as_json(res, varies, wall: float) -> dict:
    def num(v):
        return v if isinstance(v, str) else float(v)
    return {"passes": res.passes, "base_failing": list(res.base_failing), "failing": list(res.failing),
            "changes": [{"key": c.key, "from": num(c.before), "to": num(c.after), "buys": list(c.buys)}
                        for c in res.changes],
            "binding": [{"rule": r, "margin": m} for r, m in res.binding], "notes": list(res.notes),
            "searched": [v.text() for v in varies], "designs_evaluated": res.evaluated, "wall_s": wall,
            "front": None if res.front is None else {
                "size": res.front.size, "sampled": res.front.sampled, "passing": res.front.passing, "refused": res.front.refused,
                "notes": list(res.front.notes),
                "points": [_point_json(q) for q in res.front.points]}}


def _point_json(q) -> dict:
    """A front design as the JSON (and the report's Trade-offs section) reads it."""
    return {"speed_m_s": q.speed_m_s, "mass_kg": q.mass_kg, "power_w": q.power_w, "binding": q.binding,
            "margin": q.margin, "limits_speed": list(q.limits_speed),
            "changes": {k: v if isinstance(v, str) else float(v) for k, v in q.changes}}
