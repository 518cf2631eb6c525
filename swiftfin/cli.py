"""The ``swiftfin`` command (also ``python -m swiftfin``).

Each sub-command lives in ``swiftfin/commands/<name>.py`` and exposes ``configure(parser)`` (adds its arguments,
sets ``func``) and ``run(args) -> int``. Only the command being run is imported: ``swiftfin check`` never loads
the CAD kernel, the calibration engine or the simulators, and ``swiftfin --help`` loads none of them.

Bad input (ParamError, UserError) prints one clear message on stderr and exits 2; a failed build check
(BuildError) exits 1. Tracebacks are for bugs only.
"""
from __future__ import annotations

import argparse
import importlib
import sys
import textwrap
from dataclasses import dataclass

from swiftfin import __version__
from swiftfin.core.errors import BuildError, UserError
from swiftfin.core.params import ParamError


@dataclass(frozen=True)
class Command:
    summary: str        # one line, for `swiftfin --help`
    description: str    # one paragraph, for `swiftfin COMMAND --help`
    examples: str       # command lines, one per line


COMMANDS: dict[str, Command] = {
    "build": Command(
        "build every part (STEP, STL, 3MF), the assembly, the simulator files and the report",
        "Builds every part of the design from one parameter file: each part as STEP, STL and 3MF (printed parts "
        "turned to their print orientation), the assembly STEP with its clearance proof, the mass properties, the "
        "robot for simulators (URDF, MJCF, SDF), report.html and manifest.json. Part families whose inputs did not "
        "change are taken from the rebuild cache. The output folder is written whole or not at all. With "
        "--calibration, a joint's measured damping, friction and stiffness (swiftfin fit joint) go into the "
        "simulator files and the report's rules.",
        "swiftfin build                          # ./swiftfin.toml (or the shipped design) -> build/\n"
        "swiftfin build my_fish.toml --out my_build\n"
        "swiftfin build --calibration fit_joint/calibration.toml --out build_cal\n"
        "swiftfin build --no-cache               # every part afresh"),
    "check": Command(
        "apply the design rules (exit 1 if any fails)",
        "Applies every design rule to the design (drum to cable diameter, pretension, holding torque against the "
        "swimming load, cable strength and stretch, slack, stepper pull-out, Strouhal number, print bed, and with "
        "a build's mass properties the floating rules) and prints a table of findings. Exit 0 when no rule fails, "
        "1 when one does, 2 for a bad input file. Needs no CAD kernel. With --calibration, the rules use a joint's "
        "measured cable stiffness, hinge damping and friction; with --build, a build folder's mass properties and "
        "its printed parts' support, thin walls and bridges.",
        "swiftfin check\n"
        "swiftfin check --calibration fit_joint/calibration.toml\n"
        "swiftfin check my_fish.toml --json check.json\n"
        "swiftfin check --build build\n"
        "swiftfin check --mass-properties build/mass_properties.json --loads"),
    "audit": Command(
        "recompute the paper's derived numbers and say which hold",
        "Recomputes every number the SwiftFin paper derives from its own inputs (its equations, tables and "
        "claims) and says, entry by entry, whether it holds. Always exits 0: the audit reports on the paper.",
        "swiftfin audit\n"
        "swiftfin audit --json audit.json"),
    "fit": Command(
        "fit a model family to measured data and name the effects it lacks",
        "Compares a model family (joint: a capstan-driven tail joint; drive: a one-axis drive such as EMPS; body: "
        "the body wave from video markers) with a measured log, diagnoses the residual and adds named physical "
        "effects one at a time, each kept only when it lowers the error on held-out data. Writes fit_report.json, "
        "fit_report.md and plots to --out; for a joint, also calibration.toml (the measured values, for build and "
        "check --calibration) and, with --mjcf, the log replayed in MuJoCo through the exported and the calibrated "
        "joint.",
        "swiftfin fit joint bench_log.csv --design swiftfin.toml --out fit_joint\n"
        "swiftfin fit joint bench_log.csv --bench bench.toml --mjcf build/robot/swiftfin.xml --out fit_joint\n"
        "swiftfin fit drive DATA_EMPS.mat --holdout DATA_EMPS_PULSES.mat --out fit_emps\n"
        "swiftfin fit body fishsim/ --holdout fishsim/markers_f2_25.csv --out fit_body"),
    "synth": Command(
        "simulate a measured log with chosen (undeclared) effects",
        "Simulates a bench log of one tail joint of the design (stepper, spool, pretensioned elastic cables, the "
        "link with inertia, damping, drag and friction, an encoder with noise) with the effects you choose, to "
        "test `swiftfin fit` on known truth.",
        "swiftfin synth joint --effect backlash --out log.csv\n"
        "swiftfin synth joint --effect coulomb_friction=0.02 --effect sensor_delay --seed 3 --out log.csv"),
    "report": Command(
        "write DIR/report.html: pictures, rules, masses, plots, audit, fit",
        "Writes the design report, one self-contained HTML page: the assembly and every printed part rendered, "
        "the design rules, the mass table, the efficiency, tail-beat and body-wave plots, the paper audit and, "
        "with --fit, a fit's before and after, and with --solve, a solve's nearest design and Pareto front. Uses "
        "the build in DIR when it is of the same parameter file.",
        "swiftfin report --out build\n"
        "swiftfin report my_fish.toml --out my_build --fit fit_joint\n"
        "swiftfin report --out build --solve solve.json"),
    "solve": Command(
        "find the nearest design that passes every rule, and what each change buys",
        "Searches the keys you name (ranges of numbers, catalogue motors and cables, materials) for the design "
        "nearest to yours that passes every kernel-free design rule: fewest keys changed first, then the "
        "smallest change, each change pulled back to the boundary of the rule that binds. Prints what each change "
        "buys (the rules that fail when it alone is undone) and writes the design as a parameter file. Exit 0 "
        "when a design passes, 1 when none does within the ranges (nothing written), 2 for bad input. Then the "
        "Pareto front over speed, mass and electrical power of the passing designs, with the rule that binds "
        "along it (--front-plot draws it). The search needs no CAD kernel; --build DIR builds the written design "
        "as a Dask task and checks it afloat (exit 1 if the built design fails a rule).",
        "swiftfin solve                                   # the default levers, -> solved.toml\n"
        "swiftfin solve my_fish.toml --vary cable.pretension_n=10:200 --vary motor.model=custom,23HS22-2804S\n"
        "swiftfin solve --vary swimming.tail_beat_frequency_hz=0.5:3 --out slower.toml --json solve.json\n"
        "swiftfin solve --objective speed --out fastest.toml   # the front's fastest passing design instead\n"
        "swiftfin solve --json solve.json --front-plot front.png --build solved_build   # then: swiftfin report "
        "--solve solve.json"),
    "sweep": Command(
        "run many designs as Dask tasks (a build each, or the rules) into one table",
        "Runs every design named (parameter files, or folders of them) as a Dask task on a local cluster of one "
        "process per core, or on an existing Dask cluster (--scheduler): a full build into its own folder with its "
        "manifest, then every rule with that build's mass properties (or, --stage check, the kernel-free rules "
        "alone). One row per design gathers in results.csv; a design that is refused or fails to build keeps its "
        "row and message. A run that was stopped resumes: designs whose row matches their file are skipped.",
        "swiftfin sweep designs/ --out sweep_out\n"
        "swiftfin sweep a.toml b.toml --out sweep_out --stage check --workers 2\n"
        "swiftfin sweep designs/ --out sweep_out --scheduler tcp://10.0.0.5:8786"),
    "params": Command(
        "validate a parameter file or print the documented defaults",
        "Validates a parameter file (every problem at once, each with its key, value and allowed range) or, with "
        "--dump, prints the default design with every key's unit, range and source: the starting point of a "
        "design of your own.",
        "swiftfin params --dump > my_fish.toml   # then edit, and: swiftfin build my_fish.toml\n"
        "swiftfin params my_fish.toml"),
}

