"""``swiftfin synth joint --effect NAME[=VALUE] ... --out FILE``: a physically simulated bench log.

See :mod:`calibration.synth` for the simulation (stepper -> spool -> pretensioned elastic cables -> joint with
inertia, damping, drag and friction -> 12-bit encoder with noise) and the default size of each effect.
"""
from __future__ import annotations

from swiftfin.layout.design import load_design
from swiftfin.core.errors import UserError
from swiftfin.commands import DESIGN_HELP
from swiftfin.outdir import check_output_file


def configure(ap) -> None:
    """Add this command's arguments to its parser (made by swiftfin.cli)."""
    from swiftfin.calibration.synth import EFFECT_DEFAULTS, EXTRA_EFFECTS
    lines = [f"{k} (default {v[0]:g} {v[1]}: {v[2]})" + (" [not in the fit library]" if k in EXTRA_EFFECTS else "")
             for k, v in EFFECT_DEFAULTS.items()]
    ap.add_argument("family", choices=["joint"], help="model family to simulate (joint)")
    ap.add_argument("--effect", action="append", default=[], metavar="NAME[=VALUE]",
                    help="add an effect (repeatable): " + "; ".join(lines))
    ap.add_argument("--out", required=True, help="CSV file to write")
    ap.add_argument("--seed", type=int, default=0, help="random seed (command phases and noise)")
    ap.add_argument("--design", default=None, help=DESIGN_HELP)
    ap.add_argument("--joint", type=int, default=None, help="tail joint simulated, 1-based (default: the last)")
    ap.add_argument("--duration", type=float, default=40.0, help="log length [s] (default 40)")
    ap.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    ap.add_argument("--noise", type=float, default=None, help="sensor noise [rad] (default 1e-3)")
    ap.add_argument("--no-load-cell", action="store_true",
                    help="leave out the cable_tension_n column (a bench without a load cell)")
    ap.add_argument("--bench", metavar="FILE", default=None,
                    help="bench file: the link on the hinge and its bearing (medium = \"air\" | "
                         "\"water\", link_inertia_kg_m2, bearing_damping_nm_s_rad; default the design's own link "
                         "in air)")
    ap.set_defaults(func=run)


def run(args) -> int:
    from swiftfin.calibration.io import write_log
    from swiftfin.calibration.joint import joint_design
    from swiftfin.calibration.synth import NOISE_RAD, simulate_joint, parse_effects

    try:
        effects = parse_effects(args.effect)
    except ValueError as exc:
        raise UserError(f"--effect: {exc}") from None
    if not 0.5 <= args.duration <= 1e5:
        raise UserError(f"--duration {args.duration}: expected 0.5 to 1e5 s")
    if not 10 <= args.rate <= 1e5:
        raise UserError(f"--rate {args.rate}: expected 10 to 1e5 Hz")
    noise = NOISE_RAD if args.noise is None else args.noise
    if noise < 0:
        raise UserError(f"--noise {noise}: must be >= 0 rad")
    bench = None
    if args.bench:
        from swiftfin.calibration.bench import load_bench
        bench = load_bench(args.bench)
    check_output_file(args.out)           # before simulating: a folder or an unwritable place fails now
    joint = None if args.joint is None else args.joint - 1
    design = load_design(args.design)
    d = joint_design(design, joint) if bench is None else bench.design(design, joint)
    log = simulate_joint(d, effects, duration_s=args.duration, rate_hz=args.rate, noise_rad=noise, seed=args.seed)
    cols = {"time_s": log.t, "motor_angle_rad": log.motor_angle_rad, "joint_angle_rad": log.joint_angle_rad}
    if not args.no_load_cell:
        cols["cable_tension_n"] = log.cable_tension_n
    try:
        write_log(args.out, cols)
    except OSError as exc:
        raise UserError(f"--out {args.out}: cannot write the log ({exc.strerror or exc})") from None
    desc = ", ".join(f"{k}={v:g}" for k, v in effects.items()) or "none"
    print(f"{args.out}: {log.t.size} samples, joint {d.joint + 1}, effects: {desc} ({log.integrator}"
          + (f", {log.n_slips} slips" if "lost_steps" in effects else "") + ")")
    return 0
