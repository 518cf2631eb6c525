"""``swiftfin fit FAMILY DATA``: compare a model family with measured data, find the effects it lacks, report.

Writes ``DIR/fit_report.json``, ``DIR/fit_report.md`` and PNG plots (see :mod:`calibration.report`); the joint
family also writes ``DIR/calibration.toml``, the physical values it found (:mod:`calibration.closing`), which
``swiftfin build --calibration`` and ``swiftfin check --calibration`` read back.
Bad data (missing columns, broken time stamps, long NaN gaps, degrees in a ``_rad`` column, a log too short or
too poorly excited) exits 2 with a message naming the file, the column and the row; short NaN gaps are filled
and reported as warnings. Bad options (unknown family, several files for a one-file family, a fraction outside
(0, 1), an empty folder, a held-out file that is also training data, an ``--out`` that is a file or cannot be
written, ...) exit 2 with one message, before any fitting. Data that cannot be what they claim exit 2 as well:
millimetres in ``position_m``, time in milliseconds, a joint column that copies the motor column, a motionless
video, a file name whose drive frequency the tail beat contradicts (see each family's loader).

Held-out data (``--holdout``): a fraction of the run held out as contiguous time blocks (default 0.3), or one
separate run. Families that read several files (``body``: one video per drive frequency) take several files or
a folder as DATA and one or more held-out files: ``swiftfin fit body fishsim/ --holdout
fishsim/markers_f2_25.csv`` fits on the other five videos and predicts the held-out drive frequency.

Selection criterion (``--alpha``, ``--min-drop``): an effect is added when it lowers the held-out RMSE by more
than the relative margin ``--min-drop`` and the drop is significant at ``--alpha`` (held-out F-test with the
residual's effective sample size). Defaults are the family's (joint and drive: 1e-3 and 0.10; body: 0.01 and
0.03, because a short video holds only a few dozen effective samples; see :mod:`calibration.body`).
"""
from __future__ import annotations

import inspect
import sys
from pathlib import Path

from swiftfin.layout.design import load_design
from swiftfin.core.errors import UserError
from swiftfin.commands import DESIGN_HELP
from swiftfin.outdir import check_output_dir


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    from swiftfin.calibration import FAMILY_MODULES
    ap.add_argument("family", help=f"model family: {', '.join(FAMILY_MODULES)}")
    ap.add_argument("data", nargs="+",
                    help="measured log (CSV for joint and drive; marker CSV for body). The body family also takes "
                         "several files or a folder (every markers_*.csv in it)")
    ap.add_argument("--design", default=None, help=DESIGN_HELP)
    ap.add_argument("--holdout", default=None, nargs="+",
                    help="held-out data: a fraction in (0, 1) of the run held out as contiguous time blocks "
                         "(default 0.3), or a separate run (a second log; for body one or more marker files, "
                         "left out of a DATA folder)")
    ap.add_argument("--out", default="fit_out", help="output directory (default: fit_out); checked before the fit: "
                                                     "an existing file or an unwritable place exits 2")
    ap.add_argument("--joint", type=int, default=None,
                    help="joint family: which tail joint the log is from, 1-based (default: the last, caudal one)")
    ap.add_argument("--max-effects", type=int, default=4, help="at most this many effects are added (default 4)")
    ap.add_argument("--alpha", type=float, default=None,
                    help="significance level an effect's held-out error drop must reach, in (0, 1) "
                         "(default: the family's; joint, drive 1e-3; body 0.01)")
    ap.add_argument("--min-drop", type=float, default=None,
                    help="smallest relative drop of the held-out RMSE that counts, in [0, 1) "
                         "(default: the family's; joint, drive 0.10; body 0.03)")
    ap.add_argument("--no-plots", action="store_true", help="write the JSON and markdown only")
    ap.add_argument("--bench", metavar="FILE", default=None,
                    help="joint family: bench file, the link on the hinge and its bearing (medium = \"air\" | "
                         "\"water\", link_inertia_kg_m2, bearing_damping_nm_s_rad; default the design's own link "
                         "in air)")
    ap.add_argument("--mjcf", metavar="FILE", default=None,
                    help="joint family: an exported MJCF (a build's robot/swiftfin.xml); the measured command is "
                         "replayed in MuJoCo through its joint, as exported and as calibrated, on the bench's "
                         "link, and the report gives both errors")
    ap.set_defaults(func=run)


def _load(fam, path: str, design, args, notes: list, bench=None) -> object:
    kw = {}
    params = inspect.signature(fam.load).parameters
    if "joint" in params and args.joint is not None:
        kw["joint"] = args.joint - 1
    if "bench" in params and bench is not None:
        kw["bench"] = bench
    if "notes" in params:
        kw["notes"] = notes
    return fam.load(path, design, **kw)