DESCRIPTION = ("Parametric CAD and mechanism design for a capstan-driven robotic tuna (the SwiftFin): every part "
               "from one parameter file, the design rules, simulator files and calibration against measured data.")
EPILOG = ("Without a parameter file, a command uses ./swiftfin.toml when there is one, otherwise the SwiftFin "
          "design shipped with swiftfin. `swiftfin COMMAND --help` describes each command, with examples.")


def _selected(argv: list[str]) -> str | None:
    """The sub-command named on the command line (the first argument that is not an option)."""
    for a in argv:
        if not a.startswith("-"):
            return a if a in COMMANDS else None
    return None


def make_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser; only the selected command's module is imported (``argv`` None: every command's, for tests)."""
    parser = argparse.ArgumentParser(prog="swiftfin", description=DESCRIPTION, epilog=EPILOG)
    parser.add_argument("--version", action="version", version=f"swiftfin {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    chosen = _selected(argv) if argv is not None else None
    for name, cmd in COMMANDS.items():
        examples = textwrap.indent(cmd.examples, "  ")
        ap = sub.add_parser(name, help=cmd.summary, description=textwrap.fill(cmd.description, 100),
                            epilog=f"examples:\n{examples}", formatter_class=argparse.RawDescriptionHelpFormatter)
        if argv is None or name == chosen:
            importlib.import_module(f"swiftfin.commands.{name}").configure(ap)
    return parser


def _resolve_default_design(args) -> None:
    """A command given no parameter file uses ./swiftfin.toml, or the design shipped with swiftfin."""
    for attr in ("params_file", "design"):
        if hasattr(args, attr) and getattr(args, attr) is None:
            from swiftfin.layout.design import default_design_path

            setattr(args, attr, str(default_design_path()))


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = make_parser(argv)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        _resolve_default_design(args)
        return int(args.func(args) or 0)
    except ParamError as exc:
        print(f"swiftfin {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except UserError as exc:
        print(f"swiftfin {args.command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except BuildError as exc:
        print(f"swiftfin {args.command}: build check failed: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"swiftfin {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into `head` etc.: stop quietly, like other Unix tools
        import os
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
