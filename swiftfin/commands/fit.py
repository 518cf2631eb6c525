"""``swiftfin fit FAMILY DATA``: compare a model family with measured data, find the effects it lacks, report.

Writes ``DIR/fit_report.json``, ``DIR/fit_report.md`` and PNG plots (see :mod:`calibration.report`).
Bad data (missing columns, broken time stamps, long NaN gaps, degrees in a ``_rad`` column, a log too short or
too poorly excited) exits 2 with a message naming the file, the column and the row; short NaN gaps are filled
and reported as warnings.
"""
from __future__ import annotations

import inspect
import sys
from pathlib import Path

from swiftfin.config import DEFAULT_DESIGN, load_design
from swiftfin.errors import UserError


def register(sub) -> None:
    from calibration.engine import FAMILY_MODULES
    ap = sub.add_parser("fit", help="fit a model family to measured data and name the effects it lacks")
    ap.add_argument("family", help=f"model family: {', '.join(FAMILY_MODULES)}")
    ap.add_argument("data", help="measured log (CSV for joint and drive; see the family's docs)")
    ap.add_argument("--design", default=DEFAULT_DESIGN, help="parameter file (default: swiftfin.toml)")
    ap.add_argument("--holdout", default=None,
                    help="held-out data: a second log (a separate run) or a fraction in (0, 1) of the run held out "
                         "as contiguous time blocks (default 0.3)")
    ap.add_argument("--out", default="fit_out", help="output directory (default: fit_out)")
    ap.add_argument("--joint", type=int, default=None,
                    help="joint family: which tail joint the log is from, 1-based (default: the last, caudal one)")
    ap.add_argument("--max-effects", type=int, default=4, help="at most this many effects are added (default 4)")
    ap.add_argument("--no-plots", action="store_true", help="write the JSON and markdown only")
    ap.set_defaults(func=run)


def _load(fam, path: str, design, args, notes: list) -> object:
    kw = {}
    params = inspect.signature(fam.load).parameters
    if "joint" in params and args.joint is not None:
        kw["joint"] = args.joint - 1
    if "notes" in params:
        kw["notes"] = notes
    return fam.load(path, design, **kw)


def run(args) -> int:
    from calibration.engine import Calibrator, get_family
    from calibration.io import split_holdout_arg
    from calibration.report import write_report

    try:
        fam = get_family(args.family)
    except KeyError as exc:
        raise UserError(str(exc.args[0])) from None
    except ModuleNotFoundError as exc:
        raise UserError(f"family {args.family!r} is not available in this installation ({exc.name})") from None
    if args.joint is not None and args.family != "joint":
        raise UserError(f"--joint applies to the joint family only, not {args.family!r}")
    if args.max_effects < 0:
        raise UserError(f"--max-effects {args.max_effects}: must be >= 0")
    design = load_design(args.design)
    notes: list[str] = []
    hold_file, fraction = split_holdout_arg(args.holdout)
    train = _load(fam, args.data, design, args, notes)
    holdout = _load(fam, hold_file, design, args, notes) if hold_file else None
    for n in notes:
        print(f"swiftfin fit: warning: {n}", file=sys.stderr)
    cal = Calibrator(fam, holdout_fraction=fraction or 0.3, max_effects=args.max_effects)
    cal.fit(train, holdout)
    rep = write_report(cal, args.out, data=str(args.data), notes=notes, plots=not args.no_plots)
    base, fin = rep["baseline"], rep["final"]
    print(f"{args.family}: {rep['n_samples']} samples; held-out RMSE {base['rmse_holdout']:.4g} (base) -> "
          f"{fin['rmse_holdout']:.4g} {fam.target_unit} (final)")
    for e in rep["added_effects"]:
        alt = f" (indistinguishable from {', '.join(e['indistinguishable_from'])})" if e["indistinguishable_from"] else ""
        print(f"  + {e['name']}: {e['rmse_holdout_before']:.4g} -> {e['rmse_holdout_after']:.4g}, "
              f"{e['confidence']} confidence{alt}")
    if not rep["added_effects"]:
        print("  no effect added")
    if rep["unexplained_structure"]:
        print("  unexplained structure remains in the residual (no candidate explains it)")
    print(f"report: {Path(args.out) / 'fit_report.md'}")
    return 0