def _expand(paths: list[str], what: str) -> list[Path]:
    """Files named, folders replaced by their CSV files (sorted). Missing paths and empty folders: UserError."""
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            files = sorted(p.glob("markers_*.csv")) or sorted(p.glob("*.csv"))
            if not files:
                raise UserError(f"{what} {p}: folder holds no CSV file")
            out += files
        elif not p.exists():
            raise UserError(f"{what} {p}: file not found (no such file or folder)")
        else:
            out.append(p)
    return out


def _data_sets(fam, args) -> tuple[list[Path], list[Path], float | None]:
    """(training files, held-out files, held-out fraction) from DATA and --holdout, checked."""
    from swiftfin.calibration.io import split_holdout_arg
    hold_args = args.holdout or []
    fraction = 0.3
    hold_files: list[Path] = []
    if len(hold_args) == 1:
        f, fraction = split_holdout_arg(hold_args[0])
        hold_files = _expand([f], "--holdout") if f else []
    elif hold_args:
        for h in hold_args:
            try:
                float(h)
            except ValueError:
                continue
            raise UserError(f"--holdout {' '.join(hold_args)}: give either one fraction or held-out files, not both")
        hold_files = _expand(hold_args, "--holdout")
    several = len(args.data) > 1 or any(Path(d).is_dir() for d in args.data) or len(hold_files) > 1
    if several and fam.load_many is None:
        raise UserError(f"the {fam.name} family reads one log per run: give one DATA file (got "
                        f"{', '.join(args.data)}) and at most one --holdout file")
    train = _expand(args.data, "DATA")
    folder = any(Path(d).is_dir() for d in args.data)
    resolved_hold = {h.resolve() for h in hold_files}
    if folder:      # a held-out file inside the DATA folder is left out of the training set
        train = [t for t in train if t.resolve() not in resolved_hold]
    else:
        both = [str(t) for t in train if t.resolve() in resolved_hold]
        if both:
            raise UserError(f"--holdout {', '.join(both)}: also given as DATA; held-out data must be another run")
    if not train:
        raise UserError(f"DATA {' '.join(args.data)}: no training file left after removing the held-out files")
    return train, hold_files, (None if hold_files else fraction)


def run(args) -> int:
    from swiftfin.calibration.engine import Calibrator, concat_contexts, get_family
    from swiftfin.calibration.report import write_report

    try:
        fam = get_family(args.family)
    except KeyError as exc:
        raise UserError(str(exc.args[0])) from None
    except ModuleNotFoundError as exc:
        raise UserError(f"family {args.family!r} is not available in this installation ({exc.name})") from None
    for opt in ("joint", "bench", "mjcf"):
        if getattr(args, opt) is not None and args.family != "joint":
            raise UserError(f"--{opt} applies to the joint family only, not {args.family!r}")
    bench = None
    if args.bench:
        from swiftfin.calibration.bench import load_bench
        bench = load_bench(args.bench)
    if args.mjcf is not None and not Path(args.mjcf).is_file():
        raise UserError(f"--mjcf {args.mjcf}: file not found (give a build's robot/swiftfin.xml)")
    if args.max_effects < 0:
        raise UserError(f"--max-effects {args.max_effects}: must be >= 0")
    if args.alpha is not None and not 0.0 < args.alpha < 1.0:
        raise UserError(f"--alpha {args.alpha:g}: a significance level must lie strictly between 0 and 1 (e.g. 0.01)")
    if args.min_drop is not None and not 0.0 <= args.min_drop < 1.0:
        raise UserError(f"--min-drop {args.min_drop:g}: a relative drop must lie in [0, 1) (e.g. 0.05 for 5 %)")
    train_files, hold_files, fraction = _data_sets(fam, args)
    check_output_dir(args.out)            # before the fit: a path that cannot be written fails now, not after
    design = load_design(args.design)
    exported = None
    if args.mjcf is not None:             # before the fit: an MJCF MuJoCo cannot load, or without the joint, fails now
        from swiftfin.calibration.replay import joint_from_mjcf
        exported = joint_from_mjcf(args.mjcf, args.joint if args.joint is not None else design.joints.count)
    notes: list[str] = []
    if fam.load_many is not None and (len(train_files) > 1 or len(hold_files) > 1):
        kw = {"notes": notes} if "notes" in inspect.signature(fam.load_many).parameters else {}
        ctxs = fam.load_many([str(p) for p in train_files + hold_files], design, **kw)
        train = concat_contexts(ctxs[:len(train_files)])
        holdout = concat_contexts(ctxs[len(train_files):]) if hold_files else None
    else:
        train = _load(fam, str(train_files[0]), design, args, notes, bench)
        holdout = _load(fam, str(hold_files[0]), design, args, notes, bench) if hold_files else None
    for n in notes:
        print(f"swiftfin fit: warning: {n}", file=sys.stderr)
    cal = Calibrator(fam, holdout_fraction=fraction or 0.3, max_effects=args.max_effects, alpha=args.alpha,
                     min_relative_drop=args.min_drop)
    cal.fit(train, holdout)
    data = " ".join(str(p) for p in train_files)
    calibration = replayed = None
    extra, extra_md = {}, ""
    if args.family == "joint":
        calibration = _calibration(args, cal.report_dict(), design, train_files[0], train)
        if exported is not None:
            from swiftfin.calibration.replay import replay_markdown, replay_report
            replayed = replay_report(train, args.mjcf, exported, calibration.revised_params(design),
                                     calibration.joint(_joint(args, design)))
            extra, extra_md = {"replay": replayed.summary}, replay_markdown(replayed.summary, not args.no_plots)
    try:
        rep = write_report(cal, args.out, data=data, notes=notes, plots=not args.no_plots, extra=extra,
                           extra_markdown=extra_md)
        cal_file = _write_calibration(args.out, calibration) if calibration is not None else None
        if replayed is not None and not args.no_plots:
            from swiftfin.calibration.replay import plot_replay
            plot_replay(replayed, Path(args.out) / "replay.png")
    except OSError as exc:
        raise UserError(f"--out {args.out}: cannot write the report ({exc.strerror or exc})") from None
    base, fin, unit = rep["baseline"], rep["final"], rep["units"]["target"]
    nf = rep.get("noise_floor")
    floor = f"; noise floor {nf:.4g} {unit}" if nf is not None and nf == nf and nf > 0 else ""
    print(f"{args.family}: {rep['n_samples']} samples; held-out RMSE {base['rmse_holdout']:.4g} (base) -> "
          f"{fin['rmse_holdout']:.4g} {unit} (final{floor})")
    for e in rep["added_effects"]:
        alt = f" (indistinguishable from {', '.join(e['indistinguishable_from'])})" if e["indistinguishable_from"] else ""
        print(f"  + {e['name']}: {e['rmse_holdout_before']:.4g} -> {e['rmse_holdout_after']:.4g}, "
              f"{e['confidence']} confidence{alt}")
    for s in rep.get("steps", []):
        if str(s.get("decision", "")).startswith("remove "):
            print(f"  - {s['decision'][7:]}: removed again, it stood in for an effect found later "
                  f"(held-out drop given the others {100 * s['relative_drop_given_others']:.1f} %)")
    if not rep["added_effects"]:
        print("  no effect added")
    if rep["unexplained_structure"]:
        print("  unexplained structure remains in the residual (no candidate explains it)")
    print(f"report: {Path(args.out) / 'fit_report.md'}")
    if cal_file is not None:
        print(f"calibration: {cal_file} (use it with swiftfin build/check --calibration)")
    if replayed is not None:
        r = replayed.summary
        print(f"replay in MuJoCo through joint_{r['joint']} of {r['mjcf']} on the bench's link: RMSE "
              f"{r['before']['rmse_rad']:.4g} rad as exported -> {r['after']['rmse_rad']:.4g} rad calibrated")
    return 0


def _joint(args, design) -> int:
    """The log's joint, 1-based (--joint, else the design's last)."""
    return args.joint if args.joint is not None else design.joints.count


def _calibration(args, report: dict, design, log: Path, ctx):
    """The physical values the joint fit found (calibration.closing), with the bench's bearing damping the fit's
    base model assumed (``ctx``'s design constants, a bench file's if one was given)."""
    from swiftfin.calibration.closing import calibration_from_report
    from swiftfin.layout.design import default_design_path

    return calibration_from_report(report, _joint(args, design), log, args.design or default_design_path(),
                                   Path(args.out) / "fit_report.json", ctx.meta["design"].bearing_damping_nm_s_rad)


def _write_calibration(out: str, calibration) -> Path:
    """``OUT/calibration.toml``, which ``swiftfin build --calibration`` and ``swiftfin check --calibration`` read."""
    from swiftfin.core.calibration import FILE_NAME, calibration_toml

    path = Path(out) / FILE_NAME
    path.write_text(calibration_toml(calibration), encoding="utf-8")
    return path
